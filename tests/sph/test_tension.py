"""Surface tension and wetting of the pairwise cohesive SPH model, with real LAMMPS (tiny scenes).

Run: /tmp/venv/bin/pytest tests/sph/test_tension.py -v   (about 1 minute on one idle core)
"""

from __future__ import annotations

import functools

import numpy as np
import pytest

from beadsim.lammps_env import new_lammps
from beadsim.materials import get_material
from beadsim.sph import verify_tension as vt
from beadsim.sph.tension import (
    CONTACT_ANGLE_HYSTERESIS,
    CONTACT_ANGLE_HYSTERESIS_BALANCED,
    CONTACT_ANGLE_TABLE_BALANCED,
    CohesionModel,
    wetting_ratio_for_angle,
)

TI = get_material("Ti-Gr2")
DX = 3.0e-4
#: The settings the calibration tables were measured with: c0 10 m/s, artificial viscosity 0.2, dt 5 us.
SETTINGS = dict(dx=DX, c0=10.0, alpha=0.2, dt=5e-6)


def _two_particle_lammps(model: CohesionModel, table):
    """Two solid (type 2) particles 0.6 h apart with the SPH and cohesive styles of the bead driver."""
    lmp = new_lammps()
    for cmd in (
        "units si",
        "atom_style sph",
        "atom_modify map array",
        "region b block -3e-3 3e-3 -3e-3 3e-3 -3e-3 3e-3 units box",
        "create_box 2 b",
        "create_atoms 2 single 0 0 0 units box",
        f"create_atoms 2 single {0.6 * model.h} 0 0 units box",
        f"mass * {TI.rho * DX**3}",
        f"set group all sph/rho {TI.rho}",
        f"neighbor {0.3 * DX} bin",
        "pair_style hybrid/overlay sph/taitwater " + model.pair_style_tokens(),
        f"pair_coeff * * sph/taitwater {TI.rho} 10 0.2 {model.h}",
        *model.pair_coeff_commands([1], [2], table_file=table),
        "fix 1 all sph",
        "timestep 1e-9",
        "thermo 0",
        "run 0 post no",
    ):
        lmp.command(cmd)
    return lmp


def test_table_reproduces_the_force(tmp_path):
    """LAMMPS' interpolated table gives the analytic force and energy (pair_write): to 0.1 % of s, plus 0.5 %
    of the local force in the steep repulsive core (LAMMPS interpolates linearly in r^2)."""
    model = CohesionModel.from_material(TI, DX, wetting_ratio=0.8)
    lmp = new_lammps()
    try:
        for cmd in (
            "units si",
            "atom_style sph",
            "region b block 0 1e-2 0 1e-2 0 1e-2 units box",
            "create_box 2 b",
            "mass * 1e-7",
            f"pair_style hybrid/overlay zero {model.h} {model.pair_style_tokens()}",
            "pair_coeff * * zero",
            *model.pair_coeff_commands([1], [2], table_file=tmp_path / "t.table"),
        ):
            lmp.command(cmd)
        lmp.command(f"pair_write 1 1 200 r {0.05 * model.h} {0.999 * model.h} {tmp_path / 'll.txt'} LL")
        lmp.command(f"pair_write 1 2 200 r {0.05 * model.h} {0.999 * model.h} {tmp_path / 'ls.txt'} LS")
    finally:
        lmp.close()
    for name, s in (("ll.txt", model.s_ll), ("ls.txt", model.s_ls)):
        r, e, f = np.loadtxt(tmp_path / name, skiprows=5, usecols=(1, 2, 3)).T
        exact = model.force(r, s)
        assert np.all(np.abs(f - exact) < 1e-3 * s + 5e-3 * np.abs(exact))
        assert np.abs(e - model.energy(r, s)).max() < 1e-3 * s * model.h


@pytest.mark.parametrize("pre, cohesive", [("no", False), ("yes", True)])
def test_type_change_needs_setup(tmp_path, pre, cohesive):
    """After a solid particle turns liquid, the cohesive force appears only once the run does its setup.

    The cohesive sub-style covers liquid pairs only, so pair hybrid gives it a type-filtered neighbour list
    that ``run N pre no`` does not rebuild.
    """
    model = CohesionModel.from_material(TI, DX, wetting_ratio=0.9)
    lmp = _two_particle_lammps(model, tmp_path / "t.table")
    try:
        assert lmp.numpy.extract_atom("f")[0, 0] == 0.0  # solid-solid: no cohesion, no SPH pressure at rho0
        lmp.numpy.extract_atom("type")[0] = 1  # particle 1 melts
        lmp.command(f"run 1 pre {pre} post no")
        fx = lmp.numpy.extract_atom("f")[0, 0]
    finally:
        lmp.close()
    expected = -model.force(0.6 * model.h, model.s_ls)  # attraction pulls particle 1 towards +x
    assert fx == (pytest.approx(expected, rel=1e-3) if cohesive else 0.0)


