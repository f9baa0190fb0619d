"""Settings of the data sources: ``site``, the tables to read (weather, measurements) and
the demo; the ``data`` section that holds them: :mod:`heritage_bayes.config.data`.

How these become model inputs and outputs: :mod:`heritage_bayes.prepare`.
"""

from __future__ import annotations

import re
from typing import Literal

import pandas as pd
from pydantic import field_validator, model_validator

from heritage_bayes.config._base import (
    DURATION_UNIT,
    MAX_SEED,
    DateText,
    Duration,
    TimeZone,
    _Strict,
    check_dates,
    key,
)

__all__ = ["DemoData", "Site", "Source"]


class Site(_Strict):
    """Where the building stands (for the sun's position)."""

    latitude: float = key(unit="° north", description="latitude of the site", ge=-90, le=90)
    longitude: float = key(unit="° east", description="longitude of the site", ge=-180, le=180)
    altitude: float = key(0.0, unit="m", description="height above sea level", ge=-500, le=9000)


class DemoData(_Strict):
    """The built-in virtual monument (see :mod:`heritage_bayes.demo`)."""

    seed: int = key(7, unit=None, description="seed of the simulated noise", ge=0, le=MAX_SEED)
    weather: Literal["greensboro_tmy3", "debilt_knmi"] = key(
        "greensboro_tmy3",
        unit=None,
        description="weather driving the virtual room: pvlib's Greensboro TMY3 year, or "
        "KNMI De Bilt hours (give weather_path)",
    )
    weather_path: str | list[str] | None = key(
        None,
        unit=None,
        description="KNMI hourly file(s) for weather 'debilt_knmi', relative to the config",
    )
    thermal_model: Literal["thermal_4a", "thermal_2c"] = key(
        "thermal_4a", unit=None, description="the model that generates the indoor temperature"
    )
    sensor_noise_T: float = key(
        0.1, unit="K", description="sd of the temperature sensor's white noise", ge=0
    )
    sensor_noise_RH: float = key(
        1.0, unit="%RH", description="sd of the RH sensor's white noise", ge=0, le=100
    )
    model_error_T: float = key(
        0.2, unit="K", description="sd of the AR(1) model error in temperature", ge=0
    )
    model_error_P: float = key(
        25.0, unit="Pa", description="sd of the AR(1) model error in vapour pressure", ge=0
    )
    model_error_phi: float = key(
        0.9, unit="-", description="hourly AR(1) coefficient of the model error", ge=0, lt=1
    )
    gap: tuple[DateText, DateText] | None = key(
        ("2019-03-10", "2019-03-17"),
        unit=None,
        description="[start, end) of a logger outage in the simulated record, or null",
    )
    truth: dict[Literal["thermal", "hygric"], dict[str, float]] = key(
        unit="SI",
        description="overrides of documented true parameter values, e.g. "
        "{thermal: {fI_S: 0}, hygric: {Cw: 1.0}}",
        default_factory=dict,
    )

    @field_validator("gap")
    @classmethod
    def _gap(cls, v):
        if v is not None:
            check_dates(*v)
        return v

    @model_validator(mode="after")
    def _weather_path(self):
        if self.weather == "debilt_knmi" and self.weather_path is None:
            raise ValueError(
                "weather_path: required for weather 'debilt_knmi' (the KNMI hourly file of "
                "De Bilt, e.g. ../shared/data/knmi-debilt/uurgeg_260_2011-2020.txt.gz)"
            )
        if self.weather != "debilt_knmi" and self.weather_path is not None:
            raise ValueError(f"weather_path: only for weather 'debilt_knmi' (got {self.weather!r})")
        return self


#: The keys only a csv source takes.
_CSV_ONLY = tuple(
    (
        "time_column time_format time_origin timezone columns sep decimal averaged interval "
        "label duplicates sort na_values skiprows encoding units"
    ).split()
)


