"""Aggregate per-run results into one xarray Dataset per study (netCDF, CF-style attributes).

One dimension, ``case`` (the run id). Every parameter is a coordinate on it with ``units`` and ``long_name``;
every metric is a variable with ``units`` and ``long_name``; failed runs stay in with ``status`` and ``reason``.
"""

from __future__ import annotations

import json
import math
from pathlib import Path

import numpy as np
import pandas as pd
import xarray as xr

from beadsim.metrics import METRICS, TEXT_OUTPUTS
from beadsim.parameters import all_parameters
from beadsim.provenance import provenance


def read_benchmark(path: str | Path) -> dict:
    """Wall time (s) and peak memory (MiB) from a Snakemake benchmark TSV."""
    df = pd.read_csv(path, sep="\t")
    return {"benchmark_s": float(df["s"].iloc[0]), "max_rss_MiB": float(pd.to_numeric(
        df["max_rss"], errors="coerce").iloc[0])}


def build_dataset(results: list[str | Path], benchmarks: list[str | Path] | None, config: dict,
                  design: pd.DataFrame) -> xr.Dataset:
    """Collect ``result.json`` files (and benchmark TSVs, same order) into a Dataset.

    Parameters
    ----------
    results : list of paths
        One ``result.json`` per run.
    benchmarks : list of paths or None
        Snakemake benchmark files in the same order (wall time of the simulate job).
    config : dict
        The study config (digest and name go into the attributes).
    design : pandas.DataFrame
        The case table (``beadsim.study.design``), indexed by run id.
    """
    from beadsim.study import config_digest

    records = [json.loads(Path(p).read_text()) for p in results]
    ids = [r["run_id"] for r in records]
    params = all_parameters()
    coords = {"case": ("case", ids, {"long_name": "run id"})}
    for name, p in params.items():
        values = design.loc[ids, name].to_numpy()
        if p.type == "boolean":
            values = values.astype(np.int8)
            attrs = {"long_name": p.long_name or name, "flag_values": "0 1", "flag_meanings": "false true"}
        elif p.type in ("number", "integer"):
            values = values.astype(float)
            attrs = {"long_name": p.long_name or name, "units": p.units or "1"}
        else:
            values = values.astype(str)
            attrs = {"long_name": p.long_name or name}
        attrs["description"] = p.description
        coords[name] = ("case", values, attrs)
    coords["case_name"] = ("case", design.loc[ids, "case_name"].astype(str).to_numpy(), {"long_name": "case name"})

    data = {}
    for name, (units, long_name) in METRICS.items():
        vals = [_num(r.get("metrics", {}).get(name)) for r in records]
        data[name] = ("case", np.array(vals, dtype=float), {"units": units, "long_name": long_name})
    data["status"] = ("case", np.array([r["status"] for r in records], dtype=str), {"long_name": TEXT_OUTPUTS["status"]})
    data["reason"] = ("case", np.array([r.get("reason", "") for r in records], dtype=str),
                      {"long_name": TEXT_OUTPUTS["reason"]})
    data["regime"] = ("case", np.array([r.get("metrics", {}).get("regime", "") or "" for r in records], dtype=str),
                      {"long_name": TEXT_OUTPUTS["regime"]})
    data["lammps_version"] = ("case", np.array([r["provenance"].get("lammps_version", "") for r in records],
                                               dtype=str), {"long_name": "LAMMPS version used by the run"})
    data["code_version"] = ("case", np.array([r["provenance"]["git_commit"] for r in records], dtype=str),
                            {"long_name": "git commit of the code that made the run"})
    if benchmarks:
        bench = [read_benchmark(b) for b in benchmarks]
        data["job_wall_time_s"] = ("case", np.array([b["benchmark_s"] for b in bench]),
                                   {"units": "s", "long_name": "job wall time (Snakemake benchmark)"})
        data["job_max_rss_MiB"] = ("case", np.array([b["max_rss_MiB"] for b in bench]),
                                   {"units": "MiB", "long_name": "job peak memory (Snakemake benchmark)"})
    attrs = {
        "Conventions": "CF-1.10",
        "title": f"beadsim study {config.get('study', '')}",
        "study": config.get("study", ""),
        "description": config.get("description", ""),
        "config_digest": config_digest(config),
        "config_json": json.dumps(config, sort_keys=True, default=str),
        "lammps_versions": ", ".join(sorted({v for v in data["lammps_version"][1] if v})) or "not used",
        **{k: v for k, v in provenance(with_lammps=False).items()},
    }
    return xr.Dataset(data, coords=coords, attrs=attrs)


def _num(v) -> float:
    if v is None:
        return math.nan
    try:
        return float(v)
    except (TypeError, ValueError):
        return math.nan


def swept_parameters(ds: xr.Dataset) -> list[str]:
    """Parameters that take more than one value across the cases, in table order."""
    out = []
    for name in all_parameters():
        if name in ds.coords and len(np.unique(ds[name].values)) > 1:
            out.append(name)
    return out


def gridded(ds: xr.Dataset) -> xr.Dataset | None:
    """The dataset on a grid over the swept parameters, or None when the cases do not form a full grid."""
    axes = swept_parameters(ds)
    if not axes:
        return None
    n_grid = int(np.prod([len(np.unique(ds[a].values)) for a in axes]))
    if n_grid != ds.sizes["case"]:
        return None
    keep = [c for c in ds.coords if c not in axes and c != "case"]
    flat = ds.reset_coords(keep, drop=True)
    if len(axes) == 1:
        grid = flat.swap_dims(case=axes[0]).drop_vars("case")
    else:
        flat = flat.set_index(case=axes)
        if flat.indexes["case"].has_duplicates:
            return None
        grid = flat.unstack("case")
    for a in axes:
        grid[a].attrs = ds[a].attrs
    grid.attrs = ds.attrs
    return grid
