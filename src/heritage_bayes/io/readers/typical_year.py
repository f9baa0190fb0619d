"""Readers of typical-year weather files: EnergyPlus weather (:func:`read_epw`) and TMY3
(:func:`read_tmy3`), with one shared tail (missing values, coercion to one year, UTC).

See :mod:`heritage_bayes.io` for the conventions every reader follows.
"""

from __future__ import annotations

from collections.abc import Mapping
from os import PathLike

import numpy as np
import pandas as pd

from heritage_bayes.errors import DataError, InputError
from heritage_bayes.io._common import (
    INVALID_POLICIES,
    _quote_list,
    check_choice,
    check_file,
    finalize,
    order_and_deduplicate,
    source_name,
    validate_ranges,
)

__all__ = ["TYPICAL_YEAR", "read_epw", "read_tmy3"]

#: Year that typical-year files (TMY3, EPW typical years) are coerced to by default.
TYPICAL_YEAR = 2019

# EPW missing-value markers (EnergyPlus Auxiliary Programs, "Weather file data fields").
_EPW_MISSING = {
    "temp_air": 99.9,
    "temp_dew": 99.9,
    "relative_humidity": 999.0,
    "wind_speed": 999.0,
}
_EPW_IRR_MISSING = 9999.0
_WEATHER_MAP = {
    "temp_air": "Te",
    "relative_humidity": "RHe",
    "ghi": "ghi",
    "dni": "dni",
    "dhi": "dhi",
    "temp_dew": "Tdew",
    "wind_speed": "wind",
}


def _site_from_meta(meta: Mapping) -> dict:
    return {
        "latitude": float(meta["latitude"]),
        "longitude": float(meta["longitude"]),
        "altitude": float(meta["altitude"]),
    }


def _typical_year(frame, path, name, fmt, meta, year_used, invalid, *, first_line, station):
    """Shared tail of the EPW and TMY3 readers: ranges, order, provenance attrs."""
    lines = np.arange(len(frame)) + first_line
    counts: dict[str, int] = {}
    clipped = validate_ranges(frame, lines, name, {}, invalid, counts)
    frame["__line"] = lines
    frame = order_and_deduplicate(frame, name, duplicates="raise", sort=False, counts=counts)
    frame = frame.drop(columns="__line")
    return finalize(
        frame,
        source=str(path),
        fmt=fmt,
        averaged=("ghi", "dni", "dhi"),
        interval=pd.Timedelta("1h"),
        counts=counts,
        clipped=clipped,
        extra={
            "timezone": f"UTC{float(meta['TZ']):+g} (local standard time)",
            "site": _site_from_meta(meta),
            "coerced_year": year_used,
            "station": station,
        },
    )


def read_epw(path: str | PathLike, *, year: int | None = None, invalid: str = "raise"):
    """Read an EnergyPlus weather file (``.epw``) with :func:`pvlib.iotools.read_epw`.

    Parameters
    ----------
    path : str or path-like
    year : int, optional
        Put every row in this year (typical-year files mix months of different years).
        Default: keep the file's years when the rows form one contiguous hourly series
        (an actual-year file), else coerce to 2019 (a non-leap year, as EPW typical years
        have 8760 rows).
    invalid : {"raise", "nan"}, default "raise"
        Values outside physical ranges: raise, or set to NaN (counted).

    Returns
    -------
    pandas.DataFrame
        UTC index; ``Te`` [°C], ``Tdew`` [°C], ``RHe`` [%], ``wind`` [m/s] (the wind
        speed field) at the stamp; ``ghi``, ``dni``, ``dhi`` [W/m²] mean of the hour
        ending at the stamp.
        ``attrs["site"]`` holds ``latitude``, ``longitude``, ``altitude`` from the
        header, ``attrs["coerced_year"]`` the year used (or None).

    Notes
    -----
    EPW rows are in local **standard** time (``TZ`` of the LOCATION line, no DST). Hour
    ``h`` (1..24) is the interval from ``h-1`` to ``h``; radiation fields are energy over
    that hour [Wh/m²], i.e. its mean irradiance [W/m²], stamped here at ``h`` (pvlib
    stamps the interval start). EPW missing-value markers (99.9 °C, 999 %, 999 m/s,
    9999 W/m²) become NaN.

    References
    ----------
    .. [1] U.S. DOE, "EnergyPlus Auxiliary Programs", chapter "Weather Converter
       Program", section "EnergyPlus Weather File (EPW) Data Dictionary".
    """
    import pvlib

    path = check_file(path)
    name = source_name(path)
    check_choice(invalid, INVALID_POLICIES, "invalid")
    try:
        data, meta = pvlib.iotools.read_epw(str(path))
    except Exception as exc:  # pvlib raises assorted errors on malformed files
        raise DataError(f"{name}: cannot read as EPW: {exc}") from exc
    years = data["year"].to_numpy()
    month, day, hour = (data[c].to_numpy() for c in ("month", "day", "hour"))
    if year is None:
        naive = _epw_naive(years, month, day, hour)
        steps = None if naive is None else np.unique(np.diff(naive.asi8))
        contiguous = steps is not None and steps.size == 1 and steps[0] > 0
        year_used = None if contiguous else TYPICAL_YEAR
    else:
        year_used = _check_year(year)
    if year_used is not None:
        naive = _epw_naive(np.full_like(years, year_used), month, day, hour)
        if naive is None:
            raise DataError(f"{name}: contains 29 February; pass a leap year, e.g. year=2020")
    tz = pd.Timedelta(hours=float(meta["TZ"]))
    index = (naive - tz).tz_localize("UTC")
    frame = pd.DataFrame(
        {std: data[src].to_numpy(dtype=float) for src, std in _WEATHER_MAP.items()},
        index=index,
    )
    for src, marker in _EPW_MISSING.items():
        col = _WEATHER_MAP[src]
        frame.loc[frame[col] >= marker, col] = np.nan
    for col in ("ghi", "dni", "dhi"):
        frame.loc[frame[col] >= _EPW_IRR_MISSING, col] = np.nan
    return _typical_year(
        frame,
        path,
        name,
        "epw",
        meta,
        year_used,
        invalid,
        first_line=9,  # 8 header lines
        station=str(meta.get("city", "")),
    )


