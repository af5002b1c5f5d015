"""Particle scene of the SPH bead model: the substrate block and the wire.

Frame: x is the travel direction, y across the bead, z up, the substrate top surface at z = 0, lengths in
metres. Two frames: ``domain`` auto/plate use the substrate frame (the substrate is fixed; the beam axis and
the wire move together at +V_s along x, starting at x = 0); ``domain = window`` uses the beam frame (the beam
axis stays at x = 0, the substrate moves at -V_s: it enters cold through the front face and the solid bead
leaves through the rear face).
The wire comes from the front (+x) and points down at ``wire_angle_deg``; its axis passes through the point
(x_beam, 0, wire_height_mm) and its cut tip face lies in the plane through that point normal to the axis.
Particles sit on a simple cubic lattice of spacing dx (substrate: cell centres, so the top layer is at -dx/2);
the wire is a stack of slices normal to its axis, each a square grid of spacing dx inside the disc, spaced along
the axis so that the particles carry the nominal wire mass (:func:`wire_slice_pitch`; ``wire_packing:
stretched``), or dx apart with as many grid points per slice as the nominal area holds on average
(``wire_packing: lattice``: the points nearest the axis, a rotating choice among equidistant ones).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

#: Never-melted substrate particle.
TYPE_SUBSTRATE = 1
#: Never-melted wire particle (moves rigidly at the feed velocity).
TYPE_WIRE = 2
#: Particle above the melting temperature (flows).
TYPE_LIQUID = 3
#: Particle that melted and froze again (fixed in space).
TYPE_RESOLIDIFIED = 4
#: Unmelted wire cut off from the fed wire (``wire_detach = fall``): no longer fed, it falls and moves with the
#: fluid (SPH forces and gravity) until it has melted.
TYPE_FALLING = 5
N_TYPES = 5
#: Types whose particles move by the SPH momentum equation (everything else is frozen between chunks).
FLUID_TYPES = (TYPE_LIQUID, TYPE_FALLING)


@dataclass(frozen=True)
class SceneGeometry:
    """Sizes of the modelled block and the wire, in metres (velocities in m/s).

    Attributes
    ----------
    dx : particle spacing
    x_lo, x_hi, y_lo, y_hi, z_lo : extent of the substrate block (top at z = 0)
    box_z_hi : top of the simulation box
    cut_faces : names of block faces that cut the plate ('x_lo', 'x_hi', 'y_lo', 'y_hi', 'z_lo')
    wire_radius, wire_height, wire_angle, wire_length : wire radius, axis height at the beam, angle from the
        surface (rad), modelled length from tip to feed end
    substrate_speed, wire_feed : V_s and V_w
    """

    dx: float
    x_lo: float
    x_hi: float
    y_lo: float
    y_hi: float
    z_lo: float
    box_z_hi: float
    cut_faces: tuple
    wire_radius: float
    wire_height: float
    wire_angle: float
    wire_length: float
    substrate_speed: float
    wire_feed: float
    frame: str = "substrate"
    wire_packing: str = "stretched"

    @property
    def moving_window(self) -> bool:
        """True in the beam frame (``domain = window``)."""
        return self.frame == "beam"

    @property
    def substrate_velocity(self) -> np.ndarray:
        """Velocity of solid substrate and bead, m/s: zero, or -V_s in the beam frame."""
        return np.array([-self.substrate_speed if self.moving_window else 0.0, 0.0, 0.0])

    @property
    def wire_axis(self) -> np.ndarray:
        """Unit vector along the wire from its tip towards the feed end."""
        return np.array([math.cos(self.wire_angle), 0.0, math.sin(self.wire_angle)])

    @property
    def wire_velocity(self) -> np.ndarray:
        """Velocity of unmelted wire, m/s: feed towards the tip, plus travel in the substrate frame."""
        return self.wire_velocity_at(True)

    def wire_velocity_at(self, feeding: bool) -> np.ndarray:
        """Velocity of unmelted wire (m/s) while it is fed, or held still relative to the beam before the feed
        starts (``wire_feed_start = pool``)."""
        travel = np.array([self.substrate_speed, 0.0, 0.0]) + self.substrate_velocity
        return travel - self.wire_feed * self.wire_axis if feeding else travel

    def wire_landing_x(self) -> float:
        """Offset (m) along x from the beam axis of the point where the lowest edge of the wire's tip face meets
        the substrate surface when the wire is fed along its axis."""
        a, r = self.wire_angle, self.wire_radius
        z_low = self.wire_height - r * math.cos(a)
        return r * math.sin(a) - max(z_low, 0.0) / math.tan(a) if a < math.pi / 2 - 1e-9 else 0.0

    def beam_x(self, t: float) -> float:
        """x of the beam axis at process time t (s)."""
        return 0.0 if self.moving_window else self.substrate_speed * t

    def deposited_x_min(self, t: float, r_fp: float) -> float:
        """Smallest x (m) of the track that passed under the beam at least r_fp / V_s after the start (the
        start-up transient excluded)."""
        if self.moving_window:
            return -(self.substrate_speed * t - r_fp)
        return r_fp

    def counts(self) -> tuple[int, int, int]:
        """Number of substrate lattice cells along x, y, z."""
        return tuple(int(round(v / self.dx)) for v in
                     (self.x_hi - self.x_lo, self.y_hi - self.y_lo, -self.z_lo))


def _snap(length: float, dx: float) -> float:
    """Round a length up to a whole number of cells (at least 2); widths use an even number, so that the
    cell-centred lattice is symmetric about y = 0."""
    return max(2, math.ceil(length / dx - 1e-9)) * dx


def build_geometry(params: dict, material=None) -> SceneGeometry:
    """Size the modelled block and the wire from the case parameters.

    ``domain = auto``: the block spans the scanned track over ``sim_time_s`` plus ``domain_margin_mm`` behind
    the start, ahead of the wire and on both sides, ``domain_depth_mm`` deep, each never larger than the plate.
    ``domain = plate``: the whole plate, with the start of the track ``domain_margin_mm`` plus the beam radius
    from its rear end. ``domain = window``: a block that moves with the beam (beam frame), sized from the
    thermal length L = a / V_s of the case: ``window_thermal_lengths`` x L ahead of and beside the beam
    footprint, behind it the melt-pool tail estimated by the reduced model's moving source
    (:func:`pool_tail`) plus ``window_bead_mm`` of solid bead and two spacings; ``domain_depth_mm`` deep.
    Faces where the block is smaller than the plate are ``cut_faces``; in the window the front (inflow, at
    the preheat temperature) and rear (outflow) faces are not heat-loss faces.
    """
    mm = 1e-3
    dx = params["resolution_mm"] * mm
    margin = params["domain_margin_mm"] * mm
    radius = params["wire_diameter_mm"] * mm / 2
    alpha = math.radians(params["wire_angle_deg"])
    wire_len = params["wire_length_mm"] * mm
    height = params["wire_height_mm"] * mm
    vs = params["substrate_speed_mm_s"] * mm
    beam_r = params["scan_diameter_mm"] * mm / 2 + 3 * params["beam_spot_radius_mm"] * mm
    wire_front = wire_len * math.cos(alpha) + radius * math.sin(alpha)
    plate = (params["substrate_length_mm"] * mm, params["substrate_width_mm"] * mm,
             params["substrate_thickness_mm"] * mm)
    rear = _snap(beam_r + margin, dx)
    frame = "substrate"
    if params["domain"] == "window":
        frame = "beam"
        from beadsim.materials import get_material
        mat = material or get_material(params["material"])  # the run's material (its materials file)
        thermal = params["window_thermal_lengths"] * mat.diffusivity / vs
        front = _snap(beam_r + thermal, dx)
        rear = _snap(max(beam_r, pool_tail(params, mat)) + params["window_bead_mm"] * mm + 2 * dx, dx)
        width = 2 * _snap(min(max(beam_r, radius) + thermal, plate[1] / 2), dx)
        depth = _snap(min(params["domain_depth_mm"] * mm, plate[2]), dx)
        top = height + wire_len * math.sin(alpha) + radius + 2 * dx
        cut = ["y_lo", "y_hi"] if width < plate[1] - dx / 2 else []
        cut += ["z_lo"] if depth < plate[2] - dx / 2 else []
        return SceneGeometry(dx=dx, x_lo=-rear, x_hi=front, y_lo=-width / 2, y_hi=width / 2, z_lo=-depth,
                             box_z_hi=top, cut_faces=tuple(cut), wire_radius=radius, wire_height=height,
                             wire_angle=alpha, wire_length=wire_len, substrate_speed=vs,
                             wire_feed=params["wire_feed_mm_s"] * mm, frame=frame,
                             wire_packing=params["wire_packing"])
    if params["domain"] == "plate":
        length, width, depth = _snap(plate[0], dx), 2 * _snap(plate[1] / 2, dx), _snap(plate[2], dx)
    else:
        length = _snap(min(rear + vs * params["sim_time_s"] + max(beam_r, wire_front) + margin, plate[0]), dx)
        width = 2 * _snap(min(max(beam_r, radius) + margin, plate[1] / 2), dx)
        depth = _snap(min(params["domain_depth_mm"] * mm, plate[2]), dx)
    rear = min(rear, length / 2)
    cut = []
    if length < plate[0] - dx / 2:
        cut += ["x_lo", "x_hi"]
    if width < plate[1] - dx / 2:
        cut += ["y_lo", "y_hi"]
    if depth < plate[2] - dx / 2:
        cut += ["z_lo"]
    top = height + wire_len * math.sin(alpha) + radius + 2 * dx
    return SceneGeometry(dx=dx, x_lo=-rear, x_hi=length - rear, y_lo=-width / 2, y_hi=width / 2, z_lo=-depth,
                         box_z_hi=top, cut_faces=tuple(cut), wire_radius=radius, wire_height=height,
                         wire_angle=alpha, wire_length=wire_len, substrate_speed=vs,
                         wire_feed=params["wire_feed_mm_s"] * mm, wire_packing=params["wire_packing"])


def pool_tail(params: dict, mat) -> float:
    """Distance (m) behind the beam axis where the surface centre line of the reduced model's quasi-steady
    moving source (absorbed power less the wire's melting power, see :mod:`beadsim.reduced`) falls below the
    melting temperature; 0 if nothing melts."""
    from beadsim import reduced

    mm = 1e-3
    p_wire = reduced.wire_melt_power(mat, params["wire_diameter_mm"] * mm, params["wire_feed_mm_s"] * mm,
                                     params["preheat_K"])
    ring = params["scan_diameter_mm"] * mm / 2 if params["beam_profile"] in ("ring", "scan") else 0.0
    src = reduced.MovingSource(Q=max(params["beam_power_W"] * params["beam_efficiency"] - p_wire, 0.0),
                               V=params["substrate_speed_mm_s"] * mm, rho_c=mat.rho * mat.cp,
                               alpha=mat.diffusivity, T0=params["preheat_K"],
                               sigma=params["beam_spot_radius_mm"] * mm, ring_radius=ring,
                               thickness=params["substrate_thickness_mm"] * mm)
    if src.Q <= 0:
        return 0.0
    xs = -np.linspace(0.0, 0.05, 2001)
    temp = src.temperature(np.column_stack([xs, np.zeros_like(xs), np.zeros_like(xs)]))
    hot = np.flatnonzero(temp >= mat.T_melt)
    return float(-xs[hot.max()]) if len(hot) else 0.0


def substrate_layer(geom: SceneGeometry, x: float) -> np.ndarray:
    """One y-z layer of the substrate lattice at x (m), shape (ny * nz, 3): what enters the window."""
    _, ny, nz = geom.counts()
    iy, iz = np.meshgrid(np.arange(ny), np.arange(nz), indexing="ij")
    d = geom.dx
    return np.column_stack([np.full(ny * nz, x), geom.y_lo + (iy.ravel() + 0.5) * d, -(iz.ravel() + 0.5) * d])


def substrate_positions(geom: SceneGeometry) -> np.ndarray:
    """Cell-centred lattice filling the block, shape (N, 3), metres."""
    nx, ny, nz = geom.counts()
    ix, iy, iz = np.meshgrid(np.arange(nx), np.arange(ny), np.arange(nz), indexing="ij")
    d = geom.dx
    pos = np.column_stack([geom.x_lo + (ix.ravel() + 0.5) * d, geom.y_lo + (iy.ravel() + 0.5) * d,
                           -(iz.ravel() + 0.5) * d])
    return pos


def face_areas(geom: SceneGeometry, pos: np.ndarray) -> np.ndarray:
    """Area (m^2) of cut plate faces carried by each substrate particle (0 inside; corners add up)."""
    d = geom.dx
    area = np.zeros(len(pos))
    tests = {"x_lo": pos[:, 0] < geom.x_lo + d, "x_hi": pos[:, 0] > geom.x_hi - d,
             "y_lo": pos[:, 1] < geom.y_lo + d, "y_hi": pos[:, 1] > geom.y_hi - d,
             "z_lo": pos[:, 2] < geom.z_lo + d}
    for face in geom.cut_faces:
        area[tests[face]] += d * d
    return area


def _disc_offsets(radius: float, dx: float) -> np.ndarray:
    """Square-grid points (u, v) inside a disc, choosing the grid offset whose count best matches the area."""
    best = None
    n = int(math.ceil(radius / dx)) + 1
    for shift in (0.0, 0.5):
        g = (np.arange(-n, n + 1) + shift) * dx
        u, v = np.meshgrid(g, g, indexing="ij")
        inside = u ** 2 + v ** 2 <= radius ** 2
        pts = np.column_stack([u[inside], v[inside]])
        err = abs(len(pts) * dx * dx - math.pi * radius ** 2)
        if best is None or err < best[0]:
            best = (err, pts)
    return best[1]


def _lattice_slice_offsets(radius: float, dx: float, index: int) -> np.ndarray:
    """Grid points (u, v) of slice number ``index`` of a lattice-packed wire: the n_k points nearest the axis,
    n_k = floor((k + 1) a) - floor(k a) with a = pi r^2 / dx^2, so that k slices hold the nominal area on
    average (error diffusion); among equidistant points the choice rotates by a quarter turn per slice (at
    d 1.2 mm, dx 0.4 mm: the centre, its 4 neighbours and 2 or 3 of the 4 corners)."""
    a = math.pi * radius ** 2 / dx ** 2
    n_k = int(math.floor((index + 1) * a) - math.floor(index * a))
    m = int(math.ceil(math.sqrt(a))) + 1
    g = np.arange(-m, m + 1) * dx
    u, v = (w.ravel() for w in np.meshgrid(g, g, indexing="ij"))
    r = np.round(np.hypot(u, v) / dx, 6)
    turn = np.mod(np.arctan2(v, u) - index * math.pi / 2 + 1e-9, 2 * math.pi)
    order = np.lexsort((turn, r))[:n_k]
    return np.column_stack([u[order], v[order]])


def wire_slice(geom: SceneGeometry, s: float, beam_x: float, index: int = 0) -> np.ndarray:
    """Particles of one wire slice at axial distance s (m) from the tip plane, beam at beam_x; shape (n, 3).
    ``index`` numbers the slices from the tip (it picks the points of a lattice-packed wire).

    Points that would sit inside the substrate (z < dx/2) are dropped.
    """
    axis = geom.wire_axis
    e_u = np.array([-math.sin(geom.wire_angle), 0.0, math.cos(geom.wire_angle)])
    e_v = np.array([0.0, 1.0, 0.0])
    if geom.wire_packing == "lattice":
        uv = _lattice_slice_offsets(geom.wire_radius, geom.dx, index)
    else:
        uv = _disc_offsets(geom.wire_radius, geom.dx)
    centre = np.array([beam_x, 0.0, geom.wire_height]) + s * axis
    pos = centre + uv[:, :1] * e_u + uv[:, 1:] * e_v
    return pos[pos[:, 2] >= geom.dx / 2]


def wire_slice_count(geom: SceneGeometry) -> int:
    """Particles per full wire slice (lattice packing: the mean, rounded)."""
    if geom.wire_packing == "lattice":
        return int(round(math.pi * geom.wire_radius ** 2 / geom.dx ** 2))
    return len(_disc_offsets(geom.wire_radius, geom.dx))


def wire_slice_pitch(geom: SceneGeometry) -> float:
    """Axial distance (m) between wire slices such that the particles carry the nominal wire mass per length:
    n_slice dx^3 / (pi r^2). Within a few percent of dx; it corrects the count of the square grid in the disc
    (+3 % at d 1.2 mm, dx 0.3 mm; +27 % at dx 0.4 mm). Lattice packing: dx (the count varies instead)."""
    if geom.wire_packing == "lattice":
        return geom.dx
    return wire_slice_count(geom) * geom.dx ** 3 / (math.pi * geom.wire_radius ** 2)


def wire_link_length(geom: SceneGeometry) -> float:
    """Largest distance (m) between neighbouring particles of an intact wire: the diagonal between one slice
    and the next (pitch along the axis, dx across), with 5 % slack."""
    return 1.05 * math.hypot(wire_slice_pitch(geom), geom.dx)


def detached_wire(pos: np.ndarray, s: np.ndarray, s_feed: float, link: float) -> np.ndarray:
    """Which unmelted wire particles are cut off from the feed end.

    Parameters
    ----------
    pos : (n, 3) positions (m) of the unmelted wire particles (all ranks)
    s : (n,) their axial distance (m) from the tip plane
    s_feed : axial position (m) of the slice at the feed end
    link : particles closer than this (m) are connected (:func:`wire_link_length`)

    Returns
    -------
    Boolean mask: True for particles of connected pieces without a particle within half a link of the feed
    slice. All False when no piece reaches the feed end (the wire melted through at the feed end, which a
    sensible ``wire_length_mm`` prevents): nothing is released on doubtful evidence.
    """
    from scipy.sparse import coo_matrix
    from scipy.sparse.csgraph import connected_components
    from scipy.spatial import cKDTree

    n = len(pos)
    if n == 0:
        return np.zeros(0, dtype=bool)
    pairs = cKDTree(pos).query_pairs(link, output_type="ndarray")
    graph = coo_matrix((np.ones(len(pairs)), (pairs[:, 0], pairs[:, 1])), shape=(n, n))
    _, label = connected_components(graph, directed=False)
    feeding = np.unique(label[s >= s_feed - 0.5 * link])
    if len(feeding) == 0:
        return np.zeros(n, dtype=bool)
    return ~np.isin(label, feeding)


def initial_wire(geom: SceneGeometry) -> tuple[np.ndarray, float, int]:
    """Wire particles from the tip to the feed end at t = 0, the axial position (m) of the last slice and the
    number of slices."""
    pitch = wire_slice_pitch(geom)
    s_values = np.arange(0.5, geom.wire_length / pitch) * pitch
    pos = np.vstack([wire_slice(geom, s, geom.beam_x(0.0), k) for k, s in enumerate(s_values)])
    return pos, float(s_values[-1]), len(s_values)
