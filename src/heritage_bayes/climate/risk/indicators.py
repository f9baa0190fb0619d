r"""The conservation-risk indicators, one object per family: what each number is, its
options, its numpy computation and the parameters of its compiled kernel, side by side.

An :class:`Indicator` describes one column (name, unit, definition, source, period, the
direction that is worse, its rating scale, whether the projection also computes it per
year). A :class:`Family` is a set of columns computed together from the same hourly
terms — the groups of :func:`~heritage_bayes.climate.risk.assess`: ``chemical``,
``mechanical``, ``mould``, ``ashrae``, ``en15757``. It holds

* ``options``: the keyword of :func:`~heritage_bayes.climate.risk.assess` and the public
  function whose keyword defaults it takes (unknown keys are refused by name);
* ``check``: validation of the resolved options, once, before any work;
* ``columns`` and ``compute``: the column names and their values with numpy (one value
  per draw);
* ``ints``, ``floats`` and ``plan``: the named parameters of the compiled pass
  (:mod:`heritage_bayes.climate.risk._fused`) and their values. The parameter arrays'
  layout (:data:`LAYOUT`) is derived from these names: no index is kept by hand.

:data:`FAMILIES` is the registry that :func:`~heritage_bayes.climate.risk.assess`, the
fused pass, the projection and the pages read (through
:mod:`heritage_bayes.climate.risk.registry`). Adding an indicator to an existing family
is an entry here (its value in ``compute`` and in the compiled pass); a new family is a
:class:`Family` added with :func:`heritage_bayes.climate.risk.registry.register` (numpy
only, offered by ``assess``, the fused pass and the projection alike; the docs' page
"Extending the package" walks through one).
"""

from __future__ import annotations

import inspect
from collections.abc import Callable, Mapping
from dataclasses import asdict, dataclass, field

import numpy as np

from heritage_bayes.climate.risk._inputs import (
    HOURS_PER_YEAR,
    Hourly,
    check_positive,
    harmonic_mean,
    share_percent,
)
from heritage_bayes.climate.risk.biological import (
    _hours_above,
    _lim_c,
    _vtt_args,
    _vtt_run,
    hours_above_isopleth,
    vtt_mould_index,
)
from heritage_bayes.climate.risk.chemical import _T0, R_GAS, _check_lm, _pi, twlm
from heritage_bayes.climate.risk.mechanical import _emc, _minmax, dimensional_change
from heritage_bayes.climate.risk.standards import (
    _ashrae_check,
    _ashrae_core,
    _en_check,
    _en_core,
    _window_half,
    ashrae_classes,
    en15757_band,
)
from heritage_bayes.errors import InputError

__all__ = ["FAMILIES", "LAYOUT", "PROJECTION_INDICATORS", "Family", "Indicator", "Layout"]

_YEARS = "per complete year, summarised over the complete years of the series"
_SERIES = "over the complete years of the series (the whole series if shorter than a year)"
_HH = "Hailwood & Horrobin (1946); Wood Handbook FPL-GTR-190 (2010)"
_ASHRAE = "ASHRAE Handbook — HVAC Applications, ch. 24 (museums)"


@dataclass(frozen=True)
class Indicator:
    """One conservation-risk indicator (a column of
    :func:`~heritage_bayes.climate.risk.assess_batch` and of a projection).

    Attributes
    ----------
    key : str
        Column name (``{}`` in a parameterised family, e.g. ``ashrae_{}``).
    name : str
        Human name (for pages and tables).
    unit : str
        Unit of the value (``"-"`` for a ratio, ``"% of hours"`` for a share in 0–100).
    definition : str
        What is computed, in one or two sentences.
    source : str
        Standard or paper the definition follows.
    period : str
        The period the value is computed over.
    worse : int
        +1: a higher value is worse for the collection; -1: a lower value is worse;
        0: no direction (a band offset, a class).
    group : str
        Family (group of :func:`~heritage_bayes.climate.risk.assess`), or
        ``"projection"`` for indicators that need a baseline.
    annual : bool
        True where the value is a per-year quantity (computed per complete year).
    per_year : bool
        The projection also reports the value of each complete year
        (:func:`heritage_bayes.projection._stream.annual_values`).
    rating : callable or None
        value → rating on the field's published scale (``""`` where none applies).
    headline : int
        Place among the key indicators of a projection's figures and first screen
        (1 first; 0: not among them).
    """

    key: str
    name: str
    unit: str
    definition: str
    source: str
    period: str
    worse: int
    group: str
    annual: bool = True
    per_year: bool = field(default=False, compare=False)
    rating: Callable[[float], str] | None = field(default=None, compare=False, repr=False)
    headline: int = field(default=0, compare=False)

    def label(self) -> str:
        """``name [unit]`` (the unit left out for dimensionless ``-``)."""
        return self.name if self.unit in ("-", "") else f"{self.name} [{self.unit}]"

    def as_dict(self) -> dict:
        """JSON-ready entry (the descriptive fields)."""
        d = asdict(self)
        del d["per_year"], d["rating"], d["headline"]
        return d


