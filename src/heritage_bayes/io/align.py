"""Alignment of weather (model inputs) and measurements (model outputs) on one UTC grid.

Grid convention (zero-order hold)
---------------------------------
The simulator advances ``x[k+1] = Ad x[k] + Bd u[k]`` with ``u[k]`` held constant over
``[t_k, t_k + step)``. Hence, in the aligned frame:

* an **input** column at row ``t_k`` is the **mean over** ``[t_k, t_k + step)``. An
  interval average stamped at its end (hour-ending irradiance stamped ``t_k + 1h``) is a
  piecewise-constant function on its interval and therefore lands on row ``t_k``; an
  instantaneous series (temperature readings) is interpolated linearly between readings
  and averaged over the bin (hourly readings on an hourly grid: ``(v(t_k) + v(t_k+1h))/2``);
* a **measurement** column at row ``t_k`` is the **instantaneous value at** ``t_k``,
  interpolated linearly between the two neighbouring readings when ``t_k`` falls between
  them (never across a missing reading). A measurement that is itself an interval average
  is taken as the instantaneous value at the middle of its interval.

Gap policy
----------
Input gaps (missing samples of the native series) up to ``max_gap`` are filled by
linear interpolation in time and every grid row that depends on a filled sample is
flagged in :attr:`Aligned.flags`. Longer input gaps inside the period raise a
:class:`~heritage_bayes.errors.DataError` listing them (restrict the period with
``start``/``end`` to avoid them), unless ``long_gaps="split"``: then they are filled
the same way only to keep the arrays finite, and every grid row that depends on one of
their samples is marked in :attr:`Aligned.breaks`; the caller splits the record there
into segments (no simulated value inside, a fresh initial state after). Measurement
gaps stay NaN (the likelihood masks them) and are listed in the report.
"""

from __future__ import annotations

from collections.abc import Iterable, Sequence
from dataclasses import dataclass

import numpy as np
import pandas as pd

from heritage_bayes.errors import DataError, InputError, quoted
from heritage_bayes.io._common import (
    AVERAGED_BY_DEFAULT,
    format_timedelta,
    modal_step,
)
from heritage_bayes.io.aligned import Aligned, AlignmentReport, Gap  # re-exported

__all__ = ["Aligned", "AlignmentReport", "Gap", "align"]

_NS = 1_000_000_000
_MAX_LISTED = 12


# ---------------------------------------------------------------------------------------
# Native series
# ---------------------------------------------------------------------------------------


@dataclass
class _Input:
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


def _frames(obj, role: str) -> list[pd.DataFrame]:
    if obj is None:
        return []
    frames = [obj] if isinstance(obj, pd.DataFrame) else list(obj)
    out = []
    for k, df in enumerate(frames):
        label = f"{role}[{k}]" if len(frames) > 1 else role
        if not isinstance(df, pd.DataFrame):
            raise InputError(f"{label} must be a pandas DataFrame (got {type(df).__name__})")
        if not isinstance(df.index, pd.DatetimeIndex) or df.index.tz is None:
            raise DataError(
                f"{label} ({df.attrs.get('source', 'frame')}): index must be a tz-aware "
                f"DatetimeIndex (the readers return UTC); found {type(df.index).__name__}"
                f"{'' if not isinstance(df.index, pd.DatetimeIndex) else ' without time zone'}"
            )
        if len(df) < 2:
            raise DataError(f"{label}: needs at least 2 rows, found {len(df)}")
        if not df.index.is_monotonic_increasing or df.index.has_duplicates:
            raise DataError(
                f"{label} ({df.attrs.get('source', 'frame')}): index must be increasing and unique"
            )
        non_numeric = [c for c in df.columns if not pd.api.types.is_numeric_dtype(df[c])]
        if non_numeric:
            raise DataError(f"{label}: non-numeric column(s) {non_numeric}")
        df = df.copy()
        df.index = df.index.tz_convert("UTC").as_unit("ns")
        out.append(df)
    return out


