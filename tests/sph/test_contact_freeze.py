"""``contact_freeze``: melt touching cold plate is held still.

A melt particle that touches plate that never melted (type substrate, within 1.25 dx) at a contact temperature, the
mean of the pair's two temperatures, below the melting point is held still, moving with the plate, over the next
chunk; it keeps its type (liquid) and its energy. Checked on a short real bead against a brute-force evaluation of
the rule on the gathered particles, and by the held particles' motion over one more chunk.
"""

import numpy as np
import pytest

from beadsim.bench import mode_params
from beadsim.sph.driver import BeadRun
from beadsim.sph.scene import TYPE_LIQUID, TYPE_SUBSTRATE


@pytest.mark.slow
def test_contact_freeze_holds_the_melt_that_touches_cold_plate(tmp_path):
    p = mode_params(1, resolution_mm=0.5, domain="window", sim_time_s=0.1, surface_tension=True,
                    artificial_viscosity=0.2, wetting_pressure_balance=True, wetting_angle_deg=72.7,
                    contact_freeze=True, wire_feed_start="immediate")
    run = BeadRun(p, tmp_path)
    run.open(resume=False)
    try:
        m = run.run()
        assert abs(m["energy_balance_error"]) < 1e-3
        types, x, v, ids = run._types().copy(), run._x().copy(), run._v().copy(), run._ids().copy()
        temp = run.thermal.temperature(run._e())
        pin = run.lmp.numpy.extract_atom("d_pin")[: len(types)] > 0
        # the rule, by brute force over every pair
        liquid = np.flatnonzero(types == TYPE_LIQUID)
        plate = np.flatnonzero(types == TYPE_SUBSTRATE)
        r = np.linalg.norm(x[liquid, None, :] - x[None, plate, :], axis=2)
        contact = np.where(r < 1.25 * run.num.dx, 0.5 * (temp[liquid, None] + temp[None, plate]), np.inf)
        expect = np.zeros(len(types), dtype=bool)
        expect[liquid] = contact.min(axis=1) < run.mat.T_melt
        assert 0 < expect.sum() < len(liquid)  # some melt touches cold plate, not all of it
        np.testing.assert_array_equal(pin, expect)
        assert run.n_pinned == expect.sum() and run.series[-1]["n_pinned"] == expect.sum()
        # the run's held share: the second half's chunks, each n_pinned / n_liquid
        half = [s["n_pinned"] / s["n_liquid"] for s in run.series if s["t"] >= run.state.t / 2 - 1e-12
                and s["n_liquid"] > 0]
        assert len(half) >= 2 and 0 < m["held_melt_share"] < 1
        assert m["held_melt_share"] == pytest.approx(np.mean(half), rel=1e-12)
        np.testing.assert_allclose(v[pin], np.broadcast_to(run.geom.substrate_velocity, (pin.sum(), 3)))
        # one more chunk: the held melt moves with the plate, exactly; the free melt does not
        run._run_lammps(setup=True)
        # by id: the setup may sort the local particles spatially (LAMMPS does when it rebuilds the neighbour
        # lists on a multiple of its sort interval)
        now = run._ids()
        order = np.argsort(now)
        moved = run._x()[order[np.searchsorted(now[order], ids)]] - x
        step = np.asarray(run.geom.substrate_velocity) * run.chunk * run.num.dt
        np.testing.assert_allclose(moved[pin], np.broadcast_to(step, (pin.sum(), 3)), atol=1e-12)
        free = (types == TYPE_LIQUID) & ~pin
        assert np.abs(moved[free] - step).max() > 1e-7
    finally:
        run.close()


@pytest.mark.slow
def test_frozen_group_per_chunk_is_the_dynamic_group(tmp_path):
    """With the cohesion the frozen group (fix setforce's) is evaluated once before each chunk instead of at every
    step (types and holds change only between chunks): the same run, particle for particle, as with LAMMPS's
    dynamic group, through melting, holds, wire slices fed and window layers added."""
    p = mode_params(1, resolution_mm=0.5, domain="window", sim_time_s=0.1, surface_tension=True,
                    artificial_viscosity=0.2, wetting_pressure_balance=True, wetting_angle_deg=72.7,
                    contact_freeze=True, wire_feed_start="immediate")
    state = {}
    for per_chunk in (True, False):
        run = BeadRun(p, tmp_path / str(per_chunk))
        run.frozen_per_chunk = per_chunk
        run.open(resume=False)
        try:
            run.run()
            assert run.n_pinned > 0 and (run._types() == TYPE_LIQUID).sum() > 10
            order = np.argsort(run._ids())
            state[per_chunk] = (run._ids()[order], run._x()[order], run._v()[order], run._e()[order])
        finally:
            run.close()
        deck = (tmp_path / str(per_chunk) / "deck.in").read_text()
        assert ("group frozen dynamic" in deck) != per_chunk
        assert (deck.count("group frozen variable frozen") > 100) == per_chunk
    for a, b in zip(state[True], state[False]):
        np.testing.assert_array_equal(a, b)
