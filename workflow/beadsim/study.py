"""A study: config -> table of cases (one row per simulation) with stable, readable run ids.

``sweep`` is a list of design blocks; the study is their union. Each block is cases x grid x zip x lhs, each
factor optional:

- ``cases``: explicit list of parameter dicts; ``experiment: N`` fills in Table 4 mode N (and names the case
  ``modeN`` unless ``name`` is given);
- ``grid``: ``{param: [values]}``, full factorial;
- ``zip``: ``{param: [values]}``, equal-length lists taken together;
- ``lhs``: ``{samples, seed, ranges: {param: [lo, hi]}}``, a seeded Latin hypercube over numeric ranges.

Parameters not set anywhere take ``base`` values, then the defaults of ``beadsim.parameters``.
"""

from __future__ import annotations

import hashlib
import itertools
import json
import re
from pathlib import Path

import numpy as np
import pandas as pd

from beadsim.errors import ConfigError
from beadsim.parameters import all_parameters, defaults

ROOT = Path(__file__).resolve().parents[2]

# Table 4 columns of the experiments file that are scene parameters.
EXPERIMENT_PARAMS = (
    "material",
    "beam_power_W",
    "substrate_speed_mm_s",
    "wire_feed_mm_s",
    "wire_diameter_mm",
    "scan_diameter_mm",
    "scan_frequency_Hz",
    "wire_angle_deg",
    "wire_height_mm",
)


def load_experiments(path: str | Path | None = None) -> pd.DataFrame:
    """Measured beads (Table 1) with their process parameters (Table 4), indexed by mode number."""
    df = pd.read_csv(path or ROOT / "config" / "experiments.csv", comment="#")
    return df.set_index("mode")


def _check_value(key: str, value, where: str):
    """Raise ConfigError unless ``value`` is allowed for parameter ``key``."""
    params = all_parameters()
    if key not in params:
        raise ConfigError(f"{where}: unknown parameter {key!r}; allowed: {', '.join(params)}")
    p = params[key]
    ok_type = {
        "number": lambda v: isinstance(v, (int, float)) and not isinstance(v, bool),
        "integer": lambda v: isinstance(v, int) and not isinstance(v, bool),
        "string": lambda v: isinstance(v, str),
        "boolean": lambda v: isinstance(v, bool),
    }[p.type]
    if not ok_type(value):
        raise ConfigError(f"{where}.{key}: {value!r} is not a {p.type}")
    if p.enum and value not in p.enum:
        raise ConfigError(f"{where}.{key}: {value!r} is not allowed; allowed values: {list(p.enum)}")
    if p.type in ("number", "integer"):
        if p.minimum is not None and value < p.minimum:
            raise ConfigError(f"{where}.{key}: {value} is below the minimum {p.minimum} {p.units}")
        if p.exclusive_minimum is not None and value <= p.exclusive_minimum:
            raise ConfigError(f"{where}.{key}: {value} must be greater than {p.exclusive_minimum} {p.units}")
        if p.maximum is not None and value > p.maximum:
            raise ConfigError(f"{where}.{key}: {value} is above the maximum {p.maximum} {p.units}")


def _cases(block: dict, experiments: pd.DataFrame | None, where: str) -> list[tuple[str, dict]]:
    cases = block.get("cases") or [{}]
    out = []
    for i, case in enumerate(cases):
        case = dict(case)
        name = case.pop("name", "")
        if "experiment" in case:
            mode = case.pop("experiment")
            if experiments is None or mode not in experiments.index:
                known = [] if experiments is None else list(experiments.index)
                raise ConfigError(f"{where}.cases[{i}].experiment: no mode {mode!r} in the experiments file; "
                                  f"known modes: {known}")
            row = experiments.loc[mode]
            fill = {k: (row[k].item() if hasattr(row[k], "item") else row[k]) for k in EXPERIMENT_PARAMS}
            case = {**fill, **case}
            name = name or f"mode{mode}"
        for k, v in case.items():
            _check_value(k, v, f"{where}.cases[{i}]")
        out.append((str(name), case))
    return out


def _grid(block: dict, where: str) -> list[dict]:
    grid = block.get("grid") or {}
    for k, values in grid.items():
        for v in values:
            _check_value(k, v, f"{where}.grid")
    keys = list(grid)
    return [dict(zip(keys, combo)) for combo in itertools.product(*(grid[k] for k in keys))] or [{}]


def _zip(block: dict, where: str) -> list[dict]:
    zipped = block.get("zip") or {}
    lengths = {k: len(v) for k, v in zipped.items()}
    if len(set(lengths.values())) > 1:
        raise ConfigError(f"{where}.zip: all lists must have the same length; got {lengths}")
    for k, values in zipped.items():
        for v in values:
            _check_value(k, v, f"{where}.zip")
    n = next(iter(lengths.values()), 0)
    return [{k: zipped[k][i] for k in zipped} for i in range(n)] or [{}]


def latin_hypercube(ranges: dict[str, list[float]], samples: int, seed: int) -> list[dict]:
    """Seeded Latin hypercube: each range cut into ``samples`` strata, one point per stratum per axis."""
    rng = np.random.default_rng(seed)
    cols = {}
    for k, (lo, hi) in ranges.items():
        u = (rng.permutation(samples) + rng.random(samples)) / samples
        cols[k] = lo + u * (hi - lo)
    return [{k: float(np.round(cols[k][i], 6)) for k in ranges} for i in range(samples)]


