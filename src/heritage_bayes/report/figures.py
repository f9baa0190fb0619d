"""The report's figures: matplotlib (object API, Agg canvas) and ``corner``.

Every function returns a :class:`matplotlib.figure.Figure` built without ``pyplot``, so
nothing here touches the global backend or keeps figures alive; :func:`to_png_uri`
renders one to a ``data:image/png;base64,…`` URI for the self-contained HTML. Axes carry
units in brackets, time axes are dates (UTC) and every figure with more than one series
has a legend.

Text from the config (room names, notes) never goes into a figure: only parameter,
input and output names, escaped for mathtext by :func:`tex_safe`.
"""

from __future__ import annotations

import base64
import io
import math
from collections.abc import Mapping, Sequence

import numpy as np

from heritage_bayes.report._diag import acf, cumulative_periodogram, innovations

__all__ = [
    "RC_PARAMS",
    "fig_corner",
    "fig_correlation",
    "fig_data_overview",
    "fig_fit",
    "fig_ladder",
    "fig_residuals",
    "fig_tau_history",
    "fig_traces",
    "tex_safe",
    "to_png_uri",
]

#: Matplotlib settings for every report figure (applied with ``rc_context``).
RC_PARAMS = {
    "font.size": 9,
    "axes.titlesize": 10,
    "axes.labelsize": 9,
    "legend.fontsize": 8,
    "xtick.labelsize": 8,
    "ytick.labelsize": 8,
    "axes.grid": True,
    "grid.alpha": 0.3,
    "grid.linewidth": 0.5,
    "axes.spines.top": False,
    "axes.spines.right": False,
    "legend.framealpha": 0.85,
    "figure.dpi": 80,
    "path.simplify": True,
    "agg.path.chunksize": 10000,
}

PERIOD_STYLE = {
    0: ("warm-up (not fitted)", "#d9d9d9"),
    1: ("calibration", "#e3f1dc"),
    2: ("validation", "#fbe5cc"),
}
C_MEAS = "#222222"
C_MODEL = "#1f5fa8"
C_ALT = "#c0392b"
C_GAP = "#999999"

_OUT_LABEL = {
    "Ti": ("indoor temperature", "°C"),
    "Pi": ("indoor vapour pressure", "Pa"),
    "RHi": ("indoor relative humidity", "%"),
}


def tex_safe(text: str) -> str:
    """Escape ``$`` so that matplotlib does not parse text as mathtext."""
    return str(text).replace("$", r"\$")


def to_png_uri(fig, dpi: float | None = None) -> str:
    """Render ``fig`` to a PNG ``data:`` URI (Agg, no pyplot); default: the figure's dpi."""
    from matplotlib.backends.backend_agg import FigureCanvasAgg

    FigureCanvasAgg(fig)
    buf = io.BytesIO()
    fig.savefig(buf, format="png", dpi=dpi or fig.dpi, metadata={"Software": None})
    return "data:image/png;base64," + base64.b64encode(buf.getvalue()).decode("ascii")


def _figure(w: float, h: float, dpi: float = 80, margins: dict | None = None):
    """A Figure with constrained layout, or fixed ``margins`` [in] (faster to draw)."""
    from matplotlib.figure import Figure

    if margins is None:
        return Figure(figsize=(w, h), dpi=dpi, layout="constrained")
    fig = Figure(figsize=(w, h), dpi=dpi)
    m = {"left": 0.7, "right": 0.15, "top": 0.35, "bottom": 0.55, **margins}
    fig.subplots_adjust(
        left=m["left"] / w,
        right=1 - m["right"] / w,
        top=1 - m["top"] / h,
        bottom=m["bottom"] / h,
        hspace=m.get("hspace"),
        wspace=m.get("wspace"),
    )
    return fig


def _date_axis(ax, label: bool = True) -> None:
    import matplotlib.dates as mdates

    loc = mdates.AutoDateLocator(minticks=4, maxticks=9)
    ax.xaxis.set_major_locator(loc)
    ax.xaxis.set_major_formatter(mdates.ConciseDateFormatter(loc, show_offset=True))
    if label:
        ax.set_xlabel("time (UTC)")


