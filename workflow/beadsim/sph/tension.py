"""Surface tension and wetting for the LAMMPS SPH bead model: a pairwise cohesive force.

Model
-----
Pairwise-force SPH (Tartakovsky and Panchenko 2016) adds, between two liquid particles closer than ``h``, a
central force along r_ij (positive = repulsive)

    F(r) = s * phi(q),   phi(q) = cos(1.5 pi q) + A (1 - q / q_c)^2 [q < q_c],   q = r / h,

repulsive for q < 1/3, attractive for 1/3 < q < 1, zero beyond. The core term (A = 20, q_c = 0.3, i.e. inside
0.75 dx at h = 2.5 dx) acts only on pairs much closer than the particle spacing and keeps them from pairing up.

Summed over the bulk the force is a net attraction, a pair (virial) pressure P_pair = (1 / (6 dx^3)) sum_j r_j
F(r_j) < 0 over the neighbours of a simple cubic lattice site (:meth:`CohesionModel.pair_pressure`; about
-4e4 Pa for Ti at dx 0.3 mm, i.e. -7.7 sigma / dx), which would compress the Tait liquid by 10-30 %. A fixed
repulsive pair compensation (K q (1 - q)^2, tried first, as in the project notes) made drops expand below rho0
once the lattice disordered, and the negative SPH pressure then set off the tensile instability (densities
0.65-1.17 rho, speeds above 1 m/s). Instead the Tait reference density of ``sph/taitwater`` is lowered to
``rho0'`` so that the Tait pressure at the true density rho equals -P_pair (:meth:`CohesionModel.tait_rho0`):
the bulk sits at rho under a positive SPH background pressure balanced by the cohesion. Use ``rho0'`` for all
particle types (solid too), so that liquid-solid pairs see the same background pressure as liquid-liquid pairs.
The shifted liquid is stiffer: its sound speed c_eff = c0 (rho / rho0')^3 (:meth:`effective_sound_speed`) is
at least sqrt(7 |P_pair| / rho) (7.9 m/s for Ti at dx 0.3 mm) whatever c0, and it sets the time step.

Surface tension is what the attraction leaves at a free surface: sigma = C_sigma * s / dx, with the dimensionless
``C_sigma`` measured with the Kirkwood-Buff virial route on a periodic liquid slab (:data:`SIGMA_CALIBRATION`;
1.62 at dx 0.3 mm, 1.63 at dx 0.2 mm). Laplace pressures of free drops of 6-10 dx radius scatter from 0.5 to 1.24
times 2 sigma / R: at this resolution the particle arrangement carries a spurious yield stress of the order of
the Laplace pressure (drops freeze 10-20 % out of round).

Yield stress
------------
The cohesive liquid is a solid below a yield stress of ~0.6-0.8 sigma / dx. A film with a shear stress on its
free surface (:func:`beadsim.sph.verify_tension.surface_traction_film`) holds still up to 0.6 sigma / dx and
creeps at 1.5-5 % of a Newtonian film's speed at 0.8-1.2 sigma / dx (dx 0.2, 0.3 and 0.4 mm), while the
plain SPH liquid circulates at 4-17 % at every stress tried (0.03-0.3 sigma / dx). The bulk cohesion and the
background pressure balancing it, both ~7.7 sigma / dx, pin the particles in place. A bead's shaping stresses
(Marangoni ~80 Pa, gravity ~40 Pa, a bead cap's Laplace pressure ~1 kPa) lie below the 2-3 kPa of dx 0.4 mm,
and the ratio grows as 1 / dx. Scaling each particle's strength with temperature (a Marangoni term through
``lepton/coul`` and a per-particle charge) gave a bulk force along the strength gradient, balanced by a density
gradient, and no surface flow; it was left out (README, "The cohesive melt has a yield stress").

The yield lives in the bulk. In a periodic box with no surface (:func:`beadsim.sph.verify_tension.cellular_flow`)
Taylor-Green cells, where particles must change neighbours, reach 0.3-1.5 % of the Stokes speed at 100-300 Pa
(dx 0.4 mm) against 94-98 % for plain SPH, and the background pressure alone, without the cohesion, locks them
too (4 % at 300 Pa; a quarter of it flows at 90 %): P_b grad W is a pairwise repulsion that cages each particle.
Layers sliding along lattice planes (Kolmogorov shear) move from ~0.1 sigma / dx. The cohesion needs that
pressure to balance it, so a pairwise cohesion in an athermal SPH liquid is a particle crystal; see the README,
"Where the yield stress comes from", for the Couette film, thermal-noise and pair-shape probes.

Wetting
-------
Liquid-solid pairs use ``s_ls = wetting_ratio * s_ll`` with the same shape; solid-solid pairs get no cohesive
term (the solid is frozen). The contact line pins on the solid lattice: drops spreading from 90 degrees stop at
an advancing angle, caps started at 50 degrees stop at a receding angle 20-25 degrees lower
(:data:`CONTACT_ANGLE_HYSTERESIS`); :data:`CONTACT_ANGLE_TABLE` holds their mean, 90 / 79 / 65 degrees at ratio
0.8 / 0.9 / 1.0, and :func:`wetting_ratio_for_angle` interpolates it. Ratios above 1 do not give lower static
angles: a one-layer film creeps out from the drop (and at 1.3 the liquid spreads as a film). Angles below
~65 degrees (mean) are therefore out of reach of this model at dx 0.3 mm; at ratio 1.0 the receding angle is
52 degrees.

With a ratio below 1 the solid, at the liquid's shifted Tait pressure, pushes harder across the interface than
the weaker liquid-solid cohesion pulls: the liquid is pushed off the solid (part of the non-wetting above) and
melt beside solid expands. :meth:`CohesionModel.solid_tait_rho0` balances the crossing pairs (the driver's
``wetting_pressure_balance``); :data:`CONTACT_ANGLE_HYSTERESIS_BALANCED` holds the angles with it.

These tables come from drops, whose contact line crosses the plate's lattice at every orientation. A bead's
flanks run along a lattice row, and there the melt wets more. Ridges periodic along y
(:func:`beadsim.sph.verify_tension.sessile_ridge`, the bead's numerics: dx 0.4 mm, c0 4.15 m/s, artificial
viscosity 0.2, the balance and the smoothed loose-melt ceiling), thermally agitated so that they forget their
start (``SceneSettings.anneal_speed`` 0.3 m/s; means over 0.25-0.5 s from a wide and a tall start), settle at
85 / 75 / 72 / 65 / 60 / 52 / 49 degrees at ratio 0.5 / 0.6 / 0.65 / 0.7 / 0.75 / 0.8 / 0.9 (sd of the
samples 4-7 degrees; 0.6, 0.8 and 0.9 over 0.15-0.3 s), 10-20 degrees below the drop tables. Agitated drops
with the same numerics settle at 72 (0.7), 63-68 (0.8) and 61 degrees (0.9). Without the agitation a ridge
stops wherever its start and damping leave it (45 and 124 degrees at ratio 0.8 from a wide and a tall start
with artificial viscosity 1.0): the angle of an athermal bead is not its equilibrium angle, and beads did not
follow the ratio (README, "Contact lines along the lattice").

LAMMPS plumbing
---------------
The term is a sub-style of ``pair_style hybrid/overlay`` next to the SPH styles::

    model = CohesionModel.from_material(get_material("Ti-Gr2"), dx=3e-4, contact_angle_deg=65)
    c0, alpha = 10.0, 0.2
    lmp.command("pair_style hybrid/overlay sph/taitwater sph/heatconduction " + model.pair_style_tokens())
    lmp.command(f"pair_coeff * * sph/taitwater {model.tait_rho0(material, c0)} {c0} {alpha} {model.h}")
    lmp.command(f"pair_coeff * * sph/heatconduction {D} {model.h}")
    for line in model.pair_coeff_commands(liquid_types=[1], solid_types=[2], table_file="tension.table"):
        lmp.command(line)
    lmp.command(f"timestep {model.dt_limit(material, dx, c0, alpha)}")

Particle masses stay rho dx^3 and the initial ``sph/rho`` stays rho; resetting solid densities between chunks
uses rho as before. Backend ``"table"`` (default) writes force and energy to a ``pair_style table`` file;
``"lepton"`` gives the same force through ``pair_style lepton``. Lepton re-parses, differentiates and compiles
every distinct expression at every force call (``PairLepton::eval``): 0.45-1.4 ms per expression per step on
this machine whatever the particle count (125 particles: 0.034 ms per step with the table, 0.9 ms with 2 lepton
expressions, 6.9 ms with 9), plus a string-keyed variable look-up per pair. In an 8100-particle chunked scene
the table costs 17-27 % on top of the SPH styles, lepton 50 %, lepton on all type pairs 63 %.

Because the cohesive sub-style covers only liquid-liquid and liquid-solid type pairs, ``pair_style hybrid``
gives it a neighbour list filtered by type when lists are built. After changing particle types (melting,
freezing) the next ``run`` must do its setup (``run N pre yes``): with ``pre no`` a freshly melted particle feels
no cohesion, and a frozen one keeps it, until the next automatic rebuild (tested in tests/sph/test_tension.py).

Time step, sound speed, viscosity
---------------------------------
:meth:`CohesionModel.dt_limit` (capillary and acoustic limits, with measured factors that depend on the
artificial viscosity) and :meth:`CohesionModel.min_sound_speed` (Laplace pressure small against rho c0^2). For Ti
at dx 0.3 mm: c0 10 m/s -> c_eff 12.5 m/s, dt 5.0 us (alpha 0.2); c0 5 m/s -> c_eff 9.1 m/s, dt 7.0 us (held,
noisier). The particle-scale capillary motions (speeds ~ sqrt(sigma / (rho dx)) ~ 1 m/s) need strong damping:
``sph/taitwater`` with alpha >= 0.2 held; ``sph/taitwater/morris`` with the physical 0.01 Pa s or with 0.2 Pa s
blew up (speeds > 1 m/s, densities 0.3-1.2 rho, at dt 5 and 2.5 us), with 1 Pa s it held.
"""

