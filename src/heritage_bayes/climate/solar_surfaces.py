"""Solar irradiance on building surfaces (facades, roof planes), with pvlib underneath.

Surfaces are given by tilt (0° horizontal roof, 90° vertical facade) and azimuth of the
outward normal, in degrees clockwise from north (0 = N, 90 = E, 180 = S, 270 = W), the
convention of pvlib. Interval averages are stamped at the **end** of their interval and
the sun is placed at its **middle**; instantaneous irradiance (``averaged=False``) uses
the sun at the stamp.

References
----------
.. [1] D. G. Erbs, S. A. Klein and J. A. Duffie, "Estimation of the diffuse radiation
   fraction for hourly, daily and monthly-average global radiation", Solar Energy 28
   (1982) 293-302. doi:10.1016/0038-092X(82)90302-4
.. [2] R. Perez, P. Ineichen, R. Seals, J. Michalsky and R. Stewart, "Modeling daylight
   availability and irradiance components from direct and global irradiance", Solar
   Energy 44 (1990) 271-289. doi:10.1016/0038-092X(90)90055-H
.. [3] W. F. Holmgren, C. W. Hansen and M. A. Mikofski, "pvlib python: a python package
   for modeling solar energy systems", J. Open Source Softw. 3 (2018) 884.
   doi:10.21105/joss.00884
"""

from __future__ import annotations

from collections.abc import Mapping

import numpy as np
import pandas as pd

from heritage_bayes.climate._solar_timing import _fmt, _interval, _quiet_pvlib, _site, _utc_index
from heritage_bayes.climate.solar_sky import clear_sky_weather
from heritage_bayes.errors import DataError, InputError

__all__ = ["DEFAULT_SURFACES", "roof_planes", "surface_irradiance"]

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
#: Above this zenith [°] the beam is set to zero and the sky treated as isotropic.
_MAX_ZENITH = 87.0


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
        Opt in to a clear-sky proxy
        (:func:`~heritage_bayes.climate.solar_sky.clear_sky_weather`) for weather
        **without** irradiance columns. The result is labelled in ``attrs["irradiance_source"]``.

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
