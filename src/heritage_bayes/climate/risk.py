r"""Conservation-risk indicators from hourly indoor temperature and relative humidity.

Conservators do not read temperatures; they read risk to the collection. This module turns
an hourly indoor climate (measured, simulated from a posterior draw, or projected) into
the indicators the heritage field uses:

* chemical decay: Michalski's lifetime multiplier (:func:`lifetime_multiplier`, time
  aggregated by :func:`twlm`), the preservation index (:func:`preservation_index`) and
  the time-weighted preservation index (:func:`twpi`);
* mechanical damage: equilibrium moisture content of wood (:func:`emc_wood`), its range
  (:func:`emc_range`) and a dimensional-change proxy (:func:`dimensional_change`);
* biological: the VTT mould index (:func:`vtt_mould_index`) and the hours above the
  lowest isopleth for mould (:func:`lowest_isopleth`, :func:`hours_above_isopleth`);
* climate specifications: ASHRAE museum classes (:func:`ashrae_classes`) and the
  EN 15757 seasonal RH band (:func:`en15757_band`);
* everything at once: :func:`assess` (one series → tidy table) and :func:`assess_batch`
  (draws × hours → one row per draw), summarised by :func:`summarize`.

Conventions
-----------
* Temperature ``T`` in [°C], relative humidity ``RH`` in [%] (0–100; a fraction 0–1 is
  rejected with :class:`~heritage_bayes.errors.InputError`, so is RH above 100 %).
* Pointwise functions (:func:`lifetime_multiplier`, :func:`preservation_index`,
  :func:`emc_wood`, :func:`lowest_isopleth`) accept scalars, arrays of any shape or
  Series, and return the same kind (float, array, Series).
* Series functions take a regular **hourly** series: a 1-D array or Series (hours), or a
  2-D array (draws × hours, hours along the last axis). A Series with a
  :class:`~pandas.DatetimeIndex` must advance by exactly one hour at every step. A 1-D
  input gives a float per indicator; a 2-D input gives one value per draw.
* Yearly indicators (ASHRAE classes, EN 15757, hours above the isopleth per year) need at
  least one year (8760 h).
* ``nan_policy`` (series functions): ``"propagate"`` (default; a NaN anywhere makes the
  aggregate NaN, and the VTT index NaN from the first gap on), ``"omit"`` (skip missing
  hours: aggregates over the valid hours, moving averages over the valid hours of each
  window, the VTT index holds its state across gaps and is NaN in them) or ``"raise"``
  (a NaN in the input raises :class:`~heritage_bayes.errors.InputError`).

Where the formulas or limits were not read in a primary source (ASHRAE compliance
algorithm and table, EN 15757 minimum band), the function says so and the choice is a
parameter.
"""

from __future__ import annotations

import inspect
import math
import numbers
from collections.abc import Mapping
from dataclasses import dataclass
from typing import NamedTuple

import numpy as np
import pandas as pd

from heritage_bayes.climate._risk_inputs import (
    EDGES,
    HOURS_PER_YEAR,
    Hourly,
    centred_mean,
    check_choice,
    check_positive,
    harmonic_mean,
    hourly,
    pointwise,
    share_percent,
)
from heritage_bayes.climate._risk_vtt import SENSITIVITY, vtt_kernel
from heritage_bayes.errors import InputError

__all__ = [
    "ASHRAE_CLASSES",
    "HOURS_PER_YEAR",
    "INDICATOR_GROUPS",
    "AshraeResult",
    "ClimateClass",
    "EMCRange",
    "EN15757Band",
    "ashrae_classes",
    "assess",
    "assess_batch",
    "dimensional_change",
    "emc_range",
    "emc_wood",
    "en15757_band",
    "hours_above_isopleth",
    "lifetime_multiplier",
    "lowest_isopleth",
    "preservation_index",
    "summarize",
    "twlm",
    "twpi",
    "vtt_mould_index",
]

#: Molar gas constant [J/(mol·K)] (CODATA 2018).
R_GAS = 8.314462618
_T0 = 273.15

# Zeng et al. (2023): LIM_u = 100 [0.02633 cosh(0.10083 (T - 30)) + c_u], u in mm/day.
_LIM_CONSTANT = {0.0: 0.7153, 0.1: 0.7300, 0.5: 0.7675, 1.0: 0.7950, 2.0: 0.8250,
                 3.0: 0.8502, 4.0: 0.8701}  # fmt: skip

_SPECIES = {"pine": 0.0, "spruce": 1.0}
_SURFACE = {"resawn": 0.0, "kiln-dried": 1.0}


# --------------------------------------------------------------------------------------
# Chemical decay
# --------------------------------------------------------------------------------------


def _lm(T, RH, Ea, T_ref, RH_ref, n):
    with np.errstate(divide="ignore", over="ignore"):
        return (RH_ref / RH) ** n * np.exp(Ea / R_GAS * (1.0 / (T + _T0) - 1.0 / (T_ref + _T0)))


def _check_lm(func, Ea, T_ref, RH_ref, n):
    check_positive(func, "Ea", Ea)
    check_positive(func, "RH_ref", RH_ref)
    check_positive(func, "n", n)
    try:
        ok = -100.0 <= float(T_ref) <= 100.0
    except (TypeError, ValueError):
        ok = False
    if not ok:
        raise InputError(f"{func}: T_ref must be in °C within -100…100; got {T_ref!r}")


