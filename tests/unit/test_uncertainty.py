"""Uncertainty bands of the reduced model (beadsim.uncertainty): sampling, quantiles, drivers, real model runs."""

import numpy as np
import pandas as pd
import yaml

from beadsim.materials import DEFAULT_FILE
from beadsim.parameters import defaults
from beadsim.study import load_experiments
from beadsim.uncertainty import bands, material_ranges, propagate


def test_material_ranges_are_read_by_field_name():
    ranges = material_ranges("Ti-Gr2")
    assert ranges["k"] == (16.0, 30.0)
    assert ranges["contact_angle_deg"] == (40.0, 80.0)
    assert "rho" not in ranges  # no range given: not sampled


def test_bands_quantiles_driver_and_measured_flag():
    rng = np.random.default_rng(3)
    n = 201
    eta = np.linspace(0.7, 0.95, n)
    noise = rng.permutation(n) / n
    samples = pd.DataFrame({"param.beam_efficiency": eta, "material.k": noise,
                            "bead_width_mm": 10 * eta, "bead_height_mm": 1 - noise,
                            "pool_length_mm": np.nan, "penetration_depth_mm": eta})
    exp = pd.Series({"bead_width_mm": 9.6, "bead_width_unc_mm": 0.1, "bead_height_mm": 2.0,
                     "bead_height_unc_mm": 0.1})
    table = bands(samples, exp).set_index("metric")
    width = table.loc["bead_width_mm"]
    assert width["p05"] == np.quantile(10 * eta, 0.05) and width["p95"] == np.quantile(10 * eta, 0.95)
    assert width["driver"] == "param.beam_efficiency" and width["driver_spearman"] > 0.999
    assert not width["measured_in_band"]  # 9.6 > p95 9.375 + 0.1
    assert table.loc["bead_height_mm", "driver"] == "material.k"
    assert table.loc["bead_height_mm", "driver_spearman"] < -0.999
    assert table.loc["pool_length_mm", "samples_ok"] == 0


def test_reduced_model_width_grows_with_beam_efficiency(tmp_path):
    """Real reduced-model runs: with only the efficiency uncertain (a materials file without ranges), the
    Latin hypercube puts one draw in each stratum and the melted width rises with the absorbed power."""
    table = yaml.safe_load(DEFAULT_FILE.read_text())
    for entry in table.values():
        for prop in entry.values():
            if isinstance(prop, dict):
                prop.pop("range", None)
    materials = tmp_path / "materials.yaml"
    materials.write_text(yaml.safe_dump(table))
    params = defaults() | {k: v for k, v in load_experiments().loc[1].items() if k in defaults()}
    params["resolution_mm"] = 0.6  # the reduced grid uses dx/4: coarse is enough here
    samples = propagate(params, samples=4, seed=2, ranges={"beam_efficiency": [0.6, 1.0]},
                        materials_file=materials)
    assert list(samples.columns[:2]) == ["sample", "param.beam_efficiency"]
    strata = np.floor((samples["param.beam_efficiency"] - 0.6) / 0.1).astype(int)
    assert sorted(strata) == [0, 1, 2, 3]
    ordered = samples.sort_values("param.beam_efficiency")
    assert np.all(np.diff(ordered["penetration_depth_mm"]) > 0)
    assert np.all(np.diff(ordered["bead_width_mm"]) >= 0)


def test_uncertainty_plot_draws_every_band_with_one_legend_below():
    import matplotlib.pyplot as plt

    from beadsim.plots import uncertainty_plot

    table = pd.DataFrame({"metric": ["bead_width_mm"] * 2 + ["bead_height_mm"] * 2, "mode": [1, 2, 1, 2],
                          "p05": [3.0, 4.0, 0.6, 0.9], "p50": [3.5, 4.5, 0.7, 1.0], "p95": [4.0, 5.0, 0.8, 1.1],
                          "nominal": [3.6, 4.4, 0.72, 1.05], "measured": [3.3, 3.6, 1.0, 0.7],
                          "measured_unc": [0.1] * 4})
    fig = uncertainty_plot(table)
    assert len(fig.legends) == 1 and all(ax.get_legend() is None for ax in fig.axes)
    assert [t.get_text() for t in fig.legends[0].get_texts()] == ["5-95 % band", "median", "nominal inputs",
                                                                  "Table 1"]
    for ax, (lo, hi) in zip(fig.axes, ((3.0, 5.0), (0.6, 1.1))):
        assert ax.get_ylim()[0] <= lo - 1e-9 and ax.get_ylim()[1] >= hi + 1e-9
    plt.close(fig)
