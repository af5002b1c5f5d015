"""Figures: process maps over swept parameters and parity plots against the measured beads.

Axis labels come from the dataset's ``long_name`` and ``units`` attributes.
"""

from __future__ import annotations

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402
import pandas as pd  # noqa: E402
import seaborn as sns  # noqa: E402
import xarray as xr  # noqa: E402
from matplotlib.colors import BoundaryNorm, ListedColormap  # noqa: E402

from beadsim.dataset import swept_parameters  # noqa: E402
from beadsim.reduced import REGIMES  # noqa: E402

DEFAULT_METRICS = ["bead_width_mm", "bead_height_mm", "aspect_ratio", "pool_length_mm", "regime"]
REGIME_CMAP = ListedColormap(sns.color_palette("Set2", len(REGIMES)))
REGIME_NORM = BoundaryNorm(np.arange(-0.5, len(REGIMES)), len(REGIMES))


def main_block(ds: xr.Dataset, axes: list[str]) -> xr.Dataset:
    """The cases that share the most common value of every swept parameter not in ``axes``, and whose axis
    values are among the most frequent ones (at least half as frequent as the most frequent: a stray case off
    the grid does not break a heat map, a case on a grid level does not hide the others).

    A study may be a union of blocks (measured modes beside a grid); a map shows the block that varies only
    along its axes. Where several values are equally common (a full factorial grid), the middle one is kept: a
    5-D grid is shown at the centre of its other axes (the middle of the common levels).
    """
    keep = np.ones(ds.sizes["case"], dtype=bool)
    for name in swept_parameters(ds):
        values, counts = np.unique(ds[name].values[keep], return_counts=True)
        common = values[counts >= 0.5 * counts.max()]  # grid levels; a measured mode on a level adds one
        if name in axes:
            keep &= np.isin(ds[name].values, common)
        else:
            keep &= ds[name].values == common[(len(common) - 1) // 2]
    return ds.isel(case=np.where(keep)[0])


def fixed_values(shown: xr.Dataset, full: xr.Dataset, axes: list[str]) -> dict:
    """The swept parameters not on the map axes and the one value the map shows them at."""
    return {name: shown[name].values[0] for name in swept_parameters(full)
            if name not in axes and shown.sizes["case"] and len(np.unique(shown[name].values)) == 1}


def label(da: xr.DataArray) -> str:
    """'long name [units]' from a DataArray's attributes."""
    name = da.attrs.get("long_name", da.name)
    units = da.attrs.get("units", "")
    return f"{name} [{units}]" if units and units != "1" else str(name)


def _frame(ds: xr.Dataset, cols: list[str]) -> pd.DataFrame:
    df = pd.DataFrame({c: ds[c].values for c in cols})
    df["status"] = ds["status"].values
    df["regime"] = ds["regime"].values
    return df


def process_maps(ds: xr.Dataset, map_x: str | None = None, map_y: str | None = None, map_facet: str | None = None,
                 map_metrics: list[str] | None = None, experiments: pd.DataFrame | None = None) -> plt.Figure:
    """A grid of maps: one row per metric, one column per facet value.

    Two or more swept axes: heat maps on a full (x, y) grid, coloured scatter otherwise (Latin hypercube);
    failed runs marked with a cross. One swept axis: lines. None: bars per case. ``experiments`` (Table 4 rows
    indexed by mode) are overlaid as white stars on the maps whose facet value they share.
    """
    metrics = list(map_metrics or DEFAULT_METRICS)
    axes = swept_parameters(ds)
    numeric = [a for a in axes if ds[a].dtype.kind == "f"]
    x = map_x or (numeric[0] if numeric else None)
    y = map_y or next((a for a in numeric if a != x), None)
    facet = map_facet or next((a for a in axes if a not in (x, y)), None)
    n_all = ds.sizes["case"]
    fixed = {}
    if x is not None:
        full = ds
        ds = main_block(ds, [a for a in (x, y, facet) if a])
        fixed = fixed_values(ds, full, [a for a in (x, y, facet) if a])
    facet_vals = list(np.unique(ds[facet].values)) if facet else [None]
    fig, grid = plt.subplots(len(metrics), len(facet_vals), figsize=(4.2 * len(facet_vals), 3.3 * len(metrics)),
                             squeeze=False)
    for col, fv in enumerate(facet_vals):
        sub = ds.isel(case=np.where(ds[facet].values == fv)[0]) if facet else ds
        for row, metric in enumerate(metrics):
            ax = grid[row, col]
            if x is None:
                _bars(ax, sub, metric)
            elif y is None:
                _lines(ax, sub, x, metric)
            else:
                heat = _map(ax, sub, x, y, metric)
                if experiments is not None:
                    _overlay_experiments(ax, sub, x, y, facet, fv, experiments, heat)
            title = f"{facet} = {fv}" if facet else ""
            ax.set_title(f"{title}\n{metric}" if row == 0 and title else metric, fontsize=9)
    at = ", ".join(f"{k} = {_tick(v.item() if hasattr(v, 'item') else v)}" for k, v in fixed.items())
    fig.suptitle(f"{ds.attrs.get('title', '')}: {ds.sizes['case']} of {n_all} runs shown, "
                 f"{int((ds['status'].values == 'failed').sum())} failed" + (f"\nat {at}" if at else ""),
                 fontsize=10)
    fig.tight_layout()
    return fig


def _overlay_experiments(ax, ds, x, y, facet, facet_value, experiments: pd.DataFrame, heat: bool):
    """White stars at the measured modes' (x, y) on this panel (positions interpolated between heat-map cells),
    for the modes that share the values the panel holds fixed (material, wire feed, ...)."""
    if x not in experiments or y not in experiments:
        return
    held = {facet: facet_value} if facet and facet in experiments else {}
    for name in experiments.columns:  # parameters the panel holds at one value: the mode must share them
        if name not in (x, y, facet) and name in ds.coords and len(np.unique(ds[name].values)) == 1:
            held[name] = ds[name].values[0]
    rows = experiments
    for name, value in held.items():
        column = rows[name]
        same = np.isclose(column.astype(float), float(value)) if pd.api.types.is_numeric_dtype(column) \
            else column.astype(str) == str(value)
        rows = rows[same]
    xs, ys = np.unique(ds[x].values), np.unique(ds[y].values)
    for mode, r in rows.iterrows():
        px, py = float(r[x]), float(r[y])
        if heat:  # cell centres at i + 0.5; y drawn descending
            if not (xs.min() <= px <= xs.max() and ys.min() <= py <= ys.max()):
                continue
            px = np.interp(px, xs, np.arange(len(xs))) + 0.5
            py = len(ys) - 1 - np.interp(py, ys, np.arange(len(ys))) + 0.5
        ax.plot(px, py, "*", ms=13, mfc="white", mec="k")
        ax.annotate(f"mode {mode}", (px, py), fontsize=7, xytext=(4, 4), textcoords="offset points")


def main_effects_plot(ds: xr.Dataset, metrics: list[str] | None = None) -> plt.Figure:
    """Main effects over a factorial or Latin-hypercube sweep: the mean of each metric (successful runs) at each
    level of each swept numeric parameter, all other parameters averaged over. Shows every axis of a 5-D sweep
    on one page; interactions are what the maps add."""
    metrics = [m for m in (metrics or DEFAULT_METRICS) if m != "regime" and m in ds]
    params = [p for p in swept_parameters(ds) if ds[p].dtype.kind == "f"]
    ok = ds.isel(case=np.where(ds["status"].values == "ok")[0])
    fig, grid = plt.subplots(len(metrics), max(len(params), 1), figsize=(3.2 * max(len(params), 1),
                             2.6 * len(metrics)), squeeze=False, sharey="row")
    for j, p in enumerate(params):
        frame = pd.DataFrame({p: ok[p].values} | {m: ok[m].values for m in metrics})
        levels = frame.groupby(p)
        if levels.ngroups > 12:  # Latin hypercube: bin the axis
            frame[p] = pd.cut(frame[p], 6).apply(lambda iv: iv.mid).astype(float)
            levels = frame.groupby(p)
        for i, m in enumerate(metrics):
            ax = grid[i, j]
            stats = levels[m].agg(["mean", "min", "max"])
            ax.fill_between(stats.index, stats["min"], stats["max"], alpha=0.2, label="range")
            ax.plot(stats.index, stats["mean"], "o-", label="mean")
            ax.set_xlabel(label(ds[p]), fontsize=8)
            if j == 0:
                ax.set_ylabel(label(ds[m]), fontsize=8)
    grid[0, 0].legend(fontsize=7)
    fig.suptitle(f"main effects over {ok.sizes['case']} successful runs", fontsize=10)
    fig.tight_layout()
    return fig


def _regime_codes(values) -> np.ndarray:
    return np.array([REGIMES.index(v) if v in REGIMES else np.nan for v in values], dtype=float)


def _map(ax, ds, x, y, metric) -> bool:
    """Heat map (full grid; returns True) or coloured scatter (returns False) of one metric over (x, y)."""
    df = _frame(ds, [x, y] + ([metric] if metric != "regime" else []))
    is_regime = metric == "regime"
    df["value"] = _regime_codes(df["regime"]) if is_regime else df[metric]
    df.loc[df["status"] != "ok", "value"] = np.nan
    cmap, norm = (REGIME_CMAP, REGIME_NORM) if is_regime else ("viridis", None)
    full = df.groupby([y, x]).size().unstack(x)
    heat = bool(full.notna().all().all())  # every cell filled; a case repeated on a grid point is averaged
    if heat:
        table = df.pivot_table(index=y, columns=x, values="value", aggfunc="mean", dropna=False)
        table = table.sort_index(ascending=False)
        table.index = [_tick(v) for v in table.index]
        table.columns = [_tick(v) for v in table.columns]
        sns.heatmap(table, ax=ax, cmap=cmap, norm=norm, annot=not is_regime, fmt=".2g", cbar=not is_regime,
                    cbar_kws={"label": label(ds[metric])} if not is_regime else None)
        failed = df[df["status"] != "ok"]
        for _, r in failed.iterrows():
            ax.text(list(table.columns).index(_tick(r[x])) + 0.5, list(table.index).index(_tick(r[y])) + 0.5,
                    "failed", ha="center", va="center", color="red", fontsize=7)
    else:
        ok = df[df["status"] == "ok"]
        sc = ax.scatter(ok[x], ok[y], c=ok["value"], cmap=cmap, norm=norm, s=40)
        bad = df[df["status"] != "ok"]
        ax.scatter(bad[x], bad[y], marker="x", color="red", s=40, label="failed")
        if not is_regime:
            fig = ax.figure
            fig.colorbar(sc, ax=ax, label=label(ds[metric]))
    if is_regime:
        present = sorted({r for r in df["regime"] if r in REGIMES}, key=REGIMES.index)
        handles = [plt.Rectangle((0, 0), 1, 1, color=REGIME_CMAP(REGIMES.index(r))) for r in present]
        ax.legend(handles, present, fontsize=7, loc="best")
    ax.set_xlabel(label(ds[x]))
    ax.set_ylabel(label(ds[y]))
    return heat


def _tick(v) -> str:
    return f"{v:g}" if isinstance(v, float) else str(v)


def _lines(ax, ds, x, metric):
    order = np.argsort(ds[x].values)
    xs = ds[x].values[order]
    ok = ds["status"].values[order] == "ok"
    if metric == "regime":
        codes = _regime_codes(ds["regime"].values[order])
        ax.scatter(xs[ok], codes[ok])
        ax.set_yticks(range(len(REGIMES)), REGIMES, fontsize=7)
    else:
        ys = ds[metric].values[order]
        ax.plot(xs[ok], ys[ok], "o-")
        ax.set_ylabel(label(ds[metric]))
    ax.plot(xs[~ok], np.zeros((~ok).sum()), "rx", label="failed")
    ax.set_xlabel(label(ds[x]))


def _bars(ax, ds, metric):
    names = [str(c) for c in ds["case"].values]
    if metric == "regime":
        ax.barh(names, np.ones(len(names)))
        for i, r in enumerate(ds["regime"].values):
            ax.text(0.05, i, r or ds["status"].values[i], va="center", fontsize=8)
        ax.set_xticks([])
    else:
        ax.barh(names, np.nan_to_num(ds[metric].values))
        ax.set_xlabel(label(ds[metric]))


def _run_spread(errors: pd.DataFrame, q: str) -> pd.Series | None:
    """Standard deviation of the sections around the run mean of ``q`` (0 where not given); None without run
    means (an error table from before they existed)."""
    if f"{q}_run_mean_mm" not in errors:
        return None
    sd = errors[f"{q}_run_sd_mm"] if f"{q}_run_sd_mm" in errors else pd.Series(0.0, index=errors.index)
    return sd.fillna(0.0)


def parity_plot(errors: pd.DataFrame, balance: pd.DataFrame) -> plt.Figure:
    """Predicted vs measured bead width and height, one marker per run; hollow where the measured bead fails
    its own mass balance (the wire fed more metal than the bead holds). SPH window runs with run means (the
    mean of every section since the wire's metal arrived) get a second marker, x, with the sections' standard
    deviation as error bar, beside the last sections' bead: for a humping bead the spread is the answer. Open
    triangles: the run means of the width and height from the mass per column (SPH window runs), which a
    disordered frozen melt does not read low and thin metal at the toes does not escape. Grey stars: the paper's
    own SPH estimates of the measured beads (Table 1), where the experiments table gives them."""
    fig, axes = plt.subplots(1, 2, figsize=(9, 4.2))
    for ax, q in zip(axes, ("width", "height")):
        meas_all = balance[f"measured_{q}_mm"]
        top = errors[f"{q}_pred_mm"].max() if len(errors) else 0
        spread = _run_spread(errors, q)
        if spread is not None:
            top = np.nanmax([top, (errors[f"{q}_run_mean_mm"] + spread).max()])
        mass = f"{q}_mass_run_mean_mm" in errors
        if mass:
            top = np.nanmax([top, (errors[f"{q}_mass_run_mean_mm"]
                                   + errors[f"{q}_mass_run_sd_mm"].fillna(0.0)).max()])
        lim = [0, 1.25 * max(meas_all.max(), top)]
        ax.plot(lim, lim, "k-", lw=1)
        ax.fill_between(lim, [v * 0.95 for v in lim], [v * 1.05 for v in lim], color="0.85", label="+-5 %")
        paper = balance.dropna(subset=[f"paper_sph_{q}_mm"]) if f"paper_sph_{q}_mm" in balance else balance.iloc[:0]
        if len(paper):
            ax.plot(paper[f"measured_{q}_mm"], paper[f"paper_sph_{q}_mm"], "*", color="0.45", ms=9, zorder=1,
                    label="the paper's SPH estimate (its Table 1)")
        for k, ((model, res), grp) in enumerate(errors.groupby(["model", "resolution_mm"])):
            ok = grp[grp["status"] == "ok"]
            name = model if model == "reduced" else f"{model} dx={res:g} mm"
            band = grp.drop_duplicates("mode").dropna(subset=[f"{q}_lattice_lo_mm"]) \
                if f"{q}_lattice_lo_mm" in grp else grp.iloc[:0]
            if len(band):
                # the measured bead as the particle measure reads it at this spacing: a bar over the band of
                # lattice phases, dots at the registered and the random-phase means (left of the measured value)
                # modes measured alike (modes 2 and 3: 3.6 mm wide) side by side, not on top of each other
                alike = band.groupby(f"{q}_meas_mm").cumcount()
                xb = band[f"{q}_meas_mm"] - (0.015 * (k + 1) + 0.01 * alike) * lim[1]
                ax.vlines(xb, band[f"{q}_lattice_lo_mm"], band[f"{q}_lattice_hi_mm"], color=f"C{k}", lw=4,
                          alpha=0.3, label=f"measured bead read by the measure at dx={res:g} mm")
                ax.plot(xb, band[f"{q}_lattice_registered_mm"], "_", color=f"C{k}", ms=9)
                ax.plot(xb, band[f"{q}_lattice_random_mm"], ".", color=f"C{k}", ms=5)
            for consistent, part in ok.groupby("measured_mass_consistent"):
                ax.errorbar(part[f"{q}_meas_mm"], part[f"{q}_pred_mm"], xerr=part[f"{q}_unc_mm"], fmt="o",
                            color=f"C{k}", mfc=None if consistent else "none",
                            label=name + ("" if consistent else " (bead fails mass balance)"))
            runs = ok[ok[f"{q}_run_mean_mm"].notna()] if f"{q}_run_mean_mm" in ok else ok.iloc[:0]
            if len(runs):
                # drawn a little to the right of the measured value so that it does not hide the last sections
                ax.errorbar(runs[f"{q}_meas_mm"] + 0.015 * lim[1], runs[f"{q}_run_mean_mm"],
                            yerr=_run_spread(runs, q), fmt="x",
                            color=f"C{k}", capsize=3, label=name + ", run mean +- sd of the sections")
            runs = ok[ok[f"{q}_mass_run_mean_mm"].notna()] if mass else ok.iloc[:0]
            if len(runs):
                # the width / height from the mass per column, further right
                ax.errorbar(runs[f"{q}_meas_mm"] + 0.03 * lim[1], runs[f"{q}_mass_run_mean_mm"],
                            yerr=runs[f"{q}_mass_run_sd_mm"].fillna(0.0), fmt="^", mfc="none", color=f"C{k}",
                            capsize=3, label=name + ", from the mass per column, mean +- sd of the sections")
            for _, r in ok.iterrows():
                ax.annotate(f"m{r['mode']}", (r[f"{q}_meas_mm"], r[f"{q}_pred_mm"]), fontsize=7,
                            xytext=(3, 3), textcoords="offset points")
        if errors.empty:
            ax.text(0.5, 0.5, "no run matches a measured bead", ha="center", transform=ax.transAxes)
        ax.set_xlim(lim)
        ax.set_ylim(lim)
        ax.set_xlabel(f"measured bead {q} [mm]")
        ax.set_ylabel(f"predicted bead {q} [mm]")
    # one legend for both panels, below them: inside the axes its long entries covered the markers and ran
    # past the figure's edge
    entries = {}
    for ax in axes:
        for handle, label in zip(*ax.get_legend_handles_labels()):
            entries.setdefault(label, handle)
    fig.tight_layout()
    if entries:
        fig.legend(list(entries.values()), list(entries), loc="upper center", bbox_to_anchor=(0.5, 0.0), ncol=2,
                   fontsize=7, frameon=False)
    return fig


def calibration_plot(curves: dict, table: pd.DataFrame, exp: pd.DataFrame, parameter: str,
                     attrs: dict, width_label: str = "bead width") -> plt.Figure:
    """Width (``width_label`` names the metric compared) and height against the calibrated parameter per mode,
    measured values, left-out fits."""
    fig, axes = plt.subplots(1, 2, figsize=(9, 4))
    xlabel = f"{attrs.get('long_name', parameter)} [{attrs.get('units', '')}]"
    loo = table.set_index("mode")
    for k, (mode, c) in enumerate(sorted(curves.items())):
        for ax, q in zip(axes, ("width", "height")):
            ax.plot(c[parameter], c[q], "o-", color=f"C{k}", label=f"mode {mode}")
            ax.axhline(float(exp.loc[mode, f"bead_{q}_mm"]), color=f"C{k}", ls="--", lw=1)
            x = loo.loc[mode, f"{parameter}_loo"]
            ax.plot([x], [loo.loc[mode, f"{q}_pred_loo_mm"]], "*", ms=12, color=f"C{k}")
    for ax, label in zip(axes, (width_label, "bead height")):
        ax.set_xlabel(xlabel)
        ax.set_ylabel(f"{label} [mm]", fontsize=8 if len(label) > 30 else None)
    axes[0].legend(title="dashed: measured; star: left-out fit", fontsize=7, title_fontsize=7)
    fig.tight_layout()
    return fig


def convergence_plot(ds: xr.Dataset, table: pd.DataFrame, parameter: str) -> plt.Figure:
    """Each convergence metric against resolution per group, with the extrapolated value and its GCI band."""
    metrics = list(pd.unique(table["metric"])) if len(table) else []
    groups = list(pd.unique(table["group"])) if len(table) else []
    fig, axes = plt.subplots(1, max(len(metrics), 1), figsize=(3.6 * max(len(metrics), 1), 3.4), squeeze=False)
    for j, m in enumerate(metrics):
        ax = axes[0, j]
        for k, g in enumerate(groups):
            row = table[(table["group"] == g) & (table["metric"] == m)].iloc[0]
            pts = sorted((float(c.split("@")[1]), row[c]) for c in table.columns
                         if c.startswith(f"{m}@") and pd.notna(row[c]))
            if not pts:
                continue
            hs, vs = zip(*pts)
            ax.plot(hs, vs, "o-", color=f"C{k}", label=str(g))
            if pd.notna(row.get("extrapolated", np.nan)):
                ext, band = row["extrapolated"], row["gci_fine"] * abs(row["finest"])
                ax.errorbar([0], [ext], yerr=[band], fmt="s", color=f"C{k}", capsize=3)
        ax.set_xlabel(label(ds[parameter]))
        ax.set_ylabel(label(ds[m]))
        ax.set_xlim(left=-0.02)
    if metrics:
        axes[0, 0].legend(fontsize=7, title="square at 0: extrapolated +- GCI", title_fontsize=7)
    fig.tight_layout()
    return fig


STABILITY_COLORS = {"stable": "tab:green", "degraded": "tab:orange", "blown_up": "tab:red", "error": "tab:gray"}


def stability_map(ds: xr.Dataset, table: pd.DataFrame, x: str | None, y: str | None,
                  facet: str | None) -> plt.Figure:
    """Runs over two numerics axes (one panel per facet value), coloured by stability class; the defaults
    (dt_factor 1, the study's base values) are ringed."""
    axes = [a for a in swept_parameters(ds) if ds[a].dtype.kind == "f"]
    x = x or (axes[0] if axes else None)
    y = y or next((a for a in axes if a != x), None)
    facets = list(pd.unique(table[facet])) if facet and facet in table else [None]
    fig, grid = plt.subplots(1, len(facets), figsize=(4.5 * len(facets), 3.8), squeeze=False)
    for ax, fv in zip(grid[0], facets):
        sub = table if fv is None else table[table[facet] == fv]
        yv = sub[y] if y else np.zeros(len(sub))
        for cls, color in STABILITY_COLORS.items():
            part = sub["class"] == cls
            ax.scatter(sub[x][part], yv[part], c=color, s=90, label=cls, edgecolors="k")
        if x == "dt_factor":
            ax.axvline(1.0, color="0.5", ls="--", lw=1)
            ax.text(1.0, ax.get_ylim()[1], " default", va="top", fontsize=7, color="0.4")
        ax.set_xlabel(label(ds[x]))
        if y:
            ax.set_ylabel(label(ds[y]))
        ax.set_title(f"{facet} = {fv}" if fv is not None else "", fontsize=9)
        ax.legend(fontsize=7)
    fig.tight_layout()
    return fig


def speed_accuracy_plot(table: pd.DataFrame) -> plt.Figure:
    """Wall time against error (versus Table 1 and versus the reference run), Pareto fronts joined."""
    fig, axes = plt.subplots(1, 2, figsize=(11, 4.2), squeeze=False)
    for ax, (col, flag, title) in zip(axes[0], (("error_table1", "pareto_table1", "error vs Table 1"),
                                                 ("error_reference", "pareto_reference", "error vs reference run"))):
        sub = table[np.isfinite(table[col]) & np.isfinite(table["cost_s"])]
        for model, part in sub.groupby("model"):
            ax.scatter(part["cost_s"], 100 * part[col], s=50, label=model, edgecolors="k")
        front = sub[sub[flag]].sort_values("cost_s")
        ax.plot(front["cost_s"], 100 * front[col], "k--", lw=1, label="Pareto front")
        for _, r in sub.iterrows():
            ax.annotate(r["run_id"], (r["cost_s"], 100 * r[col]), fontsize=6, xytext=(3, 3),
                        textcoords="offset points")
        failed = table[table["status"] != "ok"]
        for _, r in failed.iterrows():
            if np.isfinite(r["cost_s"]):
                ax.axvline(r["cost_s"], color="tab:red", lw=0.6, ls=":")
        ax.set_xscale("log")
        ax.set_xlabel("wall time of the run, s (log)")
        ax.set_ylabel("mean |relative error| of width and height, %")
        ax.set_title(title + (" (red dotted: failed runs)" if len(failed) else ""), fontsize=9)
        ax.legend(fontsize=7)
    fig.tight_layout()
    return fig


def uncertainty_plot(table: pd.DataFrame, metrics=("bead_width_mm", "bead_height_mm")) -> plt.Figure:
    """Per mode: the 5-95 % band of the reduced model (bar), its median (dot), the nominal prediction (x) and the
    measured bead with its assumed uncertainty (black square with error bar)."""
    fig, axes = plt.subplots(1, len(metrics), figsize=(4.5 * len(metrics), 3.8), squeeze=False)
    for ax, metric in zip(axes[0], metrics):
        sub = table[table["metric"] == metric].sort_values("mode")
        x = np.arange(len(sub))
        ax.vlines(x - 0.1, sub["p05"], sub["p95"], lw=8, color="tab:blue", alpha=0.35, label="5-95 % band")
        ax.plot(x - 0.1, sub["p50"], "o", color="tab:blue", label="median")
        ax.plot(x - 0.1, sub["nominal"], "x", color="tab:orange", ms=9, label="nominal inputs")
        if "measured" in sub:
            ax.errorbar(x + 0.1, sub["measured"], yerr=sub["measured_unc"], fmt="ks", capsize=3, label="Table 1")
        ax.set_xticks(x, [f"mode {m}" for m in sub["mode"]])
        ax.set_ylabel(metric.replace("_mm", " [mm]").replace("_", " "))
    fig.tight_layout()
    # one legend, below the panels (inside them it covered a band)
    fig.legend(*axes[0][0].get_legend_handles_labels(), loc="upper center", bbox_to_anchor=(0.5, 0.0), ncol=4,
               fontsize=7, frameon=False)
    return fig
