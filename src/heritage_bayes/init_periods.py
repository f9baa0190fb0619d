"""The periods ``hbayes init`` proposes (:mod:`heritage_bayes.init_config`): the usable
span of overlapping data (gaps inside it split the record), the calibration and
validation periods in it, and a note when the validation holds weather the calibration
does not.

A record shorter than a year cannot hold every season in both periods. Split in time
with the validation at the end, a record from November to July calibrates on a winter
and validates on a summer: the model is then asked to extrapolate (the sun's gain on a
roof free of snow, summer conditions it never saw). Such a record validates on its
middle third instead (the calibration on both sides of it, the validation held out of
the fit and simulated through) or on its first third, whichever puts more of the
validation's outdoor conditions inside the calibration's (:func:`covered_share`), the
middle on a tie: the calibration then spans both seasons, and the validation tests an
interpolation.
"""

from __future__ import annotations

import numpy as np
import pandas as pd

from heritage_bayes.errors import DataError

__all__ = [
    "COVERED_SHARE",
    "MAX_GAP_H",
    "MIN_COVERAGE",
    "RANGE_MARGIN",
    "VALIDATION_MONTHS",
    "WARMER_K",
    "YEAR_DAYS",
    "choose_periods",
    "covered_share",
    "daily_conditions",
    "extrapolated_seasons",
    "longest_stretch",
    "present_hours",
    "usable_span",
]

#: Longest gap [h] bridged inside a period (the config's ``data.max_gap``).
MAX_GAP_H = 6
#: Least share of the hours with a reading, of the logger and of the weather each, in the
#: span init proposes: gaps inside it split the record (each segment its own start).
MIN_COVERAGE = 0.7
#: A stretch this long [days] or longer is split 8 months / 4 months (a year); shorter
#: ones 2/3 / 1/3, the validation's third at the end or at the start.
YEAR_DAYS = 365
#: Least share of the validation's days whose outdoor conditions lie inside the
#: calibration's range (:func:`covered_share`) for a short record to keep its validation
#: at the end.
COVERED_SHARE = 0.9
#: Share of the calibration's range of a daily condition by which a validation day may
#: lie beyond it and still count as covered (:func:`covered_share`).
RANGE_MARGIN = 0.1
#: Months of data after a whole calendar year from which that year calibrates and what
#: follows (up to a year) validates, rather than 8 and 4 months of one year.
VALIDATION_MONTHS = 8


def longest_stretch(ti: pd.Series, te: pd.Series) -> tuple[pd.Timestamp, pd.Timestamp, list[str]]:
    """The longest run of hours with both ``Ti`` and ``Te`` [°C], gaps of up to
    :data:`MAX_GAP_H` hours bridged: (start, end) [UTC] and notes on the gaps found.

    Raises
    ------
    DataError
        The files overlap in fewer than 48 hours (the message gives both spans).
    """
    both = present_hours(ti, te)
    if len(both) < 48:
        raise DataError(
            f"the logger and weather files overlap in {len(both)} hour(s) only "
            f"(logger {ti.index[0]} to {ti.index[-1]}, weather {te.index[0]} to {te.index[-1]})"
        )
    gap_h = np.diff(both) / pd.Timedelta(hours=1)
    gaps = np.flatnonzero(gap_h > MAX_GAP_H)
    starts = np.r_[0, gaps + 1]
    ends = np.r_[gaps, len(both) - 1]
    k = int(np.argmax(both[ends] - both[starts]))
    notes = [f"gap of {gap_h[g]:.0f} h from {both[g]:%Y-%m-%d %H:%M} UTC" for g in gaps[:5]] + (
        [f"... {len(gaps) - 5} more"] if len(gaps) > 5 else []
    )
    return both[starts[k]], both[ends[k]] + pd.Timedelta(hours=1), notes


