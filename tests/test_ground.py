"""A ground that follows the season: the annual cycle fitted to the outdoor air, carried
into the soil (Kusuda-Achenbach), and the default ground input it makes."""

from __future__ import annotations

import itertools

import numpy as np
import pandas as pd
import pytest

from _io_helpers import knmi_2011_2020
from heritage_bayes.climate.ground import (
    GROUND_DEPTH,
    SOIL_DIFFUSIVITY,
    YEAR_DAYS,
    damping,
    fit_annual_cycle,
    kusuda_achenbach,
)
from heritage_bayes.config import Data, GroundTemperature, parse_config
from heritage_bayes.errors import ConfigError, DataError, InputError
from heritage_bayes.inputs import ground_input, seasonal_ground_temperature

DAY_NS = 86_400 * 10**9


def _days(idx: pd.DatetimeIndex) -> np.ndarray:
    return idx.as_unit("ns").asi8 / DAY_NS


def _hourly_cycle(start, days, mean=10.0, amplitude=8.0, coldest="2021-01-20", noise=0.0):
    """Hourly air temperature: an annual cosine (minimum at ``coldest``) + a daily swing."""
    idx = pd.date_range(start, periods=24 * days, freq="1h", tz="UTC")
    t0 = pd.Timestamp(coldest, tz="UTC").value / DAY_NS
    w = 2 * np.pi / YEAR_DAYS
    rng = np.random.default_rng(3)
    daily = np.repeat(rng.normal(0.0, noise, days), 24)
    te = mean - amplitude * np.cos(w * (_days(idx) - t0)) + 3 * np.sin(2 * np.pi * idx.hour / 24)
    return pd.Series(te + daily, index=idx)


def test_kusuda_hand_computed_damping_and_lag():
    # d = sqrt(2 alpha / omega) = sqrt(2 * 0.5e-6 m²/s * 86400 s/d * 365.2425 d / 2pi)
    d = np.sqrt(2 * 0.5e-6 * 86_400 * 365.2425 / (2 * np.pi))
    assert d == pytest.approx(2.2411, abs=1e-4)
    t0 = pd.Timestamp("2021-01-20", tz="UTC").value / DAY_NS
    times = pd.date_range("2021-01-01", "2022-12-31", freq="1h", tz="UTC")
    for depth, ratio, lag in ((1.0, 0.6401, 25.94), (2.0, 0.4097, 51.88)):
        tz = kusuda_achenbach(times, 10.0, 8.0, t0, depth=depth)
        assert (tz.max() - tz.min()) / 2 == pytest.approx(8.0 * ratio, abs=1e-3)
        coldest = _days(times)[np.argmin(tz[: 24 * 365])]
        assert coldest - t0 == pytest.approx(lag, abs=0.05)
        assert tz.mean() == pytest.approx(10.0, abs=0.02)
    assert GROUND_DEPTH == 1.0 and SOIL_DIFFUSIVITY == 0.5e-6
    assert damping(1.0) == pytest.approx((0.6401, 25.94), abs=1e-2)
    assert damping(1.0, diffusivity=2e-6) == pytest.approx(damping(0.5), abs=1e-9)  # z/sqrt(α)
    with pytest.raises(InputError, match="depth"):
        kusuda_achenbach(times, 10.0, 8.0, t0, depth=-1.0)
    with pytest.raises(InputError, match="tz-aware"):
        kusuda_achenbach(times.tz_localize(None), 10.0, 8.0, t0)


def test_damping_and_lag_grow_with_depth_and_z0_is_the_fitted_surface_sinusoid():
    te = _hourly_cycle("2021-01-01 00:00", 730, noise=1.5)  # whole UTC days
    c = fit_annual_cycle(te)
    times = pd.date_range("2021-01-01", periods=365, freq="1D", tz="UTC")
    # at z = 0 the fitted least-squares sinusoid itself
    w, t = 2 * np.pi / YEAR_DAYS, _days(times)
    x = np.column_stack([np.ones_like(t), np.cos(w * t), np.sin(w * t)])
    daily = te.resample("1D").mean()
    td = _days(daily.index) + 0.5
    xd = np.column_stack([np.ones_like(td), np.cos(w * td), np.sin(w * td)])
    coef, *_ = np.linalg.lstsq(xd, daily.to_numpy(), rcond=None)
    surface = kusuda_achenbach(times, c["mean"], c["amplitude"], c["t_min"], depth=0.0)
    np.testing.assert_allclose(surface, x @ coef, atol=1e-9)
    swings, coldest = [], []
    for z in (0.0, 0.5, 1.0, 2.0, 4.0):
        tz = kusuda_achenbach(times, c["mean"], c["amplitude"], c["t_min"], depth=z)
        swings.append(tz.max() - tz.min())
        coldest.append(int(np.argmin(tz)))
    assert all(a > b for a, b in itertools.pairwise(swings))
    assert all(a < b for a, b in itertools.pairwise(coldest))


