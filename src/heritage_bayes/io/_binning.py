"""The numerics of :func:`~heritage_bayes.io.align.align`: native input series, their
exact means over the grid's bins, and outputs sampled at the grid instants.

A native input series is regular (missing rows as NaN). An interval average stamped at
its interval end is piecewise constant, ``v_j`` on ``(t_j - delta, t_j]``; an
instantaneous series is piecewise linear between its samples. With ``F`` the integral of
that reconstruction, the mean over the bin ``[t_k, t_k + step)`` is
``(F(t_k + step) - F(t_k)) / step``, exact for any ratio of native spacing to ``step``
and any phase.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import pandas as pd

from heritage_bayes.errors import DataError, quoted
from heritage_bayes.io._common import format_timedelta, modal_step

NS = 1_000_000_000  # nanoseconds per second

__all__ = [
    "NS",
    "NativeSeries",
    "bin_integrals",
    "bin_slopes",
    "input_series",
    "nan_runs",
    "sample_at",
]


@dataclass
class NativeSeries:
    """One input column on its own regular grid, missing rows as NaN.

    ``times`` [ns UTC] are regular with spacing ``delta`` [ns]; an ``averaged`` series
    holds interval means stamped at the interval end, the others instantaneous values.
    """

    name: str
    source: str
    times: np.ndarray  # int64 ns, regular, step delta
    values: np.ndarray  # float, NaN = missing
    delta: int  # ns
    averaged: bool

    @property
    def first_valid(self) -> int:
        return int(np.flatnonzero(~np.isnan(self.values))[0])

    @property
    def last_valid(self) -> int:
        return int(np.flatnonzero(~np.isnan(self.values))[-1])

    def coverage(self) -> tuple[int, int]:
        lo = self.times[self.first_valid] - (self.delta if self.averaged else 0)
        return int(lo), int(self.times[self.last_valid])

    def runs(self) -> list[tuple[int, int]]:
        """Inclusive index ranges of NaN runs strictly inside the valid span."""
        missing = np.isnan(self.values)
        fv, lv = self.first_valid, self.last_valid
        inner = missing[fv : lv + 1].astype(np.int8)
        edges = np.diff(np.concatenate([[0], inner, [0]]))
        starts = np.flatnonzero(edges == 1)
        ends = np.flatnonzero(edges == -1) - 1
        return [(int(a) + fv, int(b) + fv) for a, b in zip(starts, ends, strict=True)]

    def affects(self, a: int, b: int, start: int, end: int) -> bool:
        """Does the missing run a..b change any bin of ``[start, end)``?"""
        lo = self.times[a] - self.delta
        hi = self.times[b] + (0 if self.averaged else self.delta)
        return lo < end and hi > start


def input_series(df: pd.DataFrame, label: str, averaged: set[str]) -> list[NativeSeries]:
    """The columns of one weather table as native series on the table's modal spacing.

    Raises
    ------
    heritage_bayes.errors.DataError
        An averaging interval other than the spacing, a timestamp off the regular grid, a
        column without values.
    """
    idx = df.index.asi8
    step = modal_step(df.index)
    delta = int(step.value)
    interval = df.attrs.get("interval")
    if averaged and interval is not None and pd.Timedelta(interval).value != delta:
        raise DataError(
            f"{label}: averaging interval {interval} differs from the spacing of the "
            f"timestamps {format_timedelta(step)}; resample the table first"
        )
    off = (idx - idx[0]) % delta
    if off.any():
        i = int(np.flatnonzero(off)[0])
        raise DataError(
            f"{label}: weather timestamps must lie on a regular grid of "
            f"{format_timedelta(step)}; row {i} ({df.index[i]}) is off the grid"
        )
    n = int((idx[-1] - idx[0]) // delta) + 1
    pos = (idx - idx[0]) // delta
    times = idx[0] + np.arange(n, dtype=np.int64) * delta
    out = []
    for col in df.columns:
        values = np.full(n, np.nan)
        values[pos] = df[col].to_numpy(dtype=float)
        if np.isnan(values).all():
            raise DataError(f"{label}: input column {quoted(col)} has no values")
        out.append(NativeSeries(col, label, times, values, delta, col in averaged))
    return out


def bin_integrals(series: NativeSeries, values: np.ndarray, edges: np.ndarray) -> np.ndarray:
    """Integral of the series over each bin [edges[k], edges[k+1]) [value·s], NaN-aware.

    Averaged: piecewise constant, ``values[j]`` on ``(t_j - delta, t_j]``.
    Instantaneous: linear interpolation between consecutive samples.
    """
    ref = edges[0]
    t = (series.times - ref) / NS
    e = (edges - ref) / NS
    d = series.delta / NS
    nan = np.isnan(values)
    v = np.where(nan, 0.0, values)
    if series.averaged:
        knots = np.concatenate([[t[0] - d], t])
        F = np.concatenate([[0.0], np.cumsum(v * d)])
        G = np.concatenate([[0.0], np.cumsum(nan * d)])
        Fe = np.interp(e, knots, F)
        Ge = np.interp(e, knots, G)
    else:
        dt = np.diff(t)
        seg_nan = (nan[:-1] | nan[1:]).astype(float)
        F = np.concatenate([[0.0], np.cumsum(0.5 * (v[:-1] + v[1:]) * dt)])
        G = np.concatenate([[0.0], np.cumsum(seg_nan * dt)])
        j = np.clip(np.searchsorted(t, e, side="right") - 1, 0, t.size - 2)
        h = e - t[j]
        slope = (v[j + 1] - v[j]) / dt[j]
        Fe = F[j] + v[j] * h + 0.5 * slope * h * h
        Ge = G[j] + seg_nan[j] * h
    integral = np.diff(Fe)
    missing = np.diff(Ge) > 1e-9 * d
    integral[missing] = np.nan
    return integral


def bin_slopes(series: NativeSeries, values: np.ndarray, edges: np.ndarray) -> np.ndarray:
    """Change of an instantaneous input over each bin, ``u(edges[k+1]) - u(edges[k])``,
    on its linear interpolation between samples; zero for an interval mean (constant
    over its interval: the zero-order hold of its bin mean is exact)."""
    n = edges.size - 1
    if series.averaged:
        return np.zeros(n)
    ok = ~np.isnan(values)
    at = np.interp(edges.astype(float), series.times[ok].astype(float), values[ok])
    return np.diff(at)


def sample_at(t: np.ndarray, v: np.ndarray, grid: np.ndarray, tol: float) -> np.ndarray:
    """Linear interpolation of (t, v) at ``grid`` between neighbours at most ``tol`` apart."""
    out = np.full(grid.size, np.nan)
    if t.size == 0:
        return out
    pos = np.searchsorted(t, grid, side="left")
    inside = pos < t.size
    exact = inside.copy()
    exact[inside] = t[pos[inside]] == grid[inside]
    out[exact] = v[pos[exact]]
    a = pos - 1
    between = ~exact & (a >= 0) & inside
    ai, bi = a[between], pos[between]
    span = (t[bi] - t[ai]).astype(float)
    ok = span <= tol
    w = (grid[between] - t[ai]) / span
    vals = v[ai] + w * (v[bi] - v[ai])
    idx = np.flatnonzero(between)
    out[idx[ok]] = vals[ok]
    return out


def nan_runs(x: np.ndarray) -> list[tuple[int, int]]:
    """Inclusive index ranges ``(first, last)`` of the runs of NaN in ``x``."""
    nan = np.isnan(x).astype(np.int8)
    edges = np.diff(np.concatenate([[0], nan, [0]]))
    return list(
        zip(
            np.flatnonzero(edges == 1).tolist(),
            (np.flatnonzero(edges == -1) - 1).tolist(),
            strict=True,
        )
    )
