"""Calibration with leave-one-out validation (on real reduced runs) and Richardson extrapolation."""

import numpy as np
import pytest

from beadsim.analysis import loo_calibration, richardson
from beadsim.compare import match_experiments
from beadsim.dataset import build_dataset
from beadsim.runner import run_case
from beadsim.study import case_params, design


@pytest.mark.parametrize("p", [1.0, 2.0, 3.0])
def test_richardson_recovers_order_and_limit(p):
    h = np.array([0.2, 0.3, 0.4])  # non-uniform refinement ratios 1.5 and 1.33
    f = 3.3 + 0.7 * h**p
    out = richardson(h, f)
    assert out["order"] == pytest.approx(p, rel=1e-8)
    assert out["extrapolated"] == pytest.approx(3.3, rel=1e-10)
    assert out["monotone"]
    # GCI brackets the true error of the finest value with the 1.25 safety factor.
    true_rel = abs(f[0] - 3.3) / f[0]
    assert out["gci_fine"] == pytest.approx(1.25 * true_rel, rel=1e-8)


def test_richardson_flags_oscillation():
    assert not richardson(np.array([0.2, 0.3, 0.4]), np.array([1.0, 1.1, 1.05]))["monotone"]


@pytest.fixture(scope="module")
def calibration_runs(tmp_path_factory, experiments):
    """Dataset of real reduced runs: the three measured modes at beam efficiency 0.3, 0.6 and 0.9."""
    out = tmp_path_factory.mktemp("cal")
    cfg = {"study": "cal", "sweep": [{"cases": [{"experiment": m} for m in (1, 2, 3)],
                                      "grid": {"beam_efficiency": [0.3, 0.6, 0.9]}}]}
    table = design(cfg, experiments)
    results = []
    for run_id in table.index:
        run_case(case_params(table, run_id), out / run_id, run_id=run_id)
        results.append(out / run_id / "result.json")
    return build_dataset(results, None, cfg, table)


def test_leave_one_out_never_fits_a_mode_to_itself(calibration_runs, experiments):
    ds = calibration_runs
    loo, summary = loo_calibration(ds, experiments, "beam_efficiency")
    assert list(loo["mode"]) == [1, 2, 3]
    for _, row in loo.iterrows():
        assert str(row["mode"]) not in row["fit_on_modes"].split()
        assert 0.3 <= row["beam_efficiency_loo"] <= 0.9
    # Cross-validated errors are never smaller in total than the errors of the fit to all modes.
    assert (loo["width_err_rel_loo"] ** 2).sum() >= (loo["width_err_rel_fit"] ** 2).sum() - 1e-12
    # Width grows with absorbed power, so the calibrated efficiency is where mode 1's width is matched best.
    assert summary["width_rms_err_rel_loo"] < 0.5
    # Another width metric (the SPH model fits its fused width): the predictions follow that metric's curve.
    pool, summary_pool = loo_calibration(ds, experiments, "beam_efficiency", width_metric="pool_width_mm")
    assert summary_pool["width_metric"] == "pool_width_mm"
    index = {str(c): i for i, c in enumerate(ds["case"].values)}
    for _, row in pool.iterrows():
        mine = sorted((index[r] for r, m in match_experiments(ds, experiments).items() if m == row["mode"]),
                      key=lambda i: ds["beam_efficiency"].values[i])
        assert row["width_pred_loo_mm"] == pytest.approx(np.interp(
            row["beam_efficiency_loo"], ds["beam_efficiency"].values[mine], ds["pool_width_mm"].values[mine]))


def test_leave_one_out_searches_each_fit_over_its_own_modes(calibration_runs, experiments):
    """Mode 3 has an ok run at one value only (its others failed, as SPH runs that stub): the fits that use mode 3
    are pinned to that value, the fit that leaves it out searches the whole range, and mode 3 is not predicted
    outside the one value it was run at."""
    ds = calibration_runs
    mode = match_experiments(ds, experiments)
    keep = [i for i, c in enumerate(ds["case"].values)
            if mode[str(c)] != 3 or ds["beam_efficiency"].values[i] == 0.9]
    loo, summary = loo_calibration(ds.isel(case=keep), experiments, "beam_efficiency")
    rows = loo.set_index("mode")
    assert summary["range_searched"] == [0.9, 0.9] and summary["ranges_per_mode"][1] == [0.3, 0.9]
    assert rows.loc[1, "beam_efficiency_loo"] == rows.loc[2, "beam_efficiency_loo"] == 0.9
    full, _ = loo_calibration(ds, experiments, "beam_efficiency")
    assert rows.loc[3, "beam_efficiency_loo"] == full.set_index("mode").loc[3, "beam_efficiency_loo"]
    if rows.loc[3, "beam_efficiency_loo"] != 0.9:
        assert np.isnan(rows.loc[3, "width_pred_loo_mm"])