from __future__ import annotations

import dataclasses
import math
from dataclasses import dataclass
from pathlib import Path

import numpy as np
from scipy.optimize import brentq

from beadsim import io
from beadsim.materials import Material

#: Kernel support h as a multiple of the particle spacing dx used by the bead driver (cutoff 2.5 dx).
H_OVER_DX = 2.5

#: Measured C_sigma = sigma * dx / s (dimensionless) for h = 2.5 dx, keyed by dx in m: (mean, spread).
#: Kirkwood-Buff virial tension of a periodic Ti slab (12 layers, 8 x 8 columns) after 1.5 ms, averaged over
#: 1.5 ms, at s = 0.7, 1.0 and 1.4 times the nominal strength (c0 10 m/s, alpha 0.2): dx 0.3 mm, dt 4 us:
#: 1.68, 1.61, 1.55; dx 0.2 mm, dt 2.5 us: 1.72, 1.40, 1.77 (noisier: particle speeds 0.3-0.5 m/s remained).
#: 308LSi (rho 7680) at dx 0.3 mm reads 1.72 N/m for a nominal 1.60 (C_sigma 1.74, +8 %).
#: See :func:`beadsim.sph.verify_tension.calibrate`.
SIGMA_CALIBRATION: dict[float, tuple[float, float]] = {3.0e-4: (1.62, 0.05), 2.0e-4: (1.63, 0.16)}

