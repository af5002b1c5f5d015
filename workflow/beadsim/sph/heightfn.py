"""Surface tension from a height function: a continuum surface force whose curvature comes from the column
height map of the particles, not from kernel gradients.

A bead is a height field z = H(x, y) over the plate. Its Laplace pressure sigma kappa, with
kappa = -div(grad H / sqrt(1 + |grad H|^2)) (positive on a convex cap), acts on the free surface; over one
dx x dx column the surface element is (-H_x, -H_y, 1) dx^2, so the force on the liquid is

    F = sigma kappa dx^2 (H_x, H_y, -1),

put on the column's highest particle. Kernel curvatures need about two smoothing lengths (five spacings) across
the interface; a bead at dx 0.4 mm is 2-3 spacings tall, and a kernel curvature probe there sat at its cap
everywhere (README, "Where the yield stress comes from"). The height map is smooth over the bead's width
instead (8-10 columns), and ``smooth_cells`` (a Gaussian filter of the map, in columns) sets how far the
curvature is averaged.

Measured on ridges (``verify_tension.sessile_ridge``, Ti, dx 0.4 mm, c0 4.15 m/s, dt 21.5 us, forces held over
chunks of 10 steps, 0.05-0.2 s; segment angle of wide 12 x 2 / tall 4 x 6 starts), set angle -> ridge angle:

- artificial viscosity 0.2, smoothing 1: 10 -> 16 / 13, 20 -> 26 / 29, 30 -> 46 / 47, 40 -> 61 / 62,
  50 -> 71 / 71, 60 -> 79 / 79, 70 -> 90 / 93, 80 -> 100 / 101 deg;
- artificial viscosity 0.5, smoothing 2 (the bead study's): 30 -> 49 / 50, 45 -> 70 / 71, 60 -> 85 / 96 deg.

The two starts meet (the pairwise cohesion's stay 45 and 124 deg apart), so the melt is a liquid; the ridge
sits 5-30 deg above the set angle because the kink where the melt meets the plate is smoothed partly onto plate
columns, which do not move, and that part of its spreading pull is lost. In the bead (mode 1, study
``height_function_sph``) the melt splashes single particles over the plate at artificial viscosity 0.2 and
smoothing 1; at 0.5 and 2 it gives beads of 3.4-3.8 x 0.75-0.86 mm for set angles 30-60 deg.

The functions work on global arrays (positions of all particles); callers in parallel gather first.
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from scipy.ndimage import gaussian_filter


@dataclass
class ColumnGrid:
    """Columns of width ``dx`` with their lower corner at (``x0``, ``y0``), ``nx`` x ``ny`` of them;
    ``periodic_y``: y wraps (a periodic ridge)."""

    x0: float
    y0: float
    dx: float
    nx: int
    ny: int
    periodic_y: bool = False

    def index(self, x: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """Column indices (ix, iy) of positions ``x`` (N, 3) and the mask of those inside the grid."""
        ix = np.floor((x[:, 0] - self.x0) / self.dx).astype(np.int64)
        iy = np.floor((x[:, 1] - self.y0) / self.dx).astype(np.int64)
        if self.periodic_y:
            iy %= self.ny
        inside = (ix >= 0) & (ix < self.nx) & (iy >= 0) & (iy < self.ny)
        return ix, iy, inside


def column_tops(x: np.ndarray, grid: ColumnGrid, floor: float = 0.0, gap: float | None = None
                ) -> tuple[np.ndarray, np.ndarray]:
    """Height map and highest particle of every column.

    With ``gap`` (m), a column's top is that of its lowest stack: particles from the bottom up until two
    neighbours in z lie more than ``gap`` apart, so that a drop hanging from the wire, or spatter, above the bead
    does not count as its surface.

    Returns
    -------
    H : (nx, ny) array
        Top particle's z + dx / 2 (its upper face); ``floor`` where a column holds no particle.
    top : (nx, ny) int array
        Index into ``x`` of the column's highest particle, -1 where empty.
    """
    ix, iy, inside = grid.index(x)
    idx = np.flatnonzero(inside)
    key = ix[idx] * grid.ny + iy[idx]
    order = np.lexsort((x[idx, 2], key))
    ks = key[order]
    last = np.r_[ks[1:] != ks[:-1], True]
    if gap is not None:
        z = x[idx[order], 2]
        broken = last | np.r_[np.diff(z) > gap, True]  # the stack ends here (gap above, or column's end)
        first_of_col = np.r_[True, ks[1:] != ks[:-1]]
        # first break at or after each column's start: a running minimum from the back
        pos = np.where(broken, np.arange(len(ks)), len(ks))
        nxt = np.minimum.accumulate(pos[::-1])[::-1]
        last = np.zeros(len(ks), dtype=bool)
        last[nxt[first_of_col]] = True
    winners = idx[order[last]]
    top = np.full(grid.nx * grid.ny, -1, dtype=np.int64)
    top[key[order[last]]] = winners
    H = np.full(grid.nx * grid.ny, floor, dtype=float)
    H[key[order[last]]] = x[winners, 2] + 0.5 * grid.dx
    return H.reshape(grid.nx, grid.ny), top.reshape(grid.nx, grid.ny)


def curvature(H: np.ndarray, dx: float, smooth_cells: float = 1.0, periodic_y: bool = False
              ) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Mean-curvature sum kappa = -div(grad H / sqrt(1 + |grad H|^2)) of the height map (1/m; 1/R on a cylinder
    of radius R along y, 2/R on a sphere), and the slopes H_x, H_y, after a Gaussian smoothing of
    ``smooth_cells`` columns (0 = none). Central differences; one-sided at non-periodic edges."""
    mode = ("nearest", "wrap" if periodic_y else "nearest")
    Hs = gaussian_filter(H, smooth_cells, mode=mode) if smooth_cells > 0 else H
    hx, hy = _grad(Hs, dx, periodic_y)
    norm = np.sqrt(1.0 + hx**2 + hy**2)
    nxx, _ = _grad(hx / norm, dx, periodic_y)
    _, nyy = _grad(hy / norm, dx, periodic_y)
    return -(nxx + nyy), hx, hy