def lifetime_multiplier(T, RH, Ea=100e3, *, T_ref=20.0, RH_ref=50.0, n=1.3):
    r"""Michalski's lifetime multiplier for chemical decay.

    The expected lifetime of a chemically unstable material (paper, film, varnish) at
    (T, RH), relative to its lifetime at the reference climate 20 °C / 50 %.

    Parameters
    ----------
    T : numeric
        Air temperature. [°C]
    RH : numeric
        Relative humidity. [%]
    Ea : float, default 100e3
        Activation energy: 100 kJ/mol for cellulose (paper), 70 kJ/mol for the yellowing
        of varnish. [J/mol]
    T_ref : float, default 20.0
        Reference temperature where LM = 1. [°C]
    RH_ref : float, default 50.0
        Reference relative humidity where LM = 1. [%]
    n : float, default 1.3
        Exponent of the humidity term. [-]

    Returns
    -------
    float, numpy.ndarray or pandas.Series
        Lifetime multiplier (> 1: longer life than at the reference climate). [-]

    Notes
    -----
    Arrhenius for temperature and a power law for humidity [1]_:

    .. math:: LM = \left(\frac{RH_{ref}}{RH}\right)^{n}
              \exp\left[\frac{E_a}{R}\left(\frac{1}{T_K} - \frac{1}{T_{ref,K}}\right)\right]

    with :math:`R` = 8.314 J/(mol·K) and temperatures in kelvin. With the defaults, LM
    ≈ 2.0 at 15 °C / 50 % ("double the life for each five-degree drop") and
    :math:`2^{1.3}` ≈ 2.5 at 20 °C / 25 % ("more than double for each halving of RH").
    The reference temperature is 293.15 K so that LM is exactly 1 at 20 °C / 50 %
    (Michalski writes 293 K). Some open implementations flip the sign of the exponent
    or use 1/3 instead of 1.3. Aggregate over time with :func:`twlm` (harmonic mean),
    not an arithmetic mean.

    References
    ----------
    .. [1] S. Michalski, "Double the life for each five-degree drop, more than double the
       life for each halving of relative humidity", in R. Vontobel (ed.), ICOM-CC 13th
       Triennial Meeting, Rio de Janeiro, Preprints vol. I, James & James, London (2002)
       66-72. (No DOI.)

    Examples
    --------
    >>> round(lifetime_multiplier(15.0, 50.0), 2)
    2.04
    """
    _check_lm("lifetime_multiplier", Ea, T_ref, RH_ref, n)
    (T, RH), wrap = pointwise("lifetime_multiplier", T=T, RH=RH)
    return wrap(_lm(T, RH, float(Ea), float(T_ref), float(RH_ref), float(n)), "LM")


def twlm(T, RH, Ea=100e3, *, T_ref=20.0, RH_ref=50.0, n=1.3, nan_policy="propagate"):
    r"""Time-weighted lifetime multiplier: the harmonic mean of the hourly LM.

    Parameters
    ----------
    T : array_like or pandas.Series
        Hourly air temperature, shape (hours,) or (draws, hours). [°C]
    RH : array_like or pandas.Series
        Hourly relative humidity, same shape. [%]
    Ea : float, default 100e3
        Activation energy (100 kJ/mol paper, 70 kJ/mol varnish). [J/mol]
    T_ref, RH_ref, n : float
        Reference climate [°C], [%] and humidity exponent [-]; see
        :func:`lifetime_multiplier`.
    nan_policy : {"propagate", "omit", "raise"}, default "propagate"
        Missing hours: NaN result, skipped, or an error.

    Returns
    -------
    float or numpy.ndarray
        Time-weighted lifetime multiplier (one value per draw for 2-D input). [-]

    Notes
    -----
    Decay rates add up over time, lifetimes do not: the rate is proportional to
    :math:`1/LM`, so the equivalent constant climate has

    .. math:: LM_{tw} = \frac{N}{\sum_{i=1}^{N} 1/LM_i}

    the same aggregation as the TWPI of the Image Permanence Institute [2]_.

    References
    ----------
    .. [1] S. Michalski (2002), see :func:`lifetime_multiplier`.
    .. [2] J. M. Reilly, D. W. Nishimura and E. Zinn, "New Tools for Preservation:
       Assessing Long-Term Environmental Effects on Library and Archives Collections",
       Commission on Preservation and Access, Washington DC (1995). (No DOI.)
    """
    func = "twlm"
    _check_lm(func, Ea, T_ref, RH_ref, n)
    h = hourly(func, T=T, RH=RH, nan_policy=nan_policy)
    lm = _lm(h.T, h.RH, float(Ea), float(T_ref), float(RH_ref), float(n))
    return h.reduce(harmonic_mean(lm, nan_policy))


def _pi(T, RH):
    return np.exp((95220.0 - 134.9 * RH) / (8.314 * (T + _T0)) + 0.0284 * RH - 28.023) / 365.0


