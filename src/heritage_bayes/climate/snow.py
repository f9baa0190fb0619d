"""Snow on a roof, estimated from the outdoor air temperature and the precipitation.

A degree-day snowpack (the temperature-index snow routine of the HBV model [1]_ [2]_,
and of Snow-17's accumulation and melt without its energy terms [3]_): precipitation
falling while the air is below a threshold temperature accumulates as snow water
equivalent :math:`S` [mm], and the pack melts in proportion to the air's excess over
0 °C,

.. math::

    S_{k+1} = \\max\\bigl(0,\\; S_k + P_k\\,[T_k < T_s] - a\\,\\Delta t\\,\\max(T_k, 0)\\bigr),

with :math:`P_k` the precipitation of the step [mm], :math:`T_k` the outdoor air
temperature [°C], :math:`T_s` the snow/rain threshold (:data:`SNOW_THRESHOLD`, +1 °C),
:math:`a` the degree-day factor (:data:`MELT_FACTOR`, 3 mm/(K d); Hock [4]_ lists
2.5-6 mm/(K d) for snow) and :math:`\\Delta t` the step [d]. The roof counts as covered
in proportion to :math:`S` up to :data:`FULL_COVER` (5 mm of water, some 2 cm of
settled snow): :math:`c = \\min(1, S / S_{full})`.

What the cover does to the attic's inputs (:func:`roof_under_snow`): a roof's solar
column stands for the sol-air excess of its cover, :math:`\\alpha I / h_e`, acting on
the attic through the cover (:mod:`heritage_bayes.climate.solair`). Under snow the
cover receives no sun (a few centimetres of snow absorb or reflect it; the part
absorbed melts the snow, :math:`T \\le 0` °C at its base), and its outer face no longer
sees the outdoor air's daily swing but the snow's base, whose temperature is the air's
damped through the snow (the daily damping depth of snow [5]_, :math:`\\sqrt{2\\kappa/\\omega}`
with :math:`\\kappa \\approx 3 \\cdot 10^{-7}` m²/s, is about 9 cm): the air's mean
over the last 24 hours drawn a share :math:`w` (:data:`BASE_WARMTH`) of the way to
the 0 °C of a melting base, :math:`T_b = (1 - w)\\,\\overline{T_e}^{\\,24 h}`. The pack
insulates the cover: its base sits between the air above the snow and the attic below,
which the house keeps warmer than the air, and it cannot rise above 0 °C, where the
pack melts from below (the warm base behind ice dams [6]_). Under a pack of resistance
:math:`R_s` on a cover of :math:`R_r` the base is the attic's temperature weighted
:math:`R_s/(R_s + R_r)`, about 0.8 for 10 cm of snow (:math:`k \\approx 0.15` W/(m K))
on a tile cover (:math:`R_r` 0.2 m² K/W), so an attic 1-4 K above the air in a cold
spell lifts the base by some 0.15-0.3 of the air's distance below 0 °C. The attic's
temperature is the model's state; 0 °C stands for it, so the term stays a known
input. With
the bare cover's aperture :math:`f = \\alpha A U_r / (h_e + U_r)` and its conductance
between the outdoor air and the attic :math:`A h_e U_r / (h_e + U_r) = f h_e /
\\alpha`, the cover's outer temperature :math:`T_b` instead of :math:`T_e` adds
:math:`f (h_e / \\alpha)(T_b - T_e)`: both effects enter through the roof's own column,
in its units,

.. math::

    I' = (1 - c)\\, I + c\\, \\frac{h_e}{\\alpha}\\,(T_b - T_e),

:math:`h_e` the standard exterior coefficient (ISO 6946, :math:`R_{se}` 0.04 m² K/W)
and :math:`\\alpha` the cover's solar absorptance (:data:`ROOF_ABSORPTANCE`): the
roof's aperture, which the calibration estimates, carries the cover's share of the
attic's conductance too. No state and no parameter are added; the model stays linear
and time-invariant in its states.

References
----------
.. [1] S. Bergström, "Development and application of a conceptual runoff model for
   Scandinavian catchments", SMHI Reports RHO 7, Norrköping (1976).
.. [2] G. Lindström, B. Johansson, M. Persson, M. Gardelin and S. Bergström,
   "Development and test of the distributed HBV-96 hydrological model", Journal of
   Hydrology 201 (1997) 272-288.
.. [3] E. A. Anderson, "National Weather Service River Forecast System - Snow
   accumulation and ablation model", NOAA Technical Memorandum NWS HYDRO-17 (1973).
.. [4] R. Hock, "Temperature index melt modelling in mountain areas", Journal of
   Hydrology 282 (2003) 104-115, table 1.
.. [5] M. Sturm, J. Holmgren, M. König and K. Morris, "The thermal conductivity of
   seasonal snow", Journal of Glaciology 43 (1997) 26-41 (:math:`k` 0.1-0.3 W/(m K) at
   :math:`\\rho` 200-350 kg/m³).
.. [6] W. Tobiasson, J. Buska and A. Greatorex, "Ventilating attics to minimize icings
   at eaves", Energy and Buildings 21 (1994) 229-234.
"""

