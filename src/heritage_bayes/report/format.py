"""Numbers, times and priors as people read them; labels of the model outputs.

Shared by every report section and by the other pages (portfolio, projection,
comparison): ``fmt(2.41e6) == "2.41×10⁶"``, ``fmt_time("2019-01-02T00:00Z") ==
"2019-01-02 00:00 UTC"``, ``prior_text("loguniform[1e+04, 1e+12]") ==
"loguniform[10000, 10¹²]"``.
"""

from __future__ import annotations

import math
import re

__all__ = [
    "OUT_UNITS",
    "OUT_WORDS",
    "fmt",
    "fmt_int",
    "fmt_interval_html",
    "fmt_pct",
    "fmt_time",
    "is_log_prior",
    "prior_text",
]

#: Unit of each model output.
OUT_UNITS = {"Ti": "°C", "Pi": "Pa", "RHi": "%"}
#: Plain words for each model output.
OUT_WORDS = {
    "Ti": "indoor temperature",
    "Pi": "indoor vapour pressure",
    "RHi": "indoor relative humidity",
}

_SUP = str.maketrans("-0123456789", "⁻⁰¹²³⁴⁵⁶⁷⁸⁹")


def fmt(x, digits: int = 3) -> str:
    """A number for people: 3 significant digits, ``2.41×10⁶`` for large/small ones."""
    if x is None:
        return "—"
    try:
        v = float(x)
    except (TypeError, ValueError):
        return str(x)
    if not math.isfinite(v):
        return "—" if math.isnan(v) else ("∞" if v > 0 else "−∞")
    if v == 0:
        return "0"
    if 1e-3 <= abs(v) < 1e5:
        s = f"{v:.{digits}g}"
        if "e" in s:  # e.g. 1e+03 from .3g
            s = f"{v:.0f}"
        return s.replace("-", "−")
    m, e = f"{v:.{digits - 1}e}".split("e")
    m = m.rstrip("0").rstrip(".") if "." in m else m
    return f"{m}×10{str(int(e)).translate(_SUP)}".replace("-", "−", 1)


def fmt_int(x) -> str:
    if x is None:
        return "—"
    try:
        v = float(x)
    except (TypeError, ValueError):
        return str(x)
    if not math.isfinite(v):
        return "—"
    return f"{round(v):,}".replace(",", " ")


def fmt_pct(x, digits: int = 0) -> str:
    if x is None or not math.isfinite(float(x)):
        return "—"
    return f"{100 * float(x):.{digits}f} %"


def fmt_interval_html(median, low, high) -> str:
    """``2.41×10⁶ [1.9×10⁶, 3.1×10⁶]`` as HTML that a narrow column wraps between the
    median and its interval, never inside a number or inside the interval."""
    return (
        f"<span class='nowrap'>{fmt(median)}</span> "
        f"<span class='nowrap'>[{fmt(low)}, {fmt(high)}]</span>"
    )


def fmt_time(text: str | None) -> str:
    """ISO time -> ``2019-01-02 00:00 UTC``."""
    if not text:
        return "—"
    import pandas as pd

    try:
        ts = pd.Timestamp(text)
    except (TypeError, ValueError):
        return str(text)
    ts = ts.tz_convert("UTC") if ts.tzinfo is not None else ts
    return f"{ts:%Y-%m-%d %H:%M} UTC"


_SCI = re.compile(r"(?<![\w.])[-+]?\d+(?:\.\d+)?e[-+]?\d+")


def prior_text(prior: str | None) -> str:
    """``loguniform[1e+04, 1e+12]`` -> ``loguniform[10⁴, 10¹²]`` (numbers for people)."""
    if not prior:
        return "—"

    def num(m):
        v = float(m.group(0))
        text = fmt(v)
        return text[2:] if text.startswith("1×10") else text

    return _SCI.sub(num, str(prior))


def is_log_prior(prior: str | None) -> bool:
    return bool(prior) and str(prior).startswith(("loguniform", "lognormal"))
