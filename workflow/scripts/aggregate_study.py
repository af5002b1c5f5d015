"""Collect all runs of the study into dataset.nc (and dataset_grid.nc when the sweep is a full grid)."""

from pathlib import Path

from beadsim.dataset import build_dataset, gridded
from beadsim.io import write_netcdf, atomic_path
from beadsim.logs import configure_logging
from beadsim.study import design, load_experiments

configure_logging(snakemake.log[0])
config = dict(snakemake.params.config)
table = design(config, load_experiments(snakemake.params.experiments))
ds = build_dataset(snakemake.input.results, snakemake.input.benchmarks, config, table)
write_netcdf(ds, snakemake.output.dataset)
grid = gridded(ds)
if grid is not None:
    write_netcdf(grid, Path(snakemake.output.dataset).with_name("dataset_grid.nc"))
with atomic_path(snakemake.output.summary) as tmp:
    ds.reset_coords().to_dataframe().to_csv(tmp)
