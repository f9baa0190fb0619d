"""Which clock a file keeps: measured from the sun, the outdoor daily cycle and DST jumps.

A logger or weather file states its time zone at best in a header (``t_UTC+2``,
``Date Time, GMT+01:00``) and often not at all; a config declares it (``timezone:``).
A wrong declaration shifts every reading: an hour for a daylight-saving zone declared on a
fixed clock (most loggers keep one) during half the year, several hours for a file from
another zone. Three detectors measure the clock from the data themselves:

* :func:`solar_clock_offset` — the sun: the irradiance-weighted mean time of day of each
  day, against the solar noon of the site computed from its longitude and the equation of
  time (Spencer 1971). Precise to minutes on a year of hourly data; needs a measured
  irradiance column and the site's longitude.
* :func:`outdoor_cycle_offset` — the outdoor air temperature's daily cycle, whose first
  harmonic peaks :data:`TE_PEAK_LAG_H` hours after solar noon (measured below). Coarser
  (about ±1 h: clouds, fronts, sea breezes shift it), used when there is no irradiance.
* :func:`dst_structure` — the wall-clock stamps of a file against a daylight-saving zone:
  a clock that follows DST skips the spring hour (a 23-hour day) and repeats the autumn
  hour (a 25-hour day); a fixed clock holds stamps inside the skipped hour and repeats
  nothing. The zone to test is the site's own (:func:`site_zone`: the IANA zone
  boundaries of ``timezonefinder``, offline), so a logger at 60.2 N 24.7 E on
  daylight-saving time is read as Europe/Helsinki (:func:`detect_dst_zone`), not as
  the first zone with the same rules.

Offsets are in hours east of UTC (``UTC+2`` is ``+2``). Each detector gives one value per
day; the medians by season tell a fixed clock (the same offset all year) from a DST clock
(one hour more from April to September).

References
----------
Spencer, J. W. (1971). Fourier series representation of the position of the sun.
Search 2(5), 172. (The equation of time, via
:func:`pvlib.solarposition.equation_of_time_spencer71`.)
"""

from __future__ import annotations

import datetime as _dt
from dataclasses import dataclass, field

import numpy as np
import pandas as pd

from heritage_bayes.io.zones import DST_ZONES, dst_candidate, keeps_dst, site_zone, zone_transitions

__all__ = [
    "DST_ZONES",
    "TE_PEAK_LAG_H",
    "ClockEstimate",
    "DSTStructure",
    "detect_dst_zone",
    "dst_candidate",
    "dst_structure",
    "outdoor_cycle_offset",
    "site_zone",
    "solar_clock_offset",
    "solar_noon_utc",
]

#: Lag [h] of the first harmonic of the outdoor air temperature's daily cycle behind
#: solar noon: the median of the daily phases on stations whose clocks are known
#: (docs/science/real_rooms.md, "Figures behind the code's choices").
TE_PEAK_LAG_H = 2.4

#: Months of the northern summer half (DST in force in Europe and North America) and of
#: the winter half, leaving out the months with a change.
_SUMMER = (4, 5, 6, 7, 8, 9)
_WINTER = (11, 12, 1, 2)


def solar_noon_utc(dates: pd.DatetimeIndex, longitude: float) -> np.ndarray:
    """Solar noon [h UTC] of each date at ``longitude`` [° east].

    ``12 - longitude / 15 - EoT / 60`` with the equation of time EoT [min] of Spencer
    (1971).
    """
    from pvlib.solarposition import equation_of_time_spencer71

    eot = np.asarray(equation_of_time_spencer71(np.asarray(dates.day_of_year)), dtype=float)
    return 12.0 - longitude / 15.0 - eot / 60.0


def _wrap(hours: np.ndarray) -> np.ndarray:
    """Hours wrapped into [-12, 12)."""
    return (np.asarray(hours, dtype=float) + 12.0) % 24.0 - 12.0


