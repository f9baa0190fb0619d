"""Climate numerics on arrays: psychrometrics, solar on surfaces, risk indicators."""

from heritage_bayes.climate.psychro import (
    absolute_humidity,
    dew_point,
    relative_humidity,
    saturation_vapour_pressure,
    vapour_pressure,
)

__all__ = [
    "absolute_humidity",
    "dew_point",
    "relative_humidity",
    "saturation_vapour_pressure",
    "vapour_pressure",
]
