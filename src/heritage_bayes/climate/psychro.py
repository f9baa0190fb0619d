"""Psychrometrics: saturation vapour pressure, RH <-> vapour pressure, dew point.

Pure, vectorised numpy functions. Temperatures in [°C], relative humidity in [%],
pressures in [Pa].

References
----------
.. [1] W. Wagner and A. Pruß, "International equations for the saturation properties of
   ordinary water substance. Revised according to the international temperature scale of
   1990", J. Phys. Chem. Ref. Data 22 (1993) 783-787. doi:10.1063/1.555926
.. [2] W. Wagner, T. Riethmann, R. Feistel and A. H. Harvey, "New equations for the
   sublimation pressure and melting pressure of H2O ice Ih", J. Phys. Chem. Ref. Data 40
   (2011) 043103. doi:10.1063/1.3657937
.. [3] IAPWS, "Revised Supplementary Release on Saturation Properties of Ordinary Water
   Substance" (1992).
"""

from __future__ import annotations

import numpy as np

__all__ = [
    "R_VAPOUR",
    "T_ZERO",
    "absolute_humidity",
    "dew_point",
    "relative_humidity",
    "saturation_vapour_pressure",
    "vapour_pressure",
]

#: Specific gas constant of water vapour [J/(kg·K)].
R_VAPOUR = 461.52
#: 0 °C in [K].
T_ZERO = 273.15

# Wagner & Pruß (1993) saturation line over liquid water.
_TC = 647.096  # critical temperature [K]
_PC = 22.064e6  # critical pressure [Pa]
_A_WATER = (-7.85951783, 1.84408259, -11.7866497, 22.6807411, -15.9618719, 1.80122502)
# Wagner et al. (2011) sublimation line over ice Ih.
_TT = 273.16  # triple point [K]
_PT = 611.657  # triple-point pressure [Pa]
_A_ICE = (-21.2144006, 27.3203819, -6.10598130)
_B_ICE = (0.00333333333, 1.20666667, 1.70333333)


def _psat_water(TK: np.ndarray) -> np.ndarray:
    th = 1.0 - TK / _TC
    a1, a2, a3, a4, a5, a6 = _A_WATER
    poly = a1 * th + a2 * th**1.5 + a3 * th**3 + a4 * th**3.5 + a5 * th**4 + a6 * th**7.5
    return _PC * np.exp(_TC / TK * poly)


def _psat_ice(TK: np.ndarray) -> np.ndarray:
    th = TK / _TT
    s = sum(a * th**b for a, b in zip(_A_ICE, _B_ICE, strict=True))
    return _PT * np.exp(s / th)


def saturation_vapour_pressure(T, over: str = "water"):
    """Saturation vapour pressure [Pa].

    Parameters
    ----------
    T : array_like
        Air temperature. [°C]
    over : {"water", "ice", "auto"}, default "water"
        Phase of the saturation reference. ``"water"`` (the meteorological and
        conservation convention for relative humidity, also below 0 °C), ``"ice"``, or
        ``"auto"`` (ice below the triple point 0.01 °C, water above).

    Returns
    -------
    numpy.ndarray or float
        Saturation vapour pressure. [Pa]

    Notes
    -----
    Over water, the IAPWS formulation of Wagner & Pruß [1]_:
    :math:`\\ln(p/p_c) = (T_c/T)(a_1\\vartheta + a_2\\vartheta^{1.5} + a_3\\vartheta^3 +
    a_4\\vartheta^{3.5} + a_5\\vartheta^4 + a_6\\vartheta^{7.5})`, :math:`\\vartheta = 1 - T/T_c`.
    Over ice, Wagner et al. (2011) [2]_:
    :math:`\\ln(p/p_t) = \\theta^{-1}\\sum_i a_i\\theta^{b_i}`, :math:`\\theta = T/T_t`.

    Examples
    --------
    >>> round(float(saturation_vapour_pressure(20.0)), 1)
    2339.2
    """
    TK = np.asarray(T, dtype=float) + T_ZERO
    if over == "water":
        out = _psat_water(TK)
    elif over == "ice":
        out = _psat_ice(TK)
    elif over == "auto":
        out = np.where(TK < _TT, _psat_ice(np.minimum(TK, _TT)), _psat_water(TK))
    else:
        raise ValueError(f"over must be 'water', 'ice' or 'auto' (got {over!r})")
    return out if out.ndim else float(out)


def vapour_pressure(T, RH, over: str = "water"):
    """Partial vapour pressure [Pa] from temperature [°C] and relative humidity [%].

    :math:`p_v = \\varphi/100 \\cdot p_{sat}(T)`.
    """
    return np.asarray(RH, dtype=float) / 100.0 * saturation_vapour_pressure(T, over=over)


def relative_humidity(T, Pv, over: str = "water"):
    """Relative humidity [%] from temperature [°C] and vapour pressure [Pa].

    Not clipped: a value above 100 % means supersaturation in the inputs (for example a
    model prediction of vapour pressure above saturation); callers decide what to do.
    """
    return 100.0 * np.asarray(Pv, dtype=float) / saturation_vapour_pressure(T, over=over)


def dew_point(T, RH):
    """Dew-point temperature [°C] from temperature [°C] and relative humidity [%].

    The temperature at which the vapour pressure equals the saturation vapour pressure
    over liquid water, found by Newton iteration on the IAPWS formulation (started from
    the Magnus inversion); accurate to better than 1e-9 K. ``RH <= 0`` gives NaN.
    """
    Pv = np.asarray(vapour_pressure(T, RH), dtype=float)
    with np.errstate(divide="ignore", invalid="ignore"):
        # Magnus (Alduchov & Eskridge 1996) inversion as a starting point
        g = np.log(Pv / 610.94)
        td = 243.04 * g / (17.625 - g)
        for _ in range(6):
            p = np.asarray(saturation_vapour_pressure(td), dtype=float)
            h = 1e-4
            dp = (np.asarray(saturation_vapour_pressure(td + h)) - p) / h
            td = td - (p - Pv) / dp
    td = np.where(Pv > 0, td, np.nan)
    return td if td.ndim else float(td)


def absolute_humidity(T, RH):
    """Absolute humidity (vapour density) [g/m³] from T [°C] and RH [%].

    Ideal gas: :math:`\\rho_v = p_v / (R_v T)` with :math:`R_v` = 461.52 J/(kg·K).
    """
    TK = np.asarray(T, dtype=float) + T_ZERO
    return 1000.0 * vapour_pressure(T, RH) / (R_VAPOUR * TK)