@dataclass(frozen=True)
class Family:
    """Indicators computed together: options, numpy computation, kernel parameters.

    Attributes
    ----------
    name : str
        Group name of :func:`~heritage_bayes.climate.risk.assess` (``indicators=``).
    yearly : bool
        The values depend on the season: at least a year of hours is required.
    indicators : tuple of Indicator
        The registry entries of its columns.
    options : dict
        Keyword of :func:`~heritage_bayes.climate.risk.assess` → the function whose
        keyword defaults (less ``T``, ``RH``, ``nan_policy``, ``per_year``) are its options.
    check : callable
        ``check(func, opts)``: validates (and normalises in place) the resolved options
        ``opts`` (keyword → dict); raises :class:`~heritage_bayes.errors.InputError`.
    columns : callable
        ``columns(opts)`` → the column names, in order.
    compute : callable
        ``compute(h, opts, nan_policy, seasonal)`` → {column: values (draws,)} with numpy;
        ``seasonal`` is the 30-day RH mean shared by ASHRAE and EN 15757 (or None).
    ints, floats : tuple of str
        Names of its integer and float parameters in the compiled pass.
    plan : callable
        ``plan(opts, n_hours, shared)`` → ``(ints, floats, pad)``: values by name and the
        periodic padding [h] its moving averages need.
    defaults : dict
        Defaults that differ from the target function's (keyword → {option: value}).
    compiled : bool
        The compiled pass (:mod:`heritage_bayes.climate.risk._fused`) computes it: the
        projection and :func:`~heritage_bayes.climate.risk.assess_fused` use the kernel.
        Otherwise both compute it with ``compute``: the projection on the series the
        compiled pass keeps (:class:`heritage_bayes.climate.risk.fused.NumpyPass`).
    """

    name: str
    yearly: bool
    indicators: tuple[Indicator, ...]
    options: dict[str, Callable]
    check: Callable
    columns: Callable
    compute: Callable
    ints: tuple[str, ...] = ()
    floats: tuple[str, ...] = ()
    plan: Callable = field(default=lambda opts, n, shared: ({}, {}, 0), repr=False)
    defaults: dict = field(default_factory=dict)
    compiled: bool = False

    def option_defaults(self, keyword: str) -> dict:
        """Resolved defaults of the options ``keyword``."""
        sig = inspect.signature(self.options[keyword])
        skip = {"T", "RH", "nan_policy", "per_year"}
        d = {
            k: p.default
            for k, p in sig.parameters.items()
            if k not in skip and p.default is not inspect.Parameter.empty
        }
        d.update({k: (dict(v) if isinstance(v, Mapping) else v)
                  for k, v in self.defaults.get(keyword, {}).items()})  # fmt: skip
        return d


def _scale(*steps, last):
    """A rating: the label of the first ``(test, label)`` whose test holds, else ``last``."""

    def rate(v) -> str:
        return next((lab for test, lab in steps if test(v)), last)

    return rate


#: Upper limits of the ISO 9223 time-of-wetness categories τ1-τ4. [h/year]
TOW_TOPS = (10.0, 250.0, 2500.0, 5500.0)
_TOW = _scale(*((lambda v, top=top: v <= top, f"τ{i}") for i, top in enumerate(TOW_TOPS, 1)),
              last="τ5")  # fmt: skip


