"""Particle-cloud reductions against synthetic clouds of known shape.

The clouds are cubic lattices of spacing dx (a substrate below z = 0 and a circular-arc cap above it); a
particle belongs to the cap when its centre lies inside the arc. Tolerances follow from that discretisation:

* width: a bin counts when a whole particle fits under the cap at its centre, so the width is biased low
  by about dx / tan(theta) and quantised by dx: |error| <= dx / tan(theta) + dx.
* height: the highest centre lies within dx of the cap top, and its cube reaches dx/2 above it:
  |error| <= dx/2.
* area: counting cubes misses or adds at most half a cube along the arc, which cancels on average; a 3 mm wide
  cap at dx = 0.1 mm is ~ 150 bins, so a few per cent (asserted: 4 %).
* contact angle: a least-squares circle through ~30 staircase points: within 4 degrees.
"""

import numpy as np
import pytest

from beadsim.sph.surface import (
    bead_cross_section,
    height_map,
    isotherm_extent,
    lattice_cap_readings,
    lattice_phase,
    mass_height_profile,
    mass_width,
    penetration_depth,
    pool_geometry,
    smoothed_peak,
    top_layer_registration,
)

DX = 1e-4  # m
WIDTH = 3e-3  # m, cap footprint
WINDOW = (0.0, 2e-3)  # m, x range of the cross-section


def lattice(lo, hi, dx=DX):
    """Cell centres of a cubic lattice filling the box [lo, hi] (m)."""
    axes = [(np.arange(int(round((b - a) / dx))) + 0.5) * dx + a for a, b in zip(lo, hi)]
    return np.stack(np.meshgrid(*axes, indexing="ij"), axis=-1).reshape(-1, 3)


def cap_shape(width, theta_deg):
    """Radius, height and area of a circular cap of given footprint width and contact angle (SI)."""
    theta = np.radians(theta_deg)
    radius = 0.5 * width / np.sin(theta)
    height = radius * (1.0 - np.cos(theta))
    area = radius**2 * theta - (radius - height) * 0.5 * width
    return radius, height, area


def bead_cloud(theta_deg, jitter=0.0, y_shift=0.0, seed=1):
    """Substrate 2 x 6 x 1 mm below z = 0 plus a cap along x; positions jittered by +-jitter*dx."""
    radius, height, _ = cap_shape(WIDTH, theta_deg)
    pos = lattice((0.0, -3e-3 + y_shift, -1e-3), (2e-3, 3e-3 + y_shift, height + 2 * DX))
    zc = height - radius
    inside = (pos[:, 2] < 0) | (pos[:, 1] ** 2 + (pos[:, 2] - zc) ** 2 <= radius**2)
    pos = pos[inside]
    return pos + np.random.default_rng(seed).uniform(-jitter * DX, jitter * DX, pos.shape)


def test_lattice_phase_recovers_offset():
    values = (np.arange(50) + 0.3) * DX + np.random.default_rng(0).uniform(-0.1, 0.1, 50) * DX
    assert lattice_phase(values, DX) == pytest.approx(0.3, abs=0.02)


def test_flat_substrate_has_zero_height():
    pos = lattice((0.0, -1e-3, -1e-3), (2e-3, 1e-3, 0.0))
    y, top = height_map(pos, DX, WINDOW)
    assert len(y) == 20
    np.testing.assert_allclose(top, 0.0, atol=1e-12)
    res = bead_cross_section(pos, DX, WINDOW)
    assert res["bead_width_mm"] == 0.0
    assert res["bead_area_mm2"] == pytest.approx(0.0, abs=1e-12)


