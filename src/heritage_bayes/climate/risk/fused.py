r"""Every indicator of :func:`~heritage_bayes.climate.risk.assess_batch` in one compiled
pass per series: :func:`assess_fused`, and the plan that compiled callers use.

:func:`~heritage_bayes.climate.risk.assess_batch` evaluates each indicator with numpy
over the whole (draws × hours) block: a few dozen temporaries of that size, each
written and read once; on 30 years of hours that is memory traffic more than
arithmetic. Here each series is reduced by one compiled function
(:func:`heritage_bayes.climate.risk._fused.series_indicators`) that walks the hours in
blocks of 512 (the temporaries stay in the CPU cache), with vectorised exp/log, and the
draws run in parallel (numba ``prange``).

Results: the same table as :func:`~heritage_bayes.climate.risk.assess_batch` (same
columns, units, order, dtypes). The moving averages, annual means, comparisons, EMC,
VTT recursion and EN 15757 percentiles are the same arithmetic bit for bit; the
lifetime multipliers and the TWPI differ by rounding only (vectorised exp/log within
2 ulp, summation order): relative differences below 1e-12, checked in
``tests/test_fused_risk.py``. Series with a missing hour, or that
:func:`~heritage_bayes.climate.risk.assess_batch` would reject, are handed to
:func:`~heritage_bayes.climate.risk.assess_batch` itself (same NaN policy, same errors).

The plan (:func:`fused_plan`) turns the options of :func:`assess` into small arrays, once;
:meth:`FusedPlan.workspace` gives the work arrays of each parallel slot (about five
arrays of the series length per slot, whatever the number of draws).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numba
import numpy as np
import pandas as pd
from numba import njit, prange

from heritage_bayes.climate import _vecmath
from heritage_bayes.climate._vecmath import stamp_cache
from heritage_bayes.climate.risk import _fused as k
from heritage_bayes.climate.risk._inputs import HOURS_PER_YEAR, Hourly
from heritage_bayes.climate.risk.assess import (
    _check_year,
    _prepare_assess,
    _resolve_groups,
    _unit,
    assess_batch,
)
from heritage_bayes.climate.risk.chemical import R_GAS
from heritage_bayes.climate.risk.indicators import FAMILIES, LAYOUT, shared_seasonal
from heritage_bayes.climate.risk.registry import indicator_info, resolve_options, years_of
from heritage_bayes.climate.risk.standards import _window_half
from heritage_bayes.errors import InputError

__all__ = ["FusedPlan", "NumpyPass", "assess_fused", "fused_plan", "projection_plan"]


@dataclass(frozen=True)
class FusedPlan:
    """The resolved options of :func:`assess` as arrays for the compiled kernel.

    Attributes
    ----------
    n_hours : int
        Length of the series the plan is for. [h]
    columns : tuple of str
        Indicator names, in the order of :func:`assess_batch`.
    class_names : tuple of str
        ASHRAE classes (``ashrae_best_class`` is an index into them, -1 for none).
    arrays : tuple of numpy.ndarray
        ``(ea_r, fpar, ipar, kinds, cls)``: the kernel's parameters.
    pad : int
        Periodic padding of the moving averages (``edges="wrap"``). [h]
    """

    n_hours: int
    columns: tuple[str, ...]
    class_names: tuple[str, ...]
    arrays: tuple
    pad: int

    @property
    def width(self) -> int:
        """Number of indicator columns."""
        return len(self.columns)

    def workspace(self, slots: int) -> tuple:
        """Work arrays of ``slots`` parallel slots: ``(ws, tmp, btmp, hist)``.

        ``5 × (n_hours + 2 pad + 1)`` doubles per slot (10.5 MB for 262 770 h).
        """
        L = self.n_hours + 2 * self.pad + 1
        return (
            np.empty((slots, 5, L)),
            np.empty((slots, 3, k.BLOCK)),
            np.empty((slots, 4, k.BLOCK), np.uint8),
            np.empty((slots, k.N_BINS), np.int64),
        )

    def frame(self, values: np.ndarray) -> pd.DataFrame:
        """(draws, width) kernel output → the DataFrame of :func:`assess_batch`."""
        d = values.shape[0]
        cols = {}
        for j, name in enumerate(self.columns):
            if name == "ashrae_best_class":
                names = np.array([*self.class_names, "none"], dtype=object)
                v = values[:, j]  # NaN: not computed (a measure's noise-free pass)
                idx = np.where(np.isfinite(v), v, -1.0).astype(np.int64)
                cols[name] = names[np.where(idx < 0, len(self.class_names), idx)]
            else:
                cols[name] = values[:, j].copy()
        df = pd.DataFrame(cols, index=pd.RangeIndex(d, name="draw"))
        df.attrs["units"] = {c: _unit(c) for c in self.columns}
        return df

    def values(self, df: pd.DataFrame) -> np.ndarray:
        """The inverse of :meth:`frame`: a table of :func:`assess_batch` → (draws, width)."""
        out = np.empty((len(df), self.width))
        for j, name in enumerate(self.columns):
            if name == "ashrae_best_class":
                pos = {c: i for i, c in enumerate(self.class_names)}
                out[:, j] = [pos.get(str(v), -1) for v in df[name]]
            else:
                out[:, j] = df[name].to_numpy(dtype=float)
        return out


def _kinds_and_table(classes, method):
    kinds = np.zeros((max(len(classes), 1), 2), np.int64)
    cls = np.zeros((max(len(classes), 1), k.N_CLS))
    for j, c in enumerate(classes):
        for v, (short, (down, up)) in enumerate(
            ((c.T_short, c.T_season), (c.RH_short, c.RH_season))
        ):
            if short is None:
                kinds[j, v] = k.K_NONE
            elif method == "setpoint":
                kinds[j, v] = k.K_SETPOINT
            elif down == 0.0 and up == 0.0:
                kinds[j, v] = k.K_MEAN
            else:
                kinds[j, v] = k.K_SEASON
        nan = math.nan
        cls[j] = (
            nan if c.T_short is None else float(c.T_short),
            float(c.T_season[0]),
            float(c.T_season[1]),
            float(c.T_season_max),
            float(c.T_max),
            nan if c.RH_short is None else float(c.RH_short),
            float(c.RH_season[0]),
            float(c.RH_season[1]),
            float(c.RH_range[0]),
            float(c.RH_range[1]),
        )
    return kinds, cls


def _plan(func, n, groups, opts) -> FusedPlan:
    _check_year(func, groups, n)
    ipar, fpar = LAYOUT.arrays()
    shared = shared_seasonal(groups, opts)
    if shared:
        _window_half("assess", opts["ashrae"]["window_days"], n)
    cols: list[str] = []
    pad = 0
    for fam in FAMILIES:  # each family's parameters, by name
        if fam.name not in groups or not fam.compiled:
            continue
        ints, floats, fam_pad = fam.plan(opts, n, shared)
        ipar[LAYOUT.i(fam.name)] = 1
        for name, v in ints.items():
            ipar[LAYOUT.i(f"{fam.name}.{name}")] = v
        for name, v in floats.items():
            fpar[LAYOUT.f(f"{fam.name}.{name}")] = v
        pad = max(pad, fam_pad)
        cols += fam.columns(opts)
    ea_r = np.array([Ea / R_GAS for Ea in opts["lm"]["Ea"].values()])
    a = opts["ashrae"]
    classes = tuple(a["classes"])
    kinds, cls = _kinds_and_table(classes, a["method"])
    return FusedPlan(
        n_hours=int(n),
        columns=tuple(cols),
        class_names=tuple(c.name for c in classes),
        arrays=(ea_r, fpar, ipar, kinds, cls),
        pad=int(pad),
    )


def fused_plan(
    n_hours: int,
    *,
    indicators=None,
    lm=None,
    emc=None,
    vtt=None,
    isopleth=None,
    ashrae=None,
    en15757=None,
    func: str = "assess_fused",
    **more,
) -> FusedPlan:
    """Resolve and check the options of :func:`assess` for series of ``n_hours`` hours.

    Parameters
    ----------
    n_hours : int
        Length of the series. [h]
    indicators, lm, emc, vtt, isopleth, ashrae, en15757, **more
        As in :func:`assess` (defaults resolved the same way, unknown keys rejected);
        by default the compiled families only, and a family without a compiled pass is
        refused by name.
    func : str
        Name used in error messages.

    Returns
    -------
    FusedPlan

    Raises
    ------
    heritage_bayes.errors.InputError
        As :func:`assess_batch`: bad options, a series shorter than a year for the
        yearly groups, a moving-average window longer than the series.
    """
    options = dict(
        lm=lm, emc=emc, vtt=vtt, isopleth=isopleth, ashrae=ashrae, en15757=en15757, **more
    )
    groups = _resolve_groups(func, indicators)
    numpy_only = [g for g in groups if g not in _compiled()]
    if indicators is None:
        groups = tuple(g for g in groups if g not in numpy_only)
    elif numpy_only:
        raise InputError(
            f"{func}: the indicators {numpy_only} have no compiled pass (numpy only: "
            f"assess, assess_batch, assess_fused); compiled: {_compiled()}"
        )
    opts = resolve_options(func, options)
    return _plan(func, int(n_hours), groups, opts)


@dataclass(frozen=True)
class NumpyPass:
    """The selected families without a compiled pass, computed with their numpy
    ``compute`` on series a compiled caller kept (the projection).

    Attributes
    ----------
    families : tuple of Family
        In registry order (their columns follow the compiled ones).
    opts : dict
        The resolved options of every family.
    nan_policy : str
        As in :func:`~heritage_bayes.climate.risk.assess`.
    """

    families: tuple
    opts: dict
    nan_policy: str = "propagate"

    def __bool__(self) -> bool:
        return bool(self.families)

    @property
    def columns(self) -> tuple[str, ...]:
        """Their columns, in order."""
        return tuple(c for f in self.families for c in f.columns(self.opts))

    @property
    def annual_columns(self) -> tuple[str, ...]:
        """Their columns a projection also reports per complete year (``per_year``)."""
        return tuple(c for c in self.columns if indicator_info(c).per_year)

    def values(self, T: np.ndarray, RH: np.ndarray) -> dict[str, np.ndarray]:
        """Column → values (draws,) of the (draws, hours) series ``T`` [°C], ``RH`` [%]."""
        h = Hourly(T=T, RH=RH, index=None, ndim=2)
        out: dict = {}
        for fam in self.families:
            out.update(fam.compute(h, self.opts, self.nan_policy, None))
        return out

    def annual(self, T: np.ndarray, RH: np.ndarray) -> np.ndarray:
        """(draws, years, len(annual_columns)): :attr:`annual_columns` of each complete
        year (blocks of 8760 h from the start; one block of the whole series when it
        holds 8736–8759 h, as the compiled per-year values)."""
        n = T.shape[1]
        ny, names = years_of(n), self.annual_columns
        out = np.full((T.shape[0], ny, len(names)), np.nan)
        L = min(n, HOURS_PER_YEAR)
        for y in range(ny if names else 0):
            sl = slice(y * L, (y + 1) * L)
            v = self.values(T[:, sl], RH[:, sl])
            for j, c in enumerate(names):
                out[:, y, j] = v[c]
        return out


def projection_plan(
    n_hours: int, *, indicators=None, nan_policy="propagate", func="assess_batch", **options
) -> tuple[FusedPlan, NumpyPass]:
    """The plan of the compiled families and the families without a compiled pass, for
    series of ``n_hours`` hours (a caller that runs the compiled pass on its own series
    and the numpy ``compute`` of the others on the same series).

    Parameters are those of :func:`fused_plan`; ``indicators`` may name any family
    (default: every registered one).

    Returns
    -------
    FusedPlan, NumpyPass

    Raises
    ------
    heritage_bayes.errors.InputError
        As :func:`fused_plan`.
    """
    groups = _resolve_groups(func, indicators)
    _check_year(func, groups, int(n_hours))
    opts = resolve_options(func, options)
    compiled = tuple(g for g in groups if g in _compiled())
    plan = _plan(func, int(n_hours), compiled, opts)
    rest = tuple(f for f in FAMILIES if f.name in groups and not f.compiled)
    return plan, NumpyPass(rest, opts, nan_policy)


def _compiled() -> list[str]:
    return [f.name for f in FAMILIES if f.compiled]


@njit(parallel=True, cache=True)
def _batch(
    T, RH, ea_r, fpar, ipar, kinds, cls, ws, tmp, btmp, hist, out, status
):  # pragma: no cover
    d, n = T.shape
    slots = ws.shape[0]
    for s in prange(slots):
        for i in range(s, d, slots):
            status[i] = k.series_indicators(
                T[i], RH[i], n, ea_r, fpar, ipar, kinds, cls, ws[s], tmp[s], btmp[s],
                hist[s], out[i],
            )  # fmt: skip


stamp_cache(globals(), k, _vecmath)


def assess_fused(
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
    **more,
):
    r"""All indicators for many series at once, one compiled pass per series.

    Parameters
    ----------
    T : array_like
        Hourly air temperature, shape (draws, hours), or (hours,) shared by all draws of
        ``RH``. [°C]
    RH : array_like
        Hourly relative humidity, shape (draws, hours), or (hours,) shared. [%]
    indicators, nan_policy, lm, emc, vtt, isopleth, ashrae, en15757, **more
        As in :func:`assess`.

    Returns
    -------
    pandas.DataFrame
        The table of :func:`assess_batch`: one row per draw, one column per indicator,
        units in ``df.attrs["units"]``.

    Raises
    ------
    heritage_bayes.errors.InputError
        As :func:`assess_batch`.

    Notes
    -----
    Same values as :func:`assess_batch` up to rounding (see the module docstring);
    draws with a missing hour are computed by :func:`assess_batch`. Uses the numba
    threads (``numba.set_num_threads``); five work arrays of the series length per
    thread, whatever the number of draws.
    """
    func = "assess_fused"
    options = dict(
        lm=lm, emc=emc, vtt=vtt, isopleth=isopleth, ashrae=ashrae, en15757=en15757, **more
    )
    h, groups, opts = _prepare_assess(func, T, RH, indicators, nan_policy, options)
    Tc = np.ascontiguousarray(h.T, dtype=float)
    RHc = np.ascontiguousarray(h.RH, dtype=float)
    d, n = Tc.shape
    plan = _plan(func, n, groups, opts)
    slots = max(1, min(numba.get_num_threads(), d))
    values = np.empty((d, plan.width))
    status = np.zeros(d, np.int64)
    _batch(Tc, RHc, *plan.arrays, *plan.workspace(slots), values, status)
    redo = np.flatnonzero(status)
    if redo.size:
        ref = assess_batch(Tc[redo], RHc[redo], indicators=indicators, nan_policy=nan_policy,
                           **options)  # fmt: skip
        values[redo] = plan.values(ref)
    df = plan.frame(values)
    for fam in FAMILIES:  # families without a compiled pass: numpy, on the same series
        if fam.name in groups and not fam.compiled:
            h = Hourly(T=Tc, RH=RHc, index=None, ndim=2)
            for key, v in fam.compute(h, opts, nan_policy, None).items():
                df[key] = v
                df.attrs["units"][key] = _unit(key)
    return df
