"""Process maps of the study's metrics over its swept parameters (measured modes overlaid), and main effects."""

import xarray as xr

from beadsim.io import save_figure
from beadsim.logs import configure_logging
from beadsim.plots import main_effects_plot, process_maps
from beadsim.study import load_experiments

configure_logging(snakemake.log[0])
ds = xr.load_dataset(snakemake.input.dataset)
options = snakemake.params.options
experiments = load_experiments(snakemake.input.experiments)
save_figure(process_maps(ds, **options, experiments=experiments), snakemake.output.maps)
save_figure(main_effects_plot(ds, options.get("map_metrics")), snakemake.output.effects)