def test_fit_on_nine_months_recovers_the_cycle():
    te = _hourly_cycle("2021-03-01 01:00", 270, noise=1.5)  # March to November
    c = fit_annual_cycle(te)
    assert c["mean"] == pytest.approx(10.0, abs=0.4)
    assert c["amplitude"] == pytest.approx(8.0, abs=0.4)
    assert abs(c["coldest_day"] - 20) <= 5 and c["days"] == 270
    assert 1.0 < c["rmse"] < 2.0
    with pytest.raises(DataError, match="span 99 days"):
        fit_annual_cycle(te.iloc[: 24 * 100])


def test_seasonal_ground_input_and_its_fallback():
    te = _hourly_cycle("2021-01-01 01:00", 365)
    times = pd.date_range("2021-01-01", periods=365 * 24, freq="1h", tz="UTC")
    values, info = ground_input("seasonal", te, times)
    assert info["mode"] == "seasonal" and info["depth"] == 1.0
    assert info["amplitude_ratio"] == pytest.approx(0.640, abs=1e-3)
    assert info["lag_days"] == pytest.approx(25.9, abs=0.05)
    assert info["amplitude"] == pytest.approx(8.0, abs=0.05) and info["coldest_day"] == 20
    assert (values.max() - values.min()) / 2 == pytest.approx(8.0 * 0.640, abs=0.05)
    deep, info2 = seasonal_ground_temperature(te, times, depth=3.0)
    assert deep.max() - deep.min() < values.max() - values.min()
    assert "at 3 m" in info2["method"]
    # 60 days: no cycle to fit; the annual mean, said so
    flat, info3 = seasonal_ground_temperature(te.iloc[: 24 * 60], times)
    assert np.ptp(flat) == 0 and "no seasonal cycle: Te spans 60 days" in info3["method"]
    annual, info4 = ground_input("annual_mean", te, times)
    assert info4["mode"] == "annual_mean" and np.ptp(annual) == 0


@pytest.mark.shared_data
def test_de_bilt_nine_months_give_the_years_cycle(shared_data):
    te = knmi_2011_2020(shared_data)["Te"]
    year = fit_annual_cycle(te.loc["2015"])
    nine = fit_annual_cycle(te.loc["2015-03":"2015-11"])
    assert 9.5 < year["mean"] < 11.5 and 6.0 < year["amplitude"] < 9.0
    assert 1 <= year["coldest_day"] <= 45 or year["coldest_day"] >= 350
    assert nine["mean"] == pytest.approx(year["mean"], abs=1.0)
    assert nine["amplitude"] == pytest.approx(year["amplitude"], abs=1.5)


def _data(**gt):
    return {
        "weather": {"format": "knmi", "path": "w.txt"},
        "measurements": {"format": "csv", "path": "m.csv", "time_column": "t"},
        "ground_temperature": gt,
    }


def test_config_defaults_and_depth():
    assert GroundTemperature().mode == "seasonal" and GroundTemperature().depth is None
    assert Data(**_data()).ground_temperature.mode == "seasonal"
    assert Data(**_data(mode="seasonal", depth=2.5)).ground_temperature.depth == 2.5
    # the demo keeps its generator's annual mean unless asked otherwise
    assert Data(demo={}).ground_temperature.mode == "annual_mean"
    assert Data(demo={}, ground_temperature={"mode": "seasonal"}).ground_temperature.mode == (
        "seasonal"
    )
    raw = {"data": {"demo": {}, "ground_temperature": {"mode": "constant", "value": 9, "depth": 1}}}
    raw["thermal"] = {"model": "thermal_2c"}
    with pytest.raises(ConfigError, match="depth: only for mode 'seasonal'"):
        parse_config(raw)
