"""Climate specifications: ASHRAE museum climate classes and the EN 15757 RH band.

:func:`ashrae_classes` (share of hours within each class's short-term and seasonal
limits, :data:`ASHRAE_CLASSES`, :class:`ClimateClass`, result :class:`AshraeResult`) and
:func:`en15757_band` (the seasonal target band of EN 15757 and the hours outside it,
result :class:`EN15757Band`). Both need at least a year of hourly data. Where the
compliance algorithm or a limit was not read in a primary source, the function says so
and the choice is a parameter.
"""

from __future__ import annotations

import math
import numbers
from dataclasses import dataclass

import numpy as np
import pandas as pd

from heritage_bayes.climate.risk._inputs import (
    EDGES,
    MIN_YEAR_HOURS,
    centred_mean,
    check_choice,
    check_positive,
    hourly,
    share_percent,
)
from heritage_bayes.errors import InputError

_INF = math.inf


@dataclass(frozen=True)
class ClimateClass:
    """Limits of one ASHRAE museum climate class.

    Attributes
    ----------
    name : str
        Class label.
    RH_short : float or None
        Short-term fluctuation allowed around the (seasonally adjusted) set point, ±.
        None: no set-point control of RH in this class. [%RH]
    T_short : float or None
        Same for temperature, ±. [K]
    RH_season : (float, float)
        Seasonal adjustment of the RH set point allowed (down, up) from the annual mean;
        (0, 0) means none. [%RH]
    T_season : (float, float)
        Seasonal adjustment of the temperature set point (down, up); ``math.inf`` for
        no limit. [K]
    T_season_max : float
        Cap on the seasonally adjusted temperature set point. [°C]
    RH_range : (float, float)
        Absolute bounds every hourly RH must respect (inclusive). [%]
    T_max : float
        Absolute upper bound on every hourly temperature. [°C]
    """

    name: str
    RH_short: float | None = None
    T_short: float | None = None
    RH_season: tuple[float, float] = (0.0, 0.0)
    T_season: tuple[float, float] = (0.0, 0.0)
    T_season_max: float = _INF
    RH_range: tuple[float, float] = (-_INF, _INF)
    T_max: float = _INF


#: ASHRAE Handbook — HVAC Applications, museums chapter: classes AA, As, A, B, C, D, as
#: collected in the project's reference notes (table **not verified** against the
#: Handbook). "A" is the Ad variant (larger short-term RH, no seasonal RH change).
ASHRAE_CLASSES: tuple[ClimateClass, ...] = (
    ClimateClass("AA", RH_short=5.0, T_short=2.0, RH_season=(0.0, 0.0), T_season=(5.0, 5.0)),
    ClimateClass("As", RH_short=5.0, T_short=2.0, RH_season=(10.0, 10.0), T_season=(10.0, 5.0)),
    ClimateClass("A", RH_short=10.0, T_short=2.0, RH_season=(0.0, 0.0), T_season=(10.0, 5.0)),
    ClimateClass(
        "B",
        RH_short=10.0,
        T_short=5.0,
        RH_season=(10.0, 10.0),
        T_season=(_INF, 10.0),
        T_season_max=30.0,
    ),
    ClimateClass("C", RH_range=(25.0, 75.0), T_max=30.0),
    ClimateClass("D", RH_range=(-_INF, 75.0)),
)

_EPS = 1e-9  # tolerance on limits (round-off of the moving averages)


class _Var:
    """One variable of the ASHRAE check: values, seasonal component, set point; the
    deviations shared by all classes are computed once."""

    def __init__(self, x, s, m):
        self.x, self.s, self.m = x, s, m[:, None]
        self._dev_m = self._dev_s = self._ds = None

    @property
    def dev_m(self):  # |x - m|
        if self._dev_m is None:
            self._dev_m = np.abs(self.x - self.m)
        return self._dev_m

    @property
    def dev_s(self):  # |x - s|
        if self._dev_s is None:
            self._dev_s = np.abs(self.x - self.s)
        return self._dev_s

    @property
    def ds(self):  # s - m
        if self._ds is None:
            self._ds = self.s - self.m
        return self._ds


