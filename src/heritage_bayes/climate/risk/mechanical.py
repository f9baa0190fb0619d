"""Mechanical damage: equilibrium moisture content of wood and its swings.

:func:`emc_wood` (Hailwood–Horrobin sorption isotherm, Simpson's fit; pointwise),
:func:`emc_range` (lowest and highest EMC of a series) and :func:`dimensional_change`
(a proxy for the free swelling/shrinkage across that range). Temperature in [°C], RH in
[%]; conventions in :mod:`heritage_bayes.climate.risk`.
"""

from __future__ import annotations

from typing import NamedTuple

import numpy as np

from heritage_bayes.climate.risk._inputs import (
    check_positive,
    hourly,
    pointwise,
)


def _emc(T, RH):
    h = RH / 100.0
    W = 349.0 + 1.29 * T + 0.0135 * T * T
    K = 0.805 + 7.36e-4 * T - 2.73e-6 * T * T
    K1 = 6.27 - 9.38e-3 * T - 3.03e-4 * T * T
    K2 = 1.91 + 0.0407 * T - 2.93e-4 * T * T
    Kh = K * h
    KKh = K1 * Kh
    KKKh2 = K1 * K2 * Kh * Kh
    return (1800.0 / W) * (Kh / (1.0 - Kh) + (KKh + 2.0 * KKKh2) / (1.0 + KKh + KKKh2))


def emc_wood(T, RH):
    r"""Equilibrium moisture content of wood (Hailwood–Horrobin, Simpson's fit).

    Parameters
    ----------
    T : numeric
        Air temperature. [°C]
    RH : numeric
        Relative humidity. [%]

    Returns
    -------
    float, numpy.ndarray or pandas.Series
        Equilibrium moisture content, mass of water per oven-dry mass of wood. [% MC]

    Notes
    -----
    The one-hydrate Hailwood–Horrobin sorption model [1]_ with Simpson's temperature
    dependence [2]_, as given in the FPL Wood Handbook [3]_; :math:`h` = RH/100, T in °C:

    .. math::
        W = 349 + 1.29T + 0.0135T^2, \quad
        K = 0.805 + 7.36\cdot10^{-4}T - 2.73\cdot10^{-6}T^2,

        K_1 = 6.27 - 9.38\cdot10^{-3}T - 3.03\cdot10^{-4}T^2, \quad
        K_2 = 1.91 + 0.0407T - 2.93\cdot10^{-4}T^2,

        EMC = \frac{1800}{W}\left[\frac{Kh}{1-Kh}
              + \frac{K_1Kh + 2K_1K_2K^2h^2}{1 + K_1Kh + K_1K_2K^2h^2}\right].

    ≈ 9.3 % at 20 °C / 50 %. The fit covers desorption of Sitka spruce-like wood above
    0 °C; below 0 °C the formula is extrapolated. IPI-style ratings used by
    :func:`assess`: mechanical damage *OK* when 5 ≤ EMC ≤ 12.5 %, metal corrosion *good*
    below 7 %, *OK* 7–10.5 %, *risk* from 10.5 % (on the maximum EMC).

    References
    ----------
    .. [1] A. J. Hailwood and S. Horrobin, "Absorption of water by polymers: analysis in
       terms of a simple model", Trans. Faraday Soc. 42B (1946) 84-92.
       doi:10.1039/TF946420B084
    .. [2] W. T. Simpson, "Predicting equilibrium moisture content of wood by mathematical
       models", Wood and Fiber 5(1) (1973) 41-49. (No DOI.)
    .. [3] Forest Products Laboratory, "Wood Handbook: Wood as an Engineering Material",
       General Technical Report FPL-GTR-190, USDA Forest Service, Madison WI (2010),
       chapter 4 (EMC) and chapter 13, Table 13-5 (dimensional change coefficients).
       doi:10.2737/FPL-GTR-190
    """
    (T, RH), wrap = pointwise("emc_wood", T=T, RH=RH)
    return wrap(_emc(T, RH), "EMC")


class EMCRange(NamedTuple):
    """Extremes of the equilibrium moisture content over the period [% MC]."""

    min: float | np.ndarray
    max: float | np.ndarray
    range: float | np.ndarray


def _minmax(x, nan_policy):
    if nan_policy == "omit":
        return np.fmin.reduce(x, axis=-1), np.fmax.reduce(x, axis=-1)
    return x.min(axis=-1), x.max(axis=-1)


