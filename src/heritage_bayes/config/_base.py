"""Building blocks of the schema: the strict base model, documented keys, typed durations,
time zones and dates.

Every key of the schema is declared with :func:`key`: a description, a unit (``None``
for text and choices) and a default, kept in pydantic's field info where the generated
configuration reference and ``hbayes init`` read them (:mod:`heritage_bayes.config.reference`).
"""

from __future__ import annotations

import datetime as _dt
from collections.abc import Mapping
from typing import Annotated, Any

import pandas as pd
from pydantic import (
    BaseModel,
    BeforeValidator,
    ConfigDict,
    Field,
    PlainSerializer,
    PlainValidator,
    WithJsonSchema,
)
from pydantic_core import PydanticCustomError, PydanticUndefined, core_schema

from heritage_bayes.convert import format_timedelta, parse_duration, parse_timezone, timezone_text
from heritage_bayes.errors import InputError

__all__ = [
    "MAX_SEED",
    "Choices",
    "DateText",
    "Duration",
    "NonNegativeDuration",
    "TimeZone",
    "check_dates",
    "check_in_range",
    "key",
    "range_text",
    "utc",
]

#: Seeds are 32-bit (numpy's RandomState) and each model adds 101 × its index.
MAX_SEED = 2**31 - 1

#: The unit of duration keys in the schema: the value carries its own unit.
DURATION_UNIT = "duration"


class Choices:
    """A key whose value is a name of a registry (a mapping, read at each validation, so
    that a name registered after this module's import is accepted): the type of
    ``noise:`` and ``sampler.moves``, e.g. ``Annotated[str, Choices(NOISE_MODELS)]``.

    A wrong name gets pydantic's own message for a ``Literal`` (``Input should be 'a',
    'b' or 'c'``); the JSON schema and the generated reference list the names."""

    def __init__(self, registry: Mapping[str, Any], *, described: bool = False):
        self.registry = registry
        #: The key's description in the references goes on with the names and their
        #: entries' ``description`` (:meth:`describe`).
        self.described = described

    def describe(self, text: str) -> str:
        """A key's description ``text``, followed when ``described`` by each name with
        its entry's ``description``, read now (a name registered later shows too)."""
        if not self.described:
            return text
        return f"{text}: " + ", ".join(f"{n} ({e.description})" for n, e in self.registry.items())

    @property
    def names(self) -> tuple[str, ...]:
        return tuple(self.registry)

    def _check(self, value: Any) -> str:
        if isinstance(value, str) and value in self.registry:
            return value
        quoted = [repr(n) for n in self.names]
        expected = " or ".join([", ".join(quoted[:-1]), quoted[-1]] if len(quoted) > 1 else quoted)
        raise PydanticCustomError(
            "literal_error", "Input should be {expected}", {"expected": expected}
        )

    def __get_pydantic_core_schema__(self, source: Any, handler: Any) -> Any:
        return core_schema.no_info_plain_validator_function(self._check)

    def __get_pydantic_json_schema__(self, schema: Any, handler: Any) -> dict:
        return {"enum": list(self.names), "type": "string"}


class _Strict(BaseModel):
    """Unknown keys are refused; no NaN or infinity."""

    model_config = ConfigDict(extra="forbid", frozen=False, allow_inf_nan=False)


def key(
    default: Any = PydanticUndefined,
    *,
    unit: str | None,
    description: str,
    **kwargs: Any,
) -> Any:
    """A documented config key: ``Field`` with its description and unit.

    Parameters
    ----------
    default : optional
        The default (omit for a required key; or pass ``default_factory``).
    unit : str or None
        ``'°C'``, ``'m³'``, ``'-'`` (dimensionless), ``'duration'`` (text with its own
        unit, e.g. ``10min``), or None for text and choices.
    description : str
        One or two sentences for the configuration reference.
    **kwargs
        Passed to :func:`pydantic.Field` (bounds ``ge``, ``gt``, ...).
    """
    if not description.strip():
        raise ValueError("key: a description is required")
    return Field(default, description=description, json_schema_extra={"unit": unit}, **kwargs)


