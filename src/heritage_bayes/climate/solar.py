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

Why one module (about 690 lines): the cloudless sky, the estimate from the temperature
range and the transposition share one timing convention (stamps at the interval end, the
sun at mid-interval) and its helpers (site, interval, index checks); the estimate is a
cloudless sky scaled day by day.

References
----------
.. [1] D. G. Erbs, S. A. Klein and J. A. Duffie, "Estimation of the diffuse radiation
   fraction for hourly, daily and monthly-average global radiation", Solar Energy 28
   (1982) 293-302. doi:10.1016/0038-092X(82)90302-4
.. [2] R. Perez, P. Ineichen, R. Seals, J. Michalsky and R. Stewart, "Modeling daylight
   availability and irradiance components from direct and global irradiance", Solar
   Energy 44 (1990) 271-289. doi:10.1016/0038-092X(90)90055-H
.. [3] P. Ineichen and R. Perez, "A new airmass independent formulation for the Linke
   turbidity coefficient", Solar Energy 73 (2002) 151-157.
   doi:10.1016/S0038-092X(02)00045-2
.. [4] W. F. Holmgren, C. W. Hansen and M. A. Mikofski, "pvlib python: a python package
   for modeling solar energy systems", J. Open Source Softw. 3 (2018) 884.
   doi:10.21105/joss.00884
.. [5] R. G. Allen, L. S. Pereira, D. Raes and M. Smith, "Crop evapotranspiration:
   guidelines for computing crop water requirements", FAO Irrigation and Drainage
   Paper 56, FAO, Rome (1998), chapter 3, eqs. 21-25 and 50. ISBN 92-5-104219-5
.. [6] G. H. Hargreaves and Z. A. Samani, "Reference crop evapotranspiration from
   temperature", Applied Engineering in Agriculture 1 (1985) 96-99.
   doi:10.13031/2013.26773
"""

from __future__ import annotations

import warnings
from collections.abc import Mapping
from contextlib import contextmanager

import numpy as np
import pandas as pd

from heritage_bayes.errors import DataError, InputError

__all__ = [
    "DEFAULT_SURFACES",
    "clear_sky_weather",
    "extraterrestrial_radiation_daily",
    "hargreaves_samani",
    "roof_planes",
    "surface_irradiance",
    "temperature_range_weather",
]

#: The four vertical facades of the paper, in its order: name -> (tilt, azimuth) [°].
DEFAULT_SURFACES: dict[str, tuple[float, float]] = {
    "N": (90.0, 0.0),
    "E": (90.0, 90.0),
    "S": (90.0, 180.0),
    "W": (90.0, 270.0),
}

_COMPASS = ("N", "NE", "E", "SE", "S", "SW", "W", "NW")


def roof_planes(pitch: float, ridge_azimuth: float) -> dict[str, tuple[float, float]]:
    """The two slopes of a gable roof as solar surfaces ``{name: (tilt, azimuth)}`` [°].

    Parameters
    ----------
    pitch : float
        Tilt of each slope from the horizontal [°], in (0, 90).
    ridge_azimuth : float
        Direction in which the ridge runs [°] clockwise from north, in [0, 360]; a line,
        so 90 and 270 (an east-west ridge) are the same roof.

    Returns
    -------
    dict
        Two surfaces whose outward normals face away from the ridge on either side,
        azimuths ``ridge_azimuth ± 90`` (modulo 360), in increasing azimuth. Names are
        ``roof_<compass point>`` (``roof_N``, ``roof_SE``) when the azimuth is a
        multiple of 45°, else ``roof_<azimuth rounded to a degree>`` (``roof_120``).

    Examples
    --------
    >>> roof_planes(45, 90)
    {'roof_N': (45.0, 0.0), 'roof_S': (45.0, 180.0)}
    """
    try:
        pitch, ridge = float(pitch), float(ridge_azimuth)
    except (TypeError, ValueError) as exc:
        raise InputError(
            f"roof: pitch and ridge_azimuth must be numbers in degrees (got {pitch!r}, "
            f"{ridge_azimuth!r})"
        ) from exc
    if not 0.0 < pitch < 90.0:
        raise InputError(f"roof: pitch must be in (0, 90) ° from the horizontal (got {pitch:g})")
    if not 0.0 <= ridge <= 360.0:
        raise InputError(
            f"roof: ridge_azimuth must be in [0, 360] ° clockwise from north (got {ridge:g})"
        )
    out = {}
    for az in sorted(round((ridge + side) % 360.0, 9) for side in (90.0, 270.0)):
        point = az / 45.0
        label = _COMPASS[round(point) % 8] if point == round(point) else f"{round(az) % 360:d}"
        out[f"roof_{label}"] = (pitch, az)
    return out


_TRANSPOSITION = ("isotropic", "haydavies", "perez", "klucher", "reindl")
_DECOMPOSITION = ("erbs", "dirint")
_CLEAR_SKY = ("ineichen", "haurwitz", "simplified_solis")
_SITE_KEYS = ("latitude", "longitude", "altitude", "name")
#: Above this zenith [°] the beam is set to zero and the sky treated as isotropic.
_MAX_ZENITH = 87.0


@contextmanager
def _quiet_pvlib():
    """Silence pandas' ``dayofyear`` deprecation raised inside pvlib 0.16 (not our code)."""
    with warnings.catch_warnings():
        warnings.filterwarnings("ignore", message=r".*dayofyear is deprecated", category=Warning)
        yield


