"""The room's operation year by year, for the periods ``hbayes init`` proposes
(:mod:`heritage_bayes.init_config`): a long record of a controlled room often holds more
than one way of running it, and a model calibrated under one and validated under another
tests the change, not the model.

A calendar year's *regime* is three signatures init also proposes the model from
(:mod:`heritage_bayes.init_model`), each measured on that year's hourly data [UTC]:

* **the RH band**: indoor RH between its 5th and 95th percentiles; held (a humidistat or a
  dehumidifier) at :data:`~heritage_bayes.init_model.BAND_MAX_PCT` points or under, and
  under :data:`~heritage_bayes.init_model.BAND_RATIO` of the outdoor span; free at
  :data:`BAND_MARGIN_PCT` points above that (or over the outdoor ratio); between the two,
  unclear. Needs :data:`MIN_RH_DAYS` days of RH in the year.
* **the heating floor** (:func:`heritage_bayes.init_checks.heating_floor` on the year):
  heated or free-running, and the floor [°C]; two heated years differ when their floors
  differ by :data:`FLOOR_SHIFT_K` or more. Needs :data:`MIN_COLD_DAYS` days with the
  outdoor air 5 K or more below the record's floor (a winter).
* **the summer excess**: the indoor minus the outdoor mean temperature [K] over the
  year's three warmest months (a constant heat gain: a dehumidifier's or a neighbour's
  heat, lights); two years differ when their excesses differ by :data:`EXCESS_SHIFT_K`
  or more. Needs :data:`MIN_MONTHS` months with 20 days of data (a summer).

A signature a year cannot measure, or measures as unclear, agrees with any other.
Walking back from the most recent year, a year joins the stretch while none of its
signatures clearly differs from the stretch's; the first that does ends it (the
operation changed). :func:`regime_stretch` returns the most recent such stretch long
enough for a calendar year to calibrate and :data:`~heritage_bayes.init_periods.
VALIDATION_MONTHS` months after it to validate; the calibration and validation then
describe one regime.

A heating set-point is set for a winter, and a winter straddles the calendar year: the
**heating level** is measured per heating season (July to June, :func:`season_levels`:
the indoor daily mean on heated days at a common outdoor temperature). A level moved
by :data:`LEVEL_SHIFT_K` or more between two winters is a set-point moved by hand,
which a model with one set-point cannot carry; within the calendar years run one way,
:func:`level_stretch` keeps the most recent heating seasons at one level when they are
long enough (12 months and the validation months after them).

The signatures of a real logger file year by year and season by season:
docs/science/real_rooms.md, "Figures behind the code's choices".
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import pandas as pd

from heritage_bayes.init_checks import heating_floor
from heritage_bayes.init_model import BAND_MAX_PCT, BAND_RATIO
from heritage_bayes.init_periods import VALIDATION_MONTHS

__all__ = [
    "SeasonLevel",
    "YearRegime",
    "level_stretch",
    "regime_stretch",
    "season_levels",
    "year_regimes",
]

#: Points [% RH] above :data:`~heritage_bayes.init_model.BAND_MAX_PCT` at which a band is
#: clearly free, and below it at which it is clearly held.
BAND_MARGIN_PCT = 3.0
#: Change of the summer excess [K] between two years that is a gain switched on or off.
EXCESS_SHIFT_K = 2.0
#: Shift of the heating floor [K] between two heated years that is a new set-point.
FLOOR_SHIFT_K = 2.0
#: Days of indoor RH a year needs for its band.
MIN_RH_DAYS = 90
#: Days 5 K or more below the record's floor a year needs for its heating signature.
MIN_COLD_DAYS = 60
#: Months with 20 days of data a year needs for its summer excess.
MIN_MONTHS = 9
#: Move of the heating level [K] between two heating seasons in a row that one set-point
#: cannot carry: three standard errors of the difference of two seasons' levels when a
#: season's monthly levels scatter by 0.4 K over 4-5 months (Ørholm's).
LEVEL_SHIFT_K = 0.8
#: Heated days a heating season needs for its level.
MIN_HEAT_DAYS = 30


@dataclass(frozen=True)
class YearRegime:
    """One calendar year's signatures (None: not measurable in the year).

    Attributes
    ----------
    year : int
    rh_width : float or None
        Indoor RH span, 5th to 95th percentile [% points].
    rh_held : bool or None
        The band held (True), free (False) or unclear (None).
    heated : bool or None
        A heating floor held in the year's winter.
    floor : float or None
        The year's floor [°C] (5th percentile of the daily indoor minima).
    excess : float or None
        Indoor minus outdoor mean temperature over the three warmest months [K].
    """

    year: int
    rh_width: float | None = None
    rh_held: bool | None = None
    heated: bool | None = None
    floor: float | None = None
    excess: float | None = None

    def describe(self) -> str:
        """The year in words: ``2019: RH band 23 points (free), floor 10.0 °C, ...``."""

        def cls(v, yes, no):
            return "unclear" if v is None else yes if v else no

        parts = []
        if self.rh_width is not None:
            parts.append(
                f"RH band {self.rh_width:.0f} points ({cls(self.rh_held, 'held', 'free')})"
            )
        if self.heated is not None:
            parts.append(
                f"heating floor {self.floor:.1f} °C" if self.heated else "no heating floor"
            )
        if self.excess is not None:
            parts.append(f"summer {self.excess:+.1f} K above outdoors")
        return f"{self.year}: " + (", ".join(parts) or "too little data")

    def differs(self, other: YearRegime) -> list[str]:
        """The signatures that clearly differ from ``other``'s, in words."""
        out = []
        if None not in (self.rh_held, other.rh_held) and self.rh_held != other.rh_held:
            out.append("the RH band")
        if None not in (self.heated, other.heated) and self.heated != other.heated:
            out.append("the heating floor")
        elif self.heated and other.heated and abs(self.floor - other.floor) >= FLOOR_SHIFT_K:
            out.append("the heating set-point")
        if None not in (self.excess, other.excess):
            if abs(self.excess - other.excess) >= EXCESS_SHIFT_K:
                out.append("the summer gain")
        return out

    def merged(self, older: YearRegime) -> YearRegime:
        """This stretch's signatures, those it cannot tell taken from ``older``."""
        kw = {}
        for a, b in (("rh_held", "rh_width"), ("heated", "floor"), ("excess", "excess")):
            src = self if getattr(self, a) is not None else older
            kw[a], kw[b] = getattr(src, a), getattr(src, b)
        return YearRegime(self.year, **kw)