def _averaged_columns(df: pd.DataFrame, override: set[str] | None) -> set[str]:
    if override is not None:
        return {c for c in df.columns if c in override}
    if "averaged" in df.attrs:
        return {c for c in df.attrs["averaged"] if c in df.columns}
    return {c for c in AVERAGED_BY_DEFAULT if c in df.columns}


def _input_series(df: pd.DataFrame, label: str, averaged: set[str]) -> list[_Input]:
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
        out.append(_Input(col, label, times, values, delta, col in averaged))
    return out


# ---------------------------------------------------------------------------------------
# Exact bin means
# ---------------------------------------------------------------------------------------


def _bin_integrals(series: _Input, values: np.ndarray, edges: np.ndarray) -> np.ndarray:
    """Integral of the series over each bin [edges[k], edges[k+1]) [value·s], NaN-aware.

    Averaged: piecewise constant, ``values[j]`` on ``(t_j - delta, t_j]``.
    Instantaneous: linear interpolation between consecutive samples.
    """
    ref = edges[0]
    t = (series.times - ref) / _NS
    e = (edges - ref) / _NS
    d = series.delta / _NS
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


# ---------------------------------------------------------------------------------------
# align
# ---------------------------------------------------------------------------------------


def _timestamp(value, what: str) -> pd.Timestamp:
    try:
        ts = pd.Timestamp(value)
    except (ValueError, TypeError) as exc:
        raise InputError(
            f"{what} must be a date/time such as '2011-01-01' (got {value!r})"
        ) from exc
    if ts is pd.NaT:
        raise InputError(f"{what} must be a date/time (got {value!r})")
    return ts.tz_localize("UTC") if ts.tz is None else ts.tz_convert("UTC")


def _duration(value, what: str, *, allow_zero: bool) -> pd.Timedelta:
    try:
        td = pd.Timedelta(value)
    except (ValueError, TypeError) as exc:
        raise InputError(f"{what} must be a duration such as '1h' (got {value!r})") from exc
    if td is pd.NaT or td < pd.Timedelta(0) or (td == pd.Timedelta(0) and not allow_zero):
        raise InputError(f"{what} must be a positive duration (got {value!r})")
    return td