def _runs(mask: np.ndarray) -> list[tuple[int, int]]:
    """[start, stop) index runs where ``mask`` is true."""
    m = np.concatenate([[False], np.asarray(mask, bool), [False]])
    d = np.flatnonzero(np.diff(m.astype(np.int8)))
    return list(zip(d[::2], d[1::2], strict=True))


def _step(times: np.ndarray) -> np.timedelta64:
    if times.size > 1:
        return np.median(np.diff(times[: min(times.size, 1000)]))
    return np.timedelta64(3600, "s")


def _shade_periods(ax, times, codes, labelled: set[int] | None = None) -> None:
    """Background spans for warm-up, calibration and validation."""
    dt = _step(times)
    for code, (label, colour) in PERIOD_STYLE.items():
        for a, b in _runs(codes == code):
            lab = None
            if labelled is not None and code not in labelled:
                lab = label
                labelled.add(code)
            ax.axvspan(times[a], times[b - 1] + dt, color=colour, lw=0, zorder=0, label=lab)


def _shade_gaps(
    ax, gaps: Sequence[tuple[np.datetime64, np.datetime64]], labelled: list[bool] | None = None
) -> None:
    for t0, t1 in gaps:
        lab = None
        if labelled is not None and not labelled[0]:
            lab = "measurement gap"
            labelled[0] = True
        ax.axvspan(
            t0, t1, facecolor="none", edgecolor=C_GAP, hatch="///", lw=0, zorder=0.5, label=lab
        )


# --------------------------------------------------------------------------- data
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


# -------------------------------------------------------------------- parameters
def fig_correlation(names: Sequence[str], matrix: np.ndarray, *, title: str):
    """Posterior correlation matrix as an annotated heat map."""
    C = np.asarray(matrix, dtype=float)
    d = C.shape[0]
    size = min(9.0, 2.2 + 0.5 * d)
    fig = _figure(size + 1.0, size)
    ax = fig.add_subplot()
    im = ax.imshow(C, cmap="RdBu_r", vmin=-1, vmax=1)
    ax.set_xticks(range(d), [tex_safe(n) for n in names], rotation=60, ha="right")
    ax.set_yticks(range(d), [tex_safe(n) for n in names])
    ax.grid(False)
    if d <= 20:
        fs = 7 if d > 10 else 8
        for i in range(d):
            for j in range(d):
                if np.isfinite(C[i, j]):
                    v = 0.0 if abs(C[i, j]) < 0.005 else C[i, j]
                    ax.text(
                        j,
                        i,
                        f"{v:.2f}".replace("0.", ".").replace("-.", "−."),
                        ha="center",
                        va="center",
                        fontsize=fs,
                        color="white" if abs(C[i, j]) > 0.6 else "black",
                    )
    fig.colorbar(im, ax=ax, shrink=0.8, label="posterior correlation [-]")
    ax.set_title(title)
    return fig


