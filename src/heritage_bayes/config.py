"""The validated YAML configuration of ``hbayes calibrate``.

Unknown keys are rejected; every error names the key path, the expected form and the
value found, e.g. ``priors.Gw.lower: must be < upper (got 500 > 200)``. Relative paths
in ``data`` are relative to the config file.

Layout (see ``configs/demo.yaml`` for a complete, commented example)::

    name: my_room                  # run name; default: the config file's stem
    building: Castle X             # free text, shown in the report (escaped)
    room: Great hall
    notes: ...
    seed: 1
    site: {latitude: 52.1, longitude: 5.18, altitude: 2}
    room_volume: 800               # [m³], optional: log-normal prior on each model's Ci
    data:
      demo: {...}                  # the built-in virtual monument, or:
      weather: {format: knmi, path: ../shared/data/knmi-debilt/uurgeg_260_2011-2020.txt.gz}
      measurements: {format: csv, path: logger.csv, time_column: ..., timezone: ...,
                     columns: {Ti: "TEMP C", RHi: "%RH"}}
      irradiance: measured         # measured | clear_sky (explicit proxy) | none
      surfaces: {N: [90, 0], E: [90, 90], S: [90, 180], W: [90, 270]}
      ground_temperature: {mode: annual_mean}   # or {mode: constant, value: 10},
                                                #    {mode: column, column: Tg}
      step: 1h
      max_gap: 6h
    periods:
      calibration: {start: 2019-01-01, end: 2019-07-01}
      validation: {start: 2019-07-01, end: 2020-01-01}
      warmup: 14d
    thermal: {model: thermal_4a, noise: ar1, priors: {Gf: {fixed: 0}}}
    hygric: {model: hygric_2c_fixed, noise: ar1}
    sampler: {max_steps: 20000}
    optimizer: {method: differential_evolution}
"""

from __future__ import annotations

import hashlib
import json
from pathlib import Path
from typing import Any, Literal

import pandas as pd
import yaml
from pydantic import BaseModel, ConfigDict, Field, ValidationError, field_validator, model_validator

from heritage_bayes.errors import ConfigError

__all__ = ["CalibrationConfig", "config_hash", "load_config", "parse_config"]


class _Strict(BaseModel):
    model_config = ConfigDict(extra="forbid", frozen=False)


class Site(_Strict):
    latitude: float = Field(ge=-90, le=90, description="[° north]")
    longitude: float = Field(ge=-180, le=180, description="[° east]")
    altitude: float = Field(default=0.0, ge=-500, le=9000, description="[m]")


class DemoData(_Strict):
    """The built-in virtual monument (see :mod:`heritage_bayes.demo`)."""

    seed: int = 7
    weather: Literal["greensboro_tmy3"] = "greensboro_tmy3"
    sensor_noise_T: float = Field(default=0.1, ge=0, description="[K] sd of white noise")
    sensor_noise_RH: float = Field(default=1.0, ge=0, description="[%RH] sd")
    gap: tuple[str, str] | None = ("2019-03-10", "2019-03-17")


class Source(_Strict):
    """A table to read: ``format`` selects the reader; the rest are its options."""

    format: Literal["csv", "epw", "knmi", "tmy3"]
    path: str
    time_column: str | list[str] | None = None
    time_format: str | None = None
    timezone: str | None = None
    columns: dict[str, str] | None = None
    sep: str = ","
    decimal: str = "."
    averaged: list[str] | None = None
    interval: str | None = None
    label: Literal["end", "start"] = "end"
    duplicates: Literal["raise", "first", "last", "mean"] = "raise"
    year: int | None = None

    @model_validator(mode="after")
    def _csv_needs_time(self):
        if self.format == "csv" and self.time_column is None:
            raise ValueError("time_column: required for format 'csv'")
        if self.format != "csv":
            extra = [
                k
                for k in ("time_column", "time_format", "timezone", "columns")
                if getattr(self, k) is not None
            ]
            if extra:
                raise ValueError(f"{extra}: only for format 'csv' (format is {self.format!r})")
        return self


class GroundTemperature(_Strict):
    mode: Literal["annual_mean", "constant", "column"] = "annual_mean"
    value: float | None = Field(default=None, description="[°C] for mode constant")
    column: str | None = None

    @model_validator(mode="after")
    def _check(self):
        if self.mode == "constant" and self.value is None:
            raise ValueError("value: required for mode 'constant' (a temperature in °C)")
        if self.mode == "column" and not self.column:
            raise ValueError("column: required for mode 'column'")
        return self


