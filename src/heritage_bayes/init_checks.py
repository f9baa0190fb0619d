"""The checks behind ``hbayes init`` (:mod:`heritage_bayes.init_config`): the clocks of
the two files (a clock changed within a logger file too), a heating floor; the usable
span and the periods are :mod:`heritage_bayes.init_periods`' (re-exported here).

Each returns what it found and, when it cannot decide, a question (text; the writer marks
it with :data:`heritage_bayes.questions.MARK`).
"""

from __future__ import annotations

import datetime as _dt
from dataclasses import dataclass

import numpy as np
import pandas as pd

from heritage_bayes.init_periods import (
    MAX_GAP_H,
    MIN_COVERAGE,
    YEAR_DAYS,
    choose_periods,
    extrapolated_seasons,
    longest_stretch,
    present_hours,
    usable_span,
)
from heritage_bayes.io import clock as _clock
from heritage_bayes.io.loggers import TableLayout
from heritage_bayes.questions import MARK

__all__ = [
    "MAX_GAP_H",
    "MIN_COVERAGE",
    "YEAR_DAYS",
    "ClockSwitch",
    "choose_periods",
    "clock_step",
    "clock_switch",
    "extrapolated_seasons",
    "heating_floor",
    "logger_clock",
    "longest_stretch",
    "marked",
    "present_hours",
    "raw_table",
    "to_utc",
    "usable_span",
    "weather_clock",
]


def marked(text: str) -> str:
    """``text`` as an open question: the value ``?? text`` the schema refuses."""
    return f"{MARK} {text}"


def _fmt_h(h: float) -> str:
    sign = "+" if h >= 0 else "-"
    m = round(abs(h) * 60)
    return f"UTC{sign}{m // 60}" + (f":{m % 60:02d}" if m % 60 else "")


def _declared_offsets(zone: str, index: pd.DatetimeIndex) -> tuple[float, float | None]:
    """(winter offset, summer offset or None) [h] of a declared zone over ``index``."""
    from heritage_bayes.io import parse_timezone

    tz = parse_timezone(zone)
    off = [
        pd.Timestamp(year=int(index[0].year), month=m, day=15, tz="UTC")
        .tz_convert(tz)
        .utcoffset()
        .total_seconds()
        / 3600
        for m in (1, 7)
    ]
    return off[0], (off[1] if off[1] != off[0] else None)


_READING = {
    "end": "means ending at the stamp",
    "instant": "values at the stamp",
    "start": "means starting at the stamp",
}


def _whole_hour_label(est: dict) -> str:
    """The stamp reading that puts the clock on a whole hour from UTC (ties: 'end')."""
    return min(
        est, key=lambda k: abs(est[k].offset_h - round(est[k].offset_h)) + 0.01 * (k != "end")
    )


