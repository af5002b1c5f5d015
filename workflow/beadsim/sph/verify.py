"""Small LAMMPS SPH verification scenes against analytic solutions and conservation laws.

Each scene builds a tiny cubic lattice of particles (spacing ``dx``, kernel support ``h = h_factor dx``, Lucy
kernel as hard-coded in the SPH package), runs real LAMMPS through :func:`beadsim.lammps_env.new_lammps`, and
returns a dict of measured and analytic numbers. SI units throughout.

What the SPH package computes (read from its sources, LAMMPS 22Jul2025; confirmed by these scenes):

* ``sph/heatconduction`` with coefficient D (m2/s):
  ``de_i/dt = sum_j 2 m_i m_j/(m_i+m_j) (rho_i+rho_j)/(rho_i rho_j) D (e_i - e_j) W'(r_ij)/r_ij``,
  i.e. the Brookshaw/Cleary Laplacian of ``e`` itself, not of ``T = e/cv``. With equal masses it is the
  same whether ``e`` is read as energy per particle or per unit mass; where masses or ``cv`` differ between
  particles it drives heat along differences of e, not of T.
* ``sph/taitwater`` and ``sph/taitwater/morris`` add their pressure work and viscous heating to ``de/dt`` as
  power per particle (J/s: the increment carries ``m_i m_j``). ``fix sph`` integrates ``e += dt * de/dt``
  without dividing by the mass. Energy is therefore conserved when ``e`` is the energy of the particle (J) and
  ``cv`` its heat capacity ``m cp`` (J/K); if ``e`` is read as J/kg (``cv = cp``) the mechanical heating is
  under-counted by the factor m (kg), i.e. it vanishes. :func:`closed_melt` measures both.
* ``sph/taitwater/morris`` takes the dynamic viscosity mu (Pa s):
  ``dv_i/dt = sum_j m_j 2 mu/(rho_i rho_j) (v_i - v_j) W'/r`` (Morris et al. 1997).
* ``sph/taitwater`` artificial viscosity (Monaghan 1992) acts only between approaching particles, with
  ``Pi_ij = -alpha (c_i + c_j) h (v_ij . r_ij)/((r_ij^2 + 0.01 h^2)(rho_i + rho_j))``, h = cutoff.
  :func:`poiseuille` measures the effective kinematic viscosity it gives in shear flow.

Measured with these scenes (Ti-Gr2, h = 2.5 dx unless said):

* On a cubic lattice the SPH Laplacian (heat conduction and Morris viscosity alike) is 3.2 % weak at
  h = 2.5 dx (4.2 % strong at 2.0 dx, 0.6 % strong at 3.0 dx): :func:`lattice_laplacian_factor`.
* Particles held at a value (reservoir, still walls) impose it at their own centres, not at the mid-plane
  between them and the first free layer.
* Artificial viscosity in shear flow: ``nu_eff = 0.0457 alpha h c0`` (0.043 at h = 2.0 dx, 0.046 at 3.0 dx),
  for alpha = 0.1 to 1; the continuum estimate is ``alpha h c0 / 20`` times the lattice factor (0.0484).
* Time step: with h the cutoff, ``dt = 0.1 h / c0`` (or more) let energy or transverse velocity grow and, with
  Morris viscosity or weak artificial viscosity, lose atoms; ``dt = 0.05 h / c0`` conserved energy.
* The bead scene's heat transfer (:func:`moving_ring_conduction`, beam-only, nothing melting; Ti, 500 W on a
  2 mm ring, 5 mm/s, dx 0.4 mm): the melting isotherm is 3.6 % narrower and 0.5 % longer than the analytic
  moving ring source with the beam on the top particle layer, 7.0 % narrower and 3.9 % shorter with it shared
  over the top two layers (``beam_layers`` 2, the default): the deposit sits below the analytic surface flux.
"""

from __future__ import annotations

import math
import tempfile
import time
from pathlib import Path

import numpy as np
from scipy.optimize import minimize_scalar
from scipy.special import erfc

from beadsim import reduced
from beadsim.lammps_env import new_lammps
from beadsim.materials import get_material
from beadsim.parameters import defaults
from beadsim.sph import surface
from beadsim.sph.driver import run_case
from beadsim.sph.pictures import dumps_by_step, read_dump
from beadsim.sph.scene import TYPE_WIRE