def _clock_hours(times: pd.DatetimeIndex) -> tuple[np.ndarray, pd.DatetimeIndex]:
    """Hour of day [h] of each stamp as written (naive) or in UTC (aware), and its date."""
    t = pd.DatetimeIndex(times)
    if t.tz is not None:
        t = t.tz_convert("UTC").tz_localize(None)
    hours = (t - t.normalize()) / pd.Timedelta(hours=1)
    return np.asarray(hours, dtype=float), t.normalize()


@dataclass
class ClockEstimate:
    """A clock measured from the data: per-day offsets and their summaries.

    Attributes
    ----------
    method : str
        ``"sun"`` or ``"outdoor temperature"``.
    daily : pandas.Series
        Offset [h east of UTC] of the file's clock measured on each usable day.
    """

    method: str
    daily: pd.Series = field(repr=False)

    @property
    def n_days(self) -> int:
        return int(self.daily.notna().sum())

    def _median(self, months=None) -> float | None:
        d = self.daily.dropna()
        if months is not None:
            d = d[d.index.month.isin(months)]
        return float(np.median(d)) if len(d) >= 5 else None

    @property
    def offset_h(self) -> float | None:
        """Median offset [h east of UTC] over all usable days (None below 5 days)."""
        return self._median()

    @property
    def summer_h(self) -> float | None:
        """Median offset [h] over April-September."""
        return self._median(_SUMMER)

    @property
    def winter_h(self) -> float | None:
        """Median offset [h] over November-February."""
        return self._median(_WINTER)

    @property
    def follows_dst(self) -> bool | None:
        """True when summer runs about an hour ahead of winter (a DST clock), False when
        both agree within 20 min, None without both seasons or in between."""
        s, w = self.summer_h, self.winter_h
        if s is None or w is None:
            return None
        if abs((s - w) - 1.0) < 0.35:
            return True
        if abs(s - w) < 1 / 3:
            return False
        return None

    def describe(self) -> str:
        """One line: the offset, the seasons, the number of days."""
        if self.offset_h is None:
            return f"{self.method}: too few usable days ({self.n_days})"
        text = f"{self.method}: UTC{_fmt_offset(self.offset_h)} (median of {self.n_days} days"
        if self.summer_h is not None and self.winter_h is not None:
            s, w = _fmt_offset(self.summer_h), _fmt_offset(self.winter_h)
            text += f"; Apr-Sep UTC{s}, Nov-Feb UTC{w}"
        return text + ")"

    def to_dict(self) -> dict:
        return {
            "method": self.method,
            "offset_h": self.offset_h,
            "summer_h": self.summer_h,
            "winter_h": self.winter_h,
            "days": self.n_days,
            "follows_dst": self.follows_dst,
        }


def _fmt_offset(h: float) -> str:
    sign = "+" if h >= 0 else "-"
    minutes = round(abs(h) * 60)
    return f"{sign}{minutes // 60}:{minutes % 60:02d}"