def align(
    weather: pd.DataFrame | Sequence[pd.DataFrame],
    measurements: pd.DataFrame | Sequence[pd.DataFrame] | None = None,
    step="1h",
    *,
    max_gap="6h",
    start=None,
    end=None,
    averaged: Iterable[str] | None = None,
    long_gaps: str = "raise",
) -> Aligned:
    """Put weather (inputs) and measurements (outputs) on one regular UTC grid.

    Parameters
    ----------
    weather : DataFrame or sequence of DataFrames
        Model inputs, e.g. a reader's output and the output of
        :func:`heritage_bayes.climate.surface_irradiance`. Each table needs a tz-aware
        index on a regular grid of its own spacing (rows may be missing); its
        ``attrs["averaged"]`` and ``attrs["interval"]`` say which columns are interval
        averages stamped at the interval end (default: ``ghi``, ``dni``, ``dhi``).
    measurements : DataFrame or sequence of DataFrames, optional
        Model outputs (e.g. ``Ti``, ``RHi``, ``Pi``), any spacing, gaps allowed. Omit for
        inputs only (simulation with future weather).
    step : str or Timedelta, default "1h"
        Grid spacing. The grid is anchored on multiples of ``step`` since 1970-01-01
        UTC (whole hours for ``"1h"``) unless ``start`` is given.
    max_gap : str or Timedelta, default "6h"
        Longest input gap that is filled by interpolation (``"0h"``: none).
    start, end : str or Timestamp, optional
        Period ``[start, end)``; naive values are UTC. Default: the longest period
        covered by every input column and by the measurements.
    averaged : iterable of str, optional
        Override the interval-average columns of all tables (names of input or output
        columns); the other columns are instantaneous.
    long_gaps : {"raise", "split"}, default "raise"
        Input gaps longer than ``max_gap``: an error, or bridged by interpolation and
        marked as breaks (:attr:`Aligned.breaks`) where the record splits into segments.

    Returns
    -------
    Aligned
        ``.frame``, ``.flags``, ``.report`` (see :class:`AlignmentReport`), ``.inputs``,
        ``.outputs``.

    Raises
    ------
    heritage_bayes.errors.DataError
        Input gaps longer than ``max_gap`` inside the period (all listed), a period not
        covered by the inputs, irregular weather timestamps, clashing column names.

    Notes
    -----
    With ``F`` the integral of a piecewise-constant (averages) or piecewise-linear
    (instantaneous) reconstruction of the native input series, the value of row ``k`` is
    :math:`u_k = (F(t_k + \\Delta t) - F(t_k)) / \\Delta t`, exact for any ratio of native
    spacing to ``step`` and any phase. Outputs are sampled at the instants ``t_k``.
    """
    step = _duration(step, "step", allow_zero=False)
    max_gap = _duration(max_gap, "max_gap", allow_zero=True)
    if long_gaps not in ("raise", "split"):
        raise InputError(f"long_gaps must be 'raise' or 'split' (got {long_gaps!r})")
    override = None
    if averaged is not None:
        override = {averaged} if isinstance(averaged, str) else set(averaged)
    wframes = _frames(weather, "weather")
    if not wframes:
        raise InputError("weather: at least one table of inputs is required")
    mframes = _frames(measurements, "measurements")
    names = [c for df in wframes + mframes for c in df.columns]
    dupes = sorted({c for c in names if names.count(c) > 1})
    if dupes:
        raise DataError(f"column(s) {dupes} appear in more than one table; rename them")
    if override is not None:
        unknown = sorted(override - set(names))
        if unknown:
            raise InputError(f"averaged: unknown column(s) {unknown}; columns are {names}")

    # -- native inputs -------------------------------------------------------------------
    inputs: list[_Input] = []
    sources: list[dict] = []
    for k, df in enumerate(wframes):
        label = df.attrs.get("source", f"weather[{k}]")
        avg = _averaged_columns(df, override)
        inputs.extend(_input_series(df, f"weather {label}", avg))
        sources.append(_source_note(df, "weather", avg, modal_step(df.index)))

    # -- native outputs ------------------------------------------------------------------
    outputs: list[tuple[str, np.ndarray, np.ndarray, int]] = []  # name, t ns, v, delta
    for df in mframes:
        avg = _averaged_columns(df, override)
        mstep = modal_step(df.index)
        interval = pd.Timedelta(df.attrs.get("interval") or mstep)
        sources.append(_source_note(df, "measurements", avg, mstep))
        for col in df.columns:
            s = df[col].dropna()
            t = s.index.asi8.copy()
            if col in avg:
                t = t - interval.value // 2
            outputs.append((col, t, s.to_numpy(dtype=float), int(mstep.value)))

    # -- period --------------------------------------------------------------------------
    cov = {s.name: s.coverage() for s in inputs}
    cov_lo = max(c[0] for c in cov.values())
    cov_hi = min(c[1] for c in cov.values())
    step_ns = int(step.value)
    if start is not None:
        s0 = _timestamp(start, "start").value
    else:
        s0 = cov_lo
        firsts = [o[1][0] for o in outputs if o[1].size]
        if firsts:
            s0 = max(s0, min(firsts))
        s0 = -((-s0) // step_ns) * step_ns  # ceil to the grid
    if end is not None:
        e0 = _timestamp(end, "end").value
    else:
        e0 = cov_hi
        lasts = [o[1][-1] for o in outputs if o[1].size]
        if lasts:
            e0 = min(e0, max(lasts) + step_ns)
    n_rows = (e0 - s0) // step_ns
    if n_rows < 1:
        raise DataError(
            f"empty period: start {_fmt(s0)} is not at least one step ({format_timedelta(step)}) "
            f"before end {_fmt(e0)}; the inputs cover {_fmt(cov_lo)} to {_fmt(cov_hi)}"
            + (" and the measurements do not overlap them" if outputs else "")
        )
    e0 = s0 + n_rows * step_ns
    short = [(n, c) for n, c in cov.items() if c[0] > s0 or c[1] < e0]
    if short:
        lines = "; ".join(f"{n} covers {_fmt(c[0])} to {_fmt(c[1])}" for n, c in short)
        raise DataError(
            f"the period {_fmt(s0)} to {_fmt(e0)} is not covered by every input: {lines}. "
            f"Choose start/end inside the inputs' coverage"
        )
    edges = s0 + np.arange(n_rows + 1, dtype=np.int64) * step_ns

    # -- input gaps, filling, bin means --------------------------------------------------
    gaps: list[Gap] = []
    too_long: list[Gap] = []
    frame_cols: dict[str, np.ndarray] = {}
    flag_cols: dict[str, np.ndarray] = {}
    interpolated: dict[str, int] = {}
    slope_cols: dict[str, np.ndarray] = {}
    breaks = np.zeros(n_rows, dtype=bool)
    for s in inputs:
        values = s.values.copy()
        filled = np.zeros(values.size)
        bridged = np.zeros(values.size)
        for a, b in s.runs():
            if not s.affects(a, b, s0, e0):
                continue
            n = b - a + 1
            gap = Gap(
                s.name,
                pd.Timestamp(s.times[a], tz="UTC"),
                pd.Timestamp(s.times[b], tz="UTC"),
                n,
                pd.Timedelta(n * s.delta, unit="ns"),
                n * s.delta <= max_gap.value,
            )
            if not gap.filled and long_gaps == "raise":
                too_long.append(gap)
                continue
            gaps.append(gap)
            x = s.times[a - 1 : b + 2].astype(float)
            values[a : b + 1] = np.interp(x[1:-1], x[[0, -1]], values[[a - 1, b + 1]])
            (filled if gap.filled else bridged)[a : b + 1] = 1.0
        if bridged.any():
            breaks |= _bin_integrals(s, bridged, edges) > 1e-9
        interpolated[s.name] = int(filled.sum())
        frame_cols[s.name] = _bin_integrals(s, values, edges) / (step_ns / _NS)
        slope_cols[s.name] = _slopes(s, values, edges)
        flag_cols[s.name] = _bin_integrals(s, filled, edges) > 1e-9
    if too_long:
        listed = "\n  ".join(str(g) for g in too_long[:_MAX_LISTED])
        more = (
            f"\n  ... and {len(too_long) - _MAX_LISTED} more" if len(too_long) > _MAX_LISTED else ""
        )
        raise DataError(
            f"{len(too_long)} input gap(s) longer than max_gap={format_timedelta(max_gap)} in "
            f"the period {_fmt(s0)} to {_fmt(e0)}:\n  {listed}{more}\nInputs cannot be left "
            f"missing (the simulation needs every step): restrict the period with start=/end= "
            f"to avoid the gaps, fill them upstream, or raise max_gap="
        )

    # -- outputs at the grid instants ----------------------------------------------------
    grid = edges[:-1]
    measurement_gaps: list[Gap] = []
    missing: dict[str, int] = {}
    for name, t, v, delta in outputs:
        col = _sample(t, v, grid, tol=1.5 * delta)
        frame_cols[name] = col
        flag_cols[name] = np.zeros(n_rows, dtype=bool)
        missing[name] = int(np.isnan(col).sum())
        for a, b in _nan_runs(col):
            n = b - a + 1
            measurement_gaps.append(
                Gap(
                    name,
                    pd.Timestamp(grid[a], tz="UTC"),
                    pd.Timestamp(grid[b], tz="UTC"),
                    n,
                    n * step,
                    False,
                )
            )

    index = pd.DatetimeIndex(pd.to_datetime(grid, unit="ns", utc=True), freq=step, name="time")
    frame = pd.DataFrame(frame_cols, index=index)
    flags = pd.DataFrame(flag_cols, index=index)
    in_names = tuple(s.name for s in inputs)
    out_names = tuple(o[0] for o in outputs)
    frame.attrs = {
        "units": {c: u for df in wframes + mframes for c, u in df.attrs.get("units", {}).items()},
        "step": format_timedelta(step),
        "inputs": in_names,
        "outputs": out_names,
        "convention": "inputs: mean over [t, t+step); outputs: value at t",
    }
    irr = [df.attrs["irradiance_source"] for df in wframes if "irradiance_source" in df.attrs]
    if irr:
        frame.attrs["irradiance_source"] = "; ".join(dict.fromkeys(irr))
    report = AlignmentReport(
        start=pd.Timestamp(s0, tz="UTC"),
        end=pd.Timestamp(e0, tz="UTC"),
        step=step,
        n_rows=int(n_rows),
        inputs=in_names,
        outputs=out_names,
        averaged_inputs=tuple(s.name for s in inputs if s.averaged),
        max_gap=max_gap,
        # distinct time stamps: tables derived from one record (its facade irradiance)
        # share its rows and are not counted twice
        rows_in={
            "weather": int(_stamps(wframes).size),
            "measurements": int(_stamps(mframes).size),
        },
        rows_dropped={
            "weather": _outside(_stamps(wframes), s0, e0),
            "measurements": _outside(_stamps(mframes), s0, e0),
        },
        interpolated=interpolated,
        flagged_rows={k: int(flag_cols[k].sum()) for k in in_names},
        input_gaps=gaps,
        measurement_gaps=measurement_gaps,
        measurement_missing=missing,
        sources=sources,
    )
    slopes = pd.DataFrame({k: slope_cols[k] for k in in_names}, index=index)
    return Aligned(frame, flags, report, in_names, out_names, slopes, breaks)


def _slopes(series: _Input, values: np.ndarray, edges: np.ndarray) -> np.ndarray:
    """Change of an instantaneous input over each bin, ``u(edges[k+1]) - u(edges[k])``,
    on its linear interpolation between samples; zero for an interval mean (constant
    over its interval: the zero-order hold of its bin mean is exact)."""
    n = edges.size - 1
    if series.averaged:
        return np.zeros(n)
    ok = ~np.isnan(values)
    at = np.interp(edges.astype(float), series.times[ok].astype(float), values[ok])
    return np.diff(at)


def _fmt(ns: int) -> str:
    return f"{pd.Timestamp(ns, tz='UTC'):%Y-%m-%d %H:%M} UTC"


def _stamps(frames: Sequence[pd.DataFrame]) -> np.ndarray:
    """The distinct time stamps [ns] of a role's tables."""
    if not frames:
        return np.empty(0, dtype=np.int64)
    return np.unique(np.concatenate([df.index.asi8 for df in frames]))


def _outside(t: np.ndarray, lo: int, hi: int) -> int:
    return int(((t < lo) | (t > hi)).sum())


def _source_note(df: pd.DataFrame, role: str, avg: set[str], spacing) -> dict:
    note = {
        "role": role,
        "source": df.attrs.get("source", None),
        "columns": list(df.columns),
        "averaged": sorted(avg),
        "spacing": format_timedelta(spacing) if spacing is not None else None,
    }
    for key in ("dropped", "clipped", "irradiance_source", "timezone"):
        if key in df.attrs:
            note[key] = df.attrs[key]
    return note


def _sample(t: np.ndarray, v: np.ndarray, grid: np.ndarray, tol: float) -> np.ndarray:
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


def _nan_runs(x: np.ndarray) -> list[tuple[int, int]]:
    nan = np.isnan(x).astype(np.int8)
    edges = np.diff(np.concatenate([[0], nan, [0]]))
    return list(
        zip(
            np.flatnonzero(edges == 1).tolist(),
            (np.flatnonzero(edges == -1) - 1).tolist(),
            strict=True,
        )
    )
