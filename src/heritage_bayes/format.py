"""The one formatter: numbers, intervals, times, priors, units and labels for people.

Shared by every report section, the other pages (portfolio, projection, comparison)
and the CLI, so that the same figure prints the same digits everywhere:
``fmt(2.41e6) == "2.41×10⁶"``, ``fmt_time("2019-01-02T00:00Z") == "2019-01-02 00:00 UTC"``,
``prior_text("loguniform[1e+04, 1e+12]") == "loguniform[10000, 10¹²]"``.

Labels: every parameter and derived quantity of a run as people read it, with its
symbol where it helps and its unit (:func:`quantity_label`: ``tau_1_h`` -> ``τ₁ [h]``,
``fI_E`` -> ``solar aperture, east facade [m²]``, ``sigma_meas_Ti`` -> ``measurement
noise of Ti [K]``, ``gain_Ti_Te`` -> ``gain from outdoor air [-]``), so that no page
prints a code name in its prose; parameter tables keep the code name in a small
secondary column for users of the Python interface.
"""

from __future__ import annotations

import math
import re

__all__ = [
    "OUT_UNITS",
    "OUT_WORDS",
    "fmt",
    "fmt_int",
    "fmt_interval",
    "fmt_interval_html",
    "fmt_pct",
    "fmt_time",
    "is_log_prior",
    "prior_text",
    "prose_html",
    "quantity_label",
    "quantity_name",
    "surface_words",
    "tick_names",
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


def _number(x) -> float | str:
    """``x`` as a float, or the text a page prints for it: "—" for None, ``str(x)`` for
    what is not a number."""
    if x is None:
        return "—"
    try:
        return float(x)
    except (TypeError, ValueError):
        return str(x)


def fmt(x, digits: int = 3) -> str:
    """A number for people: 3 significant digits, ``2.41×10⁶`` for large/small ones."""
    v = _number(x)
    if isinstance(v, str):
        return v
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
    v = _number(x)
    if isinstance(v, str):
        return v
    if not math.isfinite(v):
        return "—"
    return f"{round(v):,}".replace(",", " ")


def fmt_pct(x, digits: int = 0) -> str:
    if x is None or not math.isfinite(float(x)):
        return "—"
    return f"{100 * float(x):.{digits}f} %"


def fmt_interval(low, high) -> str:
    """A 90 % interval as every page prints it: ``[1.9×10⁶, 3.1×10⁶]``."""
    return f"[{fmt(low)}, {fmt(high)}]"


def fmt_interval_html(median, low, high) -> str:
    """``2.41×10⁶ [1.9×10⁶, 3.1×10⁶]`` as HTML that a narrow column wraps between the
    median and its interval, never inside a number or inside the interval."""
    return (
        f"<span class='nowrap'>{fmt(median)}</span> "
        f"<span class='nowrap'>{fmt_interval(low, high)}</span>"
    )


_TICKS = re.compile(r"`([^`]+)`")


def prose_html(text) -> str:
    """Plain text as HTML: escaped, and each ```name``` (a config key, a command, a
    model name the user types) set as code, so that the page's prose names no code
    identifier outside a code element."""
    from html import escape

    return _TICKS.sub(r"<code>\1</code>", escape(str(text), quote=False))


def tick_names(text: str, names) -> str:
    """``text`` with each whole-word occurrence of one of ``names`` (parameter names of
    a model) in backticks, for :func:`prose_html` to set as code."""
    names = sorted({str(n) for n in names if n}, key=len, reverse=True)
    if not names or not text:
        return text
    pattern = re.compile(r"(?<![\w`])(" + "|".join(map(re.escape, names)) + r")(?![\w`])")
    return pattern.sub(r"`\1`", str(text))


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


# ---------------------------------------------------------------- labels of quantities

_FACADE = {"N": "north", "E": "east", "S": "south", "W": "west", "H": "roof", "R": "roof"}
_SUB = str.maketrans("0123456789", "₀₁₂₃₄₅₆₇₈₉")

#: Plain words of the RC parameters, by domain; the symbol follows where it helps.
_PARAM_WORDS = {
    "thermal": {
        "Cw": "heat capacity of the envelope Cw",
        "Ci": "heat capacity of the air and fast contents Ci",
        "Cint": "heat capacity of the interior mass Cint",
        "Gw": "conductance envelope to outdoors Gw",
        "Gi": "conductance envelope to indoor air Gi",
        "Gint": "conductance indoor air to interior mass Gint",
        "Gfast": "fast conductance to outdoors (air change, glazing) Gfast",
        "Gf": "conductance to the ground Gf",
        "Ge": "conductance to outdoors Ge",
        "fsol": "share of the sun on the interior mass",
        "Tf": "ground temperature Tf",
        "Ph": "heating power Ph",
    },
    "hygric": {
        "Cw": "moisture capacity of the buffering surfaces Cw",
        "Ci": "moisture capacity of the indoor air Ci",
        "Gw": "vapour conductance buffer to outdoors Gw",
        "Gi": "vapour conductance buffer to indoor air Gi",
        "Gfast": "vapour conductance to outdoors (air change) Gfast",
        "Gf": "vapour conductance to the fixed node Gf",
        "Pf": "vapour pressure of the fixed node Pf",
    },
}
_NOISE_WORDS = {
    "sigma_meas": "measurement noise of {o}",
    "sigma": "model error of {o}",
    "phi": "model-error autocorrelation of {o}",
    "diffusion": "process noise of node {o}",
}
_INPUT_WORDS = {
    "Te": "outdoor air",
    "Tf": "the ground",
    "Pe": "outdoor vapour pressure",
    "Pf": "the fixed vapour-pressure node",
    "Ph": "heating power",
}


_COMPASS = {
    **{k: _FACADE[k] for k in ("N", "E", "S", "W")},
    "NE": "north-east",
    "SE": "south-east",
    "SW": "south-west",
    "NW": "north-west",
}


def surface_words(side: str) -> str:
    """A solar surface in words: ``E`` the east facade, ``roof_SE`` the south-east
    slope of the roof (the roof planes ``hbayes init`` writes), anything else by its
    name (``surface dome``)."""
    if side in _FACADE:
        return f"{_FACADE[side]} facade"
    if side.startswith("roof_") and side[5:] in _COMPASS:
        return f"{_COMPASS[side[5:]]} slope of the roof"
    return f"surface {side}"


def _input_words(u: str) -> str:
    if u.startswith("I_"):
        return f"sun on the {surface_words(u[2:])}"
    return _INPUT_WORDS.get(u, u)


#: Names built from a pattern (time constants, gains, offsets, apertures, initial
#: states) and their words.
_NAME_PATTERNS = (
    (re.compile(r"tau_(\d+)_h"), lambda m: f"time constant τ{m.group(1).translate(_SUB)}"),
    (re.compile(r"gain_(Ti|Pi|RHi)_(.+)"), lambda m: f"gain from {_input_words(m.group(2))}"),
    (re.compile(r"offset_(Ti|Pi|RHi)_(.+)"), lambda m: f"offset from {_input_words(m.group(2))}"),
    (re.compile(r"fI_(\w+)"), lambda m: f"solar aperture, {surface_words(m.group(1))}"),
    (re.compile(r"x0_(\w+)"), lambda m: f"initial state of node {m.group(1)}"),
)


def quantity_name(name: str, description: str | None = None, *, domain: str = "") -> str:
    """The plain-words name of a parameter or derived quantity of a run, without unit.

    ``name`` is the quantity's name in its section (``Ci``, ``fI_E``, ``tau_1_h``,
    ``gain_Ti_I_N``, ``sigma_meas_Ti``) or its key with the section (``thermal.Ci``,
    which also gives the domain). An unknown name falls back to its ``description``
    (the model's words), else to itself.
    """
    if "." in name:
        domain, name = name.split(".", 1)
    for pattern, words in _NAME_PATTERNS:
        if m := pattern.fullmatch(name):
            return words(m)
    for kind, words in _NOISE_WORDS.items():
        if name.startswith(f"{kind}_"):
            return words.format(o=name[len(kind) + 1 :])
    words = _PARAM_WORDS.get(domain, {}).get(name) or _PARAM_WORDS["thermal"].get(name)
    if words and not (domain == "" and name in _PARAM_WORDS["hygric"]):
        return words
    if description:
        return str(description)
    return name.replace("_", " ")


def quantity_label(
    name: str, unit: str | None = None, description: str | None = None, *, domain: str = ""
) -> str:
    """:func:`quantity_name` with its unit: ``τ₁ [h]``-style text for tables and prose
    (``[-]`` for a dimensionless quantity, nothing when the unit is unknown)."""
    words = quantity_name(name, description, domain=domain)
    if words.startswith("time constant τ"):
        words = words[len("time constant ") :]
    if unit is None or unit == "":
        return words
    return f"{words} [{unit}]"
