"""Future weather (issue 12): KNMI'14 transformation against the published tables,
morphing (Belcher et al. 2005), humidity under warming."""

from __future__ import annotations

import numpy as np
import pandas as pd
import pytest

from heritage_bayes.climate.morph import (
    KNMI14_PERCENTILES,
    knmi14_region,
    knmi14_transform,
    morph,
    read_knmi14_deltas,
    read_monthly_deltas,
    transform_daily_quantiles,
)
from heritage_bayes.climate.psychro import saturation_vapour_pressure
from heritage_bayes.errors import ConfigError

COLS = [f"P{p:02d}" for p in KNMI14_PERCENTILES]


def _debilt_daily(shared_data) -> pd.Series:
    """De Bilt daily mean temperature 1981-2010 (the KNMI'14 reference period)."""
    path = shared_data / "knmi14-deltas" / "tgtg260.dat"
    df = pd.read_csv(path, sep=r"\s+", comment="#", header=None, names=["y", "m", "d", "tg"])
    idx = pd.to_datetime(dict(year=df.y, month=df.m, day=df.d)).dt.tz_localize("UTC")
    s = pd.Series(df.tg.to_numpy(float), index=pd.DatetimeIndex(idx), name="tg")
    return s["1981-01-01":"2010-12-31"]


def _hourly(seed=0, years=3, start="2001-01-01"):
    """A synthetic hourly weather table: seasonal + diurnal cycles + weather noise."""
    idx = pd.date_range(start, periods=years * 8760 + 17, freq="h", tz="UTC")
    t = np.arange(len(idx))
    rng = np.random.default_rng(seed)
    slow = np.convolve(rng.normal(0, 3, len(idx) + 96), np.ones(96) / 96 * 4, "valid")[: len(idx)]
    te = 10 - 8 * np.cos(2 * np.pi * t / 8766) + 4 * np.sin(2 * np.pi * (t % 24) / 24) + slow
    ghi = np.clip(500 * np.sin(np.pi * ((t % 24) - 6) / 12), 0, None)
    rh = np.clip(75 - 2 * (te - te.mean()), 20, 100)
    df = pd.DataFrame({"Te": te, "RHe": rh, "ghi": ghi, "dhi": 0.3 * ghi}, index=idx)
    df.attrs["site"] = {"latitude": 52.1, "longitude": 5.18}
    return df


@pytest.mark.parametrize("scenario,horizon", [("WH", 2085), ("GL", 2050), ("GH", 2030)])
def test_knmi14_daily_quantiles_reproduce_table(shared_data, scenario, horizon):
    folder = shared_data / "knmi14-deltas"
    region = knmi14_region(folder, 260)
    assert region == "MON"
    deltas = read_knmi14_deltas(folder, "tg", scenario, horizon, region)
    x = _debilt_daily(shared_data)
    y = transform_daily_quantiles(x, deltas)
    for m in range(1, 13):
        sel = x.index.month == m
        qx = np.quantile(x[sel], np.asarray(KNMI14_PERCENTILES) / 100)
        qy = np.quantile(y[sel], np.asarray(KNMI14_PERCENTILES) / 100)
        # the map is monotone and piecewise linear through (X_p, X_p + Δ_p)
        np.testing.assert_allclose(qy - qx, deltas.loc[m, COLS], atol=0.05)
        # the monthly mean change: the table's deltas interpolated between the month's
        # percentiles (held constant beyond P01/P99) averaged over its days, within 0.05 K
        implied = np.interp(x[sel], qx, deltas.loc[m, COLS].to_numpy(float)).mean()
        change = float(y[sel].mean() - x[sel].mean())
        assert change == pytest.approx(implied, abs=0.05)
        assert deltas.loc[m, COLS].min() - 1e-9 <= change <= deltas.loc[m, COLS].max() + 1e-9


def test_knmi14_uniform_table_is_a_shift():
    x = _hourly(years=2)["Te"].resample("D").mean()
    deltas = pd.DataFrame({c: np.full(12, 1.7) for c in COLS}, index=range(1, 13))
    np.testing.assert_allclose(transform_daily_quantiles(x, deltas) - x, 1.7, atol=1e-9)


