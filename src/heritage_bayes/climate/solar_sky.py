"""The cloudless sky and the global irradiance estimated from the daily temperature range.

Without a pyranometer, :func:`temperature_range_weather` estimates the global horizontal
irradiance from the daily range of the outdoor air temperature (Hargreaves-Samani): a
cloudless sky (:func:`clear_sky_weather`) scaled day by day. Stamps mark the **end** of
each averaging interval and the sun is placed at its **middle**.

References
----------
.. [1] P. Ineichen and R. Perez, "A new airmass independent formulation for the Linke
   turbidity coefficient", Solar Energy 73 (2002) 151-157.
   doi:10.1016/S0038-092X(02)00045-2
.. [2] W. F. Holmgren, C. W. Hansen and M. A. Mikofski, "pvlib python: a python package
   for modeling solar energy systems", J. Open Source Softw. 3 (2018) 884.
   doi:10.21105/joss.00884
.. [3] R. G. Allen, L. S. Pereira, D. Raes and M. Smith, "Crop evapotranspiration:
   guidelines for computing crop water requirements", FAO Irrigation and Drainage
   Paper 56, FAO, Rome (1998), chapter 3, eqs. 21-25 and 50. ISBN 92-5-104219-5
.. [4] G. H. Hargreaves and Z. A. Samani, "Reference crop evapotranspiration from
   temperature", Applied Engineering in Agriculture 1 (1985) 96-99.
   doi:10.13031/2013.26773
"""

from __future__ import annotations

from collections.abc import Mapping

import numpy as np
import pandas as pd

from heritage_bayes.climate._solar_timing import _fmt, _interval, _quiet_pvlib, _site, _utc_index
from heritage_bayes.errors import DataError, InputError

__all__ = [
    "KRS_INTERIOR",
    "clear_sky_weather",
    "extraterrestrial_radiation_daily",
    "hargreaves_samani",
    "temperature_range_weather",
]

_CLEAR_SKY = ("ineichen", "haurwitz", "simplified_solis")


def clear_sky_weather(
    index: pd.DatetimeIndex,
    site: Mapping,
    *,
    interval=None,
    model: str = "ineichen",
    substeps: int = 6,
) -> pd.DataFrame:
    """Clear-sky irradiance as a stand-in for weather without measured radiation.

    An explicit **proxy**: it knows the sun's path but not the clouds. Use it only when no
    irradiance was measured (e.g. the Danish DMI station data); the result is labelled
    ``attrs["irradiance_source"]``, which
    :func:`~heritage_bayes.climate.solar_surfaces.surface_irradiance`,
    :func:`heritage_bayes.io.align` and the reports carry along.

    Parameters
    ----------
    index : pandas.DatetimeIndex
        Tz-aware stamps of the weather, each at the **end** of its interval.
    site : mapping
        ``latitude``, ``longitude`` [°, east positive], ``altitude`` [m] (default 0).
    interval : str or Timedelta, optional
        Averaging interval ending at each stamp. Default: the most frequent spacing of
        ``index``.
    model : {"ineichen", "haurwitz", "simplified_solis"}, default "ineichen"
        pvlib clear-sky model; Ineichen-Perez uses the Linke turbidity climatology
        shipped with pvlib.
    substeps : int, default 6
        Number of evaluations averaged per interval (mid-points of equal sub-intervals).

    Returns
    -------
    pandas.DataFrame
        ``ghi``, ``dni``, ``dhi`` [W/m²], mean over the interval ending at each stamp;
        ``attrs["averaged"] = ("ghi", "dni", "dhi")``, ``attrs["interval"]``,
        ``attrs["irradiance_source"] = "clear-sky proxy (pvlib Ineichen, ...)"``.

    Notes
    -----
    The clear sky overestimates the mean irradiance of a cloudy climate; with a
    calibrated solar aperture the model absorbs the mean cloudiness in the aperture, but
    the day-to-day variation of the solar gain is missing from the inputs.
    """
    import pvlib

    idx = _utc_index(index, "clear_sky_weather").as_unit("ns")
    lat, lon, alt = _site(site)
    if model not in _CLEAR_SKY:
        raise InputError(f"model must be one of {list(_CLEAR_SKY)} (got {model!r})")
    if isinstance(substeps, bool) or not isinstance(substeps, int) or substeps < 1:
        raise InputError(f"substeps must be a positive integer (got {substeps!r})")
    td = _interval(idx, {}, interval, "clear_sky_weather")
    offsets = (np.arange(substeps) + 0.5) / substeps - 1.0  # fractions of the interval
    times = pd.DatetimeIndex(
        (idx.asi8[:, None] + np.round(offsets * td.value).astype(np.int64)).ravel(),
        tz="UTC",
    )
    location = pvlib.location.Location(lat, lon, altitude=alt)
    with _quiet_pvlib():
        cs = location.get_clearsky(times, model=model)
    values = cs[["ghi", "dni", "dhi"]].to_numpy().reshape(len(idx), substeps, 3).mean(axis=1)
    out = pd.DataFrame(values, index=index, columns=["ghi", "dni", "dhi"]).clip(lower=0.0)
    label = {
        "ineichen": "pvlib Ineichen-Perez, Linke turbidity climatology",
        "haurwitz": "pvlib Haurwitz",
        "simplified_solis": "pvlib simplified Solis",
    }[model]
    out.attrs = {
        "units": {"ghi": "W/m²", "dni": "W/m²", "dhi": "W/m²"},
        "averaged": ("ghi", "dni", "dhi"),
        "interval": _fmt(td),
        "irradiance_source": f"clear-sky proxy ({label}); no measured irradiance",
        "site": {"latitude": lat, "longitude": lon, "altitude": alt},
    }
    return out