def test_slab_tension_matches_the_calibration():
    """Kirkwood-Buff virial tension of a flat periodic slab equals the material's sigma within 10 %."""
    res = vt.slab_tension(TI, settings=vt.SceneSettings(**SETTINGS))
    assert res["sigma_N_m"] == pytest.approx(TI.surface_tension, rel=0.10)
    assert 0.98 < res["rho_mean_rel"] < 1.02


def test_free_drop_laplace_pressure():
    """Free drops stay nearly round and their core pressure (pair virial, time-averaged) follows 2 sigma / R.

    Tolerances are the scatter measured at dx 0.3 mm over R = 6-10 dx (core pressure / (2 sigma / R) =
    1.24, 0.69, 0.50, 0.66 for R = 1.8, 2.1, 2.4, 3.0 mm): the particle arrangement gives the liquid a
    spurious yield stress of the order of the Laplace pressure at this resolution, and the drops freeze
    10-20 % out of round (a sphere cut from the lattice reads 0.05-0.08 on the same measure).
    """
    ratios = []
    for radius in (1.8e-3, 2.4e-3):
        res = vt.free_drop(TI, radius=radius, t_end=4e-3, t_average=2e-3, settings=vt.SceneSettings(**SETTINGS))
        assert res["laplace_analytic_Pa"] == pytest.approx(2 * TI.surface_tension / res["radius_m"])
        ratios.append(res["laplace_virial_Pa"] / res["laplace_analytic_Pa"])
        assert res["roundness"] < 0.25
        assert res["vmax_final_m_s"] < 0.3
        assert 0.93 < res["rho_min_final_rel"] and res["rho_max_final_rel"] < 1.07
    assert all(0.4 < r < 1.6 for r in ratios)
    assert np.mean(ratios) == pytest.approx(1.0, abs=0.35)


def test_sessile_drop_contact_angle():
    """Drops started above and below the set angle settle on either side of it, as the table says.

    The ratio for 79 degrees (0.9) is taken from the table; advancing (from a hemisphere) and receding (from a
    50 degree cap) angles must match the tabulated ones within 8 degrees and their mean the set angle within
    6 degrees. The drop is smaller than the one the table was measured with (442 particles instead of 1052).
    """
    target = 79.0
    ratio = wetting_ratio_for_angle(target)
    _, advancing, receding = next(row for row in CONTACT_ANGLE_HYSTERESIS if row[0] == pytest.approx(ratio))
    measured = []
    for start in (90.0, 50.0):
        res = vt.sessile_drop(
            TI,
            wetting_ratio=ratio,
            radius=1.8e-3,
            plate_half_width=4.2e-3,
            plate_layers=3,
            initial_angle_deg=start,
            t_end=0.012,
            settings=vt.SceneSettings(**SETTINGS),
        )
        assert res["n_liquid"] == res["n_liquid_initial"]
        assert abs(res["angle_height_deg"] - res["angle_deg"]) < 8.0  # a spherical cap, no spreading film
        measured.append(res["angle_deg"])
    assert measured[0] == pytest.approx(advancing, abs=8.0)
    assert measured[1] == pytest.approx(receding, abs=8.0)
    assert np.mean(measured) == pytest.approx(target, abs=6.0)


def test_cohesive_melt_in_the_bead_scene_stays_packed(tmp_path):
    """With surface tension the melt of a bead run keeps the lattice's packing (kernel fill ~1).

    The shifted Tait liquid sits at a positive background pressure balanced by the cohesion; a Shepard filter
    (which the driver skips with surface tension) held its density at rho0 while it expanded. Measured on this
    scene (mode 1, dx 0.5, 0.3 s, ~60 molten particles at the end): kernel fill 0.66-0.70 over the last 0.15 s
    with the filter, 0.96-0.98 without.
    """
    import xarray as xr

    from beadsim.bench import mode_params
    from beadsim.sph.driver import BeadRun

    p = mode_params(1, resolution_mm=0.5, domain="window", sim_time_s=0.3, dump_interval_s=0.1,
                    surface_tension=True, artificial_viscosity=0.2, beam_efficiency=0.6)
    run = BeadRun(p, tmp_path)
    run.open(resume=False)
    assert not run.shepard and "no Shepard filter" in (tmp_path / "deck.in").read_text()
    m = run.run()
    ts = xr.open_dataset(tmp_path / "timeseries.nc")
    late = ts.liquid_packing.values[ts.time.values > 0.15]
    assert ts.n_liquid.values[-1] >= 30
    assert np.all(late > 0.9), late
    assert 0.8 < m["liquid_packing"] < 1.1


