"""Reduced bead model: moving-source conduction for the melt pool, mass balance and a capillary cap for the bead.

The cheapest rung of the model ladder: a steady state, no melt flow, no wire dynamics.

Conduction (quasi-steady, frame moving with the beam at speed V along +x, constant properties)
    T - T0 = (2 Q / rho c) int_0^inf S(xi + V tau, y; tau) Z(z; tau) dtau
with the surface term of a source of total power Q
    point:     S = exp(-r^2 / 4 a tau) / (4 pi a tau)
    Gaussian:  S = exp(-r^2 / s) / (pi s),                     s = 4 a tau + 2 sigma^2
    ring:      S = exp(-(r - R0)^2 / s) i0e(2 r R0 / s) / (pi s)   (Gaussian spot swept over a circle of radius R0,
               time-averaged: valid when the scan speed pi D f >> V and 1/f is short against the diffusion time)
and the depth term of a plate of thickness Hs with an insulated bottom (images at z = 2 n Hs)
    Z = sum_n exp(-(z - 2 n Hs)^2 / 4 a tau) / sqrt(4 pi a tau).
For sigma -> 0, R0 -> 0 and Hs -> inf this is Rosenthal's thick-plate solution
    T - T0 = Q / (2 pi k R) exp(-V (xi + R) / 2 a),
which the tests check.

Power balance: Q = eta P - P_wire, where P_wire = rho A_w V_w (c (T_m - T0) + L) melts the wire.

Bead: the wire supplies the cross-section A = (pi d^2 / 4) V_w / V_s above the surface. Its cap is a circular arc
(capillarity dominates: the bead width is below the capillary length). It wets the whole melted width w_m of the
substrate; where w_m is narrower than the width the cap takes at the material's contact angle theta_e, it spreads
over the solid until theta = theta_e. So w = max(w_m, w(theta_e)), and the contact angle follows from (w, A).
"""

from __future__ import annotations

import math
import time
from dataclasses import dataclass

import numpy as np
from scipy import optimize, special

from beadsim.materials import Material

# Regimes a process engineer cares about, worst first; ``beam_only`` is a pass without wire (V_w = 0) that melts
# the plate, which has no bead to call flat or tall.
REGIMES = ("no_wire_melt", "lack_of_fusion", "burn_through", "tall_bead", "flat_bead", "beam_only", "ok")


@dataclass(frozen=True)
class MovingSource:
    """A beam moving at speed V over a plate; SI units.

    Parameters
    ----------
    Q : float
        Power into the substrate, W.
    V : float
        Travel speed, m s-1.
    rho_c : float
        Volumetric heat capacity rho c, J m-3 K-1.
    alpha : float
        Thermal diffusivity, m2 s-1.
    T0 : float
        Far-field (preheat) temperature, K.
    sigma : float
        Gaussian spot radius (standard deviation), m; 0 for a point source.
    ring_radius : float
        Radius of the time-averaged scanned circle, m; 0 for a static spot.
    thickness : float
        Plate thickness, m (inf for a half-space).
    """

    Q: float
    V: float
    rho_c: float
    alpha: float
    T0: float
    sigma: float = 0.0
    ring_radius: float = 0.0
    thickness: float = math.inf
    n_tau: int = 240

    def _tau(self) -> np.ndarray:
        """Log-spaced quadrature nodes in tau (s) covering the whole integrand (the same for every point)."""
        a, V = self.alpha, self.V
        lo = 1e-3 * max(self.sigma, 1e-5) ** 2 / a
        hi = 60.0 * 4 * a / V**2
        if math.isfinite(self.thickness):
            hi = max(hi, 10 * self.thickness**2 / a)
        return np.geomspace(lo, hi, self.n_tau)

    def temperature(self, pts: np.ndarray) -> np.ndarray:
        """Temperature (K) at points (..., 3) = (xi, y, z) in metres, z <= 0 inside the plate (0 = surface)."""
        pts = np.asarray(pts, dtype=float)
        shape = pts.shape[:-1]
        p = pts.reshape(-1, 3)
        tau = self._tau()
        ln_tau = np.log(tau)
        out = np.empty(len(p))
        a, V, s2 = self.alpha, self.V, 2 * self.sigma**2
        for i0 in range(0, len(p), 2048):
            xi, y, z = (p[i0:i0 + 2048, k][:, None] for k in range(3))
            s = 4 * a * tau + s2
            xs = xi + V * tau
            if self.ring_radius > 0:
                r = np.sqrt(xs**2 + y**2)
                R0 = self.ring_radius
                surf = np.exp(-((r - R0) ** 2) / s) * special.i0e(2 * r * R0 / s) / (np.pi * s)
            else:
                surf = np.exp(-(xs**2 + y**2) / s) / (np.pi * s)
            depth = self._depth_term(z, tau)
            f = surf * depth * tau  # d tau = tau d ln tau
            out[i0:i0 + 2048] = np.trapezoid(f, ln_tau, axis=1)
        return (self.T0 + 2 * self.Q / self.rho_c * out).reshape(shape)

    def _depth_term(self, z: np.ndarray, tau: np.ndarray) -> np.ndarray:
        four_at = 4 * self.alpha * tau
        norm = 1 / np.sqrt(np.pi * four_at)
        if not math.isfinite(self.thickness):
            return norm * np.exp(-(z**2) / four_at)
        H = self.thickness
        n_img = int(np.ceil(np.sqrt(four_at.max()) * 4 / (2 * H))) + 1
        total = np.zeros(np.broadcast_shapes(z.shape, tau.shape))
        for n in range(-n_img, n_img + 1):
            total += np.exp(-((z - 2 * n * H) ** 2) / four_at)
        return norm * total


