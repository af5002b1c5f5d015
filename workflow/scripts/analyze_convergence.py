"""Observed order, Richardson extrapolation and GCI over the study's resolution ladder."""

import xarray as xr

from beadsim.analysis import convergence_table
from beadsim.io import atomic_path, save_figure
from beadsim.logs import configure_logging
from beadsim.plots import convergence_plot

configure_logging(snakemake.log[0])
ds = xr.load_dataset(snakemake.input[0])
table = convergence_table(ds, snakemake.params.parameter)
with atomic_path(snakemake.output.table) as tmp:
    table.to_csv(tmp, index=False)
save_figure(convergence_plot(ds, table, snakemake.params.parameter), snakemake.output.figure)