#: Measured contact angles (degree) of sessile Ti drops against wetting_ratio = s_ls / s_ll: (ratio, advancing,
#: receding). Drop of 1.05k particles (hemisphere of 2.4 mm) on a frozen 3-layer plate, dx 0.3 mm, h 2.5 dx,
#: c0 10 m/s, alpha 0.2, dt 5 us, after 15 ms; angle of the sphere fitted to the free surface
#: (:func:`beadsim.sph.verify_tension.cap_angle_from_surface`). "Advancing": started as a 90 degree hemisphere;
#: "receding": started as a 50 degree cap of the same volume. The model pins the contact line on the solid
#: lattice, so the two differ by 20-25 degrees. Both branches are static at ratio 1.0 (advancing 75.7, receding
#: 51.9 at 30 ms; gravity 9.81 m/s2 lowers the receding one by 0.5). At dx 0.2 mm, ratio 1.0 gives 85.1 / 52.5.
#: Ratios above 1 (1.05: 76.5 / 52.2; 1.1: 71.2 / 54.2, with a
#: one-layer film creeping ahead, 67.7 at 30 ms; 1.2: 61 with a spreading film; 1.3: the liquid spreads as a
#: film) give no lower static angle and are left out. Ratios below 1 hold in these drop tests but not in a bead:
#: mode 1 at dx 0.4 (efficiency 0.53) with ratio 0.9 grew a bead 1.4-1.7 mm high at 65-95 degrees whose melt
#: expanded (kernel fill 0.72-0.75, height-map area 1.6x the area its metal fills; 0.98-0.99 and 1.07x at 1.0):
#: liquid beside solid is cohered less than the shifted Tait background pressure needs (the driver warns).
CONTACT_ANGLE_HYSTERESIS: tuple[tuple[float, float, float], ...] = (
    (0.8, 101.1, 79.5),
    (0.9, 91.5, 66.5),
    (1.0, 77.3, 52.0),
)

