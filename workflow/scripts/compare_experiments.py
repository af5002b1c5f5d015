"""Compare the study's runs with the measured beads (Table 1) and check the beads' own mass balance."""

import xarray as xr

from beadsim.compare import error_table, measured_mass_balance
from beadsim.io import atomic_path, save_figure
from beadsim.logs import configure_logging
from beadsim.plots import parity_plot
from beadsim.study import load_experiments

configure_logging(snakemake.log[0])
ds = xr.load_dataset(snakemake.input.dataset)
exp = load_experiments(snakemake.input.experiments)
errors = error_table(ds, exp)
balance = measured_mass_balance(exp)
for df, path in ((errors, snakemake.output.errors), (balance, snakemake.output.mass_balance)):
    with atomic_path(path) as tmp:
        df.to_csv(tmp, index=False)
save_figure(parity_plot(errors, balance), snakemake.output.parity)