def emc_range(T, RH, *, nan_policy="propagate"):
    r"""Minimum, maximum and range of the wood EMC over the period.

    Parameters
    ----------
    T : array_like or pandas.Series
        Hourly air temperature, shape (hours,) or (draws, hours). [°C]
    RH : array_like or pandas.Series
        Hourly relative humidity, same shape. [%]
    nan_policy : {"propagate", "omit", "raise"}, default "propagate"
        Missing hours: NaN result, skipped, or an error.

    Returns
    -------
    EMCRange
        ``(min, max, range)``, each a float (or one value per draw). [% MC]

    Notes
    -----
    Hourly EMC from :func:`emc_wood`; :math:`\Delta EMC = \max EMC - \min EMC`. The EMC
    follows RH instantly here: real objects respond with a lag (hours to months with
    thickness and coating), so this is an upper bound of the moisture swing.

    References
    ----------
    .. [1] A. J. Hailwood and S. Horrobin, "Absorption of water by polymers: analysis in
       terms of a simple model", Trans. Faraday Soc. 42B (1946) 84-92.
       doi:10.1039/TF946420B084
    .. [2] W. T. Simpson, "Predicting equilibrium moisture content of wood by mathematical
       models", Wood and Fiber 5(1) (1973) 41-49. (No DOI.)
    .. [3] Forest Products Laboratory, "Wood Handbook: Wood as an Engineering Material",
       General Technical Report FPL-GTR-190, USDA Forest Service, Madison WI (2010),
       chapter 4 (EMC) and chapter 13, Table 13-5 (dimensional change coefficients).
       doi:10.2737/FPL-GTR-190
    """
    h = hourly("emc_range", T=T, RH=RH, nan_policy=nan_policy)
    lo, hi = _minmax(_emc(h.T, h.RH), nan_policy)
    return EMCRange(h.reduce(lo), h.reduce(hi), h.reduce(hi - lo))


def dimensional_change(T, RH, *, coefficient=0.00369, nan_policy="propagate"):
    r"""Dimensional-change proxy: swelling/shrinkage over the EMC range of the period.

    Parameters
    ----------
    T : array_like or pandas.Series
        Hourly air temperature, shape (hours,) or (draws, hours). [°C]
    RH : array_like or pandas.Series
        Hourly relative humidity, same shape. [%]
    coefficient : float, default 0.00369
        Dimensional change coefficient: fractional change of dimension per percentage
        point of moisture content. The default is the tangential coefficient of
        commercial red oak in the Wood Handbook, Table 13-5 [3]_ (radial: 0.00158;
        other species 0.001–0.0045). [1/% MC]
    nan_policy : {"propagate", "omit", "raise"}, default "propagate"
        Missing hours: NaN result, skipped, or an error.

    Returns
    -------
    float or numpy.ndarray
        Unrestrained dimensional change between the driest and the wettest state of the
        period, as a percentage of the dimension. [%]

    Notes
    -----
    Wood Handbook linear shrinkage model [3]_, valid for MC between about 6 and 14 %:

    .. math:: \frac{\Delta D}{D} = 100\,C\,(\max EMC - \min EMC)

    A proxy for the mechanical risk from RH swings, not a damage criterion: it ignores
    the response time of the object and restraint. EMC from :func:`emc_wood`.

    References
    ----------
    .. [1] A. J. Hailwood and S. Horrobin, "Absorption of water by polymers: analysis in
       terms of a simple model", Trans. Faraday Soc. 42B (1946) 84-92.
       doi:10.1039/TF946420B084
    .. [2] W. T. Simpson, "Predicting equilibrium moisture content of wood by mathematical
       models", Wood and Fiber 5(1) (1973) 41-49. (No DOI.)
    .. [3] Forest Products Laboratory, "Wood Handbook: Wood as an Engineering Material",
       General Technical Report FPL-GTR-190, USDA Forest Service, Madison WI (2010),
       chapter 4 (EMC) and chapter 13, Table 13-5 (dimensional change coefficients).
       doi:10.2737/FPL-GTR-190
    """
    c = check_positive("dimensional_change", "coefficient", coefficient)
    h = hourly("dimensional_change", T=T, RH=RH, nan_policy=nan_policy)
    lo, hi = _minmax(_emc(h.T, h.RH), nan_policy)
    return h.reduce(100.0 * c * (hi - lo))
