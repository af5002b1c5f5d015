"""Study analyses over an aggregated dataset: calibration with leave-one-out validation, grid convergence.

Both work on any model's dataset: they only need the cases, their parameters and metrics.
"""

from __future__ import annotations

import math

import numpy as np
import pandas as pd
import xarray as xr

from beadsim.compare import match_experiments, measured_mass_balance


def _targets_for(mode: int, balance: pd.DataFrame) -> list[str]:
    """Metrics a mass-conserving model can be asked to match for a measured bead.

    Width always; height only where the bead holds the metal the wire fed (otherwise no mass-conserving
    prediction can match width and height together, and fitting the height would bias the parameter).
    """
    return ["width", "height"] if bool(balance.loc[mode, "consistent"]) else ["width"]


def response_curves(ds: xr.Dataset, exp: pd.DataFrame, parameter: str,
                    width_metric: str = "bead_width_mm") -> dict[int, pd.DataFrame]:
    """For each measured mode: the ok runs sorted by ``parameter`` with predicted width (``width_metric``) and
    height."""
    matched = match_experiments(ds, exp)
    index = {str(c): i for i, c in enumerate(ds["case"].values)}
    curves: dict[int, list] = {}
    for run_id, mode in matched.items():
        i = index[run_id]
        if ds["status"].values[i] != "ok":
            continue
        curves.setdefault(mode, []).append({parameter: float(ds[parameter].values[i]),
                                            "width": float(ds[width_metric].values[i]),
                                            "height": float(ds["bead_height_mm"].values[i])})
    return {m: pd.DataFrame(rows).sort_values(parameter).reset_index(drop=True) for m, rows in curves.items()}


def loo_calibration(ds: xr.Dataset, exp: pd.DataFrame, parameter: str = "beam_efficiency",
                    n_fine: int = 2001, width_metric: str = "bead_width_mm") -> tuple[pd.DataFrame, dict]:
    """Calibrate one parameter against Table 1 with leave-one-out cross-validation.

    The parameter's value for predicting mode m is the one that minimises the summed squared relative error of
    the *other* modes (width, and height where that bead passes its mass balance), with the metrics linearly
    interpolated between the swept values. So no mode is predicted by a fit to itself. Each fit searches the range
    swept (with ok runs) by every mode it fits, and the left-out mode is predicted only inside its own range (NaN
    outside it, no extrapolation), so one mode whose runs failed at some values does not narrow the others' fits.
    The predicted width is ``width_metric``: ``bead_width_mm`` (the bead's height profile), or ``fusion_width_mm`` (the molten top
    surface) where the bead is too flat for a height threshold (SPH beads one or two particles high).

    Returns
    -------
    table : pandas.DataFrame
        One row per mode: the left-out fit value, predictions and relative errors (cross-validated), the
        all-modes fit value and its (fitted, not validated) errors.
    summary : dict
        All-modes fit value, RMS cross-validated relative errors of width and height.
    """
    curves = response_curves(ds, exp, parameter, width_metric)
    balance = measured_mass_balance(exp).set_index("mode")
    modes = sorted(curves)
    if len(modes) < 2:
        raise ValueError(f"calibration needs runs of at least two measured modes; found {modes}")

    def span(fit_modes):
        """Parameter values swept (ok runs) in every one of fit_modes: no extrapolation of any curve."""
        return (max(curves[m][parameter].min() for m in fit_modes),
                min(curves[m][parameter].max() for m in fit_modes))

    def pred(mode, q, values):
        c = curves[mode]
        inside = (values >= c[parameter].min()) & (values <= c[parameter].max())
        return np.where(inside, np.interp(values, c[parameter], c[q]), np.nan)

    def fit(fit_modes):
        """Best value over the common span of fit_modes (NaN where they share none), and the grid, objective."""
        lo, hi = span(fit_modes)
        if lo > hi:
            return math.nan, np.array([]), np.array([])
        grid = np.linspace(lo, hi, n_fine)
        total = np.zeros_like(grid)
        for m in fit_modes:
            for q in _targets_for(m, balance):
                meas = float(exp.loc[m, f"bead_{q}_mm"])
                total += ((pred(m, q, grid) - meas) / meas) ** 2
        if not np.isfinite(total).any():
            return math.nan, grid, total
        return float(grid[np.nanargmin(total)]), grid, total

    best_all, grid_all, obj_all = fit(modes)
    lo, hi = span(modes)
    # Where the objective is flat the fit is not identifiable: report the whole near-optimal interval.
    near = grid_all[obj_all <= np.nanmin(obj_all) * 1.01 + 1e-9] if np.isfinite(best_all) else np.array([np.nan])
    rows = []
    for m in modes:
        others = [o for o in modes if o != m]
        best = fit(others)[0]
        # the left-out mode is predicted only inside its own swept range (NaN outside: no extrapolation)
        row = {"mode": m, "fit_on_modes": " ".join(map(str, others)), f"{parameter}_loo": best,
               f"{parameter}_all": best_all, "measured_mass_consistent": bool(balance.loc[m, "consistent"])}
        for q in ("width", "height"):
            meas = float(exp.loc[m, f"bead_{q}_mm"])
            p_loo = float(pred(m, q, np.array([best]))[0]) if np.isfinite(best) else math.nan
            p_all = float(pred(m, q, np.array([best_all]))[0]) if np.isfinite(best_all) else math.nan
            row.update({f"{q}_meas_mm": meas, f"{q}_pred_loo_mm": p_loo, f"{q}_err_rel_loo": (p_loo - meas) / meas,
                        f"{q}_pred_fit_mm": p_all, f"{q}_err_rel_fit": (p_all - meas) / meas})
        rows.append(row)
    table = pd.DataFrame(rows)
    summary = {
        "parameter": parameter,
        "width_metric": width_metric,
        "range_searched": [float(lo), float(hi)],
        "ranges_per_mode": {int(m): [float(c[parameter].min()), float(c[parameter].max())] for m, c in curves.items()},
        f"{parameter}_all": best_all,
        f"{parameter}_all_interval": [float(np.nanmin(near)), float(np.nanmax(near))],
        "identifiable": bool(hi > lo and np.nanmax(near) - np.nanmin(near) < 0.05 * (hi - lo)),
        "modes_predicted_loo": int(table["width_err_rel_loo"].notna().sum()),
        "width_rms_err_rel_loo": float(np.sqrt(np.nanmean(table["width_err_rel_loo"] ** 2))),
        "height_rms_err_rel_loo": float(np.sqrt(np.nanmean(table["height_err_rel_loo"] ** 2))),
        "height_rms_err_rel_loo_consistent_modes": float(np.sqrt(np.nanmean(
            table.loc[table["measured_mass_consistent"], "height_err_rel_loo"] ** 2)))
        if table["measured_mass_consistent"].any() else math.nan,
    }
    return table, summary