@pytest.mark.parametrize("theta_deg", [30.0, 60.0, 90.0])
@pytest.mark.parametrize("jitter,y_shift", [(0.0, 0.0), (0.1, 3e-5)])
def test_cap_cross_section(theta_deg, jitter, y_shift):
    _, height, area = cap_shape(WIDTH, theta_deg)
    pos = bead_cloud(theta_deg, jitter, y_shift)
    res = bead_cross_section(pos, DX, WINDOW)
    width_tol = DX / np.tan(np.radians(theta_deg)) + DX
    assert res["bead_width_mm"] == pytest.approx(WIDTH * 1e3, abs=width_tol * 1e3)
    assert res["bead_height_mm"] == pytest.approx(height * 1e3, abs=0.5 * DX * 1e3 + 1e-9)
    assert res["bead_area_mm2"] == pytest.approx(area * 1e6, rel=0.04)
    assert res["contact_angle_deg"] == pytest.approx(theta_deg, abs=4.0)


def test_overhanging_cap_width_seen_from_above():
    """At 120 degrees the widest part (2R) overhangs the footprint; seen from above it is 2R."""
    radius, _, area = cap_shape(WIDTH, 120.0)
    res = bead_cross_section(bead_cloud(120.0), DX, WINDOW)
    assert res["bead_width_mm"] == pytest.approx(2 * radius * 1e3, abs=DX * 1e3)
    assert res["bead_area_mm2"] == pytest.approx(area * 1e6, rel=0.04)
    # the fit takes the edges seen from above (at 2R) as contact points: 115 degree, biased low
    assert res["contact_angle_deg"] == pytest.approx(120.0, abs=7.0)


def test_flat_puddle_has_a_small_contact_angle():
    """One particle layer 3 mm wide: a shallow arc through the edges, 2 atan(2 H / W) = 7.6 degree."""
    sub = lattice((0.0, -3e-3, -1e-3), (2e-3, 3e-3, 0.0))
    puddle = lattice((0.0, -1.5e-3, 0.0), (2e-3, 1.5e-3, DX))
    res = bead_cross_section(np.vstack([sub, puddle]), DX, WINDOW)
    assert res["bead_width_mm"] == pytest.approx(3.0)
    assert res["bead_height_mm"] == pytest.approx(0.1)
    assert res["bead_area_mm2"] == pytest.approx(0.3)
    assert res["contact_angle_deg"] == pytest.approx(np.degrees(2 * np.arctan(2 * DX / WIDTH)), abs=4.0)


def test_stray_particles_do_not_change_the_result():
    pos = bead_cloud(60.0, jitter=0.1)
    clean = bead_cross_section(pos, DX, WINDOW)
    strays = np.array([[1.0e-3, 0.0, 3e-3], [0.55e-3, 2.5e-3, 0.4e-3], [1.25e-3, -2.2e-3, 0.2e-3]])
    dirty = bead_cross_section(np.vstack([pos, strays]), DX, WINDOW)
    # the strays only nudge the lattice phase estimate (circular mean over ~8000 particles): 1e-3 relative
    assert dirty == pytest.approx(clean, rel=1e-3)


def test_mask_excludes_material():
    pos = bead_cloud(60.0)
    res = bead_cross_section(pos, DX, WINDOW, mask=pos[:, 2] < 0)
    assert res["bead_width_mm"] == 0.0 and res["bead_height_mm"] == 0.0


def test_z_surface_shift():
    pos = bead_cloud(60.0)
    base = bead_cross_section(pos, DX, WINDOW)
    shifted = bead_cross_section(pos + [0.0, 0.0, 0.7e-3], DX, WINDOW, z_surface=0.7e-3)
    assert shifted == pytest.approx(base, rel=1e-9, abs=1e-9)


def ellipsoid_pool(a, b, c):
    """Lattice particles of a half-ellipsoid below z = 0 (semi-axes a, b in x, y; depth c)."""
    pos = lattice((-a - DX, -b - DX, -c - DX), (a + DX, b + DX, 0.0))
    r2 = (pos[:, 0] / a) ** 2 + (pos[:, 1] / b) ** 2 + (pos[:, 2] / c) ** 2
    return pos[r2 <= 1.0]