def solar_clock_offset(
    times,
    irradiance,
    longitude: float,
    *,
    interval=None,
    label: str = "end",
    min_daily_mean: float = 20.0,
) -> ClockEstimate:
    """Measure a file's clock from the solar phase of its irradiance.

    For each day, the irradiance-weighted circular mean of the time of day (the centre of
    the sunlit hours) is compared with the solar noon of the site; their difference is
    the offset of the file's clock from UTC.

    Parameters
    ----------
    times : pandas.DatetimeIndex
        The stamps: naive (the file's own clock, as written) or tz-aware (converted to
        UTC first: the offset is then the residual error of the declared zone, 0 when
        it is right).
    irradiance : array_like
        Global (or diffuse) horizontal irradiance [W/m²] at ``times``.
    longitude : float
        Site longitude [° east].
    interval : str or Timedelta, optional
        Averaging interval of the irradiance values (default: the modal step). Their
        centre is ``interval / 2`` before an end stamp, after a start stamp.
    label : {"end", "start", "instant"}
        Where the file stamps its averages (``"instant"``: the value at the stamp).
    min_daily_mean : float
        Days whose mean irradiance is below this [W/m²] (overcast, polar night, gaps)
        are skipped.

    Returns
    -------
    ClockEstimate
        Per-day offsets [h east of UTC] and their medians by season.

    Notes
    -----
    With hourly means, a start stamp read as an end stamp shifts the result by one hour:
    the offset and the stamp label cannot be told apart from irradiance alone.
    """
    hours, dates = _clock_hours(times)
    irr = np.asarray(irradiance, dtype=float)
    if interval is None:
        diffs = np.diff(pd.DatetimeIndex(times).as_unit("ns").asi8)
        diffs = diffs[diffs > 0]
        step_h = float(np.median(diffs)) / 3.6e12 if diffs.size else 1.0
    else:
        step_h = pd.Timedelta(interval) / pd.Timedelta(hours=1)
    shift = {"end": -step_h / 2, "start": step_h / 2, "instant": 0.0}[label]
    theta = 2 * np.pi * (hours + shift) / 24.0
    w = np.where(np.isfinite(irr) & (irr > 0), irr, 0.0)
    frame = pd.DataFrame(
        {"c": w * np.cos(theta), "s": w * np.sin(theta), "w": w, "n": np.isfinite(irr)},
        index=dates,
    )
    g = frame.groupby(level=0).sum()
    days = g.index
    mean_irr = g["w"] / g["n"].clip(lower=1)
    ok = (g["n"] >= 0.8 * 24.0 / step_h) & (mean_irr >= min_daily_mean)
    phase = np.arctan2(g["s"].to_numpy(), g["c"].to_numpy()) * 24.0 / (2 * np.pi)
    offset = _wrap(phase - solar_noon_utc(pd.DatetimeIndex(days), longitude))
    daily = pd.Series(np.where(ok, offset, np.nan), index=days, name="offset_h")
    return ClockEstimate("sun", daily)


def daily_cycle_phase(times, values, *, min_range: float = 3.0) -> pd.Series:
    """Hour [h, on the stamps' clock] at which each day's first harmonic peaks.

    Days with fewer than 20 of 24 hours or a range below ``min_range`` (overcast days
    barely cycle) are NaN.
    """
    hours, dates = _clock_hours(times)
    v = np.asarray(values, dtype=float)
    ok = np.isfinite(v)
    theta = 2 * np.pi * hours / 24.0
    frame = pd.DataFrame({"v": np.where(ok, v, np.nan), "h": hours}, index=dates)
    mean = frame.groupby(level=0)["v"].transform("mean").to_numpy()
    a = np.where(ok, v - mean, 0.0)
    parts = pd.DataFrame(
        {"c": a * np.cos(theta), "s": a * np.sin(theta), "n": ok, "hr": np.floor(hours)},
        index=dates,
    )
    g = parts.groupby(level=0).agg(c=("c", "sum"), s=("s", "sum"), n=("n", "sum"))
    hours_covered = parts[parts["n"]].groupby(level=0)["hr"].nunique()
    rng = frame.groupby(level=0)["v"].agg(lambda x: x.max() - x.min())
    good = (hours_covered.reindex(g.index).fillna(0) >= 20) & (rng.reindex(g.index) >= min_range)
    phase = (np.arctan2(g["s"], g["c"]) * 24.0 / (2 * np.pi)) % 24.0
    return pd.Series(np.where(good, phase, np.nan), index=g.index, name="peak_h")


def outdoor_cycle_offset(times, te, longitude: float) -> ClockEstimate:
    """Measure a file's clock from the daily cycle of the outdoor air temperature [°C].

    Per day: the hour of the first harmonic's peak, minus solar noon [h UTC] and the
    typical lag :data:`TE_PEAK_LAG_H`, is the clock's offset from UTC. Coarser than
    :func:`solar_clock_offset` (about ±1 h per season); use it when the file has no
    irradiance.
    """
    peak = daily_cycle_phase(times, te)
    noon = solar_noon_utc(pd.DatetimeIndex(peak.index), longitude)
    daily = pd.Series(_wrap(peak.to_numpy() - noon - TE_PEAK_LAG_H), index=peak.index)
    return ClockEstimate("outdoor temperature", daily)


