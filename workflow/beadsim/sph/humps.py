"""What the bead's cross-sections follow: the pool's state some time before each section, from a run's series.

A window run measures a cross-section of the frozen bead every 0.05 s a fixed distance behind the beam, so a
section shows metal the pool laid down some time earlier. Where a bead humps (mode 1: period 1.1-2.2 s) the
question is what the pool and the wire were doing then. For each quantity of the series (the melt count
``n_liquid``, the pool's front ``pool_x_max`` ahead of the beam centre and its width, the solid wire tip
``wire_tip_s`` along its axis and the wire's lowest particle ``wire_z_min``, and the shares of the absorbed beam
power landing on solid wire and on melt from the wire, from the ledger's running sums) this correlates its mean
over the ``window`` seconds ending ``lag`` seconds before each section with that section's mass balance, for a
range of lags: a large correlation at one lag says the sections follow that quantity that much later (README,
"The wire tip, the drip cycle and the humps"); the lags order the quantities in time. It also tabulates the
quantities and the sections' mass balance span by span.

    python -m beadsim.sph.humps results/<study>/runs/<run_id> [--from 1.5] [--window 0.5] [--span 0.5]
"""

from __future__ import annotations

import argparse
from pathlib import Path

import numpy as np
import pandas as pd

#: Pool and wire quantities of the time series read (name in timeseries.nc: label, scale to the label's unit)
QUANTITIES = {"n_liquid": ("melt count", 1.0), "pool_x_max": ("pool front (mm)", 1e3),
              "pool_width_mm": ("pool width (mm)", 1.0), "wire_tip_s": ("wire tip (mm)", 1e3),
              "wire_z_min": ("wire low point (mm)", 1e3)}
#: Shares of the absorbed beam power, per sample interval, from the ledger's running sums (share name: the
#: running sum whose increments are divided by those of ``E_beam``, label)
BEAM_SHARES = {"beam_share_solid_wire": ("E_beam_solid_wire", "beam on solid wire"),
               "beam_share_wire_melt": ("E_beam_wire_melt", "beam on wire's melt")}
LAGS = tuple(np.round(np.arange(0.0, 1.01, 0.1), 2))


def lead_correlation(t: np.ndarray, x: np.ndarray, t_sections: np.ndarray, y: np.ndarray,
                     lags=LAGS, window: float = 0.5) -> np.ndarray:
    """Pearson correlation, for each lag L (s), between the mean of ``x`` (sampled at ``t``) over
    [t_s - L - window, t_s - L) and ``y`` at each section time t_s. Sections whose window holds no sample are
    left out; NaN where fewer than three sections remain or either side is constant."""
    t, x = np.asarray(t, float), np.asarray(x, float)
    t, x = t[np.isfinite(x)], x[np.isfinite(x)]
    out = []
    for lag in lags:
        lead, keep = [], []
        for ts, ys in zip(t_sections, y):
            s = (t >= ts - lag - window) & (t < ts - lag)
            if s.any() and np.isfinite(ys):
                lead.append(x[s].mean())
                keep.append(ys)
        ok = len(keep) >= 3 and np.std(lead) > 0 and np.std(keep) > 0
        out.append(float(np.corrcoef(lead, keep)[0, 1]) if ok else np.nan)
    return np.array(out)


def read_series(run_dir: str | Path) -> pd.DataFrame:
    """The run's time series (index: process time, s) with the pool quantities and the sections' mass balance
    (NaN between sections)."""
    import xarray as xr

    path = Path(run_dir) / "timeseries.nc"
    if not path.exists():
        raise FileNotFoundError(f"{path}: no time series (not an SPH run folder, or the run has not started)")
    with xr.open_dataset(path) as ds:
        if "mass_balance_ratio" not in ds or not np.isfinite(ds["mass_balance_ratio"].values).any():
            raise ValueError(f"{path}: no bead cross-sections in the series; they are taken in moving-window runs "
                             "(domain: window) once the bead has formed")
        cols = {c: ds[c].values for c in (*QUANTITIES, "mass_balance_ratio") if c in ds}
        if "E_beam" in ds:
            d_beam = np.diff(ds["E_beam"].values, prepend=np.nan)
            with np.errstate(divide="ignore", invalid="ignore"):
                for share, (running, _) in BEAM_SHARES.items():
                    if running in ds:
                        cols[share] = np.where(d_beam > 0, np.diff(ds[running].values, prepend=np.nan) / d_beam,
                                               np.nan)
        return pd.DataFrame(cols, index=pd.Index(ds["t"].values, name="t"))