class Source(_Strict):
    """A table to read: ``format`` selects the reader; the rest are its options.

    ``csv``: :func:`heritage_bayes.io.read_csv` (``time_column``, ``timezone`` and the
    ``columns`` mapping ``{standard name: column in the file}``); ``epw``/``tmy3``:
    :func:`~heritage_bayes.io.read_epw`/:func:`~heritage_bayes.io.read_tmy3` (``year``
    for typical years); ``knmi``: :func:`~heritage_bayes.io.read_knmi_hourly` (``path``
    may list consecutive files).
    """

    format: Literal["csv", "epw", "knmi", "tmy3"] = key(
        unit=None, description="the reader: csv, epw (EnergyPlus), knmi (KNMI hourly), tmy3"
    )
    path: str | list[str] = key(
        unit=None,
        description="the file, relative to the config file (knmi: a list of consecutive files)",
    )
    time_column: str | list[str] | None = key(
        None,
        unit=None,
        description="csv: the time column, or several joined with spaces (date, hour)",
    )
    time_format: str | None = key(
        None, unit=None, description="csv: strptime format of the time, e.g. '%d-%m-%Y %H:%M'"
    )
    time_origin: str | None = key(
        None,
        unit=None,
        description="csv: the time column holds seconds elapsed since this instant",
    )
    timezone: TimeZone | None = key(
        None,
        unit=None,
        description="csv: the logger's clock: UTC, a fixed offset (UTC+2; most loggers) or "
        "an IANA zone with summer time (Europe/Helsinki)",
    )
    columns: dict[str, str] | None = key(
        None, unit=None, description="csv: {standard name: column in the file}, e.g. {Ti: TEMP}"
    )
    sep: str = key(",", unit=None, description="csv: field separator (',', ';', '\\t', '\\s+')")
    decimal: str = key(".", unit=None, description="csv: decimal mark ('.' or ',')")
    averaged: list[str] | None = key(
        None,
        unit=None,
        description="csv: standard names of interval-average columns (default: irradiance)",
    )
    interval: Duration | None = key(
        None,
        unit=DURATION_UNIT,
        description="csv: averaging interval (default: the most frequent step)",
    )
    label: Literal["end", "start"] = key(
        "end", unit=None, description="csv: interval averages stamped at the interval end/start"
    )
    duplicates: Literal["raise", "first", "last", "mean"] = key(
        "raise", unit=None, description="csv: what to do with a repeated time stamp"
    )
    sort: bool = key(
        False,
        unit=None,
        description="csv: rows whose time stamps go backwards (overlapping downloads joined "
        "in one file) sorted by time instead of refused; a stamp then repeated follows "
        "duplicates",
    )
    na_values: list[str | float] | None = key(
        None, unit=None, description="csv: extra markers of a missing value, e.g. [-999]"
    )
    invalid: Literal["raise", "nan"] = key(
        "raise", unit=None, description="an implausible value: an error, or left out (NaN)"
    )
    year: int | None = key(None, unit=None, description="epw/tmy3: the year a typical year becomes")
    skiprows: int | list[int] = key(
        0,
        unit=None,
        description="csv: lines before the header, or the 0-based numbers of the lines to "
        "skip (logger metadata lines: Tinytag, Rotronic; see heritage_bayes.io.loggers)",
    )
    encoding: str = key("utf-8", unit=None, description="csv: text encoding (utf-8-sig, cp1252)")
    units: dict[str, str] | None = key(
        None,
        unit=None,
        description="csv: {standard name: unit in the file} for temperatures in °F or K and "
        "relative humidity as a fraction, converted on reading, e.g. {Ti: °F, RHi: fraction}",
    )

    @model_validator(mode="after")
    def _options_fit_format(self):
        if self.format == "csv" and self.time_column is None:
            raise ValueError("time_column: required for format 'csv'")
        fields = type(self).model_fields
        given = {k for k in fields if getattr(self, k) != fields[k].default}
        if self.format != "csv":
            extra = [k for k in _CSV_ONLY if k in given]
            if extra:
                also = f"; also {', '.join(extra[1:])}" if len(extra) > 1 else ""
                raise ValueError(
                    f"{extra[0]}: only for format 'csv' (format is {self.format!r}){also}"
                )
        if self.year is not None and self.format not in ("epw", "tmy3"):
            raise ValueError(f"year: only for formats 'epw' and 'tmy3' (format is {self.format!r})")
        if isinstance(self.path, list) and self.format != "knmi":
            raise ValueError(
                f"path: a list of files is only for format 'knmi' (format is {self.format!r})"
            )
        if isinstance(self.path, list) and not self.path:
            raise ValueError("path: the list of files is empty")
        if self.time_format is not None:
            _check_time_format(self.time_format)
        if self.time_origin is not None:
            if self.time_format is not None:
                raise ValueError("time_format: not used with time_origin (elapsed seconds)")
            try:
                pd.Timestamp(self.time_origin)
            except (ValueError, TypeError):
                raise ValueError(
                    f"time_origin: expected an instant such as '2016-03-01 00:00' "
                    f"(got {self.time_origin!r})"
                ) from None
        if self.sep not in (r"\s+", "\t") and len(self.sep) != 1:
            raise ValueError(
                f"sep: one character such as ',' or ';', '\\t' for tabs or '\\s+' for "
                f"white space (got {self.sep!r})"
            )
        if len(self.decimal) != 1 or self.decimal == self.sep:
            raise ValueError(
                f"decimal: one character, not the separator {self.sep!r} (got {self.decimal!r})"
            )
        return self


#: strptime directives (Python's): a time_format may use only these.
_DIRECTIVES = set("aAwdbBmyYHIpMSfzZjUWcxXGuV%")


def _check_time_format(fmt: str) -> None:
    if fmt in ("ISO8601", "mixed"):  # pandas' own
        return
    bad = [d for d in re.findall(r"%-?(.?)", fmt) if d not in _DIRECTIVES]
    if "%" not in fmt or bad:
        shown = f"'%{bad[0]}' is not a strptime directive" if bad else "no % directive"
        raise ValueError(
            f"time_format: {shown}; use e.g. '%Y-%m-%d %H:%M' or '%d/%m/%Y %H:%M' (got {fmt!r})"
        )
