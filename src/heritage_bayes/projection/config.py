"""The projection file (``hbayes project RUN_DIR PROJECTION.yaml``): validated schema.

Example (morphing, for any site)::

    name: demo_2050
    humidity: constant_rh        # or constant_vapour_pressure, table (morphing only)
    draws: 200                   # posterior draws (each with its own noise draw)
    seed: 1
    morphing:
      - scenario: moderate
        horizon: 2050
        method: shift_stretch    # shift | stretch | shift_stretch
        deltas:                  # 12 monthly values each, January first (or a CSV path)
          Te: [1.4, 1.4, 1.3, 1.2, 1.2, 1.4, 1.6, 1.7, 1.5, 1.4, 1.4, 1.5]   # [K]
          Te_max: [...]          # [K], for shift_stretch
          Te_min: [...]
          ghi: [...]             # [%]

KNMI'14 (Dutch sites)::

    knmi14:
      tables: ../shared/data/knmi14-deltas
      scenarios: [GL, GH, WL, WH]
      horizons: [2050, 2085]     # 2030: one table for all four scenarios
      region: MON                # default: from the KNMI station of the weather file

User-supplied future weather::

    files:
      - {scenario: rcp85, horizon: 2080, weather: {format: epw, path: future.epw}}

``baseline``: the weather the transformations start from (a ``Source`` as in the
calibration config); default the calibration's own weather. A baseline or future file
whose site lies more than 50 km from the calibration's is refused unless
``allow_other_site: true``. Relative paths are relative to the projection file.

Interventions (``interventions``, :mod:`heritage_bayes.projection.interventions`):
named changes to the calibrated room, each simulated draw by draw with the same
parameters, noise and weather as doing nothing, on the baseline and every future::

    interventions:
      - name: conservation heating
        conservation_heating: {rh_max: 65, t_min: 5, t_max: 20, power_max: 3000}
      - name: dehumidifier
        dehumidification: {rh_max: 60, capacity: 0.5, energy_per_kg: 0.7}
      - name: half the ventilation
        ventilation: {factor: 0.5}
      - name: heating for services
        heating: {t_set: 8, t_use: 16, weekly: ["Sun 08-12"], timezone: UTC+1}

      - name: humidistat band
        humidistat_band: {rh_min: 45, rh_max: 60, dehumidifier_capacity: 1,
                          humidifier_capacity: 0.5, differential: 5}
      - name: conservation heating and a dehumidifier
        conservation_heating: {rh_max: 70, t_max: 18}
        dehumidification: {rh_max: 60, capacity: 0.5}

(a thermostat, ``heating`` or ``conservation_heating``, combines with a humidistat,
``dehumidification`` or ``humidistat_band``: both models are stepped together, each
controller reading the other's air; ``ventilation`` combines with any.)

The decision table of the measures (:mod:`heritage_bayes.projection.decision`) ranks
them by ``interventions_rank_by`` (an indicator with a direction; default: mould, else
TWPI) and, with ``tariffs``, gives their annual cost and CO₂::

    interventions_rank_by: vtt_mould_index_max
    tariffs:
      electricity_eur_per_kwh: 0.30      # [EUR/kWh]
      heat_eur_per_kwh: 0.12             # [EUR/kWh] of heat delivered to the air
      electricity_co2_kg_per_kwh: 0.35   # [kg/kWh] optional: both or neither
      heat_co2_kg_per_kwh: 0.20          # [kg/kWh]

Probability statements (``thresholds``), on any indicator the projection computes
(:mod:`heritage_bayes.climate.risk.registry`; an unknown name is refused with the list)::

    thresholds:
      - {indicator: twpi, below: 45}                       # [years]
      - {indicator: en15757_outside_baseline, above: 14}   # [% of hours]
      - {indicator: time_of_wetness, above: 2500}          # [h/year], ISO 9223 τ4
"""

from __future__ import annotations

from pathlib import Path
from typing import Any, Literal

from pydantic import Field, ValidationError, field_validator, model_validator

from heritage_bayes.climate.morph import KNMI14_SCENARIOS
from heritage_bayes.climate.risk.indicators import FAMILIES
from heritage_bayes.config import (
    MAX_SEED,
    GroundTemperature,
    Source,
    _format_error,
    _Strict,
    key,
    read_yaml,
)
from heritage_bayes.errors import ConfigError, check_known_keys

