"""init's periods for a record shorter than a year: the validation where the calibration
has seen its weather; a year or more split as before."""

from __future__ import annotations

import numpy as np
import pandas as pd
import pytest
import yaml

from heritage_bayes.init_periods import choose_periods, covered_share, daily_conditions


def _weather(start: str, end: str, seed: int = 5):
    """Hourly UTC stamps, outdoor temperature [°C] (an annual cycle, coldest mid-January,
    and a daily one) and global irradiance [W/m²] (longer, higher days in summer) at 60 °N."""
    rng = np.random.default_rng(seed)
    utc = pd.date_range(start, end, freq="1h", tz="UTC", inclusive="left")
    h = np.asarray(utc.hour, dtype=float)
    doy = np.asarray(utc.day_of_year, dtype=float)
    summer = -np.cos(2 * np.pi * (doy + 10) / 365)  # -1 at the winter solstice
    clouds = np.repeat(rng.uniform(0.3, 1.0, len(utc) // 24 + 1), 24)[: len(utc)]
    width = 2.5 + 1.5 * summer  # [h] the day's half-width
    ghi = 450 * (1.4 + summer) * clouds * np.exp(-(((h - 11) / width) ** 2))
    te = 5 - 12 * np.cos(2 * np.pi * (doy - 15) / 365) + 3 * np.cos(2 * np.pi * (h - 14) / 24)
    return utc, te + rng.normal(0, 0.5, h.size), np.round(ghi, 1)


def _daily(start, end):
    utc, te, ghi = _weather(start, end)
    return daily_conditions(pd.Series(te, index=utc), pd.Series(ghi, index=utc))


def _utc(day: str) -> pd.Timestamp:
    return pd.Timestamp(day, tz="UTC")


def test_a_winter_to_summer_record_validates_in_its_middle():
    """November to July (the TRH-1 R5 attic's span): the end would validate a summer on a
    winter's calibration; the middle third validates, held out of a calibration on both
    sides of it (winter and summer), which covers it (so does the first third: the
    middle wins the tie). A record whose end the calibration covers keeps it."""
    s, e = _utc("2010-11-15"), _utc("2011-07-26")
    daily = _daily("2010-11-15", "2011-07-26")
    cs, ce, vs, ve, why = choose_periods(s, e, daily=daily)
    assert (cs, vs, ve, ce) == ("2010-11-15", "2011-02-07", "2011-05-03", "2011-07-26")
    assert "middle third to validate" in why and "calibration spans the validation" in why
    around = [(cs, vs), (ve, ce)]
    assert covered_share(daily, around, (vs, ve)) >= 0.9
    assert covered_share(daily, ("2011-02-07", ce), (cs, "2011-02-07")) >= 0.9
    assert covered_share(daily, ("2010-11-15", "2011-05-03"), ("2011-05-03", "2011-07-26")) < 0.6
    # without the weather: today's split; spring to autumn, whose end the calibration
    # covers (a summer calibrating an early autumn): the end, as before
    assert choose_periods(s, e)[:4] == ("2010-11-15", "2011-05-03", "2011-05-03", "2011-07-26")
    s, e = _utc("2011-04-01"), _utc("2011-10-01")
    cs, ce, vs, ve, why = choose_periods(s, e, daily=_daily("2011-04-01", "2011-10-01"))
    assert (cs, ce, vs, ve) == ("2011-04-01", "2011-08-01", "2011-08-01", "2011-10-01")
    assert why.startswith("the longest stretch: its first 2/3 to calibrate")


@pytest.mark.parametrize(
    ("start", "end"), [("2010-11-15", "2012-05-19"), ("2012-01-01", "2015-12-18")]
)
def test_a_year_or_more_is_split_as_without_the_weather(start, end):
    """A whole year holds every season: the weather does not move its periods."""
    s, e = _utc(start), _utc(end)
    assert choose_periods(s, e, daily=_daily(start, end)) == choose_periods(s, e)


def test_a_record_whose_middle_is_new_weather_validates_first():
    """A record whose middle third holds the coldest days (September to May, mid-winter
    in the middle) and whose first third is covered by the rest: the first third."""
    s, e = _utc("2010-09-01"), _utc("2011-05-20")
    daily = _daily("2010-09-01", "2011-05-20")
    cs, ce, vs, ve, why = choose_periods(s, e, daily=daily)
    assert ve == cs and "first 1/3 to validate" in why, why


def test_init_writes_the_validation_inside_with_its_reason(tmp_path):
    """init on a winter-to-summer attic record: the written validation lies inside the
    calibration, its comment says why, and the config prepares with the validation held
    out of the fit."""
    from heritage_bayes.config import load_config
    from heritage_bayes.init_config import init_config
    from heritage_bayes.models import models_of
    from heritage_bayes.prepare import prepare

    utc, te, ghi = _weather("2012-11-01", "2013-07-20")
    ti = pd.Series(te).ewm(halflife=6).mean().to_numpy() + 3 + 0.004 * ghi
    wall = (utc.tz_localize(None) + pd.Timedelta(hours=2)).strftime("%Y-%m-%d %H:%M:%S")
    data = tmp_path / "data"
    data.mkdir()
    pd.DataFrame({"t_UTC+2": wall, "Te": te.round(2), "Rglob": ghi}).to_csv(
        data / "fmi.csv", index=False
    )
    pd.DataFrame({"t_UTC+2": wall, "T": ti.round(2)}).to_csv(data / "attic.csv", index=False)
    out = tmp_path / "room" / "config.yaml"
    res = init_config(
        data / "attic.csv", data / "fmi.csv", output=out, latitude=60.2, longitude=24.7
    )
    assert res.questions == []
    per = yaml.safe_load(out.read_text(encoding="utf-8"))["periods"]
    assert str(per["calibration"]["start"]) == "2012-11-01"
    assert per["calibration"]["start"] < per["validation"]["start"]
    assert per["validation"]["end"] < per["calibration"]["end"]
    assert "middle third to validate" in res.text and "warmer than any" not in res.text
    cfg = load_config(out)
    prep = prepare(cfg, models_of(cfg)[0])
    assert prep.validation_inside and not prep.fitted_rows()[prep.validation].any()
