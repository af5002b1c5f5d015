"""Pictures of an SPH bead run: top view, longitudinal and cross sections by temperature from a particle dump, and
the bead's cross-section against the measured bead (:func:`section_picture`).

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
        return _note_figure(f"{note}\nno particle dump was written")
    snap = read_dump(dump)
    return bead_pictures(snap, dx, T_melt, title=f"{note}; step {snap['timestep']}; white: T = {T_melt:g} K")


def cap_outline(width: float, height: float, n: int = 101) -> tuple[np.ndarray, np.ndarray]:
    """(y, z) of the circular cap of base ``width`` and ``height`` centred on y = 0 (any length unit)."""
    radius = (width ** 2 / 4 + height ** 2) / (2 * height)
    y = np.linspace(-width / 2, width / 2, n)
    return y, np.sqrt(np.maximum(radius ** 2 - y ** 2, 0.0)) - (radius - height)


def section_picture(y: np.ndarray, h_map: np.ndarray, h_mass: np.ndarray, dx: float,
                    measured: tuple[float, float] | None = None, title: str = "",
                    plate_fused: float | None = None) -> plt.Figure:
    """The bead's cross-section as the run measured it, against the measured bead.

    Parameters
    ----------
    y, h_map, h_mass : (ny,) arrays, mm
        Bin centres across the bead and the height above the plate from the column tops (the height map, whose
        width and height are the bead metrics) and from the particles per column (the mass profile; NaN if the
        run has none), e.g. the ``section_*`` variables of a run's ``timeseries.nc``.
    dx : float, mm
        Particle spacing (the bins' width).
    measured : (width, height), mm, optional
        The measured bead (Table 1), drawn as a circular cap on the bead's axis.
    plate_fused : float, mm, optional
        Width of the plate's surface that melted (``plate_fusion_width_mm``), drawn as a bar on the plate
        centred on the beam's axis: metal beyond it lies on plate whose particles never melted.
    """
    fig, ax = plt.subplots(figsize=(8, 3.2))
    ax.axhline(0.0, color="0.6", lw=0.8)
    area = np.nansum(np.clip(h_map, 0, None)) * dx
    ax.step(y, h_map, where="mid", color="C0", label=f"column tops (height map), {area:.2f} mm2 above the plate")
    if np.isfinite(h_mass).any():
        area = np.nansum(np.clip(h_mass, 0, None)) * dx
        ax.plot(y, h_mass, "o-", ms=3, color="C1", label=f"particles per column (mass), {area:.2f} mm2")
    if plate_fused is not None and np.isfinite(plate_fused) and plate_fused > 0:
        ax.plot([-plate_fused / 2, plate_fused / 2], [0.0, 0.0], color="C3", lw=4, solid_capstyle="butt",
                label=f"plate surface melted, {plate_fused:.2f} mm (on the beam's axis)")
    if measured is not None:
        w, h = measured
        yc, zc = cap_outline(w, h)
        ax.plot(yc, zc, "k--", label=f"measured bead as a circular cap, {w:g} x {h:g} mm")
    ax.set_xlabel("y across the bead [mm]")
    ax.set_ylabel("height above the plate [mm]")
    top = np.nanmax(np.concatenate([np.atleast_1d(h_map), np.atleast_1d(h_mass), [measured[1] if measured else 0]]))
    ax.set_ylim(-0.25, 1.25 * top + dx)
    with np.errstate(invalid="ignore"):
        raised = np.abs(y[(h_map > dx / 4) | (h_mass > dx / 4)])
    half = max(raised.max() if len(raised) else 0.0, measured[0] / 2 if measured else 0.0)
    if half > 0:
        ax.set_xlim(-half - 2 * dx, half + 2 * dx)
    ax.legend(fontsize=8, loc="upper right")
    ax.set_title(title, fontsize=9)
    fig.tight_layout()
    return fig


def _note_figure(text: str) -> plt.Figure:
    fig, ax = plt.subplots(figsize=(6, 1.5))
    ax.text(0.5, 0.5, text, ha="center", va="center")
    ax.axis("off")
    return fig


def section_figure(series, dx: float, result: dict, measured: tuple[float, float] | None = None,
                   mode: int | None = None) -> plt.Figure:
    """:func:`section_picture` of a run from its time series (an xarray Dataset of ``timeseries.nc`` with the
    ``section_*`` variables, or None), titled with its status, bead metrics and measured mode; a note figure if
    the run has no section (it failed, or no bead had formed behind the pool)."""
    note = f"{result.get('run_id', '')}: {result.get('status', '?')}" + (
        f" ({result['reason']})" if result.get("reason") else "")
    if series is None or "section_height_map_mm" not in series:
        return _note_figure(f"{note}\nno bead cross-section was recorded")
    m = result.get("metrics") or {}

    def mm(key):
        v = m.get(key)
        return "-" if v is None else f"{v:.2f}"

    title = (f"{note}; bead {mm('bead_width_mm')} x {mm('bead_height_mm')} mm (height map), "
             f"{mm('bead_width_mass_mm')} x {mm('bead_height_mass_mm')} mm by mass"
             + (f"; Table 1 mode {mode}: {measured[0]:g} x {measured[1]:g} mm" if measured else ""))
    return section_picture(series["y_section"].values, series["section_height_map_mm"].values,
                           series["section_height_mass_mm"].values, dx, measured, title,
                           plate_fused=m.get("plate_fusion_width_mm"))