def weather_clock(df, lon, declared, findings, where, *, lat=None, layout=None):
    """The weather file's clock, measured and checked against the declared one.

    Parameters
    ----------
    df : pandas.DataFrame
        The weather table on its file's clock (stamps read as if UTC): ``Te`` [°C] and,
        when measured, ``ghi``/``dhi`` [W/m²].
    lon : float or None
        Site longitude [° east].
    declared : str or None
        The clock the header or ``--weather-timezone`` names.
    findings : list of str
        Appended to: what was measured.
    where : str
        Label for the findings.
    lat : float, optional
        Site latitude [° north]: with ``lon``, the site's zone is the candidate for a
        daylight-saving clock.
    layout : TableLayout, optional
        The file's layout: its stamps as written are tested for DST changes
        (:func:`~heritage_bayes.io.clock.detect_dst_zone`) when no clock is declared.

    Returns
    -------
    (timezone, reading, question)
        ``timezone``: text for the config or None; ``reading``: ``"end"``,
        ``"instant"`` or ``"start"`` (how the irradiance stamps are read); ``question``:
        None, or the text of the open question.

    Notes
    -----
    With irradiance: the sun (:func:`~heritage_bayes.io.clock.solar_clock_offset`) under
    the three readings of the stamps; the reading that confirms the declared clock, or
    puts an undeclared one on a whole hour, is kept. Without: the outdoor daily cycle
    (:func:`~heritage_bayes.io.clock.outdoor_cycle_offset`, ±1.5 h). A file that names
    no clock but whose stamps skip the spring hour and repeat the autumn hour of the
    site's zone keeps that zone, which the sun or the outdoor cycle then confirms.
    """
    if declared is None and layout is not None:
        declared = _dst_from_stamps(layout, lat, lon, findings, where)
    if lon is None:
        if declared:
            findings.append(f"{where}: clock {declared} (from the file); not checked (no site)")
            return declared, "end", None
        return None, "end", "the weather file's clock (e.g. UTC, UTC+2); give --longitude"
    irr = next((c for c in ("ghi", "dhi") if c in df.columns), None)
    est = {}
    if irr is not None:
        est = {
            lab: _clock.solar_clock_offset(df.index, df[irr], lon, label=lab)
            for lab in ("end", "instant", "start")
        }
    if not est or est["end"].offset_h is None:
        e = _clock.outdoor_cycle_offset(df.index, df["Te"], lon)
        findings.append(f"{where}: clock from the outdoor daily cycle ({e.describe()})")
        if e.offset_h is None:
            return declared, "end", None if declared else "the weather file's clock"
        if not declared:
            return (
                None,
                "end",
                f"the weather file's clock: the daily cycle says {_fmt_h(e.offset_h)}",
            )
        w, _ = _declared_offsets(declared, df.index)
        if abs(e.offset_h - w) <= 1.5:
            findings.append(
                f"{where}: clock {declared} confirmed by the outdoor daily cycle "
                f"(within 1.5 h of UTC{w:+g}; {e.describe()})"
            )
            return declared, "end", None
        return (
            declared,
            "end",
            (
                f"declared {declared} but the outdoor daily cycle says {_fmt_h(e.offset_h)} "
                f"({e.describe()}); which clock does the file keep?"
            ),
        )
    for lab, e in est.items():
        findings.append(f"{where}: the sun in {irr} read as {_READING[lab]}: {e.describe()}")
    lab = _whole_hour_label(est)
    if declared:
        w, summer = _declared_offsets(declared, df.index)
        if summer is not None and est[lab].follows_dst is False:
            return (
                declared,
                lab,
                (
                    f"declared {declared} (UTC{w:+g}, UTC{summer:+g} in summer) but the file keeps "
                    f"a fixed clock: the sun gives {est['end'].describe()} reading "
                    f"{_READING['end']}; "
                    f"use a fixed offset such as {_fmt_h(round(est[lab].offset_h))}"
                ),
            )
        if summer is not None and est[lab].follows_dst and abs(est[lab].winter_h - w) < 0.34:
            findings.append(
                f"{where}: clock {declared} confirmed by the sun (daylight-saving time: "
                f"{est[lab].describe()}), irradiance as {_READING[lab]}"
            )
            return declared, lab, None
        ok = [k for k in ("end", "instant", "start") if abs(est[k].offset_h - w) < 0.34]
        if ok:
            findings.append(
                f"{where}: clock {declared} confirmed by the sun, irradiance as {_READING[ok[0]]}"
            )
            return declared, ok[0], None
        other = "end" if lab != "end" else "instant"
        return (
            declared,
            lab,
            (
                f"declared {declared} but the sun says {_fmt_h(est[lab].offset_h)} (irradiance "
                f"as {_READING[lab]}; {_fmt_h(est[other].offset_h)} as {_READING[other]}): "
                f"{est[lab].describe()}; which clock does the file keep?"
            ),
        )
    if est[lab].follows_dst:
        return (
            None,
            lab,
            (
                f"the weather file keeps a daylight-saving clock ({est[lab].describe()}): "
                "name its zone"
                + (
                    f", e.g. {z}"
                    if (z := _clock.dst_candidate(round(est[lab].winter_h), lat, lon))
                    else ""
                )
            ),
        )
    zone = _fmt_h(round(est[lab].offset_h))
    findings.append(f"{where}: no clock named in the file; the sun says {zone} ({_READING[lab]})")
    return zone, lab, None


