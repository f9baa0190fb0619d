"""Text ↔ typed values for time: durations, time zones, and strict-JSON conversion.

Layer 0 (imports only numpy, pandas and :mod:`heritage_bayes.errors`): the settings
layer (:mod:`heritage_bayes.config`) turns the text of a YAML file into these typed
values once; the readers (:mod:`heritage_bayes.io`), the RC layer (weekly calendars in
:mod:`heritage_bayes.rc.calendar`) and the inference layer (JSON outputs) use the same
functions without importing the settings or the readers.

A duration always carries its unit (``'10min'``, ``'2h'``, ``'14d'``): a bare number is
refused, because ``max_time: 10`` meant minutes to one user and seconds to the code.
"""

from __future__ import annotations

import datetime as _dt
import re
import zoneinfo

import numpy as np
import pandas as pd

from heritage_bayes.errors import InputError

__all__ = [
    "format_timedelta",
    "parse_duration",
    "parse_timezone",
    "timezone_text",
    "to_jsonable",
]

_DAY_UNIT = re.compile(r"(?<=\d)\s*[dD](?![A-Za-z])")
_HOUR_UNIT = re.compile(r"(?<=\d)\s*H(?![A-Za-z])")
_BARE_NUMBER = re.compile(r"^[+-]?(\d+\.?\d*|\.\d+)([eE][+-]?\d+)?$")
_FIXED_OFFSET = re.compile(r"^(?:UTC|GMT)?\s*([+-])\s*(\d{1,2})(?::?(\d{2}))?$")


def _unit_hint(number) -> str:
    n = f"{number:g}" if isinstance(number, int | float) else str(number).strip()
    return (
        f"a duration needs a unit: write e.g. '{n}min', '{n}h', '{n}d' or '{n}s' (got {n}, "
        "a bare number)"
    )


def parse_duration(value) -> pd.Timedelta:
    """A duration with its unit as a :class:`pandas.Timedelta`.

    Parameters
    ----------
    value : str or timedelta
        ``'14d'``, ``'1h'``, ``'30min'``, ``'1d12h'``, ``'90s'`` (``d``/``D`` days,
        ``h``/``H`` hours, ``min``, ``s``; pandas' other spellings such as ``'2 hours'``
        too), or a timedelta (returned as a Timedelta).

    Returns
    -------
    pandas.Timedelta

    Raises
    ------
    ValueError
        A bare number (``10`` or ``'10'``: the message suggests the units), or text that
        is not a duration.
    """
    if isinstance(value, _dt.timedelta):
        return pd.Timedelta(value)
    if isinstance(value, bool) or not isinstance(value, str | int | float):
        raise ValueError(
            f"expected a duration such as '1h', '14d' or '30min' (got {type(value).__name__} "
            f"{value!r})"
        )
    if isinstance(value, int | float) or _BARE_NUMBER.match(value.strip()):
        raise ValueError(_unit_hint(value))
    try:
        return pd.Timedelta(_HOUR_UNIT.sub("h", _DAY_UNIT.sub("D", value.strip())))
    except (ValueError, TypeError):
        raise ValueError(
            f"expected a duration such as '1h', '14d' or '30min' (got {value!r})"
        ) from None


def format_timedelta(td) -> str:
    """Compact text of a duration that :func:`parse_duration` reads back, e.g. ``'1h'``,
    ``'10min'``, ``'1h30min'``, ``'2D'`` (sub-second durations in pandas' long form)."""
    td = pd.Timedelta(td)
    total = int(td.total_seconds())
    if td.total_seconds() != total:
        return str(td)
    if total == 0:
        return "0s"
    sign = "-" if total < 0 else ""
    total = abs(total)
    days, rest = divmod(total, 86400)
    hours, rest = divmod(rest, 3600)
    minutes, seconds = divmod(rest, 60)
    parts = [f"{days}D" if days else "", f"{hours}h" if hours else ""]
    parts += [f"{minutes}min" if minutes else "", f"{seconds}s" if seconds else ""]
    return sign + "".join(parts)


def parse_timezone(timezone) -> _dt.tzinfo:
    """Turn ``'UTC'``, ``'UTC+2'``, ``'UTC-03:30'``, ``'+02:00'`` or an IANA name into a tzinfo.

    Fixed offsets have no daylight-saving time; IANA names (``'Europe/Copenhagen'``)
    follow the local clock, with its DST changes. A tzinfo is returned as it is.

    Raises
    ------
    InputError
        Not text, an offset beyond ±14 h, or an unknown zone name.
    """
    if isinstance(timezone, _dt.tzinfo):
        return timezone
    if not isinstance(timezone, str) or not timezone.strip():
        raise InputError(
            f"timezone must be a string such as 'UTC', 'UTC+2' or 'Europe/Copenhagen' "
            f"(got {timezone!r})"
        )
    text = timezone.strip()
    if text.upper() in ("UTC", "Z", "GMT"):
        return _dt.UTC
    match = _FIXED_OFFSET.match(text.upper())
    if match:
        sign, hours, minutes = match.groups()
        delta = _dt.timedelta(hours=int(hours), minutes=int(minutes or 0))
        if delta > _dt.timedelta(hours=14):
            raise InputError(f"timezone {timezone!r}: offset beyond ±14 h")
        return _dt.timezone(-delta if sign == "-" else delta)
    try:
        return zoneinfo.ZoneInfo(text)
    except (zoneinfo.ZoneInfoNotFoundError, ValueError) as exc:
        raise InputError(
            f"unknown timezone {timezone!r}; use 'UTC', a fixed offset such as 'UTC+2' or "
            f"'UTC-03:30', or an IANA name such as 'Europe/Copenhagen'"
        ) from exc


def timezone_text(tz: _dt.tzinfo) -> str:
    """The text :func:`parse_timezone` reads back: ``'UTC'``, ``'UTC+01:00'``, or the
    IANA name of a zone."""
    if isinstance(tz, zoneinfo.ZoneInfo):
        return tz.key
    offset = tz.utcoffset(None)
    if offset is None:
        return str(tz)
    if offset == _dt.timedelta(0):
        return "UTC"
    minutes = int(offset.total_seconds() // 60)
    sign = "-" if minutes < 0 else "+"
    h, m = divmod(abs(minutes), 60)
    return f"UTC{sign}{h:02d}:{m:02d}"


def to_jsonable(obj):
    """Recursively convert to strict-JSON types: numpy scalars and arrays to Python,
    non-finite floats to None, timestamps to ISO 8601, durations as ``format_timedelta``,
    paths and anything else to text."""
    from collections.abc import Mapping
    from pathlib import PurePath

    if isinstance(obj, Mapping):
        return {str(k): to_jsonable(v) for k, v in obj.items()}
    if isinstance(obj, list | tuple):
        return [to_jsonable(v) for v in obj]
    if isinstance(obj, np.ndarray):
        return to_jsonable(obj.tolist())
    if isinstance(obj, bool | np.bool_):
        return bool(obj)
    if isinstance(obj, int | np.integer):
        return int(obj)
    if isinstance(obj, float | np.floating):
        return float(obj) if np.isfinite(obj) else None
    if isinstance(obj, pd.Timestamp):
        return obj.isoformat()
    if isinstance(obj, pd.Timedelta):
        return format_timedelta(obj)
    if obj is None or isinstance(obj, str):
        return obj
    if isinstance(obj, PurePath):
        return str(obj)
    return str(obj)