# ------------------------------------------------------------------------------ chemical
def _chem_check(func, opts):
    lm = opts["lm"]
    Ea = lm["Ea"]
    if not isinstance(Ea, Mapping):
        Ea = {f"Ea={float(check_positive(func, 'Ea', Ea)) / 1e3:g}kJ/mol": Ea}
    if not Ea:
        raise InputError(f"{func}: lm Ea must name at least one material; got {{}}")
    for Ea_i in Ea.values():
        _check_lm(func, Ea_i, lm["T_ref"], lm["RH_ref"], lm["n"])
    lm["Ea"] = {str(k): float(v) for k, v in Ea.items()}


def time_of_wetness(h: Hourly, nan_policy) -> np.ndarray:
    """Hours per year with RH > 80 % and T > 0 °C (ISO 9223 time of wetness). [h/year]"""
    valid = np.isfinite(h.T) & np.isfinite(h.RH)
    with np.errstate(invalid="ignore"):
        wet = (h.RH > 80.0) & (h.T > 0.0)
    return share_percent(wet, valid, nan_policy) / 100.0 * HOURS_PER_YEAR


def _chem_compute(h, opts, nan_policy, seasonal):
    T, RH, lm, out = h.T, h.RH, opts["lm"], {}
    with np.errstate(divide="ignore", over="ignore"):
        u = 1.0 / (T + _T0) - 1.0 / (lm["T_ref"] + _T0)
        rh_term = lm["n"] * np.log(lm["RH_ref"] / RH)
        for label, Ea in lm["Ea"].items():
            val = np.exp(Ea / R_GAS * u + rh_term)
            out[f"lifetime_multiplier[{label}]"] = harmonic_mean(val, nan_policy)
    out["twpi"] = harmonic_mean(_pi(T, RH), nan_policy)
    out["time_of_wetness"] = time_of_wetness(h, nan_policy)
    return out


def _chem_plan(opts, n, shared):
    lm = opts["lm"]
    floats = {"tref_inv": 1.0 / (lm["T_ref"] + _T0), "rh_ref": lm["RH_ref"], "n": lm["n"]}
    return {"nea": len(lm["Ea"])}, floats, 0


CHEMICAL = Family(
    name="chemical",
    compiled=True,
    yearly=True,
    indicators=(
        Indicator(
            "lifetime_multiplier[{}]", "Lifetime multiplier ({})", "-",
            "Time-weighted lifetime multiplier of chemically unstable material relative "
            "to 20 °C, 50 % RH: harmonic mean over the hours of exp(Ea/R (1/T − 1/Tref)) "
            "(RHref/RH)^n.",
            "Michalski (2002), ICOM-CC 13th Triennial Meeting, 66-72", _YEARS, -1, "chemical",
        ),
        Indicator(
            "twpi", "Time-weighted preservation index", "years",
            "Harmonic mean over the hours of the preservation index PI(T, RH) of "
            "cellulose-acetate/paper (IPI); < 45 years rated 'risk', ≥ 75 'good'.",
            "Sebera (1994) Isoperms; Reilly, Nishimura & Zinn (1995) New Tools for Preservation",
            _YEARS, -1, "chemical", per_year=True, headline=1,
            rating=_scale((lambda v: v >= 75.0, "good"), (lambda v: v >= 45.0, "OK"), last="risk"),
        ),
        Indicator(
            "time_of_wetness", "Time of wetness (metal corrosion)", "h/year",
            "Hours per year with RH > 80 % and T > 0 °C, the time of wetness τ of "
            "ISO 9223 (categories τ1 ≤ 10, τ2 ≤ 250, τ3 ≤ 2500, τ4 ≤ 5500, τ5 > 5500 "
            "h/year).",
            "ISO 9223:2012 (annex C, time of wetness)", _YEARS, 1, "chemical",
            per_year=True, rating=_TOW, headline=2,
        ),
    ),
    options={"lm": twlm},
    defaults={"lm": {"Ea": {"paper": 100e3, "varnish": 70e3}}},
    check=_chem_check,
    columns=lambda o: [f"lifetime_multiplier[{k}]" for k in o["lm"]["Ea"]]
    + ["twpi", "time_of_wetness"],
    compute=_chem_compute,
    ints=("nea",),
    floats=("tref_inv", "rh_ref", "n"),
    plan=_chem_plan,
)  # fmt: skip


# ---------------------------------------------------------------------------- mechanical
def _mech_check(func, opts):
    opts["emc"]["coefficient"] = check_positive(func, "coefficient", opts["emc"]["coefficient"])