def cubic_lattice(n: tuple[int, int, int], dx: float, origin=(0.0, 0.0, 0.0)) -> np.ndarray:
    """Cell centres (m) of an ``n[0] x n[1] x n[2]`` cubic lattice of spacing ``dx`` from ``origin``."""
    axes = [(np.arange(k) + 0.5) * dx + o for k, o in zip(n, origin)]
    return np.stack(np.meshgrid(*axes, indexing="ij"), axis=-1).reshape(-1, 3)


def open_box(lo, hi, periodic: str, ntypes: int, log=None):
    """New LAMMPS instance (``units si``, ``atom_style sph``) with an empty box [lo, hi] (m).

    ``periodic`` gives the boundary letters for x, y, z, e.g. ``"p p f"``.
    """
    lmp = new_lammps(log=log)
    lmp.command("units si")
    lmp.command("atom_style sph")
    lmp.command("atom_modify map array")
    lmp.command(f"boundary {periodic}")
    lmp.command("region box block {} {} {} {} {} {} units box".format(*np.ravel(np.column_stack([lo, hi]))))
    lmp.command(f"create_box {ntypes} box")
    return lmp


def add_atoms(lmp, pos: np.ndarray, atom_type: int) -> None:
    """Append particles of one type at ``pos`` (m); ids continue after the current maximum."""
    start = int(lmp.get_natoms())
    n = len(pos)
    ids = list(range(start + 1, start + n + 1))
    lmp.create_atoms(n, ids, [atom_type] * n, np.asarray(pos, dtype=float).ravel().tolist())


def id_order(lmp) -> np.ndarray:
    """Permutation that sorts the local atoms by id (single process; LAMMPS reorders atoms while running)."""
    return np.argsort(lmp.numpy.extract_atom("id")[: lmp.extract_global("nlocal")])


def by_id(lmp, name: str) -> np.ndarray:
    """Copy of a per-atom array ordered by atom id (single process)."""
    return np.array(lmp.numpy.extract_atom(name)[: lmp.extract_global("nlocal")])[id_order(lmp)]


def compute_by_id(lmp, compute_id: str) -> np.ndarray:
    """Copy of a per-atom vector compute ordered by atom id (single process)."""
    values = lmp.numpy.extract_compute(compute_id, 1, 1)[: lmp.extract_global("nlocal")]
    return np.array(values)[id_order(lmp)]


def lattice_laplacian_factor(h_factor: float) -> float:
    """Ratio of the SPH Laplacian (as in ``sph/heatconduction``) to the exact one on a cubic lattice.

    The discrete sum ``-2 sum_j V_j z_j^2 W'(r_j)/r_j`` over a cubic lattice of spacing dx applied to ``z^2``,
    divided by the exact Laplacian 2, for the 3-D Lucy kernel of support ``h = h_factor dx``. The effective
    diffusivity of a particle lattice is this factor times D (0.968 at 2.5 dx, 1.042 at 2.0 dx, 1.006 at 3.0
    dx); a driver can pass ``D / factor`` to cancel it.
    """
    n = int(np.ceil(h_factor))
    g = np.arange(-n, n + 1, dtype=float)
    x, y, z = np.meshgrid(g, g, g, indexing="ij")
    r = np.sqrt(x * x + y * y + z * z)
    wfd = np.where(r < h_factor, -315.0 / (4.0 * np.pi) * (h_factor - r) ** 2 / h_factor**7, 0.0)
    return float(-np.sum(z * z * wfd))


