"""Model inputs from weather: facade irradiance, vapour pressure, ground temperature.

Building blocks shared by data preparation (:func:`heritage_bayes.prepare.prepare`) and
the built-in demo (:mod:`heritage_bayes.demo`), so that the demo's inputs are built
exactly as those of real data. Pure functions on tables; no config, no files.
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence

import numpy as np
import pandas as pd

from heritage_bayes.errors import ConfigError, DataError, InputError

__all__ = [
    "add_slope_columns",
    "annual_mean_temperature",
    "calendar_inputs",
    "fixed_node_temperature",
    "ground_cycle_inputs",
    "ground_input",
    "seasonal_ground_temperature",
    "solar_inputs",
    "weather_inputs",
]

_IRRADIANCE = ("ghi", "dni", "dhi")
_YEAR = pd.Timedelta(days=365)
#: A 365-day window of daily means counts as complete with this many valid days.
_MIN_DAYS = 350
#: Transposition model and ground albedo used for the surfaces.
_TRANSPOSITION = "perez"
_ALBEDO = 0.2


def fixed_node_temperature(
    frame: pd.DataFrame, rows: slice, te: pd.Series | None, constant: float | None = None
) -> dict:
    """Temperature [°C] of the ground or crypt behind a hygric fixed vapour-pressure node
    (the centre of :func:`heritage_bayes.inference.survey.fixed_vapour_pressure_prior`).

    Parameters
    ----------
    frame : pandas.DataFrame
        The prepared grid; its ``Tf`` column [°C], when the thermal model has one, is
        the ground temperature to use.
    rows : slice
        Row positions of the calibration period in ``frame``.
    te : pandas.Series or None
        Outdoor air temperature [°C], the whole weather record (tz-aware index).
    constant : float, optional
        ``data.ground_temperature``'s constant [°C] (mode ``constant``).

    Returns
    -------
    dict
        ``value`` [°C] (rounded to 0.01 K) and ``method`` (plain words): the mean of
        ``Tf`` over ``rows``, else the constant, else the mean over ``rows`` of the
        annual mean outdoor temperature (:func:`annual_mean_temperature`).
    """
    if "Tf" in frame.columns:
        value, method = frame["Tf"].iloc[rows].mean(), "the thermal model's Tf, mean"
    elif constant is not None:
        value, method = constant, "data.ground_temperature's constant"
    elif te is None:
        raise ConfigError(
            "fixed_node_temperature: the weather has no outdoor temperature Te to take the "
            "annual mean of; give the temperature behind the fixed vapour-pressure node [°C]"
        )
    else:
        step = frame.index[1] - frame.index[0] if len(frame) > 1 else pd.Timedelta(0)
        tf, _ = annual_mean_temperature(te, frame.index[rows] + step / 2)
        value, method = float(np.mean(tf)), "the annual mean outdoor temperature, mean"
    return {"value": round(float(value), 2), "method": f"{method} (calibration period)"}


def annual_mean_temperature(te: pd.Series, times: pd.DatetimeIndex) -> tuple[np.ndarray, dict]:
    """Fixed (ground) temperature ``Tf`` from outdoor temperature: the mean of a year.

    Parameters
    ----------
    te : pandas.Series
        Outdoor air temperature [°C] with a tz-aware index: the **whole** weather record
        (NaN allowed), not only the period to simulate.
    times : pandas.DatetimeIndex
        Tz-aware instants at which ``Tf`` is wanted (e.g. the middle of each grid row).

    Returns
    -------
    values : numpy.ndarray
        ``Tf`` [°C] at ``times``.
    info : dict
        ``method`` (plain words), ``min``, ``max`` [°C], ``record_days``.

    Notes
    -----
    * Record shorter than 365 days (typical-year files such as TMY3/EPW: 8760 hourly
      values span 364 d 23 h): the mean of all values, a constant.
    * Otherwise: daily means (UTC days with at least half of the typical number of
      readings), their 365-day centred running mean where the window holds at least 350
      valid days, linearly interpolated to ``times`` and held constant before the first
      and after the last complete window. The result follows slow year-to-year changes
      but not the seasons.
    * No complete window (a long record full of gaps): the mean of all values, and
      ``info["method"]`` says so.

    The ground under a building and thick masonry follow the annual mean outdoor
    temperature with a seasonal swing that decays with depth; the constant (or slowly
    varying) annual mean is the usual choice for the fixed node of RC models.
    """
    s = pd.Series(np.asarray(te, dtype=float), index=te.index).dropna()
    if s.empty:
        raise DataError("outdoor temperature Te has no values: cannot form an annual mean")
    span = s.index[-1] - s.index[0]
    days = span / pd.Timedelta(days=1)
    info = {"record_days": round(float(days), 2)}
    if span >= _YEAR:
        daily = s.resample("1D").agg(["mean", "count"])
        typical = float(daily["count"].median())
        means = daily["mean"].where(daily["count"] >= 0.5 * typical)
        roll = means.rolling(365, center=True, min_periods=_MIN_DAYS).mean().dropna()
        if not roll.empty:
            centres = (roll.index + pd.Timedelta(hours=12)).asi8.astype(float)
            t = np.clip(times.asi8.astype(float), centres[0], centres[-1])
            values = np.interp(t, centres, roll.to_numpy())
            info["method"] = (
                "365-day centred running mean of the daily mean Te over the whole weather "
                "record, held constant beyond the first/last complete window"
            )
            info.update(min=float(values.min()), max=float(values.max()))
            return values, info
        method = (
            f"mean of Te over the whole weather record ({days:.0f} days): no 365-day "
            f"window holds {_MIN_DAYS} valid days"
        )
    else:
        method = f"mean of Te over the whole weather record ({days:.2f} days, less than a year)"
    value = float(s.mean())
    info.update(method=method, min=value, max=value)
    return np.full(len(times), value), info


def seasonal_ground_temperature(
    te: pd.Series, times: pd.DatetimeIndex, depth: float | None = None
) -> tuple[np.ndarray, dict]:
    """Fixed (ground) temperature ``Tf`` [°C] that follows the season, from outdoor air.

    Parameters
    ----------
    te : pandas.Series
        Outdoor air temperature [°C], tz-aware index: the **whole** weather record.
    times : pandas.DatetimeIndex
        Tz-aware instants at which ``Tf`` is wanted.
    depth : float, optional
        Depth of the ground temperature [m]; default
        :data:`heritage_bayes.climate.ground.GROUND_DEPTH` (1 m).

    Returns
    -------
    values : numpy.ndarray
        ``Tf`` [°C] at ``times``.
    info : dict
        ``method`` (plain words), ``min``, ``max`` [°C] and, when fitted, the surface
        cycle (``mean`` [°C], ``amplitude`` [K], ``coldest_day``), ``depth`` [m],
        ``amplitude_ratio`` [-] and ``lag_days`` [d].

    Notes
    -----
    The annual cycle of the daily mean air temperature
    (:func:`heritage_bayes.climate.ground.fit_annual_cycle`), taken as the ground
    surface's, carried to ``depth`` in a clay/silt soil
    (:func:`heritage_bayes.climate.ground.kusuda_achenbach`). A record whose daily means
    span less than 180 days has no cycle to fit: :func:`annual_mean_temperature`, and
    ``info["method"]`` says so.
    """
    from heritage_bayes.climate import ground

    depth = ground.GROUND_DEPTH if depth is None else float(depth)
    cycle, short = _annual_cycle(te)
    if cycle is None:
        values, info = annual_mean_temperature(te, times)
        info["method"] += short
        return values, info
    values = ground.kusuda_achenbach(
        times, cycle["mean"], cycle["amplitude"], cycle["t_min"], depth=depth
    )
    ratio, lag = ground.damping(depth)
    info = {
        "method": (
            f"annual cycle fitted to {cycle['days']} daily means of Te, at {depth:g} m in "
            f"clay/silt soil (Kusuda-Achenbach, diffusivity {ground.SOIL_DIFFUSIVITY:g} m²/s)"
        ),
        "mean": round(cycle["mean"], 2),
        "amplitude": round(cycle["amplitude"], 2),
        "coldest_day": cycle["coldest_day"],
        "depth": depth,
        "amplitude_ratio": round(ratio, 3),
        "lag_days": round(lag, 1),
        "min": float(np.min(values)) if len(values) else None,
        "max": float(np.max(values)) if len(values) else None,
    }
    return values, info


def _annual_cycle(te: pd.Series) -> tuple[dict | None, str]:
    """The annual cycle of ``te`` (:func:`heritage_bayes.climate.ground.fit_annual_cycle`),
    or None and why (daily means spanning too few days)."""
    from heritage_bayes.climate import ground

    valid = te.index[np.isfinite(np.asarray(te, dtype=float))]
    span = (valid[-1] - valid[0]) / pd.Timedelta(days=1) if len(valid) else 0.0
    if span < ground.MIN_SPAN_DAYS + 3:
        return None, (
            f"; no seasonal cycle: Te spans {span:.0f} days, the fit needs "
            f"{ground.MIN_SPAN_DAYS + 3:.0f}"
        )
    return ground.fit_annual_cycle(te), ""


def ground_cycle_inputs(te: pd.Series, times: pd.DatetimeIndex) -> tuple[dict, str]:
    """The surface's annual anomaly and its quadrature [K] at ``times``, the inputs
    ``Tf_cos`` and ``Tf_sin`` of a ground at an estimated depth
    (:class:`heritage_bayes.rc.network.GroundCycle`).

    Parameters
    ----------
    te : pandas.Series
        Outdoor air temperature [°C], tz-aware index: the **whole** weather record.
    times : pandas.DatetimeIndex
        Tz-aware instants.

    Returns
    -------
    columns : dict
        ``Tf_cos``, ``Tf_sin`` -> (N,) arrays [K]
        (:func:`heritage_bayes.climate.ground.annual_components` of the cycle fitted as
        in :func:`seasonal_ground_temperature`); zeros when ``te`` has no cycle to fit
        (the depth then has no effect).
    note : str
        Plain words for the record of the inputs.
    """
    from heritage_bayes.climate import ground

    cycle, short = _annual_cycle(te)
    if cycle is None:
        zeros = np.zeros(len(times))
        return {"Tf_cos": zeros, "Tf_sin": zeros.copy()}, f"depth not estimable{short}"
    c, s = ground.annual_components(times, cycle["amplitude"], cycle["t_min"])
    note = (
        f"depth estimated (zf): the ground follows the annual cycle of Te (amplitude "
        f"{cycle['amplitude']:.2f} K) damped and delayed at the depth zf (Kusuda-Achenbach)"
    )
    return {"Tf_cos": c, "Tf_sin": s}, note


def ground_input(
    mode: str, te: pd.Series, times: pd.DatetimeIndex, depth: float | None = None
) -> tuple[np.ndarray, dict]:
    """``Tf`` [°C] at ``times`` from the outdoor air ``te`` (whole record) for
    ``data.ground_temperature`` mode ``seasonal`` (:func:`seasonal_ground_temperature`)
    or ``annual_mean`` (:func:`annual_mean_temperature`); ``info`` holds ``mode``."""
    if mode == "seasonal":
        values, info = seasonal_ground_temperature(te, times, depth)
    elif mode == "annual_mean":
        values, info = annual_mean_temperature(te, times)
    else:
        raise ValueError(f"mode must be 'seasonal' or 'annual_mean' (got {mode!r})")
    return values, {"mode": mode} | info


def calendar_inputs(models, index: pd.DatetimeIndex, dt: float) -> dict[str, np.ndarray]:
    """Input columns that the models generate from a calendar, on a time grid.

    Parameters
    ----------
    models : iterable of RCModel
        Models whose ``calendar_inputs`` (e.g. a thermostat's weekly hours of use,
        :mod:`heritage_bayes.rc.calendar`) are wanted.
    index : pandas.DatetimeIndex
        Step starts (tz-aware; UTC in the prepared data).
    dt : float
        Step [s].

    Returns
    -------
    dict
        Column name -> (N,) array: the fraction of each step ``[t_k, t_k + dt)`` in the
        hours of use [-] (zero-order-hold mean, the convention of every input).
    """
    out: dict[str, np.ndarray] = {}
    for m in models:
        for name, cal in getattr(m, "calendar_inputs", {}).items():
            out[name] = cal.fraction(index, dt)
    return out


def add_slope_columns(
    frame: pd.DataFrame, models, slopes: pd.DataFrame | None, flags: pd.DataFrame | None = None
) -> None:
    """Add the slope columns (``<input>_slope``) the models need to ``frame``, in place.

    An input's change over each step [its unit per step] from
    :attr:`heritage_bayes.io.Aligned.slopes` (instantaneous readings: the first-order
    hold, :meth:`heritage_bayes.rc.RCModel.with_slopes`); zeros for interval means and
    for inputs made on the grid (``Tf`` as an annual mean or a constant, calendars),
    which are held over the step. ``flags`` (when given) copy the input's flags;
    ``frame.attrs`` gain the units and ``input_hold`` (``"exact"`` or
    ``"interval_mean"``).
    """
    units = frame.attrs.setdefault("units", {})
    outputs = [c for c in frame.attrs.get("outputs", ()) if c in frame.columns]
    for m in models:
        for u, col in zip(m.slope_inputs, m.slope_columns, strict=True):
            if col in frame.columns:
                continue
            if slopes is not None and u in slopes.columns:
                values = slopes[u].reindex(frame.index).to_numpy(dtype=float)
            else:
                values = np.zeros(len(frame))
            # before the outputs (the frame's order: inputs, then outputs)
            at = frame.columns.get_loc(outputs[0]) if outputs else len(frame.columns)
            frame.insert(at, col, values)
            if flags is not None:
                flag = flags[u].to_numpy() if u in flags.columns else np.zeros(len(frame), bool)
                flags.insert(at, col, flag)
            units[col] = f"{units.get(u, '')} per step".strip()
    cols = [c for m in models for c in m.slope_columns]
    if "inputs" in frame.attrs:
        frame.attrs["inputs"] = tuple(dict.fromkeys((*frame.attrs["inputs"], *cols)))
    slope = bool(cols)
    frame.attrs["input_hold"] = "exact" if slope else "interval_mean"


def solar_inputs(
    weather: pd.DataFrame,
    site: Mapping,
    surfaces: Mapping[str, Sequence[float]],
    mode: str,
    *,
    where: str = "data.weather",
    roof: Sequence[str] = (),
    roof_horizon: float = 0.0,
) -> tuple[pd.DataFrame, str, str]:
    """Irradiance on each solar surface as model inputs ``I_<surface>`` [W/m²].

    Parameters
    ----------
    weather : pandas.DataFrame
        A reader's output (``ghi`` and optionally ``dni``, ``dhi``, with ``attrs``).
    site : mapping
        ``latitude``, ``longitude`` [°], ``altitude`` [m].
    surfaces : mapping
        ``{name: (tilt, azimuth)}`` [°].
    mode : {"measured", "estimated", "clear_sky"}
        Measured irradiance; the global irradiance estimated from the daily range of
        ``Te`` (:func:`heritage_bayes.climate.solar.temperature_range_weather`); or the
        cloudless sky. With the last two, measured columns, if any, are dropped and the
        input is labelled.
    roof : sequence of str, optional
        The surfaces that are opaque roof planes: when the weather has a wind speed
        ``wind`` [m/s], their irradiance is weighted by the share of the absorbed sun
        that reaches the attic at that wind
        (:func:`heritage_bayes.climate.solair.roof_wind_weight`; gaps in the wind
        interpolated in time); without it, or for other surfaces, unweighted (the
        standard exterior resistance). When the weather has a precipitation ``precip``
        [mm] and a day below 0 °C, they are also taken under the snow estimated from it
        (:func:`heritage_bayes.climate.snow.roof_snow_columns`: no sun, the outer face
        at the snow's base, the air's daily mean drawn towards 0 °C).
    roof_horizon : float, default 0
        Skyline [° of sun elevation] of the roof planes: while the sun is lower their
        beam is shaded (``horizon`` of
        :func:`heritage_bayes.climate.solar.surface_irradiance`); other surfaces none.

    Returns
    -------
    table : pandas.DataFrame
        ``I_<name>`` columns, interval averages stamped at the interval end (``attrs``).
    label : str
        Short label: ``"measured"``, ``"estimated from the daily Te range
        (Hargreaves-Samani)"`` or ``"clear-sky proxy (pvlib Ineichen)"``.
    detail : str
        The full provenance label of :func:`heritage_bayes.climate.surface_irradiance`.
    """
    from heritage_bayes.climate.solar import surface_irradiance, temperature_range_weather

    present = [c for c in _IRRADIANCE if c in weather.columns]
    attrs = dict(weather.attrs)
    kwargs = {}
    if mode == "measured":
        if "ghi" not in present:
            raise DataError(
                f"{where}: data.irradiance is 'measured' but the weather has no global "
                f"horizontal irradiance 'ghi' (columns: {list(weather.columns)}); map it in "
                f"{where}.columns.ghi, or set data.irradiance to 'estimated' (from the "
                f"daily temperature range), 'clear_sky' or 'none'"
            )
        table = weather[present].copy()
        table.attrs = attrs
        label = "measured"
    elif mode == "estimated":
        if "Te" not in weather.columns:
            raise DataError(
                f"{where}: data.irradiance is 'estimated' (from the daily range of the "
                f"outdoor temperature) but the weather has no Te (columns: "
                f"{list(weather.columns)})"
            )
        te = weather["Te"].copy()
        te.attrs = {"source": attrs.get("source", "weather")}
        try:
            table = temperature_range_weather(te, dict(site), interval=attrs.get("interval"))
        except DataError as exc:
            raise DataError(f"{where}: {exc}") from None
        except InputError as exc:
            raise ConfigError(f"{where}: {exc}") from None
        label = "estimated from the daily Te range (Hargreaves-Samani)"
    elif mode == "clear_sky":
        table = weather.drop(columns=present)
        table.attrs = attrs
        kwargs = {"clear_sky": True}
        label = "clear-sky proxy (pvlib Ineichen)"
    else:
        raise ValueError(f"mode must be 'measured', 'estimated' or 'clear_sky' (got {mode!r})")
    try:
        irr = surface_irradiance(
            table,
            dict(site),
            {k: tuple(v) for k, v in surfaces.items()},
            model=_TRANSPOSITION,
            albedo=_ALBEDO,
            **kwargs,
        )
    except DataError as exc:
        raise DataError(f"{where}: {exc}") from None
    except InputError as exc:
        raise ConfigError(f"{where}: {exc}") from None
    detail = irr.attrs.get("irradiance_source", label)
    planes = [k for k in roof if k in surfaces]
    if planes and roof_horizon:
        try:
            shaded = surface_irradiance(
                table, dict(site), {k: tuple(surfaces[k]) for k in planes},
                model=_TRANSPOSITION, albedo=_ALBEDO, horizon=roof_horizon, **kwargs,
            )  # fmt: skip
        except InputError as exc:
            raise ConfigError(f"data.roof.horizon: {exc}") from None
        irr = irr.assign(**{k: shaded[k] for k in planes})
        detail += f"; roof planes shaded below {roof_horizon:g}° of sun elevation"
    if planes and "wind" in weather.columns:
        irr = _wind_weighted(irr, weather["wind"], planes, where)
        detail += f"; roof planes {planes} weighted by the wind on the roof (ISO 6946 h_e)"
    if planes and {"precip", "Te"} <= set(weather.columns):
        from heritage_bayes.climate.snow import roof_snow_columns

        try:
            irr, snow = roof_snow_columns(irr, weather["Te"], weather["precip"], planes)
        except InputError as exc:
            raise DataError(f"{where}: column 'precip': {exc}") from None
        detail += f"; {snow}" if snow else ""
    if mode != "measured" and present:
        detail += f"; measured {present} ignored (data.irradiance: {mode})"
    out = irr.rename(columns={k: f"I_{k}" for k in surfaces})
    out.attrs = dict(irr.attrs)
    out.attrs["averaged"] = tuple(f"I_{k}" for k in irr.attrs.get("averaged", ()))
    out.attrs["units"] = {f"I_{k}": "W/m²" for k in surfaces}
    out.attrs["irradiance_source"] = detail
    out.attrs["source"] = f"{attrs.get('source', 'weather')} (irradiance on surfaces)"
    return out, label, detail


def _wind_weighted(irr: pd.DataFrame, wind: pd.Series, planes, where: str) -> pd.DataFrame:
    """``irr`` with the ``planes`` columns times the roof's wind weight."""
    from heritage_bayes.climate.solair import roof_wind_weight

    v = wind.reindex(irr.index).interpolate(limit_direction="both")
    if not np.isfinite(v.to_numpy(dtype=float)).any():
        raise DataError(f"{where}: the wind speed column 'wind' has no values")
    try:
        w = roof_wind_weight(v.to_numpy(dtype=float))
    except InputError as exc:
        raise DataError(f"{where}: column 'wind': {exc}") from None
    out = irr.copy()
    for k in planes:
        out[k] = irr[k].to_numpy(dtype=float) * w
    out.attrs = dict(irr.attrs)
    return out


