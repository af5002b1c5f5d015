"""Verification scenes for the cohesive surface-tension model, run with real LAMMPS.

Each scene uses the bead driver's ingredients: ``atom_style sph``, ``pair_style hybrid/overlay sph/taitwater
sph/heatconduction`` plus the cohesive sub-style of :class:`beadsim.sph.tension.CohesionModel`, ``fix sph`` on
all particles, the solid (type 2) frozen with ``fix setforce 0 0 0``, and a chunked loop
(``run N pre no post no``) that resets solid velocity and density from Python between chunks.

Public functions
----------------
free_drop(...) -> dict
    A spherical drop in vacuum: Laplace pressure inside (time-averaged pair virial of the core, and Tait
    pressure) against 2 sigma / R, roundness.
sessile_drop(...) -> dict
    A drop on a frozen plate, started as a spherical cap of a chosen angle: contact angle from a sphere fitted
    to its free surface, from its apex height and from its centroid height.
slab_tension(...) -> dict
    Kirkwood-Buff virial surface tension of a periodic liquid slab (the calibration route).
surface_traction_film(...) -> dict
    A film on a plate with a shear stress on its free surface (a Marangoni stress): does it circulate?
film_surface_speed(tau, mu, k, d) -> float
    The Stokes surface speed of that film (its reference).
sessile_ridge(...) -> dict
    A ridge on a plate, periodic along its length, started as a rectangle: the contact angle of its flanks,
    which run along a lattice row as a bead's do.
cellular_flow(...) -> dict
    A periodic bulk under Taylor-Green or Kolmogorov body forces: does it flow where particles must rearrange?
calibrate(...) -> dict
    C_sigma = sigma dx / s from slabs at several strengths.
benchmark(...) -> dict
    Particle-steps per second of the SPH styles with and without the cohesive term in a chunked loop.
roundness(x, dx), cap_angle_from_surface(x, dx), cap_angle_from_centroid(volume, z_c)
    Shape measures used by the above.

Settings the tables of :mod:`beadsim.sph.tension` were measured with: ``SceneSettings(c0=10, alpha=0.2,
dt=5e-6)`` at dx 0.3 mm.
"""

from __future__ import annotations

import dataclasses
import math
import tempfile
import time
from collections.abc import Callable
from dataclasses import dataclass
from pathlib import Path

import numpy as np
from scipy.constants import Boltzmann as BOLTZMANN
from scipy.optimize import brentq
from scipy.spatial import cKDTree

from beadsim.lammps_env import new_lammps
from beadsim.materials import Material, get_material
from beadsim.sph.driver import LOOSE_MELT_D3, relax_loose_density
from beadsim.reduced import cap_shape
from beadsim.sph.heightfn import ColumnGrid
from beadsim.sph.heightfn import surface_forces as height_function_forces
from beadsim.sph.surface import _column_table, profile_metrics
from beadsim.sph.tension import CohesionModel

LIQUID, SOLID = 1, 2


@dataclass
class SceneSettings:
    """Numerical settings shared by the scenes (SI units).

    Attributes
    ----------
    dx : float
        Particle spacing, m.
    c0 : float
        Tait sound speed, m s-1.
    alpha : float
        Artificial viscosity of sph/taitwater (dimensionless).
    morris_viscosity : float or None
        If given, use ``sph/taitwater/morris`` with this dynamic viscosity (Pa s) instead of ``sph/taitwater``.
    dt : float or None
        Time step, s; None = :meth:`CohesionModel.dt_limit` for c0 and alpha.
    chunk : int
        Steps per ``run N pre no post no`` chunk.
    skin : float or None
        Neighbour skin, m; None = 0.3 dx.
    backend : str
        Cohesive backend, ``"table"``, ``"lepton"`` or ``"none"`` (no cohesion).
    pressure_balance : bool
        Give the solid type the Tait reference density of :meth:`CohesionModel.solid_tait_rho0` (the bead
        driver's ``wetting_pressure_balance``) instead of the liquid's.
    loose_ceiling : bool
        Relax the density of loosely packed liquid towards its ceiling every chunk, as the bead driver's
        ``loose_melt_ceiling`` does (:func:`beadsim.sph.driver.relax_loose_density`).
    loose_d3, loose_smoothing : float
        The ceiling's threshold and smoothing radius in dx (``loose_melt_d3``, ``loose_melt_smoothing``).
    anneal_speed : float
        Thermal agitation of the liquid, m s-1 (0 = none, as in the bead driver): a DPD thermostat
        (``pair_style dpd/tstat``, friction ``anneal_friction`` kg s-1 per pair, liquid-liquid pairs only) at
        kT = m ``anneal_speed``^2. A verification device, not physics: it unpins the cohesive liquid (which is a
        solid below a yield stress) so that a drop finds its equilibrium contact angle.
    """

    dx: float = 3.0e-4
    c0: float = 10.0
    alpha: float = 0.2
    morris_viscosity: float | None = None
    dt: float | None = None
    chunk: int = 10
    skin: float | None = None
    backend: str = "table"
    pressure_balance: bool = False
    loose_ceiling: bool = False
    loose_d3: float = LOOSE_MELT_D3
    loose_smoothing: float = 0.0
    anneal_speed: float = 0.0
    anneal_friction: float = 1e-4


def _setup(lmp, st: SceneSettings, half: tuple[float, float, float], boundary: str = "f f f"):
    """Create the box (half widths in m) and neighbour settings; atoms are added by the caller afterwards."""
    hx, hy, hz = half
    for cmd in (
        "units si",
        "atom_style sph",
        "dimension 3",
        f"boundary {boundary}",
        "atom_modify map array",
        "comm_modify vel yes",
        f"neighbor {st.skin if st.skin is not None else 0.3 * st.dx:.6g} bin",
        "neigh_modify every 1 delay 0 check yes",
        f"region box block {-hx:.6g} {hx:.6g} {-hy:.6g} {hy:.6g} {-hz:.6g} {hz:.6g} units box",
        "create_box 2 box",
        f"lattice sc {st.dx:.6g}",
    ):
        lmp.command(cmd)