def _mean_angles(hysteresis) -> tuple[tuple[float, float], ...]:
    """(wetting_ratio, mean of the advancing and receding angles) for rows (ratio, advancing, receding)."""
    return tuple((ratio, round((adv + rec) / 2, 1)) for ratio, adv, rec in hysteresis)


#: (wetting_ratio, contact angle in degree): the mean of the advancing and receding angles above, the
#: estimate of the equilibrium angle used by :func:`wetting_ratio_for_angle`.
CONTACT_ANGLE_TABLE: tuple[tuple[float, float], ...] = _mean_angles(CONTACT_ANGLE_HYSTERESIS)

#: As :data:`CONTACT_ANGLE_HYSTERESIS`, with the solid at the balancing Tait reference density
#: (:meth:`CohesionModel.solid_tait_rho0`, the driver's ``wetting_pressure_balance``). Measured 2026-12-03 on a
#: smaller drop (442 particles, hemisphere of 1.8 mm on a 3-layer plate, dx 0.3 mm, c0 10 m/s, alpha 0.2,
#: dt 5 us, 12 ms; the unbalanced 0.9 on that drop: 92.7 / 70.1). Without the repulsive imbalance the angles
#: depend much less on the ratio: much of the unbalanced model's non-wetting was the liquid being pushed off
#: the solid, the same push that made bead melt expand.
CONTACT_ANGLE_HYSTERESIS_BALANCED: tuple[tuple[float, float, float], ...] = (
    (0.8, 83.1, 62.3),
    (0.85, 81.2, 59.8),
    (0.9, 78.5, 57.3),
    (0.95, 78.5, 53.2),
    (1.0, 75.9, 48.9),
)

#: Mean angles of :data:`CONTACT_ANGLE_HYSTERESIS_BALANCED`.
CONTACT_ANGLE_TABLE_BALANCED: tuple[tuple[float, float], ...] = _mean_angles(CONTACT_ANGLE_HYSTERESIS_BALANCED)