__all__ = ["ProjectionConfig", "load_projection_config", "parse_projection_config"]

#: Bounds of an air temperature set by a measure [°C]: a heated or conserved room's air
#: (frost protection to comfort heating), not the outdoor or a heater's surface.
SETPOINT = {"ge": -20.0, "le": 40.0}
#: Bounds of a heating power [W]: up to 10 MW (a cathedral's plant is below 1 MW).
POWER = {"gt": 0.0, "le": 1e7}
#: Bounds of a (de)humidifier's capacity [kg/h]: up to 1000 kg/h (a portable unit
#: removes about 1 kg/h, an industrial desiccant one tens).
CAPACITY = {"ge": 0.0, "le": 1000.0}
#: Bounds of the electric energy per kg of water moved [kWh/kg] (latent heat 0.63,
#: a steam humidifier about 0.75).
ENERGY_PER_KG = {"ge": 0.0, "le": 10.0}

Humidity = Literal["constant_rh", "constant_vapour_pressure", "table"]


class Knmi14(_Strict):
    """KNMI'14 transformation (:func:`heritage_bayes.climate.morph.knmi14_transform`)."""

    tables: str = Field(description="folder of the KNMI'14 delta tables")
    scenarios: list[Literal["GL", "GH", "WL", "WH"]] = Field(default=list(KNMI14_SCENARIOS))
    horizons: list[Literal[2030, 2050, 2085]] = Field(default=[2050, 2085])
    region: Literal["NWN", "ZWN", "NON", "MON", "ZON", "NZK"] | None = None

    @field_validator("scenarios", "horizons")
    @classmethod
    def _not_empty(cls, v):
        if not v:
            raise ValueError("give at least one")
        if len(set(v)) != len(v):
            raise ValueError(f"repeated entries (got {v})")
        return v


class Morphing(_Strict):
    """One morphed future (:func:`heritage_bayes.climate.morph.morph`)."""

    scenario: str
    horizon: int
    method: Literal["shift", "stretch", "shift_stretch"] = "shift_stretch"
    deltas: dict[str, list[float]] | str


class FutureFile(_Strict):
    """A user-supplied future weather file (read like the calibration weather)."""

    scenario: str
    horizon: int
    weather: Source


class RiskOptions(_Strict):
    """Options of :func:`heritage_bayes.climate.risk.assess_batch` (see there)."""

    indicators: list[str] | None = Field(
        default=None,
        description="indicator groups (families of heritage_bayes.climate.risk.indicators, "
        "registered ones included); default all",
    )
    chunk_draws: int = Field(default=50, ge=1, description="draws simulated together")

    @field_validator("indicators")
    @classmethod
    def _known(cls, v):
        known = [f.name for f in FAMILIES]  # read at validation: registered families too
        bad = [g for g in v or () if g not in known]
        if bad or v == []:
            raise ValueError(f"unknown indicator group(s) {bad}; expected some of {known}")
        return v


class Threshold(_Strict):
    """A probability statement: P(indicator above / below a value)."""

    indicator: str
    above: float | None = None
    below: float | None = None

    @model_validator(mode="after")
    def _one(self):
        if (self.above is None) == (self.below is None):
            raise ValueError("give exactly one of 'above' and 'below'")
        return self


class ConservationHeating(_Strict):
    """Heating so that the indoor RH stays at or below ``rh_max`` (Staniforth 2006),
    within ``[t_min, t_max]`` and up to ``power_max``."""

    rh_max: float = key(
        unit="%", gt=0, le=100, description="RH the heating keeps the air at or below"
    )
    t_min: float | None = key(
        None,
        unit="°C",
        description="heating floor: the air is never colder (default none)",
        **SETPOINT,
    )
    t_max: float = key(
        unit="°C",
        **SETPOINT,
        description="the heating never raises the air above this temperature; the RH "
        "limit then yields (comfort, collection, energy)",
    )
    power_max: float | None = key(
        None, unit="W", description="heating power available (default unlimited)", **POWER
    )

    @model_validator(mode="after")
    def _limits(self):
        if self.t_min is not None and self.t_min >= self.t_max:
            raise ValueError(f"t_min ({self.t_min}) must be below t_max ({self.t_max})")
        return self