def preservation_index(T, RH):
    r"""Preservation index: expected lifetime of cellulose-based materials at (T, RH).

    Parameters
    ----------
    T : numeric
        Air temperature. [°C]
    RH : numeric
        Relative humidity. [%]

    Returns
    -------
    float, numpy.ndarray or pandas.Series
        Preservation index PI. [years]

    Notes
    -----
    The isoperm concept of Sebera [1]_ as tabulated by the Image Permanence Institute
    (IPI) [2]_, in the closed form attributed to Padfield (form taken from the project's
    reference notes, not from a primary source; it reproduces IPI's table within ≈7 %):

    .. math:: PI = \frac{1}{365}\exp\left(\frac{95220 - 134.9\,RH}{8.314\,T_K}
              + 0.0284\,RH - 28.023\right)

    with RH in % and :math:`T_K` in kelvin. Check values: ≈51 years at 20 °C / 45 %,
    ≈26 years at 20 °C / 70 %. A fit to IPI's table, meant for roughly 0–35 °C and
    20–80 %RH; outside that it is an extrapolation. Aggregate over time with :func:`twpi`.

    References
    ----------
    .. [1] D. K. Sebera, "Isoperms: An Environmental Management Tool", Commission on
       Preservation and Access, Washington DC (1994). (No DOI.)
    .. [2] J. M. Reilly, D. W. Nishimura and E. Zinn, "New Tools for Preservation:
       Assessing Long-Term Environmental Effects on Library and Archives Collections",
       Commission on Preservation and Access, Washington DC (1995). (No DOI.)

    Examples
    --------
    >>> round(preservation_index(20.0, 45.0))
    51
    """
    (T, RH), wrap = pointwise("preservation_index", T=T, RH=RH)
    return wrap(_pi(T, RH), "PI")


def twpi(T, RH, *, nan_policy="propagate"):
    r"""Time-weighted preservation index (IPI): the harmonic mean of the hourly PI.

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
    float or numpy.ndarray
        TWPI (one value per draw for 2-D input). [years]

    Notes
    -----
    .. math:: TWPI = \frac{N}{\sum_{i=1}^{N} 1/PI_i}

    with :math:`PI_i` from :func:`preservation_index`. IPI-style rating of natural
    ageing [1]_: ≥ 75 years *good*, 45–75 *OK*, < 45 *risk* (used by :func:`assess`).

    References
    ----------
    .. [1] J. M. Reilly, D. W. Nishimura and E. Zinn, "New Tools for Preservation:
       Assessing Long-Term Environmental Effects on Library and Archives Collections",
       Commission on Preservation and Access, Washington DC (1995). (No DOI.)
    .. [2] D. K. Sebera, "Isoperms: An Environmental Management Tool", Commission on
       Preservation and Access, Washington DC (1994). (No DOI.)
    """
    h = hourly("twpi", T=T, RH=RH, nan_policy=nan_policy)
    return h.reduce(harmonic_mean(_pi(h.T, h.RH), nan_policy))


# --------------------------------------------------------------------------------------
# Mechanical
# --------------------------------------------------------------------------------------


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


# --------------------------------------------------------------------------------------
# Biological: VTT mould index, lowest isopleth for mould
# --------------------------------------------------------------------------------------


def _vtt_args(func, sensitivity, species, surface, M0, frozen):
    check_choice(func, "sensitivity", sensitivity, tuple(SENSITIVITY))
    check_choice(func, "species", species, tuple(_SPECIES))
    check_choice(func, "surface", surface, tuple(_SURFACE))
    check_choice(func, "frozen", frozen, ("decline", "hold"))
    try:
        M0 = float(M0)
    except (TypeError, ValueError):
        raise InputError(f"{func}: M0 must be a number in 0…6; got {M0!r}") from None
    if not 0.0 <= M0 <= 6.0:
        raise InputError(f"{func}: M0 must be a number in 0…6; got {M0!r}")
    k1_lo, k1_hi, A, B, C, RH_min, C_mat = SENSITIVITY[sensitivity]
    return (k1_lo, k1_hi, A, B, C, RH_min, C_mat, _SPECIES[species], _SURFACE[surface],
            M0, frozen == "decline")  # fmt: skip


def _vtt_run(h: Hourly, args, nan_policy, store):
    T = np.ascontiguousarray(h.T, dtype=float)
    RH = np.ascontiguousarray(h.RH, dtype=float)
    out = np.empty(T.shape) if store else np.empty((0, 0))
    peak = vtt_kernel(T, RH, *args, nan_policy == "omit", out)
    return out, peak