def heating_floor(ti: pd.Series, te: pd.Series) -> tuple[float, int, int]:
    """A thermostat's signature: (floor [°C], days held at it, days with both series).

    The floor is the 5th percentile of the daily indoor minima; a day is *held* when its
    indoor minimum is within 0.5 K of the floor while the outdoor air averaged more than
    5 K below it (its counts on real rooms: docs/science/models.md, "The model init
    proposes").
    """
    dti = ti.resample("1D").min().rename("ti")
    dte = te.resample("1D").mean().rename("te")
    both = pd.concat([dti, dte], axis=1, sort=True).dropna()
    if len(both) < 10:
        return float("nan"), 0, len(both)
    floor = float(np.percentile(both["ti"], 5))
    held = (both["ti"] - floor).abs().le(0.5) & both["te"].lt(floor - 5)
    return floor, int(held.sum()), len(both)


def logger_clock(layout, df_naive, declared, lon, findings, where, lat=None):
    """Check a logger's declared clock; return the zone text or an open question.

    No declared clock: stamps that skip the spring hour and repeat the autumn hour of
    the site's zone (:func:`~heritage_bayes.io.clock.detect_dst_zone`, ``lat`` and
    ``lon`` needed) make the clock that zone, checked as if declared; otherwise a
    question. A DST zone: its changes against the stamps as written
    (:func:`~heritage_bayes.io.clock.dst_structure`; a fixed clock is a question). A
    fixed offset: the same against the site's DST zone, or the DST zone of that offset
    without a site (:func:`~heritage_bayes.io.clock.dst_candidate`; a DST clock is a
    question naming that zone). With a longitude: the indoor temperature's daily peak
    against solar noon [h], a finding (a question when it comes more than half an hour
    before noon: no free-running room warms before the sun does).
    """
    question = None
    if declared is None:
        declared = _dst_from_stamps(layout, lat, lon, findings, where)
    if declared is None:
        site = lat is not None and lon is not None
        rules = None if site else _dst_rules(layout)
        if rules:
            return marked(
                f"the logger's stamps follow daylight-saving time ({rules}): name its zone, "
                "or give --latitude and --longitude to have it looked up"
            )
        example = (site and _clock.site_zone(lat, lon)) or "Europe/Amsterdam"
        fixed = _fixed_stamps(layout, example) if site else None
        if fixed:
            return marked(fixed)
        return marked(
            "the logger's clock: UTC, a fixed offset such as UTC+1, or a zone with "
            f"daylight-saving time such as {example} (see its settings or the software it "
            "was read out with)"
        )
    from heritage_bayes.io import parse_timezone

    tz = parse_timezone(declared)
    if not isinstance(tz, _dt.timezone):  # a DST zone: does the file follow its changes?
        times = _raw_times(layout)
        st = _clock.dst_structure(times, declared)
        findings.append(f"{where}: {st.describe()}")
        if st.verdict == "fixed":
            w, _ = _declared_offsets(declared, df_naive.index)
            question = marked(
                f"declared {declared}, but the file keeps a fixed clock ({st.describe()}); "
                f"the winter offset would be UTC{w:+g}"
            )
    else:  # a fixed offset: does the file jump at the DST changes of its region?
        off = tz.utcoffset(None).total_seconds() / 3600
        raw = _raw_times(layout)
        years = range(raw.min().year, raw.max().year + 1) if len(raw) else ()
        zone = _clock.dst_candidate(off, lat, lon, years)
        st = _clock.dst_structure(raw, zone) if zone else None
        if st is not None and st.changes:
            findings.append(f"{where}: {st.describe()}")
        if st is not None and st.verdict == "dst":
            question = marked(
                f"declared the fixed clock {declared}, but the stamps jump at the DST "
                f"changes of {zone} ({st.describe()}): declare that zone"
            )
    if lon is not None and "Ti" in df_naive:
        from heritage_bayes.io._common import localize

        loc = localize(df_naive.index.tz_localize(None), tz)
        peak = _clock.daily_cycle_phase(loc.utc, df_naive["Ti"].to_numpy()[loc.keep], min_range=1.0)
        lag = _clock._wrap(peak - _clock.solar_noon_utc(pd.DatetimeIndex(peak.index), lon))
        if np.isfinite(lag).sum() >= 5:
            med = float(np.nanmedian(lag))
            # a clock read with the right DST rule shows no hour's jump between seasons
            e = _clock.ClockEstimate("indoor peak", pd.Series(lag, index=peak.index))
            seasons = (
                f"; Apr-Sep {e.summer_h:+.1f} h, Nov-Feb {e.winter_h:+.1f} h"
                if e.summer_h is not None and e.winter_h is not None
                else ""
            )
            findings.append(
                f"{where}: the indoor temperature peaks {med:+.1f} h after solar noon on the "
                f"declared clock (median of {int(np.isfinite(lag).sum())} days{seasons})"
            )
            if med < -0.5 and question is None:
                question = marked(
                    f"declared {declared}, but the indoor temperature peaks {-med:.1f} h "
                    "before solar noon on that clock: no room warms before the sun and the "
                    "outdoor air do; is the logger's clock ahead of the declared one?"
                )
    return question or declared


