"""Cost and error of every run, Pareto fronts, speed-vs-accuracy chart."""

import xarray as xr

from beadsim.analysis import speed_accuracy_table
from beadsim.io import atomic_path, save_figure
from beadsim.logs import configure_logging
from beadsim.plots import speed_accuracy_plot
from beadsim.study import load_experiments

configure_logging(snakemake.log[0])
ds = xr.load_dataset(snakemake.input.dataset)
table = speed_accuracy_table(ds, load_experiments(snakemake.input.experiments), snakemake.params.reference)
with atomic_path(snakemake.output.table) as tmp:
    table.to_csv(tmp, index=False)
save_figure(speed_accuracy_plot(table), snakemake.output.figure)
