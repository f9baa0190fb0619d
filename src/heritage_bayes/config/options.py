"""Options of one calibrated model (``thermal.options``, ``hygric.options``), typed when
the config is loaded.

Two kinds: the network's own (``surfaces``, ``ground``, ``heating`` of the thermal
catalogue models, ``sink`` of the hygric models with a fixed node), passed to the
catalogue model's factory as keywords, and the control of the air node (``thermostat``,
``humidistat``, ``source``), which becomes one
:class:`~heritage_bayes.rc.control_spec.Control`. Which catalogue model takes which
network option is the model's own business (its factory's keywords): the model building
checks that, naming the key.

The YAML shorthands become typed values here and nowhere else: ``thermostat: true`` is a
thermostat with the defaults, ``humidistat: band`` a humidistat in that mode, ``false``
none; a weekly schedule becomes a :class:`heritage_bayes.rc.calendar.WeeklyCalendar`.
"""

from __future__ import annotations

from typing import TYPE_CHECKING, Annotated, Any, Literal

from pydantic import (
    ConfigDict,
    PrivateAttr,
    field_validator,
    model_serializer,
    model_validator,
)

from heritage_bayes.config._base import Choices, _Strict, key
from heritage_bayes.names import CONTROLS, HUMIDISTAT_MODES

if TYPE_CHECKING:  # the numerics load when a model is built, not with the settings
    from heritage_bayes.rc.calendar import WeeklyCalendar
    from heritage_bayes.rc.control_spec import Control

__all__ = [
    "NETWORK_OPTIONS",
    "HumidistatOptions",
    "ModelOptions",
    "ThermostatOptions",
    "parse_options",
]

#: The options that are the network's (keywords of a catalogue model's factory).
NETWORK_OPTIONS = ("surfaces", "ground", "heating", "sink", "isotherm")


class ThermostatOptions(_Strict):
    """Heating of the air node to an estimated set-point ``Tset`` [°C]."""

    model_config = ConfigDict(frozen=True)

    power_limit: bool = key(
        False,
        unit=None,
        strict=True,
        description="estimate the maximum heating power Pmax [W] (otherwise the heating is ideal)",
    )
    schedule: str | dict[str, Any] | None = key(
        None,
        unit=None,
        description="the hours of use, with their own set-point Tset_use [°C]: an input "
        "column (1 in use, 0 not, fractions allowed) or a weekly calendar {weekly: "
        "['Sun 08-12'], timezone: UTC+1}",
    )
    conservation: bool = key(
        False,
        unit=None,
        strict=True,
        description="conservation heating: the set-point is raised to keep the RH of the "
        "measured vapour pressure Pi at most RH_ch [-]",
    )
    _calendar: Any = PrivateAttr(default=None)

    @model_validator(mode="after")
    def _weekly(self):
        s = self.schedule
        if isinstance(s, dict):
            from heritage_bayes.rc.calendar import parse_weekly

            self._calendar = parse_weekly(s, "schedule")
        elif s is not None and not s:
            raise ValueError(
                "schedule: expected an input column name or a weekly calendar "
                "{weekly: ['Sun 08-12'], timezone: UTC+1} (got '')"
            )
        return self

    @property
    def calendar(self) -> WeeklyCalendar | None:
        """The weekly calendar of the hours of use (None for a schedule column)."""
        return self._calendar

    @property
    def column(self) -> str | None:
        """The input column of the hours of use: the configured one, or
        :data:`~heritage_bayes.rc.control_spec.HOURS_OF_USE` for a weekly calendar."""
        from heritage_bayes.rc.control_spec import HOURS_OF_USE

        return HOURS_OF_USE if self._calendar is not None else self.schedule


class HumidistatOptions(_Strict):
    """The air's RH at the indoor temperature held by a (de)humidifier."""

    model_config = ConfigDict(frozen=True)

    mode: Annotated[str, Choices(dict.fromkeys(HUMIDISTAT_MODES))] = key(
        "band",
        unit=None,
        description="band: within [RH_lo, RH_hi]; dehumidifier: below RH_hi; humidifier: "
        "above RH_lo; setpoint: at RH_set",
    )
    capacity: bool = key(
        False,
        unit=None,
        strict=True,
        description="estimate the dehumidifier's and humidifier's capacities M_dehum, "
        "M_hum [kg/s] (otherwise ideal)",
    )


def _switch(value: Any, shape: str, short: type | None = None) -> Any:
    """A control given as ``true`` (the defaults), ``false``/null (none), a mapping, or
    (``short``) a bare ``mode``."""
    if value is None or value is False:
        return None
    if value is True:
        return {}
    if short is not None and isinstance(value, short):
        return {"mode": value}
    if isinstance(value, dict | ThermostatOptions | HumidistatOptions):
        return value
    raise ValueError(f"expected {shape} (got {value!r})")