def _unclear(value: float, lo: float, hi: float) -> bool | None:
    """True at or below ``lo``, False at or above ``hi``, None between."""
    return True if value <= lo else False if value >= hi else None


def year_regimes(
    ti: pd.Series, te: pd.Series, rhi: pd.Series | None, rhe: pd.Series | None, start, end
) -> list[YearRegime]:
    """Each calendar year's signatures in ``[start, end)`` (UTC), oldest first.

    Parameters
    ----------
    ti, te : pandas.Series
        Indoor and outdoor temperature [°C] on UTC stamps.
    rhi, rhe : pandas.Series or None
        Indoor and outdoor relative humidity [%] on UTC stamps.
    start, end : pandas.Timestamp
        The span [UTC].
    """

    def hourly(s):
        if s is None:
            return None
        s = s[(s.index >= start) & (s.index < end)].dropna()
        return s.resample("1h").mean() if len(s) else None

    ti, te, rhi, rhe = (hourly(s) for s in (ti, te, rhi, rhe))
    if ti is None or te is None:
        return []
    floor_all, _, _ = heating_floor(ti, te)
    out = []
    for year in range(start.year, (end - pd.Timedelta(hours=1)).year + 1):
        sl = slice(f"{year}-01-01", f"{year}-12-31 23:59")
        t, o = ti[sl], te[sl]
        kw: dict = {}
        if rhi is not None and rhi[sl].count() >= 24 * MIN_RH_DAYS:
            lo, hi = np.nanpercentile(rhi[sl], [5, 95])
            width = float(hi - lo)
            held = _unclear(width, BAND_MAX_PCT - BAND_MARGIN_PCT, BAND_MAX_PCT + BAND_MARGIN_PCT)
            if rhe is not None and rhe[sl].count() >= 24 * MIN_RH_DAYS:
                elo, ehi = np.nanpercentile(rhe[sl], [5, 95])
                held = False if width > BAND_RATIO * (ehi - elo) else held
            kw.update(rh_width=width, rh_held=held)
        cold = int((o.resample("1D").mean() < floor_all - 5).sum()) if len(o) else 0
        if cold >= MIN_COLD_DAYS:
            floor, held_days, ndays = heating_floor(t, o)
            kw.update(heated=held_days >= max(20, 0.05 * ndays), floor=floor)
        both = pd.concat([t.rename("ti"), o.rename("te")], axis=1).dropna()
        count = both["ti"].resample("MS").count()
        months = both.resample("MS").mean()[count >= 24 * 20]
        if len(months) >= MIN_MONTHS:
            warm = months.nlargest(3, "te")
            kw["excess"] = float((warm["ti"] - warm["te"]).mean())
        out.append(YearRegime(year, **kw))
    return out


