"""Scene geometry of the SPH model: the moving window against its sizing rules (no LAMMPS)."""

from __future__ import annotations

import math

import numpy as np
import pytest

from beadsim.materials import get_material
from beadsim.parameters import defaults
from beadsim.sph import scene


def window_case(**over) -> dict:
    p = defaults()
    p.update(model="sph", domain="window", resolution_mm=0.3, beam_power_W=1000.0, substrate_speed_mm_s=5.0,
             wire_feed_mm_s=10.0, scan_diameter_mm=2.0)
    p.update(over)
    return p


def test_window_is_sized_from_the_thermal_length():
    p = window_case()
    g = scene.build_geometry(p)
    mat = get_material(p["material"])
    thermal = p["window_thermal_lengths"] * mat.diffusivity / (p["substrate_speed_mm_s"] * 1e-3)
    footprint = p["scan_diameter_mm"] * 1e-3 / 2 + 3 * p["beam_spot_radius_mm"] * 1e-3
    dx = g.dx
    assert g.moving_window and g.beam_x(0.7) == 0.0
    assert footprint + thermal <= g.x_hi < footprint + thermal + dx + 1e-12
    assert footprint + thermal <= g.y_hi < footprint + thermal + dx + 1e-12
    tail = scene.pool_tail(p, mat)
    assert -g.x_lo >= tail + p["window_bead_mm"] * 1e-3 + 2 * dx - 1e-12
    assert "x_lo" not in g.cut_faces and "x_hi" not in g.cut_faces and "z_lo" in g.cut_faces
    # a faster substrate: shorter thermal length, narrower window
    assert scene.build_geometry(window_case(substrate_speed_mm_s=10.0)).y_hi < g.y_hi


def test_pool_tail_grows_with_power_and_vanishes_without_melting():
    mat = get_material("Ti-Gr2")
    tails = [scene.pool_tail(window_case(beam_power_W=w), mat) for w in (600.0, 1000.0, 1400.0)]
    assert 0 < tails[0] < tails[1] < tails[2] < 0.05
    assert scene.pool_tail(window_case(beam_power_W=50.0), mat) == 0.0


def test_beam_frame_velocities_and_inflow_layer():
    g = scene.build_geometry(window_case())
    assert np.allclose(g.substrate_velocity, [-g.substrate_speed, 0, 0])
    assert np.allclose(g.wire_velocity, -g.wire_feed * g.wire_axis)  # no travel term in the beam frame
    _, ny, nz = g.counts()
    layer = scene.substrate_layer(g, 1e-3)
    assert layer.shape == (ny * nz, 3) and np.allclose(layer[:, 0], 1e-3)
    # the layer continues the lattice of the initial block in y and z
    block = scene.substrate_positions(g)
    assert np.allclose(np.unique(layer[:, 1]), np.unique(block[:, 1]))
    assert np.allclose(np.unique(layer[:, 2]), np.unique(block[:, 2]))
    fixed = scene.build_geometry(window_case(domain="auto"))
    assert not fixed.moving_window and fixed.beam_x(0.2) == pytest.approx(0.2 * fixed.substrate_speed)
    assert np.allclose(fixed.wire_velocity, [fixed.substrate_speed, 0, 0] - fixed.wire_feed * fixed.wire_axis)
    assert math.isclose(scene.wire_slice_pitch(g), scene.wire_slice_pitch(fixed))


def _wire(g):
    """Initial wire particles and their axial distance from the tip plane (beam at x = 0)."""
    pos, s_last, _ = scene.initial_wire(g)
    s = (pos - np.array([0.0, 0.0, g.wire_height])) @ g.wire_axis
    return pos, s, s_last


@pytest.mark.parametrize("packing", ["stretched", "lattice"])
@pytest.mark.parametrize("dx", [0.3, 0.4, 0.5])
def test_intact_wire_stays_attached_and_a_cut_piece_is_detached(dx, packing):
    g = scene.build_geometry(window_case(resolution_mm=dx, wire_length_mm=4.0, wire_packing=packing))
    pos, s, s_last = _wire(g)
    link = scene.wire_link_length(g)
    assert not scene.detached_wire(pos, s, s_last, link).any()
    # melt a slab two slices thick across the whole wire, 1 mm up the axis: everything below it is cut off
    pitch = scene.wire_slice_pitch(g)
    slices = np.round(s / pitch - 0.5).astype(int)
    cut_slice = int(round(1e-3 / pitch))
    keep = (slices < cut_slice) | (slices > cut_slice + 1)
    cut = scene.detached_wire(pos[keep], s[keep], s_last, link)
    assert np.array_equal(cut, slices[keep] < cut_slice)
    # one melted slice with a single particle left standing keeps the tip attached through it
    one = (slices != cut_slice) | (np.arange(len(s)) == np.flatnonzero(slices == cut_slice)[0])
    assert not scene.detached_wire(pos[one], s[one], s_last, link).any()
    # no particle at the feed end: nothing is released on doubtful evidence
    top = slices < slices.max()
    assert not scene.detached_wire(pos[top], s[top], s_last, link).any()


@pytest.mark.parametrize("angle, height", [(45.0, 1.5), (30.0, 2.0), (70.0, 1.0)])
def test_wire_landing_point_is_where_the_fed_tip_meets_the_surface(angle, height):
    g = scene.build_geometry(window_case(resolution_mm=0.1, wire_angle_deg=angle, wire_height_mm=height))
    tip = scene.wire_slice(g, 0.0, 0.0)  # the tip face, particles on a fine grid
    low = tip[np.argmin(tip[:, 2])]
    travel = low[2] / math.sin(g.wire_angle)  # along -axis until the lowest point touches z = 0
    x_land = low[0] - travel * math.cos(g.wire_angle)
    assert g.wire_landing_x() == pytest.approx(x_land, abs=g.dx)
    assert np.allclose(g.wire_velocity_at(False), 0.0)  # held still relative to the beam before the feed starts


@pytest.mark.parametrize("dx", [0.2, 0.3, 0.4, 0.5])
def test_both_wire_packings_carry_the_nominal_wire_mass(dx):
    """Particles per unit length of wire x dx^3 = the nominal area: the stretched wire by its slice pitch, the
    lattice-packed one by its slice counts, with slices dx apart and no point further out than r + dx/2."""
    area = math.pi * 0.6e-3 ** 2  # d 1.2 mm, Table 4
    for packing in ("stretched", "lattice"):
        g = scene.build_geometry(window_case(resolution_mm=dx, wire_length_mm=8.0, wire_diameter_mm=1.2,
                                             wire_packing=packing))
        pos, s_last, n_slices = scene.initial_wire(g)
        pitch = scene.wire_slice_pitch(g)
        tol = 0.03 if packing == "lattice" else 1e-9
        assert len(pos) * g.dx ** 3 / (n_slices * pitch) == pytest.approx(area, rel=tol)
    assert pitch == g.dx
    axis_dist = np.linalg.norm(np.cross(pos - np.array([0.0, 0.0, g.wire_height]), g.wire_axis), axis=1)
    assert axis_dist.max() <= 0.6e-3 + g.dx / 2
    # lattice-packed: every particle has its axial neighbour one dx along (the section varies only at the rim)
    s = (pos - np.array([0.0, 0.0, g.wire_height])) @ g.wire_axis
    assert np.allclose(np.diff(np.unique(np.round(s / g.dx, 6))), 1.0)