def _site(site) -> tuple[float, float, float]:
    if not isinstance(site, Mapping):
        raise InputError(
            "site must be a mapping with 'latitude' and 'longitude' [°] and optional "
            f"'altitude' [m] (got {type(site).__name__})"
        )
    unknown = [k for k in site if k not in _SITE_KEYS]
    if unknown:
        raise InputError(f"site: unknown key(s) {unknown}; allowed keys are {list(_SITE_KEYS)}")
    missing = [k for k in ("latitude", "longitude") if k not in site]
    if missing:
        raise InputError(f"site: missing key(s) {missing}")
    try:
        lat = float(site["latitude"])
        lon = float(site["longitude"])
        alt = float(site.get("altitude", 0.0))
    except (TypeError, ValueError) as exc:
        raise InputError(
            f"site: latitude, longitude and altitude must be numbers ({site})"
        ) from exc
    if not -90.0 <= lat <= 90.0:
        raise InputError(f"site: latitude must be in [-90, 90] ° (got {lat})")
    if not -180.0 <= lon <= 360.0:
        raise InputError(f"site: longitude must be in [-180, 180] ° east (got {lon})")
    if not -500.0 <= alt <= 9000.0:
        raise InputError(f"site: altitude must be in metres above sea level (got {alt})")
    return lat, lon, alt


def _max_zenith(horizon) -> float:
    """Zenith angle [°] above which the beam is cut: 87° or the skyline's."""
    if isinstance(horizon, bool) or not isinstance(horizon, int | float):
        raise InputError(f"horizon must be a number of degrees (got {horizon!r})")
    if not 0.0 <= horizon <= 45.0:
        raise InputError(f"horizon must be in [0, 45] ° of sun elevation (got {horizon:g})")
    return min(_MAX_ZENITH, 90.0 - float(horizon))


def _surfaces(surfaces) -> dict[str, tuple[float, float]]:
    if surfaces is None:
        return dict(DEFAULT_SURFACES)
    if not isinstance(surfaces, Mapping) or not surfaces:
        raise InputError("surfaces must be a non-empty mapping name -> (tilt, azimuth) [°]")
    out = {}
    for name, spec in surfaces.items():
        try:
            tilt, azimuth = (float(x) for x in spec)
        except (TypeError, ValueError) as exc:
            raise InputError(
                f"surfaces[{name!r}] must be a pair (tilt, azimuth) in degrees (got {spec!r})"
            ) from exc
        if not 0.0 <= tilt <= 180.0:
            raise InputError(f"surfaces[{name!r}]: tilt must be in [0, 180] ° (got {tilt})")
        if not 0.0 <= azimuth <= 360.0:
            raise InputError(
                f"surfaces[{name!r}]: azimuth must be in [0, 360] ° clockwise from north "
                f"(got {azimuth})"
            )
        out[str(name)] = (tilt, azimuth)
    return out


def _utc_index(index, what: str) -> pd.DatetimeIndex:
    if not isinstance(index, pd.DatetimeIndex) or index.tz is None:
        raise DataError(f"{what}: needs a tz-aware DatetimeIndex (the readers return UTC)")
    return index.tz_convert("UTC")


