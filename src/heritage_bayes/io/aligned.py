"""The result of :func:`heritage_bayes.io.align`: the aligned frame (:class:`Aligned`), what
was done to get it (:class:`AlignmentReport`) and the gaps found (:class:`Gap`).

The grid convention and the gap policy are described in :mod:`heritage_bayes.io.align`,
which re-exports these classes.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np
import pandas as pd

from heritage_bayes.io._common import format_timedelta, to_jsonable

__all__ = ["Aligned", "AlignmentReport", "Gap"]


def _iso(ts: pd.Timestamp) -> str:
    return pd.Timestamp(ts).tz_convert("UTC").strftime("%Y-%m-%dT%H:%M:%SZ")


@dataclass(frozen=True)
class Gap:
    """A run of missing values.

    Attributes
    ----------
    column : str
    start, end : pandas.Timestamp
        First and last missing stamp (UTC). For input gaps these are stamps of the native
        series; for measurement gaps, grid rows.
    n_missing : int
        Number of missing samples (native) or rows (grid).
    length : pandas.Timedelta
        ``n_missing`` times the spacing of the series.
    filled : bool
        True when the gap was interpolated (input gaps up to ``max_gap``).
    """

    column: str
    start: pd.Timestamp
    end: pd.Timestamp
    n_missing: int
    length: pd.Timedelta
    filled: bool

    def to_dict(self) -> dict:
        return {
            "column": self.column,
            "start": _iso(self.start),
            "end": _iso(self.end),
            "n_missing": int(self.n_missing),
            "length": format_timedelta(self.length),
            "length_hours": self.length / pd.Timedelta("1h"),
            "filled": bool(self.filled),
        }

    def __str__(self) -> str:
        return (
            f"{self.column}: {self.start:%Y-%m-%d %H:%M} to {self.end:%Y-%m-%d %H:%M} UTC "
            f"({format_timedelta(self.length)}, {self.n_missing} missing)"
        )


@dataclass
class AlignmentReport:
    """What :func:`align` did, for the run record and the HTML report.

    Attributes
    ----------
    start, end : pandas.Timestamp
        The period ``[start, end)``: first row ``start``, last row ``end - step``.
    step : pandas.Timedelta
    n_rows : int
    inputs, outputs : tuple of str
        Input (weather) and output (measurement) columns of the aligned frame.
    averaged_inputs : tuple of str
        Input columns read as interval averages (the others as instantaneous).
    max_gap : pandas.Timedelta
    rows_in : dict
        Rows of the weather and measurement tables given.
    rows_dropped : dict
        Rows of each table outside the period (not used).
    interpolated : dict
        Per input column, native samples filled by interpolation.
    flagged_rows : dict
        Per input column, grid rows that depend on a filled sample (``flags`` True).
    input_gaps, measurement_gaps : list of Gap
        Gaps inside the period: native input gaps (``filled`` False: longer than
        ``max_gap``, a break between segments) and runs of NaN rows of
        each measurement column.
    measurement_missing : dict
        Per output column, NaN rows in the aligned frame.
    sources : list of dict
        ``source``, role, timing and the reader's ``dropped``/``irradiance_source`` notes
        of every table given.
    """

    start: pd.Timestamp
    end: pd.Timestamp
    step: pd.Timedelta
    n_rows: int
    inputs: tuple[str, ...]
    outputs: tuple[str, ...]
    averaged_inputs: tuple[str, ...]
    max_gap: pd.Timedelta
    rows_in: dict[str, int]
    rows_dropped: dict[str, int]
    interpolated: dict[str, int]
    flagged_rows: dict[str, int]
    input_gaps: list[Gap] = field(default_factory=list)
    measurement_gaps: list[Gap] = field(default_factory=list)
    measurement_missing: dict[str, int] = field(default_factory=dict)
    sources: list[dict] = field(default_factory=list)

    def to_dict(self) -> dict:
        """JSON-serialisable dictionary (ISO 8601 UTC times, durations as strings and hours)."""
        return {
            "period": {
                "start": _iso(self.start),
                "end": _iso(self.end),
                "step": format_timedelta(self.step),
                "n_rows": int(self.n_rows),
            },
            "inputs": list(self.inputs),
            "outputs": list(self.outputs),
            "averaged_inputs": list(self.averaged_inputs),
            "max_gap": format_timedelta(self.max_gap),
            "rows_in": {k: int(v) for k, v in self.rows_in.items()},
            "rows_dropped": {k: int(v) for k, v in self.rows_dropped.items()},
            "interpolated": {k: int(v) for k, v in self.interpolated.items()},
            "flagged_rows": {k: int(v) for k, v in self.flagged_rows.items()},
            "input_gaps": [g.to_dict() for g in self.input_gaps],
            "measurement_gaps": [g.to_dict() for g in self.measurement_gaps],
            "measurement_missing": {k: int(v) for k, v in self.measurement_missing.items()},
            "sources": [to_jsonable(s) for s in self.sources],
        }


@dataclass(frozen=True)
class Aligned:
    """Result of :func:`align`.

    Attributes
    ----------
    frame : pandas.DataFrame
        Regular UTC grid (index ``time``, ``freq`` = step): input columns (means over
        ``[t_k, t_k + step)``) then output columns (values at ``t_k``, NaN where missing).
    flags : pandas.DataFrame
        Boolean, same index and columns: True where an input value depends on a filled
        (interpolated) sample. Output columns are never filled, hence always False.
    report : AlignmentReport
    inputs, outputs : tuple of str
        Column names of the inputs and outputs in ``frame``.
    slopes : pandas.DataFrame or None
        Same index, one column per input: its change over the row,
        :math:`u(t_{k+1}) - u(t_k)` of the linear interpolation between the samples of
        an instantaneous input, zero for an interval mean (the first-order hold's
        second input, see :meth:`heritage_bayes.rc.RCModel.with_slopes`).
    breaks : numpy.ndarray or None
        (n_rows,) bool: True where an input value depends on a sample of an input gap
        longer than ``max_gap`` (``long_gaps="split"``): the record is split there.
    """

    frame: pd.DataFrame
    flags: pd.DataFrame
    report: AlignmentReport
    inputs: tuple[str, ...]
    outputs: tuple[str, ...]
    slopes: pd.DataFrame | None = None
    breaks: np.ndarray | None = None

    @property
    def step(self) -> pd.Timedelta:
        return self.report.step
