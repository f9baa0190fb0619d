r"""The indicator registry: one entry per conservation-risk indicator, read by
:func:`~heritage_bayes.climate.risk.assess` (units), the projection page, its CSV/JSON
outputs and the documentation.

Each :class:`Indicator` says what the number is (``definition``), in which unit, where
the definition comes from (``source``), over which period it is computed (``period``)
and which direction is worse for the collection (``worse``). Parameterised columns
(``lifetime_multiplier[paper]``, ``hours_above_LIM0``, ``ashrae_AA``) resolve to their
family's entry with the parameter filled in (:func:`indicator_info`).

Periods
-------
Indicators that aggregate over time depend on the season the series covers (a
January–May record gives a much longer TWPI than the full year of the same room, because
cold months slow chemical decay). :func:`~heritage_bayes.climate.risk.assess` therefore
computes every indicator of a series of a year or more over its **complete years** only
(:func:`complete_year_hours`: the first ``⌊n / 8760⌋ × 8760`` hours; a typical year on
a grid, 8736–8759 h, counts as one) and states the hours left out; the yearly groups
(``chemical``, ``mould``, ``ashrae``, ``en15757``) refuse a series shorter than a year.

An intervention (a change of the calibrated room) is compared with the
do-nothing case through the same entries: ``worse`` gives the sign of "better" and the
unit the scale of a difference.
"""

from __future__ import annotations

import re
from dataclasses import asdict, dataclass, replace

from heritage_bayes.climate.risk._inputs import HOURS_PER_YEAR, MIN_YEAR_HOURS
from heritage_bayes.errors import InputError

__all__ = [
    "INDICATORS",
    "Indicator",
    "as_markdown",
    "check_indicator_names",
    "complete_year_hours",
    "indicator_info",
]

_YEARS = "per complete year, summarised over the complete years of the series"
_SERIES = "over the complete years of the series (the whole series if shorter than a year)"