def _setpoint_ok(v: _Var, short, season, season_max, method):
    """Hours where the variable stays within ``short`` of its (seasonal) set point."""
    if short is None:
        return np.ones(v.x.shape, dtype=bool)
    down, up = season
    if method == "decomposition":
        if down == 0.0 and up == 0.0:
            return v.dev_m <= short + _EPS
        ok = v.dev_s <= short + _EPS
        if math.isfinite(down):
            ok &= v.ds >= -down - _EPS
        if math.isfinite(up):
            ok &= v.ds <= up + _EPS
        if math.isfinite(season_max):
            ok &= v.s <= season_max + _EPS
        return ok
    sp = v.m + np.clip(v.ds, -down, up)
    if math.isfinite(season_max):
        sp = np.minimum(sp, season_max)
    return np.abs(v.x - sp) <= short + _EPS


@dataclass
class AshraeResult:
    """Compliance with the ASHRAE museum climate classes.

    Attributes
    ----------
    share : pandas.Series or pandas.DataFrame
        Percentage of hours meeting both the T and the RH limits of each class (a Series
        indexed by class; for 2-D input a DataFrame draws × classes). [%]
    share_T, share_RH : pandas.Series or pandas.DataFrame
        The same for the temperature and the RH limits separately. [%]
    best : str, None or numpy.ndarray
        First class in order (AA, As, A, B, C, D) whose share reaches ``threshold``
        (None if none does; an object array per draw for 2-D input).
    threshold : float
        Share of hours required to achieve a class. [%]
    method : str
        Compliance algorithm used.
    T_setpoint, RH_setpoint : float or numpy.ndarray
        Set points used (annual means unless given). [°C], [%]
    """

    share: pd.Series | pd.DataFrame
    share_T: pd.Series | pd.DataFrame
    share_RH: pd.Series | pd.DataFrame
    best: str | np.ndarray | None
    threshold: float
    method: str
    T_setpoint: float | np.ndarray
    RH_setpoint: float | np.ndarray


def _mean(x, nan_policy):
    """Mean along the last axis (``omit``: of the finite values; NaN if there are none)."""
    if nan_policy != "omit":
        return x.mean(axis=-1)
    valid = np.isfinite(x)
    n = valid.sum(axis=-1)
    with np.errstate(invalid="ignore", divide="ignore"):
        return np.where(n > 0, np.where(valid, x, 0.0).sum(axis=-1) / n, np.nan)


def _window_half(func, window_days, n):
    w = check_positive(func, "window_days", window_days)
    half = round(w * 24.0 / 2.0)
    if half < 1 or 2 * half + 1 > n:
        raise InputError(
            f"{func}: window_days={window_days!r} gives a {2 * half + 1} h window; "
            f"expected between 3 h and the series length ({n} h)"
        )
    return half


def _ashrae_check(func, method, threshold, classes, edges, T_setpoint, RH_setpoint):
    check_choice(func, "method", method, ("decomposition", "setpoint"))
    check_choice(func, "edges", edges, EDGES)
    try:
        thr = float(threshold)
    except (TypeError, ValueError):
        thr = math.nan
    if not 0.0 < thr <= 100.0:
        raise InputError(f"{func}: threshold must be a percentage in (0, 100]; got {threshold!r}")
    classes = tuple(classes)
    if not classes or not all(isinstance(c, ClimateClass) for c in classes):
        raise InputError(
            f"{func}: classes must be a non-empty sequence of ClimateClass; got {classes!r}"
        )
    names = [c.name for c in classes]
    if len(set(names)) != len(names):
        raise InputError(f"{func}: class names must be unique; got {names}")
    for label, sp in (("T_setpoint", T_setpoint), ("RH_setpoint", RH_setpoint)):
        real = isinstance(sp, numbers.Real) and not isinstance(sp, bool)
        if sp is not None and not (real and math.isfinite(sp)):
            raise InputError(f"{func}: {label} must be None (annual mean) or a number; got {sp!r}")
    return thr, classes