def _finish_setup(
    lmp, mat: Material, model: CohesionModel, st: SceneSettings, cohesive_types: tuple[int, ...] = (LIQUID,)
) -> float:
    """Set masses, pair styles, fixes and the time step; return dt (s).

    ``cohesive_types`` get the liquid-liquid cohesion among themselves (the benchmark adds the solid to measure
    an unfiltered neighbour list); the other types get the liquid-solid one.
    """
    m = mat.rho * st.dx**3
    lmp.command(f"mass * {m:.9g}")
    lmp.command(f"set group all sph/rho {mat.rho}")
    lmp.command(f"set group all sph/cv {mat.cp}")
    lmp.command(f"set group all sph/e {mat.cp * mat.T_melt:.9g}")
    lmp.command("group liquid type 1")
    lmp.command("group solid type 2")
    extra = "" if st.backend == "none" else " " + model.pair_style_tokens()
    sph = "sph/taitwater" if st.morris_viscosity is None else "sph/taitwater/morris"
    visc = st.alpha if st.morris_viscosity is None else st.morris_viscosity
    if st.anneal_speed > 0:
        temp = m * st.anneal_speed**2 / BOLTZMANN  # DPD temperature (K) at kT = m v^2, LAMMPS SI units
        extra += f" dpd/tstat {temp:.9g} {temp:.9g} {model.h:.9g} 4821"
    lmp.command(f"pair_style hybrid/overlay {sph} sph/heatconduction" + extra)
    rho0 = mat.rho if st.backend == "none" else model.tait_rho0(mat, st.c0)
    lmp.command(f"pair_coeff * * {sph} {rho0:.9g} {st.c0} {visc} {model.h:.9g}")
    if st.pressure_balance and st.backend != "none":  # the style reads a type's rho0 from its pair_coeff lines
        lmp.command(f"pair_coeff {SOLID} {SOLID} {sph} {model.solid_tait_rho0(mat, st.c0):.9g} {st.c0} {visc} "
                    f"{model.h:.9g}")
    lmp.command(f"pair_coeff * * sph/heatconduction {mat.diffusivity:.9g} {model.h:.9g}")
    if st.anneal_speed > 0:
        for a, b, gamma in ((LIQUID, LIQUID, st.anneal_friction), (LIQUID, SOLID, 0.0), (SOLID, SOLID, 0.0)):
            lmp.command(f"pair_coeff {min(a, b)} {max(a, b)} dpd/tstat {gamma:.9g} {model.h:.9g}")
    if st.backend != "none":
        others = [t for t in (LIQUID, SOLID) if t not in cohesive_types]
        with tempfile.TemporaryDirectory() as tmp:  # LAMMPS reads the table during pair_coeff
            for line in model.pair_coeff_commands(list(cohesive_types), others, Path(tmp) / "tension.table"):
                lmp.command(line)
    lmp.command("fix integrate all sph")
    lmp.command("fix freeze solid setforce 0 0 0")
    dt = st.dt or model.dt_limit(mat, st.dx, st.c0, st.alpha)
    lmp.command(f"timestep {dt:.9g}")
    lmp.command("thermo 0")
    return dt


def _local(lmp, name: str) -> np.ndarray:
    """Live view of per-atom property ``name`` for the local atoms only (LAMMPS may append ghost atoms)."""
    return lmp.numpy.extract_atom(name)[: lmp.extract_global("nlocal")]


