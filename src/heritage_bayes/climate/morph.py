"""Future weather as documented transformations of a baseline hourly series.

Three transformations, each a pure function on a reader's hourly table (tz-aware index,
columns ``Te`` [°C], ``RHe`` [%], ``Pe`` [Pa], ``ghi``/``dni``/``dhi`` [W/m²]):

* :func:`knmi14_transform` — the KNMI'14 time-series transformation (Bakker 2015) for
  Dutch sites, from the published delta tables: daily mean temperature changed per
  calendar month and per percentile of the daily values (:func:`transform_daily_quantiles`),
  the hourly temperatures shifted so that their daily means follow the transformed daily
  series, and the global radiation scaled per month (bounded by 0.75 × the Angot
  top-of-atmosphere radiation, :func:`transform_daily_radiation`).
* :func:`morph` — morphing (Belcher, Hacker & Powell 2005) from a table of monthly
  changes, for any site: *shift* ``x = x0 + Δx_m``, *stretch* ``x = α_m x0``, and
  *shift + stretch* ``x = x0 + Δx_m + α_m (x0 − ⟨x0⟩_m)`` with
  ``α_m = (ΔTmax_m − ΔTmin_m)/(⟨Tmax⟩_m − ⟨Tmin⟩_m)``.
* a user-supplied future file needs no transformation (read it with the readers).

Humidity under warming (``humidity``), explicit in every transformation:

* ``"constant_rh"`` (default): the outdoor relative humidity stays as it was, the vapour
  pressure ``Pe`` follows the new temperature (``Pe = RHe · Psat(Te)``), i.e. the
  absolute humidity rises by ≈ 6–7 %/K (Clausius–Clapeyron), the usual assumption of
  climate-model output over land in the mid-latitudes;
* ``"constant_vapour_pressure"``: ``Pe`` stays as it was, ``RHe`` falls with warming
  (capped at 100 % where the air cools);
* ``"table"`` (morphing only): the table's ``RHe`` column [%-points] shifts the relative
  humidity (clipped to 0–100 %), ``Pe`` follows.

References
----------
.. [1] A. Bakker (2015), "Time series transformation tool: description of the program
   to generate time series consistent with the KNMI'14 climate scenarios", KNMI
   Technical Report TR-349, De Bilt.
.. [2] S. E. Belcher, J. N. Hacker and D. S. Powell (2005), "Constructing design weather
   data for future climates", Building Services Engineering Research and Technology
   26(1), 49-61, doi:10.1191/0143624405bt112oa.
.. [3] KNMI (2014), "KNMI'14: Climate Change scenarios for the 21st Century — A
   Netherlands perspective", Scientific Report WR2014-01.
"""

from __future__ import annotations

from collections.abc import Mapping
from pathlib import Path

import numpy as np
import pandas as pd

from heritage_bayes.climate.psychro import saturation_vapour_pressure
from heritage_bayes.errors import ConfigError, DataError

__all__ = [
    "HUMIDITY_MODES",
    "KNMI14_HORIZONS",
    "KNMI14_PERCENTILES",
    "KNMI14_SCENARIOS",
    "knmi14_region",
    "knmi14_transform",
    "morph",
    "read_knmi14_deltas",
    "read_monthly_deltas",
    "transform_daily_quantiles",
    "transform_daily_radiation",
]

KNMI14_SCENARIOS = ("GL", "GH", "WL", "WH")
KNMI14_HORIZONS = (2030, 2050, 2085)
#: Percentiles of the KNMI'14 temperature tables (columns P01 … P99). [%]
KNMI14_PERCENTILES = (1, 5, 50, 95, 99)
HUMIDITY_MODES = ("constant_rh", "constant_vapour_pressure", "table")
MORPH_METHODS = ("shift", "stretch", "shift_stretch")
_REGIONS = ("NLD", "NWN", "ZWN", "NON", "MON", "ZON", "NZK")


# ------------------------------------------------------------------------------ tables
def _table_path(folder: Path, variable: str, scenario: str, horizon: int) -> Path:
    scen = "__" if horizon == 2030 else scenario
    name = f"deltas-KNMI14__{variable:_<4}_{scen:_<2}__{horizon}.txt"
    return folder / name


