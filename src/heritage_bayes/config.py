"""The validated YAML configuration of ``hbayes calibrate``.

Unknown keys are rejected; every error names the key path, the expected form and the
value found, e.g. ``priors.Gw.lower: must be < upper (got 500 > 200)``. Relative paths
in ``data`` are relative to the config file. How ``data`` and ``periods`` become model
inputs and outputs: :mod:`heritage_bayes.prepare`.

Why one module (about 800 lines): the schema is one tree of pydantic models whose validators
refer to each other (sections, periods, data sources, the cross-section checks of
:class:`CalibrationConfig`) and share one error formatter that turns pydantic's locations
into key paths; kept together, a reader finds every key, its default and its check in one
place, in the order of the YAML file.

Layout (see ``configs/demo.yaml`` for a complete, commented example)::

    name: my_room                  # run name; default: the config file's stem
    building: Castle X             # free text, shown in the report (escaped)
    room: Great hall
    notes: ...
    seed: 1
    site: {latitude: 52.1, longitude: 5.18, altitude: 2}
    room_volume: 800               # [m³], optional: log-normal prior on each model's Ci
    floor_area: 160                # [m²] on the ground, optional: log-normal prior on Gf
    envelope_area: 420             # [m²] walls + roof outside, optional: bounds Gw, Cw
    data:
      demo: {seed: 7, gap: [2019-03-10, 2019-03-17]}   # the built-in virtual monument
                                   # (heritage_bayes.demo), or real files:
      weather: {format: knmi, path: ../shared/data/knmi-debilt/uurgeg_260_2011-2020.txt.gz}
      measurements: {format: csv, path: logger.csv, time_column: ..., timezone: ...,
                     columns: {Ti: "TEMP C", RHi: "%RH"}}   # or a list of such tables
      irradiance: measured         # measured | clear_sky (explicit proxy) | none
      surfaces: {N: [90, 0], E: [90, 90], S: [90, 180], W: [90, 270]}  # (tilt, azimuth)
      ground_temperature: {mode: annual_mean}   # or {mode: constant, value: 10},
                        # {mode: column, column: T, source: {format: csv, path: ...}}
      step: 1h
      max_gap: 6h
    periods:                       # dates: UTC unless they carry an offset
      calibration: {start: 2019-01-01, end: 2019-07-01}   # [start, end)
      validation: {start: 2019-07-01, end: 2020-01-01}
      warmup: 14d                  # durations: 1h, 30min, 14d (see parse_duration)
    thermal: {model: thermal_4a, noise: ar1, priors: {Gf: {fixed: 0}}}
    hygric: {model: hygric_2c_fixed, noise: ar1}
    sampler: {max_time: 30min}          # wall-time budget per model; the chain decides
    optimizer: {method: differential_evolution}
"""

from __future__ import annotations

import datetime as _dt
import hashlib
import json
import math
import re
from pathlib import Path
from typing import Annotated, Any, Literal

import pandas as pd
import yaml
from pydantic import (
    BaseModel,
    BeforeValidator,
    ConfigDict,
    Field,
    PrivateAttr,
    ValidationError,
    field_validator,
    model_validator,
)

from heritage_bayes.errors import ConfigError, check_known_keys

__all__ = [
    "CalibrationConfig",
    "chain_tag",
    "config_hash",
    "load_config",
    "parse_config",
    "parse_duration",
]


class _Strict(BaseModel):
    model_config = ConfigDict(extra="forbid", frozen=False, allow_inf_nan=False)


#: Seeds are 32-bit (numpy's RandomState) and each model adds 101 × its index.
MAX_SEED = 2**31 - 1


def _date_text(v):
    """YAML turns ``2019-01-01`` into a date: accept it as the ISO text it was."""
    if isinstance(v, _dt.datetime | _dt.date):
        return v.isoformat()
    return v


#: A date or date-time: YAML dates and strings such as ``2019-01-01`` or
#: ``2019-01-01T06:00``; naive values are UTC, an explicit offset (``+01:00``) is honoured.
DateText = Annotated[str, BeforeValidator(_date_text)]


_DAY_UNIT = re.compile(r"(?<=\d)\s*[dD](?![A-Za-z])")
_HOUR_UNIT = re.compile(r"(?<=\d)\s*H(?![A-Za-z])")