@pytest.mark.parametrize("keep", ["rho0", "freeze"])
def test_refrozen_melt_remelts_at_the_density_it_froze_at(tmp_path, keep):
    """``resolidified_density: freeze``: the density reset of frozen particles gives melt that froze again the
    continuity density it froze at, and never-melted solid rho0; the value moves with the atom into a restart.

    With the reset to rho0, melt that expanded and froze is refilled to rho0 at every freeze-melt cycle at the
    pool's edge, and the cohesive cap puffs up (mode 2, dx 0.4, harmonic interface: kernel fill of the melt
    0.86-0.89 at 1.8-2.0 s with ``freeze``, 0.71-0.73 with ``rho0``; see the README). This checks the mechanism on
    particles set by hand.
    """
    from beadsim.bench import mode_params
    from beadsim.sph.driver import BeadRun
    from beadsim.sph.scene import TYPE_LIQUID, TYPE_RESOLIDIFIED, TYPE_SUBSTRATE

    p = mode_params(1, resolution_mm=0.5, domain="window", sim_time_s=0.01, surface_tension=True,
                    artificial_viscosity=0.2, resolidified_density=keep)
    run = BeadRun(p, tmp_path)
    run.open(resume=False)
    rho0, t_melt = run.mat.rho, run.mat.T_melt
    sub = np.flatnonzero(run._types() == TYPE_SUBSTRATE)
    melt, never = sub[:5], sub[5:10]
    e, cv = run._e(), run._cv()

    def heat(temp):
        e[melt] = cv[melt] * temp
        run._phase_update()

    heat(t_melt + 100)
    assert (run._types()[melt] == TYPE_LIQUID).all()
    run._rho()[melt] = 0.9 * rho0  # the melt expanded
    heat(t_melt - 100)
    assert (run._types()[melt] == TYPE_RESOLIDIFIED).all()
    run._rho()[np.r_[melt, never]] = 1.05 * rho0  # continuity drift of frozen particles beside moving melt
    run._phase_update()
    kept = 0.9 * rho0 if keep == "freeze" else rho0
    np.testing.assert_allclose(run._rho()[melt], kept)
    np.testing.assert_allclose(run._rho()[never], rho0)
    heat(t_melt + 100)  # remelts at the density it froze at
    np.testing.assert_allclose(run._rho()[melt], kept)
    if keep == "freeze":
        heat(t_melt - 100)
        melt_ids = run._ids()[melt]
        run.checkpoint()
        run.lmp.close()
        again = BeadRun(p, tmp_path)
        again.open(resume=True)
        rho_freeze = again.lmp.numpy.extract_atom("d_rhofreeze")
        np.testing.assert_allclose(rho_freeze[np.isin(again._ids(), melt_ids)], kept)
        assert (rho_freeze[~np.isin(again._ids(), melt_ids)] == 0).all()


@pytest.mark.parametrize("ratio", [0.8, 0.9, 1.0])
def test_solid_tait_density_balances_the_interface(ratio):
    """The solid's Tait pressure at the true density is (2 r - 1) times the liquid's background pressure."""
    model = CohesionModel.from_material(TI, DX, wetting_ratio=ratio)
    c0 = 10.0
    p_b = -model.pair_pressure()

    def tait(rho0):
        return c0**2 * rho0 / 7 * ((TI.rho / rho0) ** 7 - 1)

    assert tait(model.tait_rho0(TI, c0)) == pytest.approx(p_b, rel=1e-9)
    assert tait(model.solid_tait_rho0(TI, c0)) == pytest.approx((2 * ratio - 1) * p_b, rel=1e-9)
    if ratio == 1.0:
        assert model.solid_tait_rho0(TI, c0) == pytest.approx(model.tait_rho0(TI, c0), rel=1e-12)


