"""hbayes init finds where a room's operation changed within a long record
(heritage_bayes.init_regimes) and proposes periods run one way: a store whose
dehumidifier (and its heat) was switched off, written as the Ørholm files are (a
European `;` logger export on a fixed UTC+1 clock, a DMI weather file in UTC)."""

from __future__ import annotations

from dataclasses import replace

import numpy as np
import pandas as pd
import pytest

from heritage_bayes.climate.psychro import saturation_vapour_pressure
from heritage_bayes.config import load_config
from heritage_bayes.init_config import init_config
from heritage_bayes.init_regimes import YearRegime, regime_stretch, year_regimes

SITE = {"latitude": 55.79, "longitude": 12.50}
OFF = pd.Timestamp("2015-01-01", tz="UTC")  # the dehumidifier switched off


def _store(end: str):
    """Hourly UTC stamps, Te, RHe, Ti, RHi [°C, %] of a store heated to a 10 °C floor:
    before :data:`OFF` a dehumidifier holds RH at 47-51 % and its heat keeps the air 5 K
    above outdoors; after it, the RH follows the outdoor moisture and the gain is 1 K."""
    rng = np.random.default_rng(11)
    utc = pd.date_range("2013-01-01", end, freq="1h", tz="UTC", inclusive="left")
    doy = np.asarray(utc.day_of_year)
    h = np.asarray(utc.hour)
    te = 8 - 8 * np.cos(2 * np.pi * (doy - 15) / 365) + 3 * np.cos(2 * np.pi * (h - 14) / 24)
    te = te + np.repeat(rng.normal(0, 2.5, len(utc) // 24 + 1), 24)[: len(utc)]
    rhe = np.clip(80 - 12 * np.cos(2 * np.pi * (h - 14) / 24) + rng.normal(0, 5, h.size), 30, 100)
    on = np.asarray(utc < OFF)
    smooth = pd.Series(te).ewm(halflife=48).mean().to_numpy()
    ti = np.maximum(smooth + np.where(on, 5.0, 1.0), 10 + rng.normal(0, 0.05, h.size))
    pe = rhe / 100 * saturation_vapour_pressure(te)
    free = 100 * pd.Series(pe).ewm(halflife=24).mean().to_numpy() / saturation_vapour_pressure(ti)
    held = 49 + 2 * np.sin(np.arange(h.size) / 30) + rng.normal(0, 0.5, h.size)
    rhi = np.clip(np.where(on, held, free), 5, 99)
    return utc, te, rhe, ti, rhi


def _write(tmp_path, utc, te, rhe, ti, rhi):
    d = tmp_path / "data"
    d.mkdir()
    local = utc.tz_localize(None) + pd.Timedelta(hours=1)  # the logger's fixed UTC+1
    lines = ["DATE AND TIME; TEMP C; %RH"] + [
        f"{t:%d-%m-%Y %H:%M}; {a:.1f}; {b:.0f}" for t, a, b in zip(local, ti, rhi, strict=True)
    ]
    lp = d / "store-indoor.csv"
    lp.write_bytes(("\r\n".join(lines) + "\r\n").encode())
    w = utc.tz_localize(None)
    wp = d / "DMI_outdoor.csv"
    pd.DataFrame(
        {
            "Station": 618100,
            "Year": w.year,
            "Month": w.month,
            "Day": w.day,
            "Hour (UTC)": w.hour,
            "TEMP C": te.round(1),
            "%RH": rhe.round(1),
        }
    ).to_csv(wp, sep=";", index=False)
    return lp, wp


@pytest.fixture(scope="module")
def switched_off(tmp_path_factory):
    """init on a record of 2013-01 to 2016-05 whose dehumidifier went off in 2015."""
    tmp = tmp_path_factory.mktemp("regimes")
    lp, wp = _write(tmp, *_store("2016-05-01"))
    out = tmp / "room" / "config.yaml"
    res = init_config(lp, wp, output=out, timezone="UTC+1", **SITE)
    return res, out


def test_the_periods_stay_in_one_regime(switched_off):
    res, out = switched_off
    assert res.questions == []
    cfg = load_config(out)
    # the 16 months since the change hold no calendar year and 8 months after it: the
    # periods are in the stretch before (without the regimes: 2014 / 2015, one each)
    assert (cfg.periods.calibration.start, cfg.periods.calibration.end) == (
        "2013-01-01",
        "2014-01-01",
    )
    assert cfg.periods.validation.end == "2015-01-01"
    # the model measured over that stretch: the band and the dehumidifier's heat
    assert cfg.hygric.options.given() == {"humidistat": "band"}
    assert cfg.thermal.options.given() == {"thermostat": True, "source": True}
    # the evidence, year by year, in the periods' comment and on the console
    text = out.read_text(encoding="utf-8")
    flat = " ".join(line.strip("# ") for line in text.splitlines() if line.startswith("  #"))
    assert "the RH band, the summer gain changed between 2014 and 2015" in flat
    assert "2014: RH band 4 points (held)" in flat
    assert any(f.startswith("operation: operation by year: 2013:") for f in res.findings)


def test_a_year_near_a_threshold_joins_either_side():
    """A year whose band or summer excess is unclear does not end a stretch; a year whose
    signatures clearly differ does, and the most recent stretch long enough is kept."""
    held = YearRegime(2014, rh_width=6, rh_held=True, heated=True, floor=10.2, excess=5.2)
    unclear = YearRegime(2018, rh_width=14, heated=True, floor=10.0, excess=3.3)
    free = YearRegime(2019, 23, False, True, 10.1, excess=2.3)
    assert unclear.differs(free) == [] and unclear.differs(held) == []
    assert held.differs(free) == ["the RH band", "the summer gain"]
    moved = YearRegime(2020, heated=True, floor=12.5)
    assert moved.differs(held) == ["the heating set-point"]
    # the store's own series: the change shows and the stretch after it is taken
    utc, te, rhe, ti, rhi = _store("2017-01-01")
    series = [pd.Series(v, index=utc) for v in (ti, te, rhi, rhe)]
    s, e = utc[0], utc[-1] + pd.Timedelta(hours=1)
    years = year_regimes(*series, s, e)
    assert [(y.year, y.rh_held) for y in years] == [
        (2013, True),
        (2014, True),
        (2015, False),
        (2016, False),
    ]
    assert years[1].differs(years[2]) == ["the RH band", "the summer gain"]
    start, end, notes = regime_stretch(*series, s, e)
    assert (start, end) == (OFF, e)  # 2015 and 2016: a year and 8 months or more
    assert "the most recent stretch run one way" in notes[-1]


def test_twenty_months_calibrate_a_whole_year():
    """A record of 20 months holding no calendar year with 8 months after it (the
    Ørholm logger file as a user held it, 2013-03 to 2014-10): 12 whole months calibrate,
    the rest validates; 19 months keep the 8/4 split of the first year."""
    from heritage_bayes.init_periods import choose_periods

    utc = "UTC"
    s = pd.Timestamp("2013-03-01", tz=utc)
    cs, ce, _, ve, why = choose_periods(s, pd.Timestamp("2014-10-31", tz=utc))
    assert (cs, ce, ve) == ("2013-03-01", "2014-03-01", "2014-10-31")
    assert why.startswith("the most recent 12 whole months")
    cs, ce, _, ve, _ = choose_periods(s, pd.Timestamp("2014-10-01", tz=utc))
    assert (cs, ce, ve) == ("2013-03-01", "2013-11-01", "2014-03-01")
    # 26 months: the most recent 12 with a year after them
    cs, ce, _, ve, _ = choose_periods(s, pd.Timestamp("2015-05-01", tz=utc))
    assert (cs, ce, ve) == ("2013-05-01", "2014-05-01", "2015-05-01")


MOVED = pd.Timestamp("2014-09-15", tz="UTC")  # the heating turned up by hand


def _moved_store():
    """The store of :func:`_store` without its dehumidifier (RH free, a 1 K gain), heated
    to 10 °C until :data:`MOVED` and to 11.5 °C after it: the calendar years' floors
    differ by 1.5 K, under the 2 K of a set-point shift year by year."""
    utc, te, rhe, _, _ = _store("2016-05-01")
    rng = np.random.default_rng(5)
    setpoint = np.where(np.asarray(utc < MOVED), 10.0, 11.5)
    smooth = pd.Series(te).ewm(halflife=48).mean().to_numpy()
    ti = np.maximum(smooth + 1.0, setpoint + rng.normal(0, 0.05, te.size))
    pe = rhe / 100 * saturation_vapour_pressure(te)
    rhi = np.clip(
        100 * pd.Series(pe).ewm(halflife=24).mean().to_numpy() / saturation_vapour_pressure(ti),
        5,
        99,
    )
    return utc, te, rhe, ti, rhi


@pytest.fixture(scope="module")
def moved_by_hand(tmp_path_factory):
    """init on the store whose heating level moved between the winters of 2013/14 and
    2014/15."""
    tmp = tmp_path_factory.mktemp("moved")
    lp, wp = _write(tmp, *_moved_store())
    out = tmp / "room" / "config.yaml"
    res = init_config(lp, wp, output=out, timezone="UTC+1", **SITE)
    return res, out


def test_a_heating_level_moved_between_winters_ends_the_stretch(moved_by_hand):
    res, out = moved_by_hand
    assert res.questions == []
    cfg = load_config(out)
    # the 22 months from the 1st of July before the first winter at the new level: 12
    # months to calibrate, the rest to validate (without the seasons: 2014 / 2015, a
    # calibration year holding both levels)
    assert (cfg.periods.calibration.start, cfg.periods.calibration.end) == (
        "2014-07-01",
        "2015-07-01",
    )
    assert cfg.periods.validation.end >= "2016-04-30"
    text = out.read_text(encoding="utf-8")
    flat = " ".join(line.strip("# ") for line in text.splitlines() if line.startswith("  #"))
    assert "2013/14 10.0 °C; 2014/15 11.5 °C" in flat
    assert "moved by 0.8 K or more between seasons (2013/14 to 2014/15" in flat
    assert any("heating level by season" in f for f in res.findings)


def test_season_levels_and_their_stretch():
    """The levels per heating season (July to June) and the stretch at one level; a
    free-running room has none; a move under the threshold keeps the whole span."""
    from heritage_bayes.init_regimes import LEVEL_SHIFT_K, level_stretch, season_levels

    utc, te, _, ti, _ = _moved_store()
    s_ti, s_te = pd.Series(ti, index=utc), pd.Series(te, index=utc)
    levels = season_levels(s_ti, s_te)
    assert [lv.season for lv in levels] == [2012, 2013, 2014, 2015]
    assert [round(lv.level, 1) for lv in levels] == [10.0, 10.0, 11.5, 11.5]
    s, e = utc[0], utc[-1] + pd.Timedelta(hours=1)
    start, end, notes = level_stretch(levels, s, e)
    assert (start, end) == (pd.Timestamp("2014-07-01", tz="UTC"), e)
    # free-running (no floor): no level to move
    assert season_levels(pd.Series(np.asarray(te) + 1.0, index=utc), s_te) == []
    # a move under the threshold is one level
    small = [replace(lv, level=10.0 + (LEVEL_SHIFT_K - 0.1) * (lv.level > 11)) for lv in levels]
    assert level_stretch(small, s, e) == (s, e, [])
    # too short after the move: the whole span, with a note
    start, end, notes = level_stretch(levels, s, pd.Timestamp("2015-12-01", tz="UTC"))
    assert start == s and "the periods span the move" in notes[-1]