def parse_duration(text) -> pd.Timedelta:
    """A config duration (``'14d'``, ``'1h'``, ``'30min'``, ``'1d12h'``) as a Timedelta.

    ``d``/``D`` are days and ``h``/``H`` hours (pandas 3 deprecates the aliases ``d``
    and ``H``; they are normalised first).
    """
    return pd.Timedelta(_normalise_duration(text))


def _check_duration(v: str, *, positive: bool = False) -> str:
    try:
        td = parse_duration(v)
    except (ValueError, TypeError):
        raise ValueError(
            f"expected a duration such as '1h', '14d' or '30min' (got {v!r})"
        ) from None
    if td < pd.Timedelta(0) or (positive and td == pd.Timedelta(0)):
        raise ValueError(f"must be {'positive' if positive else 'non-negative'} (got {v!r})")
    return _normalise_duration(v)


def _seconds_or_inf(v: str) -> float:
    """A validated duration or ``'none'`` in seconds (``inf`` for none)."""
    return math.inf if v == "none" else parse_duration(v).total_seconds()


def _normalise_duration(v):
    return _HOUR_UNIT.sub("h", _DAY_UNIT.sub("D", v.strip())) if isinstance(v, str) else v


def _utc(text: str) -> pd.Timestamp:
    """A config date as a UTC timestamp (naive values are UTC)."""
    ts = pd.Timestamp(text)
    return ts.tz_localize("UTC") if ts.tzinfo is None else ts.tz_convert("UTC")


def _check_dates(start: str, end: str) -> tuple[pd.Timestamp, pd.Timestamp]:
    try:
        s, e = _utc(start), _utc(end)
    except (ValueError, TypeError) as exc:
        raise ValueError(
            f"start/end must be dates such as 2019-01-01 or 2019-01-01T06:00 ({exc})"
        ) from None
    if not s < e:
        raise ValueError(f"start must be before end (got {start} >= {end})")
    return s, e


class Site(_Strict):
    latitude: float = Field(ge=-90, le=90, description="[° north]")
    longitude: float = Field(ge=-180, le=180, description="[° east]")
    altitude: float = Field(default=0.0, ge=-500, le=9000, description="[m]")


class DemoData(_Strict):
    """The built-in virtual monument (see :mod:`heritage_bayes.demo`).

    ``truth`` overrides documented true parameter values, e.g.
    ``{thermal: {fI_S: 0}, hygric: {Cw: 1.0}}`` (SI units).
    """

    seed: int = 7
    weather: Literal["greensboro_tmy3", "debilt_knmi"] = "greensboro_tmy3"
    weather_path: str | list[str] | None = Field(
        default=None, description="KNMI hourly file(s) for weather 'debilt_knmi'"
    )
    thermal_model: Literal["thermal_4a", "thermal_2c"] = "thermal_4a"
    sensor_noise_T: float = Field(default=0.1, ge=0, description="[K] sd of white noise")
    sensor_noise_RH: float = Field(default=1.0, ge=0, description="[%RH] sd of white noise")
    model_error_T: float = Field(default=0.2, ge=0, description="[K] sd of the AR(1) error")
    model_error_P: float = Field(default=25.0, ge=0, description="[Pa] sd of the AR(1) error")
    model_error_phi: float = Field(default=0.9, ge=0, lt=1, description="[-] hourly AR(1)")
    gap: tuple[DateText, DateText] | None = ("2019-03-10", "2019-03-17")
    truth: dict[Literal["thermal", "hygric"], dict[str, float]] = Field(default_factory=dict)

    @field_validator("gap")
    @classmethod
    def _gap(cls, v):
        if v is not None:
            _check_dates(*v)
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


_CSV_ONLY = (
    "time_column",
    "time_format",
    "time_origin",
    "timezone",
    "columns",
    "sep",
    "decimal",
    "averaged",
    "interval",
    "label",
    "duplicates",
    "na_values",
)