def _grad(f: np.ndarray, dx: float, periodic_y: bool) -> tuple[np.ndarray, np.ndarray]:
    gx = np.gradient(f, dx, axis=0) if f.shape[0] > 1 else np.zeros_like(f)
    if periodic_y:
        gy = (np.roll(f, -1, axis=1) - np.roll(f, 1, axis=1)) / (2 * dx)
    else:
        gy = np.gradient(f, dx, axis=1) if f.shape[1] > 1 else np.zeros_like(f)
    return gx, gy


def surface_forces(x: np.ndarray, movable: np.ndarray, grid: ColumnGrid, sigma: float,
                   smooth_cells: float = 1.0, wetting_deg: float | None = None, floor: float = 0.0,
                   gap: float | None = None, mapped: np.ndarray | None = None
                   ) -> tuple[np.ndarray, dict]:
    """Force (N, 3), newtons, on every particle: sigma kappa dx^2 (H_x, H_y, -1) on the highest particle of
    each column where that particle is ``movable`` (melt), zero elsewhere.

    The map runs over the bare solid too, where it is flat; there the surface energy it stands for is that of
    the liquid's, so on its own the force wets completely (the kink where the melt meets the solid pulls the
    melt's edge outward). ``wetting_deg`` adds the contact line's share of Young's balance: on every melt column
    next to a column topped by solid, a pull sigma (1 - cos theta) dx towards the melt, per solid neighbour
    (4-neighbours; along a straight line, sigma (1 - cos theta) per unit length). Only particles in
    ``mapped`` (default: all) enter the height map.

    Returns the forces and a dict with the maps (``H``, ``kappa``, ``top``, ``melt``) for diagnostics."""
    use = np.ones(len(x), dtype=bool) if mapped is None else mapped
    idx = np.flatnonzero(use)
    H, top_m = column_tops(x[idx], grid, floor, gap)
    top = np.where(top_m >= 0, idx[np.maximum(top_m, 0)], -1)
    kappa, hx, hy = curvature(H, grid.dx, smooth_cells, grid.periodic_y)
    f = np.zeros_like(x, dtype=float)
    sel = top >= 0
    sel[sel] &= movable[top[sel]]
    scale = sigma * kappa[sel] * grid.dx**2
    f[top[sel]] = np.column_stack([scale * hx[sel], scale * hy[sel], -scale])
    if wetting_deg is not None:
        solid = (top >= 0) & ~sel
        pull = sigma * (1.0 - np.cos(np.radians(wetting_deg))) * grid.dx
        for axis in (0, 1):
            for shift in (1, -1):  # the neighbour at index - shift; the pull points along +shift
                nb = np.roll(solid, shift, axis=axis)
                if axis == 0 or not grid.periodic_y:  # no neighbour across a non-periodic edge
                    np.moveaxis(nb, axis, 0)[0 if shift == 1 else -1] = False
                cols = top[sel & nb]
                f[cols, axis] += shift * pull
    return f, {"H": H, "kappa": kappa, "top": top, "melt": sel}