def conduction_slab(
    material: str = "Ti-Gr2",
    dx: float = 1e-4,
    h_factor: float = 2.5,
    n_cross: int = 4,
    n_z: int = 40,
    dt_factor: float = 0.1,
    t_end: float | None = None,
    T0: float = 300.0,
    T1: float = 1300.0,
    n_samples: int = 5,
    correct_lattice: bool = False,
) -> dict:
    """1-D transient conduction into a half-space of SPH particles with a held face, against erfc.

    Scene: a column of ``n_cross x n_cross x n_z`` particles (periodic in x and y) at ``T0`` above a reservoir
    of three particle layers (thicker than the kernel) held at ``T1`` by leaving them out of every integrating
    fix. Only ``pair_style sph/heatconduction`` acts; ``fix sph/stationary`` integrates ``e`` of the column.
    ``cv = cp`` per atom, ``e = cp T`` and T is read from ``compute sph/t/atom``. The held temperature sits on
    the centres of the top reservoir layer, z_face = -dx/2 (fitting the face position gives -0.50 to -0.63 dx
    for h = 2 to 3 dx, not the mid-plane z = 0). Analytic solution:
    ``T = T0 + (T1 - T0) erfc((z - z_face) / (2 sqrt(D t)))``. The far end is a free (insulated) surface;
    ``t_end`` defaults to the time at which ``4 sqrt(D t)`` reaches 80 % of the column, where erfc is < 1e-2
    there. With ``correct_lattice`` the pair coefficient is ``D / lattice_laplacian_factor(h_factor)``.

    Returns
    -------
    dict
        ``max_error_rel``: max |T - T_exact| / (T1 - T0) over all layers at the sample times with
        ``sqrt(D t) >= 3 dx`` (earlier the step is not resolved by the kernel); ``errors_rel``: that error per
        sample time; ``times_s``; ``diffusivity_m2_s``; ``energy_in_rel``: heat taken up by the column at
        ``t_end``, SPH over analytic (both summed over the layers); ``lattice_factor``:
        :func:`lattice_laplacian_factor`; ``z_m``, ``T_K``: the last layer-averaged profile; sizes,
        ``n_steps``, ``wall_time_s``.
    """
    mat = get_material(material)
    diff = mat.diffusivity
    h = h_factor * dx
    length = n_z * dx
    t_end = t_end if t_end is not None else (0.8 * length / 4.0) ** 2 / diff
    dt = dt_factor * dx * dx / diff
    n_steps_total = int(np.ceil(t_end / dt))
    n_res = int(np.ceil(h / dx))
    side = n_cross * dx
    mass = mat.rho * dx**3

    start = time.perf_counter()
    lmp = open_box((0, 0, -(n_res + 1) * dx), (side, side, length + dx), "p p f", 2)
    try:
        add_atoms(lmp, cubic_lattice((n_cross, n_cross, n_z), dx), 1)
        add_atoms(lmp, cubic_lattice((n_cross, n_cross, n_res), dx, (0, 0, -n_res * dx)), 2)
        lmp.commands_list([
            f"mass * {mass}",
            f"set group all sph/rho {mat.rho}",
            f"set group all sph/cv {mat.cp}",
            f"set type 1 sph/e {mat.cp * T0}",
            f"set type 2 sph/e {mat.cp * T1}",
            "group column type 1",
            "pair_style sph/heatconduction",
            f"pair_coeff * * {diff / lattice_laplacian_factor(h_factor) if correct_lattice else diff} {h}",
            f"neighbor {0.2 * dx} bin",
            "neigh_modify every 100 delay 0 check yes",
            "fix integrate column sph/stationary",
            "compute T all sph/t/atom",
            f"timestep {dt}",
            "run 0 post no",
        ])
        z_all = by_id(lmp, "x")[:, 2]
        layer = np.rint(z_all / dx - 0.5).astype(int)
        in_column = layer >= 0
        times, errors = [], []
        steps = np.linspace(0, n_steps_total, n_samples + 1)[1:].astype(int)
        done = 0
        for step in steps:
            lmp.command(f"run {step - done} pre no post no")
            done = step
            t = done * dt
            T = compute_by_id(lmp, "T")
            profile = np.bincount(layer[in_column], T[in_column]) / np.bincount(layer[in_column])
            z = (np.arange(n_z) + 0.5) * dx
            exact = T0 + (T1 - T0) * erfc((z + 0.5 * dx) / (2.0 * np.sqrt(diff * t)))
            times.append(t)
            errors.append(float(np.max(np.abs(profile - exact)) / (T1 - T0)))
        taken = float(np.sum(profile - T0) * dx)
        expected = float(np.sum(exact - T0) * dx)
    finally:
        lmp.close()
    resolved = np.sqrt(diff * np.array(times)) >= 3 * dx
    return {
        "max_error_rel": float(np.max(np.array(errors)[resolved])),
        "errors_rel": errors,
        "times_s": times,
        "diffusivity_m2_s": diff,
        "energy_in_rel": taken / expected,
        "lattice_factor": lattice_laplacian_factor(h_factor),
        "z_m": z,
        "T_K": profile,
        "n_particles": n_cross * n_cross * (n_z + n_res),
        "dx_mm": dx * 1e3,
        "dt_s": dt,
        "n_steps": int(done),
        "wall_time_s": time.perf_counter() - start,
    }


