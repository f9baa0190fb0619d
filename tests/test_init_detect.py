"""hbayes init detects what a new user's files do not say: a logger or weather station on
daylight-saving time (from its own stamps, the zone from the site's coordinates), on
files shaped like real exports (written in tmp_path)."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pandas as pd
import pytest

from heritage_bayes.config import load_config
from heritage_bayes.convert import timezone_text
from heritage_bayes.init_config import init_config
from heritage_bayes.io.clock import solar_noon_utc

HELSINKI = {"latitude": 60.2, "longitude": 24.7}
NEW_YORK = {"latitude": 40.71, "longitude": -74.0}


def _climate(start: str, end: str, lon: float, seed: int = 3):
    """Hourly UTC stamps, Te, Ti, RH [%] and ghi [W/m²] of a free-running room."""
    rng = np.random.default_rng(seed)
    utc = pd.date_range(start, end, freq="1h", tz="UTC", inclusive="left")
    noon = solar_noon_utc(utc.normalize().tz_localize(None), lon)
    h = np.asarray((utc - utc.normalize()) / pd.Timedelta(hours=1))
    doy = np.asarray(utc.day_of_year)
    clouds = np.repeat(rng.uniform(0.3, 1.0, len(utc) // 24 + 1), 24)[: len(utc)]
    season = 0.6 + 0.4 * np.sin(np.pi * doy / 365)
    ghi = np.round(700 * clouds * season * np.exp(-(((h - noon) / 3.0) ** 2)), 1)
    te = (
        5
        - 10 * np.cos(2 * np.pi * (doy - 15) / 365)
        + 4 * np.cos(2 * np.pi * (h - noon - 2.4) / 24)
        + rng.normal(0, 0.3, h.size)
    )
    ti = pd.Series(te).ewm(halflife=6).mean().to_numpy() + 3
    ti += 0.004 * pd.Series(ghi).ewm(halflife=3).mean().to_numpy()
    rh = np.clip(70 - 2 * (ti - ti.mean()) + rng.normal(0, 1, h.size), 5, 99)
    return utc, te, ti, rh, ghi


def _data(tmp_path: Path) -> Path:
    d = tmp_path / "data"
    d.mkdir(parents=True, exist_ok=True)
    return d


def _fmi(tmp_path: Path, utc, te, rh, ghi) -> Path:
    """An FMI-style weather CSV on UTC+2 (the clock in the time column's name)."""
    wp = _data(tmp_path) / "fmi.csv"
    pd.DataFrame(
        {
            "t_UTC+2": (utc.tz_localize(None) + pd.Timedelta(hours=2)).strftime(
                "%Y-%m-%d %H:%M:%S"
            ),
            "Te": te.round(2),
            "RHe": rh.round(1),
            "Rglob": ghi,
        }
    ).to_csv(wp, index=False)
    return wp


def _european_export(tmp_path: Path) -> tuple[Path, Path]:
    """A logger export in Finnish local time (split date and time columns, `;`, decimal
    comma; the spring hour 03:00 missing, the autumn hour 03:00 twice) and an FMI-style
    weather file on UTC+2 with global radiation."""
    utc, te, ti, rh, ghi = _climate("2013-03-01", "2013-12-01", HELSINKI["longitude"])
    wall = utc.tz_convert("Europe/Helsinki").tz_localize(None)
    rows = ["Date;Time;Temperature (°C);Humidity (%RH)"] + [
        f"{t:%d.%m.%Y};{t:%H:%M:%S};" + f"{a:.2f};{b:.1f}".replace(".", ",")
        for t, a, b in zip(wall, ti, rh, strict=True)
    ]
    lp = _data(tmp_path) / "logger.csv"
    lp.write_text("\n".join(rows) + "\n", encoding="utf-8")
    return lp, _fmi(tmp_path, utc, te, rh, ghi)


def test_a_european_logger_on_daylight_saving_time_gets_the_sites_zone(tmp_path):
    lp, wp = _european_export(tmp_path)
    text = lp.read_text()
    assert "31.03.2013;03:00:00" not in text and text.count("27.10.2013;03:00:00") == 2
    out = tmp_path / "room" / "config.yaml"
    res = init_config(lp, wp, output=out, **HELSINKI)
    assert res.questions == []
    cfg = load_config(out)
    assert timezone_text(cfg.data.measurements[0].timezone) == "Europe/Helsinki"
    assert any(
        "the stamps follow daylight-saving time" in f and "Europe/Helsinki" in f
        for f in res.findings
    )
    # confirmed by the room's own daily cycle: no hour's jump between the seasons
    import re

    (peak,) = [f for f in res.findings if "the indoor temperature peaks" in f]
    summer, winter = map(
        float, re.search(r"Apr-Sep ([-+.\d]+) h, Nov-Feb ([-+.\d]+) h", peak).groups()
    )
    assert abs(summer - winter) < 0.3
    # declared UTC (the user's guess): the question names the site's zone, not London
    res = init_config(lp, wp, output=out, force=True, timezone="UTC", **HELSINKI)
    (q,) = res.questions
    assert "jump at the DST changes of Europe/Helsinki" in q and "London" not in q
    # no site: the stamps still tell daylight-saving time, and the question says so
    res = init_config(lp, wp, output=out, force=True)
    (q,) = [q for q in res.questions if q.startswith("data.measurements.timezone")]
    assert "the logger's stamps follow daylight-saving time (EU rules" in q


def test_a_us_station_on_daylight_saving_time_is_new_york_not_an_odd_offset(tmp_path):
    """A station export in US Eastern local time (2025-03-09 02:00 skipped, 2025-11-02
    01:00 twice) without irradiance, and a HOBOware logger on GMT-05:00."""
    utc, te, ti, rh, _ = _climate("2025-02-01", "2025-12-01", NEW_YORK["longitude"])
    wall = utc.tz_convert("America/New_York").tz_localize(None)
    wp = _data(tmp_path) / "station.csv"
    pd.DataFrame(
        {
            "Date/Time": wall.strftime("%Y-%m-%d %H:%M"),
            "Temp (°C)": te.round(1),
            "Rel Hum (%)": rh.round(0),
        }
    ).to_csv(wp, index=False)
    assert "2025-03-09 02:00" not in wp.read_text()
    lines = ['"Plot Title: parlor"', '"#","Date Time, GMT-05:00","Temp, °C","RH, %"']
    est = utc.tz_localize(None) - pd.Timedelta(hours=5)
    lines += [
        f"{i + 1},{t:%m/%d/%y %I:%M:%S %p},{a:.3f},{b:.2f}"
        for i, (t, a, b) in enumerate(zip(est, ti, rh, strict=True))
    ]
    lp = _data(tmp_path) / "hobo.csv"
    lp.write_text("\n".join(lines) + "\n", encoding="utf-8")
    out = tmp_path / "room" / "config.yaml"
    res = init_config(lp, wp, output=out, **NEW_YORK)
    assert res.questions == []
    cfg = load_config(out)
    assert timezone_text(cfg.data.weather.timezone) == "America/New_York"
    assert timezone_text(cfg.data.measurements[0].timezone) == "UTC-05:00"
    assert any("confirmed by the outdoor daily cycle" in f for f in res.findings)


def test_site_zone_and_the_dst_candidate():
    from heritage_bayes.io.clock import detect_dst_zone, dst_candidate, site_zone

    assert site_zone(60.2, 24.7) == "Europe/Helsinki"
    assert site_zone(36.1, -79.95) == "America/New_York"
    # a declared UTC at Helsinki is tested against Helsinki's changes, not London's
    assert dst_candidate(0, 60.2, 24.7) == "Europe/Helsinki"
    assert dst_candidate(0, None, None) == "Europe/London"  # no site: by the offset
    assert dst_candidate(9, 35.7, 139.7) is None  # Tokyo keeps no DST
    fixed = pd.date_range("2013-03-01", "2013-12-01", freq="1h")  # stamps of a fixed clock
    assert detect_dst_zone(fixed, 60.2, 24.7) is None
    assert detect_dst_zone(fixed, None, None) is None


@pytest.mark.parametrize("declared", ["UTC", "UTC+2"])
def test_calibrate_names_the_sites_zone_for_a_dst_logger_declared_fixed(tmp_path, declared):
    from heritage_bayes.io import read_csv
    from heritage_bayes.io.clock import check_declared_clock

    utc = pd.date_range("2013-01-01", "2013-12-31", freq="1h", tz="UTC")
    wall = utc.tz_convert("Europe/Helsinki").tz_localize(None)
    p = tmp_path / "dst.csv"
    pd.DataFrame(
        {"t": wall.strftime("%Y-%m-%d %H:%M"), "T": 15.0 + np.arange(wall.size) % 7}
    ).to_csv(p, index=False)
    df = read_csv(p, time_column="t", columns={"Ti": "T"}, timezone=declared, duplicates="first")
    (w,) = check_declared_clock(df, 24.7, "data.measurements", 60.2)["warnings"]
    assert "declare its zone (e.g. Europe/Helsinki)" in w


def _hobo(path: Path, stamps, ti, rh, gmt: str) -> Path:
    lines = ['"Plot Title: nave"', f'"#","Date Time, GMT{gmt}","Temp, °C","RH, %"']
    lines += [
        f"{i + 1},{t:%m/%d/%y %I:%M:%S %p},{a:.3f},{b:.2f}"
        for i, (t, a, b) in enumerate(zip(stamps, ti, rh, strict=True))
    ]
    path.write_text("\n".join(lines) + "\n", encoding="utf-8")
    return path


def test_periods_stay_inside_the_data_whatever_the_answer_to_an_open_clock(tmp_path):
    """A weather file that names no clock (kept on UTC-2, no irradiance) with a 35-hour
    outage: its clock is a question, and the periods init proposes stay inside the data
    once it is answered (they used to start inside the outage: calibrate refused; now they
    span it)."""
    import yaml

    from heritage_bayes.config import parse_config
    from heritage_bayes.prepare import prepare

    utc, te, ti, rh, _ = _climate("2021-03-01", "2021-06-01", -30.0)
    wall = utc.tz_localize(None) - pd.Timedelta(hours=2)
    keep = ~((wall >= "2021-03-05 13:00") & (wall < "2021-03-07 00:00"))  # 35 h missing
    wp = _data(tmp_path) / "station.csv"
    pd.DataFrame(
        {"time": wall[keep].strftime("%Y-%m-%d %H:%M"), "T_out": te[keep].round(2)}
    ).to_csv(wp, index=False)
    lp = _hobo(_data(tmp_path) / "logger.csv", wall, ti, rh, "-02:00")
    out = tmp_path / "room" / "config.yaml"
    res = init_config(lp, wp, output=out, latitude=40.0, longitude=-30.0)
    assert [q.split(":")[0] for q in res.questions] == ["data.weather.timezone"]
    assert any("a clock is still an open question" in f for f in res.findings)
    raw = yaml.safe_load(out.read_text(encoding="utf-8"))
    # the data start 2021-03-01 00:00 on the file's clock: 14 h margin, next midnight;
    # the periods span the outage (a gap splits the record into segments); a spring
    # record: the middle third (April) validates, held out of the calibration around
    # it, which covers its weather
    per = raw["periods"]
    assert str(per["calibration"]["start"]) == "2021-03-02"
    assert str(per["validation"]["start"]) == "2021-04-01"
    assert per["validation"]["end"] < per["calibration"]["end"]
    for answer in ("UTC-2", "UTC+12", "UTC-12"):
        raw["data"]["weather"]["timezone"] = answer
        prep = prepare(parse_config(raw, base_dir=str(out.parent), name="room"))
        assert prep.breaks.sum() >= 35  # the outage: not simulated, no DataError


def test_periods_never_start_in_a_short_gap():
    from heritage_bayes.init_checks import choose_periods

    hours = pd.date_range("2021-01-01", "2021-04-01", freq="1h", tz="UTC")
    # the stretch (gaps up to 6 h bridged) starts at midnight inside a 3-hour gap; its
    # last reading is at 23:00, an hour before the end of its last hour
    present = hours[(hours >= "2021-01-01 03:00") & (hours < "2021-04-01")]
    s, _, _, end, why = choose_periods(hours[0], hours[-1], present)
    assert (s, end) == ("2021-01-02", "2021-03-31") and "moved off gaps" in why
    s, _, _, end, why = choose_periods(hours[0], hours[-1], hours)
    assert (s, end) == ("2021-01-01", "2021-04-01") and "moved" not in why


def test_periods_are_the_most_recent_whole_calendar_year():
    """Four years without a long gap (the Ørholm store's 2012-01 to 2015-12-18): the
    most recent whole calendar year with 8 months or more after it calibrates, what
    follows validates; one whole year and 4.5 months: that year, 8 and 4 months."""
    from heritage_bayes.init_checks import choose_periods

    s, e = pd.Timestamp("2012-01-01", tz="UTC"), pd.Timestamp("2015-12-18", tz="UTC")
    cs, ce, _, ve, why = choose_periods(s, e)
    assert (cs, ce, ve) == ("2014-01-01", "2015-01-01", "2015-12-18")
    assert "most recent whole calendar year" in why
    e = pd.Timestamp("2015-07-01", tz="UTC")  # 6 months after 2014: 2013 calibrates
    cs, ce, _, ve, why = choose_periods(s, e)
    assert (cs, ce, ve) == ("2013-01-01", "2014-01-01", "2015-01-01")
    s, e = pd.Timestamp("2010-11-15", tz="UTC"), pd.Timestamp("2012-05-19", tz="UTC")
    cs, ce, _, ve, why = choose_periods(s, e)
    assert (cs, ce, ve) == ("2011-01-01", "2011-09-01", "2012-01-01") and "first" in why


def test_overlapping_downloads_get_a_sort_setting_that_exists(tmp_path):
    """Two HOBO downloads joined in one file, the second starting ten days before the
    first ended: init writes `sort: true` (a real key) and a question that can be
    answered; the reader without it names the key."""
    import yaml

    from heritage_bayes.config import parse_config
    from heritage_bayes.errors import DataError
    from heritage_bayes.prepare import prepare
    from heritage_bayes.questions import open_questions

    utc, te, ti, rh, ghi = _climate("2021-03-01", "2021-06-01", 5.0)
    wall = utc.tz_localize(None) + pd.Timedelta(hours=1)
    first, second = slice(0, 24 * 50), slice(24 * 40, None)
    stamps = wall[first].append(wall[second])
    lp = _hobo(
        _data(tmp_path) / "logger.csv",
        stamps,
        np.r_[ti[first], ti[second]],
        np.r_[rh[first], rh[second]],
        "+01:00",
    )
    wp = _data(tmp_path) / "weather.csv"
    pd.DataFrame(
        {"t_UTC+1": wall.strftime("%Y-%m-%d %H:%M"), "Te": te.round(2), "Rglob": ghi}
    ).to_csv(wp, index=False)
    out = tmp_path / "room" / "config.yaml"
    res = init_config(lp, wp, output=out, latitude=52.0, longitude=5.0)
    (q,) = res.questions
    assert "go backwards 1 time(s); `sort: true` below" in q
    text = out.read_text(encoding="utf-8")
    assert "    sort: true   # 1 time stamps going backwards" in text
    raw = yaml.safe_load(text)
    assert len(open_questions(raw)) == 1
    raw.pop("questions")  # the user checked: overlapping downloads
    prepare(parse_config(raw, base_dir=str(out.parent), name="room"))
    raw["data"]["measurements"].pop("sort")
    with pytest.raises(DataError, match=r"config key sort: true"):
        prepare(parse_config(raw, base_dir=str(out.parent), name="room"))


def test_the_readme_init_command_works_as_printed(tmp_path, monkeypatch):
    """The README's `hbayes init` line, run in a folder holding data/logger.csv (a HOBO
    export on GMT+01:00) and data/weather.csv (UTC+1 with global radiation)."""
    import shlex

    from heritage_bayes.cli import main

    readme = (Path(__file__).resolve().parents[1] / "README.md").read_text(encoding="utf-8")
    (line,) = [
        x.strip() for x in readme.splitlines() if x.strip().startswith(".venv/bin/hbayes init")
    ]
    argv = shlex.split(line)[1:]
    utc, te, ti, rh, ghi = _climate("2021-03-01", "2021-06-01", 5.2)
    wall = utc.tz_localize(None) + pd.Timedelta(hours=1)
    _hobo(_data(tmp_path) / "logger.csv", wall, ti, rh, "+01:00")
    pd.DataFrame(
        {"t_UTC+1": wall.strftime("%Y-%m-%d %H:%M"), "Te": te.round(2), "Rglob": ghi}
    ).to_csv(_data(tmp_path) / "weather.csv", index=False)
    monkeypatch.chdir(tmp_path)
    assert main(argv) == 0
    out = Path(argv[argv.index("-o") + 1])
    assert out.is_file() and load_config(out).name == "nave"


def _attic(tmp_path: Path, *, fahrenheit: bool, rh_fault: str | None = None):
    """A Finnish attic logger starting in winter (an EasyLog-style CSV: `Time,
    Temperature,Humidity`, no units in the names) and the FMI-style weather beside it."""
    utc, te, ti, rh, ghi = _climate("2012-11-01", "2013-08-01", HELSINKI["longitude"])
    wall = utc.tz_localize(None) + pd.Timedelta(hours=2)
    t_out = 32 + 1.8 * ti if fahrenheit else ti
    rh_out = [f"{x:.1f}" for x in rh]
    if rh_fault in ("range", "range_early"):  # a wet sensor: readings above 100 %
        a = 3000 if rh_fault == "range" else 100  # beyond or inside init's sample lines
        rh_out = [
            f"{min(x + 35, 108):.1f}" if a <= i < a + 400 else s
            for i, (x, s) in enumerate(zip(rh, rh_out, strict=True))
        ]
    elif rh_fault == "empty":
        rh_out = [""] * len(rh)
    lp = _data(tmp_path) / "attic.csv"
    pd.DataFrame(
        {"Time": wall.strftime("%Y-%m-%d %H:%M"), "Temperature": t_out.round(1), "Humidity": rh_out}
    ).to_csv(lp, index=False)
    return lp, _fmi(tmp_path, utc, te, rh, ghi)


def test_an_unlabelled_fahrenheit_column_is_recognised_from_the_outdoor_air(tmp_path):
    lp, wp = _attic(tmp_path, fahrenheit=True)
    # the first winter months read as °C look plausible (25 to 45, median 32 "°C")
    from heritage_bayes.io.loggers import inspect_table

    assert inspect_table(lp).first("T").unit == "°C"
    out = tmp_path / "room" / "config.yaml"
    res = init_config(lp, wp, output=out, timezone="UTC+2", **HELSINKI)
    assert res.questions == []
    cfg = load_config(out)
    assert cfg.data.measurements[0].units == {"Ti": "°F"}
    assert any("has no unit in its name" in f and f.endswith(": °F") for f in res.findings)
    # the same room logged in °C is left alone
    lp, wp = _attic(tmp_path / "c", fahrenheit=False)
    res = init_config(
        lp, wp, output=tmp_path / "c" / "room" / "config.yaml", timezone="UTC+2", **HELSINKI
    )
    assert res.questions == [] and "units:" not in res.text


def test_fahrenheit_evidence_thresholds():
    from heritage_bayes.init_columns import F_AGREEMENT_K, F_MEDIAN_C, fahrenheit_evidence

    days = pd.date_range("2013-01-01", periods=40, freq="1D")
    te = pd.Series(np.linspace(-10, 10, 40), index=days.tz_localize("UTC"))
    room_c = pd.Series(te.to_numpy() + 2, index=days)
    assert fahrenheit_evidence(room_c, te)[0] == "°C"
    assert fahrenheit_evidence(32 + 1.8 * room_c, te)[0] == "°F"
    # a heated room at 20 °C: the °F reading is no closer to the outdoor air
    assert fahrenheit_evidence(pd.Series(20.0, index=days), te)[0] == "°C"
    # the median rule at its boundary
    assert fahrenheit_evidence(pd.Series(F_MEDIAN_C, index=days), te)[0] == "°F"
    assert fahrenheit_evidence(pd.Series(F_MEDIAN_C - 0.1, index=days), te)[0] == "°C"
    # the agreement rule at its boundary: read as °F the room sits F_AGREEMENT_K above Te
    # (a winter month, -20 to -10 °C, keeps the median rule out of it)
    cold = te - 10
    for k, unit in ((F_AGREEMENT_K, "°F"), (F_AGREEMENT_K + 0.01, "°C")):
        assert fahrenheit_evidence(32 + 1.8 * (cold.tz_localize(None) + k), cold)[0] == unit
    # values above 70 but no agreement: asked
    spiky = room_c.copy()
    spiky.iloc[3] = 85.0
    assert fahrenheit_evidence(spiky, te)[0] == "?"


@pytest.mark.parametrize("fault", ["range", "range_early", "empty"])
def test_an_rh_column_out_of_range_or_empty_is_a_question_not_a_silent_drop(tmp_path, fault):
    from heritage_bayes.cli import main

    lp, wp = _attic(tmp_path, fahrenheit=False, rh_fault=fault)
    out = tmp_path / "room" / "config.yaml"
    res = init_config(lp, wp, output=out, timezone="UTC+2", **HELSINKI)
    (q,) = res.questions
    assert q.startswith("data.measurements.columns.RHi: column 'Humidity'")
    assert ("holds no value" if fault == "empty" else "above 100 %") in q
    assert "hygric:" in res.text  # the hygric model waits for the answer
    assert main(["calibrate", str(out)]) == 2  # calibrate refuses, naming the key


def test_a_logger_whose_clock_was_changed_keeps_one_part(tmp_path):
    """A logger on Finnish local time (DST) in 2010-2011 whose DST was switched off for
    2012-2013 (the stamps then keep UTC+2: the spring hour stamped, no autumn repeat),
    as the Ørholm store's logger did: init names the change, keeps one clock and chooses
    the periods within its part; a declared DST zone keeps the DST part."""
    utc, te, ti, rh, ghi = _climate("2010-02-01", "2013-12-01", HELSINKI["longitude"])
    switch = utc < pd.Timestamp("2012-01-01", tz="UTC")
    wall = (
        utc.tz_convert("Europe/Helsinki")
        .tz_localize(None)
        .where(switch, utc.tz_localize(None) + pd.Timedelta(hours=2))
    )
    rows = ["DATE AND TIME; TEMP C; %RH"] + [
        f"{t:%d-%m-%Y %H:%M};{a:.1f};{b:.0f}" for t, a, b in zip(wall, ti, rh, strict=True)
    ]
    lp = _data(tmp_path) / "logger.csv"
    lp.write_text("\r\n".join(rows) + "\r\n", encoding="utf-8")
    assert "27-03-2011 03:00" not in lp.read_text() and "25-03-2012 03:00" in lp.read_text()
    wp = _fmi(tmp_path, utc, te, rh, ghi)
    out = tmp_path / "room" / "config.yaml"
    res = init_config(lp, wp, output=out, **HELSINKI)
    assert res.questions == []
    cfg = load_config(out)
    assert timezone_text(cfg.data.measurements[0].timezone) == "UTC+02:00"
    assert pd.Timestamp(cfg.periods.calibration.start) >= pd.Timestamp("2012-01-01")
    (f,) = [f for f in res.findings if "the logger's clock was changed" in f]
    assert "Europe/Helsinki in 2010-2011 and a fixed clock in 2012-2013" in f
    res = init_config(lp, wp, output=out, force=True, timezone="Europe/Helsinki", **HELSINKI)
    assert res.questions == []
    cfg = load_config(out)
    assert pd.Timestamp(cfg.periods.validation.end) <= pd.Timestamp("2012-01-01")


def test_a_validation_warmer_than_the_calibration_is_named():
    """Eight months from November split in time: a winter to calibrate, a summer to
    validate (the TRH-1 R5 attic's record); a whole year split 8/4 months is not."""
    from heritage_bayes.init_checks import extrapolated_seasons

    utc, te, *_ = _climate("2010-11-15", "2011-07-26", HELSINKI["longitude"])
    s = pd.Series(te, index=utc)
    note = extrapolated_seasons(s, "2010-11-15", "2011-05-02", "2011-05-02", "2011-07-26")
    assert note is not None and "the calibration holds no summer" in note
    utc, te, *_ = _climate("2011-01-01", "2012-01-01", HELSINKI["longitude"])
    s = pd.Series(te, index=utc)
    assert extrapolated_seasons(s, "2011-01-01", "2011-09-01", "2011-09-01", "2012-01-01") is None


def test_a_logger_on_a_fixed_clock_is_asked_which_fixed_clock(tmp_path):
    """Stamps through the spring change of the site's zone without a jump (the hour
    Europe/Helsinki skips is stamped): the question names a fixed clock and the zone's
    standard offset, not a zone with daylight-saving time."""
    utc, te, ti, rh, ghi = _climate("2013-03-01", "2013-12-01", HELSINKI["longitude"])
    wall = utc.tz_localize(None) + pd.Timedelta(hours=2)
    rows = ["DATE AND TIME; TEMP C; %RH"] + [
        f"{t:%d-%m-%Y %H:%M};{a:.1f};{b:.0f}" for t, a, b in zip(wall, ti, rh, strict=True)
    ]
    lp = _data(tmp_path) / "logger.csv"
    lp.write_text("\n".join(rows) + "\n", encoding="utf-8")
    res = init_config(lp, _fmi(tmp_path, utc, te, rh, ghi), output=tmp_path / "r" / "c.yaml",
                      **HELSINKI)  # fmt: skip
    (q,) = [q for q in res.questions if q.startswith("data.measurements.timezone")]
    assert "keep a fixed clock, not Europe/Helsinki" in q and "standard time UTC+2" in q
