"""Ground temperature that follows the season: a damped, lagged annual cycle.

Cellars, crawlspaces and floors on the ground sit on soil whose temperature follows the
annual cycle of the air above it, damped and delayed with depth. Without a ground
logger, :func:`fit_annual_cycle` fits the surface cycle (mean, amplitude, phase) to the
daily mean outdoor air temperature, and :func:`kusuda_achenbach` carries it to a depth
by the conduction of a periodic surface temperature into a semi-infinite soil.

References
----------
.. [1] T. Kusuda and P. R. Achenbach, "Earth temperature and thermal diffusivity at
   selected stations in the United States", ASHRAE Transactions 71(1) (1965) 61-75.
.. [2] H. S. Carslaw and J. C. Jaeger, "Conduction of heat in solids", 2nd ed., Oxford
   University Press (1959), section 2.6 (periodic surface temperature).
.. [3] ISO 13370:2017, "Thermal performance of buildings - Heat transfer via the ground -
   Calculation methods", table 7 (soil category 1, clay or silt: λ 1.5 W/(m K),
   ρc 3.0 MJ/(m³ K)).
"""

from __future__ import annotations

import numpy as np
import pandas as pd

from heritage_bayes.errors import DataError, InputError

__all__ = [
    "GROUND_DEPTH",
    "SOIL_DIFFUSIVITY",
    "YEAR_DAYS",
    "annual_components",
    "damping",
    "damping_depth",
    "depth_factors",
    "fit_annual_cycle",
    "kusuda_achenbach",
]

#: Thermal diffusivity of clay or silt soil [m²/s]: λ/(ρc) = 1.5 / 3.0e6 (ISO 13370 [3]_).
SOIL_DIFFUSIVITY = 0.5e-6
#: Default depth [m] of the ground temperature behind a floor on the ground: with
#: :data:`SOIL_DIFFUSIVITY` the annual swing is damped to 0.64 and delayed by 26 days.
GROUND_DEPTH = 1.0
#: Period of the annual cycle [d] (the mean Gregorian year).
YEAR_DAYS = 365.2425
#: The fit needs daily means spanning at least this many days [d].
MIN_SPAN_DAYS = 180.0
_DAY_NS = 86_400 * 10**9


def _days(times) -> np.ndarray:
    """Days [d] since 1970-01-01 UTC of tz-aware instants."""
    if not isinstance(times, pd.DatetimeIndex) or times.tz is None:
        raise InputError("times must be a tz-aware pandas DatetimeIndex")
    return times.tz_convert("UTC").as_unit("ns").asi8 / _DAY_NS


def damping(depth: float, diffusivity: float = SOIL_DIFFUSIVITY) -> tuple[float, float]:
    """Amplitude ratio [-] and lag [d] of the annual cycle at ``depth`` [m] in a soil of
    thermal ``diffusivity`` [m²/s]: :math:`e^{-z/d}` and :math:`z/(d\\,\\omega)`, with
    :math:`d = \\sqrt{2\\alpha/\\omega}` (see :func:`kusuda_achenbach`)."""
    depth, alpha = float(depth), float(diffusivity)
    if not depth >= 0.0:
        raise InputError(f"depth must be >= 0 m (got {depth})")
    if not alpha > 0.0:
        raise InputError(f"diffusivity must be > 0 m²/s (got {alpha})")
    omega = 2.0 * np.pi / YEAR_DAYS  # [1/d]
    d = np.sqrt(2.0 * alpha * 86_400.0 / omega)  # damping depth [m]
    return float(np.exp(-depth / d)), float(depth / d / omega)


def damping_depth(diffusivity: float = SOIL_DIFFUSIVITY) -> float:
    """Damping depth :math:`d = \\sqrt{2\\alpha/\\omega}` [m] of the annual cycle in a
    soil of thermal ``diffusivity`` :math:`\\alpha` [m²/s] (2.24 m for clay/silt)."""
    omega = 2.0 * np.pi / (YEAR_DAYS * 86_400.0)  # [1/s]
    return float(np.sqrt(2.0 * float(diffusivity) / omega))


def depth_factors(depth, diffusivity: float = SOIL_DIFFUSIVITY) -> tuple[np.ndarray, np.ndarray]:
    """Weights of the surface cycle's components at ``depth`` [m] (scalar or array).

    Returns :math:`(e^{-z/d}\\cos(z/d),\\ e^{-z/d}\\sin(z/d))` [-], so that the soil
    temperature of :func:`kusuda_achenbach` is
    :math:`T_m + a(z)\\,c(t) + b(z)\\,s(t)` with :math:`c, s` from
    :func:`annual_components`: linear in two series that do not depend on the depth.
    At :math:`z = 0`: (1, 0), the surface cycle itself.
    """
    x = np.asarray(depth, dtype=float) / damping_depth(diffusivity)
    rho = np.exp(-x)
    return rho * np.cos(x), rho * np.sin(x)


def annual_components(
    times: pd.DatetimeIndex, amplitude: float, t_min: float
) -> tuple[np.ndarray, np.ndarray]:
    """The surface's annual anomaly and its quadrature [K] at ``times``.

    :math:`c(t) = -A\\cos\\omega(t - t_0)` (the surface temperature minus its annual
    mean) and :math:`s(t) = -A\\sin\\omega(t - t_0)` (the same cycle a quarter of a
    year earlier), with ``amplitude`` :math:`A` [K] and ``t_min`` :math:`t_0` [d since
    1970-01-01 UTC] as in :func:`kusuda_achenbach`; :math:`\\omega = 2\\pi/P`.
    """
    arg = 2.0 * np.pi / YEAR_DAYS * (_days(times) - float(t_min))
    return -float(amplitude) * np.cos(arg), -float(amplitude) * np.sin(arg)


