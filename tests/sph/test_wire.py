"""Wire feed start with real LAMMPS: a scan ring wider than the wire (Table 4 mode 3, D 3 mm) leaves the wire tip
in the ring's cold hole. Fed from t = 0, the cold wire is pushed into cold metal and the watchdog stops the run
(stubbing); fed once the pool has formed under it (``wire_feed_start: pool``), the run goes on and the wire waits
still until then. Scene: 308LSi, 1300 W, V_w 15 mm/s, dx 0.5 mm, moving window (~3.2k particles, ~30 s each).
"""

from __future__ import annotations

import numpy as np
import pytest
import xarray as xr

from beadsim.errors import SimulationFailed
from beadsim.parameters import defaults
from beadsim.sph.driver import run_case
from beadsim.sph.scene import build_geometry, detached_wire, wire_link_length


def mode3(**over) -> dict:
    p = defaults()
    p.update(model="sph", material="308LSi", beam_power_W=1300.0, substrate_speed_mm_s=5.0, wire_feed_mm_s=15.0,
             scan_diameter_mm=3.0, resolution_mm=0.5, domain="window", window_thermal_lengths=4.0,
             melt_conductivity_factor=5.0, sim_time_s=0.35, dump_interval_s=0.1)
    p.update(over)
    return p


def test_cold_wire_fed_from_the_start_stubs(tmp_path):
    with pytest.raises(SimulationFailed) as info:
        run_case(mode3(), tmp_path)
    assert "stubbing" in info.value.reason and "wire_feed_start: pool" in info.value.reason


def test_feed_started_on_the_pool_runs_and_the_wire_waits_for_it(tmp_path):
    m = run_case(mode3(wire_feed_start="pool"), tmp_path)
    start = m["wire_feed_start_s"]
    assert 0 < start < 0.25 and m["simulated_time_s"] == pytest.approx(0.35, abs=1e-3)
    assert abs(m["energy_balance_error"]) < 1e-3
    ts = xr.open_dataset(tmp_path / "timeseries.nc")
    z = ts.wire_z_min.values
    before, after = z[ts.time.values < start], z[ts.time.values > start + 0.05]
    # held still before the feed: its lowest solid particle only rises (where the beam melts the wire)
    assert len(before) >= 2 and np.all(np.diff(before) >= 0)
    assert after.min() < before[-1] - 0.5e-3  # then fed down towards the pool
    # wire cut off by the beam falls; what touches solid stops there as solid (it would otherwise sink through it)
    assert m["wire_released_particles"] >= m["wire_landed_particles"] >= 0
    dump = sorted((tmp_path / "dumps").glob("*.lammpstrj"), key=lambda f: int(f.name.split(".")[1]))[-1]
    lines = dump.read_text().splitlines()
    start = next(i for i, line in enumerate(lines) if line.startswith("ITEM: ATOMS")) + 1
    atoms = np.array([line.split() for line in lines[start:]], dtype=float)
    solid, falling = np.isin(atoms[:, 1], (1, 4)), atoms[:, 1] == 5
    dx = 0.5e-3
    if falling.any():
        gap = np.min(np.linalg.norm(atoms[falling, None, 2:5] - atoms[None, solid, 2:5], axis=2), axis=1)
        assert gap.min() > 0.9 * dx
        # solid metal: its density is reset every chunk (it drifted to 0.73 rho0 at dx 0.2 before)
        assert np.all(np.abs(atoms[falling, 8] / 7680.0 - 1) < 0.02)
    assert atoms[:, 4].min() > -3e-3 - dx  # nothing below the block (domain_depth_mm 3)
    # every particle still typed wire (and so fed) hangs on the feed end: cut-off pieces never stay wire
    g = build_geometry(mode3())
    wire = atoms[atoms[:, 1] == 2, 2:5]
    s_axis = (wire - np.array([0.0, 0.0, g.wire_height])) @ g.wire_axis
    assert not detached_wire(wire, s_axis, s_axis.max(), wire_link_length(g)).any()