def usable_span(ti: pd.Series, te: pd.Series) -> tuple[pd.Timestamp, pd.Timestamp, str, list]:
    """The span ``[start, end)`` [UTC] init proposes periods in (:func:`choose_periods`)
    and what it is, with the share of the hours with a reading of the logger (``ti``) and
    of the weather (``te``) over those periods: the whole overlap of the files when the
    periods chosen in it have at least :data:`MIN_COVERAGE` of each; else the most recent
    12 months that have; else the longest stretch without a gap over :data:`MAX_GAP_H`
    hours (:func:`longest_stretch`). Gaps inside are normal: the calibration splits the
    record at those too long to bridge. Returns (start, end, what, notes on the gaps).

    Raises
    ------
    DataError
        The files overlap in fewer than 48 hours (see :func:`longest_stretch`).
    """
    s, e, notes = longest_stretch(ti, te)
    hi_t, hi_e = ti.dropna().index.floor("h"), te.dropna().index.floor("h")
    lo = max(hi_t.min(), hi_e.min()).ceil("D")
    hi = (min(hi_t.max(), hi_e.max()) + pd.Timedelta(hours=1)).floor("D")
    if hi - lo < pd.Timedelta(days=2):
        return s, e, f"the longest stretch without a gap over {MAX_GAP_H} h", notes
    hours = pd.date_range(lo, hi, freq="h", inclusive="left")
    cum = [np.r_[0, np.cumsum(hours.isin(h))] for h in (hi_t.unique(), hi_e.unique())]

    def coverage(start, end) -> list[float]:
        i, j = hours.searchsorted(start), hours.searchsorted(end)
        return [(c[j] - c[i]) / max(j - i, 1) for c in cum]

    def what(label, cov):
        return (
            f"{label} (a logger reading in {cov[0]:.1%} of the hours, a weather reading in "
            f"{cov[1]:.1%}; a gap over {MAX_GAP_H} h splits the record, each part with its "
            "own initial state)"
        )

    cs, ce, vs, ve, _ = choose_periods(lo, hi)
    cov = coverage(pd.Timestamp(min(cs, vs), tz="UTC"), pd.Timestamp(max(ce, ve), tz="UTC"))
    if min(cov) >= MIN_COVERAGE:
        return lo, hi, what("the overlap of the files", cov), notes
    for end in pd.date_range(lo, hi, freq="D")[::-1]:  # the latest 12 months first
        start = end - pd.DateOffset(years=1)
        if start < lo:
            break
        if min(cov := coverage(start, end)) >= MIN_COVERAGE:
            return start, end, what("the most recent 12 months with data", cov), notes
    return s, e, (
        f"the longest stretch without a gap over {MAX_GAP_H} h (no year with "
        f"{MIN_COVERAGE:.0%} of the hours from both files)"
    ), notes  # fmt: skip


def present_hours(ti: pd.Series, te: pd.Series) -> pd.DatetimeIndex:
    """The hours [UTC] in which both ``ti`` and ``te`` have a value, sorted."""
    a = ti.dropna().index.floor("h").unique()
    b = te.dropna().index.floor("h").unique()
    return a.intersection(b).sort_values()