class Heating(_Strict):
    """A thermostat: the air heated to ``t_set`` and, in the hours of use of a weekly
    calendar, to ``t_use`` (intermittent heating of a church), up to ``power_max``."""

    t_set: float = key(unit="°C", description="set-point outside the hours of use", **SETPOINT)
    t_use: float | None = key(
        None, unit="°C", description="set-point in the hours of use (needs weekly)", **SETPOINT
    )
    weekly: list[str] | None = key(
        None,
        unit=None,
        description="hours of use, e.g. ['Sun 08-12', 'Sat 18-20'] (heritage_bayes.rc.calendar)",
    )
    timezone: str = key("UTC", unit=None, description="time zone of the weekly hours")
    power_max: float | None = key(
        None, unit="W", description="heating power available (default unlimited)", **POWER
    )

    @model_validator(mode="after")
    def _use(self):
        if (self.t_use is None) != (self.weekly is None):
            raise ValueError("give t_use and weekly together (or neither)")
        if self.weekly is not None:
            from heritage_bayes.rc.calendar import parse_weekly

            parse_weekly({"weekly": self.weekly, "timezone": self.timezone}, "heating")
        return self


class Dehumidification(_Strict):
    """A humidistat-controlled dehumidifier: RH at or below ``rh_max``, at most
    ``capacity`` of water removed."""

    rh_max: float = key(unit="%", gt=0, le=100, description="RH kept at or below")
    capacity: float = key(
        unit="kg/h", description="water the dehumidifier can remove per hour", **CAPACITY
    )
    energy_per_kg: float | None = key(
        None,
        unit="kWh/kg",
        **ENERGY_PER_KG,
        description="electric energy per kg of water removed (the unit's data sheet); "
        "without it, the running cost is the water removed only",
    )


class HumidistatBand(_Strict):
    """A humidistat band: a dehumidifier above ``rh_max`` and a humidifier below
    ``rh_min``, on/off with a switching differential (hysteresis): the dehumidifier
    switches on when the RH exceeds ``rh_max`` and runs at its capacity until the RH is
    down to ``rh_max - differential``; the humidifier switches on below ``rh_min`` and
    runs until ``rh_min + differential``. Heating is no remedy for dry air (it lowers
    the RH): combine with ``heating`` or ``conservation_heating`` for the temperature."""

    rh_min: float = key(unit="%", ge=0, lt=100, description="the humidifier keeps the RH above")
    rh_max: float = key(unit="%", gt=0, le=100, description="the dehumidifier keeps the RH below")
    dehumidifier_capacity: float = key(
        unit="kg/h",
        description="water the dehumidifier can remove per hour (0: none)",
        **CAPACITY,
    )
    humidifier_capacity: float = key(
        unit="kg/h", description="water the humidifier can add per hour (0: none)", **CAPACITY
    )
    differential: float = key(
        5.0,
        unit="%",
        ge=0,
        le=100,
        description="switching differential of the humidistat (typical units 3-5 % RH; "
        "0: the RH held at the limit, a modulating unit)",
    )
    dehumidifier_energy_per_kg: float | None = key(
        None, unit="kWh/kg", description="electric energy per kg of water removed", **ENERGY_PER_KG
    )
    humidifier_energy_per_kg: float | None = key(
        None,
        unit="kWh/kg",
        **ENERGY_PER_KG,
        description="electric energy per kg of water added (steam: about 0.75; the data sheet)",
    )

    @model_validator(mode="after")
    def _band(self):
        if self.rh_min >= self.rh_max:
            raise ValueError(f"rh_min ({self.rh_min}) must be below rh_max ({self.rh_max})")
        if 2 * self.differential >= self.rh_max - self.rh_min:
            raise ValueError(
                f"differential ({self.differential} % RH) must be less than half the band "
                f"rh_max - rh_min ({self.rh_max - self.rh_min:g} % RH): the humidifier and "
                "the dehumidifier would chase each other"
            )
        return self


class Ventilation(_Strict):
    """The air exchange scaled: ``Gfast`` of the hygric model (ventilation) and of the
    thermal model (ventilation and glazing: the thermal model lumps them)."""

    factor: float = key(
        unit="-", ge=0, le=100, description="factor on the calibrated air exchange (0.5: half)"
    )