class Source(_Strict):
    """A table to read: ``format`` selects the reader; the rest are its options.

    ``csv``: :func:`heritage_bayes.io.read_csv` (``time_column``, ``timezone`` and the
    ``columns`` mapping ``{standard name: column in the file}``); ``epw``/``tmy3``:
    :func:`~heritage_bayes.io.read_epw`/:func:`~heritage_bayes.io.read_tmy3` (``year``
    for typical years); ``knmi``: :func:`~heritage_bayes.io.read_knmi_hourly` (``path``
    may list consecutive files).
    """

    format: Literal["csv", "epw", "knmi", "tmy3"]
    path: str | list[str]
    time_column: str | list[str] | None = None
    time_format: str | None = None
    time_origin: str | None = Field(
        default=None, description="the time column holds seconds elapsed since this instant"
    )
    timezone: str | None = None
    columns: dict[str, str] | None = None
    sep: str = ","
    decimal: str = "."
    averaged: list[str] | None = None
    interval: str | None = None
    label: Literal["end", "start"] = "end"
    duplicates: Literal["raise", "first", "last", "mean"] = "raise"
    na_values: list[str | float] | None = None
    invalid: Literal["raise", "nan"] = "raise"
    year: int | None = None

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
        if self.interval is not None:
            _check_duration(self.interval, positive=True)
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


class GroundTemperature(_Strict):
    """The fixed (ground) temperature input ``Tf`` of the thermal models.

    ``annual_mean``: the outdoor temperature averaged over a year, see
    :func:`heritage_bayes.prepare.annual_mean_temperature`; ``constant``: ``value``
    [°C]; ``column``: a measured series, the column ``column`` (name in the file) of the
    CSV table ``source`` or, without ``source``, of the weather or measurement CSV files.
    """

    mode: Literal["annual_mean", "constant", "column"] = "annual_mean"
    value: float | None = Field(default=None, ge=-60, le=70, description="[°C] mode constant")
    column: str | None = None
    source: Source | None = None

    @model_validator(mode="after")
    def _check(self):
        if self.mode == "constant" and self.value is None:
            raise ValueError("value: required for mode 'constant' (a temperature in °C)")
        if self.mode == "column" and not self.column:
            raise ValueError("column: required for mode 'column' (a column name in a CSV file)")
        if self.mode != "constant" and self.value is not None:
            raise ValueError(f"value: only for mode 'constant' (mode is {self.mode!r})")
        if self.mode != "column" and (self.column is not None or self.source is not None):
            raise ValueError(f"column/source: only for mode 'column' (mode is {self.mode!r})")
        if self.source is not None:
            if self.source.format != "csv":
                raise ValueError("source: must be a CSV table (format: csv)")
            if self.source.columns is not None:
                raise ValueError("source.columns: not used here; name the column with 'column'")
        return self


#: The four vertical facades (the paper's N, E, S, W): name -> (tilt, azimuth) [°].
_DEFAULT_SURFACES = {
    "N": (90.0, 0.0),
    "E": (90.0, 90.0),
    "S": (90.0, 180.0),
    "W": (90.0, 270.0),
}


def _as_list(v):
    return [v] if isinstance(v, dict) else v


_SURFACE_NAME = re.compile(r"^[A-Za-z][A-Za-z0-9_]*$")


class Data(_Strict):
    demo: DemoData | None = None
    weather: Source | None = None
    #: One table or several (e.g. separate T and RH loggers); kept as a list.
    measurements: Annotated[list[Source] | None, BeforeValidator(_as_list)] = None
    irradiance: Literal["measured", "clear_sky", "none"] = "measured"
    surfaces: dict[str, tuple[float, float]] = Field(
        default_factory=lambda: dict(_DEFAULT_SURFACES),
        description="name -> (tilt [°], azimuth [°, 0 = N, 90 = E])",
    )
    ground_temperature: GroundTemperature = Field(default_factory=GroundTemperature)
    step: str = "1h"
    max_gap: str = "6h"

    @model_validator(mode="after")
    def _one_source(self):
        if self.demo is None and (self.weather is None or self.measurements is None):
            raise ValueError("give either 'demo' or both 'weather' and 'measurements'")
        if self.demo is not None and (self.weather or self.measurements):
            raise ValueError(
                "'demo' generates its own data: remove 'weather' and "
                "'measurements' or remove 'demo'"
            )
        if self.irradiance == "none" and self.surfaces != _DEFAULT_SURFACES:
            raise ValueError(
                "surfaces: given, but irradiance is 'none' (no solar input); remove "
                "'surfaces' or set irradiance to 'measured' or 'clear_sky'"
            )
        return self

    @field_validator("surfaces")
    @classmethod
    def _surfaces(cls, v):
        if not v:
            raise ValueError(
                "at least one surface is needed for solar input; for none set irradiance: none"
            )
        for name, (tilt, az) in v.items():
            if not _SURFACE_NAME.match(name):
                raise ValueError(
                    f"{name!r}: surface names must be letters, digits and '_' starting with "
                    f"a letter (they become input names I_<name>)"
                )
            if not 0 <= tilt <= 180:
                raise ValueError(f"{name}: tilt must be within 0..180° (got {tilt})")
            if not 0 <= az <= 360:
                raise ValueError(f"{name}: azimuth must be within 0..360° (got {az})")
        return v

    @field_validator("step")
    @classmethod
    def _step(cls, v):
        return _check_duration(v, positive=True)

    @field_validator("max_gap")
    @classmethod
    def _max_gap(cls, v):
        return _check_duration(v)