class Data(_Strict):
    demo: DemoData | None = None
    weather: Source | None = None
    measurements: Source | list[Source] | None = None
    irradiance: Literal["measured", "clear_sky", "none"] = "measured"
    surfaces: dict[str, tuple[float, float]] = Field(
        default_factory=lambda: {
            "N": (90.0, 0.0),
            "E": (90.0, 90.0),
            "S": (90.0, 180.0),
            "W": (90.0, 270.0),
        },
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
        return self

    @field_validator("surfaces")
    @classmethod
    def _surfaces(cls, v):
        for name, (tilt, az) in v.items():
            if not 0 <= tilt <= 180:
                raise ValueError(f"{name}: tilt must be within 0..180° (got {tilt})")
            if not 0 <= az <= 360:
                raise ValueError(f"{name}: azimuth must be within 0..360° (got {az})")
        return v

    @field_validator("step", "max_gap")
    @classmethod
    def _duration(cls, v):
        try:
            td = pd.Timedelta(v)
        except (ValueError, TypeError):
            raise ValueError(f"expected a duration such as '1h' or '30min' (got {v!r})") from None
        if td < pd.Timedelta(0):
            raise ValueError(f"must not be negative (got {v!r})")
        return v


class Period(_Strict):
    start: str
    end: str

    @model_validator(mode="after")
    def _order(self):
        try:
            s, e = pd.Timestamp(self.start), pd.Timestamp(self.end)
        except (ValueError, TypeError) as exc:
            raise ValueError(f"start/end must be dates such as 2019-01-01 ({exc})") from None
        if not s < e:
            raise ValueError(f"start must be before end (got {self.start} >= {self.end})")
        return self


class Periods(_Strict):
    calibration: Period | None = None
    validation: Period | None = None
    warmup: str = "14d"
    init_window: str = "7d"


class ModelSection(_Strict):
    """One calibrated model (thermal or hygric)."""

    model: str | dict[str, Any]
    options: dict[str, Any] = Field(default_factory=dict)
    noise: Literal["ar1", "iid"] = "ar1"
    priors: dict[str, dict[str, Any]] = Field(default_factory=dict)
    room_volume: float | None = Field(default=None, gt=0, description="[m³]")


class SamplerSettings(_Strict):
    walkers: int | None = Field(default=None, ge=4, description="default max(32, 2 d + 2)")
    max_steps: int = Field(default=20000, ge=100)
    check_every: int = Field(default=500, ge=50)
    tau_factor: float = Field(default=50.0, ge=10)
    tau_rtol: float = Field(default=0.05, gt=0, le=1)
    moves: Literal["de_snooker", "stretch", "de"] = "de_snooker"
    init_ball: float = Field(default=1e-3, gt=0, le=1)
    max_draws: int = Field(default=4000, ge=100)
    n_predictive: int = Field(default=200, ge=10)


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
    seed: int = 1
    site: Site | None = None
    room_volume: float | None = Field(default=None, gt=0, description="[m³]")
    data: Data
    periods: Periods = Field(default_factory=Periods)
    thermal: ModelSection | None = None
    hygric: ModelSection | None = None
    sampler: SamplerSettings = Field(default_factory=SamplerSettings)
    optimizer: OptimizerSettings = Field(default_factory=OptimizerSettings)
    report: bool = True
    base_dir: str | None = Field(default=None, description="set by load_config")

    @model_validator(mode="after")
    def _needs_models(self):
        if self.thermal is None and self.hygric is None:
            raise ValueError("give at least one of 'thermal' and 'hygric'")
        needs_sun = self.data.irradiance != "none" and self.data.demo is None
        if needs_sun and self.site is None:
            raise ValueError(
                "site: required (latitude, longitude) to compute solar "
                "irradiance on the surfaces; or set data.irradiance: none"
            )
        return self

    def resolved(self) -> dict:
        """The config with defaults filled in (what ``config.yaml`` in a run holds)."""
        return self.model_dump(mode="json", exclude={"base_dir"})

    def path(self, p: str) -> Path:
        """A data path resolved against the config file's folder."""
        q = Path(p).expanduser()
        return q if q.is_absolute() or self.base_dir is None else Path(self.base_dir) / q


def _allowed_keys(loc) -> list[str]:
    """Field names of the config section at key path ``loc`` (for error hints)."""
    import typing

    cls: Any = CalibrationConfig
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


def _format_error(err: dict, raw: Any) -> str:
    loc = ".".join(str(x) for x in err["loc"] if not str(x).startswith("function-"))
    msg = err["msg"]
    if msg.startswith("Value error, "):
        msg = msg[len("Value error, ") :]
    typ = err["type"]
    if typ == "extra_forbidden":
        allowed = _allowed_keys(err["loc"][:-1])
        hint = f"; allowed keys: {', '.join(allowed)}" if allowed else ""
        return f"{loc}: unknown key{hint}"
    found = err.get("input")
    if typ == "missing":
        return f"{loc}: required"
    if isinstance(found, dict):  # a section-level check: its message says what was found
        return f"{loc or '(top level)'}: {msg}"
    return f"{loc or '(top level)'}: {msg} (got {found!r})"


def parse_config(
    raw: Any, *, source: str = "config", base_dir: str | None = None, name: str | None = None
) -> CalibrationConfig:
    """Validate a parsed YAML mapping; raise :class:`ConfigError` naming key paths."""
    if not isinstance(raw, dict):
        raise ConfigError(
            f"{source}: expected a YAML mapping at the top level (got {type(raw).__name__})"
        )
    try:
        cfg = CalibrationConfig.model_validate(raw)
    except ValidationError as exc:
        lines = [_format_error(e, raw) for e in exc.errors()]
        raise ConfigError(f"{source}: invalid configuration:\n  " + "\n  ".join(lines)) from None
    cfg.base_dir = base_dir
    if cfg.name is None:
        cfg.name = name or "run"
    return cfg


def load_config(path) -> CalibrationConfig:
    """Read and validate a YAML config file.

    Raises
    ------
    ConfigError
        Missing file, invalid YAML (with line and column), or invalid content (with
        key paths).
    """
    p = Path(path)
    if not p.is_file():
        raise ConfigError(f"{p}: config file not found")
    try:
        raw = yaml.safe_load(p.read_text(encoding="utf-8"))
    except yaml.YAMLError as exc:
        mark = getattr(exc, "problem_mark", None)
        where = f" at line {mark.line + 1}, column {mark.column + 1}" if mark else ""
        raise ConfigError(f"{p}: not valid YAML{where}: {getattr(exc, 'problem', exc)}") from None
    return parse_config(raw, source=str(p), base_dir=str(p.parent.resolve()), name=p.stem)


def config_hash(cfg: CalibrationConfig) -> str:
    """SHA-256 (first 16 hex digits) of the resolved config."""
    blob = json.dumps(cfg.resolved(), sort_keys=True, default=str).encode()
    return hashlib.sha256(blob).hexdigest()[:16]