from __future__ import annotations

import numpy as np
import pandas as pd

from heritage_bayes.errors import InputError

__all__ = [
    "BASE_WARMTH",
    "FULL_COVER",
    "MELT_FACTOR",
    "ROOF_ABSORPTANCE",
    "SNOW_THRESHOLD",
    "roof_snow_columns",
    "roof_under_snow",
    "snow_cover",
    "snowpack",
]

#: Snow/rain threshold of the air temperature [°C] (HBV's TT, typically 0 to +2).
SNOW_THRESHOLD = 1.0
#: Degree-day melt factor [mm/(K d)] (HBV's CFMAX; open terrain 2.5-4).
MELT_FACTOR = 3.0
#: Snow water equivalent [mm] from which a roof counts as fully covered.
FULL_COVER = 5.0
#: Share [-] of the way from the air's 24-hour mean to 0 °C at which the snow's base
#: sits (a pack insulating a cover over a warmer attic; at most a melting base).
BASE_WARMTH = 0.3
#: Solar absorptance of a roof's cover [-] (dark tile, felt, painted sheet metal 0.8-0.9).
ROOF_ABSORPTANCE = 0.9
#: Standard exterior surface coefficient [W/(m² K)] (ISO 6946, R_se 0.04 m² K/W).
_H_E = 1.0 / 0.04


def snowpack(temperature, precipitation, step_hours, swe0: float = 0.0) -> np.ndarray:
    """Snow water equivalent [mm] on a roof at the end of each step.

    Parameters
    ----------
    temperature : array_like
        Outdoor air temperature [°C] of each step; gaps (NaN) hold the last value
        before them (0 °C before any: neither snow nor melt).
    precipitation : array_like
        Precipitation of each step [mm] (water, rain or snow); gaps count as none.
    step_hours : float or array_like
        The step [h], one for all or one per step.
    swe0 : float, default 0
        Snow water equivalent [mm] before the first step.

    Returns
    -------
    numpy.ndarray
        :math:`S_k` [mm] (module docstring), one per step.

    Raises
    ------
    heritage_bayes.errors.InputError
        Arrays of different lengths, a negative precipitation, a step not positive or
        ``swe0`` negative.
    """
    t = np.asarray(temperature, dtype=float)
    p = np.asarray(precipitation, dtype=float)
    if t.shape != p.shape or t.ndim != 1:
        raise InputError(
            f"temperature and precipitation: one value per step each (shapes {t.shape}, {p.shape})"
        )
    if (p < 0).any():
        raise InputError(f"precipitation: values >= 0 mm expected (found {p[p < 0][:3].tolist()})")
    dt = np.broadcast_to(np.asarray(step_hours, dtype=float), t.shape)
    if not (np.isfinite(dt).all() and (dt > 0).all() and np.isfinite(swe0) and swe0 >= 0):
        raise InputError(f"steps > 0 h and swe0 >= 0 mm expected (got {dt[:3]}, {swe0})")
    t = _held(t)
    melt = MELT_FACTOR * dt / 24.0 * np.maximum(t, 0.0)
    snow = np.where(t < SNOW_THRESHOLD, np.nan_to_num(p, nan=0.0), 0.0)
    out = np.empty(t.size)
    s = float(swe0)
    for k in range(t.size):
        s = max(0.0, s + snow[k] - melt[k])
        out[k] = s
    return out


