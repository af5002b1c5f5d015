"""Classify every run stable / degraded / blown up and draw the stability map."""

import xarray as xr

from beadsim.analysis import stability_table
from beadsim.io import atomic_path, save_figure
from beadsim.logs import configure_logging
from beadsim.plots import stability_map

configure_logging(snakemake.log[0])
ds = xr.load_dataset(snakemake.input[0])
table = stability_table(ds, **snakemake.params.options)
with atomic_path(snakemake.output.table) as tmp:
    table.to_csv(tmp, index=False)
axes = snakemake.params.axes
save_figure(stability_map(ds, table, axes.get("map_x"), axes.get("map_y"), axes.get("map_facet")),
            snakemake.output.figure)