class Period(_Strict):
    """``[start, end)``; naive dates and times are UTC."""

    start: DateText
    end: DateText

    @model_validator(mode="after")
    def _order(self):
        _check_dates(self.start, self.end)
        return self


class Periods(_Strict):
    """Calibration and validation periods, warm-up and initial-state window.

    Default (no periods): the common period of all data, its first 2/3 for calibration
    and the rest for validation. ``warmup``: the first part of the calibration period
    simulated but excluded from the likelihood. Default: none when every model estimates
    its initial state (``initial_state: estimate``, the default of linear models), 14
    days when one starts from the steady state (a controlled room, or
    ``initial_state: steady``). ``init_window``: the mean inputs over the first
    ``init_window`` give the steady state that is the initial state's prior mean (or the
    initial state itself with ``steady``); default 30 days.
    """

    calibration: Period | None = None
    validation: Period | None = None
    warmup: str | None = None
    init_window: str = "30D"

    @field_validator("warmup", "init_window")
    @classmethod
    def _duration(cls, v):
        return v if v is None else _check_duration(v)

    @model_validator(mode="after")
    def _check(self):
        if self.validation is not None and self.calibration is None:
            raise ValueError("calibration: required when 'validation' is given")
        if self.calibration is not None and self.validation is not None:
            cs, ce = _utc(self.calibration.start), _utc(self.calibration.end)
            vs, ve = _utc(self.validation.start), _utc(self.validation.end)
            if vs < ce and cs < ve:
                raise ValueError(
                    f"validation: overlaps the calibration period (calibration "
                    f"{self.calibration.start} to {self.calibration.end}, validation "
                    f"{self.validation.start} to {self.validation.end})"
                )
        if self.calibration is not None:
            length = _utc(self.calibration.end) - _utc(self.calibration.start)
            if self.warmup is not None and parse_duration(self.warmup) >= length:
                raise ValueError(
                    f"warmup: {self.warmup} is not shorter than the calibration period "
                    f"({self.calibration.start} to {self.calibration.end})"
                )
        return self


class ModelSection(_Strict):
    """One calibrated model (thermal or hygric)."""

    model: str | dict[str, Any]
    options: dict[str, Any] = Field(default_factory=dict)
    noise: Literal["ar1_white", "ar1", "iid", "kalman"] = "ar1_white"
    initial_state: Literal["estimate", "steady"] | dict[str, float] | None = Field(
        default=None,
        description="'estimate' (integrated out exactly; default for linear models), "
        "'steady' (default for controlled rooms) or {node: value} [°C or Pa]",
    )
    initial_state_sd: float | None = Field(
        default=None, gt=0, description="[K] or [Pa] prior sd of the estimated initial state"
    )
    initial_state_horizon: str | None = Field(
        default=None,
        description="a duration (e.g. 90d) or 'none': modes slower than it have their "
        "estimated start pulled to the steady state (default: the calibration record)",
    )
    time_constant_cap: str | None = Field(
        default=None,
        description="a duration or 'none': soft prior 1/(1 + (τ/cap)²) on every time "
        "constant (default: 365d for thermal models, none for hygric ones)",
    )
    priors: dict[str, dict[str, Any]] = Field(default_factory=dict)
    room_volume: float | None = Field(default=None, gt=0, description="[m³]")

    @field_validator("initial_state_horizon", "time_constant_cap")
    @classmethod
    def _horizon(cls, v):
        if v is None or v.strip().lower() == "none":
            return v if v is None else "none"
        return _check_duration(v, positive=True)

    def cap_seconds(self, domain: str) -> float:
        """``time_constant_cap`` in seconds (``inf`` for none); the default by domain:
        a year for thermal models (no building node relaxes slower), none for hygric
        ones (deep moisture buffers can take years)."""
        if self.time_constant_cap is None:
            return 365 * 86400.0 if domain == "thermal" else math.inf
        return _seconds_or_inf(self.time_constant_cap)

    @property
    def horizon_seconds(self) -> float | None:
        """``initial_state_horizon`` in seconds: None for the calibration record's
        length, ``inf`` for ``none`` (no slow-mode shrinkage)."""
        h = self.initial_state_horizon
        return None if h is None else _seconds_or_inf(h)