def regime_stretch(
    ti: pd.Series,
    te: pd.Series,
    rhi: pd.Series | None,
    rhe: pd.Series | None,
    start: pd.Timestamp,
    end: pd.Timestamp,
) -> tuple[pd.Timestamp, pd.Timestamp, list[str]]:
    """The most recent stretch of ``[start, end)`` [UTC] run one way (see the module
    docstring), long enough for a calendar year to calibrate and
    :data:`~heritage_bayes.init_periods.VALIDATION_MONTHS` after it to validate: its
    ``(start, end)`` and notes (each year's signatures, the changes found, the choice).
    The whole span when no year differs, or no stretch is long enough (a note says so).
    Within the calendar years run one way, the heating seasons whose heating level
    agrees (:func:`season_levels`, :func:`level_stretch`) narrow it further.
    """
    s, e, notes = _year_stretch(ti, te, rhi, rhe, start, end)

    def inside(x):
        return x[(x.index >= s) & (x.index < e)]

    ls, le, level_notes = level_stretch(season_levels(inside(ti), inside(te)), s, e)
    return ls, le, notes + level_notes


def _year_stretch(ti, te, rhi, rhe, start, end):
    """:func:`regime_stretch` on the calendar years' signatures alone."""
    years = year_regimes(ti, te, rhi, rhe, start, end)
    if len(years) < 2:
        return start, end, []
    notes = ["operation by year: " + "; ".join(y.describe() for y in years)]
    runs = []  # (first year, last year, what ended it) newest first
    i = len(years) - 1
    while i >= 0:
        ref, j, why = years[i], i - 1, None
        while j >= 0:
            if changed := years[j].differs(ref):
                why = (years[j].year, changed)
                break
            ref, j = ref.merged(years[j]), j - 1
        runs.append((years[j + 1].year, years[i].year, why))
        i = j
    if len(runs) == 1:
        return start, end, notes
    need = pd.DateOffset(years=1, months=VALIDATION_MONTHS)
    for first, last, _ in runs:
        s = max(start, pd.Timestamp(year=first, month=1, day=1, tz=start.tz))
        e = min(end, pd.Timestamp(year=last + 1, month=1, day=1, tz=start.tz))
        if s + need <= e:
            changes = [
                f"{', '.join(w[1])} changed between {w[0]} and {w[0] + 1}"
                for _, _, w in runs
                if w is not None
            ]
            notes.append(
                "the operation changed within the record ("
                + "; ".join(changes)
                + f"): the periods are in {s:%Y-%m-%d} to {e:%Y-%m-%d}, "
                + ("the most recent" if (first, last) == runs[0][:2] else "the most recent long")
                + " stretch run one way, so that calibration and validation see one regime"
            )
            return s, e, notes
    notes.append(
        "the operation changed within the record, and no stretch run one way holds a "
        "calendar year and "
        f"{VALIDATION_MONTHS} months after it: the periods span the change"
    )
    return start, end, notes


@dataclass(frozen=True)
class SeasonLevel:
    """One heating season's heating level.

    Attributes
    ----------
    season : int
        The year the season starts (a season runs from July to June: one winter).
    level : float
        The indoor daily mean [°C] on its heated days, brought to a common outdoor
        temperature ``ref`` along the slope of the indoor on the outdoor daily mean.
    days : int
        Its heated days (outdoor daily mean 5 K or more below the heating floor).
    ref : float
        The common outdoor daily mean [°C] (the median of the heated days measured).
    """

    season: int
    level: float
    days: int
    ref: float

    def name(self) -> str:
        """``2019/20``."""
        return f"{self.season}/{(self.season + 1) % 100:02d}"


