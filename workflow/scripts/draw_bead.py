"""Temperature pictures (top view, sections, melt pool outline) of an SPH run's last particle dump."""

import json
from pathlib import Path

from beadsim.io import save_figure
from beadsim.logs import configure_logging
from beadsim.materials import get_material
from beadsim.sph.pictures import run_picture

configure_logging(snakemake.log[0])
result = json.loads(Path(snakemake.input[0]).read_text())
params = snakemake.params.case
material = get_material(params["material"], snakemake.params.materials)
fig = run_picture(Path(snakemake.input[0]).parent, params["resolution_mm"] * 1e-3, material.T_melt, result)
save_figure(fig, snakemake.output[0])
