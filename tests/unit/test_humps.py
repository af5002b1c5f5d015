"""The pool state a bead's sections follow (beadsim.sph.humps), on synthetic series written as a run's
timeseries.nc."""

import numpy as np
import pytest
import xarray as xr

from beadsim.sph import humps

PERIOD, DELAY = 2.0, 0.55  # s: the sections repeat the melt count 0.55 s later
LEAD = 0.3  # s: the beam's share on the solid wire runs this much ahead of the melt count


def _series(tmp_path):
    """A run folder whose series has a melt count swelling and draining with a 2 s period, the pool front in
    anti-phase, a constant wire tip, and a section every 0.05 s whose mass balance follows the melt count
    DELAY seconds later."""
    t = np.round(np.arange(0.0, 8.0, 0.01), 6)
    swell = np.sin(2 * np.pi * t / PERIOD)
    mb = np.full_like(t, np.nan)
    sections = np.isclose(t / 0.05, np.round(t / 0.05))
    mb[sections] = 1 + 0.5 * np.sin(2 * np.pi * (t[sections] - DELAY) / PERIOD)
    # absorbed beam 500 W; the solid wire's share 0.02 + 0.01 sin(2 pi (t + LEAD) / PERIOD), booked as running
    # sums (the ledger's): its integral
    e_wire = 500 * (0.02 * t - 0.01 * PERIOD / (2 * np.pi) * np.cos(2 * np.pi * (t + LEAD) / PERIOD))
    ds = xr.Dataset({"t": ("time", t), "n_liquid": ("time", 300 + 40 * swell),
                     "pool_x_max": ("time", 2e-3 - 0.5e-3 * swell), "wire_tip_s": ("time", np.full_like(t, 1e-3)),
                     "E_beam": ("time", 500 * t), "E_beam_solid_wire": ("time", e_wire),
                     "mass_balance_ratio": ("time", mb)}, coords={"time": t})
    ds.to_netcdf(tmp_path / "timeseries.nc")
    return tmp_path


def test_the_lag_at_which_sections_follow_the_pool_is_found(tmp_path):
    """The mean over the 0.5 s ending L before a section is centred 0.25 s earlier still: the sections follow
    the melt count at L = DELAY - 0.25 = 0.3 s (correlation 1), the front in anti-phase (-1), half a period
    off the other way; a constant quantity correlates with nothing."""
    series = humps.read_series(_series(tmp_path))
    table = humps.lag_table(series, t_from=1.5)
    assert table["melt count"].idxmax() == pytest.approx(DELAY - 0.25)
    assert table.loc[0.3, "melt count"] > 0.999
    assert table.loc[0.3, "pool front (mm)"] < -0.999
    assert abs(table.loc[0.3 + 0.5, "melt count"]) < 0.1  # a quarter period off (3.2 periods of sections)
    assert table["wire tip (mm)"].isna().all()
    assert "pool width (mm)" not in table  # not in this series


def test_the_beam_share_on_the_wire_comes_from_the_running_sums_and_leads(tmp_path):
    """The share per sample interval is the running sum's increment over the beam's: the interval's mean of
    0.02 + 0.01 sin(...); a share running LEAD ahead of the melt count peaks LEAD further back, and the
    summary lists it before the melt count."""
    series = humps.read_series(_series(tmp_path))
    t = series.index.values
    share = series["beam_share_solid_wire"].values
    assert np.isnan(share[0])
    mid = 0.5 * (t[1:] + t[:-1])  # the mean over an interval of 0.01 s is the midpoint value to 2e-6
    assert share[1:] == pytest.approx(0.02 + 0.01 * np.sin(2 * np.pi * (mid + LEAD) / PERIOD), abs=1e-5)
    table = humps.lag_table(series, t_from=1.5)
    assert table["beam on solid wire"].idxmax() == pytest.approx(DELAY - 0.25 + LEAD)
    top = humps.strongest(table).sort_values("lag (s)", ascending=False)
    assert top.loc["beam on solid wire", "r"] > 0.999
    assert top.index[0] == "beam on solid wire"
    assert top.loc["melt count", "lag (s)"] == pytest.approx(DELAY - 0.25)
    assert np.isnan(top.loc["wire tip (mm)", "lag (s)"])


def test_lead_correlation_leaves_out_sections_without_history():
    """Sections whose window lies before the first sample are left out; fewer than three left give NaN."""
    t = np.round(0.1 * np.arange(3, 10), 10)  # samples from 0.3 s
    r = humps.lead_correlation(t, t, np.array([0.05, 0.5, 0.7, 0.9]), np.array([9.0, 1.0, 2.0, 3.5]),
                               lags=[0.0, 0.5], window=0.2)
    assert r[0] == pytest.approx(np.corrcoef([0.35, 0.55, 0.75], [1.0, 2.0, 3.5])[0, 1])  # 0.05 s left out
    assert np.isnan(r[1])  # only the 0.9 s section has samples 0.5 s back


def test_the_span_table_and_the_command_line(tmp_path, capsys):
    run = _series(tmp_path)
    spans = humps.span_table(humps.read_series(run), t_from=3.0, span=1.0)
    # sections over [3, 4): 1 + 0.5 sin(pi (t - 0.55)) from t = 3.00 to 3.95: its crest 1.5 at 3.05, its lowest
    # at 3.95; the melt count 300 + 40 sin(pi t) averages 300 - 80 / pi over that half period
    assert spans.loc[3.0, "mass balance max"] == pytest.approx(1.5)
    assert spans.loc[3.0, "mass balance min"] == pytest.approx(1 + 0.5 * np.sin(np.pi * 3.4))
    assert spans.loc[3.0, "melt count"] == pytest.approx(300 - 80 / np.pi, abs=0.2)
    assert list(spans.index) == pytest.approx([3.0, 4.0, 5.0, 6.0, 7.0])
    humps.main([str(run), "--from", "1.5"])
    out = capsys.readouterr().out
    assert "melt count" in out and "mass balance max" in out


def test_a_run_without_sections_is_refused_by_name(tmp_path):
    """A series with no finite section mass balance (not a window run, or stopped before the bead formed), or
    no series at all, is an error naming the file, not an empty table."""
    t = np.arange(0.0, 1.0, 0.01)
    xr.Dataset({"t": ("time", t), "n_liquid": ("time", np.ones_like(t)),
                "mass_balance_ratio": ("time", np.full_like(t, np.nan))}, coords={"time": t}).to_netcdf(
        tmp_path / "timeseries.nc")
    with pytest.raises(SystemExit, match="no bead cross-sections.*domain: window"):
        humps.main([str(tmp_path)])
    with pytest.raises(SystemExit, match="no time series"):
        humps.main([str(tmp_path / "elsewhere")])