def _mech_compute(h, opts, nan_policy, seasonal):
    lo, hi = _minmax(_emc(h.T, h.RH), nan_policy)
    dim = 100.0 * opts["emc"]["coefficient"] * (hi - lo)
    return {"emc_min": lo, "emc_max": hi, "emc_range": hi - lo, "dimensional_change": dim}


MECHANICAL = Family(
    name="mechanical",
    compiled=True,
    yearly=False,
    indicators=(
        Indicator(
            "emc_min", "Lowest equilibrium moisture content of wood", "% MC",
            "Minimum over the hours of the Hailwood-Horrobin EMC of wood; < 5 % rated "
            "'risk' (shrinkage, cracking).", _HH, _SERIES, -1, "mechanical", annual=False,
            rating=_scale((lambda v: v >= 5.0, "OK"), last="risk"),
        ),
        Indicator(
            "emc_max", "Highest equilibrium moisture content of wood", "% MC",
            "Maximum over the hours of the Hailwood-Horrobin EMC of wood; > 12.5 % rated "
            "'risk' (swelling).", _HH, _SERIES, 1, "mechanical", annual=False,
            rating=_scale((lambda v: v <= 12.5, "OK"), last="risk"),
        ),
        Indicator(
            "emc_range", "Range of wood moisture content", "% MC",
            "Maximum minus minimum EMC over the period.", _HH, _SERIES, 1, "mechanical",
            annual=False, headline=5,
        ),
        Indicator(
            "dimensional_change", "Dimensional change of wood (tangential)", "%",
            "Swelling coefficient × EMC range: the tangential dimensional change of "
            "unrestrained wood over the period.",
            "Wood Handbook FPL-GTR-190 (2010), ch. 4", _SERIES, 1, "mechanical", annual=False,
        ),
    ),
    options={"emc": dimensional_change},
    check=_mech_check,
    columns=lambda o: ["emc_min", "emc_max", "emc_range", "dimensional_change"],
    compute=_mech_compute,
    floats=("coefficient",),
    plan=lambda o, n, shared: ({}, {"coefficient": o["emc"]["coefficient"]}, 0),
)  # fmt: skip


# --------------------------------------------------------------------------------- mould
def _mould_check(func, opts):
    v = opts["vtt"]
    opts["vtt"] = {"args": _vtt_args(func, **v), **v}
    opts["isopleth"]["c"] = _lim_c(func, opts["isopleth"]["growth_rate"])


def _lim_name(opts) -> str:
    return f"hours_above_LIM{float(opts['isopleth']['growth_rate']):g}"


def _mould_compute(h, opts, nan_policy, seasonal):
    _, peak = _vtt_run(h, opts["vtt"]["args"], nan_policy, store=False)
    return {
        "vtt_mould_index_max": peak,
        _lim_name(opts): _hours_above(h, opts["isopleth"]["c"], True, nan_policy),
    }


_VTT = ("k1_lo", "k1_hi", "A", "B", "C", "RH_min", "C_mat", "W", "SQ", "M0")


def _mould_plan(opts, n, shared):
    *vals, frozen_decline = opts["vtt"]["args"]
    floats = dict(zip(_VTT, vals, strict=True)) | {"lim_c": opts["isopleth"]["c"]}
    return {"frozen_decline": int(bool(frozen_decline))}, floats, 0


MOULD = Family(
    name="mould",
    compiled=True,
    yearly=True,
    indicators=(
        Indicator(
            "vtt_mould_index_max", "Highest VTT mould index", "-",
            "Maximum of the VTT mould index M (0 no growth, 1 microscopic, 3 visible) "
            "over the period; ≥ 1 rated 'risk'.",
            "Hukka & Viitanen (1999) doi:10.1007/s002260050131; Ojanen et al. (2010)",
            _SERIES, 1, "mould", annual=False, headline=3,
            rating=_scale((lambda v: v < 1.0, "good"), last="risk"),
        ),
        Indicator(
            "hours_above_LIM{}", "Hours above the lowest isopleth for mould (LIM{})", "h/year",
            "Hours per year with RH above the lowest isopleth for mould growth at the "
            "hour's temperature.",
            "Sedlbauer (2001); Zeng et al. (2023) doi:10.1177/01436244221137846", _YEARS, 1,
            "mould", per_year=True, headline=4,
        ),
    ),
    options={"vtt": vtt_mould_index, "isopleth": hours_above_isopleth},
    check=_mould_check,
    columns=lambda o: ["vtt_mould_index_max", _lim_name(o)],
    compute=_mould_compute,
    ints=("frozen_decline",),
    floats=(*_VTT, "lim_c"),
    plan=_mould_plan,
)  # fmt: skip