class ModelOptions(_Strict):
    """The options of one model section. Serialised as written (a run's ``config.yaml``
    echoes the user's text), used typed; frozen, so that the two agree (other options
    are a new :meth:`model_validate`)."""

    model_config = ConfigDict(frozen=True)

    surfaces: list[str] | None = key(
        None,
        unit=None,
        description="solar surfaces of a thermal model with solar input (default: "
        "data.surfaces, none with data.irradiance: none)",
    )
    ground: bool | Literal["estimate"] | None = key(
        None,
        unit=None,
        description="thermal: true (default): a conductance Gf to the ground temperature "
        "Tf (an input); false: none; estimate: Tf [°C] a constant to estimate",
    )
    heating: bool | None = key(
        None,
        unit=None,
        description="thermal: a measured heating power Ph [W] into the air (an input of "
        "known gain 1; it pins the absolute scale of C and G)",
    )
    sink: Literal["none", "constant", "temperature"] | None = key(
        None,
        unit=None,
        description="hygric_2c_fixed: constant (default) or temperature (a vapour sink at "
        "phi_f·psat(Tf)); hygric_2c_sorption: none (default), constant or temperature",
    )
    isotherm: Literal["linear", "gab"] | None = key(
        None,
        unit=None,
        description="hygric_2c_fixed, hygric_2c_sorption: the buffer's sorption isotherm, "
        "linear (default: one capacity) or gab (a capacity that follows the buffer's "
        "humidity, the GAB isotherm's slope with its multilayer factor K_gab estimated)",
    )
    thermostat: ThermostatOptions | None = key(
        None,
        unit=None,
        description="thermal: heating to a set-point Tset [°C]: true, or a mapping of the "
        "keys below",
    )
    humidistat: HumidistatOptions | None = key(
        None,
        unit=None,
        description="hygric: a humidistat: true, a mode (band, dehumidifier, humidifier, "
        "setpoint) or a mapping of the keys below",
    )
    source: bool = key(
        False,
        unit=None,
        strict=True,
        description="a constant source into the air, estimated: heat Qs [W] (thermal) or "
        "moisture Ms [kg/s] (hygric)",
    )
    _given: dict = PrivateAttr(default_factory=dict)

    @field_validator("ground", mode="before")
    @classmethod
    def _ground(cls, v):
        if v is None or isinstance(v, bool) or v == "estimate":
            return v
        raise ValueError(f"option ground must be true, false or 'estimate' (got {v!r})")

    @field_validator("heating", mode="before")
    @classmethod
    def _heating(cls, v):
        if v is None or isinstance(v, bool):
            return v
        raise ValueError(f"expected true or false (got {v!r})")

    @field_validator("thermostat", mode="before")
    @classmethod
    def _thermostat(cls, v):
        shape = "true, false or a mapping with keys " + _keys(ThermostatOptions)
        return _switch(v, shape)

    @field_validator("humidistat", mode="before")
    @classmethod
    def _humidistat(cls, v):
        shape = f"true, false, a mode {list(HUMIDISTAT_MODES)} or a mapping with keys " + _keys(
            HumidistatOptions
        )
        return _switch(v, shape, short=str)

    @model_validator(mode="wrap")
    @classmethod
    def _keep_given(cls, data, handler):
        m = handler(data)
        if isinstance(data, dict):
            m._given = dict(data)
        return m

    @model_serializer(mode="plain")
    def _as_given(self) -> dict:
        return dict(self._given)

    def given(self) -> dict:
        """The options as written in the config (a copy)."""
        return dict(self._given)

    def network_options(self) -> dict:
        """The network's options that were given, typed: keywords of the catalogue
        model's factory (``surfaces`` a tuple)."""
        out = {k: getattr(self, k) for k in NETWORK_OPTIONS if k in self._given}
        if out.get("surfaces") is not None:
            out["surfaces"] = tuple(out["surfaces"])
        return out

    def control(self) -> Control:
        """The control of the air node (inactive when none is configured)."""
        from heritage_bayes.rc.control_spec import Control

        t, h = self.thermostat, self.humidistat
        kw: dict = {"source": self.source}
        if t is not None:
            kw.update(
                thermostat=True,
                power_limit=t.power_limit,
                schedule=t.column,
                calendar=t.calendar,
                conservation=t.conservation,
            )
        if h is not None:
            kw.update(humidistat=h.mode, capacity=h.capacity)
        return Control(**kw)

    def misplaced_control(self, domain: str) -> str | None:
        """The control option given that does not belong to a ``domain`` model
        (``humidistat`` for a thermal one, ``thermostat`` for a hygric one), or None."""
        given = [k for k in ("thermostat", "humidistat") if getattr(self, k) is not None]
        return next((k for k in given if CONTROLS[k] != domain), None)


def _keys(cls) -> str:
    return ", ".join(cls.model_fields)


def parse_options(options: dict, where: str) -> ModelOptions:
    """Options given as keywords (``heritage_bayes.model(name, **options)``), typed.

    Raises
    ------
    ConfigError
        One clause per wrong option, each naming its key, what was expected and what
        was found; ``where`` leads the message.
    """
    from pydantic import ValidationError

    from heritage_bayes.config._messages import join_errors
    from heritage_bayes.errors import ConfigError

    try:
        return ModelOptions.model_validate(dict(options))
    except ValidationError as exc:
        lines = join_errors(exc.errors(), dict(options), ModelOptions)
        raise ConfigError(f"{where}: " + "; ".join(lines)) from None
