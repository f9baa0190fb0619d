"""io.clock: clocks measured from the sun, the outdoor daily cycle and DST jumps, and the
warning prepare() gives when a config's declared clock disagrees with the data."""

from __future__ import annotations

import re
from pathlib import Path

import numpy as np
import pandas as pd
import pytest
import yaml

from heritage_bayes.config import parse_config
from heritage_bayes.io import read_knmi_hourly
from heritage_bayes.io.clock import (
    TE_PEAK_LAG_H,
    daily_cycle_phase,
    dst_structure,
    outdoor_cycle_offset,
    solar_clock_offset,
    solar_noon_utc,
)
from heritage_bayes.prepare import prepare

CONFIGS = Path(__file__).resolve().parents[1] / "configs"
ESPOO_LON = 24.66  # configs/trh1_attic.yaml
DE_BILT_LON = 5.18


def _fmi(shared_data):
    d = pd.read_csv(shared_data / "trh1-espoo-attic" / "fmi.csv")
    return pd.DatetimeIndex(pd.to_datetime(d["t_UTC+2"])), d


def test_solar_noon_equation_of_time():
    # Greenwich: solar noon 12:00 UT minus the equation of time (Spencer 1971): about
    # 11:44 UT early November (EoT +16.4 min), 12:14 UT mid-February (EoT -14.2 min)
    noon = solar_noon_utc(pd.DatetimeIndex(["2021-11-03", "2021-02-11"]), 0.0)
    np.testing.assert_allclose(noon, [12 - 16.4 / 60, 12 + 14.2 / 60], atol=0.02)


def test_synthetic_sun_gives_the_clock_back():
    # a clear-sky-like bump centred on solar noon, written on a UTC+3 clock
    utc = pd.date_range("2021-01-01", "2021-12-31 23:00", freq="1h", tz="UTC")
    noon = solar_noon_utc(utc.normalize().tz_localize(None), 30.0)
    h = (utc - utc.normalize()) / pd.Timedelta(hours=1)
    ghi = 800 * np.exp(-(((h - noon) / 2.5) ** 2))
    est = solar_clock_offset(
        utc.tz_localize(None) + pd.Timedelta(hours=3), ghi, 30.0, label="instant"
    )
    assert abs(est.offset_h - 3.0) < 0.05 and est.follows_dst is False
    # read as end-of-hour means, the same values sit half an hour earlier
    est = solar_clock_offset(utc.tz_localize(None) + pd.Timedelta(hours=3), ghi, 30.0)
    assert abs(est.offset_h - 2.5) < 0.05


@pytest.mark.shared_data
def test_trh1_fmi_clock_from_the_sun(shared_data):
    t, d = _fmi(shared_data)
    est = solar_clock_offset(t, d["Rglob"], ESPOO_LON, label="instant")
    # the file says t_UTC+2; the sun agrees to minutes, all year (a fixed clock)
    assert abs(est.offset_h - 2.0) < 0.1 and est.n_days > 400
    assert est.follows_dst is False
    # shifted by 3 hours, the file's clock is measured 3 hours further east
    est3 = solar_clock_offset(t + pd.Timedelta(hours=3), d["Rglob"], ESPOO_LON, label="instant")
    assert abs(est3.offset_h - 5.0) < 0.1


@pytest.mark.shared_data
def test_outdoor_cycle_lag_on_two_stations(shared_data):
    t, d = _fmi(shared_data)
    peak = daily_cycle_phase(t, d["Te"])
    lag = np.nanmedian(peak - (solar_noon_utc(pd.DatetimeIndex(peak.index), ESPOO_LON) + 2))
    assert abs(lag - TE_PEAK_LAG_H) < 0.1
    w = read_knmi_hourly(shared_data / "knmi-debilt" / "uurgeg_260_2011-2020.txt.gz")
    peak = daily_cycle_phase(w.index, w["Te"])
    lag = np.nanmedian(peak - solar_noon_utc(pd.DatetimeIndex(peak.index), DE_BILT_LON))
    assert abs(lag - TE_PEAK_LAG_H) < 0.1
    # the coarse detector: within half an hour of the true clock on both
    assert abs(outdoor_cycle_offset(t, d["Te"], ESPOO_LON).offset_h - 2.0) < 0.5
    assert abs(outdoor_cycle_offset(w.index, w["Te"], DE_BILT_LON).offset_h) < 0.5
    # KNMI's hour-ending means, read by the KNMI reader to UTC: no residual
    assert abs(solar_clock_offset(w.index, w["ghi"], DE_BILT_LON).offset_h) < 0.1


@pytest.mark.shared_data
def test_dst_structure_fixed_clock(shared_data):
    t, _ = _fmi(shared_data)
    st = dst_structure(t, "Europe/Helsinki")
    assert st.verdict == "fixed"
    assert st.in_skipped_hour == 2  # springs 2011 and 2012 hold 03:00 on the fixed clock


