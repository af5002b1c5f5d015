"""Dataset built from real reduced-model runs: units, provenance, failed runs, gridded view, netCDF round trip."""

import json

import numpy as np
import xarray as xr

from beadsim.dataset import build_dataset, gridded
from beadsim.io import write_netcdf
from beadsim.runner import run_case
from beadsim.study import case_params, design


def test_dataset_from_real_runs(tmp_path, experiments):
    cfg = {"study": "t", "sweep": [{"grid": {"beam_power_W": [800, 1200], "substrate_speed_mm_s": [4, 6]}}]}
    table = design(cfg, experiments)
    results = []
    for run_id in table.index:
        out = tmp_path / run_id
        run_case(case_params(table, run_id), out, run_id=run_id)
        results.append(out / "result.json")
    # One run that cannot complete: its record says so and stays in the dataset.
    bad = json.loads(results[0].read_text())
    bad.update(status="failed", reason="watchdog: test", metrics={})
    results[0].write_text(json.dumps(bad))

    ds = build_dataset(results, None, cfg, table)
    path = tmp_path / "dataset.nc"
    write_netcdf(ds, path)
    back = xr.load_dataset(path, engine="netcdf4")

    assert back["bead_width_mm"].attrs == {"units": "mm", "long_name": "bead width"}
    assert back["beam_power_W"].attrs["units"] == "W"
    assert back.attrs["git_commit"] and back.attrs["config_digest"] and back.attrs["beadsim_version"]
    assert list(back["status"].values) == ["failed", "ok", "ok", "ok"]
    assert back["reason"].values[0] == "watchdog: test"
    assert np.isnan(back["bead_width_mm"].values[0])
    assert np.all(back["bead_width_mm"].values[1:] > 0)
    # Faster travel, same power -> narrower pool (a physical check on the aggregated numbers).
    w4, w6 = (float(back["pool_width_mm"].sel(case=c)) for c in ("P1200_Vs4", "P1200_Vs6"))
    assert w6 < w4

    grid = gridded(back)
    assert grid is not None and dict(grid.sizes) == {"beam_power_W": 2, "substrate_speed_mm_s": 2}
    assert grid["bead_width_mm"].sel(beam_power_W=1200, substrate_speed_mm_s=6) == \
        back["bead_width_mm"].sel(case="P1200_Vs6")


def test_gridded_view_of_a_single_axis(tmp_path, experiments):
    cfg = {"study": "t", "sweep": [{"grid": {"beam_power_W": [900, 1100]}}]}
    table = design(cfg, experiments)
    results = []
    for run_id in table.index:
        run_case(case_params(table, run_id), tmp_path / run_id, run_id=run_id)
        results.append(tmp_path / run_id / "result.json")
    grid = gridded(build_dataset(results, None, cfg, table))
    assert list(grid.dims) == ["beam_power_W"] and grid["beam_power_W"].attrs["units"] == "W"
    assert grid["pool_width_mm"].sel(beam_power_W=1100) > grid["pool_width_mm"].sel(beam_power_W=900)