def richardson(h: np.ndarray, f: np.ndarray, safety: float = 1.25) -> dict:
    """Observed order, extrapolated value and grid-convergence index from three resolutions.

    Roache's GCI for possibly non-constant refinement ratios (Celik et al. 2008, J. Fluids Eng. 130, 078001):
    solves ``(f3 - f2)/(f2 - f1) = (r21^p - 1)/(r32^p - 1) * r32^p ... `` by fixed-point iteration.

    Parameters
    ----------
    h : array of 3 floats
        Resolutions (e.g. particle spacing), any order.
    f : array of 3 floats
        The quantity at each resolution.

    Returns
    -------
    dict
        ``order`` (observed p), ``extrapolated`` (f at h -> 0), ``gci_fine`` (relative band of the finest
        value), ``monotone`` (False for oscillatory convergence, where the order is not meaningful).
    """
    order = np.argsort(h)
    h1, h2, h3 = np.asarray(h, float)[order]
    f1, f2, f3 = np.asarray(f, float)[order]
    r21, r32 = h2 / h1, h3 / h2
    e21, e32 = f2 - f1, f3 - f2
    if e21 == 0 or e32 == 0:
        return {"order": math.nan, "extrapolated": f1, "gci_fine": 0.0, "monotone": e21 == e32}
    s = np.sign(e32 / e21)
    p = 1.0
    for _ in range(200):
        q = math.log((r21**p - s) / (r32**p - s))
        p_new = abs(math.log(abs(e32 / e21)) + q) / math.log(r21)
        if abs(p_new - p) < 1e-12:
            break
        p = p_new
    extrap = (r21**p * f1 - f2) / (r21**p - 1)
    gci = safety * abs((f1 - f2) / f1) / (r21**p - 1) if f1 != 0 else math.nan
    return {"order": p, "extrapolated": extrap, "gci_fine": gci, "monotone": bool(s > 0)}


CONVERGENCE_METRICS = ("bead_width_mm", "fusion_width_mm", "bead_height_mm", "pool_length_mm", "pool_width_mm",
                       "pool_depth_mm")


