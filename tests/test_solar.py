"""Solar irradiance on surfaces: physical sense on real weather, timing, options, errors."""

from __future__ import annotations

import numpy as np
import pandas as pd
import pvlib
import pytest

from _io_helpers import DE_BILT, knmi_2011_2020, pvlib_tmy3_path
from heritage_bayes.climate import DEFAULT_SURFACES, clear_sky_weather, surface_irradiance
from heritage_bayes.climate.solar import (
    extraterrestrial_radiation_daily,
    hargreaves_samani,
    temperature_range_weather,
)
from heritage_bayes.errors import DataError, InputError
from heritage_bayes.io import read_tmy3

SURFACES = {**DEFAULT_SURFACES, "flat": (0, 0), "roof_S": (35, 180), "roof_N": (35, 0)}


@pytest.fixture(scope="module")
def knmi_2015(shared_data):
    return knmi_2011_2020(shared_data).loc["2015"]


@pytest.fixture(scope="module")
def debilt(knmi_2015):
    return surface_irradiance(knmi_2015, DE_BILT, SURFACES)


@pytest.fixture(scope="module")
def tmy3():
    return read_tmy3(pvlib_tmy3_path())


def _night(index, site):
    """Stamps whose whole (hour-ending) interval has the sun well below the horizon."""
    interval = pd.Timedelta("1h")
    lat, lon = site["latitude"], site["longitude"]
    end = pvlib.solarposition.get_solarposition(index, lat, lon)["elevation"]
    begin = pvlib.solarposition.get_solarposition(index - interval, lat, lon)["elevation"]
    return (end.to_numpy() < -2) & (begin.to_numpy() < -2)


@pytest.mark.shared_data
def test_default_surfaces_are_the_four_facades(knmi_2015):
    out = surface_irradiance(knmi_2015.iloc[:48], DE_BILT)
    assert list(out.columns) == ["N", "E", "S", "W"]
    assert out.index.equals(knmi_2015.index[:48])
    assert out.attrs["units"] == dict.fromkeys("NESW", "W/m²")
    assert out.attrs["averaged"] == ("N", "E", "S", "W") and out.attrs["interval"] == "1h"
    assert out.attrs["irradiance_source"] == "measured; dni/dhi from ghi by Erbs"


@pytest.mark.shared_data
def test_annual_sums_physically_sensible(debilt, knmi_2015):
    kwh = debilt.sum() / 1000
    assert kwh["S"] > kwh["E"] > kwh["N"] and kwh["S"] > kwh["W"] > kwh["N"]
    assert 250 < kwh["N"] < 450 and 750 < kwh["S"] < 1000  # De Bilt facades, kWh/m²/yr
    assert kwh["E"] == pytest.approx(kwh["W"], rel=0.1)
    # a horizontal roof sees the global horizontal irradiance
    assert kwh["flat"] == pytest.approx(knmi_2015["ghi"].sum() / 1000, rel=0.02)
    # a 35° south roof beats both the flat roof and the south facade; north roof the least
    assert kwh["roof_S"] > kwh["flat"] > kwh["roof_N"] > kwh["N"]
    assert kwh["roof_S"] > kwh["S"]
    # summer: the flat roof beats the south facade (high sun); winter: the reverse
    summer = debilt.loc["2015-06"].sum()
    winter = debilt.loc["2015-12"].sum()
    assert summer["flat"] > summer["S"] and winter["S"] > winter["flat"]


@pytest.mark.shared_data
def test_zero_at_night_and_never_negative(debilt):
    assert (debilt >= 0).all().all() and not debilt.isna().any().any()
    night = _night(debilt.index, DE_BILT)
    assert night.sum() > 3000
    assert (debilt[night] == 0).all().all()