# -------------------------------------------------------------------- ASHRAE, EN 15757
def shared_seasonal(groups, opts) -> bool:
    """ASHRAE and EN 15757 both selected with the same window and edges: one seasonal
    RH mean serves both."""
    a, e = opts["ashrae"], opts["en15757"]
    both = "ashrae" in groups and "en15757" in groups
    return both and a["window_days"] == e["window_days"] and a["edges"] == e["edges"]


def _ashrae_check_opts(func, opts):
    a = opts["ashrae"]
    a["threshold"], a["classes"] = _ashrae_check(
        func, a["method"], a["threshold"], a["classes"], a["edges"], a["T_setpoint"],
        a["RH_setpoint"],
    )  # fmt: skip
    check_positive(func, "ashrae window_days", a["window_days"])


def _ashrae_compute(h, opts, nan_policy, seasonal):
    a = opts["ashrae"]
    keys = ("window_days", "T_setpoint", "RH_setpoint", "method", "threshold", "classes", "edges")
    sh, _, _, best, _, _ = _ashrae_core(
        h, **{k: a[k] for k in keys}, nested=bool(a["nested"]), nan_policy=nan_policy,
        sRH=seasonal,
    )  # fmt: skip
    out = {f"ashrae_{c.name}": sh[:, j] for j, c in enumerate(a["classes"])}
    out["ashrae_best_class"] = np.array(["none" if b is None else b for b in best], dtype=object)
    return out


def _ashrae_plan(opts, n, shared):
    a = opts["ashrae"]
    half = _window_half("ashrae_classes", a["window_days"], n)
    wrap = a["edges"] == "wrap"
    ints = {"half": half, "wrap": int(wrap), "setpoint": int(a["method"] == "setpoint"),
            "nested": int(bool(a["nested"])), "n_classes": len(a["classes"])}  # fmt: skip
    floats = {"threshold": a["threshold"]}
    for key in ("T_setpoint", "RH_setpoint"):
        if a[key] is not None:
            ints[f"has_{key}"] = 1
            floats[key] = float(a[key])
    return ints, floats, half if wrap else 0


ASHRAE = Family(
    name="ashrae",
    compiled=True,
    yearly=True,
    indicators=(
        Indicator(
            "ashrae_{}", "Hours within ASHRAE class {}", "% of hours",
            "Share of the hours that meet the short-term and seasonal limits of the "
            "ASHRAE museum climate class.", _ASHRAE, _YEARS, -1, "ashrae",
        ),
        Indicator(
            "ashrae_best_class", "Best ASHRAE class reached", "class",
            "The strictest class whose share of hours reaches the threshold ('none' if none "
            "does).", _ASHRAE, _YEARS, 0, "ashrae",
        ),
    ),
    options={"ashrae": ashrae_classes},
    check=_ashrae_check_opts,
    columns=lambda o: [f"ashrae_{c.name}" for c in o["ashrae"]["classes"]]
    + ["ashrae_best_class"],
    compute=_ashrae_compute,
    ints=("half", "wrap", "setpoint", "nested", "n_classes", "has_T_setpoint",
          "has_RH_setpoint"),
    floats=("threshold", "T_setpoint", "RH_setpoint"),
    plan=_ashrae_plan,
)  # fmt: skip


def _en_check_opts(func, opts):
    e = opts["en15757"]
    check_positive(func, "en15757 window_days", e["window_days"])
    e["percentiles"], e["min_band"] = _en_check(
        func, e["percentiles"], e["min_band"], e["min_band_mode"], e["edges"]
    )


def _en_compute(h, opts, nan_policy, seasonal):
    e = opts["en15757"]
    keys = ("window_days", "percentiles", "min_band", "min_band_mode", "edges")
    *_, lo, hi, _, _, share = _en_core(
        h.RH, **{k: e[k] for k in keys}, nan_policy=nan_policy, seasonal=seasonal
    )
    return {"en15757_outside": share, "en15757_lower_offset": lo, "en15757_upper_offset": hi}