def test_sessile_drop_contact_angle_with_pressure_balance():
    """With the wetting pressure balance the drop settles at the angles of the balanced table (ratio 0.8)."""
    ratio = 0.8
    _, advancing, receding = next(row for row in CONTACT_ANGLE_HYSTERESIS_BALANCED if row[0] == ratio)
    assert wetting_ratio_for_angle((advancing + receding) / 2, CONTACT_ANGLE_TABLE_BALANCED) == pytest.approx(ratio)
    measured = []
    for start in (90.0, 50.0):
        res = vt.sessile_drop(TI, wetting_ratio=ratio, radius=1.8e-3, plate_half_width=4.2e-3, plate_layers=3,
                              initial_angle_deg=start, t_end=0.012,
                              settings=vt.SceneSettings(**SETTINGS, pressure_balance=True))
        assert res["n_liquid"] == res["n_liquid_initial"]
        assert abs(res["angle_height_deg"] - res["angle_deg"]) < 8.0
        measured.append(res["angle_deg"])
    # measured 83.1 / 62.3 (the table); without the balance the same ratio gives 101 / 80 (larger drop)
    assert measured[0] == pytest.approx(advancing, abs=4.0)
    assert measured[1] == pytest.approx(receding, abs=4.0)


@pytest.mark.parametrize("balance", [True, False])
def test_melt_beside_solid_stays_packed_with_the_pressure_balance(tmp_path, balance):
    """Wetting ratio 0.8 in the bead scene: with the balance the melt keeps the lattice's packing, without it
    the melt next to the solid is pushed off and expands (the defect the balance removes).

    Scene as :func:`test_cohesive_melt_in_the_bead_scene_stays_packed` (mode 1, dx 0.5 mm, 0.3 s). Measured at
    ratio 0.8 over 0.18-0.3 s: kernel fill 0.974-0.987 with the balance (a dip to 0.89 at 0.16 s as the first
    melt meets the plate), 0.755-0.805 without; at ratio 0.9 over 0.16-0.6 s: 0.98-0.99 with it, 0.87-0.90
    without; 0.94-0.97 at ratio 1.
    """
    import xarray as xr

    from beadsim.bench import mode_params
    from beadsim.sph.driver import BeadRun

    p = mode_params(1, resolution_mm=0.5, domain="window", sim_time_s=0.3, dump_interval_s=0.1,
                    surface_tension=True, artificial_viscosity=0.2, beam_efficiency=0.6, density_tolerance=0.3,
                    wetting_pressure_balance=balance, wetting_angle_deg=72.7 if balance else 90.3)
    run = BeadRun(p, tmp_path)
    run.open(resume=False)
    assert run.num.cohesion.wetting_ratio == pytest.approx(0.8, abs=0.01)
    assert (run.num.solid_tait_rho0 > run.num.tait_rho0) == balance
    run.run()
    ts = xr.open_dataset(tmp_path / "timeseries.nc")
    late = ts.liquid_packing.values[ts.time.values > 0.18]
    assert ts.n_liquid.values[-1] >= 30
    if balance:
        assert np.all(late > 0.95), late
    else:
        assert np.all(late < 0.85), late


def _lattice_block(n: int = 5) -> tuple[np.ndarray, np.ndarray]:
    """A simple cubic block of n^3 particles dx apart, and the indices of all of them."""
    g = np.arange(n) * DX
    block = np.array(np.meshgrid(g, g, g, indexing="ij")).reshape(3, -1).T
    return block, np.arange(len(block))


def test_loose_density_ceiling_spares_the_lattice_and_caps_spread_melt():
    """The ceiling leaves every particle of a lattice block (interior, faces, edges, corners: three nearest
    at dx) at rho0 or above, and caps a lattice spread to 1.2 dx at rho0 (d_ref / 1.2)^3, not below the
    minimum."""
    from beadsim.sph.driver import LOOSE_MELT_D3, loose_density_ceiling

    block, everyone = _lattice_block()
    assert np.all(loose_density_ceiling(block, everyone, DX, TI.rho, 0.8 * TI.rho) >= TI.rho * (1 - 1e-9))
    spread = loose_density_ceiling(1.2 * block, everyone, DX, TI.rho, 0.5 * TI.rho)
    assert spread == pytest.approx(TI.rho * (LOOSE_MELT_D3 / 1.2) ** 3)
    floor = loose_density_ceiling(1.2 * block, everyone, DX, TI.rho, 0.8 * TI.rho)
    assert floor == pytest.approx(0.8 * TI.rho)
    lone = loose_density_ceiling(np.vstack([block, [[1.0, 1.0, 1.0]]]), np.array([len(block)]), DX, TI.rho,
                                 0.8 * TI.rho)
    assert lone == pytest.approx(0.8 * TI.rho)  # no neighbours: the minimum


