"""Uncertainty bands of the reduced model for the measured modes (beadsim.uncertainty)."""

import pandas as pd

from beadsim.io import atomic_path, save_figure
from beadsim.logs import configure_logging
from beadsim.plots import uncertainty_plot
from beadsim.study import case_params, design, load_experiments
from beadsim.uncertainty import DEFAULT_RANGES, run_sample, bands, propagate

configure_logging(snakemake.log[0])
options = snakemake.params.options or {}
experiments = load_experiments(snakemake.input.experiments)
modes = options.get("modes") or list(experiments.index)
cases = design({"base": snakemake.params.base, "sweep": [{"cases": [{"experiment": m} for m in modes]}]},
               experiments)
all_samples, tables = [], []
for run_id, mode in zip(cases.index, modes):
    params = case_params(cases, run_id) | {"model": "reduced"}
    samples = propagate(params, int(options.get("samples", 32)), int(options.get("seed", 0)),
                        options.get("ranges", DEFAULT_RANGES), snakemake.input.materials, workers=snakemake.threads)
    nominal = run_sample((params, {}, snakemake.input.materials))
    tables.append(bands(samples, experiments.loc[mode], nominal).assign(mode=mode))
    all_samples.append(samples.assign(mode=mode))
table = pd.concat(tables, ignore_index=True)
for frame, path in ((pd.concat(all_samples, ignore_index=True), snakemake.output.samples), (table,
                                                                                            snakemake.output.table)):
    with atomic_path(path) as tmp:
        frame.to_csv(tmp, index=False)
save_figure(uncertainty_plot(table), snakemake.output.figure)
