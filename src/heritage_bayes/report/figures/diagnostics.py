"""Sampler and noise-model diagnostics: traces, τ history, rank plots, residual checks
(section 7)."""

from __future__ import annotations

import math
from collections.abc import Mapping, Sequence

import numpy as np

from heritage_bayes.report._diag import acf, cumulative_periodogram, innovations
from heritage_bayes.report.figures.style import (
    C_ALT,
    C_MEAS,
    C_MODEL,
    _date_axis,
    _figure,
    tex_safe,
)


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
    innov: np.ndarray | None = None,
    acf_scale: float = 1.0,
):
    """Residuals over the calibration period, their ACF and cumulative periodogram.

    ``phi``: the posterior median AR(1) coefficient (None for iid noise). ``innov``: the
    noise model's standardised one-step innovations (white if the noise model is right;
    default the AR(1) innovations :math:`e_t - \varphi e_{t-1}`), drawn with their own
    autocorrelation and periodogram. ``acf_scale``: the share of the residual variance
    that is correlated, so that the noise model expects the residual autocorrelation
    ``acf_scale * phi**k`` at lags k ≥ 1 (``sigma² / (sigma² + sigma_meas²)`` for AR(1)
    + white noise, 1 for AR(1)).
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
    w = innovations(resid, phi or 0.0) if innov is None else np.asarray(innov, dtype=float)
    _, rho_w, n_w = acf(w, max_lag)
    bound = 1.96 / math.sqrt(max(n, 1))
    a1.axhspan(-bound, bound, color="#cccccc", alpha=0.6, lw=0, label="white-noise 95 % band")
    a1.plot(lag_h, rho, "-", color=C_MEAS, lw=1.2, label="residuals")
    if phi is not None:
        expected = np.where(lags == 0, 1.0, acf_scale * phi**lags)
        a1.plot(
            lag_h,
            expected,
            "--",
            color=C_MODEL,
            lw=1.2,
            label=f"noise model: {acf_scale:.2f}·φᵏ, φ = {phi:.2f}"
            if acf_scale < 1
            else f"AR(1) model: φᵏ, φ = {phi:.2f}",
        )
    if phi is not None or innov is not None:
        lag1 = rho_w[1] if rho_w.size > 1 else float("nan")
        a1.plot(
            lag_h[1:],
            rho_w[1:],
            "o",
            color=C_ALT,
            ms=2.5,
            label=f"standardised innovations (lag 1: {lag1:.2f})",
        )
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
    if phi is not None or innov is not None:
        fw, cw, _ = cumulative_periodogram(w)
        a2.plot(fw * per_day, cw, "-", color=C_ALT, lw=1.0, label="innovations")
    a2.set_xlim(0, nyq)
    a2.set_ylim(-0.02, 1.05)
    a2.set_xlabel("frequency [1/d]")
    a2.set_ylabel("cumulative periodogram [-]")
    a2.set_title("cumulative periodogram")
    a2.legend(loc="lower right")
    return fig


def fig_rank(panels: Sequence[dict], *, title: str):
    """Rank plots (Vehtari et al. 2021): one rank histogram per group of walkers.

    Parameters
    ----------
    panels : dicts with ``label`` (the quantity), ``counts`` ((G, B) draws per rank bin
        and group), ``band`` ((2,) central 99 % interval of one bin's count under
        uniform ranks) and ``expected`` (the uniform count per bin), as returned by
        :func:`heritage_bayes.report.identifiable.rank_counts`.
    title : str

    Groups that sample the same distribution give flat histograms inside the grey band;
    a group above the band at the left or right holds too many of the lowest or highest
    draws (it explores another part of the posterior or mixes slowly).
    """
    from matplotlib.figure import Figure

    n = len(panels)
    ncols = min(3, max(n, 1))
    nrows = math.ceil(n / ncols)
    height = 1.9 * nrows + 0.8
    fig = Figure(figsize=(11.5, height), dpi=80)
    fig.subplots_adjust(
        left=0.06, right=0.99, top=1 - 0.55 / height, bottom=0.5 / height, wspace=0.22, hspace=0.6
    )
    axes = fig.subplots(nrows, ncols, squeeze=False).ravel()
    colours = [C_MODEL, C_ALT, "#2e8b57", "#8e44ad", "#d68910"]
    for ax, p in zip(axes, panels, strict=False):
        counts = np.asarray(p["counts"], dtype=float)
        G, B = counts.shape
        x = np.arange(B + 1) / B
        ax.axhspan(p["band"][0], p["band"][1], color="#d0d0d0", lw=0, label="99 % band if uniform")
        ax.axhline(p["expected"], color="#555555", lw=0.8, ls="--")
        for g in range(G):
            ax.stairs(counts[g], x, color=colours[g % len(colours)], lw=1.1, label=f"group {g + 1}")
        ax.set_xlim(0, 1)
        ax.set_ylim(0, max(float(counts.max()), float(p["band"][1])) * 1.12)
        ax.set_title(tex_safe(p["label"]), fontsize=9)
        ax.grid(False)
    for ax in axes[max(0, n - ncols) : n]:
        ax.set_xlabel("rank among all draws / number of draws [-]", fontsize=8)
    for k in range(0, n, ncols):
        axes[k].set_ylabel("draws per bin [-]", fontsize=8)
    for ax in axes[n:]:
        ax.set_visible(False)
    h, lb = axes[0].get_legend_handles_labels()
    fig.legend(h, lb, loc="upper right", ncols=len(lb), fontsize=8)
    fig.suptitle(title, x=0.06, ha="left")
    return fig