class SamplerSettings(_Strict):
    """emcee settings. Run length comes from the chain (τ, R-hat, ESS); ``max_time`` is
    the wall-time budget per model (a duration, e.g. ``10min``, or ``none``) and
    ``max_steps`` a safety cap on memory."""

    walkers: int | None = Field(default=None, ge=4, le=4096, description="default max(32, 2 d + 2)")
    max_steps: int = Field(default=200_000, ge=100)
    max_time: str | float | None = Field(
        default="30min", description="wall-time budget per model: a duration, or seconds"
    )
    check_every: int = Field(default=500, ge=50)
    tau_factor: float = Field(default=50.0, ge=10)
    tau_rtol: float = Field(default=0.05, gt=0, le=1)
    moves: Literal["de_snooker", "stretch", "de"] = "de_snooker"
    init_ball: float = Field(default=1e-3, gt=0, le=1)
    max_draws: int = Field(default=4000, ge=100)
    n_predictive: int = Field(
        default=1000,
        ge=10,
        description="draws (all walkers) saved in posterior.nc, the same in every group "
        "(posterior, predictive, log-likelihood); PSIS-LOO needs about 1000",
    )

    @field_validator("max_time")
    @classmethod
    def _budget(cls, v):
        if v is None or (isinstance(v, str) and v.strip().lower() == "none"):
            return None
        if isinstance(v, int | float) and not isinstance(v, bool):
            if not v > 0:
                raise ValueError(f"must be a positive number of seconds or a duration (got {v})")
            return f"{float(v):g}s"
        return _check_duration(v, positive=True)

    @property
    def max_seconds(self) -> float | None:
        """``max_time`` in seconds (None: no budget)."""
        return None if self.max_time is None else parse_duration(self.max_time).total_seconds()


class OptimizerSettings(_Strict):
    method: Literal["differential_evolution", "multistart"] = "differential_evolution"
    popsize: int = Field(default=10, ge=4)
    maxiter: int = Field(default=300, ge=10)
    starts: int = Field(default=4, ge=1)