def test_pool_geometry_ellipsoid():
    a, b, c = 2.0e-3, 1.0e-3, 0.6e-3
    pool = ellipsoid_pool(a, b, c)
    droplet = np.array([[5e-3, 0.0, 1e-3]])  # detached spatter: ignored
    res = pool_geometry(np.vstack([pool, droplet]), DX)
    assert res["pool_length_mm"] == pytest.approx(2 * a * 1e3, abs=DX * 1e3)
    assert res["pool_width_mm"] == pytest.approx(2 * b * 1e3, abs=DX * 1e3)
    assert res["pool_depth_mm"] == pytest.approx(c * 1e3, abs=0.5 * DX * 1e3 + 1e-9)
    # half-ellipsoid volume 2/3 pi a b c; surface cells make a few per cent at ~2500 cells
    assert res["pool_volume_mm3"] == pytest.approx(2.0 / 3.0 * np.pi * a * b * c * 1e9, rel=0.05)


def test_pool_geometry_empty():
    assert pool_geometry(np.empty((0, 3)), DX)["pool_volume_mm3"] == 0.0


def test_penetration_depth_of_melted_ellipsoid():
    a, b, c = 3.0e-3, 1.0e-3, 0.6e-3
    sub = lattice((-1e-3, -2e-3, -1.5e-3), (1e-3, 2e-3, 0.0))
    melted = (sub[:, 0] / a) ** 2 + (sub[:, 1] / b) ** 2 + (sub[:, 2] / c) ** 2 <= 1.0
    # a stray melted particle deep in one column must not count
    melted[np.argmin(np.hypot(sub[:, 0] - 0.55e-3, sub[:, 1] - 1.5e-3) + np.abs(sub[:, 2] + 1.45e-3))] = True
    depth = penetration_depth(sub, melted, DX, (-1e-3, 1e-3))
    # deepest melted centre lies within dx of c; its cube adds dx/2; the median over x reduces it by at most
    # the arc's drop over |x| <= 1 mm (c (1 - sqrt(1 - 1/9)) = 0.034 mm)
    assert depth == pytest.approx(c * 1e3, abs=0.5 * DX * 1e3 + 0.034)
    assert penetration_depth(sub, np.zeros(len(sub), bool), DX, (-1e-3, 1e-3)) == 0.0


def test_width_edges_are_interpolated_on_averaged_profiles():
    """A profile averaged over sections has fractional heights: the edges sit where it crosses dx/2."""
    from beadsim.sph.surface import profile_metrics

    dx = 4e-4
    h = np.array([0.0, 0.5, 1.0, 2.0, 1.0, 0.25, 0.0]) * dx
    y = (np.arange(len(h)) - 3) * dx
    # left: between 1.0 and 0.5 -> a whole bin beyond the run; right: (1 - 0.5) / (1 - 0.25) of a bin
    expected = (3 - 1 + 1.0 + 0.5 / 0.75) * dx * 1e3
    assert profile_metrics(y, h, dx)["bead_width_mm"] == pytest.approx(expected, rel=1e-12)
    lattice = np.array([np.nan, 0.0, 1.0, 1.0, 1.0, 0.0]) * dx  # whole layers: n dx as before
    assert profile_metrics(y[:6], lattice, dx)["bead_width_mm"] == pytest.approx(3 * dx * 1e3, rel=1e-12)


def test_fusion_width_is_the_molten_top_seen_from_above():
    """A flat bead one layer thick (too thin for a robust height-threshold width) on a substrate whose top
    layer melted 1 mm wider than the bead: the fused width is the molten top, bead included."""
    from beadsim.sph.surface import fusion_width

    substrate = lattice((0.0, -3e-3, -1e-3), (2e-3, 3e-3, 0.0))
    bead = lattice((0.0, -1e-3, 0.0), (2e-3, 1e-3, DX))  # 2 mm wide, one layer
    pos = np.vstack([substrate, bead])
    melted = (np.abs(pos[:, 1]) < 1.5e-3) & (pos[:, 2] > -3 * DX)  # 3 mm wide molten top, 3 layers deep
    assert fusion_width(pos, melted, DX, WINDOW) == pytest.approx(3.0, abs=1e-9)
    assert fusion_width(pos, np.zeros(len(pos), bool), DX, WINDOW) == 0.0
    # a stray unmolten particle on top of one column does not cut the fused run: it takes that column's share
    stray = np.array([[0.5 * DX, 0.05e-3, 1.5 * DX]])
    columns = round((WINDOW[1] - WINDOW[0]) / DX)
    assert fusion_width(np.vstack([pos, stray]), np.append(melted, False), DX, WINDOW) == pytest.approx(
        3.0 - DX * 1e3 / columns, abs=1e-9)