def _check_year(year) -> int:
    if isinstance(year, bool) or not isinstance(year, int | np.integer) or not 1 <= year <= 9998:
        raise InputError(f"year must be an integer year such as 2019 (got {year!r})")
    return int(year)


def _epw_naive(years, month, day, hour) -> pd.DatetimeIndex | None:
    """Naive local stamps at the end of each EPW hour; None if a date does not exist."""
    dates = pd.to_datetime(
        pd.DataFrame({"year": years, "month": month, "day": day}), errors="coerce"
    )
    if dates.isna().any():
        return None
    return pd.DatetimeIndex(dates + pd.to_timedelta(hour, unit="h"))


def read_tmy3(path: str | PathLike, *, year: int | None = None, invalid: str = "raise"):
    """Read a TMY3 file with :func:`pvlib.iotools.read_tmy3`.

    Parameters
    ----------
    path : str or path-like
        E.g. the file shipped with pvlib, ``pvlib/data/723170TYA.CSV`` (Greensboro, NC).
    year : int, optional
        Year every row is put in. TMY3 months come from different years; default 2019,
        a non-leap year (TMY3 has no 29 February), so the index increases monotonically.
        The last row (24:00 on 31 December) lands at midnight of ``year + 1``.
    invalid : {"raise", "nan"}, default "raise"

    Returns
    -------
    pandas.DataFrame
        UTC index; ``Te`` [°C], ``Tdew`` [°C], ``RHe`` [%] at the stamp; ``ghi``, ``dni``,
        ``dhi`` [W/m²], mean of the hour ending at the stamp. ``attrs["site"]`` from the
        header (latitude, longitude, altitude).

    Notes
    -----
    TMY3 stamps are local standard time (header ``TZ``, no DST) at the end of the hour
    the radiation is integrated over [1]_.

    References
    ----------
    .. [1] S. Wilcox and W. Marion, "Users manual for TMY3 data sets", NREL/TP-581-43156
       (2008). doi:10.2172/928611
    """
    import pvlib

    path = check_file(path)
    name = source_name(path)
    check_choice(invalid, INVALID_POLICIES, "invalid")
    year_used = TYPICAL_YEAR if year is None else _check_year(year)
    try:
        data, meta = pvlib.iotools.read_tmy3(str(path), coerce_year=year_used, map_variables=True)
    except Exception as exc:  # pvlib raises assorted errors on malformed files
        raise DataError(f"{name}: cannot read as TMY3: {exc}") from exc
    missing = [c for c in _WEATHER_MAP if c not in data.columns]
    if missing:
        raise DataError(f"{name}: TMY3 column(s) {_quote_list(missing)} not found")
    frame = pd.DataFrame(
        {std: data[src].to_numpy(dtype=float) for src, std in _WEATHER_MAP.items()},
        index=data.index.tz_convert("UTC"),
    )
    return _typical_year(
        frame,
        path,
        name,
        "tmy3",
        meta,
        year_used,
        invalid,
        first_line=3,  # metadata line, header line
        station=str(meta.get("Name", "")).strip('"'),
    )