def read_knmi14_deltas(
    folder, variable: str, scenario: str, horizon: int, region: str | None = None
) -> pd.DataFrame:
    """One KNMI'14 change table.

    Parameters
    ----------
    folder : path
        The folder of the tables (``deltas-KNMI14__<var>_<scen>__<horizon>.txt``).
    variable : {"tg", "tn", "tx", "rsds", "rr"}
        Daily mean/min/max temperature, global radiation, precipitation.
    scenario : {"GL", "GH", "WL", "WH"}
        KNMI'14 scenario; 2030 has one table for all four (the scenarios do not yet
        differ by then).
    horizon : {2030, 2050, 2085}
        Central year of the 30-year future period.
    region : str, optional
        Region of the temperature tables (``NWN``, ``ZWN``, ``NON``, ``MON``, ``ZON``,
        ``NZK``); see :func:`knmi14_region`. Required for the temperature tables.

    Returns
    -------
    pandas.DataFrame
        Index ``month`` 1–12; temperature: columns ``P01 … P99`` [K], change of that
        percentile of the daily values; ``rsds``/``rr``: column ``ave`` [%], relative
        change of the monthly mean.
    """
    if scenario not in KNMI14_SCENARIOS:
        raise ConfigError(f"KNMI'14 scenario {scenario!r}: expected one of {KNMI14_SCENARIOS}")
    if horizon not in KNMI14_HORIZONS:
        raise ConfigError(f"KNMI'14 horizon {horizon!r}: expected one of {KNMI14_HORIZONS}")
    path = _table_path(Path(folder), variable, scenario, int(horizon))
    if not path.is_file():
        raise DataError(f"KNMI'14 table {path}: file not found")
    df = pd.read_csv(path, sep=r"\s+")
    if "regio" in df.columns:
        if region is None:
            raise ConfigError(f"{path.name}: the table is per region; give the region")
        sub = df[df["regio"] == region]
        if sub.empty:
            raise ConfigError(
                f"{path.name}: region {region!r} not in the table; it has "
                f"{sorted(df['regio'].unique())}"
            )
        df = sub.drop(columns="regio")
    out = df.set_index("maand").sort_index()
    out.index.name = "month"
    if list(out.index) != list(range(1, 13)):
        raise DataError(f"{path.name}: expected the months 1…12, found {list(out.index)}")
    out.attrs["source"] = str(path)
    return out.astype(float)


def knmi14_region(folder, station: int) -> str:
    """KNMI'14 region of a KNMI station number, from the folder's ``stationstabel``."""
    path = Path(folder) / "stationstabel"
    if not path.is_file():
        raise DataError(f"{path}: file not found (station → region table)")
    tab = pd.read_csv(path, sep=r"\s+", header=None, names=["station", "region"])
    hit = tab.loc[tab["station"] == int(station), "region"]
    if hit.empty:
        raise ConfigError(
            f"station {station} is not in {path} (KNMI'14 regions); give the region explicitly"
        )
    return str(hit.iloc[0])