def test_fusion_width_between_lattice_steps():
    """A molten edge that steps out by one spacing halfway along the window (a pool whose width fluctuated as
    the lattice moved through it): the fused width is the mean, 3.1 mm, not a whole number of spacings."""
    from beadsim.sph.surface import fusion_width

    pos = lattice((0.0, -3e-3, -1e-3), (2e-3, 3e-3, 0.0))
    half = np.where(pos[:, 0] < 1e-3, 1.5e-3, 1.6e-3)
    melted = (np.abs(pos[:, 1]) < half) & (pos[:, 2] > -3 * DX)
    assert fusion_width(pos, melted, DX, WINDOW) == pytest.approx(3.1, abs=1e-9)


def test_plate_fusion_width_leaves_the_deposit_out():
    """A bead 2 mm wide and three layers thick, all of it once molten, on a plate whose top melted 1.2 mm wide
    under it: the fused top seen from above is the bead's 2 mm, the plate's fused surface 1.2 mm; with the plate
    melted 3 mm wide (wider than the bead) both read 3 mm."""
    from beadsim.sph.surface import fusion_width, plate_fusion_width

    plate = lattice((0.0, -3e-3, -1e-3), (2e-3, 3e-3, 0.0))
    bead = lattice((0.0, -1e-3, 0.0), (2e-3, 1e-3, 3 * DX))
    pos = np.vstack([plate, bead])
    for half, fused, plate_fused in ((0.6e-3, 2.0, 1.2), (1.5e-3, 3.0, 3.0)):
        melted = (pos[:, 2] > 0) | ((np.abs(pos[:, 1]) < half) & (pos[:, 2] > -3 * DX))
        assert fusion_width(pos, melted, DX, WINDOW) == pytest.approx(fused, abs=1e-9)
        assert plate_fusion_width(pos, melted, DX, WINDOW) == pytest.approx(plate_fused, abs=1e-9)
    assert plate_fusion_width(pos, pos[:, 2] > 0, DX, WINDOW) == 0.0  # metal on a plate that never melted


def test_mean_profile_aligns_maps_on_whole_bins():
    """Maps taken at different times: the melt shifts the lattice phase by a fraction of a spacing and a stray
    particle widens the extent; the mean is bin by bin on the union, a map on another lattice is left out."""
    from beadsim.sph.surface import mean_profile

    dx = 4e-4
    h1 = np.array([0.0, 1.0, 2.0, 3.0, 2.0, 1.0, 0.0]) * dx
    h2 = np.array([np.nan, 0.0, 0.0, 2.0, 3.0, 4.0, 3.0, 2.0, 0.0]) * dx  # two bins more on the left
    y1 = np.arange(7) * dx + 0.013 * dx
    y2 = (np.arange(9) - 2) * dx - 0.021 * dx
    y_other = np.arange(7) * dx + 0.5 * dx  # half a spacing off: another lattice
    empty = (np.empty(0), np.empty(0))  # a window without particles
    y, h, n_used = mean_profile([(y1, h1), (y_other, h1), (y2, h2), empty], dx)
    assert n_used == 2
    np.testing.assert_allclose(y, y2, rtol=0, atol=1e-12 * dx)  # the last map's bins
    expected = np.concatenate([h2[:2], 0.5 * (h1 + h2[2:])])
    np.testing.assert_allclose(h[1:], expected[1:], rtol=1e-12)
    assert np.isnan(h[0])  # empty in every map that has the bin
    assert mean_profile([empty], dx)[2] == 0