def test_smoothed_ceiling_caps_loose_regions_only():
    """With ``smoothing`` the ceiling compares d3 averaged over a neighbourhood: a block packed at 0.95 dx is
    not capped at all (infinite ceiling), blocks at dx and spread to 1.2 dx are capped at rho0 (d_ref / s)^3
    everywhere (every particle of a lattice of spacing s has d3 = s; a threshold below dx counts the lattice
    itself as slightly loose: a dense liquid at the lattice's number density has d3 of about 0.92 dx), and a
    lone particle a few spacings off the block, which averages only itself, gets the minimum."""
    from beadsim.sph.driver import loose_density_ceiling

    block, everyone = _lattice_block()
    dense = loose_density_ceiling(0.95 * block, everyone, DX, TI.rho, 0.8 * TI.rho, d_ref=0.985, smoothing=1.5)
    assert np.all(np.isinf(dense))
    for s in (1.0, 1.2):
        spread = loose_density_ceiling(s * block, everyone, DX, TI.rho, 0.5 * TI.rho, d_ref=0.985, smoothing=1.5)
        assert spread == pytest.approx(TI.rho * (0.985 / s) ** 3)
    stray = np.vstack([block, [[block[:, 0].max() + 3 * DX, 0.0, 0.0]]])
    lone = loose_density_ceiling(stray, np.array([len(block)]), DX, TI.rho, 0.8 * TI.rho, d_ref=0.985,
                                 smoothing=1.5)
    assert lone == pytest.approx(0.8 * TI.rho)


@pytest.mark.parametrize("ceiling", [False, True])
def test_loose_drop_stays_loose_unless_its_density_is_capped(ceiling):
    """A sessile Ti drop cut from a lattice at 1.2 dx with the density rho0 (ratio 0.8 with the pressure
    balance, dx 0.4 mm and the bead runs' c0 4.15 m/s and dt 10.8 us, gravity, 0.06 s): without the ceiling
    nothing pulls it together, its height-map volume stays 1.3x its particles' (measured 1.30; the Ti beads'
    deposits read 1.24-1.31); with the driver's ceiling and relaxation
    (:func:`beadsim.sph.driver.loose_density_ceiling`) the cohesion compacts it to the packing of a drop cut
    at dx (measured 0.98; drops cut at dx read 0.93 with the ceiling, 0.965 without)."""
    res = vt.sessile_drop(TI, wetting_ratio=0.8, radius=2.4e-3, plate_half_width=4.4e-3, plate_layers=3,
                          gravity=9.81, initial_spacing=1.2, t_end=0.06, t_average=1e-3,
                          settings=vt.SceneSettings(dx=4e-4, c0=4.15, alpha=0.2, dt=10.8e-6,
                                                    pressure_balance=True, loose_ceiling=ceiling))
    assert res["n_liquid"] == res["n_liquid_initial"]
    if ceiling:
        assert res["packing_ratio"] < 1.05
    else:
        assert res["packing_ratio"] > 1.2


def test_smoothed_ceiling_compacts_a_loose_drop_and_leaves_a_dense_one():
    """The smoothed ceiling (threshold 0.985 dx, d3 averaged within 1.5 dx; same drops as above) compacts the
    drop cut at 1.2 dx to 1.00 (measured; 0.98 with the first form) and leaves a drop cut at dx within the
    scatter of the drop without any ceiling.

    That scatter is wide: the drop starts on an exact lattice, and where it ends at 0.06 s depends on rounding
    (measured 2026-12-05 over starts at 0.999 / 1.0005 / 1.001 / 1.002 dx: 0.946-0.981 without a ceiling,
    0.950-0.963 smoothed, 0.919-0.951 with the first form; the smoothed drop cut at exactly dx read 0.922-0.965
    with the ceiling's pair sums taken in five different orders). So the dense drop is held to 0.045 of the
    uncapped one, not to the 0.015 that one sample once suggested."""
    drop = functools.partial(vt.sessile_drop, TI, wetting_ratio=0.8, radius=2.4e-3, plate_half_width=4.4e-3,
                             plate_layers=3, gravity=9.81, t_end=0.06, t_average=1e-3)
    settings = functools.partial(vt.SceneSettings, dx=4e-4, c0=4.15, alpha=0.2, dt=10.8e-6, pressure_balance=True)
    smoothed = settings(loose_ceiling=True, loose_d3=0.985, loose_smoothing=1.5)
    loose = drop(initial_spacing=1.2, settings=smoothed)
    assert 0.95 < loose["packing_ratio"] < 1.04
    dense = drop(initial_spacing=1.0, settings=smoothed)
    free = drop(initial_spacing=1.0, settings=settings(loose_ceiling=False))
    assert dense["packing_ratio"] == pytest.approx(free["packing_ratio"], abs=0.045)