def choose_periods(
    s: pd.Timestamp,
    e: pd.Timestamp,
    present: pd.DatetimeIndex | None = None,
    span: str = "the longest stretch",
    daily: pd.DataFrame | None = None,
) -> tuple[str, str, str, str, str]:
    """Calibration ``[cs, ce)`` and validation ``[vs, ve)`` in whole UTC days
    within the stretch ``[s, e)``, and why: the most recent whole calendar year followed
    by :data:`VALIDATION_MONTHS` or more to calibrate, and up to a year after it to
    validate (every season in both; the room as it is now, which a model for projections
    and interventions describes); else the most recent 12 whole months followed by as
    many; else the most recent whole calendar year (8 months to
    calibrate, 4 to validate), else the first 12 whole months, else (a record shorter
    than a year) the stretch's first 2/3 to calibrate and the rest to validate, unless
    with the outdoor conditions ``daily`` (:func:`daily_conditions`) fewer than
    :data:`COVERED_SHARE` of the validation's days lie inside the calibration's range
    (:func:`covered_share`) and more do with the validation's third in the middle or at
    the start (:func:`_short_split`): then that third validates and the rest calibrates.
    With ``present`` (the hours with an input reading), the start, the end and a
    calibration that follows the validation start at midnights with a reading: a period
    never starts or ends inside an input gap (or after the last reading), which the
    simulation cannot bridge; a validation inside the calibration may (it is simulated
    through). ``span`` says what ``[s, e)`` is, for ``why``. Returns ``(cs, ce, vs, ve,
    why)`` as text: ``ce == vs`` (the validation after the calibration), ``ve == cs``
    (before it) or ``cs < vs < ve < ce`` (inside it)."""
    day = pd.Timedelta(days=1)
    s0 = s.ceil("D")
    e0 = e.floor("D")

    jan = pd.Timestamp(year=s0.year + int((s0.month, s0.day) > (1, 1)), month=1, day=1, tz=s0.tz)
    if s0.day != 1 and (e - s0).days >= YEAR_DAYS + 31:
        s0 = (s0 + pd.offsets.MonthBegin(1)).normalize()
    which, val_first, inside = "first", False, None
    # a whole calendar year to calibrate and VALIDATION_MONTHS or more after it: the
    # most recent such year; every season in both periods
    cal_year = pd.Timestamp(year=e0.year - 1, month=1, day=1, tz=s0.tz)
    if cal_year + pd.DateOffset(years=1, months=VALIDATION_MONTHS) > e0:
        cal_year -= pd.DateOffset(years=1)
    if cal_year >= jan:
        mid = cal_year + pd.DateOffset(years=1)
        end = min(mid + pd.DateOffset(years=1), e0)
        s0 = cal_year
        why = (
            f"the most recent whole calendar year of {span} with "
            f"{VALIDATION_MONTHS} months or more after it to calibrate (all seasons; the "
            "room as it is now), up to a year after it to validate"
        )
    elif (e0 - (s0 + pd.DateOffset(years=1))).days >= 30 * VALIDATION_MONTHS:
        # no calendar year, but 12 whole months and VALIDATION_MONTHS after them: the
        # most recent such 12 months, a year after them to validate where the data
        # reach that far (all seasons in both periods, as above)
        last_year = e0 - pd.DateOffset(years=1)
        mid = max(s0 + pd.DateOffset(years=1), last_year.normalize().replace(day=1))
        s0, end = mid - pd.DateOffset(years=1), min(mid + pd.DateOffset(years=1), e0)
        why = (
            f"the most recent 12 whole months of {span} with {VALIDATION_MONTHS} months or "
            "more after them to calibrate (all seasons; the room as it is now), up to a "
            "year after them to validate"
        )
    else:
        if e0 >= jan + pd.DateOffset(years=1):  # a whole calendar year: the reporting year
            s0 = pd.Timestamp(year=e0.year - 1, month=1, day=1, tz=s0.tz)  # the most recent
            which = "most recent" if s0 > jan else which
        if (e0 - s0).days >= YEAR_DAYS:
            end = s0 + pd.DateOffset(months=12)
            mid = s0 + pd.DateOffset(months=8)
            what = "calendar year" if (s0.month, s0.day) == (1, 1) else "year"
            why = (
                f"the {which} whole {what} of {span} (all seasons): 8 months to "
                "calibrate, 4 to validate"
            )
        else:
            end = e0
            mid, inside, where, why = _short_split(s0, e0, daily, span)
            val_first = where == "first"
    if present is not None and len(present):  # no start or end inside a short gap
        have = set(present)
        moved = s0
        while moved < mid and moved not in have:
            moved += day
        end_moved = end
        while end_moved > (inside or mid) and end_moved not in have:
            end_moved -= day
        mid_moved = mid  # a calibration after the validation starts with a reading
        while val_first and mid_moved < end_moved and mid_moved not in have:
            mid_moved += day
        if (moved, end_moved, mid_moved) != (s0, end, mid):
            why += "; start and end moved off gaps in the data"
        s0, end, mid = moved, end_moved, mid_moved
    f = "%Y-%m-%d"
    a, m, b = s0.strftime(f), mid.strftime(f), end.strftime(f)
    if inside is not None:  # the validation in the middle: the calibration around it
        return a, b, m, inside.strftime(f), why
    return (m, b, a, m, why) if val_first else (a, m, m, b, why)


def _short_split(s0, e0, daily, span) -> tuple:
    """A record ``[s0, e0)`` shorter than a year: ``(mid, inside, where, why)``, where
    the validation goes (``"end"``, ``"first"`` or ``"middle"``) as
    :func:`choose_periods` says; ``mid`` the midnight between the periods (for
    ``"middle"`` the validation's start), ``inside`` the validation's end for
    ``"middle"``, else None. The validation's third stays at the end when
    :data:`COVERED_SHARE` of its days are covered or no other third covers more; else
    the middle or the first third, whichever covers more (the middle on a tie: the
    calibration then holds both ends of the record)."""
    day = pd.Timedelta(days=1)
    n = (e0 - s0).days
    late, early = s0 + day * round(n * 2 / 3), s0 + day * round(n / 3)
    why = f"{span}: its first 2/3 to calibrate, the rest to validate"
    if daily is None:
        return late, None, "end", why
    at_end = covered_share(daily, (s0, late), (late, e0))
    at_start = covered_share(daily, (early, e0), (s0, early))
    at_middle = covered_share(daily, [(s0, early), (late, e0)], (early, late))
    what = "outdoor temperature" + (" and irradiance" if daily.shape[1] > 1 else "")
    shares = (
        f"{at_end:.0%} of the validation's days within the calibration's range of daily "
        f"mean {what}, widened by {RANGE_MARGIN:.0%}, with the validation at the end; "
        f"{at_middle:.0%} in the middle; {at_start:.0%} first"
    )
    if at_end >= COVERED_SHARE or max(at_start, at_middle) <= at_end:
        return late, None, "end", f"{why} ({shares})"
    if at_middle >= at_start:
        return early, late, "middle", (
            f"{span}, shorter than a year: its middle third to validate, held out of the "
            "fit, the rest on both sides to calibrate, so that the calibration spans the "
            f"validation's conditions and both ends of the record ({shares}: a model "
            "calibrated on one season would be validated on another it never saw); the "
            "validation is simulated through from the calibration's start"
        )  # fmt: skip
    return early, None, "first", (
        f"{span}, shorter than a year: its first 1/3 to validate, the rest to calibrate, "
        f"so that the calibration spans the validation's conditions ({shares}: a model "
        "calibrated on one season would be validated on another it never saw); the "
        "validation starts from the steady state of its own first inputs"
    )  # fmt: skip