def _ashrae_core(h, *, window_days, T_setpoint, RH_setpoint, method, threshold, classes,
                 nested, edges, nan_policy, sRH=None):  # fmt: skip
    T, RH = h.T, h.RH
    half = _window_half("ashrae_classes", window_days, h.n_hours)
    sT = centred_mean(T, half, edges, nan_policy)
    if sRH is None:
        sRH = centred_mean(RH, half, edges, nan_policy)
    valid = np.isfinite(T) & np.isfinite(RH)
    d = T.shape[0]
    mT = np.full(d, float(T_setpoint)) if T_setpoint is not None else _mean(T, nan_policy)
    mRH = np.full(d, float(RH_setpoint)) if RH_setpoint is not None else _mean(RH, nan_policy)
    vT, vRH = _Var(T, sT, mT), _Var(RH, sRH, mRH)
    k = len(classes)
    sh, shT, shRH = np.empty((d, k)), np.empty((d, k)), np.empty((d, k))
    below_T = below_RH = None  # compliance with every class after the current one
    # from the most lenient class up, so that nesting can accumulate
    for j in range(k - 1, -1, -1):
        c = classes[j]
        okT = _setpoint_ok(vT, c.T_short, c.T_season, c.T_season_max, method)
        if math.isfinite(c.T_max):
            okT &= T <= c.T_max + _EPS
        okRH = _setpoint_ok(vRH, c.RH_short, c.RH_season, _INF, method)
        lo, hi = c.RH_range
        if math.isfinite(lo):
            okRH &= RH >= lo - _EPS
        if math.isfinite(hi):
            okRH &= RH <= hi + _EPS
        if nested:
            if below_T is not None:
                okT &= below_T
                okRH &= below_RH
            below_T, below_RH = okT, okRH
        shT[:, j] = share_percent(okT, valid, nan_policy)
        shRH[:, j] = share_percent(okRH, valid, nan_policy)
        sh[:, j] = share_percent(okT & okRH, valid, nan_policy)
    best = np.full(d, None, dtype=object)
    for i in range(d):
        for j, c in enumerate(classes):
            if sh[i, j] >= threshold - _EPS:
                best[i] = c.name
                break
    return sh, shT, shRH, best, mT, mRH


