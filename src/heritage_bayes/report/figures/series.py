"""Time-series figures: the data overview (section 2) and measured vs model (section 3)."""

from __future__ import annotations

import math
from collections.abc import Mapping, Sequence

import numpy as np

from heritage_bayes.report.figures.style import (
    _OUT_LABEL,
    C_ALT,
    C_MEAS,
    C_MODEL,
    _date_axis,
    _figure,
    _shade_gaps,
    _shade_periods,
    _step,
    tex_safe,
)


def fig_data_overview(
    times: np.ndarray,
    codes: np.ndarray,
    panels: Sequence[Mapping],
    gaps,
    interpolated: Mapping[str, np.ndarray],
):
    """Inputs and measured outputs over time, one panel per quantity.

    Parameters
    ----------
    times : (N,) datetime64
        The aligned grid (UTC).
    codes : (N,) int
        Period codes (-1 outside, 0 warm-up, 1 calibration, 2 validation).
    panels : list of {"ylabel": str, "series": [(name, label, t, values, style), ...]}
        ``t`` is the series' own time axis (e.g. daily means).
    gaps : list of (start, end) datetime64
        Measurement gaps (hatched).
    interpolated : column name -> (N,) bool
        Rows that depend on an interpolated value (marked with ×).
    """
    n = len(panels)
    fig = _figure(
        11, 1.9 * n + 0.6, dpi=96, margins={"left": 0.75, "top": 0.1, "bottom": 0.5, "hspace": 0.1}
    )
    axes = fig.subplots(n, 1, sharex=True, squeeze=False)[:, 0]
    labelled: set[int] = set()
    gap_lab = [False]
    for i, (ax, panel) in enumerate(zip(axes, panels, strict=True)):
        _shade_periods(ax, times, codes, labelled if i == 0 else None)
        _shade_gaps(ax, gaps, gap_lab if i == 0 else None)
        for name, label, t, values, style in panel["series"]:
            values = np.asarray(values, dtype=float)
            ax.plot(t, values, label=tex_safe(label), **style)
            flags = interpolated.get(name)
            if flags is not None and flags.shape == values.shape and np.any(flags):
                ax.plot(
                    t[flags],
                    values[flags],
                    "x",
                    color=C_ALT,
                    ms=4,
                    label=f"{tex_safe(name)} interpolated",
                )
        ax.set_ylabel(panel["ylabel"])
        handles = ax.get_legend_handles_labels()[0]
        # headroom for the legend row(s) above the data: a legend drawn over the
        # highest values (the south facade's winter daily means) would hide them
        lo, hi = ax.get_ylim()
        rows = math.ceil(len(handles) / min(4, max(1, len(handles))))
        ax.set_ylim(lo, hi + (0.12 + 0.12 * rows) * (hi - lo))
        ax.legend(loc="upper left", ncols=min(4, max(1, len(handles))))
        _date_axis(ax, label=i == n - 1)
    axes[0].set_xlim(times[0], times[-1] + _step(times))
    return fig


# ---------------------------------------------------------------------------- fit
def _fit_panel(ax, times, obs, med, b50, b90, codes, sl, gaps, *, detail: bool, legend: bool):
    t = times[sl]
    _shade_periods(ax, t, codes[sl], set() if legend else None)
    inside = [(a, b) for a, b in gaps if b > t[0] and a < t[-1]]
    _shade_gaps(ax, inside, [False] if legend else None)
    ax.fill_between(
        t,
        b90[0][sl],
        b90[1][sl],
        color=C_MODEL,
        alpha=0.15,
        lw=0,
        label="90 % predictive band" if legend else None,
    )
    ax.fill_between(
        t,
        b50[0][sl],
        b50[1][sl],
        color=C_MODEL,
        alpha=0.35,
        lw=0,
        label="50 % predictive band" if legend else None,
    )
    if detail:
        ax.plot(t, obs[sl], ".", color=C_MEAS, ms=2.5, label="measured" if legend else None)
    else:
        ax.plot(t, obs[sl], "-", color=C_MEAS, lw=0.5, label="measured" if legend else None)
    ax.plot(
        t,
        med[sl],
        "-",
        color=C_MODEL,
        lw=1.0 if detail else 0.7,
        label="model, posterior median" if legend else None,
    )
    ax.set_xlim(t[0], t[-1] + _step(times))
    _date_axis(ax)


def fig_fit(
    times,
    obs,
    med,
    band50,
    band90,
    codes,
    *,
    output: str,
    model_name: str,
    gaps=(),
    detail_days: float = 14.0,
):
    """Measured vs posterior-predictive median with 50 % and 90 % bands.

    Top: the whole data period with the warm-up, calibration and validation periods
    shaded; bottom: a two-week detail at the end of the calibration period and one at
    the start of the validation period (as the paper's figures). ``gaps``: (start, end)
    datetime64 pairs of measurement gaps, hatched.
    """
    what, unit = _OUT_LABEL.get(output, (output, ""))
    ylab = f"{tex_safe(output)} [{unit}]" if unit else tex_safe(output)
    fig = _figure(11, 6.4, dpi=96, margins={"top": 0.3, "hspace": 0.42, "wspace": 0.12})
    gs = fig.add_gridspec(2, 2, height_ratios=[1.15, 1])
    ax0 = fig.add_subplot(gs[0, :])
    fitted = np.flatnonzero(codes >= 0)
    full = slice(int(fitted[0]), int(fitted[-1]) + 1) if fitted.size else slice(None)
    _fit_panel(ax0, times, obs, med, band50, band90, codes, full, gaps, detail=False, legend=True)
    ax0.set_ylabel(ylab)
    ax0.set_title(f"{what} — {tex_safe(model_name)}: whole period")
    ax0.legend(loc="upper left", ncols=4)
    dt = _step(times)
    n_detail = max(2, int(np.timedelta64(int(detail_days * 86400), "s") / dt))
    details = []
    cal = np.flatnonzero(codes == 1)
    val = np.flatnonzero(codes == 2)
    if cal.size:
        stop = int(cal[-1]) + 1
        details.append(
            (
                "calibration: last two weeks" if cal.size >= n_detail else "calibration period",
                slice(max(int(cal[0]), stop - n_detail), stop),
            )
        )
    if val.size:
        start = int(val[0])
        details.append(
            (
                "validation: first two weeks" if val.size >= n_detail else "validation period",
                slice(start, min(int(val[-1]) + 1, start + n_detail)),
            )
        )
    for j, (title, sl) in enumerate(details):
        ax = fig.add_subplot(gs[1, j] if len(details) == 2 else gs[1, :])
        _fit_panel(ax, times, obs, med, band50, band90, codes, sl, gaps, detail=True, legend=False)
        ax.set_ylabel(ylab)
        ax.set_title(f"detail — {title}")
    return fig