def vtt_mould_index(
    T,
    RH,
    *,
    sensitivity="VS",
    species="pine",
    surface="resawn",
    M0=0.0,
    frozen="decline",
    nan_policy="propagate",
):
    r"""VTT mould index, hour by hour, with growth and decline.

    Parameters
    ----------
    T : array_like or pandas.Series
        Hourly surface (or air) temperature, shape (hours,) or (draws, hours). [°C]
    RH : array_like or pandas.Series
        Hourly surface (or air) relative humidity, same shape. [%]
    sensitivity : {"VS", "S", "MR", "R"}, default "VS"
        Material sensitivity class of Ojanen et al. [2]_: very sensitive (pine sapwood),
        sensitive (spruce, paper-faced boards), medium resistant (concrete, mineral
        wool), resistant (glass, metals).
    species : {"pine", "spruce"}, default "pine"
        Wood species term W of Hukka & Viitanen (0 pine, 1 spruce).
    surface : {"resawn", "kiln-dried"}, default "resawn"
        Surface quality SQ (0 resawn, 1 original kiln-dried surface).
    M0 : float, default 0.0
        Index at the start of the series. [-]
    frozen : {"decline", "hold"}, default "decline"
        Hours at T ≤ 0 °C: count as unfavourable (the index declines, as in the published
        algorithm where every non-growth hour declines) or freeze the index and the
        decline clock.
    nan_policy : {"propagate", "omit", "raise"}, default "propagate"
        Missing hours: the index is NaN from the first gap on, or holds its state across
        gaps (NaN in them), or an error.

    Returns
    -------
    numpy.ndarray or pandas.Series
        Mould index M, same shape as the input (a Series for a Series). [-]
        0 no growth; 1 microscopic, initial growth; 2 several colonies (microscope);
        3 visible, < 10 % cover; 4 visible 10–50 %; 5 > 50 %; 6 heavy, ≈100 %.

    Notes
    -----
    Growth when :math:`0 < T < 50` °C and :math:`RH \ge RH_{crit}` [1]_ [2]_:

    .. math::
        \frac{dM}{dt} = \frac{k_1 k_2}{24\cdot7\,\exp(-0.68\ln T - 13.9\ln RH
        + 0.14W - 0.33SQ + 66.02)} \quad [1/h]

    with :math:`RH_{crit} = \max(-0.00267T^3 + 0.160T^2 - 3.13T + 100, RH_{min})` for
    T ≤ 20 °C and :math:`RH_{min}` above (80 % for VS/S, 85 % for MR/R);
    :math:`k_1` = 1/0.578/0.072/0.033 for M < 1 and 2/0.386/0.097/0.014 for M ≥ 1
    (VS/S/MR/R); :math:`k_2 = \max(1 - e^{2.3(M - M_{max})}, 0)`,
    :math:`M_{max} = A + Bx - Cx^2`, :math:`x = (RH_{crit} - RH)/(RH_{crit} - 100)`,
    (A, B, C) = (1, 7, 2), (0.3, 6, 1), (0, 5, 1.5), (0, 3, 1).

    Decline in every other hour (RH below critical, T ≥ 50 °C, and T ≤ 0 °C unless
    ``frozen="hold"``), counted from the start of the unfavourable period:
    :math:`C_{mat}` × (−0.00133 /h during the first 6 h, 0 from 6 to 24 h, −0.000667 /h
    after 24 h), :math:`C_{mat}` = 1/0.5/0.25/0.1; M never drops below 0. In growth,
    :math:`k_2 = 0` once M exceeds :math:`M_{max}` (no decline towards it). Hour *k*
    of a dry spell is the interval (k−1, k] h, so hours 1–6 decline fast and hours 25+
    slowly. RH is taken as given: apply it at the surface of interest.

    The recursion runs in compiled code (numba), vectorised over draws.

    References
    ----------
    .. [1] A. Hukka and H. A. Viitanen, "A mathematical model of mould growth on wooden
       material", Wood Sci. Technol. 33 (1999) 475-485. doi:10.1007/s002260050131
    .. [2] T. Ojanen, H. Viitanen, R. Peuhkuri, K. Lähdesmäki, J. Vinha and K. Salminen,
       "Mold growth modeling of building structures using sensitivity classes of
       materials", Thermal Performance of the Exterior Envelopes of Whole Buildings XI,
       ASHRAE, Clearwater Beach FL (2010). (No DOI.)
    """
    func = "vtt_mould_index"
    args = _vtt_args(func, sensitivity, species, surface, M0, frozen)
    h = hourly(func, T=T, RH=RH, nan_policy=nan_policy)
    out, _ = _vtt_run(h, args, nan_policy, store=True)
    return h.series(out, "M")


def _lim_c(func, growth_rate):
    try:
        key = float(growth_rate)
    except (TypeError, ValueError):
        key = None
    if key not in _LIM_CONSTANT:
        raise InputError(
            f"{func}: growth_rate must be one of 0, 0.1, 0.5, 1, 2, 3, 4 [mm/day]; "
            f"got {growth_rate!r}"
        )
    return _LIM_CONSTANT[key]


def _lim(T, c):
    return 100.0 * (0.02633 * np.cosh(0.10083 * (T - 30.0)) + c)


def lowest_isopleth(T, growth_rate=0.0):
    r"""Lowest isopleth for mould (LIM), closed form of Zeng et al. (2023).

    Parameters
    ----------
    T : numeric
        Temperature. [°C]
    growth_rate : {0, 0.1, 0.5, 1, 2, 3, 4}, default 0
        Mycelium growth rate of the isopleth; 0 gives LIM0, the germination limit below
        which no mould grows. [mm/day]

    Returns
    -------
    float, numpy.ndarray or pandas.Series
        Relative humidity of the isopleth. [%]

    Notes
    -----
    .. math:: LIM_u = 100\left[0.02633\cosh\left(0.10083\,(T - 30)\right) + c_u\right]

    with :math:`c_u` = 0.7153 (LIM0), 0.7300, 0.7675, 0.7950, 0.8250, 0.8502, 0.8701 for
    u = 0.1, 0.5, 1, 2, 3, 4 mm/day [1]_. LIM0 ≈ 75.6 % at 20 °C; the curve rises
    above 100 % below about 0 °C, so no hour at or below freezing counts as mould
    weather.

    References
    ----------
    .. [1] L. Zeng, Y. Chen, M. Ma et al., "Prediction of mould growth rate within
       building envelopes: development and validation of an improved model", Build.
       Serv. Eng. Res. Technol. 44(1) (2023) 63-79. doi:10.1177/01436244221137846
    """
    c = _lim_c("lowest_isopleth", growth_rate)
    (T,), wrap = pointwise("lowest_isopleth", T=T)
    return wrap(_lim(T, c), "LIM")


def _hours_above(h: Hourly, c, per_year, nan_policy):
    valid = np.isfinite(h.T) & np.isfinite(h.RH)
    with np.errstate(invalid="ignore"):
        above = h.RH > _lim(h.T, c)
    share = share_percent(above, valid, nan_policy) / 100.0
    if per_year:
        return share * HOURS_PER_YEAR
    k = (above & valid).sum(axis=-1).astype(float)
    return np.where(np.isnan(share), np.nan, k)