def fig_corner(samples: np.ndarray, labels: Sequence[str], truths=None):
    """``corner`` plot of posterior samples (already on log10 scale where due).

    Parameters
    ----------
    samples : (K, d) array
    labels : d axis labels (with units)
    truths : d values or None (drawn in red; None entries are skipped)
    """
    import corner
    import matplotlib
    from matplotlib.figure import Figure

    d = samples.shape[1]
    size = min(16.0, max(6.0, 1.05 * d))
    fig = Figure(figsize=(size, size), dpi=80)  # corner places the axes itself
    kw = dict(
        bins=20,
        smooth=1.0,
        levels=(0.5, 0.9),
        plot_datapoints=True,
        plot_density=False,
        fill_contours=False,
        data_kwargs={"ms": 1.2, "alpha": 0.15},
        contour_kwargs={"linewidths": 0.8, "colors": C_MODEL},
        hist_kwargs={"color": C_MODEL},
        max_n_ticks=2 if d > 8 else 3,
        labels=[tex_safe(lb) for lb in labels],
        label_kwargs={"fontsize": 9},
        labelpad=0.12 if d > 8 else 0.05,
        quantiles=(0.05, 0.5, 0.95),
    )
    # a constant column (e.g. a parameter stuck at a bound) needs a non-empty range
    ranges = []
    for j in range(d):
        lo, hi = float(np.nanmin(samples[:, j])), float(np.nanmax(samples[:, j]))
        pad = 1e-6 * max(1.0, abs(lo)) if hi <= lo else 0.0
        ranges.append((lo - pad, hi + pad))
    if truths is not None:
        ranges = [
            (min(lo, t), max(hi, t)) if t is not None and np.isfinite(t) else (lo, hi)
            for (lo, hi), t in zip(ranges, truths, strict=True)
        ]
        kw.update(truths=[np.nan if t is None else t for t in truths], truth_color=C_ALT)
    # a little air around the samples (and the truths, which may lie outside them)
    ranges = [(lo - 0.03 * (hi - lo), hi + 0.03 * (hi - lo)) for lo, hi in ranges]
    with matplotlib.rc_context({"axes.grid": False}):
        corner.corner(samples, fig=fig, range=ranges, **kw)
    for ax in fig.axes:
        ax.tick_params(labelsize=7)
    # room for the two-line axis labels: 1.2 in left and bottom, 0.2 in top and right
    fig.subplots_adjust(
        left=1.2 / size, bottom=1.2 / size, right=1 - 0.2 / size, top=1 - 0.2 / size
    )
    return fig


# ---------------------------------------------------------------------- diagnostics
def fig_traces(
    steps: np.ndarray,
    values: np.ndarray,
    labels: Sequence[str],
    log_prob: np.ndarray,
    burn: int,
    *,
    title: str,
):
    """Walker traces, thinned; the discarded burn-in shaded.

    Parameters
    ----------
    steps : (S,) step numbers of the thinned chain
    values : (S, W, d) parameter values (log10 where the prior is log-scale)
    labels : d axis labels (with units)
    log_prob : (S, W)
    burn : int, burn-in [steps]
    """
    from matplotlib.collections import LineCollection
    from matplotlib.figure import Figure

    d = values.shape[2]
    ncols = 3
    nrows = math.ceil((d + 1) / ncols)
    height = 1.75 * nrows + 0.7
    fig = Figure(figsize=(11.5, height), dpi=80)  # fixed grid, no layout engine: faster
    fig.subplots_adjust(
        left=0.07, right=0.99, top=1 - 0.45 / height, bottom=0.5 / height, wspace=0.42, hspace=0.3
    )
    axes = fig.subplots(nrows, ncols, sharex=True, squeeze=False).ravel()
    for j in range(d + 1):
        ax = axes[j]
        ax.axvspan(
            0,
            burn,
            color="#e6e6e6",
            lw=0,
            zorder=0,
            label="burn-in (discarded)" if j == 0 else None,
        )
        if j < d:
            # one LineCollection per panel: much faster than a Line2D per walker
            segs = np.stack(np.broadcast_arrays(steps[None, :], values[:, :, j].T), axis=-1)
            ax.add_collection(LineCollection(segs, colors=C_MODEL, linewidths=0.4, alpha=0.35))
            v = values[:, :, j]
            if np.isfinite(v).any():
                lo, hi = np.nanmin(v), np.nanmax(v)
                pad = 0.05 * (hi - lo) if hi > lo else 0.5 * max(abs(lo), 1e-12)
                ax.set_ylim(lo - pad, hi + pad)
            ax.set_ylabel(tex_safe(labels[j]), fontsize=8)
        else:
            lp = np.where(np.isfinite(log_prob), log_prob, np.nan)
            segs = np.stack(np.broadcast_arrays(steps[None, :], lp.T), axis=-1)
            ax.add_collection(LineCollection(segs, colors="#555555", linewidths=0.4, alpha=0.35))
            post = lp[steps >= burn]
            if np.isfinite(post).any():
                lo, hi = np.nanpercentile(post, [0.5, 100])
                ax.set_ylim(lo - 0.3 * (hi - lo + 1e-9), hi + 0.1 * (hi - lo + 1e-9))
            ax.set_ylabel("log posterior [-]", fontsize=8)
        ax.set_xlim(0, steps[-1] if steps.size else 1)
    for ax in axes[d + 1 :]:
        ax.set_visible(False)
    for ax in axes[max(0, d + 1 - ncols) : d + 1]:
        ax.set_xlabel("step")
        ax.xaxis.set_tick_params(labelbottom=True)
    axes[0].legend(loc="upper right")
    fig.suptitle(title)
    return fig


