"""The columns ``hbayes init`` picked, checked against the whole file and the other file:
an indoor temperature whose name states no unit read in °F when the outdoor air says so
(:func:`fahrenheit_evidence`), a relative humidity out of 0-100 % or empty made an open
question (:func:`rh_question`) rather than a silently dropped hygric model.

Each check returns what it found and, when it cannot decide, a question (text marked
with :data:`heritage_bayes.questions.MARK`, see :func:`heritage_bayes.init_checks.marked`).
"""

from __future__ import annotations

import pandas as pd

from heritage_bayes.init_checks import marked, raw_table
from heritage_bayes.io.loggers import TableLayout
from heritage_bayes.questions import MARK

__all__ = [
    "F_AGREEMENT_K",
    "F_MEDIAN_C",
    "fahrenheit_column_check",
    "fahrenheit_evidence",
    "rh_column_check",
    "rh_question",
    "usable",
]


def usable(mapping: dict) -> dict:
    """``mapping`` without its open questions (values starting with the mark)."""
    return {k: v for k, v in mapping.items() if not str(v).startswith(MARK)}


def rh_column_check(layout, columns: dict, std: str, findings, questions, key: str) -> None:
    """An RH column out of range or empty becomes an open question in ``columns[std]``
    (and ``questions``), never a silently dropped hygric model."""
    q = rh_question(layout, std)
    if q is None:
        return
    columns[std] = q
    questions.append(f"{key}.columns.{std}: {q[len(MARK) :].strip()}")
    findings.append(f"{key}: {std}: {q[len(MARK) :].strip()}")


def fahrenheit_column_check(layout, columns, units, te, findings, questions) -> bool:
    """An indoor temperature column whose name states no unit, checked for °F against
    the outdoor air (:func:`fahrenheit_evidence`): converted (``units["Ti"] = "°F"``,
    True: read it again) or an open question; a finding either way."""
    guess = next((c for c in layout.columns if c.name == columns.get("Ti")), None)
    if guess is None or guess.labelled:
        return False
    unit, why = fahrenheit_evidence(raw_table(layout, [guess.name])[guess.name], te)
    before = units.get("Ti", "°C")
    findings.append(f"logger: Ti {guess.name!r} has no unit in its name: {why}: {unit}")
    if unit == "?":
        units["Ti"] = marked(
            f"°C or °F? column {guess.name!r}: {why}; answer °F (converted on reading) or "
            "°C (delete this line; values above 70 are then left out with invalid: nan)"
        )
        questions.append(f"data.measurements.units.Ti: {units['Ti'][len(MARK) :].strip()}")
        return before == "°F"
    if unit == before:
        return False
    if unit == "°F":
        units["Ti"] = "°F"
    else:
        units.pop("Ti", None)
    return True


def rh_question(layout: TableLayout, std: str) -> str | None:
    """The open question on a column named like relative humidity that cannot be used
    as it is, or None: every value outside 0-100 % counted (the whole file, not the
    sample the layout was guessed from), or the column empty."""
    guess = next((c for c in layout.columns if c.kind == "RH"), None) or next(
        (c for c in layout.columns if c.named == "RH" and c.kind is None), None
    )
    if guess is None:
        return None
    v = raw_table(layout, [guess.name])[guess.name]
    drop = (
        "; or delete this line and the hygric: section to calibrate the temperature only"
        if std == "RHi"
        else "; or delete this line (no hygric model without outdoor RH)"
    )
    if v.notna().sum() == 0:
        return marked(
            f"column {guess.name!r} is named like relative humidity but holds no value: "
            "name the column that holds RH" + drop
        )
    if guess.unit == "fraction":
        v = 100 * v
    lo, hi = int((v < 0).sum()), int((v > 100).sum())
    if not lo and not hi:
        return None
    return marked(
        f"column {guess.name!r} (relative humidity) has {lo} value(s) below 0 % and {hi} "
        f"above 100 % of {int(v.notna().sum())} (from {v.min():.4g} to {v.max():.4g}): a "
        "sensor fault, a wet sensor or another unit? Answer with the column name to read "
        "it with those values left out (add invalid: nan)" + drop
    )


#: [°C] a room whose temperature has this median or more all record long is read in °F.
F_MEDIAN_C = 40.0
#: [K] read as °F, the daily means of an unlabelled indoor temperature lie within this of
#: the outdoor ones (median absolute difference), and at most half as far as read as °C.
F_AGREEMENT_K = 5.0


def fahrenheit_evidence(raw: pd.Series, te: pd.Series) -> tuple[str, str]:
    """Is an unlabelled indoor temperature column in °F? ``("°F" | "°C" | "?", why)``.

    Parameters
    ----------
    raw : pandas.Series
        The column's values as written, indexed by the file's stamps.
    te : pandas.Series
        The outdoor air temperature [°C], indexed by UTC.

    Notes
    -----
    °F when read as °C the column's median is :data:`F_MEDIAN_C` or more (no room
    lives there), or when its daily means read as °F follow the outdoor air (median
    absolute difference within :data:`F_AGREEMENT_K` and at most half the °C reading's):
    a free-running room follows the outdoor air, which the °C reading of a °F file
    misses by tens of kelvin. ``"?"`` when the values exceed 70 (impossible in °C) but
    the °F reading does not follow the outdoor air either. Days are compared by date
    (the clocks are not settled yet: a few hours shift a daily mean little).
    """
    v = raw.dropna()
    if v.index.tz is not None:  # ISO stamps with their offset: compare days in UTC
        v.index = v.index.tz_convert("UTC").tz_localize(None)
    if v.empty:
        return "°C", "no values"
    med = float(v.median())
    over = int((v > 70).sum())
    day_i = v.groupby(v.index.normalize()).mean()
    e = te.dropna()
    idx = e.index.tz_convert("UTC").tz_localize(None) if e.index.tz is not None else e.index
    day_e = pd.Series(e.to_numpy(), index=idx).groupby(idx.normalize()).mean()
    both = pd.concat([day_i.rename("i"), day_e.rename("e")], axis=1, sort=True).dropna()
    if med >= F_MEDIAN_C:
        return "°F", f"median {med:.1f}: no room is that warm all record long in °C"
    if len(both) < 10:
        return (
            ("?", f"{over} values above 70, too few days beside the outdoor file")
            if over
            else (
                "°C",
                "too few days beside the outdoor file to compare",
            )
        )
    mc = float((both["i"] - both["e"]).abs().median())
    mf = float(((both["i"] - 32) / 1.8 - both["e"]).abs().median())
    why = (
        f"daily means over {len(both)} days differ from the outdoor air by {mc:.1f} K read "
        f"as °C, {mf:.1f} K read as °F (median absolute difference)"
    )
    if mf <= F_AGREEMENT_K and mf <= 0.5 * mc:
        return "°F", why + "; the °F reading follows the outdoor air"
    if over:
        return "?", f"{over} values above 70 (no air temperature in °C), but " + why
    return "°C", why