# ------------------------------------------------------------------- daily transforms
def transform_daily_quantiles(daily: pd.Series, deltas: pd.DataFrame) -> pd.Series:
    """KNMI'14 transformation of daily temperatures, per calendar month and percentile.

    Parameters
    ----------
    daily : pandas.Series
        Daily values (mean, min or max temperature) [°C], DatetimeIndex.
    deltas : pandas.DataFrame
        Index month 1–12, columns ``P01 P05 P50 P95 P99`` [K] (:func:`read_knmi14_deltas`).

    Returns
    -------
    pandas.Series
        The transformed daily values [°C].

    Notes
    -----
    For each calendar month the percentiles :math:`X_p` (p = 1, 5, 50, 95, 99) of the
    month's daily values of the whole series are computed; their future values are
    :math:`Y_p = X_p + \\Delta_p`. Each daily value is mapped by the piecewise-linear
    function through the points :math:`(X_p, Y_p)`, extrapolated linearly with the end
    segments below :math:`X_{5}` and above :math:`X_{95}` (Bakker 2015, as the KNMI
    program ``tm_trans_KNMI14``). The change of a value at a table percentile is thus
    the table's delta at that percentile; the monthly mean changes by the average of
    the interpolated deltas over the month's distribution.
    """
    cols = [f"P{p:02d}" for p in KNMI14_PERCENTILES]
    x = daily.to_numpy(dtype=float)
    y = np.full_like(x, np.nan)
    months = daily.index.month
    for m in range(1, 13):
        sel = (months == m) & np.isfinite(x)
        if not sel.any():
            continue
        X = x[sel]
        Xp = np.quantile(X, np.asarray(KNMI14_PERCENTILES) / 100.0)
        Yp = Xp + deltas.loc[m, cols].to_numpy(dtype=float)
        seg = np.clip(np.searchsorted(Xp, X, side="right"), 1, len(Xp) - 1)
        dx = Xp[seg] - Xp[seg - 1]
        with np.errstate(divide="ignore", invalid="ignore"):
            a = np.where(dx > 0, (Yp[seg] - Yp[seg - 1]) / dx, 1.0)
        y[sel] = Yp[seg] + a * (X - Xp[seg])
    return pd.Series(y, index=daily.index, name=daily.name)


def _angot(days: pd.DatetimeIndex, latitude: float) -> np.ndarray:
    """Daily top-of-atmosphere irradiation [J/m²] (FAO-56 eq. 21)."""
    gsc = 0.0820e6 / 60.0  # solar constant [J/m²/s] -> 0.0820 MJ/m²/min
    phi = np.deg2rad(latitude)
    j = days.day_of_year.to_numpy(dtype=float)
    dr = 1 + 0.033 * np.cos(2 * np.pi * j / 365)
    dec = 0.409 * np.sin(2 * np.pi * j / 365 - 1.39)
    ws = np.arccos(np.clip(-np.tan(phi) * np.tan(dec), -1.0, 1.0))
    return (
        86400
        / np.pi
        * gsc
        * dr
        * (ws * np.sin(phi) * np.sin(dec) + np.sin(ws) * np.cos(phi) * np.cos(dec))
    )


def transform_daily_radiation(daily: pd.Series, change_pct: pd.Series, latitude: float):
    """KNMI'14 transformation of daily global irradiation (per calendar month).

    Parameters
    ----------
    daily : pandas.Series
        Daily global irradiation [J/m²] (or any unit proportional to it), DatetimeIndex.
    change_pct : pandas.Series
        Index month 1–12: relative change of the monthly mean [%] (``rsds`` table).
    latitude : float
        [°] for the clear-sky bound.

    Returns
    -------
    factor : pandas.Series
        Daily multiplicative factor (new / old) [-].

    Notes
    -----
    Decreases scale every day by ``1 + δ``; increases scale by ``a`` but no day beyond
    ``0.75 × Angot`` radiation, ``a`` solved so that the monthly mean rises by ``δ``
    (Bakker 2015, ``rsds_trans_KNMI14``). The bound is in J/m², so give ``daily`` in
    J/m² when the month's change is positive.
    """
    from scipy.optimize import brentq

    x = daily.to_numpy(dtype=float)
    fac = np.ones_like(x)
    cap = 0.75 * _angot(daily.index, latitude)
    months = daily.index.month
    for m in range(1, 13):
        sel = (months == m) & np.isfinite(x)
        if not sel.any():
            continue
        d = float(change_pct.loc[m]) / 100.0
        X, C = x[sel], cap[sel]
        if d <= 0 or X.sum() <= 0:
            a = 1.0 + d
            Y = a * X
        else:
            target = (1 + d) * X.mean()

            def f(a, X=X, C=C, target=target):
                return np.minimum(a * X, np.maximum(C, X)).mean() - target

            hi = 4.0
            a = brentq(f, 1.0, hi, xtol=1e-6) if f(hi) > 0 else hi
            Y = np.minimum(a * X, np.maximum(C, X))
        with np.errstate(divide="ignore", invalid="ignore"):
            fac[sel] = np.where(X > 0, Y / X, 1.0)
    return pd.Series(fac, index=daily.index)