@pytest.mark.shared_data
def test_nan_ghi_propagates(knmi_2015):
    w = knmi_2015.iloc[:24].copy()
    w.iloc[12, w.columns.get_loc("ghi")] = np.nan
    out = surface_irradiance(w, DE_BILT)
    assert out.iloc[12].isna().all() and not out.drop(index=out.index[12]).isna().any().any()


@pytest.mark.shared_data
def test_dirint_and_isotropic_agree_roughly(knmi_2015, debilt):
    other = surface_irradiance(knmi_2015, DE_BILT, {"S": (90, 180), "N": (90, 0)},
                               decomposition="dirint", model="isotropic")  # fmt: skip
    ratio = other.sum() / debilt[["S", "N"]].sum()
    assert ratio["S"] == pytest.approx(1.0, abs=0.1)
    assert ratio["N"] == pytest.approx(1.0, abs=0.25)
    assert "DIRINT" in other.attrs["irradiance_source"]


def test_tmy3_with_all_components(tmy3):
    site = tmy3.attrs["site"]
    out = surface_irradiance(tmy3, site, SURFACES)
    kwh = out.sum() / 1000
    assert kwh["S"] > kwh["N"] and kwh["roof_S"] > kwh["S"]
    assert kwh["flat"] == pytest.approx(tmy3["ghi"].sum() / 1000, rel=0.02)
    assert out.attrs["irradiance_source"] == "measured"
    assert (out[_night(out.index, site)] == 0).all().all()


def test_closure_from_ghi_and_dhi(tmy3):
    site = tmy3.attrs["site"]
    full = surface_irradiance(tmy3, site, {"S": (90, 180)}, model="isotropic")
    closure = surface_irradiance(tmy3.drop(columns="dni"), site, {"S": (90, 180)},
                                 model="isotropic")  # fmt: skip
    assert closure.attrs["irradiance_source"] == "measured; dni from ghi and dhi by closure"
    assert closure["S"].sum() == pytest.approx(full["S"].sum(), rel=0.05)
    only_dni = surface_irradiance(tmy3.drop(columns="dhi"), site, {"S": (90, 180)})
    assert "dhi from ghi and dni" in only_dni.attrs["irradiance_source"]


def test_sun_at_mid_interval_makes_east_and_west_symmetric():
    """Clear-sky, end-stamped hourly averages: E and W facades get the same annual sum
    only if the sun is placed at the middle of each interval."""
    site = {"latitude": 45.0, "longitude": 0.0, "altitude": 0.0}
    idx = pd.date_range("2019-01-01 01:00", "2020-01-01 00:00", freq="h", tz="UTC")
    weather = clear_sky_weather(idx, site)
    right = surface_irradiance(weather, site, {"E": (90, 90), "W": (90, 270)})
    assert right["E"].sum() == pytest.approx(right["W"].sum(), rel=0.01)
    wrong = surface_irradiance(weather, site, {"E": (90, 90), "W": (90, 270)}, averaged=False)
    assert wrong["W"].sum() > 1.05 * wrong["E"].sum()


def test_clear_sky_proxy_is_labelled_and_sensible():
    idx = pd.date_range("2019-06-21 01:00", periods=48, freq="h", tz="UTC")
    cs = clear_sky_weather(idx, DE_BILT)
    assert list(cs.columns) == ["ghi", "dni", "dhi"] and (cs >= 0).all().all()
    assert cs.attrs["irradiance_source"].startswith("clear-sky proxy (pvlib Ineichen")
    assert cs.attrs["averaged"] == ("ghi", "dni", "dhi") and cs.attrs["interval"] == "1h"
    assert 800 < cs["ghi"].max() < 1000  # De Bilt, midsummer noon
    te = pd.DataFrame({"Te": 15.0}, index=idx)
    out = surface_irradiance(te, DE_BILT, clear_sky=True)
    assert out.attrs["irradiance_source"].startswith("clear-sky proxy")
    assert out["S"].max() > 0 and (out.iloc[:2] == 0).all().all()  # 01:00, 02:00 UTC


