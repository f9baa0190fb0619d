"""Weekly calendars: the hours of use of a heated room as a model input.

A church is heated for its services: the heating raises the set-point a few hours before
and during the hours of use (Sunday morning, weekly choir practice). Without a log of
those hours, a building physicist writes the regular ones down as a weekly calendar. A
:class:`WeeklyCalendar` turns such a calendar, given in the room's local clock, into the
schedule input of a thermostat (:mod:`heritage_bayes.rc.control`, option
``thermostat: {schedule: {weekly: [...], timezone: ...}}``): for every time step
:math:`[t_k, t_k + \\Delta t)` the fraction of the step that lies in the hours of use
[-], i.e. the zero-order-hold mean of the 0/1 calendar over the step, the convention of
every input column (:mod:`heritage_bayes.prepare`).

Syntax of an entry: ``DAYS HH[:MM]-HH[:MM]`` in local clock time, ``DAYS`` one day
(``Sun``), a range (``Mon-Fri``) or a comma list (``Sat,Sun``); the end may be ``24``;
an interval across midnight is written as two entries. Examples: ``"Sun 08-12"``,
``"Mon-Fri 08:30-16"``, ``"Wed 19-21:30"``.

Exactness: the fraction is the integral of the periodic 0/1 calendar over the step,
computed from its cumulative minutes of use (piecewise linear), so steps of any length
(10 min to days) and slots that do not fall on the grid are exact. The local clock of a
step is that of its start; with a daylight-saving zone (``Europe/Copenhagen``) the
calendar follows the wall clock, with a fixed offset (``UTC+1``) it does not.

References
----------
.. [1] EN 15759-1:2011, *Conservation of cultural property - Indoor climate - Part 1:
   Guidelines for heating churches, chapels and other places of worship* (intermittent
   heating for the hours of use).
"""

from __future__ import annotations

import re
from dataclasses import dataclass

import numpy as np

__all__ = ["WeeklyCalendar", "parse_weekly"]

DAYS = ("Mon", "Tue", "Wed", "Thu", "Fri", "Sat", "Sun")
_WEEK = 7 * 1440  # minutes
_ENTRY = re.compile(
    r"^\s*(?P<days>[A-Za-z]{3}(?:\s*-\s*[A-Za-z]{3})?(?:\s*,\s*[A-Za-z]{3})*)\s+"
    r"(?P<h0>\d{1,2})(?::(?P<m0>\d{2}))?\s*-\s*(?P<h1>\d{1,2})(?::(?P<m1>\d{2}))?\s*$"
)


@dataclass(frozen=True)
class WeeklyCalendar:
    """Regular weekly hours of use in a local clock.

    Attributes
    ----------
    slots : tuple of (int, int)
        Intervals ``[start, end)`` in minutes from Monday 00:00 local time, sorted and
        merged, within ``[0, 10080]``.
    timezone : str
        Clock of the calendar: ``'UTC'``, a fixed offset (``'UTC+1'``) or an IANA name
        (``'Europe/Copenhagen'``, with daylight-saving time).
    entries : tuple of str
        The entries as written (for reports).
    """

    slots: tuple
    timezone: str = "UTC"
    entries: tuple = ()

    @property
    def hours_per_week(self) -> float:
        """Hours of use in a week [h]."""
        return sum(b - a for a, b in self.slots) / 60.0

    def _cumulative(self, m: np.ndarray) -> np.ndarray:
        """Minutes of use in ``[0, m)`` [min] for minutes ``m`` since a Monday 00:00
        (any real value, the calendar repeated every week)."""
        xs, ys, acc = [0.0], [0.0], 0.0
        for a, b in self.slots:
            xs += [a, b]
            ys += [acc, acc + (b - a)]
            acc += b - a
        xs.append(_WEEK)
        ys.append(acc)
        q = np.floor(m / _WEEK)
        return q * acc + np.interp(m - q * _WEEK, xs, ys)

    def fraction(self, index, dt: float) -> np.ndarray:
        """Fraction of each step ``[t_k, t_k + dt)`` in the hours of use [-].

        Parameters
        ----------
        index : pandas.DatetimeIndex
            Step starts, timezone-aware (UTC in the prepared data).
        dt : float
            Step [s].

        Returns
        -------
        (N,) float array in [0, 1].
        """
        from heritage_bayes.convert import parse_timezone

        if index.tz is None:
            raise ValueError("WeeklyCalendar.fraction: the time index must be timezone-aware")
        local = index.tz_convert(parse_timezone(self.timezone))
        m0 = (
            local.day_of_week.to_numpy() * 1440.0
            + local.hour.to_numpy() * 60.0
            + local.minute.to_numpy()
            + local.second.to_numpy() / 60.0
        )
        length = dt / 60.0
        used = self._cumulative(m0 + length) - self._cumulative(m0)
        return np.clip(used / length, 0.0, 1.0)


