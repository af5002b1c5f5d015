"""Uncertainty bands on the reduced model's predictions of the measured modes, from the spread of its inputs.

The inputs the paper does not pin down: the beam efficiency (a range in the study config) and every material
property with a ``range`` in ``materials.yaml`` (conductivity, heat capacity, surface tension, contact angle, with
their sources). Each measured mode is run with the reduced model on one seeded Latin hypercube over all of them;
the band of a metric is its 5th to 95th percentile over the samples. Spearman rank correlations name the input
that drives each band. SPH is too dear for sampling: the bands belong to the screening rung.
"""

from __future__ import annotations

from concurrent.futures import ProcessPoolExecutor

import numpy as np
import pandas as pd

from beadsim.materials import _FIELDS, get_material, load_materials
from beadsim.study import latin_hypercube

METRICS = ("bead_width_mm", "bead_height_mm", "pool_length_mm", "penetration_depth_mm")
#: Default plausible range of the beam efficiency: electron-beam welding loses ~5-30 % to backscatter.
DEFAULT_RANGES = {"beam_efficiency": [0.7, 0.95]}
QUANTILES = (0.05, 0.5, 0.95)


def material_ranges(key: str, path=None) -> dict[str, tuple[float, float]]:
    """Plausible ranges of one material's properties, by :class:`~beadsim.materials.Material` field name."""
    entry = load_materials(path)[key]
    field_of = {src: f for f, src in _FIELDS.items()}
    return {field_of[src]: (float(v["range"][0]), float(v["range"][1]))
            for src, v in entry.items() if src in field_of and isinstance(v, dict) and "range" in v}


def run_sample(job: tuple) -> dict:
    """Reduced model for one (params, material overrides, materials file); returns the metrics and the regime."""
    from beadsim.reduced import run_reduced

    params, overrides, materials_file = job
    metrics = run_reduced(params, get_material(params["material"], materials_file, overrides))
    return {k: float(metrics.get(k, np.nan)) for k in METRICS} | {"regime": metrics.get("regime", "")}


def propagate(params: dict, samples: int = 32, seed: int = 0, ranges: dict | None = None, materials_file=None,
              workers: int = 1) -> pd.DataFrame:
    """Run the reduced model on a Latin hypercube over the uncertain inputs of one case.

    Parameters
    ----------
    params : the case (all scene parameters); ``model`` is forced to ``reduced``.
    ranges : scene parameter -> [low, high] (default :data:`DEFAULT_RANGES`).
    workers : processes running samples side by side.

    Returns
    -------
    pandas.DataFrame
        One row per sample: the drawn inputs (``param.<name>``, ``material.<field>``), then the metrics.
    """
    ranges = DEFAULT_RANGES if ranges is None else ranges
    axes = {f"param.{k}": tuple(v) for k, v in ranges.items()}
    axes |= {f"material.{k}": v for k, v in material_ranges(params["material"], materials_file).items()}
    draws = latin_hypercube(axes, samples, seed)
    jobs = []
    for draw in draws:
        case = dict(params, model="reduced")
        overrides = {}
        for axis, value in draw.items():
            kind, name = axis.split(".", 1)
            (case if kind == "param" else overrides)[name] = value
        if "contact_angle_deg" in overrides:
            case["wetting_angle_deg"] = 0.0  # the material's (sampled) angle, not a fixed one from the case
        jobs.append((case, overrides, materials_file))
    if workers > 1:
        with ProcessPoolExecutor(workers) as pool:
            results = list(pool.map(run_sample, jobs))
    else:
        results = [run_sample(j) for j in jobs]
    return pd.concat([pd.DataFrame(draws), pd.DataFrame(results)], axis=1).rename_axis("sample").reset_index()


def bands(samples: pd.DataFrame, experiment: pd.Series | None = None, nominal: dict | None = None) -> pd.DataFrame:
    """Per metric: nominal value, 5/50/95 % quantiles, the measured value and whether it lies in the band.

    ``measured_in_band`` widens the band by the measurement's own uncertainty (``*_unc_mm``) when it is known.
    ``driver`` is the input with the largest absolute Spearman rank correlation with the metric.
    """
    inputs = [c for c in samples.columns if c.startswith(("param.", "material."))]
    ranks = samples[inputs + list(METRICS)].rank()
    rows = []
    for metric in METRICS:
        values = samples[metric].dropna()
        lo, mid, hi = (values.quantile(q) if len(values) else np.nan for q in QUANTILES)
        corr = ranks[inputs].corrwith(ranks[metric]).dropna()
        driver = corr.abs().idxmax() if len(corr) else ""
        row = {"metric": metric, "nominal": (nominal or {}).get(metric, np.nan), "p05": lo, "p50": mid, "p95": hi,
               "samples_ok": int(len(values)), "driver": driver,
               "driver_spearman": float(corr[driver]) if driver else np.nan}
        if experiment is not None and metric in experiment.index:
            measured = float(experiment[metric])
            unc = float(experiment.get(metric.replace("_mm", "_unc_mm"), 0.0) or 0.0)
            row |= {"measured": measured, "measured_unc": unc,
                    "measured_in_band": bool(lo - unc <= measured <= hi + unc)}
        rows.append(row)
    return pd.DataFrame(rows)
