"""The house style of every figure: matplotlib settings, period colours, the figure
factory, date axes, period shading and gap hatching, and :func:`to_png_uri` (a figure as
a ``data:`` URI for a self-contained page). Reuse these for the figures of other pages
(projection, comparison) so that they look like the report's."""

from __future__ import annotations

import base64
import io
from collections.abc import Sequence

import numpy as np

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
            lab = "gap in the data"
            labelled[0] = True
        ax.axvspan(
            t0, t1, facecolor="none", edgecolor=C_GAP, hatch="///", lw=0, zorder=0.5, label=lab
        )