def hours_above_isopleth(T, RH, *, growth_rate=0.0, per_year=True, nan_policy="propagate"):
    r"""Hours with RH above the lowest isopleth for mould (Zeng et al. 2023).

    Parameters
    ----------
    T : array_like or pandas.Series
        Hourly temperature, shape (hours,) or (draws, hours). [°C]
    RH : array_like or pandas.Series
        Hourly relative humidity, same shape. [%]
    growth_rate : {0, 0.1, 0.5, 1, 2, 3, 4}, default 0
        Which isopleth (LIM0 by default), see :func:`lowest_isopleth`. [mm/day]
    per_year : bool, default True
        Normalise to a year of 8760 h (needs at least one year of data); else the
        plain count of hours over the period.
    nan_policy : {"propagate", "omit", "raise"}, default "propagate"
        Missing hours: NaN result, skipped (the count is then scaled by the valid hours),
        or an error.

    Returns
    -------
    float or numpy.ndarray
        Hours above the isopleth. [h/year] with ``per_year``, else [h]

    Notes
    -----
    :math:`N = 8760 \cdot \#\{i: RH_i > LIM_u(T_i)\} / N_{valid}` with
    :math:`LIM_u` from :func:`lowest_isopleth`. A count of hours, not a growth model: it
    ignores the time needed for germination (see :func:`vtt_mould_index` for that).

    References
    ----------
    .. [1] L. Zeng, Y. Chen, M. Ma et al., "Prediction of mould growth rate within
       building envelopes: development and validation of an improved model", Build.
       Serv. Eng. Res. Technol. 44(1) (2023) 63-79. doi:10.1177/01436244221137846
    """
    func = "hours_above_isopleth"
    c = _lim_c(func, growth_rate)
    h = hourly(
        func,
        T=T,
        RH=RH,
        nan_policy=nan_policy,
        min_hours=HOURS_PER_YEAR if per_year else None,
        what="hours per year above the isopleth",
    )
    return h.reduce(_hours_above(h, c, bool(per_year), nan_policy))


# --------------------------------------------------------------------------------------
# ASHRAE museum climate classes
# --------------------------------------------------------------------------------------

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
        min_hours=HOURS_PER_YEAR,
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
    h = hourly(func, RH=RH, nan_policy=nan_policy, min_hours=HOURS_PER_YEAR, what="EN 15757")
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


# --------------------------------------------------------------------------------------
# Everything at once
# --------------------------------------------------------------------------------------

#: Indicator groups of :func:`assess`; those marked True need at least a year of data.
INDICATOR_GROUPS = {
    "chemical": False,
    "mechanical": False,
    "mould": True,
    "ashrae": True,
    "en15757": True,
}

_OPTION_TARGETS = {
    "lm": "twlm",
    "emc": "dimensional_change",
    "vtt": "vtt_mould_index",
    "isopleth": "hours_above_isopleth",
    "ashrae": "ashrae_classes",
    "en15757": "en15757_band",
}
_NOT_OPTIONS = {"T", "RH", "nan_policy", "per_year"}
_DEFAULT_EA = {"paper": 100e3, "varnish": 70e3}


def _defaults(fname):
    sig = inspect.signature(globals()[fname])
    return {
        k: p.default
        for k, p in sig.parameters.items()
        if k not in _NOT_OPTIONS and p.default is not inspect.Parameter.empty
    }


def _resolve_options(func, given: Mapping[str, Mapping | None]):
    """Merge user options with the defaults of each target function; reject unknowns."""
    opts = {}
    for key, fname in _OPTION_TARGETS.items():
        d = _defaults(fname)
        if key == "lm":
            d["Ea"] = dict(_DEFAULT_EA)
        user = given.get(key) or {}
        if not isinstance(user, Mapping):
            raise InputError(
                f"{func}: {key} must be a dict of options for {fname}(); got {type(user).__name__}"
            )
        unknown = sorted(set(user) - set(d))
        if unknown:
            raise InputError(
                f"{func}: unknown option(s) {unknown} in {key}=...; expected some of "
                f"{sorted(d)} (the keywords of {fname}())"
            )
        d.update(user)
        opts[key] = d
    # validate each group's options once, before any work
    lm = opts["lm"]
    Ea = lm["Ea"]
    if not isinstance(Ea, Mapping):
        Ea = {f"Ea={float(check_positive(func, 'Ea', Ea)) / 1e3:g}kJ/mol": Ea}
    if not Ea:
        raise InputError(f"{func}: lm Ea must name at least one material; got {{}}")
    for Ea_i in Ea.values():
        _check_lm(func, Ea_i, lm["T_ref"], lm["RH_ref"], lm["n"])
    lm["Ea"] = {str(k): float(v) for k, v in Ea.items()}
    opts["emc"]["coefficient"] = check_positive(func, "coefficient", opts["emc"]["coefficient"])
    v = opts["vtt"]
    opts["vtt"] = {"args": _vtt_args(func, **v), **v}
    opts["isopleth"]["c"] = _lim_c(func, opts["isopleth"]["growth_rate"])
    a = opts["ashrae"]
    a["threshold"], a["classes"] = _ashrae_check(
        func, a["method"], a["threshold"], a["classes"], a["edges"], a["T_setpoint"],
        a["RH_setpoint"],
    )  # fmt: skip
    e = opts["en15757"]
    check_positive(func, "ashrae window_days", a["window_days"])
    check_positive(func, "en15757 window_days", e["window_days"])
    e["percentiles"], e["min_band"] = _en_check(
        func, e["percentiles"], e["min_band"], e["min_band_mode"], e["edges"]
    )
    return opts