def ashrae_classes(
    T,
    RH,
    *,
    window_days=30,
    T_setpoint=None,
    RH_setpoint=None,
    method="decomposition",
    threshold=95.0,
    classes=ASHRAE_CLASSES,
    nested=True,
    edges="shrink",
    nan_policy="propagate",
):
    r"""Share of hours meeting each ASHRAE museum climate class, and the best class.

    Parameters
    ----------
    T : array_like or pandas.Series
        Hourly air temperature, shape (hours,) or (draws, hours), at least a year. [°C]
    RH : array_like or pandas.Series
        Hourly relative humidity, same shape. [%]
    window_days : float, default 30
        Length of the centred moving average that defines the seasonal component. [days]
    T_setpoint : float or None, default None
        Temperature set point; None uses the mean of the series (the "historical annual
        mean"). ASHRAE asks for a set point between 15 and 25 °C: pass one to apply
        that (an unheated monument's annual mean is often below 15 °C). [°C]
    RH_setpoint : float or None, default None
        RH set point; None uses the mean of the series. [%]
    method : {"decomposition", "setpoint"}, default "decomposition"
        Compliance algorithm, see Notes.
    threshold : float, default 95.0
        Share of hours a class must meet to count as achieved (ASHRAE gives none). [%]
    classes : sequence of ClimateClass, default ASHRAE_CLASSES
        Class definitions, best first.
    nested : bool, default True
        An hour meets a class only if it also meets every later (more lenient) class:
        a room at 80 %RH is not class B even when it is stable, because it fails D
        ("reliably below 75 %"). False checks each class on its own limits.
    edges : {"shrink", "wrap"}, default "shrink"
        Moving average near the ends of the series: truncated window, or the series
        treated as periodic (sensible for exactly one typical year).
    nan_policy : {"propagate", "omit", "raise"}, default "propagate"
        Missing hours: NaN shares, skipped (shares of the valid hours), or an error.

    Returns
    -------
    AshraeResult
        Shares of hours per class (both, T only, RH only) [%], the best class, the set
        points [°C], [%].

    Notes
    -----
    **The class table and the compliance algorithm are not verified against the
    Handbook** [1]_ (ASHRAE gives no compliance algorithm): both follow the project's
    reference notes; [2]_ discusses the classes, [3]_ their use on measured data.
    Set point :math:`m` = annual mean; seasonal component :math:`s_t` = centred moving
    average over ``window_days`` (2·12·window_days + 1 h). Limits (short-term;
    seasonal adjustment of the set point), see :data:`ASHRAE_CLASSES`:

    * AA: ±5 %RH, ±2 K; RH no seasonal change, T ±5 K.
    * As: ±5 %RH, ±2 K; RH ±10 %, T +5/−10 K.
    * A (the "Ad" variant): ±10 %RH, ±2 K; RH no seasonal change, T +5/−10 K.
    * B: ±10 %RH, ±5 K; RH ±10 %, T +10 K (no lower limit) and at most 30 °C.
    * C: every hour RH within 25–75 % and T ≤ 30 °C.
    * D: every hour RH ≤ 75 %.

    ``"decomposition"`` (the documented algorithm): an hour complies with a variable
    when :math:`s_t - m` is within the seasonal limits and :math:`|x_t - s_t|` within the
    short-term limit; with no seasonal adjustment ("none"), when :math:`|x_t - m|` is
    within the short-term limit. ``"setpoint"``: the set point follows the seasonal
    component clipped to the seasonal limits,
    :math:`sp_t = m + \mathrm{clip}(s_t - m, -down, up)`, and an hour complies when
    :math:`|x_t - sp_t|` is within the short-term limit (more lenient when the season
    overshoots). With ``nested`` (default) an hour must also meet the limits of every
    later class. The share is the percentage of (valid) hours meeting both T and RH.
    The best class is the first of AA, As, A, B, C, D reaching ``threshold``.

    References
    ----------
    .. [1] ASHRAE, "ASHRAE Handbook — HVAC Applications", chapter "Museums, Galleries,
       Archives, and Libraries", ASHRAE, Atlanta (2019). (No DOI.)
    .. [2] S. Michalski, "ASHRAE types of control", Canadian Conservation Institute,
       https://www.canada.ca/en/conservation-institute/services/preventive-conservation/
       climate-guidelines/ashrae-types-control.html
    .. [3] M. H. J. Martens, "Climate risk assessment in museums: degradation risks
       determined from temperature and relative humidity data", PhD thesis, Eindhoven
       University of Technology (2012). (No DOI.)
    """
    func = "ashrae_classes"
    thr, classes = _ashrae_check(func, method, threshold, classes, edges, T_setpoint, RH_setpoint)
    h = hourly(
        func,
        T=T,
        RH=RH,
        nan_policy=nan_policy,
        min_hours=MIN_YEAR_HOURS,
        what="the ASHRAE classes",
    )
    sh, shT, shRH, best, mT, mRH = _ashrae_core(
        h,
        window_days=window_days,
        T_setpoint=T_setpoint,
        RH_setpoint=RH_setpoint,
        method=method,
        threshold=thr,
        classes=classes,
        nested=bool(nested),
        edges=edges,
        nan_policy=nan_policy,
    )
    names = [c.name for c in classes]

    def table(a):
        if h.ndim == 1:
            return pd.Series(a[0], index=pd.Index(names, name="class"), name="share")
        return pd.DataFrame(a, columns=pd.Index(names, name="class"))

    return AshraeResult(
        share=table(sh),
        share_T=table(shT),
        share_RH=table(shRH),
        best=best[0] if h.ndim == 1 else best,
        threshold=thr,
        method=method,
        T_setpoint=h.reduce(mT),
        RH_setpoint=h.reduce(mRH),
    )