def viscous_pair(viscosity: str, mat, c0: float, alpha: float, h: float) -> tuple[str, str]:
    """Pair style and its ``pair_coeff`` arguments after the types for the bead driver's viscosity models.

    ``"morris"``: ``sph/taitwater/morris`` with the dynamic viscosity mu (Pa s); ``"artificial"``:
    ``sph/taitwater`` with Monaghan's alpha. Both take rho0, c0 and the cutoff h.
    """
    if viscosity == "morris":
        return "sph/taitwater/morris", f"{mat.rho} {c0} {mat.mu} {h}"
    if viscosity == "artificial":
        return "sph/taitwater", f"{mat.rho} {c0} {alpha} {h}"
    raise ValueError(f"viscosity must be 'morris' or 'artificial', not {viscosity!r}")


def poiseuille_profile(z: np.ndarray, t: float, g: float, nu: float, width: float, n_terms: int = 200):
    """Start-up plane Poiseuille flow between still walls at z = 0 and z = width (m/s).

    ``u = g/(2 nu) z (W - z) - sum_{n odd} 4 g W^2/(nu pi^3 n^3) sin(n pi z/W) exp(-n^2 pi^2 nu t/W^2)``.
    """
    n = 2 * np.arange(n_terms)[:, None] + 1
    series = 4 * g * width**2 / (nu * np.pi**3 * n**3) * np.sin(n * np.pi * z / width) * np.exp(
        -(n**2) * np.pi**2 * nu * t / width**2
    )
    return g / (2 * nu) * z * (width - z) - series.sum(axis=0)


def fit_viscosity(z, u, t, g, nu_guess, width) -> float:
    """Kinematic viscosity (m2/s) that best fits one measured start-up Poiseuille profile (least squares)."""
    def cost(log_nu):
        return float(np.sum((poiseuille_profile(z, t, g, np.exp(log_nu), width) - u) ** 2))

    res = minimize_scalar(cost, bracket=(np.log(nu_guess) - 0.5, np.log(nu_guess) + 0.5))
    return float(np.exp(res.x))