def _resolve_groups(func, indicators):
    if indicators is None:
        return tuple(INDICATOR_GROUPS)
    if isinstance(indicators, str):
        indicators = (indicators,)
    groups = tuple(indicators)
    unknown = [g for g in groups if g not in INDICATOR_GROUPS]
    if unknown or not groups:
        raise InputError(
            f"{func}: indicators must be a non-empty selection of {list(INDICATOR_GROUPS)}; "
            f"got {list(groups)}"
        )
    return groups


def _check_year(func, groups, n):
    yearly = [g for g in groups if INDICATOR_GROUPS[g]]
    if yearly and n < HOURS_PER_YEAR:
        short = [g for g in groups if not INDICATOR_GROUPS[g]] or ["chemical", "mechanical"]
        raise InputError(
            f"{func}: the indicators {yearly} need at least one year of hourly data "
            f"({HOURS_PER_YEAR} h); got {n} h. For a shorter series pass "
            f"indicators={short}"
        )


def _assess_core(h: Hourly, groups, opts, nan_policy) -> dict[str, np.ndarray]:
    """All indicators of the selected groups, one value per draw."""
    T, RH = h.T, h.RH
    out: dict[str, np.ndarray] = {}
    if "chemical" in groups:
        lm = opts["lm"]
        with np.errstate(divide="ignore", over="ignore"):
            u = 1.0 / (T + _T0) - 1.0 / (lm["T_ref"] + _T0)
            rh_term = lm["n"] * np.log(lm["RH_ref"] / RH)
            for label, Ea in lm["Ea"].items():
                val = np.exp(Ea / R_GAS * u + rh_term)
                out[f"lifetime_multiplier[{label}]"] = harmonic_mean(val, nan_policy)
        out["twpi"] = harmonic_mean(_pi(T, RH), nan_policy)
    if "mechanical" in groups:
        lo, hi = _minmax(_emc(T, RH), nan_policy)
        out["emc_min"] = lo
        out["emc_max"] = hi
        out["emc_range"] = hi - lo
        out["dimensional_change"] = 100.0 * opts["emc"]["coefficient"] * (hi - lo)
        out["metal_corrosion"] = hi
    if "mould" in groups:
        _, peak = _vtt_run(h, opts["vtt"]["args"], nan_policy, store=False)
        out["vtt_mould_index_max"] = peak
        iso = opts["isopleth"]
        name = f"hours_above_LIM{float(iso['growth_rate']):g}"
        out[name] = _hours_above(h, iso["c"], True, nan_policy)
    sRH = None
    a, e = opts["ashrae"], opts["en15757"]
    if "ashrae" in groups and "en15757" in groups:
        if a["window_days"] == e["window_days"] and a["edges"] == e["edges"]:
            half = _window_half("assess", a["window_days"], h.n_hours)
            sRH = centred_mean(RH, half, a["edges"], nan_policy)
    if "ashrae" in groups:
        sh, _, _, best, _, _ = _ashrae_core(
            h,
            window_days=a["window_days"],
            T_setpoint=a["T_setpoint"],
            RH_setpoint=a["RH_setpoint"],
            method=a["method"],
            threshold=a["threshold"],
            classes=a["classes"],
            nested=bool(a["nested"]),
            edges=a["edges"],
            nan_policy=nan_policy,
            sRH=sRH,
        )
        for j, c in enumerate(a["classes"]):
            out[f"ashrae_{c.name}"] = sh[:, j]
        out["ashrae_best_class"] = np.array(
            ["none" if b is None else b for b in best], dtype=object
        )
    if "en15757" in groups:
        *_, lo, hi, _, _, share = _en_core(
            RH,
            window_days=e["window_days"],
            percentiles=e["percentiles"],
            min_band=e["min_band"],
            min_band_mode=e["min_band_mode"],
            edges=e["edges"],
            nan_policy=nan_policy,
            seasonal=sRH,
        )
        out["en15757_outside"] = share
        out["en15757_lower_offset"] = lo
        out["en15757_upper_offset"] = hi
    return out


def _unit(name: str) -> str:
    if name.startswith("lifetime_multiplier") or name == "vtt_mould_index_max":
        return "-"
    if name.startswith("hours_above_LIM"):
        return "h/year"
    if name.startswith("ashrae_") or name == "en15757_outside":
        return "% of hours"
    return {
        "twpi": "years",
        "emc_min": "% MC",
        "emc_max": "% MC",
        "emc_range": "% MC",
        "metal_corrosion": "% MC",
        "dimensional_change": "%",
        "en15757_lower_offset": "%RH",
        "en15757_upper_offset": "%RH",
    }[name]


def _rating(name: str, v) -> str:
    """IPI-style rating of one indicator value ('' where no published scale applies)."""
    if v is None or (isinstance(v, float) and math.isnan(v)):
        return ""
    if name == "twpi":
        return "good" if v >= 75.0 else ("OK" if v >= 45.0 else "risk")
    if name == "emc_min":
        return "OK" if v >= 5.0 else "risk"
    if name == "emc_max":
        return "OK" if v <= 12.5 else "risk"
    if name == "metal_corrosion":
        return "good" if v < 7.0 else ("OK" if v < 10.5 else "risk")
    if name == "vtt_mould_index_max":
        return "good" if v < 1.0 else "risk"
    return ""


def _prepare_assess(func, T, RH, indicators, nan_policy, options):
    groups = _resolve_groups(func, indicators)
    opts = _resolve_options(func, options)
    h = hourly(func, T=T, RH=RH, nan_policy=nan_policy)
    _check_year(func, groups, h.n_hours)
    return h, groups, opts