#: Repulsive core added to the force (strength in units of s, radius in units of h): A (1 - q / q_c)^2 for
#: q < q_c. It keeps pairs apart where the Lucy kernel gradient, and so the SPH pressure force, vanishes
#: (without it, liquid particles paired up at artificial viscosity 0.1 and were pulled into the solid lattice
#: at strong wetting); it does not reach the lattice neighbours (q = 0.4 at h = 2.5 dx).
CORE_STRENGTH = 20.0
CORE_RADIUS = 0.3


def _tait_reference(rho: float, c0: float, pressure: float) -> float:
    """Tait reference density rho0' (kg m-3) at which B ((rho / rho0')^7 - 1), B = c0^2 rho0' / 7, equals
    ``pressure`` (Pa) at the density rho."""
    return brentq(lambda r0: c0**2 * r0 / 7 * ((rho / r0) ** 7 - 1) - pressure, 0.3 * rho, 1.5 * rho)


def lattice_offsets(h_over_dx: float = H_OVER_DX) -> np.ndarray:
    """Distances (in units of dx) from a simple cubic lattice site to its neighbours closer than h.

    Parameters
    ----------
    h_over_dx : float
        Cutoff h in units of the lattice spacing dx.

    Returns
    -------
    numpy.ndarray
        1-D array of neighbour distances r / dx, each in (0, h_over_dx).
    """
    n = int(math.ceil(h_over_dx))
    g = np.arange(-n, n + 1)
    gx, gy, gz = np.meshgrid(g, g, g, indexing="ij")
    r = np.sqrt(gx**2 + gy**2 + gz**2).ravel()
    return r[(r > 0) & (r < h_over_dx)]


def shape_force(q: np.ndarray) -> np.ndarray:
    """Dimensionless pair force phi(q) = cos(1.5 pi q) + core (positive = repulsive), zero for q >= 1."""
    q = np.asarray(q, dtype=float)
    core = CORE_STRENGTH * np.clip(1 - q / CORE_RADIUS, 0.0, None) ** 2
    return np.where(q < 1.0, np.cos(1.5 * np.pi * q) + core, 0.0)


def shape_energy(q: np.ndarray) -> np.ndarray:
    """Dimensionless pair energy u(q) = integral_q^1 phi dq', so that F = -dU/dr with U = s h u."""
    q = np.asarray(q, dtype=float)
    core = CORE_STRENGTH * CORE_RADIUS / 3 * np.clip(1 - q / CORE_RADIUS, 0.0, None) ** 3
    return np.where(q < 1.0, -(1.0 + np.sin(1.5 * np.pi * q)) / (1.5 * np.pi) + core, 0.0)


def sigma_coefficient(dx: float) -> float:
    """Return C_sigma = sigma dx / s (dimensionless) for spacing ``dx`` (m) from :data:`SIGMA_CALIBRATION`.

    The nearest calibrated spacing is used; C_sigma is expected to be nearly independent of dx at fixed h / dx.
    """
    key = min(SIGMA_CALIBRATION, key=lambda d: abs(math.log(d / dx)))
    return SIGMA_CALIBRATION[key][0]


def wetting_ratio_for_angle(angle_deg: float, table=CONTACT_ANGLE_TABLE) -> float:
    """Return the strength ratio s_ls / s_ll that gives a static contact angle ``angle_deg`` (degree).

    Linear interpolation in ``table`` (:data:`CONTACT_ANGLE_TABLE`, or :data:`CONTACT_ANGLE_TABLE_BALANCED` with
    the wetting pressure balance; the angle falls as the ratio rises).

    Raises
    ------
    ValueError
        If the angle lies outside the measured range.
    """
    ratios, angles = (np.array(v) for v in zip(*sorted(table)))
    if not angles.min() <= angle_deg <= angles.max():
        raise ValueError(
            f"contact angle {angle_deg} deg outside the calibrated range {angles.min()}-{angles.max()} deg"
        )
    return float(np.interp(angle_deg, angles[::-1], ratios[::-1]))