def test_dst_structure_dst_clock():
    utc = pd.date_range("2020-01-01", "2021-12-31", freq="1h", tz="UTC")
    wall = utc.tz_convert("Europe/Helsinki").tz_localize(None)  # 23- and 25-hour days
    st = dst_structure(wall, "Europe/Helsinki")
    assert st.verdict == "dst"
    assert (st.spring_gap, st.autumn_repeat) == (2, 2)
    assert dst_structure(utc.tz_localize(None), "Europe/Helsinki").verdict == "fixed"


def clock_warnings(prep) -> list[str]:
    return prep.sources["clock"]["warnings"]


def _trh1(shared_data, tmp_path, weather_path=None, weather_tz=None):
    raw = yaml.safe_load((CONFIGS / "trh1_attic.yaml").read_text(encoding="utf-8"))
    raw["hygric"] = None
    w = raw["data"]["weather"]
    if weather_path is not None:
        w["path"] = str(weather_path)
    if weather_tz is not None:
        w["timezone"] = weather_tz
    return parse_config(raw, base_dir=str(CONFIGS), name="trh1")


@pytest.mark.shared_data
def test_prepare_warns_with_the_measured_offset(shared_data, tmp_path):
    # the shipped config: no warning (its clock is right)
    assert clock_warnings(prepare(_trh1(shared_data, tmp_path))) == []
    # a DST zone on the fixed UTC+2 clock: rows in the skipped hour, summer off by 1 h
    warn = clock_warnings(prepare(_trh1(shared_data, tmp_path, weather_tz="Europe/Helsinki")))
    assert any("skips in spring" in w and "fixed clock" in w for w in warn)
    assert any("April-September -1.0 h from November-February" in w for w in warn)
    # the weather file shifted by 3 hours, still declared UTC+2
    d = pd.read_csv(shared_data / "trh1-espoo-attic" / "fmi.csv")
    t = pd.to_datetime(d["t_UTC+2"]) + pd.Timedelta(hours=3)
    d["t_UTC+2"] = t.dt.strftime("%Y-%m-%d %H:%M:%S")
    shifted = tmp_path / "fmi_shifted.csv"
    d.to_csv(shifted, index=False)
    warn = clock_warnings(prepare(_trh1(shared_data, tmp_path, weather_path=shifted)))
    assert len(warn) == 1
    assert "+3.0 h from the declared timezone UTC+02:00" in warn[0]
    assert re.search(r"the file's clock is UTC\+(4:5\d|5:0\d), not the declared", warn[0])


@pytest.mark.shared_data
def test_prepare_warns_from_the_outdoor_cycle_without_irradiance(shared_data):
    # Ørholm: DMI weather (UTC, no irradiance): the daily cycle of Te is checked
    raw = yaml.safe_load((CONFIGS / "orholm.yaml").read_text(encoding="utf-8"))
    prep = prepare(parse_config(raw, base_dir=str(CONFIGS), name="orholm"))
    assert prep.sources["clock"]["warnings"] == []
    assert abs(prep.sources["clock"]["data.weather"]["outdoor_cycle"]["offset_h"]) < 0.6
    raw["data"]["weather"]["timezone"] = "UTC+3"  # the UTC file declared three hours east
    prep = prepare(parse_config(raw, base_dir=str(CONFIGS), name="orholm"))
    (w,) = prep.sources["clock"]["warnings"]
    assert "Te puts the file's clock -2.6 h from the declared timezone UTC+03:00" in w
    assert "the file's clock is about UTC+0:00" in w


def test_dst_clock_declared_fixed_is_reported(tmp_path):
    from heritage_bayes.io import read_csv
    from heritage_bayes.io.clock import check_declared_clock

    utc = pd.date_range("2010-01-01", "2011-12-31", freq="1h", tz="UTC")
    wall = utc.tz_convert("Europe/Copenhagen").tz_localize(None)  # a DST logger
    p = tmp_path / "dst.csv"
    pd.DataFrame(
        {"t": wall.strftime("%Y-%m-%d %H:%M"), "T": 15.0 + np.arange(wall.size) % 7}
    ).to_csv(p, index=False)
    df = read_csv(p, time_column="t", columns={"Ti": "T"}, timezone="UTC+1", duplicates="first")
    (w,) = check_declared_clock(df, None, "data.measurements")["warnings"]
    assert "declared the fixed clock UTC+1, but the stamps jump at the DST changes" in w
    assert "0 spring change(s) with stamps inside the skipped hour, 2 with a one-hour jump" in w
    # the same file read with its zone: no warning; a fixed clock read as fixed: none
    df = read_csv(p, time_column="t", columns={"Ti": "T"}, timezone="Europe/Copenhagen")
    assert check_declared_clock(df, None, "data.measurements")["warnings"] == []
