"""Leave-one-out calibration of one parameter against Table 1."""

import xarray as xr

from beadsim.analysis import loo_calibration, response_curves
from beadsim.io import atomic_path, save_figure, write_json
from beadsim.logs import configure_logging
from beadsim.plots import calibration_plot
from beadsim.study import load_experiments

configure_logging(snakemake.log[0])
ds = xr.load_dataset(snakemake.input.dataset)
exp = load_experiments(snakemake.input.experiments)
parameter, width = snakemake.params.parameter, snakemake.params.width_metric
table, summary = loo_calibration(ds, exp, parameter, width_metric=width)
with atomic_path(snakemake.output.table) as tmp:
    table.to_csv(tmp, index=False)
write_json(snakemake.output.summary, summary)
label = ds[width].attrs.get("long_name", width)
save_figure(calibration_plot(response_curves(ds, exp, parameter, width), table, exp, parameter, ds[parameter].attrs,
                             width_label=label), snakemake.output.figure)