def _lhs(block: dict, where: str) -> list[dict]:
    lhs = block.get("lhs")
    if not lhs:
        return [{}]
    params = all_parameters()
    where = f"{where}.lhs.ranges"
    for k, rng in lhs["ranges"].items():
        if k not in params or params[k].type != "number":
            numeric = [n for n, p in params.items() if p.type == "number"]
            raise ConfigError(f"{where}.{k}: Latin hypercube ranges need a numeric parameter; allowed: {numeric}")
        if len(rng) != 2 or not rng[0] < rng[1]:
            raise ConfigError(f"{where}.{k}: give [low, high] with low < high; got {rng}")
        _check_value(k, rng[0], where)
        _check_value(k, rng[1], where)
    return latin_hypercube(lhs["ranges"], int(lhs["samples"]), int(lhs.get("seed", 0)))


def _fmt(value) -> str:
    if isinstance(value, bool):
        return "1" if value else "0"
    if isinstance(value, float):
        text = f"{value:.6g}"
    else:
        text = str(value)
    return re.sub(r"[^A-Za-z0-9.\-]+", "-", text)


def design(config: dict, experiments: pd.DataFrame | None = None) -> pd.DataFrame:
    """Expand a validated study config into one row per case.

    Returns
    -------
    pandas.DataFrame
        Indexed by ``run_id``; one column per parameter plus ``case_name``.

    Raises
    ------
    ConfigError
        Unknown parameter, value out of bounds or not allowed, mismatched zip lists, duplicate cases.
    """
    base = dict(defaults())
    for k, v in (config.get("base") or {}).items():
        _check_value(k, v, "base")
        base[k] = v
    rows, names, swept = [], [], []
    for b, block in enumerate(config.get("sweep") or [{}]):
        where = f"sweep[{b}]"
        factors = [_grid(block, where), _zip(block, where), _lhs(block, where)]
        lhs_on = bool(block.get("lhs"))
        for name, case in _cases(block, experiments, where):
            for j, (g, z, h) in enumerate(itertools.product(*factors)):
                row = {**base, **case, **g, **z, **h}
                rows.append(row)
                names.append(name)
                swept.append((set(case) if not name else set(), {**g, **z, **h}, j if lhs_on else None))
    df = pd.DataFrame(rows)
    varying = {c for c in df.columns if df[c].astype(str).nunique() > 1}
    params = all_parameters()
    ids = []
    for name, (case_keys, sweep_vals, lhs_index), row in zip(names, swept, rows):
        keys = [k for k in params if k in varying and (k in case_keys or k in sweep_vals)]
        parts = [name] if name else []
        if lhs_index is not None:
            parts.append(f"lhs{lhs_index:03d}")
        parts += [f"{params[k].short or k}{_fmt(row[k])}" for k in keys]
        ids.append("_".join(parts) or "base")
    df.insert(0, "case_name", names)
    df.index = pd.Index(ids, name="run_id")
    dup = df.index[df.index.duplicated()].unique().tolist()
    if dup:
        raise ConfigError(f"sweep: these run ids appear more than once: {dup}; give cases distinct names or values")
    _check_continuations(df)
    return df


#: what a continued run may change against the run it continues (``continue_from``)
CONTINUE_MAY_CHANGE = ("sim_time_s", "stop_at_steady_state", "continue_from")


def _check_continuations(df: pd.DataFrame) -> None:
    """``continue_from`` names another SPH run of the study, of the same scene and a shorter run."""
    if "continue_from" not in df.columns:
        return
    ids = df.index.tolist()
    for run_id, source in df["continue_from"].items():
        if not source:
            continue
        where = f"sweep: run {run_id!r}: continue_from"
        row = case_params(df, run_id)
        if row["model"] != "sph":
            raise ConfigError(f"{where}: only SPH runs continue a checkpoint; model is {row['model']!r}")
        if source not in ids or source == run_id:
            raise ConfigError(f"{where}: {source!r} is not another run of this study; allowed: "
                              f"{[i for i in ids if i != run_id and df.loc[i, 'model'] == 'sph']}")
        if row["domain"] not in ("window", "plate"):
            raise ConfigError(f"{where}: needs domain window or plate (domain {row['domain']!r} sizes the block "
                              "from sim_time_s, so the checkpoint's block is not this run's)")
        src = case_params(df, source)
        fixed = [k for k in row if k not in CONTINUE_MAY_CHANGE]
        differ = [f"{k} {src[k]!r} there, {row[k]!r} here" for k in fixed if str(src[k]) != str(row[k])]
        if differ:
            raise ConfigError(f"{where}: {source!r} is another scene ({'; '.join(differ)}); a continued run may "
                              f"change only {' and '.join(CONTINUE_MAY_CHANGE[:2])}")
        if not src["sim_time_s"] < row["sim_time_s"]:  # (so the runs cannot continue each other in a cycle)
            raise ConfigError(f"{where}: {source!r} runs to sim_time_s {src['sim_time_s']} s, not less than this "
                              f"run's {row['sim_time_s']} s: nothing to continue")


def case_params(df: pd.DataFrame, run_id: str) -> dict:
    """The resolved parameters of one case as plain Python values."""
    row = df.loc[run_id]
    return {k: (v.item() if hasattr(v, "item") else v) for k, v in row.items() if k != "case_name"}


def config_digest(config: dict) -> str:
    """Short sha256 of the canonical JSON of a config (provenance)."""
    return hashlib.sha256(json.dumps(config, sort_keys=True, default=str).encode()).hexdigest()[:16]
