"""Biological risk: the VTT mould index and the lowest isopleth for mould.

:func:`vtt_mould_index` (the VTT model's hourly recursion, compiled with numba in
:mod:`heritage_bayes.climate.risk._vtt`), :func:`lowest_isopleth` (LIM, Zeng et al. 2023;
pointwise) and :func:`hours_above_isopleth`. Temperature in [°C], RH in [%]; conventions
in :mod:`heritage_bayes.climate.risk`.
"""

from __future__ import annotations

import numpy as np

from heritage_bayes.climate.risk._inputs import (
    HOURS_PER_YEAR,
    MIN_YEAR_HOURS,
    Hourly,
    check_choice,
    hourly,
    pointwise,
    share_percent,
)
from heritage_bayes.climate.risk._vtt import SENSITIVITY, vtt_kernel
from heritage_bayes.errors import InputError

# Zeng et al. (2023): LIM_u = 100 [0.02633 cosh(0.10083 (T - 30)) + c_u], u in mm/day.
_LIM_CONSTANT = {0.0: 0.7153, 0.1: 0.7300, 0.5: 0.7675, 1.0: 0.7950, 2.0: 0.8250,
                 3.0: 0.8502, 4.0: 0.8701}  # fmt: skip

_SPECIES = {"pine": 0.0, "spruce": 1.0}
_SURFACE = {"resawn": 0.0, "kiln-dried": 1.0}


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
        min_hours=MIN_YEAR_HOURS if per_year else None,
        what="hours per year above the isopleth",
    )
    return h.reduce(_hours_above(h, c, bool(per_year), nan_policy))
