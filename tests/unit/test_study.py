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


SPH_WINDOW = {"model": "sph", "domain": "window", "sim_time_s": 1.0}


def test_continue_from_names_a_shorter_run_of_the_same_scene(experiments):
    """A continuation may run longer and change the steady-state stop; a source that is not there, is itself,
    is another scene, is not shorter, or cannot be continued (reduced model, a block sized from sim_time_s)
    stops the study with the run, the key and what is allowed named."""
    ok = {"study": "t", "base": SPH_WINDOW, "sweep": [{"cases": [
        {"name": "a"}, {"name": "b", "sim_time_s": 2.0, "stop_at_steady_state": True, "continue_from": "a"},
        {"name": "c", "sim_time_s": 3.0, "continue_from": "b"}]}]}
    df = design(ok, experiments)
    assert df["continue_from"].to_dict() == {"a": "", "b": "a", "c": "b"}

    def fails(cases, base=SPH_WINDOW):
        with pytest.raises(ConfigError) as err:
            design({"study": "t", "base": base, "sweep": [{"cases": cases}]}, experiments)
        return str(err.value)

    text = fails([{"name": "a"}, {"name": "b", "sim_time_s": 2.0, "continue_from": "x"}])
    assert "run 'b': continue_from: 'x' is not another run of this study; allowed: ['a']" in text
    assert "not another run" in fails([{"name": "a", "continue_from": "a"}])
    text = fails([{"name": "a"}, {"name": "b", "sim_time_s": 2.0, "beam_power_W": 900, "continue_from": "a"}])
    assert "'a' is another scene (beam_power_W 1000.0 there, 900" in text and "change only sim_time_s" in text
    assert "nothing to continue" in fails([{"name": "a"}, {"name": "b", "continue_from": "a"}])
    assert "needs domain window or plate" in fails([{"name": "a"}, {"name": "b", "sim_time_s": 2.0,
                                                                    "continue_from": "a"}], {**SPH_WINDOW, "domain": "auto"})
    assert "only SPH runs" in fails([{"name": "a"}, {"name": "b", "sim_time_s": 2.0, "continue_from": "a"}],
                                    {**SPH_WINDOW, "model": "reduced"})