def range_text(field: Any) -> str:
    """The allowed range of a key with its unit, from its bounds (``ge``, ``gt``,
    ``le``, ``lt``): ``'[-20, 40] °C'``, ``'> 0 W'``, ``'0..2147483647'``; empty
    without bounds."""
    lo = hi = None
    lo_open = hi_open = False
    for m in field.metadata:
        for attr, is_lo, is_open in (("ge", 1, 0), ("gt", 1, 1), ("le", 0, 0), ("lt", 0, 1)):
            v = getattr(m, attr, None)
            if v is None:
                continue
            if is_lo:
                lo, lo_open = v, bool(is_open)
            else:
                hi, hi_open = v, bool(is_open)
    extra = field.json_schema_extra if isinstance(field.json_schema_extra, dict) else {}
    unit = extra.get("unit")
    unit = f" {unit}" if unit and unit not in ("-", "duration") else ""
    if lo is None and hi is None:
        return ""
    if field.annotation is int and lo is not None and hi is not None:
        return f"{lo}..{hi}{unit}"
    if hi is None:
        return f"{'>' if lo_open else '>='} {lo:g}{unit}"
    if lo is None:
        return f"{'<' if hi_open else '<='} {hi:g}{unit}"
    return f"{'(' if lo_open else '['}{lo:g}, {hi:g}{')' if hi_open else ']'}{unit}"


def check_in_range(model: type[BaseModel], name: str, value: Any, option: str) -> None:
    """Check a value given outside a config file (a command-line option) against the
    range of the schema's key ``model.name``: one range per quantity.

    Raises
    ------
    ConfigError
        Naming ``option``, the value and the allowed range with its unit.
    """
    from pydantic import TypeAdapter, ValidationError

    from heritage_bayes.errors import ConfigError

    field = model.model_fields[name]
    try:
        TypeAdapter(Annotated[field.annotation, *field.metadata]).validate_python(value)
    except ValidationError:
        raise ConfigError(
            f"{option}: outside the allowed range {range_text(field)} (got {value})"
        ) from None


def _duration(v: Any, *, positive: bool) -> pd.Timedelta:
    try:
        td = parse_duration(v)
    except ValueError as exc:
        raise ValueError(str(exc)) from None
    if td < pd.Timedelta(0) or (positive and td == pd.Timedelta(0)):
        shown = v if isinstance(v, str) else format_timedelta(td)
        raise ValueError(f"must be {'positive' if positive else 'non-negative'} (got {shown!r})")
    return td


_AS_TEXT = PlainSerializer(format_timedelta, return_type=str)
_DURATION_SCHEMA = WithJsonSchema({"type": "string", "format": "duration-with-unit"})

#: A positive duration with its unit (``'1h'``, ``'14d'``, ``'30min'``) as a Timedelta;
#: written back as compact text (``'14D'``). A bare number is refused.
Duration = Annotated[
    pd.Timedelta,
    PlainValidator(lambda v: _duration(v, positive=True)),
    _AS_TEXT,
    _DURATION_SCHEMA,
]
#: The same, zero allowed.
NonNegativeDuration = Annotated[
    pd.Timedelta,
    PlainValidator(lambda v: _duration(v, positive=False)),
    _AS_TEXT,
    _DURATION_SCHEMA,
]


def _timezone(v: Any) -> _dt.tzinfo:
    try:
        return parse_timezone(v)
    except InputError as exc:
        raise ValueError(str(exc)) from None


#: A clock: ``UTC``, a fixed offset (``UTC+2``) or an IANA zone with DST
#: (``Europe/Helsinki``), as a tzinfo; written back as text.
TimeZone = Annotated[
    _dt.tzinfo,
    PlainValidator(_timezone),
    PlainSerializer(timezone_text, return_type=str),
    WithJsonSchema({"type": "string", "format": "time-zone"}),
]


def _date_text(v):
    """YAML turns ``2019-01-01`` into a date: accept it as the ISO text it was."""
    if isinstance(v, _dt.datetime | _dt.date):
        return v.isoformat()
    return v


#: A date or date-time: YAML dates and strings such as ``2019-01-01`` or
#: ``2019-01-01T06:00``; naive values are UTC, an explicit offset (``+01:00``) is honoured.
DateText = Annotated[str, BeforeValidator(_date_text)]


def utc(text: str) -> pd.Timestamp:
    """A config date as a UTC timestamp (naive values are UTC)."""
    ts = pd.Timestamp(text)
    return ts.tz_localize("UTC") if ts.tzinfo is None else ts.tz_convert("UTC")


def check_dates(start: str, end: str) -> tuple[pd.Timestamp, pd.Timestamp]:
    """``start`` and ``end`` as UTC timestamps; ValueError unless start < end."""
    try:
        s, e = utc(start), utc(end)
    except (ValueError, TypeError) as exc:
        raise ValueError(
            f"start/end must be dates such as 2019-01-01 or 2019-01-01T06:00 ({exc})"
        ) from None
    if not s < e:
        raise ValueError(f"start must be before end (got {start} >= {end})")
    return s, e
