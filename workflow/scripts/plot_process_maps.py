"""Process maps of the study's metrics over its swept parameters."""

import xarray as xr

from beadsim.io import save_figure
from beadsim.logs import configure_logging
from beadsim.plots import process_maps

configure_logging(snakemake.log[0])
ds = xr.load_dataset(snakemake.input[0])
save_figure(process_maps(ds, **snakemake.params.options), snakemake.output[0])
