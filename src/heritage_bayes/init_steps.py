"""The inspection steps of ``hbayes init`` (:func:`heritage_bayes.init_config.init_config`):
the logger file, the weather file, the logger's clock and the periods, each appending what
it found to ``findings`` and what it leaves open to ``questions``, in the order init reports
them.
"""

from __future__ import annotations

import datetime as _dt
from dataclasses import dataclass, field
from pathlib import Path

import pandas as pd

from heritage_bayes.errors import DataError, InputError
from heritage_bayes.init_checks import (
    choose_periods,
    clock_step,
    clock_switch,
    extrapolated_seasons,
    heating_floor,
    logger_clock,
    marked,
    present_hours,
    raw_table,
    to_utc,
    usable_span,
    weather_clock,
)
from heritage_bayes.init_columns import fahrenheit_column_check, rh_column_check, usable
from heritage_bayes.init_periods import daily_conditions
from heritage_bayes.init_regimes import regime_stretch
from heritage_bayes.init_sources import timing_without_sun as _timing_without_sun
from heritage_bayes.io import clock as _clock
from heritage_bayes.io.loggers import TableLayout, inspect_table
from heritage_bayes.questions import MARK

__all__ = [
    "CLOCK_MARGIN",
    "WEATHER_FORMATS",
    "LoggerFile",
    "Periods",
    "WeatherFile",
    "choose_span",
    "inspect_logger",
    "inspect_weather",
    "settle_logger",
    "site_value",
]

#: The largest shift an open clock question can bring when answered (UTC+14, UTC-12).
CLOCK_MARGIN = pd.Timedelta(hours=14)

#: Weather formats ``init`` reads besides CSV (by the readers of :mod:`heritage_bayes.io`).
WEATHER_FORMATS = ("csv", "epw", "knmi", "tmy3")


@dataclass
class LoggerFile:
    """The logger file as init read it.

    ``layout``: its inspected layout; ``columns``, ``units``: ``{standard: column}`` and
    ``{standard: unit}``; ``table``: the readings on the file's own clock; ``dropped``: what
    the reader dropped or changed; ``zone``: its clock (None for stamps with their UTC
    offset, a marked question when open); ``ti_utc``: indoor temperature [°C] on UTC.
    """

    layout: TableLayout
    columns: dict[str, str]
    units: dict
    table: pd.DataFrame
    dropped: dict = field(default_factory=dict)
    zone: str | None = None
    ti_utc: pd.Series | None = None


@dataclass
class WeatherFile:
    """The weather file as init read it.

    ``fmt``: one of :data:`WEATHER_FORMATS`; ``layout``, ``columns``, ``units``,
    ``dropped``: for a CSV (None and empty otherwise); ``label``: how its values are
    stamped; ``zone``: its clock; ``table``: its readings; ``te_utc``: outdoor temperature
    [°C] on UTC; ``irradiance``: ``"measured"`` or None; ``latitude``, ``longitude``: the
    site [° north, ° east] as given, else from the file.
    """

    fmt: str
    table: pd.DataFrame
    te_utc: pd.Series
    irradiance: str | None
    latitude: float | None
    longitude: float | None
    layout: TableLayout | None = None
    columns: dict[str, str] = field(default_factory=dict)
    units: dict = field(default_factory=dict)
    dropped: dict = field(default_factory=dict)
    label: str = "end"
    zone: str | None = None


@dataclass
class Periods:
    """The calibration ``[cs, ce]`` and validation ``[vs, ve]`` periods [UTC], the comment
    ``why`` written above them, whether the hygric section is written, RH on UTC [%] and
    the heating floor ``(floor [°C], held days, days)``."""

    cs: pd.Timestamp
    ce: pd.Timestamp
    vs: pd.Timestamp
    ve: pd.Timestamp
    why: str
    hygric: bool
    rhi_utc: pd.Series | None
    rhe_utc: pd.Series | None
    floor: tuple

    @property
    def span(self) -> tuple:
        """The first and the last day of the periods (the validation may come first)."""
        return min(self.cs, self.vs), max(self.ce, self.ve)

    @property
    def calibration_length(self) -> pd.Timedelta:
        """The calibration's length, without a validation inside it."""
        cs, ce, vs, ve = (pd.Timestamp(x) for x in (self.cs, self.ce, self.vs, self.ve))
        return ce - cs - (ve - vs if cs < vs and ve < ce else pd.Timedelta(0))


def _weather_format(path: Path, given: str | None) -> str:
    if given is not None:
        if given not in WEATHER_FORMATS:
            raise InputError(
                f"--weather-format: one of {', '.join(WEATHER_FORMATS)} (got {given!r})"
            )
        return given
    name = path.name.lower()
    if name.endswith(".epw"):
        return "epw"
    if name.startswith("uurgeg") or name.endswith(".txt.gz"):
        return "knmi"
    head = path.read_bytes()[:2000].decode("latin-1")
    if head.startswith("# STN") or "YYYYMMDD" in head[:2000]:
        return "knmi"
    return "csv"