def test_mean_profile_of_jittered_maps_of_one_cap_is_that_cap():
    """Height maps of one cap from clouds jittered differently (phases differ by ~1e-3 dx): all go into the
    mean, whose width and height are those of a single map within a spacing."""
    from beadsim.sph.surface import mean_profile, profile_metrics

    maps = []
    for seed in (1, 2, 3):
        pos = bead_cloud(60, jitter=0.2, seed=seed)
        if seed == 3:  # a stray particle beside the plate widens this map's extent by a few bins
            pos = np.vstack([pos, [[1e-3, 3.35e-3, -0.5e-3]]])
        maps.append(height_map(pos, DX, WINDOW))
    assert not np.allclose(maps[0][0][:5], maps[1][0][:5], rtol=0, atol=1e-10)  # not the same bins
    y, h, n_used = mean_profile(maps, DX)
    assert n_used == 3
    one = profile_metrics(*maps[0], DX)
    mean = profile_metrics(y, h, DX)
    _, height, _ = cap_shape(WIDTH, 60)
    assert mean["bead_width_mm"] == pytest.approx(one["bead_width_mm"], abs=DX * 1e3)
    assert mean["bead_height_mm"] == pytest.approx(height * 1e3, abs=0.5 * DX * 1e3)


@pytest.mark.parametrize("shift", [0.0, 0.37])
def test_isotherm_extent_of_an_analytic_field(shift):
    # T = T_peak exp(-x^2/a^2 - y^2/b^2) decaying with depth, sampled on a coarse lattice (dx 0.4 mm, shifted
    # by a fraction of a spacing): seen from above (the hottest particle of each column, the top layer at z_top)
    # the isotherm T_iso is an ellipse of half-axes a, b times sqrt(ln(T_peak exp(z_top / 1 mm) / T_iso)).
    dx, a, b, t_peak, t_iso = 4e-4, 2.2e-3, 1.5e-3, 4000.0, 1941.0
    pos = lattice((-6e-3, -4e-3, -2e-3), (6e-3, 4e-3, 0.0), dx) + shift * dx
    temp = t_peak * np.exp(-(pos[:, 0] / a) ** 2 - (pos[:, 1] / b) ** 2 + pos[:, 2] / 1e-3)
    scale = np.sqrt(np.log(t_peak * np.exp(pos[:, 2].max() / 1e-3) / t_iso))
    ext = isotherm_extent(pos, temp, t_iso, dx)
    # linear interpolation between column centres of a Gaussian flank: measured -1.7 to +0.5 % here; the
    # widest row or column sits up to dx/2 off the axis, which narrows the extent by ~ (dx/2)^2 / (2 a^2 ln)
    assert ext["width_mm"] == pytest.approx(2 * b * scale * 1e3, rel=0.03)
    assert ext["length_mm"] == pytest.approx(2 * a * scale * 1e3, rel=0.03)
    assert isotherm_extent(pos, temp, 2 * t_peak, dx) == {"width_mm": 0.0, "length_mm": 0.0}


