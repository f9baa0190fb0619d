"""Time zones of a site and their daylight-saving changes.

:func:`site_zone` looks the IANA zone of a site up in the zone boundaries that
``timezonefinder`` ships (offline, maintained with the IANA database); :func:`dst_candidate`
picks the daylight-saving zone a file's stamps are tested against
(:func:`heritage_bayes.io.clock.dst_structure`): the site's own, or without a site the zone
of :data:`DST_ZONES` for a fixed offset.

References
----------
.. [1] J. Michelfeit, timezonefinder (Python package), https://github.com/jannikmi/timezonefinder
"""

from __future__ import annotations

import datetime as _dt
import functools

import pandas as pd

__all__ = ["DST_ZONES", "dst_candidate", "keeps_dst", "site_zone", "zone_transitions"]


def zone_transitions(tz, year: int) -> list[tuple[pd.Timestamp, pd.Timedelta]]:
    """(wall-clock instant before the change, change of the offset) in ``year``."""
    found = []
    t = _dt.datetime(year, 1, 1, tzinfo=_dt.UTC)
    prev = t.astimezone(tz).utcoffset()
    hour = _dt.timedelta(hours=1)
    while t.year == year:
        nxt = t + hour
        off = nxt.astimezone(tz).utcoffset()
        if off != prev:
            wall = (nxt + prev).replace(tzinfo=None)  # the old clock at the change
            found.append((pd.Timestamp(wall), pd.Timedelta(off - prev)))
            prev = off
        t = nxt
    return found


#: The DST zone checked for each fixed offset [h] (EU and US rules).
DST_ZONES = {
    0: "Europe/London",
    1: "Europe/Paris",
    2: "Europe/Helsinki",
    -5: "America/New_York",
    -6: "America/Chicago",
    -7: "America/Denver",
    -8: "America/Los_Angeles",
}


@functools.lru_cache(maxsize=1)
def _zone_finder():
    from timezonefinder import TimezoneFinder

    return TimezoneFinder()


@functools.lru_cache(maxsize=64)
def site_zone(latitude: float, longitude: float) -> str | None:
    """The IANA time zone of a site [° north, ° east], from the zone boundaries that
    ``timezonefinder`` ships (offline); None at sea or off every zone."""
    try:
        return _zone_finder().timezone_at(lng=float(longitude), lat=float(latitude))
    except ValueError:  # coordinates out of range
        return None


def keeps_dst(zone: str, years) -> bool:
    """True when ``zone`` changes its offset in one of ``years``."""
    import zoneinfo

    try:
        tz = zoneinfo.ZoneInfo(zone)
    except (zoneinfo.ZoneInfoNotFoundError, ValueError):
        return False
    return any(zone_transitions(tz, int(y)) for y in years)


def dst_candidate(
    offset_h: float | None, latitude: float | None, longitude: float | None, years=(2020,)
) -> str | None:
    """The daylight-saving zone a file's stamps are tested against: the site's own zone
    (:func:`site_zone`) when it keeps DST in ``years``, else the zone of
    :data:`DST_ZONES` for the fixed offset ``offset_h`` [h] (None without either)."""
    if latitude is not None and longitude is not None:
        zone = site_zone(float(latitude), float(longitude))
        if zone and keeps_dst(zone, years):
            return zone
    if offset_h is None or offset_h != int(offset_h):
        return None
    return DST_ZONES.get(int(offset_h))
