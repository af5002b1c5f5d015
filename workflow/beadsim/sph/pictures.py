"""Pictures of an SPH bead run from a particle dump: top view, longitudinal and cross sections by temperature.

As the paper's Figs. 5-8: colour is temperature, the melt pool (T >= T_melt) is outlined in white.
Particles are binned on a grid of the particle spacing: the top view shows the highest particle of each
column, a section the mean over the particles within half a spacing of the section plane.
"""

from __future__ import annotations

import re
from pathlib import Path

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402


def read_dump(path: str | Path) -> dict:
    """Read the last snapshot of a LAMMPS text dump (``dump custom``) into arrays by column name.

    Returns
    -------
    dict
        Column arrays (``id``, ``type``, ``x``, ... as named in the ``ITEM: ATOMS`` line), plus ``timestep``
        and ``box`` ((3, 2) array of bounds).
    """
    lines = Path(path).read_text().splitlines()
    starts = [i for i, line in enumerate(lines) if line.startswith("ITEM: TIMESTEP")]
    if not starts:
        raise ValueError(f"{path}: no 'ITEM: TIMESTEP' block; not a LAMMPS text dump")
    i = starts[-1]
    timestep = int(lines[i + 1])
    n = int(lines[i + 3])
    box = np.array([[float(v) for v in lines[i + 5 + k].split()[:2]] for k in range(3)])
    header = lines[i + 8].split()[2:]
    data = np.loadtxt(lines[i + 9: i + 9 + n], ndmin=2)
    out = {name: data[:, k] for k, name in enumerate(header)}
    out["timestep"] = timestep
    out["box"] = box
    return out


def _grid(a: np.ndarray, b: np.ndarray, dx: float):
    ia = np.rint((a - a.min()) / dx).astype(int)
    ib = np.rint((b - b.min()) / dx).astype(int)
    return ia, ib, a.min(), b.min()


def _image(a, b, value, dx, reduce="mean", order=None):
    """Bin ``value`` on an (a, b) grid of spacing dx; reduce by mean, or take the value at max ``order``."""
    ia, ib, a0, b0 = _grid(a, b, dx)
    img = np.full((ib.max() + 1, ia.max() + 1), np.nan)
    if reduce == "top":
        best = np.full(img.shape, -np.inf)
        for i, j, v, o in zip(ia, ib, value, order):
            if o > best[j, i]:
                best[j, i] = o
                img[j, i] = v
    else:
        total = np.zeros(img.shape)
        count = np.zeros(img.shape)
        np.add.at(total, (ib, ia), value)
        np.add.at(count, (ib, ia), 1)
        with np.errstate(invalid="ignore"):
            img = np.where(count > 0, total / np.maximum(count, 1), np.nan)
    extent = (a0 - dx / 2, a0 + (img.shape[1] - 0.5) * dx, b0 - dx / 2, b0 + (img.shape[0] - 0.5) * dx)
    return img, extent


def bead_pictures(snap: dict, dx: float, T_melt: float, x_cut: float | None = None, y_cut: float | None = None,
                  title: str = "") -> plt.Figure:
    """Top view, longitudinal section (at y_cut) and cross section (at x_cut) coloured by temperature.

    Parameters
    ----------
    snap : dict
        From :func:`read_dump`; needs x, y, z and a temperature column (``c_T`` or ``T``), metres and K.
    dx : float
        Particle spacing, m.
    T_melt : float
        Melting temperature, K (the white outline).
    x_cut, y_cut : float, optional
        Section planes, m (default: the hottest particle's x and y).
    """
    x, y, z = snap["x"], snap["y"], snap["z"]
    T = snap["c_T"] if "c_T" in snap else snap["T"]
    hot = int(np.argmax(T))
    x_cut = x[hot] if x_cut is None else x_cut
    y_cut = y[hot] if y_cut is None else y_cut
    mm = 1e3
    vmin, vmax = float(np.nanmin(T)), float(np.nanmax(T))
    fig, axes = plt.subplots(3, 1, figsize=(8, 9))
    panels = [
        ("top view", x, y, np.ones_like(x, bool), "top", z, "x [mm]", "y [mm]"),
        (f"longitudinal section y = {y_cut * mm:.2f} mm", x, z, np.abs(y - y_cut) <= dx / 2, "mean", None,
         "x [mm]", "z [mm]"),
        (f"cross section x = {x_cut * mm:.2f} mm", y, z, np.abs(x - x_cut) <= dx / 2, "mean", None, "y [mm]",
         "z [mm]"),
    ]
    im = None
    for ax, (name, a, b, sel, how, order, xl, yl) in zip(axes, panels):
        if not sel.any():
            ax.set_title(f"{name}: no particles")
            continue
        img, ext = _image(a[sel] * mm, b[sel] * mm, T[sel], dx * mm, how, None if order is None else order[sel])
        im = ax.imshow(img, origin="lower", extent=ext, cmap="inferno", vmin=vmin, vmax=vmax, aspect="equal",
                       interpolation="nearest")
        if np.nanmax(img) >= T_melt > np.nanmin(img):
            xs = np.linspace(ext[0] + dx * mm / 2, ext[1] - dx * mm / 2, img.shape[1])
            ys = np.linspace(ext[2] + dx * mm / 2, ext[3] - dx * mm / 2, img.shape[0])
            ax.contour(xs, ys, np.nan_to_num(img, nan=vmin), levels=[T_melt], colors="white", linewidths=1)
        ax.set_title(name, fontsize=9)
        ax.set_xlabel(xl)
        ax.set_ylabel(yl)
    if im is not None:
        fig.colorbar(im, ax=list(axes), label="temperature [K]", shrink=0.8)
    fig.suptitle(title or f"timestep {snap['timestep']}: white line T = {T_melt:g} K", fontsize=10)
    return fig


def dumps_by_step(folder: str | Path) -> list[Path]:
    """The ``*.lammpstrj`` files of a folder in the order of the step number in their names."""
    def step(p: Path) -> int:
        digits = re.findall(r"\d+", p.stem)
        return int(digits[-1]) if digits else -1

    return sorted(Path(folder).glob("*.lammpstrj"), key=step)


def latest_dump(folder: str | Path) -> Path | None:
    """The ``*.lammpstrj`` with the largest step number in its name, or None."""
    dumps = dumps_by_step(folder)
    return dumps[-1] if dumps else None


def run_picture(run_dir: str | Path, dx: float, T_melt: float, result: dict) -> plt.Figure:
    """Pictures of a run folder's last dump, titled with its status; a note figure if it has no dump."""
    dump = latest_dump(Path(run_dir) / "dumps")
    status = result.get("status", "?")
    note = f"{result.get('run_id', '')}: {status}" + (f" ({result['reason']})" if result.get("reason") else "")
    if dump is None:
        fig, ax = plt.subplots(figsize=(6, 1.5))
        ax.text(0.5, 0.5, f"{note}\nno particle dump was written", ha="center", va="center")
        ax.axis("off")
        return fig
    snap = read_dump(dump)
    return bead_pictures(snap, dx, T_melt, title=f"{note}; step {snap['timestep']}; white: T = {T_melt:g} K")