def convergence_table(ds: xr.Dataset, parameter: str = "resolution_mm",
                      metrics=CONVERGENCE_METRICS) -> pd.DataFrame:
    """Richardson analysis of every group of cases that differ only in ``parameter``.

    Uses the three finest ok resolutions of each group; groups with fewer are reported with NaN order.
    """
    from beadsim.dataset import swept_parameters

    others = [p for p in swept_parameters(ds) if p != parameter]
    keys = pd.DataFrame({p: ds[p].values for p in others}) if others else pd.DataFrame(index=range(ds.sizes["case"]))
    group_ids = keys.astype(str).agg("_".join, axis=1) if others else pd.Series(["all"] * ds.sizes["case"])
    rows = []
    for gid in pd.unique(group_ids):
        idx = np.where((group_ids == gid).to_numpy() & (ds["status"].values == "ok"))[0]
        hs = ds[parameter].values[idx]
        order = np.argsort(hs)[:3]
        label = str(ds["case_name"].values[idx[0]]) if len(idx) and ds["case_name"].values[idx[0]] else gid
        for m in metrics:
            row = {"group": label, "metric": m, "n_ok": len(idx)}
            vals = ds[m].values[idx][order]
            for h, v in zip(hs[order], vals):
                row[f"{m}@{h:g}"] = float(v)
            if len(idx) >= 3 and np.all(np.isfinite(vals)):
                row.update(richardson(hs[order], vals))
                row["finest"] = float(vals[0])
            rows.append(row)
    return pd.DataFrame(rows)


# Stability classes of a run, from the watchdog's verdict and the quality of a run that held.
STABILITY_CLASSES = ("stable", "degraded", "blown_up")


def stability_class(status: str, density_min: float, density_max: float, energy_error: float,
                    density_band: float = 0.05, energy_band: float = 0.02, reason: str = "") -> str:
    """Classify one run: ``error`` (it failed for a reason that is not numerical: a Python exception, reason
    starting with ``error:``), ``blown_up`` (the watchdog or LAMMPS stopped it), ``degraded`` (it held, but the
    liquid density left rho0 +- density_band or the energy balance is off by more than energy_band),
    ``stable`` otherwise."""
    if status != "ok":
        return "error" if str(reason).startswith("error:") else "blown_up"
    dens_ok = (not np.isfinite(density_min) or density_min >= 1 - density_band) and \
        (not np.isfinite(density_max) or density_max <= 1 + density_band)
    energy_ok = not np.isfinite(energy_error) or abs(energy_error) <= energy_band
    return "stable" if dens_ok and energy_ok else "degraded"


def pareto_front(cost: np.ndarray, error: np.ndarray) -> np.ndarray:
    """Boolean mask of the points no other point beats in both cost and error (lower is better)."""
    cost, error = np.asarray(cost, float), np.asarray(error, float)
    ok = np.isfinite(cost) & np.isfinite(error)
    front = np.zeros(len(cost), bool)
    for i in np.where(ok)[0]:
        dominated = ok & (cost <= cost[i]) & (error <= error[i]) & ((cost < cost[i]) | (error < error[i]))
        front[i] = not dominated.any()
    return front


def stability_table(ds: xr.Dataset, density_band: float = 0.05, energy_band: float = 0.02) -> pd.DataFrame:
    """One row per run: its swept parameters, the quantities the class rests on, the class and the reason."""
    from beadsim.dataset import swept_parameters

    cols = {p: ds[p].values for p in swept_parameters(ds)}
    df = pd.DataFrame({"run_id": ds["case"].values, **cols})
    for k in ("density_min", "density_max", "energy_balance_error", "melt_speed_max_m_s", "dt_s",
              "simulated_time_s"):
        df[k] = ds[k].values
    df["status"] = ds["status"].values
    df["reason"] = ds["reason"].values
    df["class"] = [stability_class(s, a, b, e, density_band, energy_band, r) for s, a, b, e, r in
                   zip(df["status"], df["density_min"], df["density_max"], df["energy_balance_error"],
                       df["reason"])]
    return df


def _mean_rel_error(width, height, width_ref, height_ref):
    """Mean of the absolute relative errors of bead width and height against reference values."""
    return 0.5 * (abs(width / width_ref - 1) + abs(height / height_ref - 1))


