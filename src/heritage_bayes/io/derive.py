"""Derived columns: vapour pressure from temperature and relative humidity."""

from __future__ import annotations

import numpy as np
import pandas as pd

from heritage_bayes.climate.psychro import vapour_pressure
from heritage_bayes.errors import DataError, InputError

__all__ = ["RH_SENSOR_CEILING", "add_vapour_pressure"]

_PAIRS = {"Pe": ("Te", "RHe"), "Pi": ("Ti", "RHi")}

#: Indoor relative humidity [%] at and above which a reading is censored (not a measurement):
#: a capacitive hygrometer saturates near 100 %RH (condensation on its element; stated
#: accuracies stop at 90-98 %RH), and loggers clip at 100 %, so a reading there says
#: only that the air was at or near saturation. Air at saturation also condenses on
#: cold surfaces, a moisture flow that no hygric model here has. ``Pi`` derived from
#: such a reading is missing (NaN: the likelihood leaves it out, the report lists it
#: with the gaps).
RH_SENSOR_CEILING = 99.0


def add_vapour_pressure(frame: pd.DataFrame, *, over: str = "water") -> pd.DataFrame:
    """Return a copy of ``frame`` with vapour pressure ``Pe`` and/or ``Pi`` [Pa] added.

    ``Pe`` is derived from ``Te`` [°C] and ``RHe`` [%], ``Pi`` from ``Ti`` and ``RHi``,
    row by row at the native resolution, i.e. **before** any averaging (vapour pressure is
    not linear in T and RH, so derive first, then :func:`~heritage_bayes.io.align`).

    Parameters
    ----------
    frame : pandas.DataFrame
        Output of a reader (or any frame with the standard columns).
    over : {"water", "ice", "auto"}, default "water"
        Saturation reference, see
        :func:`heritage_bayes.climate.saturation_vapour_pressure`. Hygrometers and
        weather services report RH over water, also below 0 °C.

    Returns
    -------
    pandas.DataFrame
        A copy with the new column(s); ``attrs`` updated (``units``, ``averaged`` when
        both parents are interval averages, ``derived``).

    Raises
    ------
    heritage_bayes.errors.DataError
        When neither (``Te``, ``RHe``) nor (``Ti``, ``RHi``) is present, or one of the
        target columns already exists.

    Notes
    -----
    :math:`p_v = \\varphi/100 \\cdot p_{sat}(T)` with the IAPWS saturation pressure
    (:mod:`heritage_bayes.climate.psychro`). A NaN in T or RH gives NaN. ``Pi`` is NaN
    where ``RHi`` is at or above :data:`RH_SENSOR_CEILING` (a censored reading); ``Pe``,
    a model input, keeps outdoor readings at saturation (fog: the air is saturated).
    """
    if over not in ("water", "ice", "auto"):
        raise InputError(f"over must be 'water', 'ice' or 'auto' (got {over!r})")
    todo = {p: pair for p, pair in _PAIRS.items() if all(c in frame.columns for c in pair)}
    source = frame.attrs.get("source", "frame")
    if not todo:
        raise DataError(
            f"{source}: cannot derive vapour pressure: need ('Te', 'RHe') or ('Ti', 'RHi'); "
            f"columns are: {', '.join(map(repr, frame.columns))}"
        )
    clash = [p for p in todo if p in frame.columns]
    if clash:
        raise DataError(f"{source}: column(s) {clash} already present; drop them first")
    out = frame.copy()
    attrs = dict(frame.attrs)
    averaged = tuple(attrs.get("averaged", ()))
    units = dict(attrs.get("units", {}))
    derived = dict(attrs.get("derived", {}))
    for p, (t, rh) in todo.items():
        phi = frame[rh].to_numpy(float)
        out[p] = vapour_pressure(frame[t].to_numpy(float), phi, over=over)
        units[p] = "Pa"
        derived[p] = f"vapour_pressure({t}, {rh}, over={over!r})"
        if p == "Pi":
            with np.errstate(invalid="ignore"):
                out.loc[phi >= RH_SENSOR_CEILING, p] = np.nan
            derived[p] += f", NaN where {rh} >= {RH_SENSOR_CEILING:g} %"
        if t in averaged and rh in averaged:
            averaged = (*averaged, p)
        elif (t in averaged) != (rh in averaged):
            raise DataError(
                f"{source}: {t!r} and {rh!r} differ in timing (one interval average, one "
                f"instantaneous); cannot derive {p!r} row by row"
            )
    attrs.update(units=units, averaged=averaged, derived=derived)
    out.attrs = attrs
    return out