def fig_tau_history(histories: Mapping[str, np.ndarray], tau_factor: float):
    """Autocorrelation-time estimate (max over parameters) vs chain length."""
    fig = _figure(7.5, 3.8)
    ax = fig.add_subplot()
    n_max = 1.0
    colours = [C_MODEL, C_ALT, "#2e8b57", "#8e44ad"]
    for (name, h), c in zip(histories.items(), colours, strict=False):
        h = np.asarray(h, dtype=float).reshape(-1, 2)
        if not h.size:
            continue
        ax.plot(h[:, 0], h[:, 1], "o-", color=c, ms=3, lw=1.2, label=f"{tex_safe(name)}: τ max")
        n_max = max(n_max, float(h[:, 0].max()))
    x = np.linspace(0, n_max * 1.05, 50)
    ax.plot(
        x,
        x / tau_factor,
        "--",
        color="#444444",
        lw=1,
        label=f"chain length / {tau_factor:g} (τ must fall below)",
    )
    ax.set_xlim(0, n_max * 1.05)
    ax.set_ylim(bottom=0)
    ax.set_xlabel("chain length [steps]")
    ax.set_ylabel("integrated autocorrelation time τ [steps]")
    ax.legend(loc="upper left")
    ax.set_title("τ estimate vs chain length (converged when below the dashed line and stable)")
    return fig


def fig_residuals(
    times: np.ndarray,
    resid: np.ndarray,
    *,
    output: str,
    unit: str,
    phi: float | None,
    dt_hours: float,
    max_lag_hours: float = 72.0,
):
    """Residuals over the calibration period, their ACF and cumulative periodogram.

    ``phi``: the posterior median AR(1) coefficient (None for iid noise).
    """
    fig = _figure(12, 3.6)
    a0, a1, a2 = fig.subplots(1, 3, width_ratios=[1.3, 1, 1])
    yl = f"{tex_safe(output)} [{unit}]" if unit else tex_safe(output)
    a0.plot(times, resid, "-", color=C_MEAS, lw=0.5)
    a0.axhline(0, color=C_MODEL, lw=0.8)
    a0.set_ylabel(f"residual {yl}")
    a0.set_title("measured − posterior-median model")
    _date_axis(a0)
    # ACF
    max_lag = max(1, round(max_lag_hours / dt_hours))
    lags, rho, n = acf(resid, max_lag)
    lag_h = lags * dt_hours
    w = innovations(resid, phi or 0.0)
    _, rho_w, n_w = acf(w, max_lag)
    bound = 1.96 / math.sqrt(max(n, 1))
    a1.axhspan(-bound, bound, color="#cccccc", alpha=0.6, lw=0, label="white-noise 95 % band")
    a1.plot(lag_h, rho, "-", color=C_MEAS, lw=1.2, label="residuals")
    if phi is not None:
        a1.plot(
            lag_h, phi**lags, "--", color=C_MODEL, lw=1.2, label=f"AR(1) model: φᵏ, φ = {phi:.2f}"
        )
        a1.plot(lag_h[1:], rho_w[1:], "o", color=C_ALT, ms=2.5, label="innovations e − φ·e₋₁")
    a1.set_xlabel("lag [h]")
    a1.set_ylabel("autocorrelation [-]")
    a1.set_xlim(0, lag_h[-1] if lag_h.size else 1)
    a1.set_title("autocorrelation function")
    a1.legend(loc="upper right")
    # cumulative periodogram
    per_day = 24.0 / dt_hours
    f, c, band = cumulative_periodogram(resid)
    fd = f * per_day
    nyq = 0.5 * per_day
    a2.fill_between(
        [0, nyq],
        [-band, 1 - band],
        [band, 1 + band],
        color="#cccccc",
        alpha=0.6,
        lw=0,
        label="white-noise 95 % band",
    )
    a2.plot([0, nyq], [0, 1], "-", color="#888888", lw=0.8)
    a2.plot(fd, c, "-", color=C_MEAS, lw=1.2, label="residuals")
    if phi is not None:
        fw, cw, _ = cumulative_periodogram(w)
        a2.plot(fw * per_day, cw, "-", color=C_ALT, lw=1.0, label="innovations")
    a2.set_xlim(0, nyq)
    a2.set_ylim(-0.02, 1.05)
    a2.set_xlabel("frequency [1/d]")
    a2.set_ylabel("cumulative periodogram [-]")
    a2.set_title("cumulative periodogram")
    a2.legend(loc="lower right")
    return fig


