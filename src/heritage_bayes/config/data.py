"""Settings of the ``data`` section: the tables (:mod:`heritage_bayes.config.sources`),
the solar input and its surfaces, the ground temperature, the time grid and the gaps.

How these become model inputs and outputs: :mod:`heritage_bayes.prepare`.
"""

from __future__ import annotations

import re
from typing import Annotated, Literal

from pydantic import BeforeValidator, field_validator, model_validator

from heritage_bayes.config._base import (
    DURATION_UNIT,
    Duration,
    NonNegativeDuration,
    _Strict,
    key,
)
from heritage_bayes.config.sources import DemoData, Source

__all__ = ["DEFAULT_SURFACES", "Data", "GroundTemperature", "Roof"]


class GroundTemperature(_Strict):
    """The fixed (ground) temperature input ``Tf`` of the thermal models.

    ``seasonal``: the annual cycle of the outdoor temperature, damped and delayed at
    ``depth`` in the soil, see :func:`heritage_bayes.inputs.seasonal_ground_temperature`;
    without ``depth``, the thermal models estimate it (parameter ``zf`` [m], the inputs
    of :func:`heritage_bayes.inputs.ground_cycle_inputs`) and the ground's annual mean
    minus the outdoor air's (parameter ``dTf`` [K]);
    ``annual_mean``: the outdoor temperature averaged over a year, see
    :func:`heritage_bayes.inputs.annual_mean_temperature`; ``constant``: ``value``
    [°C]; ``column``: a measured series, the column ``column`` (name in the file) of the
    CSV table ``source`` or, without ``source``, of the weather or measurement CSV files.
    """

    mode: Literal["seasonal", "annual_mean", "constant", "column"] = key(
        "seasonal",
        unit=None,
        description="seasonal (the outdoor annual cycle at depth in the soil), annual_mean "
        "(running annual mean of the outdoor temperature), constant (value) or column (a "
        "measured series). Default: seasonal for files, annual_mean for the demo (its "
        "generator's)",
    )
    depth: float | None = key(
        None,
        unit="m",
        description="mode seasonal: depth of the ground temperature in clay/silt soil "
        "(1 m: the annual swing × 0.64, 26 days late). Default: estimated by the thermal "
        "model (parameter zf, prior median 2 m within 0.5-6 m; and dTf, the ground's mean "
        "minus the outdoor air's, prior 0 ± 1 K)",
        ge=0,
        le=20,
    )
    value: float | None = key(
        None, unit="°C", description="the ground temperature of mode constant", ge=-60, le=70
    )
    column: str | None = key(None, unit=None, description="mode column: the column's name")
    source: Source | None = key(
        None,
        unit=None,
        description="mode column: the CSV table holding it (default: weather or measurements)",
    )

    @model_validator(mode="after")
    def _check(self):
        if self.mode == "constant" and self.value is None:
            raise ValueError("value: required for mode 'constant' (a temperature in °C)")
        if self.mode == "column" and not self.column:
            raise ValueError("column: required for mode 'column' (a column name in a CSV file)")
        if self.mode != "seasonal" and self.depth is not None:
            raise ValueError(f"depth: only for mode 'seasonal' (mode is {self.mode!r})")
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


#: Default skyline of a roof's slopes [° of sun elevation]: below it the low sun's beam
#: is shaded (neighbouring houses and trees around a house).
ROOF_HORIZON = 20.0


class Roof(_Strict):
    """A gable roof over the room (an attic, a loft): its two slopes become solar surfaces.

    The slopes face away from the ridge on either side, azimuths ``ridge_azimuth ± 90``,
    each tilted by ``pitch`` (:func:`heritage_bayes.climate.solar.roof_planes`); their
    irradiance is transposed from the same global (measured or estimated) irradiance and
    sky model as any surface, their beam shaded while the sun is below ``horizon``
    (:func:`heritage_bayes.climate.solar.surface_irradiance`). ``area`` sets the prior
    of their apertures (:func:`heritage_bayes.inference.survey.roof_aperture_prior`).
    """

    pitch: float = key(
        unit="°",
        description="tilt of each slope from the horizontal, e.g. 45 (steep old roofs "
        "45-60, Nordic tile roofs about 30)",
        gt=0,
        lt=90,
    )
    ridge_azimuth: float = key(
        unit="°",
        description="direction the ridge runs, clockwise from north: 90 (or 270) an "
        "east-west ridge, slopes facing north and south; 0 (or 180) a north-south ridge, "
        "slopes facing east and west",
        ge=0,
        le=360,
    )
    area: float | None = key(
        None,
        unit="m²",
        description="area of the two slopes together, measured along the slope (about "
        "the floor area / cos(pitch)): a log-normal prior on each slope's aperture, median "
        "0.07 × its half; without it the wide default prior",
        gt=0,
    )
    horizon: float = key(
        ROOF_HORIZON,
        unit="°",
        description="sun elevation below which the slopes are shaded (neighbouring "
        "houses, trees; the low sun's beam on a steep slope): 0 for a roof open to the "
        "horizon",
        ge=0,
        le=45,
    )

    def planes(self) -> dict[str, tuple[float, float]]:
        """The two slopes, ``{name: (tilt, azimuth)}`` [°]."""
        from heritage_bayes.climate.solar import roof_planes

        return roof_planes(self.pitch, self.ridge_azimuth)

    def input_keywords(self) -> dict:
        """``roof`` (the planes' names) and ``roof_horizon`` [°] of
        :func:`heritage_bayes.inputs.weather_inputs`."""
        return {"roof": tuple(self.planes()), "roof_horizon": self.horizon}

    def plane_areas(self) -> dict[str, float]:
        """Each slope's area [m²] (half of ``area``); empty without ``area``."""
        if self.area is None:
            return {}
        return dict.fromkeys(self.planes(), self.area / 2.0)