#: Solar constant of FAO-56 eq. 21 [MJ m⁻² min⁻¹].
_GSC = 0.0820
#: Hargreaves' adjustment coefficient kRs [°C^-1/2] for interior sites (FAO-56 eq. 50);
#: 0.19 for coastal sites.
KRS_INTERIOR = 0.16
#: A solar day's temperature range counts with at least this share of its readings.
_MIN_DAY_SHARE = 0.75


def extraterrestrial_radiation_daily(day_of_year, latitude) -> np.ndarray:
    """Daily extraterrestrial radiation on a horizontal surface Ra [MJ m⁻² d⁻¹].

    Parameters
    ----------
    day_of_year : array_like
        Day of the year J, 1..366.
    latitude : float or array_like
        Latitude [°, north positive].

    Returns
    -------
    numpy.ndarray
        Ra [MJ m⁻² d⁻¹] (× 11.574 for the daily mean in W/m²).

    Notes
    -----
    FAO-56 [3]_ eqs. 21-25: :math:`R_a = \\frac{24\\cdot 60}{\\pi} G_{sc} d_r
    [\\omega_s \\sin\\varphi \\sin\\delta + \\cos\\varphi \\cos\\delta \\sin\\omega_s]`
    with :math:`G_{sc}` = 0.0820 MJ m⁻² min⁻¹, :math:`d_r = 1 + 0.033\\cos(2\\pi J/365)`,
    :math:`\\delta = 0.409\\sin(2\\pi J/365 - 1.39)` and the sunset hour angle
    :math:`\\omega_s = \\arccos(-\\tan\\varphi\\tan\\delta)`, clipped to [0, π] for polar
    night and midnight sun. FAO-56's example 8 (20° S, 3 September, J = 246) gives
    Ra = 32.2 MJ m⁻² d⁻¹.
    """
    j = np.asarray(day_of_year, dtype=float)
    lat = np.asarray(latitude, dtype=float)
    if np.any((j < 1) | (j > 366)):
        raise InputError("day_of_year must be within 1..366")
    if np.any(np.abs(lat) > 90):
        raise InputError("latitude must be within [-90, 90] °")
    phi = np.radians(lat)
    dr = 1.0 + 0.033 * np.cos(2 * np.pi * j / 365)
    delta = 0.409 * np.sin(2 * np.pi * j / 365 - 1.39)
    ws = np.arccos(np.clip(-np.tan(phi) * np.tan(delta), -1.0, 1.0))
    geo = ws * np.sin(phi) * np.sin(delta) + np.cos(phi) * np.cos(delta) * np.sin(ws)
    return 24 * 60 / np.pi * _GSC * dr * geo


def hargreaves_samani(tmax, tmin, ra, krs: float = KRS_INTERIOR) -> np.ndarray:
    """Daily global radiation from the daily temperature range Rs [MJ m⁻² d⁻¹].

    Parameters
    ----------
    tmax, tmin : array_like
        Daily maximum and minimum air temperature [°C].
    ra : array_like
        Extraterrestrial radiation [MJ m⁻² d⁻¹], :func:`extraterrestrial_radiation_daily`.
    krs : float, default 0.16
        Adjustment coefficient [°C^-1/2]: 0.16 for interior sites, 0.19 for coastal ones
        (air masses under a large water body's influence).

    Returns
    -------
    numpy.ndarray
        Rs [MJ m⁻² d⁻¹]; NaN where an input is NaN.

    Notes
    -----
    Hargreaves and Samani [4]_ as FAO-56 eq. 50 [3]_:
    :math:`R_s = k_{Rs}\\sqrt{T_{max} - T_{min}}\\,R_a`. Clouds narrow the daily range
    (less sun by day, less loss to the sky by night); the relation is a daily one, whose
    errors average out over a week or more.
    """
    krs = float(krs)
    if not 0.0 < krs < 1.0:
        raise InputError(f"krs must be in (0, 1) °C^-1/2 (got {krs})")
    dt = np.asarray(tmax, dtype=float) - np.asarray(tmin, dtype=float)
    if np.any(dt < 0):
        raise InputError("tmax must not be below tmin")
    return krs * np.sqrt(dt) * np.asarray(ra, dtype=float)


