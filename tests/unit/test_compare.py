"""Measured-bead mass balance and the error table."""

import math

import pandas as pd
import pytest

from beadsim.compare import measured_mass_balance, wire_supply_area
from beadsim.reduced import cap_area


def test_cap_area_semicircle_and_shallow_limit():
    assert cap_area(2.0, 1.0) == pytest.approx(math.pi / 2)
    # A shallow cap tends to a parabola, 2/3 w h.
    assert cap_area(4.0, 0.01) == pytest.approx(2 / 3 * 4.0 * 0.01, rel=1e-4)


def test_table1_mass_balance(experiments):
    """Mode 1 holds the metal the wire fed; modes 2 and 3 hold 50-75 % of it (the paper's data)."""
    mb = measured_mass_balance(experiments).set_index("mode")
    assert mb.loc[1, "wire_supply_area_mm2"] == pytest.approx(wire_supply_area(1.2, 10, 5))
    assert mb.loc[1, "consistent"]
    assert 0.95 < mb.loc[1, "ratio_cap"] < 1.1
    assert not mb.loc[2, "consistent"] and not mb.loc[3, "consistent"]
    assert mb.loc[2, "ratio_cap"] == pytest.approx(0.75, abs=0.02)
    assert mb.loc[3, "ratio_cap"] == pytest.approx(0.51, abs=0.02)
    # A 3.6 mm wide cap must be ~1.29 mm tall to hold the fed 3.39 mm2.
    assert cap_area(3.6, mb.loc[2, "height_if_width_right_mm"]) == pytest.approx(3.393, rel=1e-3)


def test_error_table_gives_the_run_means_beside_the_last_sections(experiments):
    """An SPH window run is compared by its last sections' mean profile and by the run means of its sections
    (over the humps); a run without run means (the reduced model) gets NaN there, not a made-up value."""
    import numpy as np
    import xarray as xr

    from beadsim.compare import error_table
    from beadsim.study import EXPERIMENT_PARAMS

    mode1 = experiments.loc[1]
    cases = ["sph_run", "reduced_run"]
    data = {k: ("case", [mode1[k]] * 2) for k in EXPERIMENT_PARAMS}
    data.update(model=("case", ["sph", "reduced"]), resolution_mm=("case", [0.4, np.nan]),
                status=("case", ["ok", "ok"]), bead_width_mm=("case", [3.63, 3.3]),
                bead_height_mm=("case", [0.9, 1.1]), bead_width_run_mean_mm=("case", [3.135, np.nan]),
                bead_height_run_mean_mm=("case", [0.8, np.nan]), bead_width_run_sd_mm=("case", [0.6, np.nan]),
                bead_height_run_sd_mm=("case", [0.2, np.nan]), bead_height_mass_mm=("case", [0.98, np.nan]),
                bead_height_mass_run_mean_mm=("case", [0.93, np.nan]),
                bead_height_mass_run_sd_mm=("case", [0.4, np.nan]), bead_width_mass_mm=("case", [3.9, np.nan]),
                bead_width_mass_run_mean_mm=("case", [3.8, np.nan]),
                bead_width_mass_run_sd_mm=("case", [0.7, np.nan]))
    ds = xr.Dataset(data, coords={"case": cases})
    t = error_table(ds, experiments).set_index("run_id")
    w, h = mode1["bead_width_mm"], mode1["bead_height_mm"]
    assert t.loc["sph_run", "width_err_rel"] == pytest.approx((3.63 - w) / w)
    assert t.loc["sph_run", "width_run_mean_mm"] == pytest.approx(3.135)
    assert t.loc["sph_run", "width_run_mean_err_rel"] == pytest.approx((3.135 - w) / w)
    assert t.loc["sph_run", "height_run_mean_err_rel"] == pytest.approx((0.8 - h) / h)
    assert t.loc["sph_run", "width_run_sd_mm"] == pytest.approx(0.6)
    assert np.isnan(t.loc["reduced_run", "height_run_sd_mm"])
    # the parity plot draws the run means with their spread beside the last sections' bead
    from beadsim.plots import parity_plot

    fig = parity_plot(t.reset_index(), measured_mass_balance(experiments))
    for ax, q, sd in zip(fig.axes, ("width", "height"), (0.6, 0.2)):
        labels = ax.get_legend_handles_labels()[1]
        assert sum("run mean" in lab for lab in labels) == 1
        assert ax.get_ylim()[1] >= t.loc["sph_run", f"{q}_run_mean_mm"] + sd
    assert np.isnan(t.loc["reduced_run", "width_run_mean_mm"]) and np.isnan(t.loc["reduced_run",
                                                                                  "height_run_mean_err_rel"])
    # like with like: the SPH run carries what its measure reads for Table 1's bead at its spacing (dx 0.4: a
    # 1.0 mm cap stacked on the plate's layers reads two layers, 0.8 mm); the reduced model has no particles
    assert t.loc["sph_run", "height_lattice_registered_mm"] == pytest.approx(0.8)
    assert t.loc["sph_run", "width_lattice_lo_mm"] <= t.loc["sph_run", "width_lattice_random_mm"] < w
    assert t.loc["reduced_run", ["width_lattice_random_mm", "height_lattice_hi_mm"]].isna().all()
    # the height from the mass per column, against Table 1
    assert t.loc["sph_run", "height_mass_run_mean_err_rel"] == pytest.approx((0.93 - h) / h)
    assert t.loc["sph_run", "height_mass_err_rel"] == pytest.approx((0.98 - h) / h)
    assert t.loc["reduced_run", ["height_mass_pred_mm", "height_mass_run_mean_mm"]].isna().all()
    # and the width from it
    assert t.loc["sph_run", "width_mass_err_rel"] == pytest.approx((3.9 - w) / w)
    assert t.loc["sph_run", "width_mass_run_mean_err_rel"] == pytest.approx((3.8 - w) / w)
    assert t.loc["sph_run", "width_mass_run_sd_mm"] == pytest.approx(0.7)
    assert t.loc["reduced_run", ["width_mass_pred_mm", "width_mass_run_mean_mm"]].isna().all()
    for ax, top in zip(fig.axes, (3.8 + 0.7, 0.93 + 0.4)):
        assert sum("from the mass per column" in lab for lab in ax.get_legend_handles_labels()[1]) == 1
        assert ax.get_ylim()[1] >= top
    # one legend for both panels, below them, each entry once
    assert len(fig.legends) == 1 and all(ax.get_legend() is None for ax in fig.axes)
    texts = [t.get_text() for t in fig.legends[0].get_texts()]
    assert len(texts) == len(set(texts)) and sum("from the mass per column" in t for t in texts) == 1
    for ax in fig.axes:  # one band per SPH spacing
        assert sum("read by the measure" in lab for lab in ax.get_legend_handles_labels()[1]) == 1
    # a dataset of reduced runs only has no run-mean variables at all
    t = error_table(ds.drop_vars(["bead_width_run_mean_mm", "bead_height_run_mean_mm", "bead_width_run_sd_mm",
                                  "bead_height_run_sd_mm", "bead_height_mass_mm", "bead_height_mass_run_mean_mm",
                                  "bead_height_mass_run_sd_mm", "bead_width_mass_mm", "bead_width_mass_run_mean_mm",
                                  "bead_width_mass_run_sd_mm"]), experiments)
    assert t["width_run_mean_mm"].isna().all() and t["height_run_sd_mm"].isna().all() and len(t) == 2
    fig = parity_plot(t, measured_mass_balance(experiments))
    assert not any("run mean" in lab for ax in fig.axes for lab in ax.get_legend_handles_labels()[1])
    assert t["height_mass_run_mean_mm"].isna().all() and t["width_mass_run_mean_mm"].isna().all()


