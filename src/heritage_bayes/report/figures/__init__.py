"""The report's figures: matplotlib (object API, Agg canvas) and ``corner``.

Every function returns a :class:`matplotlib.figure.Figure` built without ``pyplot``, so
nothing here touches the global backend or keeps figures alive; :func:`to_png_uri`
renders one to a ``data:image/png;base64,…`` URI for the self-contained HTML. Axes carry
units in brackets, time axes are dates (UTC) and every figure with more than one series
has a legend.

Text from the config (room names, notes) never goes into a figure: only parameter,
input and output names, escaped for mathtext by :func:`tex_safe`.

One module per topic: :mod:`~heritage_bayes.report.figures.style` (settings, colours,
shading, :func:`to_png_uri`: the house style for every page's figures),
:mod:`~heritage_bayes.report.figures.series` (data overview, fit),
:mod:`~heritage_bayes.report.figures.posterior` (correlation, corner, prior vs
posterior),
:mod:`~heritage_bayes.report.figures.diagnostics` (traces, τ history, rank
plots, residuals) and
:mod:`~heritage_bayes.report.figures.ladder`; every name is importable from here.
"""

from __future__ import annotations

from heritage_bayes.report.figures.diagnostics import (
    fig_rank,
    fig_residuals,
    fig_tau_history,
    fig_traces,
)
from heritage_bayes.report.figures.ladder import fig_ladder
from heritage_bayes.report.figures.posterior import (
    fig_corner,
    fig_correlation,
    fig_prior_posterior,
)
from heritage_bayes.report.figures.series import fig_data_overview, fig_fit
from heritage_bayes.report.figures.style import (
    C_ALT,
    C_GAP,
    C_MEAS,
    C_MODEL,
    PERIOD_STYLE,
    RC_PARAMS,
    tex_safe,
    to_png_uri,
)

__all__ = [
    "C_ALT",
    "C_GAP",
    "C_MEAS",
    "C_MODEL",
    "PERIOD_STYLE",
    "RC_PARAMS",
    "fig_corner",
    "fig_correlation",
    "fig_data_overview",
    "fig_fit",
    "fig_ladder",
    "fig_prior_posterior",
    "fig_rank",
    "fig_residuals",
    "fig_tau_history",
    "fig_traces",
    "tex_safe",
    "to_png_uri",
]