def test_spatter_leaving_the_block_is_deleted_with_its_energy_in_the_ledger(tmp_path):
    """A molten droplet beyond the side of the block (the droplets that skate off over the cold substrate) is
    deleted before it leaves the box, its energy is booked, and the ledger residual does not move; past
    ``spatter_limit`` the watchdog fails the run."""
    from beadsim.sph.driver import BeadRun

    run = BeadRun(mode3(spatter_limit=0), tmp_path)
    run.open(resume=False)
    g = run.geom
    n0 = int(run.lmp.get_natoms())
    victim = int(run._ids()[0])
    run.deck(f"set atom {victim} type 3 x 0 y {g.y_hi + 3 * g.dx:.9g} z 0.0005 vy 0.05")
    run.deck("run 0 post no")
    now = sum(run._energy_now().values())
    assert run._remove_spatter()
    assert int(run.lmp.get_natoms()) == n0 - 1 and run.state.n_ejected == 1
    # the energy that left with the droplet is what the ledger booked, so the residual does not move
    assert run.state.ledger.ejected > 0
    assert now - sum(run._energy_now().values()) == pytest.approx(run.state.ledger.ejected, rel=1e-9)
    assert not run._remove_spatter()  # nothing left outside
    # behind the moving window's rear face too: a droplet falling off the plate there leaves the box before the
    # rear face deletes it (which it does only when the next layer enters)
    behind = int(run._ids()[1])
    run.deck(f"set atom {behind} type 3 x {g.x_lo - 2 * g.dx:.9g} y 0 z {g.z_lo - 3 * g.dx:.9g} vz -0.3")
    run.deck("run 0 post no")
    assert run._remove_spatter() and run.state.n_ejected == 2
    # or flying back over the bead above the plate (mode 1 with the height function lost one at 0.87 m/s)
    back = int(run._ids()[2])
    run.deck(f"set atom {back} type 3 x {g.x_lo - 3 * g.dx:.9g} y 0 z 0.001 vx -0.9")
    run.deck("run 0 post no")
    assert run._remove_spatter() and run.state.n_ejected == 3
    # the box reaches at least 2 dx past every plane beyond which spatter is deleted (3 dx at the sides, 5.5 at
    # the top): a droplet must cross that within one chunk to be lost instead
    lo, hi = run.lmp.extract_box()[:2]
    assert lo[0] <= g.x_lo - 4 * g.dx and hi[0] >= g.x_hi + 4 * g.dx and hi[1] >= g.y_hi + 4 * g.dx
    assert lo[2] <= g.z_lo - 4 * g.dx and hi[2] >= g.box_z_hi + 1.5 * g.dx
    m = run._measure(run.thermal.temperature(run._e()))
    with pytest.raises(SimulationFailed, match="spatter"):
        run._watchdog(m, int(run.lmp.get_natoms()))


def test_a_droplet_at_the_rear_face_is_spatter_and_the_pool_there_fails_the_run(tmp_path):
    """Moving window: melt reaching the rear face fails the run only when it belongs to the pool (the window is
    too short); a molten particle apart from the pool (a droplet resting on the solid bead) leaves as spatter."""
    from beadsim.sph.driver import BeadRun

    run = BeadRun(mode3(spatter_limit=0), tmp_path)
    run.open(resume=False)
    g, d = run.geom, run.geom.dx
    x = run._x()
    blob = (x[:, 0] < g.x_lo + 3 * d) & (np.abs(x[:, 1]) < 1.5e-3) & (x[:, 2] > -1.5e-3)
    drop = np.flatnonzero((x[:, 0] < g.x_lo + d) & (x[:, 1] > 4e-3) & (x[:, 2] > -d))[:1]
    run.deck("group blob id " + " ".join(str(int(i)) for i in run._ids()[blob]))
    run.deck("set group blob type 3")
    drop_id = int(run._ids()[drop[0]])
    run.deck(f"set atom {drop_id} type 3")
    run.deck("run 0 post no")
    x, types = run._x(), run._types()
    rear, only_drop = x[:, 0] < g.x_lo + d, run._ids() == drop_id
    assert only_drop.sum() == 1 and types[only_drop][0] == 3
    run._rear_face_melt(x, types, only_drop)
    assert run.state.n_ejected == 1
    with pytest.raises(SimulationFailed, match="of the pool reached the rear face"):
        run._rear_face_melt(x, types, rear)


def test_cut_off_wire_coheres_like_melt_with_surface_tension(tmp_path):
    """With surface tension, falling wire gets the liquid-liquid cohesion with itself and the melt, and the
    liquid-solid one with solid: under the lowered Tait reference density a piece without cohesion flies apart."""
    from beadsim.sph.driver import BeadRun

    run = BeadRun(mode3(surface_tension=True, artificial_viscosity=0.2), tmp_path)
    run.open(resume=False)
    table = {tuple(map(int, line.split()[1:3])): line.split()[5]
             for line in (tmp_path / "deck.in").read_text().splitlines()
             if line.startswith("pair_coeff") and " table " in line}
    assert table == {(3, 3): "LL", (3, 5): "LL", (5, 5): "LL", (1, 3): "LS", (2, 3): "LS", (3, 4): "LS",
                     (1, 5): "LS", (2, 5): "LS", (4, 5): "LS"}