def _day(text: str, where: str) -> int:
    key = text.strip().capitalize()
    if key not in DAYS:
        raise ValueError(f"{where}: unknown day {text!r}; use one of {list(DAYS)}")
    return DAYS.index(key)


def parse_weekly(spec, where: str = "schedule") -> WeeklyCalendar:
    """A :class:`WeeklyCalendar` from its YAML form.

    Parameters
    ----------
    spec : mapping
        ``{weekly: [entry, ...], timezone: TZ}`` (``timezone`` default ``'UTC'``), each
        entry ``DAYS HH[:MM]-HH[:MM]`` (see the module docstring).
    where : str
        Key path for error messages.

    Raises
    ------
    ValueError
        An unknown key, a malformed entry or time, an empty or reversed interval, an
        unknown timezone (the message names the key path and what is expected).
    """
    if not isinstance(spec, dict):
        raise ValueError(f"{where}: expected a mapping {{weekly: [...], timezone: ...}}")
    unknown = sorted(set(spec) - {"weekly", "timezone"})
    if unknown:
        raise ValueError(f"{where}: unknown key(s) {unknown}; allowed: ['timezone', 'weekly']")
    entries = spec.get("weekly")
    if isinstance(entries, str):
        entries = [entries]
    if not isinstance(entries, list | tuple) or not entries:
        raise ValueError(
            f"{where}.weekly: expected a list of entries such as ['Sun 08-12'] (got {entries!r})"
        )
    tz = spec.get("timezone", "UTC")
    from heritage_bayes.convert import parse_timezone

    try:
        parse_timezone(tz)
    except Exception as exc:  # InputError: a message of its own
        raise ValueError(f"{where}.timezone: {exc}") from None
    slots = []
    for i, e in enumerate(entries):
        at = f"{where}.weekly[{i}]"
        m = _ENTRY.match(e) if isinstance(e, str) else None
        if m is None:
            raise ValueError(
                f"{at}: {e!r} is not 'DAYS HH[:MM]-HH[:MM]' (e.g. 'Sun 08-12', "
                "'Mon-Fri 08:30-16', 'Sat,Sun 10-12')"
            )
        h0, h1 = int(m["h0"]), int(m["h1"])
        m0, m1 = int(m["m0"] or 0), int(m["m1"] or 0)
        if h0 > 23 or h1 > 24 or m0 > 59 or m1 > 59 or (h1 == 24 and m1):
            raise ValueError(f"{at}: {e!r}: times must lie in 00:00-24:00")
        a, b = h0 * 60 + m0, h1 * 60 + m1
        if b <= a:
            raise ValueError(
                f"{at}: {e!r}: the end is not after the start (write an interval across "
                "midnight as two entries)"
            )
        days: list[int] = []
        for part in m["days"].split(","):
            ends = [p for p in part.split("-")]
            if len(ends) == 2:
                d0, d1 = _day(ends[0], at), _day(ends[1], at)
                if d1 < d0:
                    raise ValueError(f"{at}: {part.strip()!r}: a day range runs Mon to Sun")
                days += range(d0, d1 + 1)
            else:
                days.append(_day(ends[0], at))
        slots += [(d * 1440 + a, d * 1440 + b) for d in sorted(set(days))]
    merged: list[list[int]] = []
    for a, b in sorted(slots):
        if merged and a <= merged[-1][1]:
            merged[-1][1] = max(merged[-1][1], b)
        else:
            merged.append([a, b])
    return WeeklyCalendar(
        slots=tuple((a, b) for a, b in merged), timezone=str(tz), entries=tuple(entries)
    )