def temperature_range_weather(
    te: pd.Series, site: Mapping, *, krs: float = KRS_INTERIOR, interval=None
) -> pd.DataFrame:
    """Global horizontal irradiance estimated from the outdoor air temperature alone.

    For weather without measured irradiance (the usual case at heritage sites): each
    solar day's global radiation from its temperature range (:func:`hargreaves_samani`),
    spread over the day in proportion to the cloudless-sky irradiance
    (:func:`clear_sky_weather`), and never above it in any interval.

    Parameters
    ----------
    te : pandas.Series
        Outdoor air temperature [°C], tz-aware index (NaN allowed), stamps at the end of
        their interval.
    site : mapping
        ``latitude``, ``longitude`` [°, east positive], ``altitude`` [m] (default 0).
    krs : float, default 0.16
        Hargreaves' coefficient [°C^-1/2] (FAO-56: 0.16 interior, 0.19 coastal).
    interval : str or Timedelta, optional
        Interval ending at each stamp. Default: ``te.attrs["interval"]`` or the most
        frequent spacing of the index.

    Returns
    -------
    pandas.DataFrame
        ``ghi`` [W/m²], the mean over the interval ending at each stamp, on ``te``'s
        index; ``attrs``: ``units``, ``averaged``, ``interval``, ``irradiance_source``,
        ``site``, ``days_filled`` (days whose ratio was interpolated).

    Raises
    ------
    heritage_bayes.errors.DataError
        No solar day with enough temperature readings.

    Notes
    -----
    A solar day is the 24 h centred on local solar noon (UTC shifted by longitude/15 h).
    Its range :math:`T_{max} - T_{min}` counts when at least 3/4 of its readings are
    present; other days take the ratio :math:`R_s/R_{cs}` linearly interpolated from
    the neighbouring days (held at the ends). With :math:`R_{cs}` the day's cloudless-sky
    total (pvlib Ineichen-Perez [1]_), the estimate is
    :math:`G_h(t) = \\min(R_s/R_{cs}, 1)\\,G_{h,cs}(t)`: the day's energy with the clear
    sky's course over the day, which cannot place the clouds within a day. The diffuse
    and direct parts follow from
    :func:`~heritage_bayes.climate.solar_surfaces.surface_irradiance` (Erbs) as for a
    measured ``ghi``.
    """
    if not isinstance(te, pd.Series):
        raise InputError(f"te must be a pandas Series (got {type(te).__name__})")
    idx = _utc_index(te.index, "temperature_range_weather").as_unit("ns")
    lat, lon, _ = _site(site)
    td = _interval(idx, te.attrs, interval, "temperature_range_weather")
    shift = pd.Timedelta(hours=lon / 15.0)
    day_of = (idx - td / 2 + shift).floor("D")
    values = te.to_numpy(dtype=float)
    ok = np.isfinite(values)
    days = pd.date_range(day_of.min(), day_of.max(), freq="D")
    daily = pd.Series(values[ok], index=day_of[ok]).groupby(level=0).agg(["max", "min", "count"])
    daily = daily.reindex(days)
    enough = daily["count"].to_numpy(dtype=float) >= _MIN_DAY_SHARE * (pd.Timedelta("1D") / td)
    if not enough.any():
        raise DataError(
            f"temperature_range_weather({te.attrs.get('source', 'Te')}): no solar day with "
            f"at least {_MIN_DAY_SHARE:.0%} of its temperature readings; the daily range "
            f"cannot be formed"
        )
    ra = extraterrestrial_radiation_daily(days.day_of_year, lat)
    rs = hargreaves_samani(daily["max"], daily["min"], ra, krs)
    # each solar day's cloudless-sky total [MJ/m²], from hourly means over the whole day
    hours = pd.date_range(days[0] - shift + pd.Timedelta("1h"), periods=24 * len(days), freq="1h")
    cs_hours = clear_sky_weather(hours, site, interval="1h")["ghi"].to_numpy()
    rcs = cs_hours.reshape(len(days), 24).sum(axis=1) * 3600.0 / 1e6
    with np.errstate(divide="ignore", invalid="ignore"):
        ratio = np.where(rcs > 0, rs / rcs, 0.0)
    n = np.arange(len(days), dtype=float)
    ratio = np.interp(n, n[enough], ratio[enough])
    factor = np.minimum(ratio, 1.0)[days.get_indexer(day_of)]
    cs = clear_sky_weather(te.index, site, interval=td)["ghi"].to_numpy()
    out = pd.DataFrame({"ghi": factor * cs}, index=te.index)
    out.attrs = {
        "units": {"ghi": "W/m²"},
        "averaged": ("ghi",),
        "interval": _fmt(td),
        "irradiance_source": (
            f"estimated from the daily range of Te (Hargreaves-Samani, kRs {krs:g}), "
            f"shaped over the day by the sun's path (pvlib Ineichen-Perez)"
        ),
        "site": dict(site),
        "days_filled": int((~enough).sum()),
    }
    return out