def snow_cover(swe) -> np.ndarray:
    """Fraction [-] of the roof under snow, :math:`\\min(1, S / S_{full})`, from the snow
    water equivalent ``swe`` [mm] (:data:`FULL_COVER`)."""
    return np.clip(np.asarray(swe, dtype=float) / FULL_COVER, 0.0, 1.0)


def roof_under_snow(irradiance, temperature, daily_mean, cover) -> np.ndarray:
    """A roof plane's solar column [W/m²] under a snow cover (module docstring).

    Parameters
    ----------
    irradiance : array_like
        The plane's column as the snow-free roof's [W/m²] (transposed, shaded, weighted).
    temperature, daily_mean : array_like
        Outdoor air temperature [°C] and the snow base's temperature :math:`T_b` [°C]
        (:func:`roof_snow_columns`: the air's 24-hour mean drawn towards 0 °C by
        :data:`BASE_WARMTH`), of the same steps.
    cover : array_like
        Snow cover [-] of the same steps (:func:`snow_cover`).

    Returns
    -------
    numpy.ndarray
        :math:`(1 - c) I + c\\,(h_e/\\alpha)(T_b - T_e)`; equal to ``irradiance`` where
        ``cover`` is 0.
    """
    i, c = np.asarray(irradiance, dtype=float), np.asarray(cover, dtype=float)
    dt = np.asarray(daily_mean, dtype=float) - np.asarray(temperature, dtype=float)
    return (1.0 - c) * i + c * (_H_E / ROOF_ABSORPTANCE) * dt


def roof_snow_columns(
    irr: pd.DataFrame, te: pd.Series, precip: pd.Series, planes
) -> tuple[pd.DataFrame, str | None]:
    """The roof planes' columns of ``irr`` under the snow estimated from the weather.

    Parameters
    ----------
    irr : pandas.DataFrame
        Irradiance [W/m²] per surface (the planes' columns named as in ``planes``).
    te, precip : pandas.Series
        The weather's outdoor air temperature [°C] and precipitation [mm per row, the
        interval ending at its stamp], on the weather's (sorted, unique) stamps.
    planes : sequence of str
        The roof planes among ``irr``'s columns.

    Returns
    -------
    table : pandas.DataFrame
        ``irr`` with the planes' columns by :func:`roof_under_snow`; ``irr`` itself when
        no day's mean air temperature is below 0 °C (no snow season).
    detail : str or None
        What was done (for the provenance label), None when nothing was.
    """
    daily = te.groupby(te.index.floor("D")).mean()
    if not planes or not (daily < 0.0).any():
        return irr, None
    hours = np.diff(te.index) / pd.Timedelta(hours=1)
    step = np.concatenate([[np.median(hours) if hours.size else 1.0], hours])
    swe = snowpack(te.to_numpy(float), precip.reindex(te.index).to_numpy(float), step)
    base = (1.0 - BASE_WARMTH) * te.rolling("24h", min_periods=1).mean()
    weather = pd.DataFrame({"c": snow_cover(swe), "d": (base - te).to_numpy()}, index=te.index)
    on = weather.reindex(weather.index.union(irr.index)).interpolate("time", limit_area="inside")
    on = on.reindex(irr.index).fillna(0.0)  # outside the weather's span: no snow
    out = irr.copy()
    for k in planes:  # T_b - T_e as one column: the roof's term needs only the difference
        out[k] = roof_under_snow(irr[k].to_numpy(float), -on["d"], 0.0, on["c"])
    out.attrs = dict(irr.attrs)
    days = int((pd.Series(swe, te.index).groupby(te.index.floor("D")).max() > 0).sum())
    return out, f"roof planes {list(planes)} under the snow of a degree-day snowpack ({days} days)"


def _held(t: np.ndarray) -> np.ndarray:
    """``t`` with gaps holding the last value (0 before any)."""
    if np.isfinite(t).all():
        return t
    idx = np.where(np.isfinite(t), np.arange(t.size), 0)
    np.maximum.accumulate(idx, out=idx)
    out = t[idx]
    return np.where(np.isfinite(out), out, 0.0)