def season_levels(ti: pd.Series, te: pd.Series) -> list[SeasonLevel]:
    """Each heating season's heating level (:class:`SeasonLevel`), oldest first; none
    when the record shows no heating floor (:func:`heritage_bayes.init_checks.
    heating_floor`: a free-running room has no level to move).

    A set-point is set for a winter, and winters straddle the calendar year: the seasons
    run July to June. A heated day is one whose outdoor daily mean lies 5 K or more
    below the record's floor (the heating then carries the room). A heated store's
    air still follows the outdoors a little on such days (the heaters' spread, a
    thermostat away from the logger): the level is each day's indoor mean less
    ``b`` times its outdoor mean's distance from the common ``ref``, ``b`` [K/K] the
    slope of the indoor on the outdoor daily mean within seasons, pooled over them
    (clipped to 0-1), its median over the season's heated days; at least
    :data:`MIN_HEAT_DAYS` of them.

    Parameters
    ----------
    ti, te : pandas.Series
        Indoor and outdoor temperature [°C] on UTC stamps.
    """
    ti, te = ti.dropna(), te.dropna()
    if len(ti) < 48 or len(te) < 48:
        return []
    floor, held, ndays = heating_floor(ti, te)
    if not held >= max(20, 0.05 * ndays):
        return []
    d = pd.concat(
        [ti.resample("1D").mean().rename("ti"), te.resample("1D").mean().rename("te")],
        axis=1,
        sort=True,
    ).dropna()
    d = d[d["te"] < floor - 5]
    if len(d) < MIN_HEAT_DAYS:
        return []
    idx = d.index.tz_localize(None) if d.index.tz is not None else d.index
    season = pd.Series((idx - pd.DateOffset(months=6)).year, index=d.index)
    g = d.groupby(season)
    x = d["te"] - g["te"].transform("mean")
    y = d["ti"] - g["ti"].transform("mean")
    slope = float(np.clip((x * y).sum() / max(float((x * x).sum()), 1e-9), 0.0, 1.0))
    ref = float(d["te"].median())
    level = d["ti"] - slope * (d["te"] - ref)
    return [
        SeasonLevel(int(k), float(v.median()), len(v), ref)
        for k, v in level.groupby(season)
        if len(v) >= MIN_HEAT_DAYS
    ]


def level_stretch(
    levels: list[SeasonLevel], start: pd.Timestamp, end: pd.Timestamp
) -> tuple[pd.Timestamp, pd.Timestamp, list[str]]:
    """The most recent stretch of ``[start, end)`` [UTC] whose heating seasons keep one
    heating level (no two seasons in a row apart by :data:`LEVEL_SHIFT_K` or more: a
    set-point is moved between winters), long enough for 12
    months and :data:`~heritage_bayes.init_periods.VALIDATION_MONTHS` after them; a
    stretch begins on the 1st of July before its first season. Returns ``(start, end,
    notes)``; the whole span (and no notes) when the level never moved, with a note when
    it moved and no steady stretch is long enough.
    """
    if len(levels) < 2:
        return start, end, []
    runs = []  # [first, last] seasons, newest first
    run = [levels[-1]]
    for lv in levels[-2::-1]:
        if abs(lv.level - run[-1].level) >= LEVEL_SHIFT_K:
            runs.append(run)
            run = []
        run.append(lv)
    runs.append(run)
    if len(runs) == 1:
        return start, end, []
    notes = [
        "heating level by season (the indoor daily mean on heated days at an outdoor "
        f"daily mean of {levels[0].ref:.1f} °C): "
        + "; ".join(f"{lv.name()} {lv.level:.1f} °C" for lv in levels)
    ]
    moves = ", ".join(
        f"{a[0].name()} to {b[-1].name()}" for a, b in zip(runs[1:], runs[:-1], strict=True)
    )
    need = pd.DateOffset(years=1, months=VALIDATION_MONTHS)
    for k, run in enumerate(runs):
        s = (
            start
            if k == len(runs) - 1
            else pd.Timestamp(year=run[-1].season, month=7, day=1, tz=start.tz)
        )
        e = end if k == 0 else pd.Timestamp(year=run[0].season + 1, month=7, day=1, tz=start.tz)
        s, e = max(s, start), min(e, end)
        if s + need <= e:
            notes.append(
                f"the heating level moved by {LEVEL_SHIFT_K:.1f} K or more between seasons "
                f"({moves}; the model has one set-point): the periods are in "
                f"{s:%Y-%m-%d} to {e:%Y-%m-%d}, the most recent stretch of heating seasons "
                "at one level"
            )
            return s, e, notes
    notes.append(
        f"the heating level moved by {LEVEL_SHIFT_K:.1f} K or more between seasons "
        f"({moves}), and no stretch at one level holds 12 months and {VALIDATION_MONTHS} "
        "after them: the periods span the move"
    )
    return start, end, notes