def test_lattice_cap_readings_of_a_known_bead():
    """The measure applied to a cap filled with particles. Stacked on the plate's layers (centres at dx/2,
    3 dx/2, ...) a cap of height H reads n dx, n the number of layer centres below H: a 3.3 x 0.9 mm cap reads
    0.8 mm at dx 0.4 (two layers) and 0.9 mm at dx 0.3 (three). Over random phases the top centre lies anywhere
    within dx below H, so the mean reading is H within a fraction of dx; the width reads low (a bin counts
    only where a whole particle fits under the cap). All of it vanishes as dx shrinks."""
    w, h = 3.3e-3, 0.9e-3
    for dx, n_layers in ((0.4e-3, 2), (0.3e-3, 3)):
        r = lattice_cap_readings(w, h, dx)
        assert r["height_registered_mm"] == pytest.approx(n_layers * dx * 1e3)
        assert r["height_random_mm"] == pytest.approx(h * 1e3, abs=0.25 * dx * 1e3)
        assert r["height_lo_mm"] >= (h - dx) * 1e3 - 1e-9 and r["height_hi_mm"] <= (h + 0.5 * dx) * 1e3 + 1e-9
        assert r["width_lo_mm"] <= r["width_random_mm"] < w * 1e3
        assert w * 1e3 - r["width_random_mm"] < 2 * dx * 1e3
    with pytest.raises(ValueError, match="positive width, height and dx"):
        lattice_cap_readings(w, 0.0, 0.4e-3)
    fine = lattice_cap_readings(w, h, 0.05e-3)
    for key in ("registered", "random"):
        assert fine[f"height_{key}_mm"] == pytest.approx(h * 1e3, rel=0.03)
        assert fine[f"width_{key}_mm"] == pytest.approx(w * 1e3, rel=0.02)


def test_top_layer_registration():
    """Tops stacked on the plate's layers read phase 0 and order 1; a cap lifted by a third of a spacing reads
    phase 1/3; tops at every height (jittered by a whole spacing) read an order near 0."""
    pos = bead_cloud(60.0)  # lattice cells centred at (k + 1/2) DX: the cap continues the plate's layers
    phase, order = top_layer_registration(pos, DX, WINDOW)
    assert phase == pytest.approx(0.0, abs=1e-9) and order == pytest.approx(1.0)
    lifted = pos + np.where(pos[:, 2:] > 0, DX / 3, 0.0) * np.array([0.0, 0.0, 1.0])
    assert top_layer_registration(lifted, DX, WINDOW) == pytest.approx((1 / 3, 1.0))
    rng = np.random.default_rng(3)
    shaken = pos + np.where(pos[:, 2:] > 0, rng.uniform(0, DX, (len(pos), 1)), 0.0) * np.array([0.0, 0.0, 1.0])
    assert top_layer_registration(shaken, DX, WINDOW)[1] < 0.3
    assert np.isnan(top_layer_registration(pos[pos[:, 2] < 0], DX, WINDOW)[1])  # a bare plate has no tops


def test_mass_height_profile_of_a_lattice_cap_is_its_height_map():
    """Particles stacked in columns: the mass per column and the highest particle tell the same height, bin by
    bin, and the profile's area is the cap's particles."""
    pos = bead_cloud(60.0)
    y, top = height_map(pos, DX, WINDOW)
    y_m, mass = mass_height_profile(pos, DX, WINDOW, -1e-3)
    np.testing.assert_allclose(y_m, y)
    np.testing.assert_allclose(mass, top, atol=1e-12)
    n_cap = int((pos[:, 2] > 0).sum())
    assert np.sum(mass) * DX == pytest.approx(n_cap * DX**3 / (WINDOW[1] - WINDOW[0]), rel=1e-9)


def test_mass_width_counts_toe_metal_the_height_map_misses():
    """A lattice cap: the width by mass is the height map's width. Add, on each side, three bins where every
    other x column holds two particles (7 of the 18 columns the mean takes: 0.78 dx of metal per column): the
    map's median column is bare there, so its width stays; the mass crosses dx/2 three bins further out on
    each side, the edges interpolated as before (a fraction (h - dx/2) / h of a bin beyond the edge bin)."""
    pos = bead_cloud(60.0)
    width = bead_cross_section(pos, DX, WINDOW)["bead_width_mm"] * 1e-3
    y, mass = mass_height_profile(pos, DX, WINDOW, -1e-3)
    assert mass_width(mass, DX) == pytest.approx(width, abs=1e-12)
    run = np.flatnonzero(mass > 0.5 * DX)
    columns = range(0, 16, 2)  # x columns holding toe metal; the window's first and last are left out of means
    toes = [((ix + 0.5) * DX, edge + side * k * DX, (iz + 0.5) * DX)
            for side, edge in ((-1, y[run[0]]), (1, y[run[-1]])) for k in (1, 2, 3) for ix in columns for iz in (0, 1)]
    wide = np.vstack([pos, toes])
    assert bead_cross_section(wide, DX, WINDOW)["bead_width_mm"] * 1e-3 == pytest.approx(width, abs=1e-12)
    mass_w = mass_height_profile(wide, DX, WINDOW, -1e-3)[1]
    toe = 2 * DX * 7 / 18
    assert mass_w.max() == mass.max()
    edge = mass[run[0]]
    assert mass_width(mass_w, DX) == pytest.approx(
        width + 2 * (3 + (toe - 0.5 * DX) / toe - (edge - 0.5 * DX) / edge) * DX, rel=1e-9)