def poiseuille(
    viscosity: str = "morris",
    material: str = "Ti-Gr2",
    dx: float = 5e-5,
    h_factor: float = 2.5,
    n_fluid: int = 20,
    n_cross: int = 4,
    alpha: float = 0.1,
    mach: float = 0.05,
    t_end_factor: float = 0.5,
    n_samples: int = 4,
    correct_lattice: bool = False,
    cfl: float = 0.05,
) -> dict:
    """Body-force-driven start-up Poiseuille flow between two walls of still SPH particles.

    Scene: ``n_fluid`` particle layers of fluid (periodic in x and y, ``n_cross`` particles across each)
    between two walls of ``ceil(h/dx)`` layers each held at rest by ``fix sph/stationary``; ``fix sph`` moves
    the fluid and ``fix gravity`` pulls it along +x with acceleration g. The no-slip plane is taken at the
    centres of the first wall layers (the held values sit on particle centres, as in :func:`conduction_slab`),
    so the channel width is ``W = (n_fluid + 1) dx``.

    ``viscosity="morris"``: ``pair_style sph/taitwater/morris`` with the material's dynamic viscosity mu, and
    the analytic nu = mu / rho. ``viscosity="artificial"``: ``pair_style sph/taitwater`` with Monaghan's
    alpha, and the analytic ``nu = alpha h c0 / 20`` (the continuum limit of that term is
    ``alpha h c0 / 10 (lap v + 2 grad div v)`` in 3-D; the switch that keeps only approaching pairs halves it
    in shear flow); the fitted ``nu_eff`` gives the measured coefficient ``nu_eff / (alpha h c0)``.

    g is chosen so that the steady centre speed is ``u_max = g W^2 / (8 nu)``, the sound speed is
    ``c0 = u_max / mach``; dt is the smaller of ``cfl h / c0`` and ``0.1 dx^2 / nu``, h the cutoff. Measured:
    ``0.125 h^2 / nu`` (Morris), and ``cfl`` = 0.25 or 0.1 with artificial viscosity alpha = 0.1, let a
    transverse velocity grow exponentially until the fluid atoms were lost; ``cfl = 0.05`` held. The run lasts
    ``t_end_factor W^2 / nu``. With ``correct_lattice`` the pair coefficient (mu or alpha) is divided by
    :func:`lattice_laplacian_factor` (the Morris term is the same lattice sum as the heat conduction).

    Returns
    -------
    dict
        ``max_error_rel``: max |u - u_exact| / u_max over layers and sample times; ``shape_error_rel``: the
        same for the last profile against the solution with the fitted viscosity; ``nu_m2_s`` (analytic),
        ``nu_fit_m2_s`` (best fit of the transient solution to the last profile), ``nu_coefficient`` (fit over
        ``alpha h c0``, artificial viscosity only), ``z_m``, ``u_m_s`` (last layer-averaged profile),
        ``u_exact_m_s``, ``density_range`` (min, max rho / rho0 of the fluid), sizes, ``n_steps``,
        ``wall_time_s``.
    """
    mat = get_material(material)
    h = h_factor * dx
    n_wall = int(np.ceil(h_factor))
    width = (n_fluid + 1) * dx
    side = n_cross * dx
    u_max = 1e-3
    c0 = u_max / mach
    nu = mat.nu if viscosity == "morris" else alpha * h * c0 / 20.0
    if correct_lattice:
        factor = lattice_laplacian_factor(h_factor)
        mat = get_material(material, overrides={"mu": mat.mu / factor})
        alpha = alpha / factor
    style, coeff = viscous_pair(viscosity, mat, c0, alpha, h)
    g = 8.0 * nu * u_max / width**2
    dt = min(cfl * h / c0, 0.1 * dx * dx / nu)
    t_end = t_end_factor * width**2 / nu
    n_total = int(np.ceil(t_end / dt))

    start = time.perf_counter()
    lmp = open_box((0, 0, -n_wall * dx), (side, side, (n_fluid + n_wall) * dx), "p p f", 2)
    try:
        add_atoms(lmp, cubic_lattice((n_cross, n_cross, n_fluid), dx), 1)
        add_atoms(lmp, cubic_lattice((n_cross, n_cross, n_wall), dx, (0, 0, -n_wall * dx)), 2)
        add_atoms(lmp, cubic_lattice((n_cross, n_cross, n_wall), dx, (0, 0, n_fluid * dx)), 2)
        lmp.commands_list([
            f"mass * {mat.rho * dx**3}",
            f"set group all sph/rho {mat.rho}",
            "group fluid type 1",
            "group wall type 2",
            f"pair_style {style}",
            f"pair_coeff * * {coeff}",
            f"neighbor {0.2 * dx} bin",
            "neigh_modify every 1 delay 0 check yes",
            "fix move fluid sph",
            "fix hold wall sph/stationary",
            f"fix pull fluid gravity {g} vector 1 0 0",
            f"timestep {dt}",
            "run 0 post no",
        ])
        fluid = by_id(lmp, "type") == 1
        layer = np.rint(by_id(lmp, "x")[fluid, 2] / dx - 0.5).astype(int)
        z = (np.arange(n_fluid) + 1.0) * dx  # distance from the no-slip plane at -dx/2
        errors, done = [], 0
        rho_lo, rho_hi = np.inf, -np.inf
        for step in np.linspace(0, n_total, n_samples + 1)[1:].astype(int):
            lmp.command(f"run {step - done} pre no post no")
            done = step
            fluid = by_id(lmp, "type") == 1
            layer = np.rint(by_id(lmp, "x")[fluid, 2] / dx - 0.5).astype(int)
            u = np.bincount(layer, by_id(lmp, "v")[fluid, 0], n_fluid) / np.bincount(layer, None, n_fluid)
            rho = by_id(lmp, "rho")[fluid] / mat.rho
            rho_lo, rho_hi = min(rho_lo, rho.min()), max(rho_hi, rho.max())
            exact = poiseuille_profile(z, done * dt, g, nu, width)
            errors.append(float(np.max(np.abs(u - exact)) / u_max))
    finally:
        lmp.close()
    nu_fit = fit_viscosity(z, u, done * dt, g, nu, width)
    fitted = poiseuille_profile(z, done * dt, g, nu_fit, width)
    out = {
        "shape_error_rel": float(np.max(np.abs(u - fitted)) / u_max),
        "max_error_rel": max(errors),
        "errors_rel": errors,
        "nu_m2_s": nu,
        "nu_fit_m2_s": nu_fit,
        "z_m": z,
        "u_m_s": u,
        "u_exact_m_s": exact,
        "u_max_m_s": u_max,
        "g_m_s2": g,
        "sound_speed_m_s": c0,
        "density_range": (float(rho_lo), float(rho_hi)),
        "n_particles": n_cross * n_cross * (n_fluid + 2 * n_wall),
        "dx_mm": dx * 1e3,
        "dt_s": dt,
        "n_steps": int(done),
        "simulated_time_s": done * dt,
        "wall_time_s": time.perf_counter() - start,
    }
    if viscosity == "artificial":
        out["nu_coefficient"] = nu_fit / (alpha * h * c0)
    return out


