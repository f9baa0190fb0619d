"""The periods ``hbayes init`` proposes (:mod:`heritage_bayes.init_config`): the usable
span of overlapping data (gaps inside it split the record), the calibration and
validation periods in it, and a note when the validation holds weather the calibration
does not.
"""

from __future__ import annotations

import numpy as np
import pandas as pd

from heritage_bayes.errors import DataError

__all__ = [
    "MAX_GAP_H",
    "MIN_COVERAGE",
    "VALIDATION_MONTHS",
    "WARMER_K",
    "YEAR_DAYS",
    "choose_periods",
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
#: ones 2/3 / 1/3.
YEAR_DAYS = 365
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

    cs, _, _, ve, _ = choose_periods(lo, hi)
    cov = coverage(pd.Timestamp(cs, tz="UTC"), pd.Timestamp(ve, tz="UTC"))
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
) -> tuple[str, str, str, str, str]:
    """Calibration ``[start, mid)`` and validation ``[mid, end)`` in whole UTC days
    within the stretch ``[s, e)``, and why: the most recent whole calendar year followed
    by :data:`VALIDATION_MONTHS` or more to calibrate, and up to a year after it to
    validate (every season in both; the room as it is now, which a model for projections
    and interventions describes); else the most recent 12 whole months followed by as
    many; else the most recent whole calendar year (8 months to
    calibrate, 4 to validate), else the first 12 whole months, else the
    stretch's first 2/3 and the rest. With ``present`` (the hours with an input
    reading), the start and the end are midnights with a reading: a period never starts
    or ends inside an input gap (or after the last reading), which the simulation
    cannot bridge. ``span`` says what ``[s, e)`` is, for ``why``. Returns ``(start, mid,
    mid, end, why)`` as text."""
    day = pd.Timedelta(days=1)
    s0 = s.ceil("D")
    e0 = e.floor("D")

    jan = pd.Timestamp(year=s0.year + int((s0.month, s0.day) > (1, 1)), month=1, day=1, tz=s0.tz)
    if s0.day != 1 and (e - s0).days >= YEAR_DAYS + 31:
        s0 = (s0 + pd.offsets.MonthBegin(1)).normalize()
    which = "first"
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
            mid = s0 + day * round((e0 - s0).days * 2 / 3)
            why = f"{span}: its first 2/3 to calibrate, the rest to validate"
    if present is not None and len(present):  # no start or end inside a short gap
        have = set(present)
        moved = s0
        while moved < mid and moved not in have:
            moved += day
        end_moved = end
        while end_moved > mid and end_moved not in have:
            end_moved -= day
        if (moved, end_moved) != (s0, end):
            why += "; start and end moved off gaps in the data"
        s0, end = moved, end_moved
    f = "%Y-%m-%d"
    return s0.strftime(f), mid.strftime(f), mid.strftime(f), end.strftime(f), why


#: Validation's warm days [K] (95th percentile of the daily mean outdoor temperature)
#: beyond the calibration's: the validation tests an extrapolation.
WARMER_K = 3.0


def extrapolated_seasons(te: pd.Series, cs, ce, ve) -> str | None:
    """A note when the validation ``[ce, ve)`` holds warmer weather than any in the
    calibration ``[cs, ce)`` (a record shorter than a year, split in time: a winter to
    calibrate, a summer to validate): the 95th percentile of the daily mean outdoor
    temperature [°C] higher by :data:`WARMER_K` or more. The sun's gain and the summer's
    conditions (a roof free of snow) are then learned from a season they do not hold;
    None otherwise (what it costs on a real attic: docs/science/real_rooms.md, "Figures
    behind the code's choices").
    """
    d = te.resample("1D").mean().dropna()
    d.index = d.index.tz_localize(None) if d.index.tz is not None else d.index
    cal = d[(d.index >= pd.Timestamp(cs)) & (d.index < pd.Timestamp(ce))]
    val = d[(d.index >= pd.Timestamp(ce)) & (d.index < pd.Timestamp(ve))]
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