def test_errors_and_options():
    idx = pd.date_range("2019-06-21 01:00", periods=4, freq="h", tz="UTC")
    w = pd.DataFrame({"Te": 15.0, "ghi": 100.0}, index=idx)
    with pytest.raises(DataError, match=r"no 'ghi' column .*clear_sky=True"):
        surface_irradiance(w[["Te"]], DE_BILT)
    with pytest.raises(InputError, match="already has irradiance"):
        surface_irradiance(w, DE_BILT, clear_sky=True)
    with pytest.raises(InputError, match=r"site: unknown key\(s\) \['lat'\]"):
        surface_irradiance(w, {"lat": 52, "longitude": 5})
    with pytest.raises(InputError, match="site: missing"):
        surface_irradiance(w, {"longitude": 5})
    with pytest.raises(InputError, match="latitude must be in"):
        surface_irradiance(w, {"latitude": 152, "longitude": 5})
    with pytest.raises(InputError, match=r"surfaces\['S'\] must be a pair"):
        surface_irradiance(w, DE_BILT, {"S": 180})
    with pytest.raises(InputError, match="tilt must be in"):
        surface_irradiance(w, DE_BILT, {"S": (190, 180)})
    with pytest.raises(InputError, match="model must be one of"):
        surface_irradiance(w, DE_BILT, model="hay")
    with pytest.raises(InputError, match="decomposition must be one of"):
        surface_irradiance(w, DE_BILT, decomposition="disc")
    with pytest.raises(InputError, match="albedo"):
        surface_irradiance(w, DE_BILT, albedo=2)
    with pytest.raises(DataError, match="tz-aware"):
        surface_irradiance(w.tz_localize(None), DE_BILT)
    with pytest.raises(TypeError):
        surface_irradiance(w, DE_BILT, tilt=90)
    out = surface_irradiance(w, {**DE_BILT, "name": "De Bilt"}, {"roof": (30, 200)})
    assert list(out.columns) == ["roof"]


# ---------------------------------------------------------------------------------------
# global radiation from the daily temperature range (no pyranometer)
# ---------------------------------------------------------------------------------------


def test_extraterrestrial_radiation_and_hargreaves_fao56_examples():
    # FAO-56 example 8: 20° S, 3 September (J = 246): Ra = 32.2 MJ/m²/d
    assert extraterrestrial_radiation_daily(246, -20.0) == pytest.approx(32.2, abs=0.05)
    # FAO-56's Lyon example (45°43' N, July; Annex 2 table 2.6 for mid-July): Ra = 40.6,
    # Tmax 26.6, Tmin 14.8 °C -> Rs = 0.16 * sqrt(11.8) * 40.6 = 22.3 MJ/m²/d
    assert extraterrestrial_radiation_daily(196, 45 + 43 / 60) == pytest.approx(40.6, abs=0.1)
    assert hargreaves_samani(26.6, 14.8, 40.6) == pytest.approx(22.3, abs=0.05)
    assert hargreaves_samani(26.6, 14.8, 40.6, krs=0.19) == pytest.approx(26.5, abs=0.05)
    # polar night: no sun; midnight sun: more than at the equator on that day
    assert extraterrestrial_radiation_daily(355, 80.0) == 0.0
    assert extraterrestrial_radiation_daily(172, 80.0) > extraterrestrial_radiation_daily(172, 0)
    with pytest.raises(InputError, match="tmax must not be below tmin"):
        hargreaves_samani(10.0, 12.0, 30.0)
    with pytest.raises(InputError, match="krs"):
        hargreaves_samani(20.0, 12.0, 30.0, krs=1.5)
    with pytest.raises(InputError, match="day_of_year"):
        extraterrestrial_radiation_daily(0, 50.0)