class CalibrationConfig(_Strict):
    name: str | None = None
    building: str = ""
    room: str = ""
    notes: str = ""
    seed: int = Field(default=1, ge=0, le=MAX_SEED)
    site: Site | None = None
    room_volume: float | None = Field(default=None, gt=0, description="[m³]")
    air_change_rate: float | None = Field(
        default=None, gt=0, description="[1/h]: log-normal prior on Gfast of both models"
    )
    air_change_sigma: float = Field(
        default=1.0, gt=0, le=5, description="[-] sd of log(air change rate)"
    )
    floor_area: float | None = Field(
        default=None, gt=0, description="[m²] floor on the ground: log-normal prior on thermal Gf"
    )
    envelope_area: float | None = Field(
        default=None,
        gt=0,
        description="[m²] exterior area of walls and roof: upper bounds on thermal Gw and Cw",
    )
    data: Data
    periods: Periods = Field(default_factory=Periods)
    thermal: ModelSection | None = None
    hygric: ModelSection | None = None
    sampler: SamplerSettings = Field(default_factory=SamplerSettings)
    optimizer: OptimizerSettings = Field(default_factory=OptimizerSettings)
    report: bool = True
    ladder: bool = Field(
        default=True,
        description="MAP fits of the neighbouring model "
        "orders for the accuracy-vs-identifiability comparison",
    )
    base_dir: str | None = Field(default=None, description="set by load_config")
    _source_text: str | None = PrivateAttr(default=None)

    @property
    def source_text(self) -> str | None:
        """The YAML text the config was read from (set by :func:`load_config`)."""
        return self._source_text

    @model_validator(mode="after")
    def _needs_models(self):
        if self.thermal is None and self.hygric is None:
            raise ValueError("give at least one of 'thermal' and 'hygric'")
        if self.data.demo is not None and self.site is not None:
            raise ValueError(
                "site: the demo uses the site of its weather file (Greensboro, NC; De Bilt "
                "for debilt_knmi); remove 'site'"
            )
        site_in_file = self.data.weather is not None and self.data.weather.format in (
            "epw",
            "tmy3",
        )
        needs_sun = self.data.irradiance != "none" and self.data.demo is None
        if needs_sun and self.site is None and not site_in_file:
            raise ValueError(
                "site: required (latitude, longitude) to compute solar "
                "irradiance on the surfaces; or set data.irradiance: none"
            )
        return self

    def resolved(self) -> dict:
        """The config with defaults filled in (what ``config.yaml`` in a run holds)."""
        return self.model_dump(mode="json", exclude={"base_dir"})

    def portable(self) -> dict:
        """:meth:`resolved` with absolute data paths: re-runs from any folder."""
        d = self.resolved()
        data = d["data"]
        sources = [data.get("weather"), *(data.get("measurements") or [])]
        sources.append((data.get("ground_temperature") or {}).get("source"))
        for src in sources:
            if src and src.get("path") is not None:
                p = src["path"]
                absolute = [
                    str(self.path(q).absolute()) for q in ([p] if isinstance(p, str) else p)
                ]
                src["path"] = absolute[0] if isinstance(p, str) else absolute
        demo = data.get("demo") or {}
        if demo.get("weather_path") is not None:  # the demo's KNMI weather file(s)
            p = demo["weather_path"]
            absolute = [str(self.path(q).absolute()) for q in ([p] if isinstance(p, str) else p)]
            demo["weather_path"] = absolute[0] if isinstance(p, str) else absolute
        return d

    def path(self, p: str) -> Path:
        """A data path resolved against the config file's folder."""
        q = Path(p).expanduser()
        return q if q.is_absolute() or self.base_dir is None else Path(self.base_dir) / q


def _allowed_keys(loc, root: type[BaseModel] | None = None) -> list[str]:
    """Field names of the config section at key path ``loc`` (for error hints).

    ``root``: the schema the path starts from (default :class:`CalibrationConfig`)."""
    import typing

    cls: Any = root or CalibrationConfig
    for key in loc:
        if not (isinstance(cls, type) and issubclass(cls, BaseModel)):
            return []
        field = cls.model_fields.get(str(key))
        if field is None:
            continue  # list index or dict key: stay on the same class
        cls = None
        for arg in [field.annotation, *typing.get_args(field.annotation)]:
            for cand in [arg, *typing.get_args(arg)]:
                if isinstance(cand, type) and issubclass(cand, BaseModel):
                    cls = cand
                    break
            if cls is not None:
                break
    if isinstance(cls, type) and issubclass(cls, BaseModel):
        return [k for k in cls.model_fields if k != "base_dir"]
    return []


#: Names pydantic puts into error locations for the members of a union.
_TYPE_TAGS = {"str", "int", "float", "bool", "list", "dict", "tuple", "none", "is-instance"}


def _key_path(loc, raw: Any) -> str:
    """``data.measurements[1].columns`` from a pydantic error location.

    Drops pydantic's validator/union tags (``function-after[...]``, ``list[...]``) and the
    index ``0`` that a single mapping gets when accepted as a list of one.
    """
    text = ""
    node = raw
    for x in loc:
        if isinstance(x, str) and "[" in x:
            continue
        if x in _TYPE_TAGS and not (isinstance(node, dict) and x in node):
            continue  # a union member's tag (``str``, ``int``, ...), not a key
        if isinstance(x, int):
            if isinstance(node, dict):  # a single mapping given where a list is allowed
                continue
            text += f"[{x}]"
            node = node[x] if isinstance(node, list) and -len(node) <= x < len(node) else None
            continue
        text += f".{x}" if text else str(x)
        node = node.get(x) if isinstance(node, dict) else None
    return text