# ------------------------------------------------------------------------ humidity
def _humidity(out: pd.DataFrame, base: pd.DataFrame, mode: str, rh_shift=None) -> pd.DataFrame:
    """Set ``RHe``/``Pe`` of the transformed table ``out`` according to ``mode``."""
    if mode not in HUMIDITY_MODES:
        raise ConfigError(f"humidity: {mode!r}; expected one of {HUMIDITY_MODES}")
    has_rh, has_pe = "RHe" in base.columns, "Pe" in base.columns
    if not (has_rh or has_pe):
        return out
    T0 = base["Te"].to_numpy(dtype=float)
    T1 = out["Te"].to_numpy(dtype=float)
    ps0, ps1 = saturation_vapour_pressure(T0), saturation_vapour_pressure(T1)
    rh0 = base["RHe"].to_numpy(dtype=float) if has_rh else 100.0 * base["Pe"].to_numpy() / ps0
    if mode == "constant_vapour_pressure":
        pe = base["Pe"].to_numpy(dtype=float) if has_pe else rh0 / 100.0 * ps0
        pe = np.minimum(pe, ps1)  # where the air cools below the old dew point
        rh1 = np.minimum(100.0 * pe / ps1, 100.0)  # rounding must not exceed 100 %
    else:
        rh1 = rh0 if mode == "constant_rh" else np.clip(rh0 + rh_shift, 0.0, 100.0)
        pe = rh1 / 100.0 * ps1
    if has_rh:
        out["RHe"] = rh1
    if has_pe or has_rh:
        out["Pe"] = pe
    if "Tdew" in out.columns:
        out = out.drop(columns="Tdew")
    return out


def _copy(weather: pd.DataFrame) -> pd.DataFrame:
    out = weather.copy()
    out.attrs = dict(weather.attrs)
    return out


def _scale_irradiance(out: pd.DataFrame, factor: np.ndarray) -> None:
    for c in ("ghi", "dni", "dhi"):  # keeps the diffuse fraction and the sun's position
        if c in out.columns:
            out[c] = out[c].to_numpy(dtype=float) * factor


def _check_weather(weather: pd.DataFrame, where: str) -> None:
    if "Te" not in weather.columns:
        raise DataError(
            f"{where}: the baseline weather has no outdoor temperature Te "
            f"(columns {list(weather.columns)})"
        )
    if not isinstance(weather.index, pd.DatetimeIndex) or weather.index.tz is None:
        raise DataError(f"{where}: the baseline weather needs a tz-aware DatetimeIndex")


