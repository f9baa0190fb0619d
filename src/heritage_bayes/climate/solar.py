"""Solar irradiance on building surfaces (facades, roofs), with pvlib underneath.

Irradiance columns follow the package's timestamp convention: an interval average is
stamped at the **end** of its averaging interval (KNMI, EPW, TMY3), and the sun is placed
at the **middle** of that interval. Instantaneous irradiance (``averaged=False``) uses the
sun at the stamp.

Surfaces are given by tilt (0° horizontal roof, 90° vertical facade) and azimuth of the
outward normal, in degrees clockwise from north (0 = N, 90 = E, 180 = S, 270 = W), the
convention of pvlib.

Without a pyranometer, :func:`temperature_range_weather` estimates the global horizontal
irradiance from the daily range of the outdoor air temperature (Hargreaves-Samani), and
:func:`clear_sky_weather` gives the cloudless sky on request.

The functions live in two modules sharing one timing convention: the cloudless sky and
the estimate from the temperature range in :mod:`heritage_bayes.climate.solar_sky`, the
transposition onto facades and roof planes in
:mod:`heritage_bayes.climate.solar_surfaces`; this module gathers their public names.
"""

from heritage_bayes.climate.solar_sky import (
    KRS_INTERIOR,
    clear_sky_weather,
    extraterrestrial_radiation_daily,
    hargreaves_samani,
    temperature_range_weather,
)
from heritage_bayes.climate.solar_surfaces import DEFAULT_SURFACES, roof_planes, surface_irradiance

__all__ = [
    "DEFAULT_SURFACES",
    "KRS_INTERIOR",
    "clear_sky_weather",
    "extraterrestrial_radiation_daily",
    "hargreaves_samani",
    "roof_planes",
    "surface_irradiance",
    "temperature_range_weather",
]