def box_walls(n_in: tuple[int, int, int], n_wall: int, dx: float) -> np.ndarray:
    """Wall particles, ``n_wall`` layers thick, around the x and z faces of a box of ``n_in`` cells.

    The box interior spans ``[0, n_in[0] dx] x [0, n_in[1] dx] x [0, n_in[2] dx]``; y is left open (periodic).
    """
    outer = cubic_lattice(
        (n_in[0] + 2 * n_wall, n_in[1], n_in[2] + 2 * n_wall), dx, (-n_wall * dx, 0.0, -n_wall * dx)
    )
    inside = (outer[:, 0] > 0) & (outer[:, 0] < n_in[0] * dx)
    inside &= (outer[:, 2] > 0) & (outer[:, 2] < n_in[2] * dx)
    return outer[~inside]


def closed_melt(
    material: str = "Ti-Gr2",
    energy_per: str = "particle",
    viscosity: str = "artificial",
    alpha: float = 0.1,
    dx: float = 1e-4,
    h_factor: float = 2.5,
    n_box: tuple[int, int, int] = (20, 4, 14),
    n_liquid: tuple[int, int] = (8, 10),
    c0: float = 2.0,
    cfl: float = 0.05,
    t_end: float = 0.02,
    T_bottom: float = 2000.0,
    T_top: float = 2400.0,
    gravity: float = 9.81,
    n_samples: int = 10,
) -> dict:
    """Closed box of liquid collapsing and sloshing under gravity while heat is conducted; no heat input.

    Scene: a column of ``n_liquid[0] x n_box[1] x n_liquid[1]`` liquid particles (x, y, z) in the corner of a
    box of ``n_box`` cells (periodic in y, a quasi-2-D dam break) closed by ``ceil(h/dx)`` layers of still
    wall particles (``fix sph/stationary``) on the four x and z faces. The liquid starts at rest with a linear
    temperature from ``T_bottom`` to ``T_top`` (above the melting point), the walls at ``T_bottom``.
    ``pair_style hybrid/overlay`` of the viscous style (as in :func:`poiseuille`) and ``sph/heatconduction``
    (D = k / (rho cp)); ``fix gravity`` acts on the liquid; ``dt = cfl h / c0`` (h the cutoff). Measured at
    the defaults: ``cfl = 0.1`` let kinetic energy grow out of the internal energy (density 0.86-1.12 rho0,
    energy not conserved); ``cfl = 0.05`` conserved energy to 1e-5 of the dissipated mechanical energy.

    ``energy_per="particle"``: ``e`` is the energy of the particle, ``e = m cp T`` and ``cv = m cp``; total
    energy ``E = sum e + sum m v^2/2 + sum m g z``. ``energy_per="mass"``: ``e = cp T`` (J/kg), ``cv = cp``,
    ``E = sum m e + ...``: the pair styles' pressure work and viscous heating then enter ``e`` m times too
    weakly and the dissipated mechanical energy goes missing.

    Returns
    -------
    dict
        ``mass_change_kg`` (total mass at the end minus at the start; exactly 0 unless atoms were lost),
        ``n_lost``, ``mechanical_loss_J`` (drop of kinetic + potential energy), ``thermal_gain_J`` (rise of
        the internal energy), ``energy_drift_J`` (max |E(t) - E(0)| over the samples), ``energy_drift_rel``
        (drift over ``mechanical_loss_J``), ``heating_ratio`` (``thermal_gain_J / mechanical_loss_J``),
        ``potential_drop_J``, ``kinetic_max_J``, ``T_min_K``, ``T_max_K`` (liquid), ``density_range``
        (liquid, over rho0), ``heat_moved_J`` (internal energy that crossed the liquid's mid-height, a
        measure of the conduction acting), sizes, ``n_steps``, ``wall_time_s``.
    """
    mat = get_material(material)
    if energy_per not in ("particle", "mass"):
        raise ValueError(f"energy_per must be 'particle' or 'mass', not {energy_per!r}")
    mass = mat.rho * dx**3
    cv = mat.cp * (mass if energy_per == "particle" else 1.0)
    e_scale = 1.0 if energy_per == "particle" else mass  # joules per unit of e
    h = h_factor * dx
    n_wall = int(np.ceil(h_factor))
    style, coeff = viscous_pair(viscosity, mat, c0, alpha, h)
    dt = cfl * h / c0
    n_total = int(np.ceil(t_end / dt))
    lo = (-n_wall * dx, 0.0, -n_wall * dx)
    hi = ((n_box[0] + n_wall) * dx, n_box[1] * dx, (n_box[2] + n_wall) * dx)

    start = time.perf_counter()
    lmp = open_box(lo, hi, "f p f", 2)
    try:
        liquid0 = cubic_lattice((n_liquid[0], n_box[1], n_liquid[1]), dx)
        add_atoms(lmp, liquid0, 1)
        add_atoms(lmp, box_walls(n_box, n_wall, dx), 2)
        lmp.commands_list([
            f"mass * {mass}",
            f"set group all sph/rho {mat.rho}",
            f"set group all sph/cv {cv}",
            "group liquid type 1",
            "group wall type 2",
            f"pair_style hybrid/overlay {style} sph/heatconduction",
            f"pair_coeff * * {style} {coeff}",
            f"pair_coeff * * sph/heatconduction {mat.diffusivity} {h}",
            f"neighbor {0.2 * dx} bin",
            "neigh_modify every 1 delay 0 check yes",
            "fix move liquid sph",
            "fix hold wall sph/stationary",
            f"fix fall liquid gravity {gravity} vector 0 0 -1",
            "compute T all sph/t/atom",
            f"timestep {dt}",
        ])
        z0 = (liquid0[:, 2] / (n_liquid[1] * dx)).clip(0, 1)
        n_walls = int(lmp.get_natoms()) - len(z0)
        e_start = np.concatenate([T_bottom + (T_top - T_bottom) * z0, np.full(n_walls, T_bottom)])
        esph = lmp.numpy.extract_atom("esph")
        esph[: len(e_start)] = (cv * e_start)[np.argsort(id_order(lmp))]
        lmp.command("run 0 post no")
        mid = 0.5 * n_liquid[1] * dx

        def totals():
            typ = by_id(lmp, "type")
            v, x = by_id(lmp, "v"), by_id(lmp, "x")
            e = by_id(lmp, "esph") * e_scale
            liq = typ == 1
            kin = 0.5 * mass * float(np.sum(v[liq] ** 2))
            pot = mass * gravity * float(np.sum(x[liq, 2]))
            upper = float(np.sum(e[liq & (x[:, 2] > mid)]))
            return float(np.sum(e)), kin, pot, upper, len(typ) * mass

        e0, k0, p0, up0, m0 = totals()
        drift, k_max, done = 0.0, 0.0, 0
        t_lo, t_hi, rho_lo, rho_hi = np.inf, -np.inf, np.inf, -np.inf
        for step in np.linspace(0, n_total, n_samples + 1)[1:].astype(int):
            lmp.command(f"run {step - done} pre no post no")
            done = step
            e1, k1, p1, up1, m1 = totals()
            drift = max(drift, abs((e1 + k1 + p1) - (e0 + k0 + p0)))
            k_max = max(k_max, k1)
            liq = by_id(lmp, "type") == 1
            temp = compute_by_id(lmp, "T")[liq]
            rho = by_id(lmp, "rho")[liq] / mat.rho
            t_lo, t_hi = min(t_lo, temp.min()), max(t_hi, temp.max())
            rho_lo, rho_hi = min(rho_lo, rho.min()), max(rho_hi, rho.max())
        n_end = int(lmp.get_natoms())
    finally:
        lmp.close()
    mech_loss = (k0 + p0) - (k1 + p1)
    return {
        "mass_change_kg": m1 - m0,
        "n_lost": len(e_start) - n_end,
        "mechanical_loss_J": mech_loss,
        "thermal_gain_J": e1 - e0,
        "energy_drift_J": drift,
        "energy_drift_rel": drift / mech_loss,
        "heating_ratio": (e1 - e0) / mech_loss,
        "potential_drop_J": p0 - p1,
        "kinetic_max_J": k_max,
        "heat_moved_J": up0 - up1,
        "T_min_K": float(t_lo),
        "T_max_K": float(t_hi),
        "T_melt_K": mat.T_melt,
        "density_range": (float(rho_lo), float(rho_hi)),
        "n_particles": len(e_start),
        "n_liquid": len(liquid0),
        "dx_mm": dx * 1e3,
        "dt_s": dt,
        "n_steps": int(done),
        "wall_time_s": time.perf_counter() - start,
    }