def _clock_kind(zone: str | None) -> str | None:
    """``"fixed"`` for a fixed offset, ``"dst"`` for a zone with rules, None when not
    given or not readable (the reader's own message comes later)."""
    if not zone:
        return None
    from heritage_bayes.io import parse_timezone

    try:
        tz = parse_timezone(zone)
    except (ValueError, TypeError):
        return None
    return "fixed" if isinstance(tz, _dt.timezone) else "dst"


def _read_naive(layout: TableLayout, columns: dict[str, str], units: dict) -> pd.DataFrame:
    """The table on the file's own clock (read as if UTC), for inspection only."""
    from heritage_bayes.io import read_csv

    return read_csv(
        layout.path,
        time_column=layout.time_column,
        columns=columns,
        time_format=None if layout.time_format == "ISO8601" else layout.time_format,
        timezone=None if layout.time_format == "ISO8601" else "UTC",
        sep=layout.sep,
        decimal=layout.decimal,
        skiprows=layout.skiprows,
        encoding=layout.encoding,
        units=units or None,
        averaged=(),
        duplicates="first",
        sort=True,
        invalid="nan",
    )


def _pick(layout: TableLayout, kinds: dict[str, str], findings: list[str], what: str):
    """``{standard: column}`` and ``{standard: unit}`` from the layout's guesses."""
    columns, units = {}, {}
    for std, kind in kinds.items():
        found = layout.all(kind)
        if not found:
            continue
        c = found[0]
        columns[std] = c.name
        if c.unit in ("°F", "K", "fraction"):
            units[std] = c.unit
        also = (
            f" (also {', '.join(repr(x.name) for x in found[1:])}: not used)" if found[1:] else ""
        )
        findings.append(f"{what}: {std} = column {c.name!r}: {c.why}{also}")
    return columns, units


def _dropped_findings(df: pd.DataFrame, where: str, findings: list[str], questions: list[str]):
    dropped = dict(df.attrs.get("dropped") or {})
    if dropped:
        findings.append(f"{where}: the reader dropped or changed {dropped}")
    if dropped.get("sorted"):
        questions.append(
            f"questions: the {where} file's time stamps go backwards {dropped['sorted']} "
            "time(s); `sort: true` below reads its rows sorted by time, right for overlapping "
            "downloads joined in one file, wrong for a logger whose clock was reset (then "
            "fix the file's stamps); check which, then delete this question"
        )
    return dropped


def _operation(ti_utc, te_utc, rhi_utc, rhe_utc, s, e, span, findings):
    """The most recent stretch of ``[s, e]`` over which the room was run one way, and its
    heating floor.

    Returns
    -------
    s, e : pandas.Timestamp
        The stretch [UTC] (the whole overlap when the operation did not change).
    span : str
        Its description for the periods' comment.
    regime_why : str
        The per-year evidence of a change (empty when none), appended to that comment.
    floor : tuple
        ``(floor [°C], held days, days)`` of :func:`heating_floor` over the stretch (the
        whole overlap when the operation did not change).
    """
    rs, re_, regime_notes = regime_stretch(ti_utc, te_utc, rhi_utc, rhe_utc, s, e)
    findings += [f"operation: {n}" for n in regime_notes]
    regime_why = ""
    if (rs, re_) != (s, e) or len(regime_notes) > 1:  # a change: its evidence by the periods
        regime_why = ". " + ". ".join(n[0].upper() + n[1:] for n in regime_notes[::-1])
    floor_ti, floor_te = ti_utc, te_utc  # the floor over the whole overlap, or the stretch
    if (rs, re_) != (s, e):
        s, e = rs, re_
        span = f"the stretch run one way ({s:%Y-%m-%d} to {e:%Y-%m-%d})"
        floor_ti, floor_te = ti_utc[s:e], te_utc[s:e]
    floor, held, ndays = heating_floor(floor_ti, floor_te)
    heated = held >= max(20, 0.05 * ndays)
    findings.append(
        f"control: the indoor daily minimum sat at {floor:.1f} °C (within 0.5 K) on {held} of "
        f"{ndays} days while the outdoor air averaged 5 K colder"
        + (": heated (a thermostat's floor)" if heated else ": free-running")
    )
    return s, e, span, regime_why, (floor, held, ndays)