@dataclass
class ClockSwitch:
    """A logger whose stamps follow the DST changes of its site's zone in some years and
    keep a fixed clock in others (a setting changed once): the part init keeps.

    ``zone``: the clock of the part kept (the DST zone, or its standard offset such as
    ``UTC+1``); ``start``, ``end``: the part's bounds on the file's clock (naive; None:
    open); ``why``: the evidence, in words.
    """

    zone: str
    start: pd.Timestamp | None
    end: pd.Timestamp | None
    why: str

    def keep(self, series):
        """``series`` (a Series or DataFrame on the file's clock, stamps as if UTC)
        within the part kept."""
        t = series.index.tz_localize(None) if series.index.tz is not None else series.index
        ok = np.ones(len(series), bool)
        if self.start is not None:
            ok &= t >= self.start
        if self.end is not None:
            ok &= t < self.end
        return series[ok]


def clock_switch(
    times: pd.DatetimeIndex, lat, lon, prefer: str | None = None
) -> ClockSwitch | None:
    """A change of clock within a logger file, from its stamps alone.

    Each calendar year's stamps are compared with the DST changes of the site's zone
    (:func:`~heritage_bayes.io.clock.dst_structure`): a year whose spring hour is
    skipped is on DST, a year with stamps inside the skipped hour on a fixed clock. When
    the years fall in two runs (DST, then fixed, or the reverse) the run of ``prefer``
    (``"dst"`` or ``"fixed"``: the kind of clock declared) is kept, else the longer run
    (the later on a tie), bounded at the 1st of January of the later run's first year
    (in winter the two clocks agree). The fixed clock is taken as the zone's standard
    offset (the logger's DST switched off). None without a site, for a zone without DST,
    or when the years do not fall in two runs (a logger that switched:
    docs/science/real_rooms.md, "Figures behind the code's choices").
    """
    if lat is None or lon is None or len(times) < 3:
        return None
    zone = _clock.site_zone(float(lat), float(lon))
    years = range(times.min().year, times.max().year + 1)
    if not zone or not _clock.keeps_dst(zone, years):
        return None
    verdicts = {}
    for y in years:
        v = _clock.dst_structure(times[times.year == y], zone).verdict
        if v is not None:
            verdicts[y] = v
    runs: list[list] = []  # [verdict, first year, last year]
    for y, v in verdicts.items():
        if runs and runs[-1][0] == v:
            runs[-1][2] = y
        else:
            runs.append([v, y, y])
    if len(runs) != 2:
        return None
    (v0, a0, b0), (v1, a1, b1) = runs
    kept = runs[0] if b0 - a0 > b1 - a1 else runs[1]
    if prefer in (v0, v1):
        kept = runs[0] if v0 == prefer else runs[1]
    cut = pd.Timestamp(year=a1, month=1, day=1)
    std = min(
        pd.Timestamp(year=a0, month=m, day=15, tz="UTC").tz_convert(zone).utcoffset()
        / pd.Timedelta(hours=1)
        for m in (1, 7)
    )
    kz = zone if kept[0] == "dst" else _fmt_h(std)
    words = {"dst": f"the DST changes of {zone}", "fixed": "a fixed clock"}
    why = (
        f"the stamps follow {words[v0]} in {a0}-{b0} and {words[v1]} in {a1}-{b1} (each "
        f"year's spring and autumn changes): the logger's clock was changed; the "
        f"{kept[1]}-{kept[2]} part is kept, on {kz}"
        + (" (the zone's standard offset)" if kept[0] == "fixed" else "")
        + f", from {cut:%Y-%m-%d}" * (kept is runs[1])
        + f", until {cut:%Y-%m-%d}" * (kept is runs[0])
    )
    return ClockSwitch(kz, cut if kept is runs[1] else None, cut if kept is runs[0] else None, why)