def _with_vapour_pressure(df: pd.DataFrame, target: str, where: str) -> pd.DataFrame:
    """Add ``Pe`` (from Te, RHe) or ``Pi`` (from Ti, RHi) unless already present."""
    from heritage_bayes.io import add_vapour_pressure

    t, rh = {"Pe": ("Te", "RHe"), "Pi": ("Ti", "RHi")}[target]
    if target in df.columns or not (t in df.columns and rh in df.columns):
        return df
    sub = df[[t, rh]].copy()
    sub.attrs = dict(df.attrs)
    try:
        out = add_vapour_pressure(sub, over="water")
    except DataError as exc:
        raise DataError(f"{where}: {exc}") from None
    res = df.copy()
    res[target] = out[target]
    res.attrs = dict(df.attrs)
    res.attrs["units"] = {**df.attrs.get("units", {}), target: "Pa"}
    res.attrs["derived"] = {**df.attrs.get("derived", {}), **out.attrs.get("derived", {})}
    # derived from interval means, the vapour pressure is one too (its timing, not a reading)
    res.attrs["averaged"] = tuple(out.attrs.get("averaged", ()))
    return res


def _table(df: pd.DataFrame, columns: Sequence[str]) -> pd.DataFrame:
    """Columns of a reader's table, keeping (and trimming) its attrs."""
    out = df[list(columns)].copy()
    attrs = dict(df.attrs)
    attrs["averaged"] = tuple(c for c in df.attrs.get("averaged", ()) if c in columns)
    attrs["units"] = {c: u for c, u in df.attrs.get("units", {}).items() if c in columns}
    out.attrs = attrs
    return out