@dataclass(frozen=True)
class CohesionModel:
    """Pairwise cohesive force for liquid SPH particles (all SI units).

    Attributes
    ----------
    s_ll : float
        Liquid-liquid strength s, N.
    s_ls : float
        Liquid-solid strength, N.
    h : float
        Cutoff of the force (= SPH kernel support), m.
    dx : float
        Particle spacing (simple cubic lattice), m.
    sigma : float
        Surface tension the strengths were sized for, N m-1.
    backend : str
        ``"table"`` (pair_style table) or ``"lepton"`` (pair_style lepton).
    table_points : int
        Points in the table file and in LAMMPS' internal table.
    """

    s_ll: float
    s_ls: float
    h: float
    dx: float
    sigma: float
    backend: str = "table"
    table_points: int = 2000

    @classmethod
    def from_material(
        cls,
        material: Material,
        dx: float,
        h: float | None = None,
        wetting_ratio: float | None = None,
        contact_angle_deg: float | None = None,
        backend: str = "table",
    ) -> CohesionModel:
        """Size the model for ``material`` at particle spacing ``dx`` (m).

        Parameters
        ----------
        material : Material
            Supplies surface_tension (N m-1) and, if neither of the next two is given, contact_angle_deg.
        dx : float
            Particle spacing, m.
        h : float, optional
            Cutoff, m; default ``H_OVER_DX * dx``, the only ratio calibrated (others raise ValueError).
        wetting_ratio : float, optional
            s_ls / s_ll directly.
        contact_angle_deg : float, optional
            Target static contact angle, degree, mapped with :func:`wetting_ratio_for_angle`.
        backend : str
            ``"table"`` or ``"lepton"``.
        """
        h = H_OVER_DX * dx if h is None else h
        if not math.isclose(h / dx, H_OVER_DX, rel_tol=1e-6):
            raise ValueError(f"the calibration holds for h = {H_OVER_DX} dx only, got h = {h / dx:.4g} dx")
        if wetting_ratio is None:
            angle = material.contact_angle_deg if contact_angle_deg is None else contact_angle_deg
            wetting_ratio = wetting_ratio_for_angle(angle)
        s_ll = material.surface_tension * dx / sigma_coefficient(dx)
        return cls(s_ll, wetting_ratio * s_ll, h, dx, material.surface_tension, backend)

    def with_strength(self, s_ll: float) -> CohesionModel:
        """Copy with liquid-liquid strength ``s_ll`` (N), same wetting ratio; ``sigma`` then is nominal only."""
        return dataclasses.replace(self, s_ll=s_ll, s_ls=self.wetting_ratio * s_ll)

    @property
    def wetting_ratio(self) -> float:
        """s_ls / s_ll (dimensionless)."""
        return self.s_ls / self.s_ll

    def force(self, r: np.ndarray, strength: float | None = None) -> np.ndarray:
        """Pair force at distance ``r`` (m), N, positive = repulsive; ``strength`` defaults to ``s_ll``."""
        return (self.s_ll if strength is None else strength) * shape_force(np.asarray(r) / self.h)

    def energy(self, r: np.ndarray, strength: float | None = None) -> np.ndarray:
        """Pair energy at distance ``r`` (m), J, zero at the cutoff."""
        s = self.s_ll if strength is None else strength
        return s * self.h * shape_energy(np.asarray(r) / self.h)

    def pair_pressure(self) -> float:
        """Virial pressure of the cohesive force in the bulk simple cubic lattice, Pa (negative = tension)."""
        r = lattice_offsets(self.h / self.dx) * self.dx
        return float(np.sum(r * self.force(r)) / (6 * self.dx**3))

    def tait_rho0(self, material: Material, c0: float) -> float:
        """Reference density for ``sph/taitwater`` (kg m-3) at which the Tait pressure
        B ((rho / rho0')^7 - 1), B = c0^2 rho0' / 7, equals -:meth:`pair_pressure` at the true density rho.
        """
        return _tait_reference(material.rho, c0, -self.pair_pressure())

    def solid_tait_rho0(self, material: Material, c0: float) -> float:
        """Reference density (kg m-3) for the solid particle types that balances the weaker liquid-solid
        cohesion across a liquid-solid interface: the solid's Tait pressure at rho is (2 r - 1) P_b, r the
        wetting ratio and P_b = -:meth:`pair_pressure` the liquid's background pressure.

        The pairs that cross a plane through the interface carry the pressure term (P_liquid + P_solid) and the
        cohesive term r s_ll: with the solid at P_b (:meth:`tait_rho0` for all types) and r < 1 the crossing
        stress is repulsive, the liquid beside the solid is pushed off it and expands (measured in a bead scene:
        the melt's kernel fill 0.88-0.90 at r = 0.9 against 0.94-0.97 at r = 1). With the solid at
        (2 r - 1) P_b the crossing pairs balance as the liquid-liquid pairs do (0.98-0.99 at r = 0.9). At r = 1
        this is :meth:`tait_rho0`.
        """
        return _tait_reference(material.rho, c0, (2 * self.wetting_ratio - 1) * -self.pair_pressure())

    def effective_sound_speed(self, material: Material, c0: float) -> float:
        """Sound speed sqrt(dp/drho) of the shifted Tait liquid at rho, m s-1 (c0 (rho / rho0')^3)."""
        return c0 * (material.rho / self.tait_rho0(material, c0)) ** 3

    def pair_style_tokens(self) -> str:
        """Sub-style text to append to ``pair_style hybrid/overlay ...``."""
        if self.backend == "table":
            return f"table linear {self.table_points}"
        if self.backend == "lepton":
            return f"lepton {self.h:.9g}"
        raise ValueError(f"unknown backend {self.backend!r}: use 'table' or 'lepton'")

    def lepton_expression(self, strength: float) -> str:
        """Pair energy U(r) as a Lepton expression in r (m) for ``pair_style lepton``."""
        rc = CORE_RADIUS * self.h
        core = strength * self.h * CORE_STRENGTH * CORE_RADIUS / 3
        return (
            f"{-strength * self.h / (1.5 * math.pi):.12g}*(1+sin({1.5 * math.pi / self.h:.12g}*r))"
            f"+{core:.12g}*max(0,1-r/{rc:.12g})^3"
        )

    def write_table(self, path: str | Path) -> Path:
        """Write the ``pair_style table`` file with sections ``LL`` (s_ll) and ``LS`` (s_ls); return its path.

        The table starts at r = 0.02 h: LAMMPS stops with an error if two particles come closer, which
        the SPH pressure prevents (closest pairs stay above ~0.5 dx).

        The file is replaced atomically: under MPI every rank writes it while rank 0 may already be reading
        it (a plain write let rank 0 read a half-written table: "Error parsing pair table 'LL' line 1456 of
        2000", which hung a 2-rank CI run until the abort on one rank's error existed).
        """
        path = Path(path)
        r = np.linspace(0.02 * self.h, self.h, self.table_points)
        lines = ["# pairwise cohesive force, beadsim.sph.tension; r in m, energy in J, force in N"]
        for key, s in (("LL", self.s_ll), ("LS", self.s_ls)):
            lines += ["", key, f"N {self.table_points} R {r[0]:.12g} {r[-1]:.12g}", ""]
            e, f = self.energy(r, s), self.force(r, s)
            lines += [f"{i + 1} {ri:.12g} {ei:.12g} {fi:.12g}" for i, (ri, ei, fi) in enumerate(zip(r, e, f))]
        io.write_text(path, "\n".join(lines) + "\n")
        return path

    def pair_coeff_commands(
        self, liquid_types: list[int], solid_types: list[int], table_file: str | Path | None = None,
        liquid_pairs: bool = True,
    ) -> list[str]:
        """Return the ``pair_coeff`` lines for the cohesive sub-style.

        Parameters
        ----------
        liquid_types, solid_types : list of int
            LAMMPS atom types of liquid and solid particles.
        table_file : str or Path, optional
            Where to write the table file (backend ``"table"`` only; required there).
        liquid_pairs : bool
            Include the liquid-liquid pairs; False for a second model that sets only some solids' pairs.
        """
        pairs = [(a, b, self.s_ll, "LL") for a in liquid_types for b in liquid_types if a <= b and liquid_pairs]
        pairs += [(min(a, b), max(a, b), self.s_ls, "LS") for a in liquid_types for b in solid_types]
        if self.backend == "table":
            if table_file is None:
                raise ValueError("backend 'table' needs table_file")
            table = self.write_table(table_file)
            return [f"pair_coeff {a} {b} table {table} {key} {self.h:.9g}" for a, b, _, key in pairs]
        return [f"pair_coeff {a} {b} lepton '{self.lepton_expression(s)}' {self.h:.9g}" for a, b, s, _ in pairs]

    def dt_limit(self, material: Material, dx: float, c0: float | None = None, alpha: float = 0.2) -> float:
        """Time-step limit, s: capillary 0.125 sqrt(rho dx^3 / (2 pi sigma)) (half the textbook factor of
        Brackbill et al. 1992) and, if ``c0`` (m s-1) is given, the acoustic f(alpha) h / c_eff with the shifted
        Tait sound speed c_eff (:meth:`effective_sound_speed`).

        f is measured on Ti drops at dx 0.3 mm, c0 10 m/s (c_eff 12.5 m/s; "unstable" = particle speeds growing
        past 1 m/s within 2 ms): artificial viscosity alpha 0.1: dt 7.5 us (f 0.125) unstable, 3.5 us (0.058)
        held; alpha 0.2: 7.5 us unstable, 5 us (0.083) held; alpha 0.5: 7.5 us (0.125) held. f is interpolated
        linearly in alpha between 0.058 at 0.1 and 0.125 at 0.5 and kept at those values outside.
        """
        dt = capillary_dt_limit(material.rho, dx, self.sigma)
        if c0 is not None:
            f = float(np.interp(alpha, [0.1, 0.2, 0.5], [0.058, 0.083, 0.125]))
            dt = min(dt, f * self.h / self.effective_sound_speed(material, c0))
        return dt

    def min_sound_speed(self, material: Material, radius: float | None = None, density_error: float = 0.02) -> float:
        """Smallest c0 (m s-1) for which the Laplace pressure 2 sigma / radius compresses the Tait liquid by
        no more than ``density_error`` (delta rho / rho ~ p / (rho c0^2)).

        Parameters
        ----------
        material : Material
            Supplies rho.
        radius : float, optional
            Smallest curvature radius to resolve, m; default 2 h.
        density_error : float
            Allowed relative compression.
        """
        return laplace_sound_speed(self.sigma, material.rho, 2 * self.h if radius is None else radius,
                                   density_error)


def laplace_sound_speed(sigma: float, rho: float, radius: float, density_error: float = 0.02) -> float:
    """Smallest Tait sound speed (m s-1) at which the Laplace pressure 2 sigma / radius compresses a liquid of
    density rho by no more than ``density_error`` (delta rho / rho ~ p / (rho c0^2))."""
    return math.sqrt(2 * sigma / radius / (rho * density_error))


def capillary_dt_limit(rho: float, dx: float, sigma: float) -> float:
    """Capillary time-step limit, s: 0.125 sqrt(rho dx^3 / (2 pi sigma)), half the textbook factor of
    Brackbill et al. (1992); the cohesion's (:meth:`CohesionModel.dt_limit`) and the height function's."""
    return 0.125 * math.sqrt(rho * dx**3 / (2 * math.pi * sigma))