def assess(
    T,
    RH,
    *,
    indicators=None,
    nan_policy="propagate",
    lm=None,
    emc=None,
    vtt=None,
    isopleth=None,
    ashrae=None,
    en15757=None,
):
    r"""All conservation-risk indicators of one hourly series, as a tidy table.

    Parameters
    ----------
    T : array_like or pandas.Series
        Hourly air temperature, shape (hours,). [°C]
    RH : array_like or pandas.Series
        Hourly relative humidity, shape (hours,). [%]
    indicators : iterable of str, optional
        Groups to compute, any of ``"chemical"`` (lifetime multipliers, TWPI),
        ``"mechanical"`` (EMC, dimensional change, corrosion), ``"mould"`` (VTT index,
        hours above LIM), ``"ashrae"``, ``"en15757"``; default all. ``mould``, ``ashrae``
        and ``en15757`` need at least a year (8760 h).
    nan_policy : {"propagate", "omit", "raise"}, default "propagate"
        Missing hours, for every indicator (see the module documentation).
    lm : dict, optional
        Options of :func:`twlm`; ``Ea`` is a dict label → activation energy [J/mol],
        default ``{"paper": 100e3, "varnish": 70e3}`` (one row each).
    emc : dict, optional
        Options of :func:`dimensional_change` (``coefficient``).
    vtt : dict, optional
        Options of :func:`vtt_mould_index` (``sensitivity``, ``species``, ``surface``,
        ``M0``, ``frozen``).
    isopleth : dict, optional
        Options of :func:`hours_above_isopleth` (``growth_rate``).
    ashrae : dict, optional
        Options of :func:`ashrae_classes`.
    en15757 : dict, optional
        Options of :func:`en15757_band`.

    Returns
    -------
    pandas.DataFrame
        One row per indicator, columns ``indicator``, ``value``, ``unit``, ``rating``:

        * ``lifetime_multiplier[<label>]`` — :func:`twlm` [-];
        * ``twpi`` — :func:`twpi` [years], rated good (≥ 75) / OK (≥ 45) / risk;
        * ``emc_min``, ``emc_max`` [% MC] — rated OK/risk against 5 and 12.5 %;
          ``emc_range`` [% MC]; ``dimensional_change`` [%] (:func:`dimensional_change`);
        * ``metal_corrosion`` — maximum EMC [% MC], rated good (< 7) / OK (< 10.5) /
          risk;
        * ``vtt_mould_index_max`` — maximum of :func:`vtt_mould_index` [-], rated good
          (< 1) / risk;
        * ``hours_above_LIM0`` — :func:`hours_above_isopleth` [h/year];
        * ``ashrae_AA`` … ``ashrae_D`` — share of hours per class [% of hours];
          ``ashrae_best_class`` — share of the best class, whose name is the rating
          ("none" if no class reaches the threshold);
        * ``en15757_outside`` [% of hours], ``en15757_lower_offset``,
          ``en15757_upper_offset`` [%RH] (:func:`en15757_band`).

        Ratings are empty where the field has no published scale.

    Raises
    ------
    heritage_bayes.errors.InputError
        Bad input (RH as a fraction, mismatched shapes, irregular index, a series shorter
        than a year for the yearly groups, unknown option names or values).

    See Also
    --------
    assess_batch : the same for many series at once (draws × hours).

    Notes
    -----
    The equations are in the functions named above. Unknown option keys are rejected,
    never ignored.

    References
    ----------
    .. [1] S. Michalski (2002), ICOM-CC 13th Triennial Meeting, Rio de Janeiro, 66-72
       (lifetime multiplier, :func:`lifetime_multiplier`).
    .. [2] D. K. Sebera (1994), "Isoperms"; J. M. Reilly et al. (1995), "New Tools for
       Preservation", Commission on Preservation and Access (PI, TWPI).
    .. [3] A. J. Hailwood and S. Horrobin (1946), doi:10.1039/TF946420B084; Wood
       Handbook FPL-GTR-190 (2010), doi:10.2737/FPL-GTR-190 (EMC, dimensional change).
    .. [4] A. Hukka and H. A. Viitanen (1999), doi:10.1007/s002260050131; T. Ojanen et
       al. (2010), Buildings XI (VTT mould index).
    .. [5] L. Zeng et al. (2023), doi:10.1177/01436244221137846 (lowest isopleth).
    .. [6] ASHRAE Handbook — HVAC Applications, museums chapter (climate classes).
    .. [7] EN 15757:2010; D. Camuffo et al. (2022), doi:10.3390/atmos13091344.

    Examples
    --------
    >>> import numpy as np
    >>> t = np.arange(8760)
    >>> T = 12 + 6 * np.sin(2 * np.pi * t / 8760)
    >>> RH = 60 + 8 * np.sin(2 * np.pi * t / 24)
    >>> table = assess(T, RH)
    >>> table.set_index("indicator").loc["ashrae_best_class", "rating"]
    'B'
    """
    func = "assess"
    options = dict(lm=lm, emc=emc, vtt=vtt, isopleth=isopleth, ashrae=ashrae, en15757=en15757)
    h, groups, opts = _prepare_assess(func, T, RH, indicators, nan_policy, options)
    if h.ndim != 1:
        raise InputError(
            f"{func}: expected one hourly series (1-D); got shape "
            f"{(h.T.shape[0], h.n_hours)}. Use assess_batch for draws × hours"
        )
    res = _assess_core(h, groups, opts, nan_policy)
    rows = []
    for name, v in res.items():
        if name == "ashrae_best_class":
            best = v[0]
            value = float(res[f"ashrae_{best}"][0]) if best != "none" else math.nan
            rows.append((name, value, _unit(name), best))
            continue
        value = float(v[0])
        rows.append((name, value, _unit(name), _rating(name, value)))
    return pd.DataFrame(rows, columns=["indicator", "value", "unit", "rating"])