@pytest.mark.parametrize("ceiling", [False, True])
def test_bead_melt_is_compacted_by_the_loose_melt_ceiling(tmp_path, ceiling):
    """In the bead scene (mode 1, dx 0.5 mm, ratio 0.8 with the pressure balance, 0.2 s) the melt that comes
    off the wire is loose unless ``loose_melt_ceiling`` caps its density: the mean distance of a melt particle
    to its three nearest neighbours, 90th percentile, measured 1.42 dx without and 1.02 dx with it
    (1.46 / 1.01 at 0.3 s; a dense drop reads 1.07)."""
    from scipy.spatial import cKDTree

    from beadsim.bench import mode_params
    from beadsim.sph.driver import run_case

    p = mode_params(1, resolution_mm=0.5, domain="window", sim_time_s=0.2, dump_interval_s=0.1,
                    surface_tension=True, artificial_viscosity=0.2, beam_efficiency=0.6,
                    density_tolerance=0.4, wetting_pressure_balance=True, wetting_angle_deg=72.7,
                    resolidified_density="freeze", loose_melt_ceiling=ceiling)
    run_case(p, tmp_path)
    assert ("relaxes to its density ceiling" in (tmp_path / "deck.in").read_text()) == ceiling
    last = max((tmp_path / "dumps").glob("dump.*.lammpstrj"), key=lambda f: int(f.name.split(".")[1]))
    rows = np.loadtxt(last, skiprows=9)
    x, liquid = rows[:, 2:5], rows[:, 1] == 3
    assert liquid.sum() >= 30
    dist, _ = cKDTree(x).query(x[liquid], k=4)
    p90 = np.percentile(dist[:, 1:].mean(axis=1), 90) / 5e-4
    if ceiling:
        assert p90 < 1.15
    else:
        assert p90 > 1.25


#: The bead runs' numerics (mode 1, dx 0.4 mm: c0 4.15 m/s, artificial viscosity 0.2, dt 10.8 us).
BEAD_SETTINGS = dict(dx=4.0e-4, c0=4.15, alpha=0.2, dt=10.8e-6)


@functools.cache
def _traction_film(cohesion: bool) -> dict:
    return vt.surface_traction_film(TI, traction=300.0, cohesion=cohesion, t_develop=0.02,
                                    settings=vt.SceneSettings(**BEAD_SETTINGS))


def test_plain_sph_film_circulates_under_a_surface_traction():
    """A surface shear stress of 300 Pa (a few times a Ti pool's Marangoni stress) drives the plain SPH film
    (no cohesion) into a circulation: the surface moves along the traction, the layer on the plate back.
    Measured 2026-12-04: surface speed 4-17 % of the lubrication estimate tau d / (4 mu) with the artificial
    viscosity's nominal mu (100-2300 Pa, dx 0.2-0.4 mm); 17 % here, 23 % of the Stokes film's speed
    (``u_stokes``). A transient: the plain film loses particles from its surface by 40 ms (2026-12-05)."""
    res = _traction_film(False)
    assert 0.02 < res["flow_ratio"] < 1.0
    assert res["u_bottom"] < 0.0


def test_cohesive_melt_holds_a_surface_traction_below_its_yield_stress():
    """The same film with the pairwise cohesion does not flow: the cohesive melt is a solid below a yield
    stress of ~0.6-0.8 sigma / dx (1-3 kPa at dx 0.4 mm; README, "The cohesive melt has a yield stress").
    This documents a limitation of the model: if a change to the cohesion makes the melt flow, the README's
    account of the humps and this test need revisiting."""
    res = _traction_film(True)
    assert abs(res["flow_ratio"]) < 0.02  # measured 0.004 here; -0.005 to 0.013 across the variants tried
    assert abs(res["u_top"]) < _traction_film(False)["u_top"] / 5


def test_film_surface_speed_reaches_the_lubrication_and_half_space_limits():
    """The traction film's Stokes reference: tau d / (4 mu) for a thin film (lubrication, no net flux), tau /
    (2 mu k) for a deep one (half-space), and in between below both."""
    tau, mu, d = 300.0, 0.05, 2.4e-3
    thin = vt.film_surface_speed(tau, mu, 1e-3 / d, d)
    assert thin == pytest.approx(tau * d / (4 * mu), rel=1e-4)
    k = 30 / d
    assert vt.film_surface_speed(tau, mu, k, d) == pytest.approx(tau / (2 * mu * k), rel=1e-6)
    k = 2 * np.pi / (16 * 4e-4)  # the test film: 16 columns, 6 layers at dx 0.4 mm
    mid = vt.film_surface_speed(tau, mu, k, d)
    assert mid < min(tau * d / (4 * mu), tau / (2 * mu * k))