@dataclass
class DSTStructure:
    """Wall-clock stamps against the changes of a DST zone (see :func:`dst_structure`).

    ``in_skipped_hour``: spring changes whose skipped hour holds stamps and no jump (a
    fixed clock); ``spring_gap``: spring changes where the stamps jump an hour within
    three steps of the change (a DST clock, also one that switches an hour early or late);
    ``autumn_repeat``: autumn changes whose repeated hour is stamped twice (a DST clock);
    ``autumn_single``: autumn changes stamped once (a fixed clock, or a logger that
    overwrote the repeat). ``changes``: changes inside the file's span with data around.
    """

    zone: str
    changes: int = 0
    in_skipped_hour: int = 0
    spring_gap: int = 0
    autumn_repeat: int = 0
    autumn_single: int = 0

    @property
    def verdict(self) -> str | None:
        """``"fixed"``, ``"dst"`` or None (no change covered, or mixed evidence)."""
        fixed = self.in_skipped_hour
        dst = self.spring_gap + self.autumn_repeat
        if fixed and not dst:
            return "fixed"
        if dst and not fixed:
            return "dst"
        return None

    def describe(self) -> str:
        return (
            f"{self.changes} DST changes of {self.zone} covered: {self.in_skipped_hour} "
            f"spring change(s) with stamps inside the skipped hour, {self.spring_gap} with "
            f"a one-hour jump; {self.autumn_repeat} autumn change(s) with the hour stamped "
            f"twice, {self.autumn_single} with it stamped once"
        )


def dst_structure(naive_times, zone: str) -> DSTStructure:
    """Compare a file's wall-clock stamps with the DST changes of ``zone``.

    Parameters
    ----------
    naive_times : pandas.DatetimeIndex
        The stamps as written in the file (no time zone), in file order.
    zone : str
        An IANA zone with DST, e.g. ``"Europe/Helsinki"``.
    """
    import zoneinfo

    t = pd.DatetimeIndex(naive_times).as_unit("ns")
    out = DSTStructure(zone)
    if len(t) < 3:
        return out
    tz = zoneinfo.ZoneInfo(zone)
    step = pd.Timedelta(int(np.median(np.diff(t.asi8))), unit="ns")
    if step <= pd.Timedelta(0) or step > pd.Timedelta(hours=1):
        return out
    values = t.asi8
    for year in range(t.min().year, t.max().year + 1):
        for wall, delta in zone_transitions(tz, year):
            start, end = wall, wall + delta
            lo = np.searchsorted(values, (start - 3 * step).value)
            hi = np.searchsorted(values, (end + 3 * step).value)
            near = t[lo:hi]
            if len(near) < 4:
                continue
            out.changes += 1
            if delta > pd.Timedelta(0):  # spring: [wall, wall + 1 h) does not exist
                # a jump of an hour near the change is a DST clock even when it jumped an
                # hour early or late, as real loggers do (docs/science/real_rooms.md,
                # "Figures behind the code's choices")
                if np.diff(near.asi8).max() >= (delta + step).value:
                    out.spring_gap += 1
                elif ((near >= start) & (near < end)).any():
                    out.in_skipped_hour += 1
            else:  # autumn: [wall - 1 h, wall) happens twice
                rep = near[(near >= end) & (near < start)]
                if rep.has_duplicates or (np.diff(near.asi8) < 0).any():
                    out.autumn_repeat += 1
                elif len(rep):
                    out.autumn_single += 1
    return out


#: A residual clock error below this [h] is not reported: hourly irradiance means leave
#: the stamp's place in the hour (start, middle, end) uncertain by half a step.
TOLERANCE_H = 0.75