class Intervention(_Strict):
    """A named measure: a change to the calibrated room (``ventilation`` combines with
    any other, ``heating`` with ``dehumidification``)."""

    name: str = key(unit=None, min_length=1, description="name on the page and in outputs")
    conservation_heating: ConservationHeating | None = key(
        None, unit=None, description="heat to keep the RH down"
    )
    heating: Heating | None = key(
        None, unit=None, description="a thermostat with an optional weekly schedule"
    )
    dehumidification: Dehumidification | None = key(
        None, unit=None, description="a dehumidifier with a humidistat"
    )
    humidistat_band: HumidistatBand | None = key(
        None, unit=None, description="a dehumidifier and a humidifier with a band humidistat"
    )
    ventilation: Ventilation | None = key(None, unit=None, description="scale the air exchange")

    @model_validator(mode="after")
    def _one(self):
        if all(
            x is None
            for x in (self.conservation_heating, self.heating, self.dehumidification,
                      self.humidistat_band, self.ventilation)
        ):  # fmt: skip
            raise ValueError(
                "give a change: conservation_heating, heating, dehumidification, "
                "humidistat_band or ventilation"
            )
        if self.conservation_heating is not None and self.heating is not None:
            raise ValueError(
                "conservation_heating and heating are both thermostats; give one (the "
                "conservation heating's t_min is a heating floor)"
            )
        if self.dehumidification is not None and self.humidistat_band is not None:
            raise ValueError(
                "dehumidification and humidistat_band are both humidistats; give one (the "
                "band has a dehumidifier_capacity)"
            )
        if self.name == DO_NOTHING:
            raise ValueError(
                f"{DO_NOTHING!r} names doing nothing in the outputs; rename the measure"
            )
        return self


#: The name of doing nothing in the outputs (``projection.csv``'s ``measure`` column).
DO_NOTHING = "do nothing"


#: Default probability statements (IPI-style risk limits of heritage_bayes.climate.risk;
#: EN 15757: more hours outside the baseline band than the baseline climate itself can
#: spend outside it, 14 % = below the 7th plus above the 93rd percentile).
DEFAULT_THRESHOLDS = (
    Threshold(indicator="vtt_mould_index_max", above=1.0),
    Threshold(indicator="twpi", below=45.0),
    Threshold(indicator="emc_max", above=12.5),
    Threshold(indicator="emc_min", below=5.0),
    Threshold(indicator="en15757_outside_baseline", above=14.0),
)


class Tariffs(_Strict):
    """Prices and emission factors of the running energy of the measures (the decision
    table of :mod:`heritage_bayes.projection.decision`)."""

    electricity_eur_per_kwh: float = key(
        ..., unit="EUR/kWh", description="price of electricity (dehumidifier, humidifier)",
        ge=0.0, le=10.0,
    )  # fmt: skip
    heat_eur_per_kwh: float = key(
        ..., unit="EUR/kWh", description="price of a kWh of heat delivered to the room's air "
        "(fuel or electricity over the heater's efficiency)", ge=0.0, le=10.0,
    )  # fmt: skip
    electricity_co2_kg_per_kwh: float | None = key(
        None, unit="kg/kWh", description="CO2 emitted per kWh of electricity", ge=0.0, le=2.0
    )
    heat_co2_kg_per_kwh: float | None = key(
        None, unit="kg/kWh", description="CO2 emitted per kWh of heat delivered", ge=0.0, le=2.0
    )

    @model_validator(mode="after")
    def _both_co2(self):
        if (self.electricity_co2_kg_per_kwh is None) != (self.heat_co2_kg_per_kwh is None):
            raise ValueError(
                "give both electricity_co2_kg_per_kwh and heat_co2_kg_per_kwh, or neither"
            )
        return self

    def has_co2(self) -> bool:
        """True when the CO2 factors are given."""
        return self.electricity_co2_kg_per_kwh is not None