def _run_chunks(lmp, nsteps: int, st: SceneSettings, rho0: float, history_every: int = 0,
                loose_rho_min: float | None = None, before_chunk: Callable[[], None] | None = None) -> dict:
    """Run ``nsteps`` in chunks, resetting solid velocity and density between chunks (and, with
    ``st.loose_ceiling``, capping the density of loose liquid, not below ``loose_rho_min``: the liquid's Tait
    reference density). ``before_chunk`` is called before every chunk (to set per-atom forces, say).

    Returns wall time, particle-steps per second, the largest liquid speed and density range over the run and
    at its end (``*_final``); with ``history_every`` > 0 chunks also ``history``: rows (step, vmax, rho_min,
    rho_max) every that many chunks.
    """
    lmp.command("run 0 post no")
    n_local = lmp.extract_global("nlocal")
    vmax, rho_lo, rho_hi, history = 0.0, np.inf, -np.inf, []
    nchunks = max(1, nsteps // st.chunk)
    t0 = time.perf_counter()
    for k in range(nchunks):
        if before_chunk is not None:
            before_chunk()
        lmp.command(f"run {st.chunk} pre no post no")
        if lmp.extract_global("nlocal") != n_local:
            raise RuntimeError(f"particles left the box after {(k + 1) * st.chunk} steps: the scene blew up")
        # LAMMPS sorts the local atoms spatially every 1000 steps: masks are taken afresh after every chunk
        solid = _local(lmp, "type") == SOLID
        liq = ~solid
        v = _local(lmp, "v")
        rho = _local(lmp, "rho")
        v[solid] = 0.0
        rho[solid] = rho0
        if st.loose_ceiling:
            if loose_rho_min is None:
                raise ValueError("loose_ceiling needs loose_rho_min (the liquid's Tait reference density)")
            relax_loose_density(rho, _local(lmp, "x"), np.flatnonzero(liq), st.dx, rho0, loose_rho_min,
                                st.chunk, st.loose_d3, st.loose_smoothing)
        v_now = float(np.sqrt((v[liq] ** 2).sum(axis=1)).max())
        lo, hi = float(rho[liq].min()) / rho0, float(rho[liq].max()) / rho0
        vmax, rho_lo, rho_hi = max(vmax, v_now), min(rho_lo, lo), max(rho_hi, hi)
        if history_every and (k + 1) % history_every == 0:
            history.append(((k + 1) * st.chunk, v_now, lo, hi))
    wall = time.perf_counter() - t0
    n = lmp.get_natoms()
    out = {
        "wall_s": wall,
        "steps": nchunks * st.chunk,
        "particles": n,
        "particle_steps_per_s": n * nchunks * st.chunk / wall,
        "vmax_m_s": vmax,
        "rho_min_rel": rho_lo,
        "rho_max_rel": rho_hi,
        "vmax_final_m_s": v_now,
        "rho_min_final_rel": lo,
        "rho_max_final_rel": hi,
    }
    if history_every:
        out["history"] = history
    return out


def _liquid_state(lmp, mat: Material, model: CohesionModel, st: SceneSettings, n_avg: int) -> dict:
    """Liquid positions and pressures averaged over the next ``n_avg`` steps (run here, in chunks).

    ``p_eos`` is the Tait pressure of the time-averaged density with the shifted reference density, minus the
    background pressure -P_pair (so 0 in a bulk at the lattice state); ``p_virial`` is the time-averaged
    per-atom pair virial pressure (SPH plus cohesive forces) with volume m / rho. Positions are the final ones;
    ``stats`` are the run statistics of the averaging window.
    """
    n_avg = max(st.chunk, n_avg // st.chunk * st.chunk)
    lmp.command("reset_timestep 0")  # fix ave/atom reports on multiples of n_avg
    lmp.command("compute vir all stress/atom NULL virial")
    lmp.command("compute rhoa all sph/rho/atom")
    lmp.command(f"fix avg all ave/atom 1 {n_avg} {n_avg} c_vir[1] c_vir[2] c_vir[3] c_rhoa")
    stats = _run_chunks(lmp, n_avg, st, mat.rho, loose_rho_min=model.tait_rho0(mat, st.c0))
    liq = _local(lmp, "type") == LIQUID
    avg = np.array(lmp.numpy.extract_fix("avg", 1, 2)[: len(liq)][liq])
    rho = avg[:, 3]
    rho0 = model.tait_rho0(mat, st.c0)
    b = rho0 * st.c0**2 / 7.0
    return {
        "x": np.array(_local(lmp, "x")[liq]),
        "rho": rho,
        "p_eos": b * ((rho / rho0) ** 7 - 1.0) + model.pair_pressure(),
        # stress/atom holds -p V per atom (pressure * volume); volume per particle = m / rho
        "p_virial": -avg[:, :3].sum(axis=1) / 3.0 / (mat.rho * st.dx**3 / rho),
        "stats": stats,
    }


def _model(mat: Material, st: SceneSettings, strength: float | None, wetting_ratio: float) -> CohesionModel:
    """CohesionModel for the scene; ``strength`` overrides s_ll (N) for calibration runs."""
    backend = "table" if st.backend == "none" else st.backend
    model = CohesionModel.from_material(mat, st.dx, wetting_ratio=wetting_ratio, backend=backend)
    return model if strength is None else model.with_strength(strength)


def free_drop(
    material: str | Material = "Ti-Gr2",
    radius: float = 1.5e-3,
    t_end: float = 4e-3,
    t_average: float = 2e-3,
    strength: float | None = None,
    settings: SceneSettings | None = None,
    log: str | None = None,
    history_every: int = 0,
) -> dict:
    """Relax a spherical liquid drop in vacuum (no gravity) and measure its Laplace pressure.

    Parameters
    ----------
    material : str or Material
        Material key or object (rho, cp, surface_tension, ...).
    radius : float
        Radius of the initial sphere cut from the lattice, m.
    t_end : float
        Relaxation time, s.
    t_average : float
        Averaging time after relaxation, s.
    strength : float, optional
        s_ll, N; default: sized by the calibration for the material's surface tension.
    settings : SceneSettings, optional
        Numerical settings.
    log : str, optional
        LAMMPS log file.
    history_every : int
        Record (step, vmax, rho range) every this many chunks (0 = no history).

    Returns
    -------
    dict
        ``radius_m`` (equivalent radius from the particle volume), ``laplace_eos_Pa`` and ``laplace_virial_Pa``
        (mean Tait pressure / mean virial pressure of particles deeper than h below the surface; outside is
        vacuum, p = 0), ``laplace_analytic_Pa`` (2 sigma / R with the model's nominal sigma), ``sigma_eos_N_m``
        (= laplace_eos * R / 2), ``s_ll_N``, ``roundness`` (:func:`roundness`),
        ``dt_s`` and the run statistics of :func:`_run_chunks`.
    """
    mat = get_material(material) if isinstance(material, str) else material
    st = settings or SceneSettings()
    model = _model(mat, st, strength, 1.0)
    lmp = new_lammps(log=log)
    try:
        half = radius + 3 * model.h
        _setup(lmp, st, (half, half, half))
        lmp.command(f"region drop sphere 0 0 0 {radius:.9g} units box")
        lmp.command(f"create_atoms {LIQUID} region drop")
        dt = _finish_setup(lmp, mat, model, st)
        stats = _run_chunks(lmp, int(round(t_end / dt)), st, mat.rho, history_every,
                            loose_rho_min=model.tait_rho0(mat, st.c0))
        state = _liquid_state(lmp, mat, model, st, int(round(t_average / dt)))
        stats.update({k: v for k, v in state["stats"].items() if "_final_" in k})  # end of the averaging
    finally:
        lmp.close()
    x = state["x"] - state["x"].mean(axis=0)
    n = len(x)
    r_eq = (3 * n * st.dx**3 / (4 * math.pi)) ** (1 / 3)
    core = np.linalg.norm(x, axis=1) < r_eq - model.h
    p_eos = float(state["p_eos"][core].mean())
    return {
        "radius_m": r_eq,
        "n_liquid": n,
        "n_core": int(core.sum()),
        "laplace_eos_Pa": p_eos,
        "laplace_eos_std_Pa": float(state["p_eos"][core].std()),
        "laplace_virial_Pa": float(state["p_virial"][core].mean()),
        "laplace_analytic_Pa": 2 * model.sigma / r_eq if strength is None else float("nan"),
        "sigma_eos_N_m": p_eos * r_eq / 2,
        "s_ll_N": model.s_ll,
        "roundness": roundness(x, st.dx),
        "dt_s": dt,
        **stats,
    }


def roundness(x: np.ndarray, dx: float, directions: int = 500) -> float:
    """Out-of-roundness of a particle cloud centred at the origin: (max - min) / mean of its support function
    max_i(x_i . n) + dx / 2 over ``directions`` quasi-uniform unit vectors n (0 for a sphere; 0.73 for a cube).
    """
    k = np.arange(directions) + 0.5
    polar = np.arccos(1 - 2 * k / directions)
    azim = np.pi * (1 + 5**0.5) * k
    n = np.c_[np.sin(polar) * np.cos(azim), np.sin(polar) * np.sin(azim), np.cos(polar)]
    support = (x @ n.T).max(axis=0) + dx / 2
    return float((support.max() - support.min()) / support.mean())


def cap_angle_from_surface(x: np.ndarray, dx: float, z_min: float | None = None) -> tuple[float, float]:
    """Contact angle (degree) and radius (m) of the sphere fitted to the free-surface particles of a drop
    resting on the plane z = 0.

    Surface particles are those with fewer than 3/4 of the 90th-percentile number of neighbours within 2.5 dx
    (a bulk particle has ~65-80, one on a flat surface about half); only those above ``z_min`` (default 1.5 dx, which leaves out the first layer and any precursor film)
    enter an algebraic least-squares sphere fit, whose radius is then enlarged by dx / 2 (a particle fills
    dx / 2 beyond its centre). With the centre at height z0, cos(theta) = -z0 / R.
    """
    z_min = 1.5 * dx if z_min is None else z_min
    counts = np.array([len(n) for n in cKDTree(x).query_ball_point(x, 2.5 * dx)])
    pts = x[(counts < 0.75 * np.percentile(counts, 90)) & (x[:, 2] > z_min)]
    a = np.c_[2 * pts, np.ones(len(pts))]
    sol, *_ = np.linalg.lstsq(a, (pts**2).sum(axis=1), rcond=None)
    centre = sol[:3]
    radius = math.sqrt(sol[3] + centre @ centre) + dx / 2
    return math.degrees(math.acos(np.clip(-centre[2] / radius, -1.0, 1.0))), radius


def cap_angle_from_centroid(volume: float, z_centroid: float) -> float:
    """Contact angle (degree) of the spherical cap of ``volume`` (m3) whose centroid sits ``z_centroid`` (m)
    above its base.

    A cap of a sphere of radius R with contact angle theta (c = cos theta) has height H = R (1 - c), volume
    V = pi R^3 (2 - 3c + c^3) / 3 and its centroid 3 (2R - H)^2 / (4 (3R - H)) from the sphere centre, i.e.
    that minus (R - H) above the base; the equation z_c(theta) = ``z_centroid`` is solved by bisection.
    """

    def z_of(theta: float) -> float:
        c = math.cos(theta)
        shape = (2 - 3 * c + c**3) / 3
        big_r = (volume / (math.pi * shape)) ** (1 / 3)
        h = big_r * (1 - c)
        return 3 * (2 * big_r - h) ** 2 / (4 * (3 * big_r - h)) - (big_r - h)

    lo, hi = 1e-3, math.pi - 1e-3
    if z_centroid <= z_of(lo):
        return 0.0  # flatter than any cap: a spreading film
    return math.degrees(brentq(lambda t: z_of(t) - z_centroid, lo, hi))


def sessile_drop(
    material: str | Material = "Ti-Gr2",
    wetting_ratio: float = 1.0,
    radius: float = 2.1e-3,
    plate_half_width: float = 5.1e-3,
    plate_layers: int = 4,
    gravity: float = 0.0,
    initial_angle_deg: float = 90.0,
    initial_spacing: float = 1.0,
    t_end: float = 0.02,
    t_average: float = 1e-3,
    strength: float | None = None,
    settings: SceneSettings | None = None,
    log: str | None = None,
    history_every: int = 0,
) -> dict:
    """Relax a hemispherical drop on a frozen plate and measure its contact angle.

    The plate (type 2, ``plate_layers`` layers, top layer centred at z = -dx/2 so its surface is z = 0) is held
    by ``fix setforce``; the liquid (type 1) starts as a spherical cap, by default the upper half of a sphere of
    ``radius`` (90 degrees).

    Parameters
    ----------
    material : str or Material
        Material key or object.
    wetting_ratio : float
        s_ls / s_ll.
    radius : float
        Radius of the initial hemisphere, m.
    plate_half_width : float
        Half width of the square plate, m.
    plate_layers : int
        Particle layers of the plate.
    gravity : float
        Gravitational acceleration on the liquid, m s-2 (0 keeps the cap exactly spherical).
    initial_angle_deg : float
        Contact angle of the initial spherical cap (same volume as the hemisphere of ``radius``); starting
        below the final angle measures a receding angle, above it an advancing one.
    initial_spacing : float
        Lattice spacing of the initial cap in units of dx (above 1: loosely packed liquid at density rho).
    t_end : float
        Relaxation time, s.
    t_average : float
        Averaging time after relaxation, s.
    strength : float, optional
        s_ll, N; default sized from the material's surface tension.
    settings : SceneSettings, optional
        Numerical settings.
    log : str, optional
        LAMMPS log file.
    history_every : int
        Record (step, vmax, rho range) every this many chunks (0 = no history).

    Returns
    -------
    dict
        ``angle_centroid_deg`` (from volume and centroid height), ``angle_height_deg``
        (2 atan(H / a) from the top height H and the base radius a of a cap with the drop's volume),
        ``angle_deg`` (sphere fitted to the free surface above 1.5 dx, :func:`cap_angle_from_surface`; the
        primary measure), ``packing_ratio`` (the volume under the drop's height map, top particle + dx/2 per
        dx-wide column as in :func:`beadsim.sph.surface.height_map`, over n dx^3: ~0.95 for a drop packed like
        the lattice, more for a loose one), ``height_m``, ``base_radius_m``, ``n_liquid`` and
        ``n_liquid_initial`` (atoms lost
        through the plate or the box show as a difference), ``x_liquid_m`` (final liquid positions),
        ``wetting_ratio`` and the run statistics.
    """
    mat = get_material(material) if isinstance(material, str) else material
    st = settings or SceneSettings()
    model = _model(mat, st, strength, wetting_ratio)
    dx = st.dx
    lmp = new_lammps(log=log)
    try:
        top = radius * 1.6 + 2 * model.h
        _setup(lmp, st, (plate_half_width, plate_half_width, top))
        # lattice sites sit at integer multiples of dx: shift by dx/2 in z so the plate surface is z = 0
        lmp.command(f"lattice sc {dx:.6g} origin 0 0 0.5")
        lmp.command(
            f"region plate block {-plate_half_width:.9g} {plate_half_width:.9g} {-plate_half_width:.9g} "
            f"{plate_half_width:.9g} {-plate_layers * dx:.9g} 0 units box"
        )
        lmp.command(f"create_atoms {SOLID} region plate")
        # initial cap with contact angle initial_angle_deg and the volume of the hemisphere of ``radius``
        c = math.cos(math.radians(initial_angle_deg))
        cap_r = radius * (2 / (2 - 3 * c + c**3)) ** (1 / 3)
        lmp.command(f"region cap sphere 0 0 {-cap_r * c:.9g} {cap_r:.9g} side in units box")
        lmp.command("region upper block INF INF INF INF 0 INF units box")
        lmp.command("region hemi intersect 2 cap upper")
        if initial_spacing != 1.0:
            lmp.command(f"lattice sc {initial_spacing * dx:.6g} origin 0 0 0.5")
        lmp.command(f"create_atoms {LIQUID} region hemi")
        dt = _finish_setup(lmp, mat, model, st)
        n_initial = int((_local(lmp, "type") == LIQUID).sum())
        if gravity:
            lmp.command(f"fix grav liquid gravity {gravity} vector 0 0 -1")
        stats = _run_chunks(lmp, int(round(t_end / dt)), st, mat.rho, history_every,
                            loose_rho_min=model.tait_rho0(mat, st.c0))
        state = _liquid_state(lmp, mat, model, st, int(round(t_average / dt)))
        stats.update({k: v for k, v in state["stats"].items() if "_final_" in k})  # end of the averaging
    finally:
        lmp.close()
    x = state["x"]
    volume = float((mat.rho * dx**3 / state["rho"]).sum())
    z_c = float(x[:, 2].mean())
    height = float(x[:, 2].max()) + dx / 2
    theta_c = cap_angle_from_centroid(volume, z_c)
    theta_s, sphere_r = cap_angle_from_surface(x, dx)
    tops, _, _ = _column_table(x, dx, None, x[:, 2] + 0.5 * dx, np.maximum)
    packing = float(tops[np.isfinite(tops)].sum() * dx**2 / (len(x) * dx**3))
    # base radius of the cap with this volume and height: V = pi H (3 a^2 + H^2) / 6
    a2 = (6 * volume / (math.pi * height) - height**2) / 3
    base = math.sqrt(max(a2, 0.0))
    return {
        "wetting_ratio": wetting_ratio,
        "angle_deg": theta_s,
        "packing_ratio": packing,
        "sphere_radius_m": sphere_r,
        "angle_centroid_deg": theta_c,
        "angle_height_deg": math.degrees(2 * math.atan2(height, base)),
        "height_m": height,
        "base_radius_m": base,
        "volume_m3": volume,
        "n_liquid": len(x),
        "n_liquid_initial": n_initial,
        "dt_s": dt,
        "s_ll_N": model.s_ll,
        "x_liquid_m": x,
        **stats,
    }


def segment_angle(area: float, height: float) -> float:
    """Contact angle (degree) of the circular segment with cross-section ``area`` and ``height`` (a ridge's
    cap): with base width w = 2 H / tan(t / 2) and A = w^2 :func:`beadsim.reduced.cap_shape` (t),
    A / H^2 = (t - sin t cos t) / (1 - cos t)^2, solved for t. The ratio falls from infinity (a flat film) to
    pi / 4 (a whole disc, t = 180 deg); nan below that."""
    def excess(t: float) -> float:
        return 4 * cap_shape(t) / math.tan(t / 2) ** 2 - area / height**2

    lo, hi = 1e-3, math.pi - 1e-3
    if excess(lo) * excess(hi) > 0:
        return float("nan")
    return math.degrees(brentq(excess, lo, hi))


def sessile_ridge(
    material: str | Material = "Ti-Gr2",
    wetting_ratio: float = 0.8,
    width_cells: int = 8,
    layers: int = 3,
    length_cells: int = 6,
    plate_half_cells: int = 12,
    gravity: float = 9.81,
    t_end: float = 0.1,
    t_start: float = 0.05,
    sample_every: float = 0.01,
    settings: SceneSettings | None = None,
    log: str | None = None,
    surface_force: str = "pairwise",
    wetting_deg: float = 60.0,
    smooth_cells: float = 1.0,
    cohesion_share: float = 0.0,
) -> dict:
    """A liquid ridge on a frozen plate, periodic along y (the bead's direction), started as a rectangle of
    ``width_cells`` x ``layers`` spacings: the cross-section it relaxes to and its contact angle.

    Unlike the sessile drop, whose contact line crosses the plate's lattice at every orientation, the ridge's
    two contact lines run along a lattice row, as a bead's flanks do in the moving window. The cross-section
    is the y-averaged height map (top particle + dx / 2 per dx-wide column, empty columns as 0); its apparent
    contact angle is that of the circular segment with the same area and height (:func:`segment_angle`),
    sampled every ``sample_every`` from ``t_start`` to ``t_end``.

    ``surface_force`` "height_function" replaces the cohesion by the bead driver's height-function surface
    force (:mod:`beadsim.sph.heightfn`) on a plain SPH liquid (Tait at rho, no cohesion): set contact angle
    ``wetting_deg``, map smoothing ``smooth_cells``, forces held over each chunk; ``wetting_ratio`` is then
    unused unless ``cohesion_share`` > 0: then the pairwise cohesion (at ``wetting_ratio``) carries that share of
    sigma and the height function the rest (the driver's ``height_function_cohesion``).

    Returns
    -------
    dict
        ``angle_deg`` and ``angle_sd_deg`` (mean and standard deviation of the samples), ``height_m``,
        ``width_m``, ``area_m2`` and ``arc_angle_deg`` (means of the samples, by
        :func:`beadsim.sph.surface.profile_metrics` as for a bead's sections; the arc angle is the bead
        metrics' ``contact_angle_deg``), ``profile_m`` (the last height map across x), ``angles_deg`` (the
        samples) and the run statistics of the last stretch.
    """
    mat = get_material(material) if isinstance(material, str) else material
    st = settings or SceneSettings()
    if surface_force not in ("pairwise", "height_function"):
        raise ValueError(f"surface_force {surface_force!r}: allowed pairwise, height_function")
    height_function = surface_force == "height_function"
    sigma_hf = mat.surface_tension * (1.0 - cohesion_share)
    if height_function and cohesion_share > 0:
        mat = dataclasses.replace(mat, surface_tension=mat.surface_tension * cohesion_share)
    elif height_function:
        st = dataclasses.replace(st, backend="none")
    model = _model(mat, st, None, wetting_ratio)
    dx = st.dx
    lmp = new_lammps(log=log)
    samples = []
    try:
        half_x, half_y = plate_half_cells * dx, length_cells * dx / 2
        _setup(lmp, st, (half_x, half_y, (layers + 4) * dx + 3 * model.h), boundary="f p f")
        lmp.command(f"lattice sc {dx:.6g} origin 0.5 0.5 0.5")
        lmp.command(f"region plate block INF INF INF INF {-3 * dx:.9g} 0 units box")
        lmp.command(f"create_atoms {SOLID} region plate")
        a = width_cells * dx / 2
        lmp.command(f"region ridge block {-a:.9g} {a:.9g} INF INF 0 {layers * dx:.9g} units box")
        lmp.command(f"create_atoms {LIQUID} region ridge")
        dt = _finish_setup(lmp, mat, model, st)
        if gravity:
            lmp.command(f"fix grav liquid gravity {gravity} vector 0 0 -1")
        apply = None
        if height_function:
            lmp.command("fix hfstore all property/atom d_hfx d_hfy d_hfz ghost no")
            for c in "xyz":
                lmp.command(f"variable hf{c} atom d_hf{c}")
            lmp.command("fix hf all addforce v_hfx v_hfy v_hfz")
            grid = ColumnGrid(-half_x, -half_y, dx, 2 * plate_half_cells, length_cells, periodic_y=True)

            def apply() -> None:  # masks afresh: LAMMPS sorts atoms
                x = np.array(_local(lmp, "x"))
                f, _ = height_function_forces(x, _local(lmp, "type") == LIQUID, grid, sigma_hf,
                                              smooth_cells, wetting_deg=wetting_deg)
                for k, c in enumerate("xyz"):
                    lmp.numpy.extract_atom(f"d_hf{c}")[: len(x)] = f[:, k]
        n_every = max(st.chunk, int(round(sample_every / dt)) // st.chunk * st.chunk)
        rho_min = model.tait_rho0(mat, st.c0) if st.backend != "none" else mat.rho
        x_centres = (np.arange(2 * plate_half_cells) - plate_half_cells + 0.5) * dx
        t = 0.0
        while t < t_end - 1e-12:
            stats = _run_chunks(lmp, n_every, st, mat.rho, loose_rho_min=rho_min, before_chunk=apply)
            t += n_every * dt
            if t < t_start - 1e-12:
                continue
            liquid = _local(lmp, "type") == LIQUID
            x = np.array(_local(lmp, "x")[liquid])
            # fixed dx-wide bins: x on the plate's columns, y on the periodic length (estimating the lattice
            # phase from the moving liquid, as for a bead, can split the periodic length into one bin more)
            ix = np.floor(x[:, 0] / dx).astype(int) + plate_half_cells
            iy = np.floor((x[:, 1] + half_y) / dx).astype(int) % length_cells
            tops = np.zeros((2 * plate_half_cells, length_cells))
            np.maximum.at(tops, (np.clip(ix, 0, 2 * plate_half_cells - 1), iy), x[:, 2] + 0.5 * dx)
            profile = tops.mean(axis=1)
            bead = profile_metrics(x_centres, profile, dx)  # as for a bead's sections
            area, height = bead["bead_area_mm2"] * 1e-6, bead["bead_height_mm"] * 1e-3
            samples.append((segment_angle(area, height), height, bead["bead_width_mm"] * 1e-3, area,
                            bead["contact_angle_deg"]))
    finally:
        lmp.close()
    arr = np.array(samples)
    return {
        "wetting_ratio": wetting_ratio,
        "angle_deg": float(np.nanmean(arr[:, 0])),
        "angle_sd_deg": float(np.nanstd(arr[:, 0])),
        "angles_deg": arr[:, 0],
        "height_m": float(arr[:, 1].mean()),
        "width_m": float(arr[:, 2].mean()),
        "area_m2": float(arr[:, 3].mean()),
        "arc_angle_deg": float(np.nanmean(arr[:, 4])),
        "profile_m": profile,
        "n_liquid": int(liquid.sum()),
        "dt_s": dt,
        **stats,
    }


def slab_tension(
    material: str | Material = "Ti-Gr2",
    strength: float | None = None,
    layers: int = 12,
    width_cells: int = 8,
    t_equil: float = 1.5e-3,
    t_measure: float = 1.5e-3,
    settings: SceneSettings | None = None,
    log: str | None = None,
) -> dict:
    """Surface tension of a liquid slab (periodic in x and y, two free surfaces normal to z), virial route.

    sigma = (L_z / 2) * (P_zz - (P_xx + P_yy) / 2), with the pair virial pressure tensor P of the whole box
    (SPH and cohesive pair forces, no kinetic part) averaged every step over ``t_measure`` after ``t_equil``
    (Kirkwood and Buff 1949).

    Parameters
    ----------
    material : str or Material
        Material key or object.
    strength : float, optional
        s_ll, N; default sized by the calibration for the material's surface tension.
    layers : int
        Particle layers of the slab.
    width_cells : int
        Periodic box width in particle spacings (must exceed 2 h / dx).
    t_equil, t_measure : float
        Equilibration and averaging times, s.
    settings : SceneSettings, optional
        Numerical settings.
    log : str, optional
        LAMMPS log file.

    Returns
    -------
    dict
        ``sigma_N_m`` (measured), ``sigma_nominal_N_m`` (what the model was sized for), ``c_sigma``
        (= sigma dx / s), ``s_ll_N``, ``rho_mean_rel`` and the run statistics.
    """
    mat = get_material(material) if isinstance(material, str) else material
    st = settings or SceneSettings()
    model = _model(mat, st, strength, 1.0)
    dx = st.dx
    half_xy = width_cells * dx / 2
    half_z = layers * dx / 2 + 3 * model.h
    lmp = new_lammps(log=log)
    try:
        _setup(lmp, st, (half_xy, half_xy, half_z), boundary="p p f")
        lmp.command(f"lattice sc {dx:.6g} origin 0.5 0.5 0.5")
        lmp.command(f"region slab block INF INF INF INF {-layers * dx / 2:.9g} {layers * dx / 2:.9g} units box")
        lmp.command(f"create_atoms {LIQUID} region slab")
        dt = _finish_setup(lmp, mat, model, st)
        _run_chunks(lmp, int(round(t_equil / dt)), st, mat.rho)
        n_meas = max(st.chunk, int(round(t_measure / dt)) // st.chunk * st.chunk)
        lmp.command("compute pvir all pressure NULL virial")
        lmp.command(f"fix pavg all ave/time 1 {n_meas} {n_meas} c_pvir[1] c_pvir[2] c_pvir[3]")
        lmp.command("run 0 post no")
        stats = _run_chunks(lmp, n_meas, st, mat.rho)
        pxx, pyy, pzz = (lmp.numpy.extract_fix("pavg", 0, 1, nrow=i) for i in range(3))
        rho = _local(lmp, "rho")
        rho_mean = float(np.mean(rho) / mat.rho)
    finally:
        lmp.close()
    sigma = 2 * half_z / 2 * (pzz - (pxx + pyy) / 2)
    return {
        "sigma_N_m": float(sigma),
        "sigma_nominal_N_m": model.sigma if strength is None else float("nan"),
        "c_sigma": float(sigma * dx / model.s_ll),
        "s_ll_N": model.s_ll,
        "rho_mean_rel": rho_mean,
        "dt_s": dt,
        **stats,
    }


def _column_tops(x: np.ndarray, dx: float) -> np.ndarray:
    """Mask of the highest particle of each dx-wide (x, y) column."""
    col = np.floor(x[:, :2] / dx).astype(np.int64)
    col -= col.min(axis=0)
    key = col[:, 0] * (col[:, 1].max() + 1) + col[:, 1]
    order = np.lexsort((x[:, 2], key))
    last = np.r_[key[order][1:] != key[order][:-1], True]
    top = np.zeros(len(x), dtype=bool)
    top[order[last]] = True
    return top


def film_surface_speed(tau: float, mu: float, k: float, depth: float) -> float:
    """Surface speed amplitude (m s-1) of a Stokes film of ``depth`` d on a no-slip plate, periodic along x,
    with a flat free surface (no normal flow) carrying the shear stress ``tau`` sin(k x).

    Stream function psi = f(z) sin(k x), u = f'(z) sin(k x), w = -k f(z) cos(k x), with
    f = (A + B z) cosh(k z) + (C + D z) sinh(k z) (the biharmonic equation); f(0) = f'(0) = 0 (plate),
    f(d) = 0 (flat surface), mu f''(d) = tau (shear stress). Limits: tau d / (4 mu) for k d -> 0 (lubrication
    with no net flux), tau / (2 mu k) for k d -> infinity (a half-space).
    """
    def basis(z: float) -> tuple[np.ndarray, np.ndarray, np.ndarray]:  # f, f', f'' of the four terms
        c, s = math.cosh(k * z), math.sinh(k * z)
        return (np.array([c, z * c, s, z * s]),
                np.array([k * s, c + k * z * s, k * c, s + k * z * c]),
                np.array([k * k * c, 2 * k * s + k * k * z * c, k * k * s, 2 * k * c + k * k * z * s]))

    f0, df0, _ = basis(0.0)
    fd, dfd, ddfd = basis(depth)
    coef = np.linalg.solve(np.array([f0, df0, fd, mu * ddfd]), np.array([0.0, 0.0, 0.0, tau]))
    return float(dfd @ coef)


def surface_traction_film(
    material: str | Material = "Ti-Gr2",
    traction: float = 600.0,
    cohesion: bool = True,
    gravity: float = 500.0,
    length_cells: int = 16,
    width_cells: int = 6,
    layers: int = 6,
    plate_layers: int = 3,
    t_develop: float = 0.01,
    t_average: float = 5e-3,
    initial_spacing: float = 1.0,
    settings: SceneSettings | None = None,
    log: str | None = None,
) -> dict:
    """Does the melt flow under a shear stress on its surface? A liquid film on a frozen plate, periodic in x
    and y, with a tangential traction tau(x) = ``traction`` sin(k x), k = 2 pi / L, on its free surface.

    The traction stands for a Marangoni stress (d sigma / dT times the surface temperature gradient; about
    0.16 mN m-1 K-1 x 1000 K / 2 mm ~ 80 Pa in a Ti pool). It is applied each chunk as a force tau dx^2 on the
    highest liquid particle of every dx-wide column, wherever the surface has moved. A Newtonian film of depth
    d on a no-slip plate, with no net flux along x (periodic), circulates with surface speed
    u_s = tau d / (4 mu) (lubrication). With the artificial viscosity, mu ~ rho alpha c0 h / 8 (the driver's
    estimate, not a calibrated viscosity: u_s is an order-of-magnitude reference). The film is not thin at the
    defaults (k d = 2.36): the Stokes solution of the same film with a flat surface
    (:func:`film_surface_speed`, returned as ``u_stokes``) gives 0.73 u_s (0.91 at 3 layers, 0.42 at 12), so
    the plain film's low ratios are not an artefact of the lubrication approximation.

    ``initial_spacing`` (in dx, above 1: a loosely packed film at density rho, as melt spread without the
    driver's loose_melt_ceiling) sets the film's lattice; L and the film's depth stay ``layers`` dx.
    ``cohesion`` False gives the plain SPH liquid (Tait at rho0), which needs ``gravity`` (m s-2, on the
    liquid) to stay on the plate; the same gravity is applied with cohesion so that the two differ only in it.

    Returns
    -------
    dict
        ``u_top``: sine coefficient (m s-1) of the time-averaged x velocity of the column tops (u(x) ~ u_top
        sin(k x); positive = along the traction), ``u_bottom`` the same for the liquid layer on the plate,
        ``u_lubrication`` (u_s), ``flow_ratio`` (u_top / u_s), ``u_stokes`` (:func:`film_surface_speed`
        with the same mu), ``mu_estimate_Pa_s``,
        ``traction_over_sigma_dx`` (traction / (sigma / dx), the scale of the cohesive stresses) and the run
        statistics.
    """
    mat = get_material(material) if isinstance(material, str) else material
    st = settings or SceneSettings()
    if not cohesion:
        st = dataclasses.replace(st, backend="none")
    model = _model(mat, st, None, 1.0)
    dx = st.dx
    half_x, half_y, depth = length_cells * dx / 2, width_cells * dx / 2, layers * dx
    k = 2 * math.pi / (2 * half_x)
    lmp = new_lammps(log=log)
    try:
        _setup(lmp, st, (half_x, half_y, depth + plate_layers * dx + 3 * model.h), boundary="p p f")
        lmp.command(f"lattice sc {dx:.6g} origin 0.5 0.5 0.5")
        lmp.command(f"region plate block INF INF INF INF {-plate_layers * dx:.9g} 0 units box")
        lmp.command(f"region film block INF INF INF INF 0 {depth:.9g} units box")
        lmp.command(f"create_atoms {SOLID} region plate")
        if initial_spacing != 1.0:
            a = initial_spacing * dx
            lmp.command(f"lattice custom {a:.9g} a1 {2 * half_x / round(2 * half_x / a) / a:.9g} 0 0 "
                        f"a2 0 {2 * half_y / round(2 * half_y / a) / a:.9g} 0 a3 0 0 1 basis 0.5 0.5 0.5")
        lmp.command(f"create_atoms {LIQUID} region film")
        dt = _finish_setup(lmp, mat, model, st)
        if gravity:
            lmp.command(f"fix grav liquid gravity {gravity} vector 0 0 -1")
        lmp.command("fix traction_store all property/atom d_traction ghost no")
        lmp.command("variable traction_fx atom d_traction")
        lmp.command("fix traction all addforce v_traction_fx 0 0")

        def apply_traction() -> None:  # on the column tops of the moment (masks afresh: LAMMPS sorts atoms)
            x = _local(lmp, "x")
            top = _column_tops(x, dx) & (_local(lmp, "type") != SOLID)
            lmp.numpy.extract_atom("d_traction")[: len(x)] = np.where(
                top, traction * dx * dx * np.sin(k * x[:, 0]), 0.0)

        develop = _run_chunks(lmp, int(round(t_develop / dt)), st, mat.rho, before_chunk=apply_traction)
        n_avg = max(st.chunk, int(round(t_average / dt)) // st.chunk * st.chunk)
        lmp.command("reset_timestep 0")  # fix ave/atom reports on multiples of n_avg
        lmp.command(f"fix vavg all ave/atom 1 {n_avg} {n_avg} vx")
        average = _run_chunks(lmp, n_avg, st, mat.rho, before_chunk=apply_traction)
        solid = _local(lmp, "type") == SOLID
        x = np.array(_local(lmp, "x")[~solid])
        vx = np.array(lmp.numpy.extract_fix("vavg", 1, 1)[: len(solid)][~solid])
    finally:
        lmp.close()

    def sine_coefficient(sel: np.ndarray) -> float:
        return float(2 * np.mean(vx[sel] * np.sin(k * x[sel, 0])))

    mu = mat.rho * st.alpha * st.c0 * model.h / 8
    u_s = traction * depth / (4 * mu)
    u_top = sine_coefficient(_column_tops(x, dx))
    return {
        "u_top": u_top,
        "u_bottom": sine_coefficient(x[:, 2] < 0.75 * dx),
        "u_lubrication": u_s,
        "flow_ratio": u_top / u_s,
        "u_stokes": film_surface_speed(traction, mu, k, depth),
        "mu_estimate_Pa_s": mu,
        "traction_over_sigma_dx": traction * dx / mat.surface_tension,
        "dt_s": dt,
        "wall_s": develop["wall_s"] + average["wall_s"],
        "vmax_m_s": max(develop["vmax_m_s"], average["vmax_m_s"]),
        "particles": average["particles"],
    }


def cellular_flow(
    material: str | Material = "Ti-Gr2",
    stress: float = 300.0,
    liquid: str = "cohesive",
    pattern: str = "cells",
    cells: int = 16,
    depth_cells: int = 6,
    t_develop: float = 0.02,
    t_average: float = 5e-3,
    settings: SceneSettings | None = None,
    log: str | None = None,
) -> dict:
    """Does the bulk liquid flow where the particles must rearrange? A periodic box of liquid (``cells`` dx
    along x and z, ``depth_cells`` along y, no free surface, no solid) under a steady body force of stress
    scale ``stress`` = rho F / k, k = 2 pi / (``cells`` dx), F the force per mass.

    ``pattern="cells"``: Taylor-Green cells, F (sin kx cos kz, 0, -cos kx sin kz). The flow stretches and
    compresses fluid elements, so particles must change neighbours, as in a Marangoni cell or a spreading
    bead. Stokes solution u = F / (2 nu k^2) times the same pattern.
    ``pattern="shear"``: Kolmogorov flow, F (sin kz, 0, 0). Layers of constant z slide over each other, which a
    simple cubic arrangement allows without rearranging. Stokes solution u = F / (nu k^2) sin kz.

    ``liquid``: ``"plain"`` (Tait at rho), ``"background"`` (plain SPH with the cohesive model's shifted Tait
    reference density, :meth:`CohesionModel.tait_rho0`: the same background pressure, ~7.7 sigma / dx, without
    the cohesion) or ``"cohesive"`` (the bead model's liquid). The reference speed uses the nominal viscosity
    mu = rho alpha c0 h / 8 of :func:`surface_traction_film` (an order-of-magnitude estimate).

    Returns
    -------
    dict
        ``amplitude`` (m s-1, least-squares coefficient of the time-averaged velocity on the Stokes pattern),
        ``u_stokes``, ``flow_ratio`` (their ratio), ``stress_over_sigma_dx``, ``background_pressure_Pa``,
        ``dt_s``, ``wall_s``, ``vmax_m_s``, ``particles``.
    """
    if liquid not in ("plain", "background", "cohesive"):
        raise ValueError(f"liquid must be 'plain', 'background' or 'cohesive', not {liquid!r}")
    if pattern not in ("cells", "shear"):
        raise ValueError(f"pattern must be 'cells' or 'shear', not {pattern!r}")
    mat = get_material(material) if isinstance(material, str) else material
    st = settings or SceneSettings()
    if liquid != "cohesive":
        st = dataclasses.replace(st, backend="none")
    model = _model(mat, st, None, 1.0)
    dx = st.dx
    half = (cells * dx / 2, depth_cells * dx / 2, cells * dx / 2)
    k = 2 * math.pi / (cells * dx)
    lmp = new_lammps(log=log)
    try:
        _setup(lmp, st, half, boundary="p p p")
        lmp.command(f"lattice sc {dx:.6g} origin 0.5 0.5 0.5")
        lmp.command(f"create_atoms {LIQUID} box")
        dt = _finish_setup(lmp, mat, model, st)
        rho0 = mat.rho
        if liquid == "background":  # the cohesive liquid's background pressure, no cohesion
            rho0 = model.tait_rho0(mat, st.c0)
            lmp.command(f"pair_coeff * * sph/taitwater {rho0:.9g} {st.c0} {st.alpha} {model.h:.9g}")
        m_f = mat.rho * dx**3 * stress * k / mat.rho  # force per particle amplitude, m F
        if pattern == "cells":
            lmp.command(f"variable fx atom {m_f:.9g}*sin({k:.9g}*x)*cos({k:.9g}*z)")
            lmp.command(f"variable fz atom {-m_f:.9g}*cos({k:.9g}*x)*sin({k:.9g}*z)")
            lmp.command("fix drive all addforce v_fx 0 v_fz")
        else:
            lmp.command(f"variable fx atom {m_f:.9g}*sin({k:.9g}*z)")
            lmp.command("fix drive all addforce v_fx 0 0")
        develop = _run_chunks(lmp, int(round(t_develop / dt)), st, mat.rho)
        n_avg = max(st.chunk, int(round(t_average / dt)) // st.chunk * st.chunk)
        lmp.command("reset_timestep 0")  # fix ave/atom reports on multiples of n_avg
        lmp.command(f"fix vavg all ave/atom 1 {n_avg} {n_avg} vx vz")
        average = _run_chunks(lmp, n_avg, st, mat.rho)
        x = np.array(_local(lmp, "x"))
        v = np.array(lmp.numpy.extract_fix("vavg", 1, 2)[: len(x)])
    finally:
        lmp.close()
    if pattern == "cells":
        px = np.sin(k * x[:, 0]) * np.cos(k * x[:, 2])
        pz = -np.cos(k * x[:, 0]) * np.sin(k * x[:, 2])
        u_stokes_factor = 0.5
    else:
        px, pz = np.sin(k * x[:, 2]), np.zeros(len(x))
        u_stokes_factor = 1.0
    amplitude = float(np.sum(v[:, 0] * px + v[:, 1] * pz) / np.sum(px**2 + pz**2))
    mu = mat.rho * st.alpha * st.c0 * model.h / 8
    u_stokes = u_stokes_factor * stress / (mu * k)
    return {
        "amplitude": amplitude,
        "u_stokes": u_stokes,
        "flow_ratio": amplitude / u_stokes,
        "stress_over_sigma_dx": stress * dx / mat.surface_tension,
        "background_pressure_Pa": 0.0 if liquid == "plain" else -model.pair_pressure(),
        "dt_s": dt,
        "wall_s": develop["wall_s"] + average["wall_s"],
        "vmax_m_s": max(develop["vmax_m_s"], average["vmax_m_s"]),
        "particles": average["particles"],
    }


def _loop_breakdown(log: Path) -> dict:
    """Pair share of the loop time and average neighbours per atom from the last full run summary in ``log``."""
    text = log.read_text().splitlines()
    pair = [ln for ln in text if ln.startswith("Pair    |")]
    neigh = [ln for ln in text if ln.startswith("Ave neighs/atom")]
    return {
        "pair_fraction": float(pair[-1].split("|")[-1]) / 100 if pair else float("nan"),
        "neighbors_per_particle": float(neigh[-1].split("=")[-1]) if neigh else float("nan"),
    }


def benchmark(
    material: str | Material = "Ti-Gr2",
    cells: tuple[int, int, int] = (30, 30, 6),
    liquid_layers: int = 3,
    nsteps: int = 200,
    cohesion_on_solid_pairs: bool = False,
    settings: SceneSettings | None = None,
) -> dict:
    """Throughput of the pair styles in the bead driver's chunked loop, with or without the cohesive term.

    Scene: a frozen plate of ``cells`` particles (type 2) under ``liquid_layers`` liquid layers (type 1), both
    in ``fix sph``; ``run chunk pre no post no`` repeated, with solid velocity and density reset from Python
    between chunks (as the driver does). A last plain ``run`` of ``chunk`` steps gives LAMMPS' timing summary.

    Parameters
    ----------
    material : str or Material
        Material key or object.
    cells : tuple of int
        Plate size in particles (x, y, z).
    liquid_layers : int
        Liquid layers on top of the plate.
    nsteps : int
        Timed steps (after one untimed chunk).
    cohesion_on_solid_pairs : bool
        Give all type pairs the cohesive sub-style (liquid-liquid strength), so it uses the full neighbour
        list instead of a type-filtered one (to measure what the filtering saves).
    settings : SceneSettings, optional
        Numerical settings; ``backend`` ("none", "table", "lepton") and ``skin`` are the things to vary.

    Returns
    -------
    dict
        The statistics of the timed chunked loop (``particle_steps_per_s``, ``particles``, ``wall_s``, ...),
        ``pair_fraction`` (share of loop time in pair styles) and ``neighbors_per_particle`` (master list).
    """
    mat = get_material(material) if isinstance(material, str) else material
    st = settings or SceneSettings()
    model = _model(mat, st, None, 1.0)
    dx = st.dx
    nx, ny, nz = cells
    tmp = tempfile.TemporaryDirectory()
    log = Path(tmp.name) / "benchmark.log"
    lmp = new_lammps(log=log)
    try:
        _setup(lmp, st, (nx * dx / 2, ny * dx / 2, (nz + liquid_layers + 4) * dx), boundary="p p f")
        lmp.command(f"lattice sc {dx:.6g} origin 0.5 0.5 0.5")
        lmp.command(f"region plate block INF INF INF INF {-nz * dx:.9g} 0 units box")
        lmp.command(f"region pool block INF INF INF INF 0 {liquid_layers * dx:.9g} units box")
        lmp.command(f"create_atoms {SOLID} region plate")
        lmp.command(f"create_atoms {LIQUID} region pool")
        _finish_setup(lmp, mat, model, st, (LIQUID, SOLID) if cohesion_on_solid_pairs else (LIQUID,))
        _run_chunks(lmp, st.chunk, st, mat.rho)
        stats = _run_chunks(lmp, nsteps, st, mat.rho)
        lmp.command(f"run {nsteps} post yes")
    finally:
        lmp.close()
    breakdown = _loop_breakdown(log)
    tmp.cleanup()
    return {**stats, **breakdown}


def calibrate(
    material: str | Material = "Ti-Gr2",
    strength_factors: tuple[float, ...] = (0.7, 1.0, 1.4),
    settings: SceneSettings | None = None,
) -> dict:
    """Measure C_sigma = sigma dx / s with :func:`slab_tension` at several strengths around the nominal one.

    Parameters
    ----------
    material : str or Material
        Material key or object.
    strength_factors : tuple of float
        Multiples of the nominal s_ll (from the current :data:`beadsim.sph.tension.SIGMA_CALIBRATION`).
    settings : SceneSettings, optional
        Numerical settings (dx above all).

    Returns
    -------
    dict
        ``c_sigma`` (mean), ``c_sigma_std`` (spread over strengths), ``runs`` (each run's result).
    """
    mat = get_material(material) if isinstance(material, str) else material
    st = settings or SceneSettings()
    s0 = _model(mat, st, None, 1.0).s_ll
    runs = [slab_tension(mat, strength=f * s0, settings=st) for f in strength_factors]
    c = np.array([r["c_sigma"] for r in runs])
    return {"c_sigma": float(c.mean()), "c_sigma_std": float(c.std()), "runs": runs}
