"""SPH checks of the reduced model: each SPH run beside the reduced run of the same scene."""

import xarray as xr

from beadsim.analysis import model_check_table
from beadsim.io import atomic_path
from beadsim.logs import configure_logging

configure_logging(snakemake.log[0])
table = model_check_table(xr.load_dataset(snakemake.input[0]))
with atomic_path(snakemake.output[0]) as tmp:
    table.to_csv(tmp, index=False)