def inspect_logger(indoor: Path, findings: list[str], questions: list[str]) -> LoggerFile:
    """The logger file's layout, its T and RH columns, and its readings on its own clock;
    DataError when it has no indoor temperature column."""
    lay = inspect_table(indoor, what="logger file")
    findings.append(
        f"logger: {lay.layout} layout, separator {lay.sep!r}, decimal {lay.decimal!r}, time "
        f"column {lay.time_column!r} as {lay.time_format!r}"
        + (f", clock {lay.timezone} (named in the header)" if lay.timezone else "")
    )
    findings += [f"logger: {n}" for n in lay.notes]
    icols, iunits = _pick(lay, {"Ti": "T", "RHi": "RH"}, findings, "logger")
    if "Ti" not in icols:
        raise DataError(
            f"{indoor.name}: no indoor temperature column found; columns: "
            + "; ".join(f"{c.name!r} ({c.why})" for c in lay.columns)
        )
    rh_column_check(lay, icols, "RHi", findings, questions, "data.measurements")
    din = _read_naive(lay, usable(icols), usable(iunits))
    step = clock_step(din.index)
    findings.append(
        f"logger: {len(din)} rows, step {step}, {din.index[0]:%Y-%m-%d} to "
        f"{din.index[-1]:%Y-%m-%d} (file clock)"
    )
    return LoggerFile(lay, icols, iunits, din)


def inspect_weather(
    weather: Path,
    weather_format: str | None,
    weather_timezone: str | None,
    lat: float | None,
    lon: float | None,
    findings: list[str],
    questions: list[str],
) -> WeatherFile:
    """The weather file: its format, columns, clock (checked against the sun) and outdoor
    temperature on UTC; the site from the file when not given."""
    wfmt = _weather_format(weather, weather_format)
    if wfmt != "csv":
        from heritage_bayes.io import read_epw, read_knmi_hourly, read_tmy3

        reader = {"epw": read_epw, "knmi": read_knmi_hourly, "tmy3": read_tmy3}[wfmt]
        dw = reader(weather)
        site = dw.attrs.get("site") or {}
        lat = lat if lat is not None else site.get("latitude")
        lon = lon if lon is not None else site.get("longitude")
        irr = "measured" if {"ghi", "dhi", "dni"} & set(dw.columns) else None
        findings.append(f"weather: {wfmt} file, {len(dw)} rows, columns {list(dw.columns)}")
        if lon is not None and "ghi" in dw:
            est = _clock.solar_clock_offset(dw.index, dw["ghi"], lon)
            findings.append(f"weather: clock check (the reader's UTC): {est.describe()}")
        return WeatherFile(wfmt, dw, dw["Te"], irr, lat, lon, zone=weather_timezone)
    wlay = inspect_table(weather, what="weather file")
    findings.append(
        f"weather: {wlay.layout} layout, time column {wlay.time_column!r} as "
        f"{wlay.time_format!r}"
        + (f", clock {wlay.timezone} (named in the header)" if wlay.timezone else "")
    )
    wcols, wunits = _pick(
        wlay,
        {
            "Te": "T",
            "RHe": "RH",
            "ghi": "ghi",
            "dhi": "dhi",
            "dni": "dni",
            "wind": "wind",
            "precip": "precip",
        },
        findings,
        "weather",
    )
    if "Te" not in wcols:
        raise DataError(
            f"{weather.name}: no outdoor temperature column found (columns {wlay.header})"
        )
    rh_column_check(wlay, wcols, "RHe", findings, questions, "data.weather")
    dw = _read_naive(wlay, usable(wcols), usable(wunits))
    wdropped = _dropped_findings(dw, "weather", findings, questions)
    declared = weather_timezone or wlay.timezone
    wlabel = "end"
    if wlay.time_format == "ISO8601":  # stamps with their UTC offset: the clock is known
        wzone, wq = None, None
        findings.append("weather: time stamps carry their UTC offset")
    else:
        wzone, wlabel, wq = weather_clock(
            dw, lon, declared, findings, "weather", lat=lat, layout=wlay
        )
    if wq:
        wzone = marked(wq)
        questions.append(f"data.weather.timezone: {wq}")
    te_utc = to_utc(dw["Te"], wzone)
    irr = "measured" if {"ghi"} <= set(wcols) or {"ghi", "dhi"} & set(wcols) else None
    if irr is None:
        wlabel = _timing_without_sun(wlay, findings)
    return WeatherFile(
        wfmt, dw, te_utc, irr, lat, lon, wlay, wcols, wunits, wdropped, wlabel, wzone
    )


