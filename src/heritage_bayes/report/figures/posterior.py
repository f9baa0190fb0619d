"""Posterior figures: correlation matrix and corner plot (section 6)."""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np

from heritage_bayes.report.figures.style import (
    C_ALT,
    C_MODEL,
    _figure,
    tex_safe,
)


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
