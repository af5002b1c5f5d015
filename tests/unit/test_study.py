"""Sweep expansion, run ids and config errors."""

import numpy as np
import pytest

from beadsim.errors import ConfigError
from beadsim.study import design, latin_hypercube


def test_grid_zip_cases_multiply(experiments):
    cfg = {"study": "t", "sweep": [{
        "cases": [{"experiment": 1}, {"experiment": 2}],
        "grid": {"resolution_mm": [0.4, 0.3], "wire_angle_deg": [30, 45, 60]},
        "zip": {"beam_power_W": [900, 1000], "wire_feed_mm_s": [8, 10]},
    }]}
    df = design(cfg, experiments)
    assert len(df) == 2 * 6 * 2
    assert df.index.is_unique
    # cases fill in Table 4; the zip keeps pairs together.
    assert set(df["material"]) == {"Ti-Gr2", "308LSi"}
    assert set(zip(df["beam_power_W"], df["wire_feed_mm_s"])) == {(900, 8), (1000, 10)}
    assert "mode1_P900_Vw8_alpha30_dx0.4" in df.index


def test_union_of_blocks_and_readable_ids(experiments):
    cfg = {"study": "t", "sweep": [{"cases": [{"experiment": 3}]},
                                   {"grid": {"beam_power_W": [800, 1200]}}]}
    df = design(cfg, experiments)
    assert list(df.index) == ["mode3", "P800", "P1200"]
    assert df.loc["mode3", "scan_diameter_mm"] == 3
    assert df.loc["P800", "material"] == "Ti-Gr2"  # defaults fill the rest


def test_ids_are_stable(experiments):
    cfg = {"study": "t", "sweep": [{"lhs": {"samples": 5, "seed": 7, "ranges": {"beam_power_W": [800, 1500]}}}]}
    assert list(design(cfg, experiments).index) == list(design(cfg, experiments).index)


def test_latin_hypercube_one_point_per_stratum():
    pts = latin_hypercube({"a": [0.0, 10.0], "b": [100.0, 200.0]}, samples=20, seed=3)
    for key, (lo, hi) in {"a": (0, 10), "b": (100, 200)}.items():
        strata = np.floor((np.array([p[key] for p in pts]) - lo) / (hi - lo) * 20).astype(int)
        assert sorted(strata) == list(range(20))
    assert pts != latin_hypercube({"a": [0.0, 10.0], "b": [100.0, 200.0]}, samples=20, seed=4)


@pytest.mark.parametrize("cfg, message", [
    ({"base": {"beam_power": 1000}}, "base: unknown parameter 'beam_power'; allowed: model, material"),
    ({"base": {"material": "Al"}}, "base.material: 'Al' is not allowed; allowed values: ['Ti-Gr2', '308LSi']"),
    ({"sweep": [{"grid": {"beam_power_W": [-5]}}]}, "sweep[0].grid.beam_power_W: -5 must be greater than 0 W"),
    ({"sweep": [{"zip": {"beam_power_W": [1, 2], "wire_feed_mm_s": [3]}}]},
     "sweep[0].zip: all lists must have the same length"),
    ({"sweep": [{"cases": [{"experiment": 9}]}]}, "sweep[0].cases[0].experiment: no mode 9"),
    ({"sweep": [{"lhs": {"samples": 3, "ranges": {"beam_power_W": [900, 800]}}}]},
     "sweep[0].lhs.ranges.beam_power_W: give [low, high] with low < high"),
    ({"sweep": [{"lhs": {"samples": 3, "ranges": {"material": ["a", "b"]}}}]},
     "Latin hypercube ranges need a numeric parameter"),
    ({"sweep": [{"grid": {"beam_power_W": [900]}}, {"grid": {"beam_power_W": [900]}}]},
     "appear more than once"),
])
def test_config_errors_name_the_key(cfg, message, experiments):
    with pytest.raises(ConfigError, match=None) as err:
        design({"study": "t", **cfg}, experiments)
    assert message in str(err.value)
