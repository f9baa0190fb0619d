"""Solar irradiance on surfaces: physical sense on real weather, timing, options, errors."""

from __future__ import annotations

import numpy as np
import pandas as pd
import pvlib
import pytest

from _io_helpers import DE_BILT, knmi_2011_2020, pvlib_tmy3_path
from heritage_bayes.climate import DEFAULT_SURFACES, clear_sky_weather, surface_irradiance
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