def weather_inputs(
    weather: pd.DataFrame,
    *,
    thermal: bool,
    hygric: bool,
    irradiance: str | None,
    site: Mapping | None,
    surfaces: Mapping[str, Sequence[float]],
    where: str = "data.weather",
    extra: Sequence[str] = (),
    roof: Sequence[str] = (),
    roof_horizon: float = 0.0,
) -> tuple[list[pd.DataFrame], dict]:
    """The input tables to align: ``Te`` (thermal), ``Pe`` (hygric), ``I_<surface>``.

    ``extra``: further input columns the models need and the weather table carries
    as they are (e.g. a measured heating power ``Ph`` [W] for a heated test cell, or the
    inputs of a custom network); a missing one is reported when the model asks for it.
    ``irradiance`` None (``data.irradiance``'s default) is ``"measured"`` when the weather
    has ``ghi``, else ``"estimated"``. ``roof``: the surfaces that are roof planes (their
    sun weighted by the wind and shaded below ``roof_horizon`` [°], :func:`solar_inputs`).

    Returns the tables and a dict ``{"irradiance_source": short, "irradiance": {...}}``.
    """
    need = [c for c in extra if c in weather.columns]
    if thermal:
        need.append("Te")
    if hygric:
        weather = _with_vapour_pressure(weather, "Pe", where)
        need.append("Pe")
    missing = [c for c in need if c not in weather.columns]
    if missing:
        why = {
            "Te": "outdoor temperature Te (thermal section)",
            "Pe": "outdoor vapour pressure Pe, or Te and RHe to derive it (hygric section)",
        }
        raise DataError(
            f"{where}: no {' and no '.join(why[c] for c in missing)}; the weather has "
            f"{list(weather.columns)}"
            + (f"; map them in {where}.columns" if weather.attrs.get("format") == "csv" else "")
        )
    tables = [_table(weather, need)] if need else []
    note: dict = {"irradiance_source": "none", "irradiance": {"mode": "none"}}
    if irradiance is None:  # the default: measured when there is a global irradiance
        irradiance = "measured" if "ghi" in weather.columns else "estimated"
    if thermal and irradiance != "none":
        if site is None:
            raise ConfigError(
                "site: required (latitude, longitude) to compute solar irradiance on the "
                "surfaces; or set data.irradiance: none"
            )
        irr, label, detail = solar_inputs(
            weather, site, surfaces, irradiance, where=where, roof=roof, roof_horizon=roof_horizon
        )
        tables.append(irr)
        note = {
            "irradiance_source": label,
            "irradiance": {
                "mode": irradiance,
                "label": detail,
                "surfaces": {k: {"tilt": v[0], "azimuth": v[1]} for k, v in surfaces.items()},
                "transposition": f"{_TRANSPOSITION}, albedo {_ALBEDO:g}",
                "site": dict(site),
            },
        }
    return tables, note


# ---------------------------------------------------------------------------------------
