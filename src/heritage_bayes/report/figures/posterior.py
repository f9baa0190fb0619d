"""Posterior figures: correlation matrix, corner plot, prior vs posterior (sections 5, 6)."""

from __future__ import annotations

import math
from collections.abc import Sequence

import numpy as np

from heritage_bayes.report.figures.style import (
    C_ALT,
    C_MODEL,
    _figure,
    tex_safe,
)


def fig_correlation(names: Sequence[str], matrix: np.ndarray, *, title: str, max_size: float = 9.0):
    """Posterior correlation matrix as an annotated heat map (``max_size`` [in]: height
    cap, smaller for a secondary figure)."""
    C = np.asarray(matrix, dtype=float)
    d = C.shape[0]
    size = min(max_size, max(4.4, 2.2 + 0.5 * d))
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


def fig_corner(samples: np.ndarray, labels: Sequence[str], truths=None, *, panel: float = 1.05):
    """``corner`` plot of posterior samples (already on log10 scale where due).

    Parameters
    ----------
    samples : (K, d) array
    labels : d axis labels (with units)
    truths : d values or None (drawn in red; None entries are skipped)
    panel : float
        Width of one panel [in] (the figure is between 6 and 16 in wide); larger for long
        labels.
    """
    import corner
    import matplotlib
    from matplotlib.figure import Figure

    d = samples.shape[1]
    size = min(16.0, max(6.0, panel * d))
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
        label_kwargs={"fontsize": 8 if d > 8 else 9},
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


def fig_prior_posterior(panels: Sequence[dict], *, title: str):
    """Posterior histograms with the prior drawn over them, one small panel per quantity.

    Parameters
    ----------
    panels : dicts with
        ``label`` (x-axis label with unit), ``post`` (1-D posterior draws, in the plotted
        coordinate), ``truth`` (float or None) and either ``prior_x``/``prior_y`` (a
        normalised prior density curve) or ``prior_draws`` (push-forward prior draws,
        drawn as a step histogram).
    title : str

    The x-axis covers the posterior and the prior's bulk (its support, or the 0.5–99.5 %
    quantiles of the prior draws), so that a posterior far narrower than its prior shows
    as a spike over a low, flat prior. Panels with prior draws share one set of 50 bins
    between prior and posterior and a log density axis: a push-forward prior spans
    many decades (a τ from minutes to centuries) and the posterior may fall in one bin.
    """
    from matplotlib.figure import Figure

    n = len(panels)
    ncols = min(4, max(n, 1))
    nrows = math.ceil(n / ncols)
    height = 1.9 * nrows + 0.75
    fig = Figure(figsize=(11.5, height), dpi=80)  # fixed grid: faster than a layout engine
    fig.subplots_adjust(
        left=0.05, right=0.99, top=1 - 0.5 / height, bottom=0.55 / height, wspace=0.25, hspace=0.75
    )
    axes = fig.subplots(nrows, ncols, squeeze=False).ravel()
    for ax, p in zip(axes, panels, strict=False):
        post = np.asarray(p["post"], dtype=float)
        post = post[np.isfinite(post)]
        lo, hi = (float(post.min()), float(post.max())) if post.size else (0.0, 1.0)
        px, py, pd = p.get("prior_x"), p.get("prior_y"), p.get("prior_draws")
        if px is not None:
            lo, hi = min(lo, float(px[0])), max(hi, float(px[-1]))
        elif pd is not None and np.size(pd) > 1:
            q = np.quantile(pd, [0.005, 0.995])
            lo, hi = min(lo, float(q[0])), max(hi, float(q[1]))
        t = p.get("truth")
        if t is not None and math.isfinite(t):
            lo, hi = min(lo, t), max(hi, t)
        if not hi > lo:
            lo, hi = lo - 0.5 * max(abs(lo), 1e-9), hi + 0.5 * max(abs(hi), 1e-9)
        if pd is not None and np.size(pd) > 1:
            # common bins: a posterior far narrower than its push-forward prior is one
            # tall bar over a low prior, both visible on the log density axis
            edges = np.linspace(lo, hi, 51)
            if post.size:
                ax.hist(
                    post,
                    bins=edges,
                    density=True,
                    color=C_MODEL,
                    alpha=0.55,
                    lw=0,
                    label="posterior",
                )
            ax.hist(
                np.clip(pd, lo, hi),
                bins=edges,
                density=True,
                histtype="step",
                color="#333333",
                lw=1.0,
                label="prior (push-forward)",
            )
            ax.set_yscale("log")
        else:
            if post.size:
                ax.hist(
                    post,
                    bins=30,
                    range=(float(post.min()), float(post.max()) + 1e-12 * max(1.0, abs(hi))),
                    density=True,
                    color=C_MODEL,
                    alpha=0.55,
                    lw=0,
                    label="posterior",
                )
            if px is not None:
                ax.plot(px, py, "-", color="#333333", lw=1.2, label="prior")
        if t is not None and math.isfinite(t):
            ax.axvline(t, color=C_ALT, lw=1.2, label="truth")
        ax.set_xlim(lo - 0.02 * (hi - lo), hi + 0.02 * (hi - lo))
        if ax.get_yscale() == "linear":
            ax.set_ylim(bottom=0)
        ax.set_xlabel(tex_safe(p["label"]), fontsize=8)
        ax.tick_params(labelsize=7)
        ax.grid(False)
    for k in range(0, n, ncols):
        log = axes[k].get_yscale() == "log"
        axes[k].set_ylabel("density [1/unit of x]" + (", log" if log else ""), fontsize=8)
    for ax in axes[n:]:
        ax.set_visible(False)
    handles, labels = {}, []
    for ax in axes[:n]:
        for h, lb in zip(*ax.get_legend_handles_labels(), strict=True):
            if lb not in handles:
                handles[lb] = h
                labels.append(lb)
    fig.legend([handles[lb] for lb in labels], labels, loc="upper right", ncols=len(labels))
    fig.suptitle(title, x=0.05, ha="left")
    return fig