def _fixed_stamps(layout, zone: str) -> str | None:
    """The clock question for stamps that keep a fixed clock through the DST changes of
    the site's zone (the spring hour it skips is stamped): which fixed clock, naming the
    zone's standard offset; None when the stamps do not tell."""
    times = _raw_times(layout)
    if not len(times) or not _clock.keeps_dst(zone, range(times.min().year, times.max().year + 1)):
        return None
    st = _clock.dst_structure(times, zone)
    if st.verdict != "fixed":
        return None
    t = pd.Timestamp(year=int(times.min().year), month=1, day=15, tz="UTC").tz_convert(zone)
    std = _fmt_h(t.utcoffset() / pd.Timedelta(hours=1))
    return (
        f"the logger's stamps keep a fixed clock, not {zone}'s daylight-saving time "
        f"({st.describe()}): which one, UTC or {zone}'s standard time {std}? (see its "
        "settings or the software it was read out with)"
    )


def _dst_rules(layout) -> str | None:
    """Without a site: which daylight-saving rules a file's stamps follow, in words
    (the EU's, the US'), or None."""
    times = _raw_times(layout)
    for zone, words in (("Europe/Paris", "EU rules"), ("America/New_York", "US rules")):
        st = _clock.dst_structure(times, zone)
        if st.verdict == "dst":
            return f"{words}: {st.describe()}"
    return None


def _dst_from_stamps(layout, lat, lon, findings, where) -> str | None:
    """The site's DST zone when a file's own stamps follow its changes (a finding),
    else None."""
    found = _clock.detect_dst_zone(_raw_times(layout), lat, lon)
    if found is None:
        return None
    zone, st = found
    findings.append(
        f"{where}: no clock named, but the stamps follow daylight-saving time ({st.describe()}): "
        f"the clock of the site's zone {zone} (from its coordinates)"
    )
    return zone


def _raw_times(layout: TableLayout) -> pd.DatetimeIndex:
    """The stamps as written, in file order (for the DST structure)."""
    return raw_table(layout).index


def raw_table(layout: TableLayout, columns=()) -> pd.DataFrame:
    """``columns`` of the file as numbers (NaN where empty or unreadable), indexed by
    the stamps as written, in file order; rows without a readable stamp left out."""
    names = [layout.time_column] if isinstance(layout.time_column, str) else layout.time_column
    from heritage_bayes.io.readers.workbook import is_workbook, table_source

    wanted = set(names) | set(columns)
    raw = pd.read_csv(
        table_source(layout.path)(),
        sep=layout.sep,
        skiprows=layout.skiprows,
        encoding=None if is_workbook(layout.path) else layout.encoding,
        dtype=str,
        usecols=lambda c: str(c).strip() in wanted,
    )
    raw.columns = [str(c).strip() for c in raw.columns]
    text = raw[names[0]].str.strip()
    for n in names[1:]:
        text = text + " " + raw[n].str.strip()
    fmt = None if layout.time_format == "ISO8601" else layout.time_format
    t = pd.to_datetime(text, format=fmt, errors="coerce")
    out = pd.DataFrame(
        {
            c: pd.to_numeric(
                raw[c].str.strip().str.replace(layout.decimal, ".", regex=False), errors="coerce"
            ).to_numpy()
            for c in columns
        },
        index=pd.DatetimeIndex(t),
    )
    return out[out.index.notna()]


def clock_step(index: pd.DatetimeIndex) -> str:
    """The most frequent step of ``index`` as text (``'1h'``, ``'10min'``)."""
    from heritage_bayes.io._common import format_timedelta, modal_step

    st = modal_step(index)
    return format_timedelta(st) if st is not None else "?"


def to_utc(series: pd.Series, zone: str | None) -> pd.Series:
    """A series read on its file's clock (stamps as if UTC) moved to UTC by ``zone``
    (unchanged when the zone is an open question)."""
    from heritage_bayes.io import parse_timezone
    from heritage_bayes.io._common import localize

    if zone is None or str(zone).startswith(MARK):
        return series
    loc = localize(series.index.tz_localize(None), parse_timezone(zone))
    return pd.Series(series.to_numpy()[loc.keep], index=loc.utc)