# ------------------------------------------------------------------------- KNMI'14
def knmi14_transform(
    weather: pd.DataFrame,
    folder,
    scenario: str,
    horizon: int,
    *,
    region: str,
    latitude: float | None = None,
    humidity: str = "constant_rh",
    where: str = "knmi14",
) -> pd.DataFrame:
    """KNMI'14 time-series transformation of an hourly weather table.

    Parameters
    ----------
    weather : pandas.DataFrame
        Hourly baseline (a reader's output): ``Te`` [°C]; optionally ``RHe`` [%], ``Pe``
        [Pa], ``ghi``/``dni``/``dhi`` [W/m²].
    folder : path
        Folder of the KNMI'14 tables.
    scenario, horizon
        See :func:`read_knmi14_deltas`.
    region : str
        KNMI'14 region of the site (:func:`knmi14_region`).
    latitude : float, optional
        [°] for the radiation bound; default ``weather.attrs["site"]["latitude"]``.
    humidity : {"constant_rh", "constant_vapour_pressure"}
        See the module docstring.

    Returns
    -------
    pandas.DataFrame
        The same columns and index, transformed; ``attrs["transformation"]`` describes it.

    Notes
    -----
    Daily means of ``Te`` over UTC days (partial days at the ends: the mean of their
    hours) are transformed with :func:`transform_daily_quantiles` (``tg`` table); each
    hour of a day is shifted by its day's change, so the daily means of the result are
    the transformed daily means and the diurnal cycle is kept. The percentiles are those
    of the baseline series itself: the tables are changes relative to 1981–2010, so the
    baseline should be a (detrended) record of that climate, ideally 30 years. The
    global radiation is scaled day by day with :func:`transform_daily_radiation`
    (``rsds`` table; direct and diffuse by the same factor).
    """
    _check_weather(weather, where)
    tg = read_knmi14_deltas(folder, "tg", scenario, horizon, region)
    day = weather.index.floor("D")
    te = weather["Te"].astype(float)
    daily = te.groupby(day).mean()
    new_daily = transform_daily_quantiles(daily, tg)
    shift = (new_daily - daily).reindex(day).to_numpy()
    out = _copy(weather)
    out["Te"] = te.to_numpy() + shift
    if "ghi" in weather.columns:
        rs = read_knmi14_deltas(folder, "rsds", scenario, horizon)["ave"]
        lat = latitude
        if lat is None:
            lat = (weather.attrs.get("site") or {}).get("latitude")
        if lat is None:
            raise ConfigError(f"{where}: the latitude is needed to transform the radiation")
        ghi = weather["ghi"].astype(float).clip(lower=0)
        step_s = _step_seconds(weather.index)
        dsum = ghi.groupby(day).sum() * step_s  # [J/m²]
        fac = transform_daily_radiation(dsum, rs, float(lat))
        _scale_irradiance(out, fac.reindex(day).to_numpy())
    if humidity == "table":
        raise ConfigError(f"{where}.humidity: 'table' is for morphing tables only")
    out = _humidity(out, weather, humidity)
    out.attrs["transformation"] = {
        "method": "KNMI'14 time-series transformation (Bakker 2015, TR-349)",
        "scenario": scenario,
        "horizon": int(horizon),
        "region": region,
        "tables": [tg.attrs["source"]],
        "humidity": humidity,
    }
    return out


def _step_seconds(index: pd.DatetimeIndex) -> float:
    if len(index) < 2:
        return 3600.0
    return float(np.median(np.diff(index.asi8)) / 1e9)


# ------------------------------------------------------------------------ morphing
#: Columns of a monthly morphing table and their units.
MORPH_COLUMNS = {
    "Te": "K, change of the monthly mean outdoor temperature",
    "Te_max": "K, change of the monthly mean of the daily maximum",
    "Te_min": "K, change of the monthly mean of the daily minimum",
    "ghi": "%, relative change of the monthly mean global irradiance",
    "RHe": "%-points, change of the monthly mean relative humidity (humidity: table)",
}


def read_monthly_deltas(source, where: str = "deltas") -> pd.DataFrame:
    """A table of monthly changes for :func:`morph`.

    ``source``: a mapping ``{column: [12 values]}`` (January first) or the path of a CSV
    file with a ``month`` column (1–12) and the columns of :data:`MORPH_COLUMNS`.
    """
    if isinstance(source, Mapping):
        data = dict(source)
        for k, v in data.items():
            if not isinstance(v, list | tuple) or len(v) != 12:
                n = len(v) if isinstance(v, list | tuple) else type(v).__name__
                raise ConfigError(f"{where}.{k}: expected 12 monthly values (got {n})")
        df = pd.DataFrame(data, index=pd.RangeIndex(1, 13, name="month"))
    else:
        p = Path(source)
        if not p.is_file():
            raise DataError(f"{where}: {p}: file not found")
        df = pd.read_csv(p)
        if "month" not in df.columns:
            raise DataError(f"{where}: {p.name}: no 'month' column (columns {list(df.columns)})")
        df = df.set_index("month").sort_index()
        if list(df.index) != list(range(1, 13)):
            raise DataError(f"{where}: {p.name}: expected months 1…12, found {list(df.index)}")
    unknown = [c for c in df.columns if c not in MORPH_COLUMNS]
    if unknown:
        raise ConfigError(
            f"{where}.{unknown[0]}: unknown column; expected some of {list(MORPH_COLUMNS)}"
        )
    if "Te" not in df.columns:
        raise ConfigError(f"{where}.Te: required (monthly change of the mean temperature [K])")
    try:
        return df.astype(float)
    except ValueError as exc:
        raise ConfigError(f"{where}: non-numeric value ({exc})") from None