@functools.cache
def _cells(liquid: str, pattern: str = "cells", stress: float = 300.0) -> dict:
    return vt.cellular_flow(TI, stress=stress, liquid=liquid, pattern=pattern,
                            settings=vt.SceneSettings(**BEAD_SETTINGS))


def test_plain_sph_bulk_flows_in_taylor_green_cells():
    """A periodic plain SPH bulk under a Taylor-Green body force of stress scale 300 Pa reaches the Stokes
    speed F / (2 nu k^2) with the artificial viscosity's nominal mu = rho alpha c0 h / 8. Measured 2026-12-05:
    0.94 (0.98 at 100 Pa; 1.65 at dx 0.3 mm, c0 10 m/s, where the nominal mu overstates the viscosity)."""
    res = _cells("plain")
    assert 0.6 < res["flow_ratio"] < 1.4


def test_cohesive_bulk_does_not_rearrange_below_a_yield_stress():
    """The cohesive liquid's bulk, with no free surface, does not flow in the Taylor-Green cells at 300 Pa
    (0.08 sigma / dx; measured 0.015 of the Stokes speed, plain 0.94); nor does plain SPH at the same background
    pressure (~7.7 sigma / dx, the cohesive model's shifted Tait reference density, no cohesion; 0.04). Layers
    that slide over each other without rearranging (Kolmogorov shear at 1000 Pa) do move (0.94). Documents
    where the yield stress comes from (README, "The cohesive melt has a yield stress"): if a change to the
    cohesion makes the cells flow, revisit it."""
    assert abs(_cells("cohesive")["flow_ratio"]) < 0.05
    assert abs(_cells("background")["flow_ratio"]) < 0.15
    assert _cells("cohesive", "shear", 1000.0)["flow_ratio"] > 0.5


def test_segment_angle_inverts_the_circular_segment():
    """A half disc stands at 90 deg, a 60-deg segment at 60; no segment is taller than a whole disc."""
    assert vt.segment_angle(np.pi / 2, 1.0) == pytest.approx(90.0, abs=1e-6)
    t, radius = np.radians(60.0), 2.0
    area, height = radius**2 * (t - np.sin(t) * np.cos(t)), radius * (1 - np.cos(t))
    assert vt.segment_angle(area, height) == pytest.approx(60.0, abs=1e-6)
    assert np.isnan(vt.segment_angle(0.5, 1.0))


#: The bead runs' surface-tension settings (table4_sph_dense): wetting pressure balance, smoothed loose-melt
#: ceiling, at the bead's numerics.
BEAD_TENSION = dict(BEAD_SETTINGS, pressure_balance=True, loose_ceiling=True, loose_d3=0.985, loose_smoothing=1.5)


@functools.cache
def _ridge(width: int, layers: int, alpha: float = 0.2, anneal: float = 0.0, t_end: float = 0.1) -> dict:
    st = vt.SceneSettings(**dict(BEAD_TENSION, alpha=alpha, anneal_speed=anneal))
    return vt.sessile_ridge(TI, 0.8, width, layers, settings=st, t_end=t_end, t_start=t_end / 2)


def test_ridge_keeps_the_shape_it_started_from():
    """The bead's geometry (contact lines along a lattice row) shows the cohesive melt's yield stress: two
    ridges of the same metal (24 dx^2 of cross-section, ratio 0.8), started as a wide (12 x 2) and a tall
    (4 x 6) rectangle and damped so that they do not overshoot (artificial viscosity 1.0), stop at different
    shapes. A liquid would reach the same cap from both. Measured 2026-12-05 (0.05-0.1 s): 45 and 124 deg,
    1.04 and 1.87 mm high (the tall one stays a rounded column)."""
    wide, tall = _ridge(12, 2, alpha=1.0), _ridge(4, 6, alpha=1.0)
    assert tall["angle_deg"] - wide["angle_deg"] > 30
    assert tall["height_m"] > 1.5 * wide["height_m"]
    assert wide["n_liquid"] == tall["n_liquid"] == 144


def test_annealed_ridge_forgets_where_it_started():
    """With thermal agitation (a DPD thermostat on the liquid pairs, v_th 0.3 m/s: a verification device that
    unpins the melt) the same two ridges at the bead's damping reach one angle. Measured 2026-12-05: 53.1 and
    54.8 deg over 0.1-0.2 s (sd 3.3 and 2.0; 56.1 and 53.7 over 0.15-0.3 s), where the drop table gives 72.7 deg
    for this ratio (README, "Contact lines along the lattice")."""
    wide, tall = _ridge(12, 2, anneal=0.3, t_end=0.2), _ridge(4, 6, anneal=0.3, t_end=0.2)
    assert abs(wide["angle_deg"] - tall["angle_deg"]) < 8
    assert 45 < (wide["angle_deg"] + tall["angle_deg"]) / 2 < 62


