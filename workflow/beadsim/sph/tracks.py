"""How the deposited metal reached its place: particles followed by id through an SPH run's dumps.

The bead's toes (metal above the plate beyond the plate's melted half-width, :func:`surface.plate_fusion_width`)
and its core (the metal above the plate within it) are taken from every dump's bead window since ``t_from``;
each particle is then followed back through all the dumps (every 0.05 s in the moving window) over the time it
was liquid: where it first was liquid, where it froze, how far it travelled sideways, and how that travel was
spread over its time liquid (README, "The toes lie past the melted plate").

    python -m beadsim.sph.tracks results/<study>/runs/<run_id> [--from 2.0] [--melted-from 1.5]
"""

from __future__ import annotations

import argparse
import json
from pathlib import Path

import numpy as np
import pandas as pd

from beadsim.sph import surface
from beadsim.sph.pictures import dumps_by_step, read_dump
from beadsim.sph.scene import FLUID_TYPES, TYPE_LIQUID, TYPE_RESOLIDIFIED, TYPE_WIRE

#: Sideways travel (m) below which a particle's travel is not split into steps (dump-to-dump jitter)
MIN_TRAVEL = 0.2e-3


def snapshots(run_dir: str | Path) -> list[tuple[float, dict]]:
    """The run's dumps in time order, as (t, :func:`read_dump` columns); the time of each from its step
    through the run's ``timeseries.nc``."""
    import xarray as xr

    run_dir = Path(run_dir)
    with xr.open_dataset(run_dir / "timeseries.nc") as ds:
        steps, ts = ds["step"].values, ds["t"].values
    dumps = [read_dump(f) for f in dumps_by_step(run_dir / "dumps")]
    return [(float(np.interp(d["timestep"], steps, ts)), d) for d in dumps]


def liquid_histories(snaps: list[tuple[float, dict]]) -> dict[int, np.ndarray]:
    """Per particle id, the rows (t, x, y, z) of the dumps in which it was fluid (liquid or falling)."""
    rows: dict[int, list] = {}
    for t, d in snaps:
        fluid = np.flatnonzero(np.isin(d["type"].astype(int), FLUID_TYPES))
        for i, x, y, z in zip(d["id"][fluid].astype(int), d["x"][fluid], d["y"][fluid], d["z"][fluid]):
            rows.setdefault(int(i), []).append((t, x, y, z))
    return {i: np.array(r) for i, r in rows.items()}


def path_figures(h: np.ndarray, y_axis: float = 0.0) -> dict:
    """Figures of one particle's liquid history ``h`` (rows t, x, y, z; m, s): where it first was liquid and
    where last, its outward travel |y - y_axis| (m), and, where that travel exceeds :data:`MIN_TRAVEL`, the
    share of it in the largest dump-to-dump step (above 1 where it went further out and came back) and the
    share of its time liquid by which half of it was done.
    """
    r = np.abs(h[:, 2] - y_axis)
    out = {"t_first": h[0, 0], "r_first": r[0], "z_first": h[0, 3], "t_last": h[-1, 0], "r_last": r[-1],
           "z_last": h[-1, 3], "liquid_s": h[-1, 0] - h[0, 0], "travel": r[-1] - r[0],
           "largest_step_share": np.nan, "half_travel_at": np.nan}
    if out["travel"] > MIN_TRAVEL and len(h) > 2:
        out["largest_step_share"] = np.diff(r).max() / out["travel"]
        half = int(np.argmax(r - r[0] >= 0.5 * out["travel"]))
        out["half_travel_at"] = (h[half, 0] - h[0, 0]) / out["liquid_s"]
    return out


def bead_groups(t: float, d: dict, geom, params: dict) -> dict[str, np.ndarray]:
    """Ids of the frozen metal above the plate in the dump's bead window: ``toe`` beyond the plate's melted
    half-width from the axis (y = 0), ``core`` within it. Empty without a window."""
    from beadsim.sph.driver import bead_window

    x = np.column_stack([d["x"], d["y"], d["z"]])
    ty, ids = d["type"].astype(int), d["id"].astype(int)
    liquid = ty == TYPE_LIQUID
    window = bead_window(geom, params, t, x[liquid, 0].min() if liquid.any() else np.inf)
    if window is None:
        return {"toe": ids[:0], "core": ids[:0]}
    deposit = ty != TYPE_WIRE
    melted = np.isin(ty, (TYPE_LIQUID, TYPE_RESOLIDIFIED))
    half = 0.5e-3 * surface.plate_fusion_width(x[deposit], melted[deposit], geom.dx, window)
    frozen_top = (x[:, 0] >= window[0]) & (x[:, 0] < window[1]) & (ty == TYPE_RESOLIDIFIED) & (x[:, 2] > 0)
    return {"toe": ids[frozen_top & (np.abs(x[:, 1]) > half)], "core": ids[frozen_top & (np.abs(x[:, 1]) <= half)]}


def toe_paths(run_dir: str | Path, t_from: float = 2.0, melted_from: float = 1.5,
              params: dict | None = None) -> pd.DataFrame:
    """One row per particle of the toes and the core (first seen in a bead window since ``t_from`` s) that
    first was liquid at or after ``melted_from`` s, with :func:`path_figures` (lengths in mm) and ``group``.
    ``melted_from`` leaves out the start-up's metal, which the early windows still hold (drops from the first
    wire tip, liquid since 0.15 s); particles never seen liquid in a dump are left out too. ``params``: the
    run's parameters (default: its ``params.json``, which the workflow writes)."""
    from beadsim.materials import get_material
    from beadsim.sph.scene import build_geometry

    run_dir = Path(run_dir)
    params = params or json.loads((run_dir / "params.json").read_text())
    geom = build_geometry(params, get_material(params["material"]))
    snaps = snapshots(run_dir)
    hist = liquid_histories(snaps)
    group: dict[int, str] = {}
    for t, d in snaps:
        if t >= t_from:
            for name, ids in bead_groups(t, d, geom, params).items():
                for i in ids:
                    group.setdefault(int(i), name)
    rows = [dict(id=i, group=g, **path_figures(hist[i])) for i, g in group.items()
            if i in hist and hist[i][0, 0] >= melted_from]
    df = pd.DataFrame(rows)
    for c in ("r_first", "z_first", "r_last", "z_last", "travel"):
        df[c] *= 1e3
    return df


def summary(df: pd.DataFrame) -> pd.DataFrame:
    """Medians per group, and the particle count."""
    return df.drop(columns="id").groupby("group").median().assign(n=df.groupby("group").size())


def main(argv=None) -> None:
    ap = argparse.ArgumentParser(prog="python -m beadsim.sph.tracks", description=__doc__.split("\n\n")[0])
    ap.add_argument("run_dir")
    ap.add_argument("--from", dest="t_from", type=float, default=2.0,
                    help="take the toe and core particles from the bead windows of the dumps since this time (s)")
    ap.add_argument("--melted-from", type=float, default=1.5,
                    help="keep the particles first liquid at or after this time (s): leaves the start-up out")
    args = ap.parse_args(argv)
    with pd.option_context("display.width", 160, "display.precision", 3):
        print(summary(toe_paths(args.run_dir, args.t_from, args.melted_from)).T)


if __name__ == "__main__":
    main()