def _quantities() -> dict:
    """Every quantity the tables read: name in :func:`read_series`'s frame: (label, scale)."""
    return {**QUANTITIES, **{share: (label, 1.0) for share, (_, label) in BEAM_SHARES.items()}}


def lag_table(series: pd.DataFrame, t_from: float, lags=LAGS, window: float = 0.5) -> pd.DataFrame:
    """Rows: lag (s); columns: each pool quantity's :func:`lead_correlation` with the mass balance of the
    sections at or after ``t_from``."""
    t = series.index.values
    sec = series["mass_balance_ratio"].dropna()
    sec = sec[sec.index >= t_from]
    cols = {label: lead_correlation(t, series[name].values * scale, sec.index.values, sec.values, lags, window)
            for name, (label, scale) in _quantities().items() if name in series}
    return pd.DataFrame(cols, index=pd.Index(lags, name="lag (s)"))


def strongest(table: pd.DataFrame) -> pd.DataFrame:
    """Per column of :func:`lag_table`: the lag (s) of the largest correlation in size, and that correlation
    (NaN for a column without any)."""
    rows = {}
    for col in table:
        r = table[col].dropna()
        lag = r.abs().idxmax() if len(r) else np.nan
        rows[col] = {"lag (s)": lag, "r": r[lag] if len(r) else np.nan}
    return pd.DataFrame(rows).T


def span_table(series: pd.DataFrame, t_from: float, span: float = 0.5) -> pd.DataFrame:
    """Per ``span`` seconds since ``t_from``: each pool quantity's mean and the sections' mass balance range."""
    rows = []
    t = series.index.values
    for a in np.arange(t_from, t[-1], span):
        s = (t >= a) & (t < a + span)
        row = {"from (s)": a}
        for name, (label, scale) in _quantities().items():
            if name in series:
                v = series[name].values[s]
                v = v[np.isfinite(v)]
                row[label] = float(v.mean()) * scale if len(v) else np.nan
        mb = series["mass_balance_ratio"].values[s]
        mb = mb[np.isfinite(mb)]
        row["mass balance min"] = mb.min() if len(mb) else np.nan
        row["mass balance max"] = mb.max() if len(mb) else np.nan
        rows.append(row)
    return pd.DataFrame(rows).set_index("from (s)")


def main(argv=None) -> None:
    ap = argparse.ArgumentParser(prog="python -m beadsim.sph.humps", description=__doc__.split("\n\n")[0])
    ap.add_argument("run_dir")
    ap.add_argument("--from", dest="t_from", type=float, default=1.5,
                    help="leave out the sections (and spans) before this time (s): the start-up")
    ap.add_argument("--window", type=float, default=0.5, help="seconds of pool state averaged before each lag")
    ap.add_argument("--span", type=float, default=0.5, help="seconds per row of the span table")
    args = ap.parse_args(argv)
    try:
        series = read_series(args.run_dir)
    except (FileNotFoundError, ValueError) as err:
        raise SystemExit(f"error: {err}") from None
    with pd.option_context("display.width", 160, "display.max_columns", None, "display.max_rows", 200,
                           "display.float_format", "{:.2f}".format):
        print(f"correlation of each quantity's mean over the {args.window} s ending <lag> before a section with "
              f"that section's mass balance (sections since {args.t_from} s)")
        table = lag_table(series, args.t_from, window=args.window)
        print(table)
        print()
        print("the lag at which each quantity's correlation is largest in size (the earliest lead comes first)")
        print(strongest(table).sort_values("lag (s)", ascending=False))
        print()
        print(span_table(series, args.t_from, args.span))


if __name__ == "__main__":
    main()