def _en_plan(opts, n, shared):
    e = opts["en15757"]
    half = _window_half("en15757_band", e["window_days"], n)
    wrap = e["edges"] == "wrap"
    ints = {"half": half, "wrap": int(wrap), "shared": int(shared),
            "width": int(e["min_band_mode"] == "width")}  # fmt: skip
    lo, hi = e["percentiles"]
    floats = {"q_lo": lo / 100, "q_hi": hi / 100, "min_band": e["min_band"]}  # as np.percentile
    return ints, floats, half if wrap else 0


EN15757 = Family(
    name="en15757",
    compiled=True,
    yearly=True,
    indicators=(
        Indicator(
            "en15757_outside", "Hours outside the series' own EN 15757 band (self-referenced)",
            "% of hours",
            "Share of the hours outside the EN 15757 band computed from the same series "
            "(≈ 14 % by construction for any climate: 7 % below the 7th and above the "
            "93rd percentile). Describes a measured historical climate; for a future "
            "climate use the hours outside the baseline EN 15757 band.",
            "EN 15757:2010; Camuffo et al. (2022) doi:10.3390/atmos13091344", _YEARS, 0,
            "en15757",
        ),
        Indicator(
            "en15757_lower_offset", "EN 15757 band, lower offset", "%RH",
            "Lower edge of the band relative to the 30-day centred moving average: the "
            "7th percentile of the short-term fluctuations, widened to the minimum band.",
            "EN 15757:2010", _YEARS, 0, "en15757",
        ),
        Indicator(
            "en15757_upper_offset", "EN 15757 band, upper offset", "%RH",
            "Upper edge of the band relative to the 30-day centred moving average: the "
            "93rd percentile of the short-term fluctuations, widened to the minimum band.",
            "EN 15757:2010", _YEARS, 0, "en15757",
        ),
    ),
    options={"en15757": en15757_band},
    check=_en_check_opts,
    columns=lambda o: ["en15757_outside", "en15757_lower_offset", "en15757_upper_offset"],
    compute=_en_compute,
    ints=("half", "wrap", "shared", "width"),
    floats=("q_lo", "q_hi", "min_band"),
    plan=_en_plan,
)  # fmt: skip

#: Every family, in the order of the columns (:func:`heritage_bayes.climate.risk.registry.register`
#: appends one).
FAMILIES: list[Family] = [CHEMICAL, MECHANICAL, MOULD, ASHRAE, EN15757]

#: Indicators of a projection that need a baseline (not computed by ``assess``).
PROJECTION_INDICATORS = (
    Indicator(
        "en15757_outside_baseline", "Hours outside the baseline EN 15757 band", "% of hours",
        "Share of the hours outside the band the collection is acclimatised to: the "
        "baseline climate's seasonal cycle (30-day centred moving average, averaged "
        "by hour of the year) plus its 7th/93rd percentile offsets (at least the "
        "minimum band), both from the same posterior draw's baseline simulation.",
        "EN 15757:2010, clause 5 (historical climate as the target)", _YEARS, 1, "projection",
        per_year=True, headline=6,
    ),
)  # fmt: skip


class Layout:
    """Positions of the compiled pass's parameters, derived from :data:`FAMILIES`.

    ``ipar``: one switch per family (its name), then each family's ``ints`` as
    ``"<family>.<name>"``; ``fpar``: each family's ``floats`` the same way (compiled
    families only).
    """

    def __init__(self, families):
        families = [f for f in families if f.compiled]
        names = [f.name for f in families]
        self.ints = (*names, *(f"{f.name}.{p}" for f in families for p in f.ints))
        self.floats = tuple(f"{f.name}.{p}" for f in families for p in f.floats)
        self._i = {n: j for j, n in enumerate(self.ints)}
        self._f = {n: j for j, n in enumerate(self.floats)}

    def i(self, name: str) -> int:
        """Index of an integer parameter (a family's switch: its name)."""
        return self._i[name]

    def f(self, name: str) -> int:
        """Index of a float parameter."""
        return self._f[name]

    def arrays(self) -> tuple[np.ndarray, np.ndarray]:
        """Zeroed ``(ipar, fpar)``."""
        return np.zeros(len(self.ints), np.int64), np.zeros(len(self.floats))


LAYOUT = Layout(FAMILIES)