@dataclass(frozen=True)
class Indicator:
    """One conservation-risk indicator.

    Attributes
    ----------
    key : str
        Column name in :func:`~heritage_bayes.climate.risk.assess_batch` and in the
        projection outputs.
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
        Indicator group of :func:`~heritage_bayes.climate.risk.assess` (or
        ``"projection"`` for indicators that need a baseline).
    annual : bool
        True where the value is a per-year quantity (computed per complete year).
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

    def label(self) -> str:
        """``name [unit]`` (the unit left out for dimensionless ``-``)."""
        return self.name if self.unit in ("-", "") else f"{self.name} [{self.unit}]"

    def as_dict(self) -> dict:
        """JSON-ready entry."""
        return asdict(self)


def _entries() -> dict[str, Indicator]:
    e = [
        Indicator(
            "lifetime_multiplier[{}]",
            "Lifetime multiplier ({})",
            "-",
            "Time-weighted lifetime multiplier of chemically unstable material relative "
            "to 20 °C, 50 % RH: harmonic mean over the hours of exp(Ea/R (1/T − 1/Tref)) "
            "(RHref/RH)^n.",
            "Michalski (2002), ICOM-CC 13th Triennial Meeting, 66-72",
            _YEARS,
            -1,
            "chemical",
        ),
        Indicator(
            "twpi",
            "Time-weighted preservation index",
            "years",
            "Harmonic mean over the hours of the preservation index PI(T, RH) of "
            "cellulose-acetate/paper (IPI); < 45 years rated 'risk', ≥ 75 'good'.",
            "Sebera (1994) Isoperms; Reilly, Nishimura & Zinn (1995) New Tools for Preservation",
            _YEARS,
            -1,
            "chemical",
        ),
        Indicator(
            "time_of_wetness",
            "Time of wetness (metal corrosion)",
            "h/year",
            "Hours per year with RH > 80 % and T > 0 °C, the time of wetness τ of "
            "ISO 9223 (categories τ1 ≤ 10, τ2 ≤ 250, τ3 ≤ 2500, τ4 ≤ 5500, τ5 > 5500 "
            "h/year).",
            "ISO 9223:2012 (annex C, time of wetness)",
            _YEARS,
            1,
            "chemical",
        ),
        Indicator(
            "emc_min",
            "Lowest equilibrium moisture content of wood",
            "% MC",
            "Minimum over the hours of the Hailwood-Horrobin EMC of wood; < 5 % rated "
            "'risk' (shrinkage, cracking).",
            "Hailwood & Horrobin (1946); Wood Handbook FPL-GTR-190 (2010)",
            _SERIES,
            -1,
            "mechanical",
            annual=False,
        ),
        Indicator(
            "emc_max",
            "Highest equilibrium moisture content of wood",
            "% MC",
            "Maximum over the hours of the Hailwood-Horrobin EMC of wood; > 12.5 % rated "
            "'risk' (swelling).",
            "Hailwood & Horrobin (1946); Wood Handbook FPL-GTR-190 (2010)",
            _SERIES,
            1,
            "mechanical",
            annual=False,
        ),
        Indicator(
            "emc_range",
            "Range of wood moisture content",
            "% MC",
            "Maximum minus minimum EMC over the period.",
            "Hailwood & Horrobin (1946); Wood Handbook FPL-GTR-190 (2010)",
            _SERIES,
            1,
            "mechanical",
            annual=False,
        ),
        Indicator(
            "dimensional_change",
            "Dimensional change of wood (tangential)",
            "%",
            "Swelling coefficient × EMC range: the tangential dimensional change of "
            "unrestrained wood over the period.",
            "Wood Handbook FPL-GTR-190 (2010), ch. 4",
            _SERIES,
            1,
            "mechanical",
            annual=False,
        ),
        Indicator(
            "vtt_mould_index_max",
            "Highest VTT mould index",
            "-",
            "Maximum of the VTT mould index M (0 no growth, 1 microscopic, 3 visible) "
            "over the period; ≥ 1 rated 'risk'.",
            "Hukka & Viitanen (1999) doi:10.1007/s002260050131; Ojanen et al. (2010)",
            _SERIES,
            1,
            "mould",
            annual=False,
        ),
        Indicator(
            "hours_above_LIM{}",
            "Hours above the lowest isopleth for mould (LIM{})",
            "h/year",
            "Hours per year with RH above the lowest isopleth for mould growth at the "
            "hour's temperature.",
            "Sedlbauer (2001); Zeng et al. (2023) doi:10.1177/01436244221137846",
            _YEARS,
            1,
            "mould",
        ),
        Indicator(
            "ashrae_{}",
            "Hours within ASHRAE class {}",
            "% of hours",
            "Share of the hours that meet the short-term and seasonal limits of the "
            "ASHRAE museum climate class.",
            "ASHRAE Handbook — HVAC Applications, ch. 24 (museums)",
            _YEARS,
            -1,
            "ashrae",
        ),
        Indicator(
            "ashrae_best_class",
            "Best ASHRAE class reached",
            "class",
            "The strictest class whose share of hours reaches the threshold ('none' if none does).",
            "ASHRAE Handbook — HVAC Applications, ch. 24 (museums)",
            _YEARS,
            0,
            "ashrae",
        ),
        Indicator(
            "en15757_outside",
            "Hours outside the series' own EN 15757 band (self-referenced)",
            "% of hours",
            "Share of the hours outside the EN 15757 band computed from the same series "
            "(≈ 14 % by construction for any climate: 7 % below the 7th and above the "
            "93rd percentile). Describes a measured historical climate; for a future "
            "climate use the hours outside the baseline EN 15757 band.",
            "EN 15757:2010; Camuffo et al. (2022) doi:10.3390/atmos13091344",
            _YEARS,
            0,
            "en15757",
        ),
        Indicator(
            "en15757_lower_offset",
            "EN 15757 band, lower offset",
            "%RH",
            "Lower edge of the band relative to the 30-day centred moving average: the "
            "7th percentile of the short-term fluctuations, widened to the minimum band.",
            "EN 15757:2010",
            _YEARS,
            0,
            "en15757",
        ),
        Indicator(
            "en15757_upper_offset",
            "EN 15757 band, upper offset",
            "%RH",
            "Upper edge of the band relative to the 30-day centred moving average: the "
            "93rd percentile of the short-term fluctuations, widened to the minimum band.",
            "EN 15757:2010",
            _YEARS,
            0,
            "en15757",
        ),
        Indicator(
            "en15757_outside_baseline",
            "Hours outside the baseline EN 15757 band",
            "% of hours",
            "Share of the hours outside the band the collection is acclimatised to: the "
            "baseline climate's seasonal cycle (30-day centred moving average, averaged "
            "by hour of the year) plus its 7th/93rd percentile offsets (at least the "
            "minimum band), both from the same posterior draw's baseline simulation.",
            "EN 15757:2010, clause 5 (historical climate as the target)",
            _YEARS,
            1,
            "projection",
        ),
    ]
    return {i.key: i for i in e}


#: Every indicator family by key (parameterised ones with ``{}``).
INDICATORS: dict[str, Indicator] = _entries()
_PATTERNS = [
    (re.compile(r"^lifetime_multiplier\[(.+)\]$"), "lifetime_multiplier[{}]"),
    (re.compile(r"^hours_above_LIM(.+)$"), "hours_above_LIM{}"),
    (re.compile(r"^ashrae_(?!best_class$)(.+)$"), "ashrae_{}"),
]


def indicator_info(key: str) -> Indicator:
    """The registry entry of an indicator column.

    Parameters
    ----------
    key : str
        A column of :func:`~heritage_bayes.climate.risk.assess_batch` or of a projection.

    Returns
    -------
    Indicator
        With the parameter filled in for parameterised families.

    Raises
    ------
    heritage_bayes.errors.InputError
        An unknown name (the message lists the known ones).
    """
    if key in INDICATORS:
        return INDICATORS[key]
    for pat, fam in _PATTERNS:
        m = pat.match(key)
        if m:
            base = INDICATORS[fam]
            return replace(base, key=key, name=base.name.format(m.group(1)))
    raise InputError(f"unknown indicator {key!r}; known: {', '.join(INDICATORS)}")


def check_indicator_names(names, available, where: str) -> None:
    """Refuse names that are not among ``available`` (columns a run computes).

    Raises
    ------
    heritage_bayes.errors.InputError
        Naming ``where`` (e.g. ``thresholds[2].indicator``), the bad name and the
        known ones.
    """
    avail = list(available)
    for i, n in enumerate(names):
        if n not in avail:
            import difflib

            near = difflib.get_close_matches(n, avail, n=1)
            hint = f" (did you mean {near[0]!r}?)" if near else ""
            raise InputError(
                f"{where}[{i}].indicator: unknown indicator {n!r}{hint}; this projection "
                f"computes: {', '.join(avail)}"
            )


def complete_year_hours(n: int) -> int:
    """Hours of the complete years at the start of a series of ``n`` hours.

    ``⌊n / 8760⌋ × 8760``; a series of 8736–8759 h (a typical year on an hourly grid)
    counts as one year of ``n`` hours; a series shorter than that has no complete year
    and ``n`` is returned (the yearly groups refuse it).
    """
    years = int(n) // HOURS_PER_YEAR
    return years * HOURS_PER_YEAR if years else int(n)


def years_of(n: int) -> int:
    """Number of complete years in ``n`` hours (0 below 8736 h)."""
    n = int(n)
    return 0 if n < MIN_YEAR_HOURS else max(1, n // HOURS_PER_YEAR)


def as_markdown() -> str:
    """The registry as a Markdown table (for the documentation: one source of truth).

    Parameterised families keep their ``{}`` placeholder (e.g. ``ashrae_{}``: one
    column per ASHRAE class).
    """

    def cell(text: str) -> str:
        return str(text).replace("|", "\\|").replace("\n", " ")

    lines = [
        "| key | indicator | unit | definition | source | period | worse when |",
        "|---|---|---|---|---|---|---|",
    ]
    worse = {1: "higher", -1: "lower", 0: "—"}
    for i in INDICATORS.values():
        row = (f"`{i.key}`", i.name, i.unit, i.definition, i.source, i.period, worse[i.worse])
        lines.append("| " + " | ".join(cell(c) for c in row) + " |")
    return "\n".join(lines) + "\n"