#: The same for the outdoor daily cycle [h]: clouds, fronts and sea breezes move the
#: peak (the monthly medians of De Bilt 2011-2020 spread over ±0.5 h).
TE_TOLERANCE_H = 1.5


def check_declared_clock(
    df: pd.DataFrame, longitude: float | None, where: str, latitude: float | None = None
) -> dict:
    """Check the clock a table was read with (its UTC index) against its own data.

    Parameters
    ----------
    df : pandas.DataFrame
        A reader's output: UTC index, standard columns, ``attrs`` (``timezone``,
        ``averaged``, ``interval``, ``dropped``).
    longitude : float or None
        Site longitude [° east] (None: only the DST evidence of the reader is used).
    where : str
        The config key of the table, for the messages (``data.weather``).
    latitude : float, optional
        Site latitude [° north]: with the longitude, the DST zone a fixed clock is
        tested against, and named, is the site's own (:func:`dst_candidate`).

    Returns
    -------
    dict
        ``{"sun": ClockEstimate.to_dict() or None, "warnings": [str, ...]}``. A warning
        states the measured offset: the residual between the declared clock and the
        sun beyond :data:`TOLERANCE_H` (for the stamp label that fits best), a summer and
        winter that differ by an hour (a DST clock declared fixed, or the reverse), or
        rows the reader dropped inside a skipped spring hour (a fixed clock declared
        with DST).
    """
    attrs = df.attrs
    zone = attrs.get("timezone")
    warnings: list[str] = []
    dropped = attrs.get("dropped") or {}
    if dropped.get("nonexistent_dst"):
        warnings.append(
            f"{where}: {dropped['nonexistent_dst']} row(s) stamped inside the hour that "
            f"{zone} skips in spring (dropped): the file keeps a fixed clock, not {zone}; "
            f"declare its standard offset (e.g. UTC+1) as timezone"
        )
    dst = _dst_of_fixed(df.index, zone, latitude, longitude)
    if dst is not None and dst.verdict == "dst":
        warnings.append(
            f"{where}: declared the fixed clock {zone}, but the stamps jump at the DST "
            f"changes of {dst.zone} ({dst.describe()}): the file's clock follows "
            f"daylight-saving time; declare its zone (e.g. {dst.zone})"
        )
    irr = next((c for c in ("ghi", "dhi") if c in df.columns), None)
    if longitude is None:
        return {"sun": None, "warnings": warnings}
    if irr is None:  # no irradiance: the outdoor daily cycle, coarser
        if "Te" not in df.columns:
            return {"sun": None, "warnings": warnings}
        e = outdoor_cycle_offset(df.index, df["Te"], longitude)
        if e.offset_h is not None and abs(e.offset_h) > TE_TOLERANCE_H:
            warnings.append(
                f"{where}: the daily cycle of Te puts the file's clock {e.offset_h:+.1f} h "
                f"from the declared timezone {zone} ({e.describe()}; outdoor air peaks "
                f"{TE_PEAK_LAG_H:g} h after solar noon): the file's clock is about "
                f"UTC{_fmt_offset(_zone_offset(df.index, zone) + round(e.offset_h))}; "
                "correct timezone"
            )
        return {"sun": None, "outdoor_cycle": e.to_dict(), "warnings": warnings}
    averaged = irr in (attrs.get("averaged") or ())
    labels = ("end", "instant", "start") if averaged else ("instant", "end", "start")
    est = {
        lab: solar_clock_offset(
            df.index, df[irr], longitude, interval=attrs.get("interval"), label=lab
        )
        for lab in labels
    }
    first = est[labels[0]]
    if first.offset_h is None:
        return {"sun": None, "warnings": warnings}
    best = min(labels, key=lambda k: abs(est[k].offset_h))
    # the offset reported: the reading that puts the clock on a whole hour (clocks are
    # whole hours from UTC; the stamp's place in the interval is half a step uncertain)
    whole = min(labels, key=lambda k: abs(est[k].offset_h % 1 - 0.5) * -1 + 0.01 * (k != labels[0]))
    res = est[whole].offset_h
    as_read = "interval means ending at the stamp" if averaged else "values at the stamp"
    reading = {
        "end": "means ending at the stamp",
        "instant": "values at the stamp",
        "start": "means starting at the stamp",
    }
    if abs(est[best].offset_h) > TOLERANCE_H:
        alt = "" if whole == labels[0] else f"; {first.offset_h:+.1f} h as read: {as_read}"
        warnings.append(
            f"{where}: the sun in {irr} puts the file's clock {res:+.1f} h from the "
            f"declared timezone {zone} (irradiance as {reading[whole]}{alt}; "
            f"{est[whole].describe()}): the file's clock is "
            f"UTC{_fmt_offset(_zone_offset(df.index, zone) + res)}, not the declared "
            "one; correct timezone"
        )
    elif (
        first.summer_h is not None
        and first.winter_h is not None
        and abs(first.summer_h - first.winter_h) > 0.75
    ):
        years = range(df.index.min().year, df.index.max().year + 1)
        dst_name = dst_candidate(_zone_offset(df.index, zone), latitude, longitude, years)
        warnings.append(
            f"{where}: the sun puts April-September {first.summer_h - first.winter_h:+.1f} h "
            f"from November-February on the declared timezone {zone} "
            f"({first.describe()}): the file's clock "
            + (
                "follows daylight-saving time; declare its zone"
                + (f" ({dst_name})" if dst_name else " with daylight-saving time")
                if first.summer_h > first.winter_h
                else "is fixed; declare its standard offset (e.g. UTC+1)"
            )
        )
    return {"sun": first.to_dict() | {"best_label": best}, "warnings": warnings}