_KEY_PREFIX = re.compile(r"^([A-Za-z_]\w*(?:\.[A-Za-z_]\w*)*): ")


def _format_error(err: dict, raw: Any, root: type[BaseModel] | None = None) -> str:
    loc = _key_path(err["loc"], raw)
    msg = err["msg"]
    if msg.startswith("Value error, "):
        msg = msg[len("Value error, ") :]
    typ = err["type"]
    if typ == "extra_forbidden":
        allowed = _allowed_keys(err["loc"][:-1], root)
        hint = f"; allowed keys: {', '.join(allowed)}" if allowed else ""
        return f"{loc}: unknown key{hint}"
    found = err.get("input")
    if typ == "missing":
        return f"{loc}: required"
    if isinstance(found, dict):  # a section-level check: its message says what was found
        # "warmup: ..." raised by the section 'periods' reads as "periods.warmup: ..."
        m = _KEY_PREFIX.match(msg)
        if m and loc:
            return f"{loc}.{m.group(1)}: {msg[m.end() :]}"
        return f"{loc or '(top level)'}: {msg}"
    if "(got " in msg:  # the check already says what it found
        return f"{loc or '(top level)'}: {msg}"
    return f"{loc or '(top level)'}: {msg} (got {_short(found)})"


def _short(value: Any, limit: int = 120) -> str:
    """``repr`` of a value echoed in a message, cut to a readable length."""
    import reprlib

    if isinstance(value, str) and len(value) <= limit:
        return repr(value)
    r = reprlib.Repr()  # keyword arguments only from Python 3.12
    r.maxstring = r.maxother = limit
    r.maxlist = r.maxtuple = r.maxdict = r.maxset = 8
    r.maxlevel = 3
    text = r.repr(value)
    return text if len(text) <= limit + 10 else text[:limit] + "..."


def parse_config(
    raw: Any, *, source: str = "config", base_dir: str | None = None, name: str | None = None
) -> CalibrationConfig:
    """Validate a parsed YAML mapping; raise :class:`ConfigError` naming key paths."""
    if not isinstance(raw, dict):
        raise ConfigError(
            f"{source}: expected a YAML mapping at the top level (got {type(raw).__name__})"
        )
    check_known_keys(raw, _allowed_keys(()), source=source, what="calibration config")
    try:
        cfg = CalibrationConfig.model_validate(raw)
    except ValidationError as exc:
        lines: list[str] = []
        for e in exc.errors():  # one line per key: union members' messages joined
            line = _format_error(e, raw)
            key, _, msg = line.partition(": ")
            prev = next((i for i, x in enumerate(lines) if x.startswith(f"{key}: ")), None)
            if prev is not None and msg.startswith("Input should be "):
                head, got, tail = lines[prev].rpartition(" (got ")
                extra = msg[len("Input should be ") :].partition(" (got ")[0]
                lines[prev] = (
                    f"{head} or {extra} (got {tail}" if got else f"{lines[prev]} or {extra}"
                )
                continue
            lines.append(line)
        raise ConfigError(f"{source}: invalid configuration:\n  " + "\n  ".join(lines)) from None
    cfg.base_dir = base_dir
    if cfg.name is None:
        cfg.name = name or "run"
    return cfg


class _Loader(yaml.SafeLoader):
    """Safe YAML, stricter: a key given twice in one mapping is an error (YAML would keep
    the last silently), and an impossible date (``2019-13-02``) stays text, so that the
    config check names its key instead of failing inside the YAML parser."""

    def construct_mapping(self, node, deep=False):
        if isinstance(node, yaml.MappingNode):
            seen: dict[str, int] = {}
            for key_node, _ in node.value:
                if key_node.tag == "tag:yaml.org,2002:merge" or not isinstance(
                    key_node, yaml.ScalarNode
                ):
                    continue
                if key_node.value in seen:
                    raise yaml.constructor.ConstructorError(
                        None,
                        None,
                        f"duplicate key {key_node.value!r} (first given at line "
                        f"{seen[key_node.value] + 1})",
                        key_node.start_mark,
                    )
                seen[key_node.value] = key_node.start_mark.line
        return super().construct_mapping(node, deep=deep)

    def _timestamp(self, node):
        try:
            return self.construct_yaml_timestamp(node)
        except ValueError:
            return self.construct_scalar(node)