def test_stability_classes():
    from beadsim.analysis import stability_class

    assert stability_class("failed", np.nan, np.nan, np.nan) == "blown_up"
    assert stability_class("failed", np.nan, np.nan, np.nan, reason="error: KeyError: 'x'") == "error"
    assert stability_class("ok", 0.98, 1.03, 0.01) == "stable"
    assert stability_class("ok", 0.90, 1.03, 0.01) == "degraded"
    assert stability_class("ok", 0.98, 1.03, 0.08) == "degraded"


def test_pareto_front():
    from beadsim.analysis import pareto_front

    cost = np.array([1.0, 2.0, 3.0, 2.5, 10.0, np.nan])
    err = np.array([0.5, 0.2, 0.25, 0.1, 0.1, 0.0])
    assert list(pareto_front(cost, err)) == [True, True, False, True, False, False]


def test_speed_accuracy_against_table1_and_the_finest_run(experiments):
    """Three runs of mode 1 on real reduced-model records with SPH-like labels: the errors against Table 1 and
    against the finest successful run are what the numbers say, and the Pareto flags follow."""
    import xarray as xr

    from beadsim.analysis import speed_accuracy_table

    row = experiments.loc[1]
    n = 4
    ds = xr.Dataset(
        {"bead_width_mm": ("case", [3.3, 3.63, 4.0, np.nan]), "bead_height_mm": ("case", [1.0, 0.9, 0.5, np.nan]),
         "job_wall_time_s": ("case", [100.0, 10.0, 1.0, 5.0]),
         "status": ("case", ["ok", "ok", "ok", "failed"]), "model": ("case", ["sph", "sph", "reduced", "sph"]),
         "resolution_mm": ("case", [0.2, 0.4, 0.3, 0.1])},
        coords={"case": ["fine", "coarse", "red", "bad"]})
    for k in ("material", "beam_power_W", "substrate_speed_mm_s", "wire_feed_mm_s", "wire_diameter_mm",
              "scan_diameter_mm"):
        ds[k] = ("case", [row[k]] * n)
    from beadsim.compare import EXPERIMENT_PARAMS
    for k in EXPERIMENT_PARAMS:
        if k not in ds:
            ds[k] = ("case", [row[k]] * n)
    t = speed_accuracy_table(ds, experiments).set_index("run_id")
    assert t.loc["fine", "error_table1"] == pytest.approx(0.0, abs=1e-12)
    assert t.loc["coarse", "error_table1"] == pytest.approx(0.5 * (0.1 + 0.1))
    assert (t["reference"].iloc[:3] == "fine").all()  # the failed finer run is not the reference
    assert t.loc["red", "error_reference"] == pytest.approx(0.5 * (4.0 / 3.3 - 1 + 0.5))
    assert np.isnan(t.loc["bad", "error_table1"])
    assert list(t["pareto_table1"]) == [True, True, True, False]


def test_model_check_pairs_each_sph_run_with_its_reduced_twin():
    import xarray as xr

    from beadsim.analysis import model_check_table

    ds = xr.Dataset(
        {"bead_width_mm": ("case", [4.0, 5.0, 4.0, 3.0]), "bead_height_mm": ("case", [1.0, 0.8, 0.5, 0.6]),
         "status": ("case", ["ok", "ok", "ok", "failed"]), "regime": ("case", ["ok", "flat_bead", "", ""])},
        coords={"case": ["red_P1000", "red_P1300", "sph_P1300", "sph_P700"],
                "model": ("case", ["reduced", "reduced", "sph", "sph"]),
                "beam_power_W": ("case", [1000.0, 1300.0, 1300.0, 700.0]),
                "resolution_mm": ("case", [0.3, 0.3, 0.4, 0.4])})
    table = model_check_table(ds).set_index("run_id")
    assert table.loc["sph_P1300", "reduced_run_id"] == "red_P1300"  # resolution does not split the pair
    assert table.loc["sph_P1300", "reduced_regime"] == "flat_bead"
    assert table.loc["sph_P1300", "bead_width_mm_rel"] == pytest.approx(5.0 / 4.0 - 1)
    assert table.loc["sph_P1300", "bead_height_mm_rel"] == pytest.approx(0.8 / 0.5 - 1)
    assert table.loc["sph_P700", "reduced_run_id"] == "" and np.isnan(table.loc["sph_P700", "bead_width_mm_reduced"])
    assert "pool_length_mm_sph" not in table  # metrics absent from the dataset are skipped
