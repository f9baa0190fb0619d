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

import numpy as np
import pandas as pd

from heritage_bayes.errors import DataError, InputError
from heritage_bayes.io._binning import (
    NS,
    NativeSeries,
    bin_integrals,
    bin_slopes,
    input_series,
    nan_runs,
    sample_at,
)
from heritage_bayes.io._common import (
    AVERAGED_BY_DEFAULT,
    format_timedelta,
    modal_step,
)
from heritage_bayes.io.aligned import Aligned, AlignmentReport, Gap  # re-exported

__all__ = ["Aligned", "AlignmentReport", "Gap", "align"]

_MAX_LISTED = 12


# ---------------------------------------------------------------------------------------
# Tables
# ---------------------------------------------------------------------------------------


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
    step, max_gap, override, wframes, mframes = _check_tables(
        weather, measurements, step, max_gap, averaged, long_gaps
    )
    inputs, outputs, sources = _native_series(wframes, mframes, override)
    s0, e0, edges = _period(inputs, outputs, start, end, step)
    n_rows = edges.size - 1
    columns = _input_columns(inputs, edges, max_gap, long_gaps)
    frame_cols, flag_cols, interpolated, slope_cols, gaps, breaks = columns
    grid = edges[:-1]
    measurement_gaps, missing = _output_columns(outputs, grid, step, frame_cols, flag_cols)

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


# The steps of align, in order.


def _check_tables(weather, measurements, step, max_gap, averaged, long_gaps):
    """Validate :func:`align`'s options and tables.

    Returns
    -------
    step, max_gap : pandas.Timedelta
    override : set of str or None
        The ``averaged`` override as a set.
    wframes, mframes : list of pandas.DataFrame
        The weather and measurement tables on UTC nanosecond indexes.

    Raises
    ------
    heritage_bayes.errors.InputError
        Bad durations or ``long_gaps``, no weather table, unknown ``averaged`` columns.
    heritage_bayes.errors.DataError
        A column name in more than one table; a table that is not a time series.
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
    return step, max_gap, override, wframes, mframes


def _native_series(wframes, mframes, override):
    """The native input series and output samples, and a note on each source table.

    Returns
    -------
    inputs : list of NativeSeries
        One regular series per weather column (missing rows as NaN).
    outputs : list of (name, t [ns], values, spacing [ns])
        The valid samples of each measurement column; an interval-average column is
        stamped at the middle of its interval.
    sources : list of dict
        Weather notes, then measurement notes, for :attr:`AlignmentReport.sources`.
    """
    inputs: list[NativeSeries] = []
    sources: list[dict] = []
    for k, df in enumerate(wframes):
        label = df.attrs.get("source", f"weather[{k}]")
        avg = _averaged_columns(df, override)
        inputs.extend(input_series(df, f"weather {label}", avg))
        sources.append(_source_note(df, "weather", avg, modal_step(df.index)))
    outputs: list[tuple[str, np.ndarray, np.ndarray, int]] = []
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
    return inputs, outputs, sources


def _period(inputs, outputs, start, end, step) -> tuple[int, int, np.ndarray]:
    """The grid ``[s0, e0)`` [ns UTC] and its bin edges.

    Default start: the latest first instant covered by every input and the first
    measurement, rounded up to a multiple of ``step``; default end: the earliest last
    instant of the inputs and one step after the last measurement.

    Raises
    ------
    heritage_bayes.errors.DataError
        A period shorter than one step, or not covered by every input.
    """
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
    return s0, e0, s0 + np.arange(n_rows + 1, dtype=np.int64) * step_ns


def _input_columns(inputs, edges, max_gap, long_gaps):
    """Fill the input gaps and take each input's exact mean over every bin.

    A gap (missing run of native samples) that changes a bin of the period is filled by
    linear interpolation in time; up to ``max_gap`` it is a filled gap (its bins
    flagged), longer it is an error or, with ``long_gaps="split"``, bridged (its bins
    marked as breaks).

    Returns
    -------
    frame_cols, flag_cols, interpolated, slope_cols : dict by input name
        Bin means, filled-bin flags, count of filled samples, change over each bin.
    gaps : list of Gap
        The gaps filled or bridged.
    breaks : numpy.ndarray of bool
        Bins that depend on a bridged sample.

    Raises
    ------
    heritage_bayes.errors.DataError
        Gaps longer than ``max_gap`` with ``long_gaps="raise"`` (all listed, up to 12).
    """
    s0, e0 = int(edges[0]), int(edges[-1])
    step_ns = int(edges[1] - edges[0])
    gaps: list[Gap] = []
    too_long: list[Gap] = []
    frame_cols: dict[str, np.ndarray] = {}
    flag_cols: dict[str, np.ndarray] = {}
    interpolated: dict[str, int] = {}
    slope_cols: dict[str, np.ndarray] = {}
    breaks = np.zeros(edges.size - 1, dtype=bool)
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
            breaks |= bin_integrals(s, bridged, edges) > 1e-9
        interpolated[s.name] = int(filled.sum())
        frame_cols[s.name] = bin_integrals(s, values, edges) / (step_ns / NS)
        slope_cols[s.name] = bin_slopes(s, values, edges)
        flag_cols[s.name] = bin_integrals(s, filled, edges) > 1e-9
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
    return frame_cols, flag_cols, interpolated, slope_cols, gaps, breaks


def _output_columns(outputs, grid, step, frame_cols, flag_cols):
    """Sample each output at the grid instants (into ``frame_cols``, unflagged).

    Linear interpolation between the two neighbouring samples when they are at most 1.5
    native spacings apart; otherwise NaN (a measurement gap).

    Returns
    -------
    measurement_gaps : list of Gap
        The runs of NaN rows of each output.
    missing : dict of str to int
        The count of NaN rows of each output.
    """
    measurement_gaps: list[Gap] = []
    missing: dict[str, int] = {}
    for name, t, v, delta in outputs:
        col = sample_at(t, v, grid, tol=1.5 * delta)
        frame_cols[name] = col
        flag_cols[name] = np.zeros(grid.size, dtype=bool)
        missing[name] = int(np.isnan(col).sum())
        for a, b in nan_runs(col):
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
    return measurement_gaps, missing


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