def _zone_offset(index: pd.DatetimeIndex, zone) -> float:
    """Winter UTC offset [h] of a declared zone (0 when unknown)."""
    from heritage_bayes.io._common import parse_timezone

    try:
        tz = parse_timezone(zone)
    except (ValueError, TypeError):
        return 0.0
    t = pd.Timestamp(year=int(index[0].year), month=1, day=15, tz="UTC").tz_convert(tz)
    return t.utcoffset().total_seconds() / 3600.0


def detect_dst_zone(
    naive_times, latitude: float | None, longitude: float | None
) -> tuple[str, DSTStructure] | None:
    """A daylight-saving clock recognised from a file's own stamps.

    The stamps as written (``naive_times``, file order) are compared with the changes
    of the site's zone (:func:`site_zone`): the spring hour missing and the autumn hour
    stamped twice (:func:`dst_structure`, verdict ``"dst"``) make the file's clock that
    zone. None without a site, for a zone without DST, or when the stamps do not follow
    its changes (a fixed clock, or no change covered).
    """
    if latitude is None or longitude is None:
        return None
    t = pd.DatetimeIndex(naive_times)
    if len(t) < 3:
        return None
    zone = site_zone(float(latitude), float(longitude))
    if not zone or not keeps_dst(zone, range(t.min().year, t.max().year + 1)):
        return None
    st = dst_structure(t, zone)
    return (zone, st) if st.verdict == "dst" else None


def _dst_of_fixed(
    index: pd.DatetimeIndex, zone, latitude=None, longitude=None
) -> DSTStructure | None:
    """For a table read with a fixed offset: its wall-clock stamps against the DST zone
    of the site, or of that offset without a site (a DST clock declared fixed shows a
    one-hour jump every spring)."""
    from heritage_bayes.io._common import parse_timezone

    try:
        tz = parse_timezone(zone)
    except (ValueError, TypeError):
        return None
    if not isinstance(tz, _dt.timezone) or len(index) < 3:
        return None
    off = tz.utcoffset(None).total_seconds() / 3600.0
    years = range(index.min().year, index.max().year + 1)
    name = dst_candidate(off, latitude, longitude, years)
    if name is None:
        return None
    wall = index.tz_convert("UTC").tz_localize(None) + pd.Timedelta(hours=off)
    return dst_structure(wall, name)