def kusuda_achenbach(
    times: pd.DatetimeIndex,
    mean: float,
    amplitude: float,
    t_min: float,
    *,
    depth: float = GROUND_DEPTH,
    diffusivity: float = SOIL_DIFFUSIVITY,
) -> np.ndarray:
    """Soil temperature [°C] at a depth under an annual surface cycle.

    Parameters
    ----------
    times : pandas.DatetimeIndex
        Tz-aware instants.
    mean : float
        Annual mean surface temperature :math:`T_m` [°C].
    amplitude : float
        Amplitude of the annual surface cycle :math:`A` [K] (half the peak-to-peak swing).
    t_min : float
        Instant of the surface minimum :math:`t_0` [d since 1970-01-01 UTC], any year.
    depth : float, default 1.0
        Depth :math:`z` [m].
    diffusivity : float, default 0.5e-6
        Soil thermal diffusivity :math:`\\alpha` [m²/s].

    Returns
    -------
    numpy.ndarray
        :math:`T(z, t)` [°C].

    Notes
    -----
    Kusuda and Achenbach [1]_ (Carslaw and Jaeger [2]_):

    .. math::
        T(z, t) = T_m - A\\,e^{-z/d}\\cos\\left(\\omega (t - t_0) - z/d\\right),
        \\qquad d = \\sqrt{2\\alpha/\\omega},\\quad \\omega = 2\\pi/P

    with :math:`P` = 365.2425 d. The amplitude ratio is :math:`e^{-z/d}` and the lag
    :math:`z/(d\\,\\omega)`; at :math:`z = 0` the surface cycle itself. With the defaults
    :math:`d` = 2.24 m: ratio 0.64, lag 26 d at 1 m; 0.41 and 52 d at 2 m. Expanding
    the cosine, :math:`T = T_m + a(z)\\,c(t) + b(z)\\,s(t)`
    (:func:`depth_factors`, :func:`annual_components`): a model can take :math:`c, s`
    as inputs and estimate the depth.
    """
    damping(depth, diffusivity)  # checks the depth and the diffusivity
    a, b = depth_factors(depth, diffusivity)
    c, s = annual_components(times, amplitude, t_min)
    return mean + a * c + b * s


def fit_annual_cycle(te: pd.Series) -> dict:
    """The annual cycle of the air temperature: a sinusoid fitted to its daily means.

    Parameters
    ----------
    te : pandas.Series
        Air temperature [°C], tz-aware index (NaN allowed); any record spanning at least
        180 days (9 months of a logger, a typical year, many years).

    Returns
    -------
    dict
        ``mean`` [°C], ``amplitude`` [K], ``t_min`` [d since 1970-01-01 UTC, the
        minimum nearest the record's middle], ``coldest_day`` (its day of the year),
        ``days`` (daily means used), ``rmse`` [K] of the daily means about the fit.

    Raises
    ------
    heritage_bayes.errors.DataError
        Daily means spanning less than 180 days.

    Notes
    -----
    Least squares of :math:`T_m + a\\cos\\omega t + b\\sin\\omega t` on the UTC days'
    means (days with at least half of the typical number of readings),
    :math:`\\omega = 2\\pi/365.2425` d⁻¹; :math:`A = \\sqrt{a^2 + b^2}`. On a record
    shorter than a year the mean and the amplitude rest on the part of the cycle seen;
    from 9 months on they are well separated.
    """
    s = pd.Series(np.asarray(te, dtype=float), index=te.index).dropna()
    if s.empty:
        raise DataError("the air temperature has no values: no annual cycle to fit")
    daily = s.resample("1D").agg(["mean", "count"])
    daily = daily[daily["count"] >= 0.5 * float(daily["count"].median())]
    t = _days(daily.index) + 0.5
    span = float(t[-1] - t[0]) if len(t) else 0.0
    if span < MIN_SPAN_DAYS:
        raise DataError(
            f"the air temperature's daily means span {span:.0f} days; the annual cycle "
            f"needs at least {MIN_SPAN_DAYS:.0f}"
        )
    omega = 2.0 * np.pi / YEAR_DAYS
    x = np.column_stack([np.ones_like(t), np.cos(omega * t), np.sin(omega * t)])
    y = daily["mean"].to_numpy()
    (m, a, b), *_ = np.linalg.lstsq(x, y, rcond=None)
    amplitude = float(np.hypot(a, b))
    # a cos(wt) + b sin(wt) = A cos(w(t - t_max)); the minimum half a period later
    t_max = np.arctan2(b, a) / omega
    t_min = t_max + YEAR_DAYS / 2
    middle = 0.5 * (t[0] + t[-1])
    t_min += YEAR_DAYS * np.round((middle - t_min) / YEAR_DAYS)
    resid = y - x @ np.array([m, a, b])
    coldest = pd.Timestamp(round(float(t_min) * _DAY_NS), tz="UTC")
    return {
        "mean": float(m),
        "amplitude": amplitude,
        "t_min": float(t_min),
        "coldest_day": int(coldest.day_of_year),
        "days": len(y),
        "rmse": float(np.sqrt(np.mean(resid**2))),
    }
