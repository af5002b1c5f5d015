"""Pictures of an SPH run: temperature (top view, sections, melt pool outline) of its last particle dump, and its
bead cross-section (height map and mass per column, from timeseries.nc) against the measured bead of its mode."""

import json
from pathlib import Path

import xarray as xr

from beadsim.compare import matching_mode
from beadsim.io import save_figure
from beadsim.logs import configure_logging
from beadsim.materials import get_material
from beadsim.sph.pictures import run_picture, section_figure
from beadsim.study import load_experiments

configure_logging(snakemake.log[0])
run_dir = Path(snakemake.input[0]).parent
result = json.loads(Path(snakemake.input[0]).read_text())
params = snakemake.params.case
material = get_material(params["material"], snakemake.params.materials)
fig = run_picture(run_dir, params["resolution_mm"] * 1e-3, material.T_melt, result)
save_figure(fig, snakemake.output.temperature)

experiments = load_experiments(snakemake.params.experiments)
mode = matching_mode(params, experiments)
measured = None if mode is None else tuple(experiments.loc[mode, ["bead_width_mm", "bead_height_mm"]])
series = run_dir / "timeseries.nc"
ts = xr.load_dataset(series) if series.exists() else None
fig = section_figure(ts, params["resolution_mm"], result, measured, mode)
save_figure(fig, snakemake.output.section)