def test_the_papers_own_sph_estimates_beside_the_measured_beads(experiments):
    """Table 1 gives the paper's SPH estimate of each bead; its error column says 4 / 3 / 3 % in height, its
    numbers differ from the measured heights by 13 / 10 / 14 %. The comparison carries them, and the parity
    plot draws them (one star per mode and panel, at the measured value)."""
    from beadsim.plots import parity_plot

    mb = measured_mass_balance(experiments).set_index("mode")
    assert mb.loc[1, "paper_sph_width_mm"] == pytest.approx(3.45)
    assert mb.loc[1, "paper_sph_width_err_rel"] == pytest.approx(0.15 / 3.3)
    assert list(mb["paper_sph_height_err_rel"].round(3)) == pytest.approx([-0.13, -0.1, -0.143])
    # as caps, the estimated beads hold what the measured ones hold, not the wire's supply
    assert list(mb["paper_sph_ratio_cap"].round(2)) == pytest.approx([0.93, 0.68, 0.46])
    assert mb.loc[1, "paper_sph_ratio_cap"] == pytest.approx(cap_area(3.45, 0.87) / wire_supply_area(1.2, 10, 5))
    fig = parity_plot(pd.DataFrame(columns=["model", "resolution_mm", "status", "mode"]), mb.reset_index())
    for ax, q in zip(fig.axes, ("width", "height")):
        stars = [ln for ln in ax.get_lines() if ln.get_marker() == "*"]
        assert len(stars) == 1
        assert list(stars[0].get_xdata()) == list(mb[f"measured_{q}_mm"])
        assert list(stars[0].get_ydata()) == list(mb[f"paper_sph_{q}_mm"])
    # an experiments table without the estimates: no columns made up, no stars
    plain = measured_mass_balance(experiments.drop(columns=["paper_sph_width_mm", "paper_sph_height_mm"]))
    assert plain["paper_sph_height_mm"].isna().all()
    fig = parity_plot(pd.DataFrame(columns=["model", "resolution_mm", "status", "mode"]), plain)
    assert not any(ln.get_marker() == "*" for ax in fig.axes for ln in ax.get_lines())
