"""Chemical decay: Michalski's lifetime multiplier and the preservation index.

:func:`lifetime_multiplier` (pointwise) and :func:`twlm` (its time-weighted, harmonic
mean over the hours); :func:`preservation_index` (pointwise, IPI) and :func:`twpi`
(time-weighted). Temperature in [°C], RH in [%]; conventions in
:mod:`heritage_bayes.climate.risk`.
"""

from __future__ import annotations

import numpy as np

from heritage_bayes.climate.risk._inputs import (
    check_positive,
    harmonic_mean,
    hourly,
    pointwise,
)
from heritage_bayes.errors import InputError

#: Molar gas constant [J/(mol·K)] (CODATA 2018).
R_GAS = 8.314462618
_T0 = 273.15


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