# -------------------------------------------------------------------------- ladder
def fig_ladder(ladder: Mapping[str, Sequence[Mapping]]):
    """Accuracy vs identifiability of the model ladder (MAP fits).

    Left: validation (filled) and calibration (open) FIT against the number of model
    parameters; right: validation FIT against the condition number of the identifiable
    part (log scale), labelled with the number of non-identifiable directions.
    """
    fig = _figure(11, 3.9)
    a0, a1 = fig.subplots(1, 2)
    colours = [C_MODEL, C_ALT, "#2e8b57", "#8e44ad"]
    for (domain, rows), c in zip(ladder.items(), colours, strict=False):
        xs, fc, fv, cond, lab, nn = [], [], [], [], [], []
        for r in rows:
            xs.append(_num(r.get("n_model_params", r.get("n_params"))))
            fc.append(_first_fit(r.get("fit"), "calibration"))
            fv.append(_first_fit(r.get("fit"), "validation"))
            cond.append(_num(r.get("condition_number_identifiable")))
            lab.append(tex_safe(str(r.get("model", "?"))) + (" *" if r.get("sampled") else ""))
            nn.append(r.get("n_null"))
        xs = np.asarray(xs, dtype=float)
        a0.plot(xs, fv, "o-", color=c, label=f"{tex_safe(domain)}: validation")
        a0.plot(xs, fc, "o--", mfc="white", color=c, label=f"{tex_safe(domain)}: calibration")
        for x, y, t in zip(xs, fv, lab, strict=True):
            if np.isfinite(x) and np.isfinite(y):
                a0.annotate(t, (x, y), textcoords="offset points", xytext=(4, 4), fontsize=7)
        ok = np.isfinite(cond) & np.isfinite(fv)
        a1.plot(np.asarray(cond)[ok], np.asarray(fv)[ok], "o", color=c, label=f"{tex_safe(domain)}")
        for x, y, t, k in zip(cond, fv, lab, nn, strict=True):
            if np.isfinite(x) and np.isfinite(y):
                a1.annotate(
                    f"{t} ({k} null)", (x, y), textcoords="offset points", xytext=(4, 4), fontsize=7
                )
    a0.set_xlabel("number of model parameters [-]")
    a0.set_ylabel("FIT [%]")
    a0.set_title("accuracy vs model order (MAP)")
    a0.legend(loc="lower right")
    a1.set_xscale("log")
    a1.set_xlabel("condition number of the identifiable part [-]")
    a1.set_ylabel("validation FIT [%]")
    a1.set_title("accuracy vs identifiability (* = calibrated here)")
    a1.legend(loc="lower right")
    return fig


def _first_fit(fit, period: str) -> float:
    """FIT [%] of a ladder row's period (the first output when keyed by output)."""
    per = (fit or {}).get(period) or {}
    if "FIT" not in per:
        per = next((v for v in per.values() if isinstance(v, Mapping)), {})
    return _num(per.get("FIT"))


def _num(v) -> float:
    try:
        return float(v)
    except (TypeError, ValueError):
        return float("nan")
