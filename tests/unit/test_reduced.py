"""Reduced bead model against analytic limits."""

import math

import numpy as np
import pytest
from scipy import special

from beadsim.materials import get_material
from beadsim.parameters import defaults
from beadsim.reduced import (MovingSource, cap_angle, cap_area, cap_height, cap_width, melt_pool,
                             rosenthal, rosenthal_max_width, run_reduced, wire_melt_power)

TI = get_material("Ti-Gr2")


def source(**kw):
    base = dict(Q=500.0, V=5e-3, rho_c=TI.rho * TI.cp, alpha=TI.diffusivity, T0=300.0)
    return MovingSource(**{**base, **kw})


def test_point_source_is_rosenthal():
    pts = np.array([[1e-3, 0, 0], [-2e-3, 1e-3, -0.5e-3], [-5e-3, 0, 0], [0, 3e-3, 0], [-1e-4, 0, -2e-4]])
    got = source().temperature(pts)
    want = rosenthal(500.0, 5e-3, TI.k, TI.diffusivity, 300.0, *pts.T)
    np.testing.assert_allclose(got, want, rtol=1e-6)


def test_small_spot_and_ring_tend_to_point_source_far_away():
    far = np.array([[-6e-3, 2e-3, -1e-3], [4e-3, -3e-3, 0.0]])
    want = rosenthal(500.0, 5e-3, TI.k, TI.diffusivity, 300.0, *far.T)
    np.testing.assert_allclose(source(sigma=1e-5).temperature(far), want, rtol=1e-4)
    np.testing.assert_allclose(source(sigma=1e-5, ring_radius=5e-5).temperature(far), want, rtol=1e-3)


def test_thin_plate_limit_is_two_dimensional_rosenthal():
    """A plate much thinner than the thermal length: T = Q/(2 pi k H) exp(-V xi/2a) K0(V r/2a)."""
    H, V, a = 0.2e-3, 5e-3, TI.diffusivity
    src = source(thickness=H, sigma=1e-6)
    pts = np.array([[-5e-3, 2e-3, -0.1e-3], [-10e-3, 0.0, 0.0], [3e-3, 4e-3, -0.2e-3]])
    r = np.hypot(pts[:, 0], pts[:, 1])
    want = 300 + 500 / (2 * np.pi * TI.k * H) * np.exp(-V * pts[:, 0] / (2 * a)) * special.k0(V * r / (2 * a))
    np.testing.assert_allclose(src.temperature(pts), want, rtol=0.01)


def test_high_peclet_pool_width_matches_line_source_formula():
    """At high speed the widest isotherm of the point source follows w = sqrt(8Q/(pi e rho c V dT))."""
    V, Q = 0.05, 3000.0
    src = source(Q=Q, V=V)
    pool = melt_pool(src, TI.T_melt, extent=2e-3)
    want = rosenthal_max_width(Q, V, TI.rho * TI.cp, TI.T_melt, 300.0)
    assert pool.width == pytest.approx(want, rel=0.03)
    assert pool.length > pool.width  # elongated pool at high Peclet number


def test_pool_volume_of_rosenthal_is_consistent_with_its_dimensions():
    pool = melt_pool(source(), TI.T_melt, extent=1e-3)
    ellipsoid_half = math.pi / 6 * pool.length * pool.width * pool.depth  # half an ellipsoid (below the surface)
    assert 0.6 * ellipsoid_half < pool.volume < 1.4 * ellipsoid_half
    # Rosenthal's isotherms are surfaces of the point-source solution: depth equals half-width.
    assert pool.depth == pytest.approx(pool.width / 2, rel=0.02)


@pytest.mark.parametrize("theta_deg", [20, 45, 60, 90, 120])
def test_cap_geometry_round_trip(theta_deg):
    theta = math.radians(theta_deg)
    w = cap_width(2.0, theta)
    assert math.degrees(cap_angle(w, 2.0)) == pytest.approx(theta_deg, rel=1e-9)
    assert cap_area(w, cap_height(w, theta)) == pytest.approx(2.0, rel=1e-9)


def test_semicircle_cap():
    assert cap_height(2.0, math.pi / 2) == pytest.approx(1.0)
    assert cap_width(math.pi / 2, math.pi / 2) == pytest.approx(2.0)


def test_mode1_bead_conserves_wire_metal_and_fuses():
    p = defaults()
    r = run_reduced(p, TI)
    supply = math.pi * 1.2**2 / 4 * 10 / 5
    assert r["bead_area_mm2"] == pytest.approx(supply)
    assert cap_area(r["bead_width_mm"], r["bead_height_mm"]) == pytest.approx(supply, rel=1e-6)
    assert r["bead_width_mm"] >= r["pool_width_mm"]
    assert r["regime"] in ("ok", "flat_bead")
    assert r["wire_melt_power_W"] == pytest.approx(wire_melt_power(TI, 1.2e-3, 10e-3, 300.0))


def test_regimes_at_low_power():
    p = defaults()
    p_wire = wire_melt_power(TI, 1.2e-3, 10e-3, 300.0)
    assert run_reduced({**p, "beam_power_W": 0.9 * p_wire / 0.85}, TI)["regime"] == "no_wire_melt"
    low = run_reduced({**p, "beam_power_W": 1.3 * p_wire / 0.85}, TI)
    assert low["regime"] == "lack_of_fusion" and low["pool_width_mm"] == 0


def test_more_power_wider_bead():
    p = defaults()
    widths = [run_reduced({**p, "beam_power_W": P}, TI)["pool_width_mm"] for P in (600, 900, 1200)]
    assert widths[0] < widths[1] < widths[2]


def test_beam_only_pass_has_no_bead_and_no_mass_balance():
    p = {**defaults(), "wire_feed_mm_s": 0.0}
    r = run_reduced(p, TI)
    assert r["bead_area_mm2"] == 0.0 and r["bead_width_mm"] == 0.0 and r["wire_melt_power_W"] == 0.0
    assert math.isnan(r["mass_balance_ratio"])
    assert r["regime"] == "beam_only"  # not a flat bead: there is no bead
    assert run_reduced({**p, "beam_power_W": 50.0}, TI)["regime"] == "lack_of_fusion"
    # the whole absorbed power heats the plate: a wider pool than with the wire's melting power taken out
    assert r["pool_width_mm"] > run_reduced(defaults(), TI)["pool_width_mm"] > 0
