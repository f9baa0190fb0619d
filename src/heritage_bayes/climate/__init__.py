"""Climate numerics on arrays: psychrometrics, solar on surfaces, risk indicators."""

from heritage_bayes.climate import risk
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
)

__all__ = [
    "DEFAULT_SURFACES",
    "absolute_humidity",
    "clear_sky_weather",
    "dew_point",
    "relative_humidity",
    "risk",
    "saturation_vapour_pressure",
    "surface_irradiance",
    "vapour_pressure",
]