def test_mass_height_profile_reads_a_disordered_surface_the_height_map_reads_low():
    """Particles at random (Poisson) positions in a slab 2.5 spacings thick on a lattice plate: a column's
    highest particle lies on average below the slab's top (some columns lack a particle near it), so the height
    map reads ~12 % low, as it did on the SPH beads' frozen melt; the mass per column reads the thickness."""
    dx, nx, ny, thick = 4e-4, 80, 24, 2.5 * 4e-4
    plate = lattice((0.0, 0.0, -6 * dx), (nx * dx, ny * dx, 0.0), dx)
    rng = np.random.default_rng(5)
    n = int(round(nx * ny * thick / dx))
    slab = np.column_stack([rng.uniform(0, nx * dx, n), rng.uniform(0, ny * dx, n), rng.uniform(0, thick, n)])
    pos = np.vstack([plate, slab])
    inner = slice(2, -2)
    top = height_map(pos, dx, (0.0, nx * dx))[1][inner]
    mass = mass_height_profile(pos, dx, (0.0, nx * dx), -6 * dx)[1][inner]
    assert np.mean(mass) == pytest.approx(thick, rel=0.03)
    assert np.mean(top) < 0.92 * thick
    # the window's first and last x columns are cut by it and left out: a window through the middle of the
    # columns at both ends reads the same
    cut = mass_height_profile(pos, dx, (0.5 * dx, (nx - 0.5) * dx), -6 * dx)[1][inner]
    assert np.mean(cut) == pytest.approx(thick, rel=0.03)


def test_smoothed_peak_reads_a_scattered_profile_without_the_highest_bins_bias():
    """Caps' profiles on bins of dx (each bin its exact mean height) plus a scatter of a third of a spacing (what
    single bins of the mass per column scatter by in the SPH beads): the highest bin reads the caps high, the
    peak of the (1, 2, 1) / 4 running mean reads them within a few per cent, at any phase of the bins."""
    dx = 4e-4
    rng = np.random.default_rng(11)
    for width, theta in ((3.3e-3, 62.0), (3.6e-3, 42.5), (4.2e-3, 58.0)):  # 0.99, 0.70, 1.16 mm high
        radius, height, _ = cap_shape(width, theta)
        for phase in (0.0, 0.5):
            edges = (np.arange(-8, 9) - 0.5 + phase) * dx
            yy = np.linspace(edges[0], edges[-1], 16 * 400 + 1)
            h = np.clip(np.sqrt(np.clip(radius**2 - yy**2, 0, None)) + height - radius, 0, None)
            exact = np.array([h[(yy >= a) & (yy < b)].mean() for a, b in zip(edges[:-1], edges[1:])])
            assert 0.95 * height < smoothed_peak(exact) < height
            draws = [exact + rng.normal(0, dx / 3, len(exact)) for _ in range(200)]
            assert np.mean([smoothed_peak(d) for d in draws]) == pytest.approx(height, rel=0.03)
            assert np.mean([d.max() for d in draws]) > 1.07 * height
    assert smoothed_peak(np.array([np.nan, 4.0, np.nan])) == pytest.approx(2.0) and smoothed_peak(np.empty(0)) == 0