#: The four vertical facades (the paper's N, E, S, W): name -> (tilt, azimuth) [°].
DEFAULT_SURFACES = {
    "N": (90.0, 0.0),
    "E": (90.0, 90.0),
    "S": (90.0, 180.0),
    "W": (90.0, 270.0),
}


def _as_list(v):
    return [v] if isinstance(v, dict) else v


_SURFACE_NAME = re.compile(r"^[A-Za-z][A-Za-z0-9_]*$")


class Data(_Strict):
    """Where the data come from, and the common time grid."""

    demo: DemoData | None = key(
        None, unit=None, description="the built-in virtual monument instead of files"
    )
    weather: Source | None = key(None, unit=None, description="the outdoor weather table")
    measurements: Annotated[list[Source] | None, BeforeValidator(_as_list)] = key(
        None,
        unit=None,
        description="the indoor logger table, or a list of tables (e.g. separate T and RH loggers)",
    )
    irradiance: Literal["measured", "estimated", "clear_sky", "none"] | None = key(
        None,
        unit=None,
        description="solar input: measured (from the weather), estimated (from the daily "
        "range of the outdoor temperature, Hargreaves-Samani), clear_sky (a cloudless sky, "
        "on request) or none (no solar input). Default: measured when the weather has "
        "global irradiance, else estimated",
    )
    surfaces: dict[str, tuple[float, float]] = key(
        unit="°",
        description="name -> (tilt, azimuth; 0 = N, 90 = E) of the sunlit surfaces",
        default_factory=lambda: dict(DEFAULT_SURFACES),
    )
    roof: Roof | None = key(
        None,
        unit=None,
        description="a gable roof over the room (attic, loft), e.g. {pitch: 45, "
        "ridge_azimuth: 90}: its two slopes become solar surfaces roof_<direction>, in "
        "place of the four facades when 'surfaces' is not given, else beside them",
    )
    ground_temperature: GroundTemperature = key(
        unit=None,
        description="the fixed (ground) temperature input of the thermal models",
        default_factory=GroundTemperature,
    )
    step: Duration = key(
        "1h",
        unit=DURATION_UNIT,
        description="the model's time step: every table is put on this grid",
        validate_default=True,
    )
    max_gap: NonNegativeDuration = key(
        "6h",
        unit=DURATION_UNIT,
        description="longest input gap filled by interpolation; a longer one splits the "
        "record into segments, each simulated from its own initial state",
        validate_default=True,
    )
    input_hold: Literal["exact", "interval_mean"] | None = key(
        None,
        unit=None,
        description="exact: readings at an instant linear between samples (first-order "
        "hold), interval means (a source's 'averaged' columns) constant over their interval; "
        "interval_mean: every input held at its mean over the step. Default: exact for "
        "files, interval_mean for the demo (its generator's hold)",
    )

    @model_validator(mode="after")
    def _one_source(self):
        if self.demo is None and (self.weather is None or self.measurements is None):
            raise ValueError("give either 'demo' or both 'weather' and 'measurements'")
        if self.demo is not None and (self.weather or self.measurements):
            raise ValueError(
                "'demo' generates its own data: remove 'weather' and "
                "'measurements' or remove 'demo'"
            )
        if self.demo is not None and "mode" not in self.ground_temperature.model_fields_set:
            self.ground_temperature.mode = "annual_mean"  # the demo generator's Tf
        if self.roof is not None:
            self._add_roof()
        if self.irradiance == "none" and self.surfaces != DEFAULT_SURFACES:
            raise ValueError(
                "surfaces: given, but irradiance is 'none' (no solar input); remove "
                "'surfaces' or 'irradiance: none'"
            )
        return self

    def _add_roof(self) -> None:
        if self.irradiance == "none":
            raise ValueError(
                "roof: given, but irradiance is 'none' (no solar input); remove 'roof' or "
                "'irradiance: none'"
            )
        planes = self.roof.planes()
        if "surfaces" not in self.model_fields_set:  # the roof replaces the four facades
            self.surfaces = planes
            return
        merged = dict(self.surfaces)
        for name, (tilt, az) in planes.items():
            if name in merged and tuple(merged[name]) != (tilt, az):
                raise ValueError(
                    f"surfaces.{name}: {list(merged[name])}, but the roof's plane of that name "
                    f"is [{tilt:g}, {az:g}] (roof: pitch {self.roof.pitch:g}°, ridge_azimuth "
                    f"{self.roof.ridge_azimuth:g}°); rename the surface or remove it"
                )
            merged[name] = (tilt, az)
        self.surfaces = merged

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