def rosenthal(Q: float, V: float, k: float, alpha: float, T0: float, xi, y, z):
    """Rosenthal's thick-plate point-source solution (K); xi along travel relative to the source, metres."""
    R = np.sqrt(np.asarray(xi) ** 2 + np.asarray(y) ** 2 + np.asarray(z) ** 2)
    return T0 + Q / (2 * np.pi * k * R) * np.exp(-V * (np.asarray(xi) + R) / (2 * alpha))


def rosenthal_max_width(Q: float, V: float, rho_c: float, T_iso: float, T0: float) -> float:
    """Maximum width (m) of the T_iso isotherm of Rosenthal's solution in the high-Peclet limit.

    w = sqrt(8 Q / (pi e rho c V (T_iso - T0))) (Christensen; Rosenthal's line-heat limit).
    """
    return math.sqrt(8 * Q / (math.pi * math.e * rho_c * V * (T_iso - T0)))


@dataclass(frozen=True)
class Pool:
    """Melt-pool dimensions on and in the substrate (m, m3); zeros when nothing melts."""

    width: float
    length: float
    depth: float
    volume: float
    T_peak: float


def melt_pool(src: MovingSource, T_m: float, extent: float, n: int = 36) -> Pool:
    """Dimensions of the region T >= T_m of a moving source.

    The region is found on a box grid that grows until the pool no longer touches its sides (so annular or
    off-axis pools of a scanned ring are handled), then width, length and depth are refined by root finding
    on the grid line where each is largest. The volume is the grid count (error ~ one cell layer).

    Parameters
    ----------
    src : MovingSource
    T_m : float
        Melting temperature, K.
    extent : float
        Starting half-size (m) of the search box.
    n : int
        Grid points along x and y (z gets n/2).
    """
    front, back, side, deep = extent, 2 * extent, extent, extent
    for _ in range(12):
        x = np.linspace(-back, front, n)
        y = np.linspace(0.0, side, n // 2 + 1)
        X, Y = np.meshgrid(x, y, indexing="ij")
        Ts = src.temperature(np.stack([X, Y, np.zeros_like(X)], axis=-1))
        melt = Ts >= T_m
        grown = False
        if melt[-1, :].any():
            front *= 1.6
            grown = True
        if melt[0, :].any():
            back *= 1.6
            grown = True
        if melt[:, -1].any():
            side *= 1.6
            grown = True
        if not grown:
            break
    T_peak = float(_peak(src, x, y, Ts))
    if T_peak < T_m or not melt.any():
        return Pool(0.0, 0.0, 0.0, 0.0, T_peak)

    def Tat(xi, yy, zz):
        return float(src.temperature(np.array([xi, yy, zz])))

    # Width: outermost melted y of each x column, refined on the widest column.
    iy = np.where(melt.any(axis=0))[0].max()
    ix = int(np.argmax(np.where(melt[:, iy], Ts[:, iy], -np.inf)))
    y_hi = y[iy + 1] if iy + 1 < len(y) else side * 1.6
    half_w = optimize.brentq(lambda s: Tat(x[ix], s, 0.0) - T_m, y[iy], y_hi, xtol=1e-8)
    # Length: the extreme melted x at any y, refined on those rows.
    cols = np.where(melt.any(axis=1))[0]
    i_f, i_b = cols.max(), cols.min()
    jf = int(np.argmax(np.where(melt[i_f], Ts[i_f], -np.inf)))
    jb = int(np.argmax(np.where(melt[i_b], Ts[i_b], -np.inf)))
    x_f = optimize.brentq(lambda s: Tat(s, y[jf], 0.0) - T_m, x[i_f], x[min(i_f + 1, n - 1)], xtol=1e-8) \
        if i_f + 1 < n else x[i_f]
    x_b = optimize.brentq(lambda s: Tat(s, y[jb], 0.0) - T_m, x[max(i_b - 1, 0)], x[i_b], xtol=1e-8) \
        if i_b > 0 else x[i_b]
    # Depth and volume: a 3-D grid over the melted surface box.
    xm = x[max(i_b - 1, 0): min(i_f + 2, n)]
    ym = y[: min(iy + 2, len(y))]
    for _ in range(12):
        z = -np.linspace(0.0, deep, n // 2 + 1)
        X3, Y3, Z3 = np.meshgrid(xm, ym, z, indexing="ij")
        T3 = src.temperature(np.stack([X3, Y3, Z3], axis=-1))
        m3 = T3 >= T_m
        if not m3[:, :, -1].any() or deep >= src.thickness:
            break
        deep = min(deep * 1.6, src.thickness)
    kz = np.where(m3.any(axis=(0, 1)))[0].max()
    i3, j3 = np.unravel_index(np.argmax(np.where(m3[:, :, kz], T3[:, :, kz], -np.inf)), m3.shape[:2])
    if kz + 1 < len(z):
        depth = -optimize.brentq(lambda s: Tat(xm[i3], ym[j3], s) - T_m, z[kz + 1], z[kz], xtol=1e-8)
    else:
        depth = -z[kz]
    cell = (xm[1] - xm[0]) * (ym[1] - ym[0]) * (z[0] - z[1])
    # Trapezoid weights: half cells on the y = 0 symmetry plane and the z = 0 surface.
    w = np.ones(m3.shape)
    w[:, 0, :] *= 0.5
    w[:, :, 0] *= 0.5
    volume = 2 * float((m3 * w).sum()) * cell
    return Pool(width=2 * half_w, length=x_f - x_b, depth=depth, volume=volume, T_peak=T_peak)


def _peak(src: MovingSource, x: np.ndarray, y: np.ndarray, Ts: np.ndarray) -> float:
    """Peak surface temperature (K), refined from the grid maximum; inf for a point source."""
    if src.sigma == 0 and src.ring_radius == 0:
        return math.inf
    i, j = np.unravel_index(np.argmax(Ts), Ts.shape)
    res = optimize.minimize(lambda p: -float(src.temperature(np.array([p[0], abs(p[1]), 0.0]))),
                            x0=[x[i], y[j]], method="Nelder-Mead",
                            options={"xatol": 1e-7, "fatol": 1e-3})
    return max(float(Ts[i, j]), -float(res.fun))


# --- bead cap ---------------------------------------------------------------------------------------------

def cap_shape(theta: float) -> float:
    """A / w^2 of a circular cap with contact angle theta (rad): (theta - sin cos) / (4 sin^2)."""
    return (theta - math.sin(theta) * math.cos(theta)) / (4 * math.sin(theta) ** 2)


def cap_angle(width: float, area: float) -> float:
    """Contact angle (rad) of the circular cap of given base width and area (0 < theta < pi)."""
    target = area / width**2
    return optimize.brentq(lambda t: cap_shape(t) - target, 1e-6, math.pi - 1e-6, xtol=1e-12)


def cap_area(width: float, height: float) -> float:
    """Area of the circular cap of base width and height (any consistent length unit); 0 if either is 0."""
    if width <= 0 or height <= 0:
        return 0.0
    theta = 2 * math.atan(2 * height / width)
    return width**2 * cap_shape(theta)


def cap_height(width: float, theta: float) -> float:
    """Height of a circular cap of base width and contact angle theta (rad)."""
    return width / 2 * math.tan(theta / 2)


def cap_width(area: float, theta: float) -> float:
    """Base width of the circular cap of given area and contact angle theta (rad)."""
    return math.sqrt(area / cap_shape(theta))


def wire_melt_power(mat: Material, d: float, V_w: float, T0: float) -> float:
    """Power (W) to heat the wire from T0 and melt it: rho (pi d^2/4) V_w (c (T_m - T0) + L)."""
    return mat.rho * math.pi * d**2 / 4 * V_w * (mat.cp * (mat.T_melt - T0) + mat.latent_heat)


def classify(absorbed: float, p_wire: float, pool: Pool, aspect: float, theta_deg: float,
             thickness: float, wire_fed: bool = True) -> str:
    """The process regime (one of REGIMES); ``wire_fed`` False for a beam-only pass."""
    if wire_fed and absorbed <= p_wire:
        return "no_wire_melt"
    if pool.width <= 0:
        return "lack_of_fusion"
    if math.isfinite(thickness) and pool.depth >= 0.999 * thickness:
        return "burn_through"
    if not wire_fed:
        return "beam_only"
    if theta_deg > 85 or aspect > 0.6:
        return "tall_bead"
    if theta_deg < 20 or aspect < 0.12:
        return "flat_bead"
    return "ok"


def run_reduced(params: dict, material: Material) -> dict:
    """Evaluate the reduced model for one parameter set (keys of beadsim.parameters).

    Returns
    -------
    dict
        Metrics named as in beadsim.metrics.METRICS plus ``regime``.
    """
    t_start = time.perf_counter()
    mm = 1e-3
    P, eta = params["beam_power_W"], params["beam_efficiency"]
    V_s, V_w = params["substrate_speed_mm_s"] * mm, params["wire_feed_mm_s"] * mm
    d = params["wire_diameter_mm"] * mm
    T0 = params["preheat_K"]
    absorbed = eta * P
    p_wire = wire_melt_power(material, d, V_w, T0)
    profile = params["beam_profile"]
    sigma = params["beam_spot_radius_mm"] * mm
    R0 = params["scan_diameter_mm"] * mm / 2 if profile in ("ring", "scan") else 0.0
    src = MovingSource(Q=max(absorbed - p_wire, 0.0), V=V_s, rho_c=material.rho * material.cp,
                       alpha=material.diffusivity, T0=T0, sigma=sigma, ring_radius=R0,
                       thickness=params["substrate_thickness_mm"] * mm)
    if src.Q > 0:
        pool = melt_pool(src, material.T_melt, extent=max(2 * R0, 4 * sigma, 1e-3))
    else:
        pool = Pool(0.0, 0.0, 0.0, 0.0, T0)

    area = math.pi * d**2 / 4 * V_w / V_s  # m2
    theta_e = math.radians(params["wetting_angle_deg"] or material.contact_angle_deg)
    if area > 0:
        width = max(pool.width, cap_width(area, theta_e))
        theta = cap_angle(width, area)
        height = cap_height(width, theta)
    else:
        width = height = theta = 0.0
    theta_deg = math.degrees(theta)
    aspect = height / width if width > 0 else 0.0
    regime = classify(absorbed, p_wire, pool, aspect, theta_deg, src.thickness, wire_fed=area > 0)
    return {
        "bead_width_mm": width / mm,
        "bead_height_mm": height / mm,
        "bead_area_mm2": area / mm**2,
        "aspect_ratio": aspect,
        "contact_angle_deg": theta_deg,
        "penetration_depth_mm": pool.depth / mm,
        "pool_length_mm": pool.length / mm,
        "pool_width_mm": pool.width / mm,
        "pool_depth_mm": pool.depth / mm,
        "pool_volume_mm3": pool.volume / mm**3,
        "T_max_K": pool.T_peak,
        "wire_supply_area_mm2": area / mm**2,
        "mass_balance_ratio": 1.0 if area > 0 else math.nan,  # no wire: undefined
        "wire_melt_power_W": p_wire,
        "absorbed_power_W": absorbed,
        "wall_time_s": time.perf_counter() - t_start,
        "regime": regime,
    }