# --------------------------------------------------------------------------------------
# EN 15757
# --------------------------------------------------------------------------------------


@dataclass
class EN15757Band:
    """EN 15757 target band for RH, and the hours outside it.

    Attributes
    ----------
    seasonal, lower, upper : numpy.ndarray or pandas.Series
        Seasonal cycle (centred moving average) and the band limits, hour by hour
        (Series for Series input; (draws, hours) for 2-D input). [%]
    outside : numpy.ndarray or pandas.Series
        True for the (valid) hours outside the band.
    lower_offset, upper_offset : float or numpy.ndarray
        Band limits relative to the seasonal cycle, after the minimum band. [%RH]
    p_low, p_high : float or numpy.ndarray
        The fluctuation percentiles before the minimum band was applied. [%RH]
    share_outside : float or numpy.ndarray
        Percentage of valid hours outside the band. [%]
    """

    seasonal: np.ndarray | pd.Series
    lower: np.ndarray | pd.Series
    upper: np.ndarray | pd.Series
    outside: np.ndarray | pd.Series
    lower_offset: float | np.ndarray
    upper_offset: float | np.ndarray
    p_low: float | np.ndarray
    p_high: float | np.ndarray
    share_outside: float | np.ndarray


def _en_check(func, percentiles, min_band, min_band_mode, edges):
    check_choice(func, "min_band_mode", min_band_mode, ("half", "width"))
    check_choice(func, "edges", edges, EDGES)
    try:
        lo, hi = (float(p) for p in percentiles)
    except (TypeError, ValueError):
        raise InputError(
            f"{func}: percentiles must be two numbers (low, high); got {percentiles!r}"
        ) from None
    if not 0.0 <= lo < hi <= 100.0:
        raise InputError(
            f"{func}: percentiles must satisfy 0 <= low < high <= 100; got {percentiles!r}"
        )
    try:
        mb = float(min_band)
    except (TypeError, ValueError):
        mb = math.nan
    if not (math.isfinite(mb) and mb >= 0.0):
        raise InputError(f"{func}: min_band must be a number >= 0 [%RH]; got {min_band!r}")
    return (lo, hi), mb


def _en_core(RH, *, window_days, percentiles, min_band, min_band_mode, edges, nan_policy,
             seasonal=None):  # fmt: skip
    half = _window_half("en15757_band", window_days, RH.shape[-1])
    if seasonal is None:
        seasonal = centred_mean(RH, half, edges, nan_policy)
    f = RH - seasonal
    if nan_policy == "omit" and np.isnan(f).any():
        p = np.nanpercentile(f, percentiles, axis=-1)
    else:
        p = np.percentile(f, percentiles, axis=-1)
    p_lo, p_hi = p[0], p[1]
    if min_band_mode == "half":
        lo, hi = np.minimum(p_lo, -min_band), np.maximum(p_hi, min_band)
    else:
        mid = 0.5 * (p_lo + p_hi)
        narrow = (p_hi - p_lo) < min_band
        lo = np.where(narrow, mid - 0.5 * min_band, p_lo)
        hi = np.where(narrow, mid + 0.5 * min_band, p_hi)
    valid = np.isfinite(RH)
    lower = seasonal + lo[:, None]
    upper = seasonal + hi[:, None]
    with np.errstate(invalid="ignore"):
        outside = valid & ((RH < lower) | (RH > upper))
    share = share_percent(outside, valid, nan_policy)
    return seasonal, lower, upper, outside, lo, hi, p_lo, p_hi, share