def moving_ring_conduction(
    material: str = "Ti-Gr2",
    dx_mm: float = 0.4,
    power_W: float = 500.0,
    speed_mm_s: float = 5.0,
    scan_diameter_mm: float = 2.0,
    spot_mm: float = 0.25,
    sim_time_s: float = 2.0,
    outdir=None,
    **overrides,
) -> dict:
    """The bead scene's heat transfer against the quasi-steady moving ring source of the reduced model.

    Scene: the SPH bead driver (:func:`beadsim.sph.driver.run_case`) in the moving window, beam-only (no
    wire, ``wire_feed_mm_s = 0``), the beam's absorbed power ``power_W`` on the time-averaged ring, with the
    material's melting and boiling points raised out of reach so that nothing melts and nothing is capped:
    pure conduction of the solid, with the driver's beam deposit (columns seen from above, ``beam_layers``),
    moving lattice and far-field cut faces. The melting isotherm of the real material is read from the last
    particle dump (:func:`beadsim.sph.surface.isotherm_extent`) and compared with the reduced model's
    :class:`beadsim.reduced.MovingSource` for the same beam, speed and plate
    (:func:`beadsim.reduced.melt_pool`).

    Returns
    -------
    dict
        ``sph_width_mm``, ``sph_length_mm`` (means over the last three dumps), ``analytic_width_mm``,
        ``analytic_length_mm``, ``width_error_rel``, ``length_error_rel``, ``energy_error``,
        ``mass_balance_ratio`` (NaN: no wire), ``n_wire_particles`` (in the last dumps), ``n_particles``,
        ``wall_time_s``.
    """
    mat = get_material(material)
    params = defaults()
    params.update(model="sph", material=material, resolution_mm=dx_mm, beam_power_W=power_W,
                  beam_efficiency=1.0, substrate_speed_mm_s=speed_mm_s, scan_diameter_mm=scan_diameter_mm,
                  beam_spot_radius_mm=spot_mm, wire_feed_mm_s=0.0, domain="window", sim_time_s=sim_time_s,
                  temperature_cap=False, dump_interval_s=sim_time_s / 10, restart_interval_s=10 * sim_time_s)
    params.update(overrides)
    out = Path(outdir or tempfile.mkdtemp(prefix="ring_conduction_"))
    unmeltable = get_material(material, overrides={"T_melt": 1e9, "T_boil": 1e10})
    t0 = time.perf_counter()
    metrics = run_case(params, out, material=unmeltable)
    wall = time.perf_counter() - t0
    dx = dx_mm * 1e-3
    widths, lengths, n_wire = [], [], 0
    for path in dumps_by_step(out / "dumps")[-3:]:
        snap = read_dump(path)
        n_wire = max(n_wire, int((snap["type"] == TYPE_WIRE).sum()))
        pos = np.column_stack([snap["x"], snap["y"], snap["z"]])
        ext = surface.isotherm_extent(pos, snap["c_T"], mat.T_melt, dx)
        widths.append(ext["width_mm"])
        lengths.append(ext["length_mm"])
    mm = 1e-3
    src = reduced.MovingSource(Q=power_W, V=speed_mm_s * mm, rho_c=mat.rho * mat.cp, alpha=mat.diffusivity,
                               T0=params["preheat_K"], sigma=spot_mm * mm,
                               ring_radius=scan_diameter_mm * mm / 2,
                               thickness=params["substrate_thickness_mm"] * mm)
    pool = reduced.melt_pool(src, mat.T_melt, extent=max(scan_diameter_mm * mm, 1e-3))
    w, length = float(np.mean(widths)), float(np.mean(lengths))
    return {
        "sph_width_mm": w,
        "sph_length_mm": length,
        "sph_widths_mm": widths,
        "analytic_width_mm": pool.width / mm,
        "analytic_length_mm": pool.length / mm,
        "width_error_rel": w / (pool.width / mm) - 1,
        "length_error_rel": length / (pool.length / mm) - 1,
        "energy_error": metrics.get("energy_balance_error", math.nan),
        "mass_balance_ratio": metrics.get("mass_balance_ratio", math.nan),
        "n_wire_particles": n_wire,
        "n_particles": metrics.get("n_particles"),
        "wall_time_s": wall,
    }