def _daily_swing(days: int, swing: np.ndarray, start="2021-03-01 01:00") -> pd.Series:
    """Hourly Te (stamps at the hour's end, UTC) whose hourly values span ``swing[d]`` K
    on day d (minimum at 03:00, maximum at 15:00 UTC)."""
    idx = pd.date_range(start, periods=24 * days, freq="1h", tz="UTC")
    half = np.repeat(np.asarray(swing, dtype=float) / 2, 24)
    return pd.Series(8.0 - half * np.cos(2 * np.pi * (idx.hour - 3) / 24), index=idx)


def test_estimate_is_each_days_hargreaves_total_shaped_by_the_cloudless_sky():
    site = {"latitude": 52.0, "longitude": 0.0}
    swing = np.array([4.0, 9.0, 1.0, 60.0])  # the last: more than a cloudless day allows
    te = _daily_swing(4, swing)
    est = temperature_range_weather(te, site)
    cs = clear_sky_weather(te.index, site, interval="1h")["ghi"]
    daily = est["ghi"].groupby((est.index - pd.Timedelta("30min")).floor("D")).sum() * 3600 / 1e6
    ra = extraterrestrial_radiation_daily(np.arange(60, 64), 52.0)  # 1-4 March 2021
    expected = 0.16 * np.sqrt(swing[:3]) * ra[:3]
    np.testing.assert_allclose(daily.to_numpy()[:3], expected, rtol=1e-9)
    # the shape of the day is the cloudless sky's; capped at it every hour
    day1 = slice(24, 48)
    np.testing.assert_allclose(
        est["ghi"].iloc[day1], cs.iloc[day1] * est["ghi"].iloc[36] / cs.iloc[36]
    )
    assert (est["ghi"] <= cs + 1e-9).all()
    np.testing.assert_allclose(est["ghi"].iloc[72:], cs.iloc[72:])
    assert est.attrs["averaged"] == ("ghi",) and est.attrs["interval"] == "1h"
    assert "Hargreaves-Samani, kRs 0.16" in est.attrs["irradiance_source"]
    assert "clear" not in est.attrs["irradiance_source"]  # not flagged as a clear-sky proxy


def test_estimate_fills_days_without_enough_readings_and_refuses_none():
    site = {"latitude": 52.0, "longitude": 0.0}
    te = _daily_swing(3, np.array([4.0, 9.0, 16.0]))
    te.iloc[30:40] = np.nan  # day 2 keeps 14 of 24 readings: too few for its range
    est = temperature_range_weather(te, site)
    assert est.attrs["days_filled"] == 1 and est["ghi"].notna().all()
    cs = clear_sky_weather(te.index, site, interval="1h")["ghi"]
    k = (est["ghi"] / cs).where(cs > 1).groupby(te.index.floor("D")).mean().to_numpy()
    # day 2's ratio to the cloudless sky lies between its neighbours'
    assert k[0] < k[1] < k[2]
    with pytest.raises(DataError, match="no solar day with at least 75%"):
        temperature_range_weather(te.iloc[:10], site)
    with pytest.raises(InputError, match="Series"):
        temperature_range_weather(te.to_frame("Te"), site)


@pytest.mark.shared_data
def test_estimate_follows_measured_days_at_de_bilt(knmi_2015):
    site = DE_BILT
    te = knmi_2015["Te"]
    est = temperature_range_weather(te, site)["ghi"]
    cs = clear_sky_weather(te.index, site)["ghi"]
    day = (te.index - pd.Timedelta("30min") + pd.Timedelta(hours=5.18 / 15)).floor("D")
    meas = knmi_2015["ghi"].groupby(day).sum()
    r2 = {
        k: 1 - ((s.groupby(day).sum() - meas) ** 2).sum() / ((meas - meas.mean()) ** 2).sum()
        for k, s in (("estimate", est), ("clear sky", cs))
    }
    assert r2["estimate"] > 0.75 and r2["clear sky"] < 0.4
    assert est.sum() == pytest.approx(knmi_2015["ghi"].sum(), rel=0.1)