def en15757_band(
    RH,
    *,
    window_days=30,
    percentiles=(7.0, 93.0),
    min_band=10.0,
    min_band_mode="half",
    edges="shrink",
    nan_policy="propagate",
):
    r"""EN 15757 seasonal RH band and the share of hours outside it.

    Parameters
    ----------
    RH : array_like or pandas.Series
        Hourly relative humidity, shape (hours,) or (draws, hours), at least a year. [%]
    window_days : float, default 30
        Length of the centred moving average defining the seasonal cycle. [days]
    percentiles : (float, float), default (7, 93)
        Percentiles of the short-term fluctuations that bound the band. [%]
    min_band : float, default 10.0
        Minimum band, see ``min_band_mode``. [%RH]
    min_band_mode : {"half", "width"}, default "half"
        ``"half"``: the band covers at least seasonal ± ``min_band`` (the documented
        reading, ±10 %RH); ``"width"``: the band is at least ``min_band`` wide in total,
        widened symmetrically about the middle of the percentile band when narrower.
    edges : {"shrink", "wrap"}, default "shrink"
        Moving average near the ends: truncated window, or periodic series.
    nan_policy : {"propagate", "omit", "raise"}, default "propagate"
        Missing hours: NaN band and share, skipped, or an error.

    Returns
    -------
    EN15757Band
        The seasonal cycle and band as series for plotting [%], the offsets [%RH], and
        the share of hours outside the band [%].

    Notes
    -----
    From the historical climate (≥ 1 year of hourly RH) [1]_: seasonal cycle
    :math:`s_t` = centred moving average over 30 days (here 721 h); fluctuations
    :math:`f_t = RH_t - s_t`; band :math:`[s_t + P_7(f), s_t + P_{93}(f)]`, widened to
    at least the minimum band. **The minimum band is not verified against the standard**
    (±10 %RH around the seasonal cycle, or a band 10 %RH wide in total): the choice is
    ``min_band_mode``. On the series the band was derived from, the share outside is
    at most about 14 % by construction (less when the minimum band is active). The
    treatment of the first and last 15 days is not specified in the notes either
    (``edges``). Camuffo et al. [2]_ discuss these ambiguities.

    References
    ----------
    .. [1] CEN, "EN 15757:2010 Conservation of Cultural Property — Specifications for
       temperature and relative humidity to limit climate-induced mechanical damage in
       organic hygroscopic materials", Brussels (2010). (No DOI.)
    .. [2] D. Camuffo, A. della Valle and F. Becherini, "The European Standard EN 15757
       concerning specifications for relative humidity: suggested improvements for its
       revision", Atmosphere 13 (2022) 1344. doi:10.3390/atmos13091344
    """
    func = "en15757_band"
    pct, mb = _en_check(func, percentiles, min_band, min_band_mode, edges)
    h = hourly(func, RH=RH, nan_policy=nan_policy, min_hours=MIN_YEAR_HOURS, what="EN 15757")
    seasonal, lower, upper, outside, lo, hi, p_lo, p_hi, share = _en_core(
        h.RH,
        window_days=window_days,
        percentiles=pct,
        min_band=mb,
        min_band_mode=min_band_mode,
        edges=edges,
        nan_policy=nan_policy,
    )
    if h.ndim == 1 and h.index is not None:
        out_mask = pd.Series(outside[0], index=h.index, name="outside")
    else:
        out_mask = outside if h.ndim == 2 else outside[0]
    return EN15757Band(
        seasonal=h.series(seasonal, "seasonal"),
        lower=h.series(lower, "lower"),
        upper=h.series(upper, "upper"),
        outside=out_mask,
        lower_offset=h.reduce(lo),
        upper_offset=h.reduce(hi),
        p_low=h.reduce(p_lo),
        p_high=h.reduce(p_hi),
        share_outside=h.reduce(share),
    )