def assess_batch(
    T,
    RH,
    *,
    indicators=None,
    nan_policy="propagate",
    chunk_size=128,
    lm=None,
    emc=None,
    vtt=None,
    isopleth=None,
    ashrae=None,
    en15757=None,
):
    r"""All indicators for many series at once (posterior draws × hours).

    Parameters
    ----------
    T : array_like
        Hourly air temperature, shape (draws, hours), or (hours,) shared by all draws of
        ``RH``. [°C]
    RH : array_like
        Hourly relative humidity, shape (draws, hours), or (hours,) shared. [%]
    indicators, nan_policy, lm, emc, vtt, isopleth, ashrae, en15757
        As in :func:`assess`.
    chunk_size : int, default 128
        Draws processed together (bounds the memory of the temporaries). [-]

    Returns
    -------
    pandas.DataFrame
        One row per draw (index ``draw``), one column per indicator of :func:`assess`
        (same names and units; ``df.attrs["units"]`` maps column → unit). The column
        ``ashrae_best_class`` holds the class name ("none" if none is reached). Use
        :func:`summarize` for quantiles and ratings.

    Notes
    -----
    Vectorised over draws: moving averages by cumulative sums along the hours axis,
    the VTT recursion compiled with numba. About two seconds for 1000 draws × 8760 h
    on a laptop-class CPU (``benchmarks/bench_risk.py``). Row *i* equals
    ``assess(T[i], RH[i])``.

    References
    ----------
    See :func:`assess`.
    """
    func = "assess_batch"
    options = dict(lm=lm, emc=emc, vtt=vtt, isopleth=isopleth, ashrae=ashrae, en15757=en15757)
    h, groups, opts = _prepare_assess(func, T, RH, indicators, nan_policy, options)
    bad = isinstance(chunk_size, bool) or not isinstance(chunk_size, int | np.integer)
    if bad or chunk_size < 1:
        raise InputError(f"{func}: chunk_size must be a positive integer; got {chunk_size!r}")
    d = h.T.shape[0]
    parts: list[dict[str, np.ndarray]] = []
    for start in range(0, d, int(chunk_size)):
        sl = slice(start, start + int(chunk_size))
        hc = Hourly(T=h.T[sl], RH=h.RH[sl], index=None, ndim=2)
        parts.append(_assess_core(hc, groups, opts, nan_policy))
    cols = {k: np.concatenate([p[k] for p in parts]) for k in parts[0]}
    df = pd.DataFrame(cols, index=pd.RangeIndex(d, name="draw"))
    df.attrs["units"] = {k: _unit(k) for k in cols}
    return df


def summarize(per_draw: pd.DataFrame, quantiles=(0.05, 0.5, 0.95)) -> pd.DataFrame:
    r"""Distribution of each indicator over draws, as a tidy table.

    Parameters
    ----------
    per_draw : pandas.DataFrame
        Output of :func:`assess_batch` (one row per draw; units in ``attrs["units"]``).
    quantiles : sequence of float, default (0.05, 0.5, 0.95)
        Quantiles to report, each in [0, 1]. [-]

    Returns
    -------
    pandas.DataFrame
        Columns ``indicator``, ``unit``, ``mean``, one column per quantile (``q5``,
        ``q50``, ``q95`` …) and ``rating``: the rating of the median for rated
        indicators; for ``ashrae_best_class``, the share of draws per best class
        (e.g. ``"B 80 %, C 20 %"``). NaN draws are left out. Values in the unit of
        each indicator (``per_draw.attrs["units"]``).

    Notes
    -----
    Quantiles by linear interpolation (:func:`numpy.quantile`); the rating of the
    median uses the same scales as :func:`assess`.
    """
    func = "summarize"
    if not isinstance(per_draw, pd.DataFrame):
        raise InputError(
            f"{func}: expected the DataFrame of assess_batch; got {type(per_draw).__name__}"
        )
    try:
        qs = [float(q) for q in quantiles]
    except (TypeError, ValueError):
        raise InputError(
            f"{func}: quantiles must be numbers in [0, 1]; got {quantiles!r}"
        ) from None
    if not qs or not all(0.0 <= q <= 1.0 for q in qs):
        raise InputError(f"{func}: quantiles must be numbers in [0, 1]; got {quantiles!r}")
    qcols = [f"q{100 * q:g}" for q in qs]
    units = per_draw.attrs.get("units", {})
    rows = []
    for name in per_draw.columns:
        col = per_draw[name]
        if name == "ashrae_best_class":
            freq = col.astype(str).value_counts(normalize=True)
            rating = ", ".join(f"{k} {100 * v:.0f} %" for k, v in freq.items())
            rows.append([name, "", math.nan, *([math.nan] * len(qs)), rating])
            continue
        x = col.to_numpy(dtype=float)
        x = x[~np.isnan(x)]
        if x.size:
            qv = np.quantile(x, qs)
            mean = float(x.mean())
            med = float(np.median(x))
        else:
            qv, mean, med = [math.nan] * len(qs), math.nan, math.nan
        rows.append([name, units.get(name, ""), mean, *map(float, qv), _rating(name, med)])
    return pd.DataFrame(rows, columns=["indicator", "unit", "mean", *qcols, "rating"])
