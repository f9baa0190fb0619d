"""Climate numerics on arrays: psychrometrics, solar on surfaces (measured, estimated from
the daily temperature range, or a cloudless sky), the ground's annual cycle, risk
indicators."""

from heritage_bayes.climate import ground, risk
from heritage_bayes.climate.psychro import (
    absolute_humidity,
    dew_point,
    relative_humidity,
    saturation_vapour_pressure,
    vapour_pressure,
)
from heritage_bayes.climate.solar import (
    DEFAULT_SURFACES,
    clear_sky_weather,
    surface_irradiance,
    temperature_range_weather,
)

__all__ = [
    "DEFAULT_SURFACES",
    "absolute_humidity",
    "clear_sky_weather",
    "dew_point",
    "ground",
    "relative_humidity",
    "risk",
    "saturation_vapour_pressure",
    "surface_irradiance",
    "temperature_range_weather",
    "vapour_pressure",
]