def speed_accuracy_table(ds: xr.Dataset, exp: pd.DataFrame, reference: str | None = None) -> pd.DataFrame:
    """Cost and error of every run, for a speed-vs-accuracy (Pareto) chart.

    Cost: the job's wall time (Snakemake benchmark, ``job_wall_time_s``; else the model's ``wall_time_s``).
    Error versus Table 1: mean of |relative error| of bead width and height, for runs that match a measured mode.
    Error versus the reference: the same against a reference run of the same mode -- ``reference`` (a run id) or,
    by default, the successful SPH run with the smallest ``resolution_mm`` for that mode (ties: the most
    expensive). Failed runs keep their cost and get no error. ``pareto_table1`` / ``pareto_reference`` flag the
    runs no other run beats in both cost and error.
    """
    matched = match_experiments(ds, exp)
    cases = [str(c) for c in ds["case"].values]
    cost_var = "job_wall_time_s" if "job_wall_time_s" in ds else "wall_time_s"
    df = pd.DataFrame({
        "run_id": cases, "model": ds["model"].values.astype(str), "status": ds["status"].values.astype(str),
        "resolution_mm": ds["resolution_mm"].values.astype(float),
        "mode": [matched.get(c, np.nan) for c in cases],
        "cost_s": ds[cost_var].values.astype(float),
        "width_mm": ds["bead_width_mm"].values.astype(float),
        "height_mm": ds["bead_height_mm"].values.astype(float)})
    for opt in ("domain", "stop_at_steady_state", "n_particles", "n_steps"):
        if opt in ds:
            df[opt] = ds[opt].values
    ok = df["status"] == "ok"
    meas_w = df["mode"].map(lambda m: exp.loc[int(m), "bead_width_mm"] if np.isfinite(m) else np.nan)
    meas_h = df["mode"].map(lambda m: exp.loc[int(m), "bead_height_mm"] if np.isfinite(m) else np.nan)
    df["error_table1"] = np.where(ok, _mean_rel_error(df["width_mm"], df["height_mm"], meas_w, meas_h), np.nan)
    df["reference"] = ""
    df["error_reference"] = np.nan
    for mode, grp in df[df["mode"].notna()].groupby("mode"):
        if reference and reference in set(grp["run_id"]):
            ref = grp.loc[grp["run_id"] == reference].iloc[0]
        else:
            cand = grp[(grp["model"] == "sph") & (grp["status"] == "ok") & grp["width_mm"].notna()]
            if cand.empty:
                continue
            ref = cand.sort_values(["resolution_mm", "cost_s"], ascending=[True, False]).iloc[0]
        err = _mean_rel_error(grp["width_mm"], grp["height_mm"], ref["width_mm"], ref["height_mm"])
        df.loc[grp.index, "reference"] = ref["run_id"]
        df.loc[grp.index, "error_reference"] = np.where(grp["status"] == "ok", err, np.nan)
    df["pareto_table1"] = pareto_front(df["cost_s"], df["error_table1"])
    df["pareto_reference"] = pareto_front(df["cost_s"], df["error_reference"])
    return df


def model_check_table(ds: xr.Dataset, metrics=("bead_width_mm", "bead_height_mm", "pool_width_mm",
                                              "pool_length_mm", "pool_depth_mm")) -> pd.DataFrame:
    """SPH checks of the reduced model: each SPH run beside the reduced run of the same scene.

    The same scene: equal values of every parameter the reduced model reads, except ``model`` and
    ``resolution_mm``. Per metric: both values and ``<metric>_rel`` = reduced / SPH - 1. SPH runs without a
    reduced twin are listed with an empty ``reduced_run_id``.
    """
    from beadsim.parameters import all_parameters

    keys = [n for n, p in all_parameters().items()
            if "reduced" in p.models and n not in ("model", "resolution_mm") and n in ds]
    model = ds["model"].values.astype(str)
    scene = pd.DataFrame({k: ds[k].values for k in keys}).astype(str).agg("|".join, axis=1)
    reduced = {s: i for i, s in reversed(list(enumerate(scene))) if model[i] == "reduced"}
    rows = []
    for i in np.where(model == "sph")[0]:
        j = reduced.get(scene[i])
        row = {"run_id": str(ds["case"].values[i]), "reduced_run_id": "" if j is None else str(ds["case"].values[j]),
               "status": str(ds["status"].values[i]), "resolution_mm": float(ds["resolution_mm"].values[i]),
               "reduced_regime": "" if j is None else str(ds["regime"].values[j])}
        for m in metrics:
            if m not in ds:
                continue
            s = float(ds[m].values[i])
            r = np.nan if j is None else float(ds[m].values[j])
            row |= {f"{m}_sph": s, f"{m}_reduced": r, f"{m}_rel": r / s - 1 if np.isfinite(s) and s else np.nan}
        rows.append(row)
    return pd.DataFrame(rows)