class ProjectionConfig(_Strict):
    """A validated projection file (see the module docstring)."""

    name: str | None = None
    baseline: Source | None = None
    baseline_label: str = "baseline"
    allow_other_site: bool = Field(
        default=False,
        description="accept baseline or future weather from a site more than 50 km from "
        "the calibration's (heritage_bayes.projection.weather.MAX_SITE_DISTANCE_KM)",
    )
    humidity: Humidity = "constant_rh"
    ground_temperature: GroundTemperature | None = None
    knmi14: Knmi14 | None = None
    morphing: list[Morphing] = Field(default_factory=list)
    files: list[FutureFile] = Field(default_factory=list)
    draws: int = Field(default=200, ge=1)
    seed: int = key(
        0, unit=None, description="seed of the draws chosen and of the noise", ge=0, le=MAX_SEED
    )
    noise: bool = Field(default=True, description="add a draw of each section's noise model")
    risk: RiskOptions = Field(default_factory=RiskOptions)
    thresholds: list[Threshold] = Field(default_factory=lambda: list(DEFAULT_THRESHOLDS))
    interventions: list[Intervention] = key(
        default_factory=list,
        unit=None,
        description="measures compared with doing nothing, draw by draw "
        "(heritage_bayes.projection.interventions)",
    )
    interventions_rank_by: str | None = key(
        None,
        unit=None,
        description="indicator the measures are ranked by in the decision table (default: "
        "mould, else TWPI; heritage_bayes.projection.decision)",
    )
    tariffs: Tariffs | None = key(
        None, unit=None, description="prices and CO2 factors of the measures' running energy"
    )
    base_dir: str | None = Field(default=None, description="set by the loader")

    @model_validator(mode="after")
    def _some_future(self):
        if self.knmi14 is None and not self.morphing and not self.files:
            raise ValueError(
                "give at least one future: 'knmi14' (Dutch sites), 'morphing' or 'files'"
            )
        if self.humidity == "table" and (self.knmi14 is not None or self.files):
            raise ValueError(
                "humidity: 'table' takes the RHe change from morphing tables; KNMI'14 and "
                "future files have none (use constant_rh or constant_vapour_pressure)"
            )
        names = [m.name for m in self.interventions]
        if len(set(names)) != len(names):
            raise ValueError(f"interventions: repeated names {names}")
        seen = set()
        for s, h in self.cases():
            if (s, h) in seen:
                raise ValueError(f"scenario {s!r} at horizon {h} is given twice")
            seen.add((s, h))
            if s == self.baseline_label:
                raise ValueError(f"scenario name {s!r} is the baseline's label")
        return self

    def cases(self) -> list[tuple[str, int]]:
        """(scenario, horizon) of every future, in order."""
        out: list[tuple[str, int]] = []
        if self.knmi14 is not None:
            out += [(s, int(h)) for h in self.knmi14.horizons for s in self.knmi14.scenarios]
        out += [(m.scenario, m.horizon) for m in self.morphing]
        out += [(f.scenario, f.horizon) for f in self.files]
        return out

    def path(self, p: str) -> Path:
        """A path of the file, relative to the projection file."""
        q = Path(p).expanduser()
        return q if q.is_absolute() or self.base_dir is None else Path(self.base_dir) / q


def parse_projection_config(
    raw: Any, *, source: str = "projection", base_dir: str | None = None
) -> ProjectionConfig:
    """Validate a parsed YAML mapping; raise :class:`ConfigError` naming key paths."""
    if not isinstance(raw, dict):
        raise ConfigError(
            f"{source}: expected a YAML mapping at the top level (got {type(raw).__name__})"
        )
    known = [k for k in ProjectionConfig.model_fields if k != "base_dir"]
    check_known_keys(raw, known, source=source, what="projection file")
    try:
        cfg = ProjectionConfig.model_validate(raw)
    except ValidationError as exc:
        lines = [_format_error(e, raw, ProjectionConfig) for e in exc.errors()]
        raise ConfigError(f"{source}: invalid projection file:\n  " + "\n  ".join(lines)) from None
    cfg.base_dir = base_dir
    return cfg


def load_projection_config(path) -> ProjectionConfig:
    """Read (strictly, :func:`heritage_bayes.config.read_yaml`) and validate a projection
    YAML file."""
    p = Path(path)
    raw, _ = read_yaml(p, what="projection file")
    cfg = parse_projection_config(raw, source=str(p), base_dir=str(p.parent.resolve()))
    if cfg.name is None:
        cfg.name = p.stem
    return cfg