_Loader.add_constructor("tag:yaml.org,2002:timestamp", _Loader._timestamp)

#: Limits of a config file: size [bytes], values after expanding anchors, nesting depth.
_MAX_BYTES = 1_000_000
_MAX_NODES = 100_000
_MAX_DEPTH = 40


def _check_size(raw: Any, source: str) -> None:
    """Refuse anchor bombs and absurd nesting before anything walks the structure."""
    count = 0
    todo = [(raw, 0)]
    while todo:
        v, depth = todo.pop()
        count += 1
        if count > _MAX_NODES:
            raise ConfigError(
                f"{source}: more than {_MAX_NODES} values after expanding YAML anchors "
                "(aliases *name); a config is far smaller"
            )
        if depth > _MAX_DEPTH:
            raise ConfigError(f"{source}: nested more than {_MAX_DEPTH} levels deep")
        if isinstance(v, dict):
            todo.extend((x, depth + 1) for kv in v.items() for x in kv)
        elif isinstance(v, list | tuple):
            todo.extend((x, depth + 1) for x in v)


def read_yaml(path, *, what: str = "config file") -> tuple[Any, str]:
    """Parse a YAML file strictly; return ``(data, text)``.

    Raises
    ------
    ConfigError
        Missing, too large, not UTF-8, invalid YAML (with line and column), a duplicate
        key, nesting or anchors beyond the limits.
    """
    p = Path(path)
    if not p.is_file():
        raise ConfigError(f"{p}: {what} not found")
    size = p.stat().st_size
    if size > _MAX_BYTES:
        raise ConfigError(f"{p}: {size} bytes, too large for a {what} (at most {_MAX_BYTES})")
    data = p.read_bytes()
    try:
        text = data.decode("utf-8-sig")
    except UnicodeDecodeError as exc:
        raise ConfigError(
            f"{p}: not UTF-8 text (byte 0x{data[exc.start]:02x} at offset {exc.start}); "
            "save the file as UTF-8"
        ) from None
    try:
        raw = yaml.load(text, Loader=_Loader)  # a SafeLoader
    except yaml.YAMLError as exc:
        mark = getattr(exc, "problem_mark", None)
        where = f" at line {mark.line + 1}, column {mark.column + 1}" if mark else ""
        problem = getattr(exc, "problem", None) or str(exc).splitlines()[0]
        raise ConfigError(f"{p}: not valid YAML{where}: {str(problem)[:200]}") from None
    except RecursionError:
        raise ConfigError(f"{p}: nested more than {_MAX_DEPTH} levels deep") from None
    _check_size(raw, str(p))
    return raw, text


def load_config(path) -> CalibrationConfig:
    """Read and validate a YAML config file (see :func:`read_yaml` for the limits).

    Raises
    ------
    ConfigError
        Missing file, invalid YAML (with line and column), or invalid content (with
        key paths).
    """
    p = Path(path)
    raw, text = read_yaml(p)
    cfg = parse_config(raw, source=str(p), base_dir=str(p.parent.resolve()), name=p.stem)
    cfg._source_text = text
    return cfg


def chain_tag(cfg: CalibrationConfig) -> str:
    """Hash of what determines the Markov chains (data, models, priors, seed, walkers,
    moves, optimiser), leaving out run-length settings (``max_steps``, ``check_every``,
    ``tau_factor``, ...) and outputs, so that ``--resume`` may extend a run."""
    d = cfg.resolved()
    keep = {k: d["sampler"][k] for k in ("walkers", "moves", "init_ball")}
    d = {**d, "sampler": keep}
    for k in ("report", "ladder", "name", "building", "room", "notes"):
        d.pop(k, None)
    blob = json.dumps(d, sort_keys=True, default=str).encode()
    return hashlib.sha256(blob).hexdigest()[:16]


def config_hash(cfg: CalibrationConfig) -> str:
    """SHA-256 (first 16 hex digits) of the resolved config."""
    blob = json.dumps(cfg.resolved(), sort_keys=True, default=str).encode()
    return hashlib.sha256(blob).hexdigest()[:16]