def test_knmi14_hourly_follows_daily(shared_data, tmp_path):
    folder = shared_data / "knmi14-deltas"
    w = _hourly(years=3)
    fut = knmi14_transform(w, folder, "WH", 2085, region="MON")
    day = w.index.floor("D")
    d0 = w["Te"].groupby(day).mean()
    d1 = fut["Te"].groupby(day).mean()
    deltas = read_knmi14_deltas(folder, "tg", "WH", 2085, "MON")
    np.testing.assert_allclose(d1, transform_daily_quantiles(d0, deltas), atol=1e-9)
    # the diurnal cycle is kept: hourly deviations from the daily mean unchanged
    np.testing.assert_allclose(
        (fut["Te"] - d1.reindex(day).to_numpy()), (w["Te"] - d0.reindex(day).to_numpy()), atol=1e-9
    )
    # monthly mean change of the hourly series within the table's range for that month
    ch = (fut["Te"] - w["Te"]).groupby(w.index.month).mean()
    for m in range(1, 13):
        assert deltas.loc[m, COLS].min() - 0.05 <= ch[m] <= deltas.loc[m, COLS].max() + 0.05
    # radiation: the monthly mean changes by the rsds table (decreases: exactly)
    rs = read_knmi14_deltas(folder, "rsds", "WH", 2085)["ave"]
    r = fut["ghi"].groupby(w.index.month).sum() / w["ghi"].groupby(w.index.month).sum() - 1
    for m in range(1, 13):
        assert 100 * r[m] == pytest.approx(rs[m], abs=0.05), m
    # diffuse fraction kept; constant RH: Pe follows the new temperature
    np.testing.assert_allclose(fut["dhi"], 0.3 * fut["ghi"], atol=1e-9)
    np.testing.assert_allclose(fut["RHe"], w["RHe"])
    np.testing.assert_allclose(fut["Pe"], fut["RHe"] / 100 * saturation_vapour_pressure(fut["Te"]))
    assert fut.attrs["transformation"]["scenario"] == "WH"


def test_knmi14_bad_scenario_and_horizon(shared_data):
    folder = shared_data / "knmi14-deltas"
    with pytest.raises(ConfigError, match="scenario 'XX'"):
        read_knmi14_deltas(folder, "tg", "XX", 2050, "MON")
    with pytest.raises(ConfigError, match="horizon 2070"):
        read_knmi14_deltas(folder, "tg", "WH", 2070, "MON")
    with pytest.raises(ConfigError, match="region 'ABC'"):
        read_knmi14_deltas(folder, "tg", "WH", 2050, "ABC")


@pytest.mark.parametrize("method", ["shift", "shift_stretch"])
def test_morph_monthly_mean_change(method):
    w = _hourly(years=2)
    dT = np.linspace(1.0, 3.0, 12)
    deltas = read_monthly_deltas(
        {
            "Te": list(dT),
            "Te_max": list(dT + 0.5),
            "Te_min": list(dT - 0.5),
            "ghi": [-5.0] * 12,
        }
    )
    fut = morph(w, deltas, method=method)
    ch = (fut["Te"] - w["Te"]).groupby(w.index.month).mean()
    np.testing.assert_allclose(ch.to_numpy(), dT, atol=1e-9)
    np.testing.assert_allclose(fut["ghi"], 0.95 * w["ghi"])
    if method == "shift_stretch":  # the daily range widens by ΔTmax − ΔTmin = 1 K
        day = w.index.floor("D")
        rng0 = w["Te"].groupby(day).agg(lambda s: s.max() - s.min())
        rng1 = fut["Te"].groupby(day).agg(lambda s: s.max() - s.min())
        by_m = (rng1 - rng0).groupby(rng0.index.month).mean()
        np.testing.assert_allclose(by_m.to_numpy(), 1.0, atol=1e-6)


def test_morph_humidity_modes():
    w = _hourly(years=1)
    d = read_monthly_deltas({"Te": [2.0] * 12, "RHe": [-3.0] * 12})
    rh = morph(w, d, method="shift", humidity="constant_rh")
    np.testing.assert_allclose(rh["RHe"], w["RHe"])
    pe0 = w["RHe"] / 100 * saturation_vapour_pressure(w["Te"])
    cv = morph(w, d, method="shift", humidity="constant_vapour_pressure")
    np.testing.assert_allclose(cv["Pe"], pe0)
    assert (cv["RHe"] < w["RHe"]).all()
    tb = morph(w, d, method="shift", humidity="table")
    np.testing.assert_allclose(tb["RHe"], np.clip(w["RHe"] - 3, 0, 100))
    # cooling below the old dew point: RH capped at saturation
    cold = morph(
        w.assign(RHe=100.0),
        read_monthly_deltas({"Te": [-2.0] * 12}),
        method="shift",
        humidity="constant_vapour_pressure",
    )
    assert cold["RHe"].max() <= 100.0


def test_morph_bad_tables():
    with pytest.raises(ConfigError, match=r"deltas.Te: expected 12"):
        read_monthly_deltas({"Te": [1, 2]})
    with pytest.raises(ConfigError, match=r"deltas\.wind: unknown column"):
        read_monthly_deltas({"Te": [1] * 12, "wind": [0] * 12})
    with pytest.raises(ConfigError, match="Te_max and Te_min"):
        morph(_hourly(years=1), read_monthly_deltas({"Te": [1] * 12}), method="shift_stretch")
