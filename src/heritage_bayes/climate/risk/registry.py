r"""The indicator registry: one entry per conservation-risk indicator (gathered from the
families of :mod:`heritage_bayes.climate.risk.indicators`), read by
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
from collections.abc import Mapping
from dataclasses import replace

from heritage_bayes.climate.risk._inputs import HOURS_PER_YEAR, MIN_YEAR_HOURS
from heritage_bayes.climate.risk.indicators import (
    FAMILIES,
    PROJECTION_INDICATORS,
    Family,
    Indicator,
)
from heritage_bayes.errors import InputError

__all__ = [
    "ANNUAL",
    "INDICATORS",
    "INDICATOR_GROUPS",
    "Indicator",
    "as_markdown",
    "check_indicator_names",
    "complete_year_hours",
    "headline_indicators",
    "indicator_info",
    "register",
    "resolve_options",
    "unregister",
]


def _pattern(key: str):
    return re.compile("^" + r"(.+)".join(map(re.escape, key.split("{}"))) + "$")


def _entries() -> dict[str, Indicator]:
    e = [i for f in FAMILIES for i in f.indicators] + list(PROJECTION_INDICATORS)
    return {i.key: i for i in e}


#: Every indicator family by key (parameterised ones with ``{}``).
INDICATORS: dict[str, Indicator] = _entries()
#: Indicator groups of :func:`~heritage_bayes.climate.risk.assess` (the families of
#: :mod:`~heritage_bayes.climate.risk.indicators`); those marked True need at least a
#: year of data.
INDICATOR_GROUPS = {f.name: f.yearly for f in FAMILIES}


def resolve_options(func, given: Mapping[str, Mapping | None]):
    """The options of every family: the user's (``given``: option keyword → dict or None)
    merged with the defaults of each family's target function, unknown keywords and keys
    refused (:class:`~heritage_bayes.errors.InputError` naming ``func``), then checked by
    each family."""
    known = [k for fam in FAMILIES for k in fam.options]
    unknown = [k for k in given if k not in known]
    if unknown:
        raise InputError(
            f"{func}: unknown option group(s) {unknown}; expected some of {known} (the "
            "option keywords of the indicator families)"
        )
    opts = {}
    for fam in FAMILIES:
        for key, target in fam.options.items():
            d = fam.option_defaults(key)
            fname = target.__name__
            user = given.get(key) or {}
            if not isinstance(user, Mapping):
                raise InputError(
                    f"{func}: {key} must be a dict of options for {fname}(); got "
                    f"{type(user).__name__}"
                )
            unknown = sorted(set(user) - set(d))
            if unknown:
                raise InputError(
                    f"{func}: unknown option(s) {unknown} in {key}=...; expected some of "
                    f"{sorted(d)} (the keywords of {fname}())"
                )
            d.update(user)
            opts[key] = d
    for fam in FAMILIES:  # validate each family's options once, before any work
        fam.check(func, opts)
    return opts


#: Columns the projection also reports per complete year (a parameterised family by its
#: prefix, e.g. ``hours_above_LIM``), in registry order.
ANNUAL: tuple[str, ...] = tuple(i.key.replace("{}", "") for i in INDICATORS.values() if i.per_year)
#: (pattern, family key) of the parameterised families: ``{}`` matches the parameter.
_PATTERNS = [(_pattern(key), key) for key in INDICATORS if "{}" in key]


def register(family: Family) -> None:
    """Add an indicator family: its columns join :func:`~heritage_bayes.climate.risk.assess`,
    :func:`~heritage_bayes.climate.risk.assess_batch`,
    :func:`~heritage_bayes.climate.risk.assess_fused` and a projection (with its
    ``compute``; per complete year too for its ``per_year`` columns), this registry and
    the generated reference.

    Raises
    ------
    heritage_bayes.errors.InputError
        A family or option keyword of that name exists already, an indicator key is
        taken, or the family says it is compiled (the compiled pass is code of
        :mod:`heritage_bayes.climate.risk._fused`, not registered at run time).
    """
    taken = {o for f in FAMILIES for o in f.options}
    clash = [k for k in family.options if k in taken]
    keys = [i.key for i in family.indicators if i.key in INDICATORS]
    if family.name in INDICATOR_GROUPS or clash or keys or family.compiled:
        raise InputError(
            f"register: family {family.name!r} clashes with the registry (known families "
            f"{list(INDICATOR_GROUPS)}, option keywords taken {clash}, keys taken {keys}, "
            f"compiled {family.compiled}: a compiled family is part of the compiled pass)"
        )
    FAMILIES.append(family)
    INDICATOR_GROUPS[family.name] = family.yearly
    for i in family.indicators:
        INDICATORS[i.key] = i
        if "{}" in i.key:
            _PATTERNS.append((_pattern(i.key), i.key))


def unregister(name: str) -> None:
    """Remove a family added by :func:`register` (the built-in ones stay)."""
    fam = next((f for f in FAMILIES if f.name == name and not f.compiled), None)
    if fam is None:
        raise InputError(f"unregister: no registered family {name!r}")
    FAMILIES.remove(fam)
    del INDICATOR_GROUPS[name]
    for i in fam.indicators:
        del INDICATORS[i.key]
    _PATTERNS[:] = [(p, k) for p, k in _PATTERNS if k in INDICATORS]


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


def headline_indicators() -> tuple[str, ...]:
    """The key indicators of a projection's figures and first screen, in their order
    (``Indicator.headline``): parameterised ones by their column under the default
    options (e.g. ``hours_above_LIM0``)."""
    opts = resolve_options("headline_indicators", {})
    default_cols = [c for f in FAMILIES for c in f.columns(opts)]
    out = []
    for i in sorted((i for i in INDICATORS.values() if i.headline), key=lambda i: i.headline):
        if "{}" in i.key:
            pat = _pattern(i.key)
            out += [c for c in default_cols if pat.match(c)][:1]
        else:
            out.append(i.key)
    return tuple(out)


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