def settle_logger(
    log: LoggerFile,
    wx: WeatherFile,
    timezone: str | None,
    findings: list[str],
    questions: list[str],
) -> None:
    """The logger's temperature unit (the outdoor file tells an unlabelled one), what its
    reader dropped, and its clock (after the weather's); sets ``log.table``,
    ``log.dropped``, ``log.zone`` and ``log.ti_utc``."""
    lay, lat, lon = log.layout, wx.latitude, wx.longitude
    if fahrenheit_column_check(lay, log.columns, log.units, wx.te_utc, findings, questions):
        log.table = _read_naive(lay, usable(log.columns), usable(log.units))
    log.dropped = _dropped_findings(log.table, "logger", findings, questions)
    if lay.time_format == "ISO8601":  # stamps with their UTC offset: the clock is known
        izone = None
        findings.append("logger: time stamps carry their UTC offset")
    else:
        declared = timezone or lay.timezone
        switch = clock_switch(raw_table(lay).index, lat, lon, _clock_kind(declared))
        if switch is not None:  # the clock changed within the file: one part is kept
            findings.append(f"logger: {switch.why}")
            log.table = switch.keep(log.table)
            declared = declared or switch.zone
        izone = logger_clock(lay, log.table, declared, lon, findings, "logger", lat)
    if izone and izone.startswith(MARK):
        questions.append(f"data.measurements.timezone: {izone[len(MARK) :].strip()}")
    log.zone = izone
    log.ti_utc = to_utc(log.table["Ti"], izone)


def site_value(lat: float | None, lon: float | None, questions: list[str]):
    """The ``site`` value: the position [° north, ° east], or a question when unknown."""
    if lat is None or lon is None:
        questions.append("site: the site's latitude and longitude (the sun on the facades)")
        return marked(
            "the site: {latitude: DEG north, longitude: DEG east}; give --latitude, --longitude"
        )
    return {"latitude": round(float(lat), 4), "longitude": round(float(lon), 4), "altitude": 0}


def choose_span(
    log: LoggerFile, wx: WeatherFile, indoor: Path, weather: Path, findings: list[str]
) -> Periods:
    """The periods: in the usable span of both files, within the most recent stretch run
    one way, kept :data:`CLOCK_MARGIN` inside while a clock is open; DataError when the
    files do not overlap."""
    ti_utc, te_utc, dw = log.ti_utc, wx.te_utc, wx.table
    try:
        s, e, span, gap_notes = usable_span(ti_utc, te_utc)
    except DataError as exc:
        typical = (
            " (a typical year cannot calibrate a room: use the weather measured over "
            "the logger's period)"
            if wx.fmt in ("epw", "tmy3")
            else ""
        )
        raise DataError(f"{indoor.name}, {weather.name}: {exc}{typical}") from None
    findings.append(f"overlap: {span}: {s:%Y-%m-%d %H:%M} to {e:%Y-%m-%d %H:%M} UTC")
    findings += [f"overlap: {g}" for g in gap_notes]
    # an RH column that needs an answer keeps the hygric section: answered, it runs
    rhe_open = wx.layout is not None and str(wx.columns.get("RHe", "")).startswith(MARK)
    hygric = "RHi" in log.columns and ("RHe" in dw.columns or rhe_open)
    rhi_utc = to_utc(log.table["RHi"], log.zone) if "RHi" in log.table else None
    rhe_utc = None
    if "RHe" in dw:
        rhe_utc = to_utc(dw["RHe"], wx.zone) if wx.layout is not None else dw["RHe"]
    s, e, span, regime_why, floor = _operation(
        ti_utc, te_utc, rhi_utc if hygric else None, rhe_utc, s, e, span, findings
    )
    if any(z and str(z).startswith(MARK) for z in (log.zone, wx.zone)):
        # an open clock moves the data by up to 14 h when answered: periods chosen on the
        # file's clock keep that far inside the stretch, so any answer keeps them inside
        s, e = s + CLOCK_MARGIN, e - CLOCK_MARGIN
        findings.append(
            "periods: a clock is still an open question: the periods keep "
            f"{CLOCK_MARGIN / pd.Timedelta(hours=1):.0f} h inside the stretch on the files' "
            "own clocks, so that any answer keeps them inside the data; after answering, "
            "`hbayes init` again (--timezone, --weather-timezone) chooses them on UTC"
        )
    # the inputs must hold a reading at both ends of the periods (the outputs need not)
    ghi = None
    if "ghi" in dw:
        ghi = to_utc(dw["ghi"], wx.zone) if wx.layout is not None else dw["ghi"]
    daily = daily_conditions(te_utc, ghi)
    cs, ce, vs, ve, why = choose_periods(s, e, present_hours(te_utc, te_utc), span, daily)
    findings.append(f"periods: {why}")
    why += regime_why
    if season := extrapolated_seasons(te_utc, cs, ce, vs, ve):
        findings.append(f"periods: {season}")
        why = f"{why}. Note: {season}"
    return Periods(cs, ce, vs, ve, why, hygric, rhi_utc, rhe_utc, floor)