def morph(
    weather: pd.DataFrame,
    deltas: pd.DataFrame,
    *,
    method: str = "shift_stretch",
    humidity: str = "constant_rh",
    where: str = "morphing",
) -> pd.DataFrame:
    """Morph an hourly weather table with monthly changes (Belcher et al. 2005).

    Parameters
    ----------
    weather : pandas.DataFrame
        Hourly baseline: ``Te`` [°C]; optionally ``RHe`` [%], ``Pe`` [Pa], ``ghi``,
        ``dni``, ``dhi`` [W/m²].
    deltas : pandas.DataFrame
        :func:`read_monthly_deltas`: index month 1–12; ``Te`` [K] and optionally
        ``Te_max``, ``Te_min`` [K], ``ghi`` [%], ``RHe`` [%-points].
    method : {"shift", "stretch", "shift_stretch"}
        For the temperature. ``shift``: ``Te + ΔTe_m``. ``stretch``: ``Te·(1 + ΔTe_m /
        ⟨Te⟩_m)`` (scales the monthly mean by the change; for a quantity with a natural
        zero — use it for the irradiance, not for °C, unless you mean it).
        ``shift_stretch``: ``Te + ΔTe_m + α_m (Te − ⟨Te⟩_m)`` with ``α_m = (ΔTmax_m −
        ΔTmin_m)/(⟨Tmax⟩_m − ⟨Tmin⟩_m)`` from the table's ``Te_max`` and ``Te_min``
        (``⟨·⟩_m``: monthly means over the baseline of the daily maximum/minimum).
        The irradiance is always stretched (``× (1 + Δghi_m/100)``).
    humidity : {"constant_rh", "constant_vapour_pressure", "table"}

    Returns
    -------
    pandas.DataFrame
        Transformed copy; ``attrs["transformation"]`` describes it.

    Notes
    -----
    Monthly means are taken per calendar month over all years of the baseline. The
    monthly mean of ``Te`` changes by exactly ``ΔTe_m`` with ``shift`` and
    ``shift_stretch`` (the stretch term averages to zero over the month).
    """
    _check_weather(weather, where)
    if method not in MORPH_METHODS:
        raise ConfigError(f"{where}.method: {method!r}; expected one of {MORPH_METHODS}")
    if method == "shift_stretch" and not {"Te_max", "Te_min"} <= set(deltas.columns):
        raise ConfigError(
            f"{where}.deltas: method 'shift_stretch' needs the columns Te_max and Te_min "
            "(changes of the monthly mean daily maximum and minimum [K])"
        )
    if humidity == "table" and "RHe" not in deltas.columns:
        raise ConfigError(f"{where}.deltas.RHe: required with humidity 'table'")
    m = weather.index.month
    te = weather["Te"].to_numpy(dtype=float)
    mean_m = weather["Te"].groupby(m).mean()
    d_te = deltas["Te"].reindex(m).to_numpy()
    out = _copy(weather)
    if method == "shift":
        out["Te"] = te + d_te
    elif method == "stretch":
        out["Te"] = te * (1.0 + d_te / mean_m.reindex(m).to_numpy())
    else:
        day = weather.index.floor("D")
        dly = weather["Te"].groupby(day).agg(["max", "min"])
        span = (dly["max"] - dly["min"]).groupby(dly.index.month).mean()
        alpha = (deltas["Te_max"] - deltas["Te_min"]) / span.reindex(deltas.index)
        alpha = alpha.fillna(0.0)
        mu = mean_m.reindex(m).to_numpy()
        out["Te"] = te + d_te + alpha.reindex(m).to_numpy() * (te - mu)
    if "ghi" in deltas.columns:
        _scale_irradiance(out, 1.0 + deltas["ghi"].reindex(m).to_numpy() / 100.0)
    rh_shift = deltas["RHe"].reindex(m).to_numpy() if "RHe" in deltas.columns else None
    out = _humidity(out, weather, humidity, rh_shift)
    out.attrs["transformation"] = {
        "method": f"morphing ({method}; Belcher, Hacker & Powell 2005)",
        "humidity": humidity,
        "deltas": {c: [float(v) for v in deltas[c]] for c in deltas.columns},
    }
    return out