def daily_conditions(te: pd.Series, irradiance: pd.Series | None = None) -> pd.DataFrame:
    """Daily means [UTC days] of the outdoor temperature ``Te`` [°C] and, when measured,
    of the global irradiance ``ghi`` [W/m²]: the conditions :func:`covered_share`
    compares."""
    cols = {"Te": te} | ({} if irradiance is None else {"ghi": irradiance})
    d = pd.DataFrame({k: v.resample("1D").mean() for k, v in cols.items()})
    d.index = d.index.tz_localize(None) if d.index.tz is not None else d.index
    return d.dropna(how="all")


def covered_share(daily: pd.DataFrame, cal, val: tuple) -> float:
    """The share of the validation's days ``[val[0], val[1])`` whose every column of
    ``daily`` (:func:`daily_conditions`) lies within the range (least to greatest daily
    value) of the calibration's days ``[cal[0], cal[1])`` (or of the days of a list of
    such ranges: a calibration around the validation), widened at both ends by
    :data:`RANGE_MARGIN` of its width (a day a little darker or colder than any in the
    calibration is not a new season): 1 when the calibration has seen every validation
    day's weather, near 0 for a winter calibrating a summer. 1 when either period has no
    day."""

    def days(a, b):
        a, b = (pd.Timestamp(x).tz_localize(None) if pd.Timestamp(x).tz else x for x in (a, b))
        return daily[(daily.index >= pd.Timestamp(a)) & (daily.index < pd.Timestamp(b))]

    ranges = cal if isinstance(cal, list) else [cal]
    c, v = pd.concat([days(*r) for r in ranges]), days(*val)
    if c.empty or v.empty:
        return 1.0
    margin = RANGE_MARGIN * (c.max() - c.min())
    lo, hi = c.min() - margin, c.max() + margin
    inside = ((v >= lo) & (v <= hi)) | v.isna() | (lo.isna() | hi.isna())
    return float(inside.all(axis=1).mean())


#: Validation's warm days [K] (95th percentile of the daily mean outdoor temperature)
#: beyond the calibration's: the validation tests an extrapolation.
WARMER_K = 3.0


def extrapolated_seasons(te: pd.Series, cs, ce, vs, ve) -> str | None:
    """A note when the validation ``[vs, ve)`` holds warmer weather than any in the
    calibration ``[cs, ce)`` (without the days of a validation inside it; a record
    shorter than a year, split in time: a winter to calibrate, a summer to validate):
    the 95th percentile of the daily mean outdoor
    temperature [°C] higher by :data:`WARMER_K` or more. The sun's gain and the summer's
    conditions (a roof free of snow) are then learned from a season they do not hold;
    None otherwise (what it costs on a real attic: docs/science/real_rooms.md, "Figures
    behind the code's choices").
    """
    d = te.resample("1D").mean().dropna()
    d.index = d.index.tz_localize(None) if d.index.tz is not None else d.index
    in_val = (d.index >= pd.Timestamp(vs)) & (d.index < pd.Timestamp(ve))
    cal = d[(d.index >= pd.Timestamp(cs)) & (d.index < pd.Timestamp(ce)) & ~in_val]
    val = d[in_val]
    if len(cal) < 10 or len(val) < 10:
        return None
    c95, v95 = float(np.percentile(cal, 95)), float(np.percentile(val, 95))
    if v95 - c95 < WARMER_K:
        return None
    return (
        f"the validation is warmer than any of the calibration (95th percentile of the daily "
        f"mean outdoor temperature {v95:.1f} °C against {c95:.1f} °C): the calibration holds "
        "no summer, so the sun's gain and summer conditions (a roof free of snow) are "
        "extrapolated and the validation FIT measures that; a record of a year or more "
        "calibrates all seasons"
    )