def test_table_file_is_whole_while_another_rank_rewrites_it(tmp_path):
    """Under MPI every rank writes the table while rank 0 may be reading it: a reader never sees part of it.
    (A plain write let rank 0 parse a half-written table in CI, "Error parsing pair table 'LL' line 1456 of
    2000", and the 2-rank run stopped there.)"""
    import subprocess
    import sys

    model = CohesionModel.from_material(TI, DX, wetting_ratio=0.8)
    table = model.write_table(tmp_path / "tension.table")
    whole = table.read_text()
    writer = subprocess.Popen([sys.executable, "-c", (
        "import sys; from beadsim.materials import get_material; from beadsim.sph.tension import CohesionModel\n"
        f"m = CohesionModel.from_material(get_material('Ti-Gr2'), {DX!r}, wetting_ratio=0.8)\n"
        "print('ready', flush=True)\n"
        f"for _ in range(400): m.write_table({str(table)!r})\n")], stdout=subprocess.PIPE, text=True)
    try:
        assert writer.stdout.readline().strip() == "ready"
        reads = []
        while writer.poll() is None:
            reads.append(table.read_text())
    finally:
        writer.wait(timeout=120)
    assert writer.returncode == 0
    assert len(reads) > 20
    assert sum(r != whole for r in reads) == 0


def test_plate_wetting_ratio_gives_the_unmelted_plate_its_own_cohesion(tmp_path):
    """``plate_wetting_ratio``: the melt's cohesion with the plate that never melted (type substrate) has its own
    strength, read from a second table whose liquid-solid section is that ratio of the liquid-liquid one; under
    the wetting pressure balance the plate's Tait reference density puts it at (2 r - 1) times the liquid's
    background pressure (zero at r = 0.5: rho0 = rho); melted metal keeps the ratio of wetting_angle_deg; a short
    bead runs with the energy ledger closed."""
    from beadsim.bench import mode_params
    from beadsim.sph.driver import run_case
    from beadsim.sph.scene import TYPE_LIQUID, TYPE_RESOLIDIFIED, TYPE_SUBSTRATE

    p = mode_params(1, resolution_mm=0.5, domain="window", sim_time_s=0.03, surface_tension=True,
                    artificial_viscosity=0.2, wetting_pressure_balance=True, wetting_angle_deg=72.7,
                    plate_wetting_ratio=0.5, wire_feed_start="immediate")
    m = run_case(p, tmp_path)
    assert abs(m["energy_balance_error"]) < 1e-3

    def forces(path):
        out, key = {}, None
        for line in path.read_text().splitlines():
            words = line.split()
            if len(words) == 1:
                key, out[words[0]] = words[0], []
            elif len(words) == 4 and key:
                out[key].append(float(words[3]))
        return {k: np.array(v) for k, v in out.items()}

    own, plate = forces(tmp_path / "tension.table"), forces(tmp_path / "tension_plate.table")
    np.testing.assert_allclose(plate["LL"], own["LL"], rtol=1e-12)
    np.testing.assert_allclose(plate["LS"], 0.5 * plate["LL"], rtol=1e-9)
    np.testing.assert_allclose(own["LS"], 0.8 * own["LL"], rtol=0.02)  # 72.7 deg on the balanced table
    deck = (tmp_path / "deck.in").read_text().splitlines()
    tables = {}  # the last pair_coeff of a type pair in the table sub-style is the one LAMMPS keeps
    rho0 = {}  # a type's Tait reference density, from the sph/taitwater line whose first type it is
    for line in deck:
        words = line.split()
        if words[:1] == ["pair_coeff"] and words[3] == "table":
            tables[(int(words[1]), int(words[2]))] = (words[4].rsplit("/", 1)[-1], words[5])
        if words[:1] == ["pair_coeff"] and words[3] == "sph/taitwater" and words[1] == words[2]:
            rho0[int(words[1])] = float(words[4])
    assert tables[(TYPE_SUBSTRATE, TYPE_LIQUID)] == ("tension_plate.table", "LS")
    assert tables[(TYPE_LIQUID, TYPE_RESOLIDIFIED)] == ("tension.table", "LS")
    assert tables[(TYPE_LIQUID, TYPE_LIQUID)] == ("tension.table", "LL")
    assert rho0[TYPE_SUBSTRATE] == pytest.approx(TI.rho, rel=1e-9)
    assert rho0[TYPE_RESOLIDIFIED] < TI.rho and rho0[TYPE_LIQUID] < rho0[TYPE_RESOLIDIFIED]
