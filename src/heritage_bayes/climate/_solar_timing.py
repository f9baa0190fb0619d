"""Shared timing and site helpers of the solar modules (private).

Irradiance columns follow the package's timestamp convention: an interval average is
stamped at the **end** of its averaging interval (KNMI, EPW, TMY3), and the sun is placed
at the **middle** of that interval. These helpers check the site, the tz-aware index and
the averaging interval for :mod:`heritage_bayes.climate.solar_sky` and
:mod:`heritage_bayes.climate.solar_surfaces`.
"""

from __future__ import annotations

import warnings
from collections.abc import Mapping
from contextlib import contextmanager

import numpy as np
import pandas as pd

from heritage_bayes.errors import DataError, InputError

_SITE_KEYS = ("latitude", "longitude", "altitude", "name")


@contextmanager
def _quiet_pvlib():
    """Silence pandas' ``dayofyear`` deprecation raised inside pvlib 0.16 (not our code)."""
    with warnings.catch_warnings():
        warnings.filterwarnings("ignore", message=r".*dayofyear is deprecated", category=Warning)
        yield


def _site(site) -> tuple[float, float, float]:
    if not isinstance(site, Mapping):
        raise InputError(
            "site must be a mapping with 'latitude' and 'longitude' [°] and optional "
            f"'altitude' [m] (got {type(site).__name__})"
        )
    unknown = [k for k in site if k not in _SITE_KEYS]
    if unknown:
        raise InputError(f"site: unknown key(s) {unknown}; allowed keys are {list(_SITE_KEYS)}")
    missing = [k for k in ("latitude", "longitude") if k not in site]
    if missing:
        raise InputError(f"site: missing key(s) {missing}")
    try:
        lat = float(site["latitude"])
        lon = float(site["longitude"])
        alt = float(site.get("altitude", 0.0))
    except (TypeError, ValueError) as exc:
        raise InputError(
            f"site: latitude, longitude and altitude must be numbers ({site})"
        ) from exc
    if not -90.0 <= lat <= 90.0:
        raise InputError(f"site: latitude must be in [-90, 90] ° (got {lat})")
    if not -180.0 <= lon <= 360.0:
        raise InputError(f"site: longitude must be in [-180, 180] ° east (got {lon})")
    if not -500.0 <= alt <= 9000.0:
        raise InputError(f"site: altitude must be in metres above sea level (got {alt})")
    return lat, lon, alt


def _utc_index(index, what: str) -> pd.DatetimeIndex:
    if not isinstance(index, pd.DatetimeIndex) or index.tz is None:
        raise DataError(f"{what}: needs a tz-aware DatetimeIndex (the readers return UTC)")
    return index.tz_convert("UTC")


def _interval(index: pd.DatetimeIndex, attrs: Mapping, interval, what: str) -> pd.Timedelta:
    if interval is None:
        interval = attrs.get("interval")
    if interval is None:
        if len(index) < 2:
            raise DataError(f"{what}: cannot infer the averaging interval; pass interval=")
        diffs = np.diff(index.asi8)
        values, counts = np.unique(diffs[diffs > 0], return_counts=True)
        return pd.Timedelta(int(values[np.argmax(counts)]), unit=index.unit)
    try:
        td = pd.Timedelta(interval)
    except (TypeError, ValueError) as exc:
        raise InputError(f"interval must be a duration such as '1h' (got {interval!r})") from exc
    if td <= pd.Timedelta(0):
        raise InputError(f"interval must be positive (got {interval!r})")
    return td


def _fmt(td: pd.Timedelta) -> str:
    seconds = int(td.total_seconds())
    if seconds % 3600 == 0:
        return f"{seconds // 3600}h"
    if seconds % 60 == 0:
        return f"{seconds // 60}min"
    return f"{seconds}s"
