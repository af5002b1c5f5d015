"""Particles followed through a run's dumps (beadsim.sph.tracks), on synthetic histories and snapshots."""

import numpy as np
import pytest

from beadsim.sph import tracks
from beadsim.sph.scene import TYPE_FALLING, TYPE_LIQUID, TYPE_RESOLIDIFIED, TYPE_SUBSTRATE


def _history(r):
    """Rows (t, x, y, z) every 0.05 s with y = r (m)."""
    r = np.asarray(r, dtype=float)
    t = 0.05 * np.arange(len(r))
    return np.column_stack([t, np.zeros_like(r), r, np.full_like(r, 2e-4)])


def test_an_even_creep_and_a_spurt_read_apart():
    """1 mm outward in 10 even steps: a tenth in the largest step, half done at half the time liquid; the same
    travel in one step at the start: all of it in the largest step, half done after the first interval."""
    even = tracks.path_figures(_history(np.linspace(0.4e-3, 1.4e-3, 11)))
    assert even["travel"] == pytest.approx(1e-3)
    assert even["largest_step_share"] == pytest.approx(0.1)
    assert even["half_travel_at"] == pytest.approx(0.5)
    assert even["liquid_s"] == pytest.approx(0.5)
    spurt = tracks.path_figures(_history([0.4e-3] + [1.4e-3] * 10))
    assert spurt["largest_step_share"] == pytest.approx(1.0)
    assert spurt["half_travel_at"] == pytest.approx(0.1)
    # towards the axis from the other side: |y| is the distance from it
    inward = tracks.path_figures(_history(-np.linspace(1.4e-3, 0.4e-3, 11)))
    assert inward["travel"] == pytest.approx(-1e-3) and np.isnan(inward["largest_step_share"])
    # jitter below MIN_TRAVEL is not split into steps
    still = tracks.path_figures(_history([0.4e-3, 0.45e-3, 0.42e-3, 0.5e-3]))
    assert np.isnan(still["largest_step_share"]) and np.isnan(still["half_travel_at"])


def test_liquid_histories_follow_ids_over_the_dumps_they_were_fluid_in():
    def snap(types, ys):
        n = len(types)
        return {"id": np.arange(1, n + 1, dtype=float), "type": np.array(types, dtype=float),
                "x": np.zeros(n), "y": np.array(ys), "z": np.zeros(n)}

    snaps = [(0.0, snap([TYPE_LIQUID, TYPE_SUBSTRATE, TYPE_FALLING], [1.0, 2.0, 3.0])),
             (0.05, snap([TYPE_LIQUID, TYPE_LIQUID, TYPE_RESOLIDIFIED], [1.5, 2.5, 3.5])),
             (0.10, snap([TYPE_RESOLIDIFIED, TYPE_LIQUID, TYPE_RESOLIDIFIED], [1.6, 2.6, 3.6]))]
    h = tracks.liquid_histories(snaps)
    assert sorted(h) == [1, 2, 3]
    np.testing.assert_allclose(h[1][:, [0, 2]], [[0.0, 1.0], [0.05, 1.5]])
    np.testing.assert_allclose(h[2][:, [0, 2]], [[0.05, 2.5], [0.10, 2.6]])
    np.testing.assert_allclose(h[3][:, [0, 2]], [[0.0, 3.0]])  # falling counts as fluid
