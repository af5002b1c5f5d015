"""Process-map helpers on a constructed 3-D grid: the slice shown, the measured modes overlaid, main effects."""

import itertools

import matplotlib.pyplot as plt
import numpy as np
import pandas as pd
import pytest
import xarray as xr

from beadsim.plots import fixed_values, main_block, main_effects_plot, process_maps

POWERS, SPEEDS, FEEDS = [800.0, 1000.0, 1200.0], [3.0, 5.0, 7.0], [5.0, 10.0, 15.0]


def width(p, vs, vw):
    return 1e-3 * p + 0.1 * vw - 0.2 * vs


@pytest.fixture
def grid3():
    cases = list(itertools.product(POWERS, SPEEDS, FEEDS))
    p, vs, vw = (np.array(c) for c in zip(*cases))
    coords = {"beam_power_W": ("case", p), "substrate_speed_mm_s": ("case", vs), "wire_feed_mm_s": ("case", vw)}
    ds = xr.Dataset({"bead_width_mm": ("case", width(p, vs, vw)),
                     "bead_height_mm": ("case", 0.05 * vw),
                     "status": ("case", np.array(["ok"] * len(cases), dtype=object)),
                     "regime": ("case", np.array(["ok"] * len(cases), dtype=object))},
                    coords={"case": [f"c{i}" for i in range(len(cases))], **coords})
    ds["status"].values[0] = "failed"  # P 800, Vs 3, Vw 5: left out of the means
    return ds


def test_grid_slice_is_the_middle_level_of_the_other_axes(grid3):
    shown = main_block(grid3, ["beam_power_W", "substrate_speed_mm_s"])
    assert shown.sizes["case"] == 9
    assert set(shown["wire_feed_mm_s"].values) == {10.0}
    assert fixed_values(shown, grid3, ["beam_power_W", "substrate_speed_mm_s"]) == {"wire_feed_mm_s": 10.0}


def test_measured_mode_is_drawn_between_heat_map_cells(grid3):
    experiments = pd.DataFrame({"beam_power_W": [900.0, 5000.0], "substrate_speed_mm_s": [5.0, 5.0]},
                               index=pd.Index([1, 2], name="mode"))
    fig = process_maps(grid3, "beam_power_W", "substrate_speed_mm_s", map_metrics=["bead_width_mm"],
                       experiments=experiments)
    ax = fig.axes[0]  # the third axis (wire feed) is the facet: one panel per feed
    stars = [line for line in ax.lines if line.get_marker() == "*"]
    assert len(stars) == 1  # mode 2 lies outside the map
    assert sum(line.get_marker() == "*" for a in fig.axes for line in a.lines) == 3  # no feed given: every panel
    # 900 W is halfway between the first two columns (centres 0.5, 1.5); 5 mm/s is the middle row (centre 1.5)
    assert stars[0].get_xdata()[0] == pytest.approx(1.0)
    assert stars[0].get_ydata()[0] == pytest.approx(1.5)
    plt.close(fig)


def test_main_effects_are_level_means_of_successful_runs(grid3):
    fig = main_effects_plot(grid3, ["bead_width_mm", "regime"])
    axes = np.array(fig.axes).reshape(1, 3)
    line = [ln for ln in axes[0, 2].lines if ln.get_marker() == "o"][0]  # width against wire feed
    assert list(line.get_xdata()) == FEEDS
    ok = [(p, vs, vw) for p, vs, vw in itertools.product(POWERS, SPEEDS, FEEDS) if (p, vs, vw) != (800, 3, 5)]
    expected = [np.mean([width(*c) for c in ok if c[2] == f]) for f in FEEDS]
    np.testing.assert_allclose(line.get_ydata(), expected, rtol=1e-12)
    plt.close(fig)


def test_a_measured_mode_on_a_grid_level_does_not_hide_the_other_levels(grid3):
    extra = grid3.isel(case=[13]).assign_coords(case=["mode1"])  # P 1000, Vs 5, Vw 10: on the grid
    both = xr.concat([grid3, extra], dim="case")
    shown = main_block(both, ["beam_power_W", "substrate_speed_mm_s"])
    assert sorted(set(shown["beam_power_W"].values)) == POWERS
    assert shown.sizes["case"] == 10 and set(shown["wire_feed_mm_s"].values) == {10.0}
    fig = process_maps(both, "beam_power_W", "substrate_speed_mm_s", "wire_feed_mm_s", ["bead_width_mm"])
    assert len(fig.axes[0].collections) == 1  # still a heat map: the repeated point is averaged into its cell
    plt.close(fig)


def test_section_figure_draws_the_run_against_the_measured_cap():
    """The bead cross-section picture: the measured bead as the circular cap of its width and height (outline
    through the toes and the apex, area as the comparison's cap), the run's two profiles with their areas, and
    a note instead of a plot for a run without a section."""
    from beadsim.reduced import cap_area
    from beadsim.sph.pictures import cap_outline, section_figure

    yc, zc = cap_outline(3.3, 1.0, n=2001)
    assert (yc[0], yc[-1]) == (-1.65, 1.65) and zc[[0, -1]] == pytest.approx(0.0, abs=1e-12)
    assert zc.max() == pytest.approx(1.0, rel=1e-6)
    assert np.trapezoid(zc, yc) == pytest.approx(cap_area(3.3, 1.0), rel=1e-4)
    dx = 0.4
    y = np.arange(-12, 13) * dx
    h_map = np.clip(0.8 * (1 - (y / 1.6) ** 2), 0, None)
    ts = xr.Dataset({"section_height_map_mm": ("y_section", h_map),
                     "section_height_mass_mm": ("y_section", 1.1 * h_map)}, coords={"y_section": y})
    result = {"run_id": "m1", "status": "ok", "metrics": {"bead_width_mm": 3.2, "bead_height_mm": 0.8,
                                                          "bead_height_mass_mm": None}}
    fig = section_figure(ts, dx, result, (3.3, 1.0), 1)
    ax = fig.axes[0]
    labels = [t.get_text() for t in ax.get_legend().get_texts()]
    assert labels[0].endswith(f"{np.sum(h_map) * dx:.2f} mm2 above the plate")
    assert labels[1].endswith(f"{1.1 * np.sum(h_map) * dx:.2f} mm2") and "3.3 x 1 mm" in labels[2]
    assert "Table 1 mode 1" in ax.get_title() and "3.20 x 0.80 mm" in ax.get_title()
    assert ax.get_xlim()[1] >= 1.65 and ax.get_ylim()[1] > 1.0
    assert not any("plate surface melted" in label for label in labels)  # no width recorded: no bar
    plt.close(fig)
    result["metrics"]["plate_fusion_width_mm"] = 2.6  # the plate melted narrower than the metal lies
    fig = section_figure(ts, dx, result, (3.3, 1.0), 1)
    bars = [line for line in fig.axes[0].get_lines() if line.get_label().startswith("plate surface melted, 2.60 mm")]
    assert len(bars) == 1 and list(bars[0].get_xdata()) == [-1.3, 1.3] and list(bars[0].get_ydata()) == [0, 0]
    plt.close(fig)
    failed = section_figure(None, dx, {"run_id": "m2", "status": "failed", "reason": "NaN at t=0.1"})
    assert "no bead cross-section" in failed.axes[0].texts[0].get_text()
    plt.close(failed)