def _interval(index: pd.DatetimeIndex, attrs: Mapping, interval, what: str) -> pd.Timedelta:
    if interval is None:
        interval = attrs.get("interval")
    if interval is None:
        if len(index) < 2:
            raise DataError(f"{what}: cannot infer the averaging interval; pass interval=")
        diffs = np.diff(index.asi8)
        values, counts = np.unique(diffs[diffs > 0], return_counts=True)
        return pd.Timedelta(int(values[np.argmax(counts)]), unit=index.unit)
    try:
        td = pd.Timedelta(interval)
    except (TypeError, ValueError) as exc:
        raise InputError(f"interval must be a duration such as '1h' (got {interval!r})") from exc
    if td <= pd.Timedelta(0):
        raise InputError(f"interval must be positive (got {interval!r})")
    return td


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
    ``attrs["irradiance_source"]``, which :func:`surface_irradiance`,
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
    FAO-56 [5]_ eqs. 21-25: :math:`R_a = \\frac{24\\cdot 60}{\\pi} G_{sc} d_r
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
    Hargreaves and Samani [6]_ as FAO-56 eq. 50 [5]_:
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
    total (pvlib Ineichen-Perez [3]_), the estimate is
    :math:`G_h(t) = \\min(R_s/R_{cs}, 1)\\,G_{h,cs}(t)`: the day's energy with the clear
    sky's course over the day, which cannot place the clouds within a day. The diffuse
    and direct parts follow from :func:`surface_irradiance` (Erbs) as for a measured
    ``ghi``.
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


def _fmt(td: pd.Timedelta) -> str:
    seconds = int(td.total_seconds())
    if seconds % 3600 == 0:
        return f"{seconds // 3600}h"
    if seconds % 60 == 0:
        return f"{seconds // 60}min"
    return f"{seconds}s"


def _check_options(model: str, decomposition: str, albedo, clear_sky) -> float:
    """The options of :func:`surface_irradiance` checked; returns ``albedo`` [-] as a float."""
    if model not in _TRANSPOSITION:
        raise InputError(f"model must be one of {list(_TRANSPOSITION)} (got {model!r})")
    if decomposition not in _DECOMPOSITION:
        raise InputError(
            f"decomposition must be one of {list(_DECOMPOSITION)} (got {decomposition!r})"
        )
    try:
        albedo = float(albedo)
    except (TypeError, ValueError) as exc:
        raise InputError(f"albedo must be a number in [0, 1] (got {albedo!r})") from exc
    if not 0.0 <= albedo <= 1.0:
        raise InputError(f"albedo must be in [0, 1] (got {albedo})")
    if not isinstance(clear_sky, bool):
        raise InputError(f"clear_sky must be True or False (got {clear_sky!r})")
    return albedo


def _beam_and_diffuse(ghi, dni, dhi, zenith, low, times, dni_extra, decomposition, alt):
    """Beam normal and diffuse horizontal irradiance [W/m²] from what the weather holds.

    The missing one(s) of ``dni`` and ``dhi`` follow from ``ghi`` by closure, or from the
    ``decomposition`` model when both are absent; the beam is zero where ``low`` (sun
    below the limiting zenith). Returns ``(dni, dhi, note)``, the note naming the
    estimate made (None when both were given).
    """
    import pvlib

    note = None
    cosz = np.cos(np.radians(zenith))
    if dni is None and dhi is None:
        if decomposition == "erbs":
            parts = pvlib.irradiance.erbs(ghi, zenith, times.day_of_year.to_numpy())
            dni = np.asarray(parts["dni"], dtype=float)
        else:
            pressure = pvlib.atmosphere.alt2pres(alt)
            with _quiet_pvlib():
                dni = pvlib.irradiance.dirint(
                    pd.Series(ghi, index=times), zenith, times, pressure=pressure
                )
            dni = np.asarray(dni, dtype=float)
        dni = np.where(low | ~np.isfinite(dni), 0.0, dni)
        dhi = ghi - dni * cosz
        note = f"dni/dhi from ghi by {'Erbs' if decomposition == 'erbs' else 'DIRINT'}"
    elif dni is None:
        with np.errstate(divide="ignore", invalid="ignore"):
            dni = np.where(low, 0.0, (ghi - dhi) / cosz)
        dni = np.clip(np.nan_to_num(dni, nan=0.0), 0.0, dni_extra)
        note = "dni from ghi and dhi by closure"
    elif dhi is None:
        dni = np.where(low, 0.0, dni)
        dhi = ghi - dni * cosz
        note = "dhi from ghi and dni by closure"
    dni = np.where(low, 0.0, dni)
    dhi = np.clip(np.minimum(dhi, np.where(np.isnan(ghi), np.inf, ghi)), 0.0, None)
    dhi = np.where(np.isnan(ghi), np.nan, dhi)
    return dni, dhi, note


def surface_irradiance(
    weather: pd.DataFrame,
    site: Mapping,
    surfaces: Mapping | None = None,
    *,
    model: str = "perez",
    decomposition: str = "erbs",
    albedo: float = 0.2,
    averaged: bool | None = None,
    interval=None,
    clear_sky: bool = False,
    horizon: float = 0.0,
) -> pd.DataFrame:
    """Total (beam + sky diffuse + ground-reflected) irradiance on each surface [W/m²].

    Parameters
    ----------
    weather : pandas.DataFrame
        Tz-aware index; ``ghi`` [W/m²] and optionally ``dni``, ``dhi`` [W/m²]. With only
        ``ghi`` (KNMI) the split is estimated by ``decomposition``; with ``ghi`` and
        ``dhi`` (FMI) ``dni`` follows from closure; with ``ghi`` and ``dni``, ``dhi``.
    site : mapping
        ``latitude``, ``longitude`` [°, east positive], ``altitude`` [m] (default 0),
        optionally ``name``.
    surfaces : mapping, optional
        ``{name: (tilt, azimuth)}`` in degrees: tilt from horizontal (90 = vertical
        facade), azimuth of the outward normal clockwise from north (0 = N, 90 = E).
        Default :data:`DEFAULT_SURFACES`, the vertical facades ``N``, ``E``, ``S``,
        ``W``. Roofs take any tilt, e.g. ``{"roof_S": (45, 180)}``.
    model : {"perez", "isotropic", "haydavies", "klucher", "reindl"}, default "perez"
        Sky-diffuse transposition model (pvlib).
    decomposition : {"erbs", "dirint"}, default "erbs"
        GHI split used when ``dni`` and ``dhi`` are both absent.
    albedo : float, default 0.2
        Ground reflectance [-] for the ground-reflected part.
    averaged : bool, optional
        Whether the irradiance columns are interval averages stamped at the interval end
        (sun at mid-interval) or instantaneous (sun at the stamp). Default: from
        ``weather.attrs["averaged"]`` when present, else True.
    interval : str or Timedelta, optional
        Averaging interval. Default ``weather.attrs["interval"]`` or the most frequent
        spacing of the index.
    clear_sky : bool, default False
        Opt in to a clear-sky proxy (:func:`clear_sky_weather`) for weather **without**
        irradiance columns. The result is labelled in ``attrs["irradiance_source"]``.

    Returns
    -------
    pandas.DataFrame
        One column per surface [W/m²], same index (and stamping) as ``weather``; NaN where
        ``ghi`` is NaN. ``attrs``: ``units``, ``averaged`` (the surface columns when the
        input was averaged), ``interval``, ``irradiance_source``, ``surfaces``, ``model``.

    Raises
    ------
    heritage_bayes.errors.DataError
        No ``ghi`` column and ``clear_sky`` not set; index not tz-aware.

    Notes
    -----
    For each surface :math:`G_{poa} = G_b\\max(\\cos\\theta, 0) + G_{d,sky} + G_{d,gr}` with
    :math:`\\theta` the angle of incidence, :math:`G_{d,gr} = \\rho\\,G_h(1 - \\cos\\beta)/2`
    and :math:`G_{d,sky}` from the chosen model (Perez et al. [2]_ by default). Closure:
    :math:`G_h = G_d + G_b\\cos\\theta_z`. With only GHI, Erbs et al. [1]_ (or DIRINT)
    estimate the diffuse fraction from the clearness index. For zenith angles above 87°
    (or ``90 - horizon``) at mid-interval the beam is set to zero and the sky diffuse is
    isotropic; at night (``ghi`` = 0) every surface gets 0. Negative results are clipped to 0.
    """
    import pvlib

    if not isinstance(weather, pd.DataFrame):
        raise InputError(f"weather must be a DataFrame (got {type(weather).__name__})")
    what = f"surface_irradiance({weather.attrs.get('source', 'weather')})"
    idx = _utc_index(weather.index, what)
    lat, lon, alt = _site(site)
    surf = _surfaces(surfaces)
    albedo = _check_options(model, decomposition, albedo, clear_sky)
    present = [c for c in ("ghi", "dni", "dhi") if c in weather.columns]

    if clear_sky:
        if present:
            raise InputError(
                f"{what}: weather already has irradiance {present}; clear_sky=True would "
                f"ignore it. Drop those columns to use the proxy deliberately"
            )
        if averaged is False:
            raise InputError("clear_sky=True builds interval averages; averaged=False conflicts")
        comps = clear_sky_weather(
            weather.index, site, interval=interval or weather.attrs.get("interval")
        )
        attrs = comps.attrs
        averaged = True
        source = attrs["irradiance_source"]
        weather = comps
    else:
        if "ghi" not in weather.columns:
            raise DataError(
                f"{what}: no 'ghi' column (global horizontal irradiance [W/m²]); columns "
                f"are: {', '.join(map(repr, weather.columns))}. For weather without "
                f"measured irradiance pass clear_sky=True to use a clear-sky proxy"
            )
        attrs = weather.attrs
        if averaged is None:
            averaged = "ghi" in attrs["averaged"] if "averaged" in attrs else True
        elif not isinstance(averaged, bool):
            raise InputError(f"averaged must be True, False or None (got {averaged!r})")
        source = attrs.get("irradiance_source", "measured")

    if averaged:
        td = _interval(idx, attrs, interval, what)
        times = idx - td / 2
    else:
        td = _interval(idx, attrs, interval, what) if len(idx) > 1 else None
        times = idx
    sun = pvlib.solarposition.get_solarposition(times, lat, lon, altitude=alt)
    zenith = sun["zenith"].to_numpy()
    app_zenith = sun["apparent_zenith"].to_numpy()
    azimuth = sun["azimuth"].to_numpy()
    low = zenith > _max_zenith(horizon)

    ghi = weather["ghi"].to_numpy(dtype=float)
    dni = weather["dni"].to_numpy(dtype=float) if "dni" in weather else None
    dhi = weather["dhi"].to_numpy(dtype=float) if "dhi" in weather else None
    doy = times.day_of_year.to_numpy()
    dni_extra = np.asarray(pvlib.irradiance.get_extra_radiation(doy), dtype=float)
    dni, dhi, note = _beam_and_diffuse(
        ghi, dni, dhi, zenith, low, times, dni_extra, decomposition, alt
    )
    airmass = pvlib.atmosphere.get_relative_airmass(app_zenith)

    out = {}
    for name, (tilt, az) in surf.items():
        kw = {
            "surface_tilt": tilt,
            "surface_azimuth": az,
            "solar_zenith": app_zenith,
            "solar_azimuth": azimuth,
            "dni": dni,
            "ghi": ghi,
            "dhi": dhi,
            "dni_extra": dni_extra,
            "airmass": airmass,
            "albedo": albedo,
        }
        poa = np.asarray(pvlib.irradiance.get_total_irradiance(model=model, **kw)["poa_global"])
        iso = np.asarray(
            pvlib.irradiance.get_total_irradiance(model="isotropic", **kw)["poa_global"]
        )
        poa = np.where(low | ~np.isfinite(poa), iso, poa)
        poa = np.where(ghi > 0, np.clip(poa, 0.0, None), 0.0)
        out[name] = np.where(np.isnan(ghi), np.nan, poa)

    result = pd.DataFrame(out, index=weather.index)
    label = source if note is None else f"{source}; {note}"
    result.attrs = {
        "units": dict.fromkeys(surf, "W/m²"),
        "averaged": tuple(surf) if averaged else (),
        "interval": _fmt(td) if td is not None else None,
        "irradiance_source": label,
        "surfaces": {k: {"tilt": v[0], "azimuth": v[1]} for k, v in surf.items()},
        "model": f"{model} transposition, albedo {albedo:g}",
        "site": {"latitude": lat, "longitude": lon, "altitude": alt},
    }
    return result
