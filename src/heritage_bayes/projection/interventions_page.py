"""The "Measures" section of ``projection.html``: each intervention against doing nothing.

Per case (baseline, each scenario), a table of measures × indicators (the paired change
with its 5–95 % interval and the probability that the measure is better) and the
running costs with intervals; a figure of risk reduction against annual energy (the
trade-off a manager decides on), with 5–95 % intervals on both axes; and, in words,
where the absolute scale of the costs comes from.
"""

from __future__ import annotations

from html import escape

import numpy as np

from heritage_bayes.climate.risk.registry import indicator_info
from heritage_bayes.projection.interventions import COSTS
from heritage_bayes.projection.interventions import ENERGY as _ENERGY
from heritage_bayes.report.figures.style import RC_PARAMS, _figure, to_png_uri
from heritage_bayes.report.format import fmt, fmt_interval_html, fmt_pct

_MARKERS = ("o", "s", "D", "^", "v", "P", "X", "*")
#: Indicators of the trade-off figure, first two computed: mould, then chemical decay.
_TRADEOFF = ("hours_above_LIM0", "vtt_mould_index_max", "twpi", "time_of_wetness")


def _indicators(proj, page_key: tuple) -> list[str]:
    """Key indicators with a direction (better/worse), in the page's order."""
    names = [n for n in page_key if n in proj.summary["indicators"]]
    return [n for n in names if indicator_info(n).worse]


def _cell(d: dict) -> str:
    if not d or d.get("q50") is None:
        return "–"
    better = (
        ""
        if d.get("p_better") is None
        else f"<br><span class='nowrap'>P(better) {fmt_pct(d['p_better'])}</span>"
    )
    return f"{fmt_interval_html(d['q50'], d['q05'], d['q95'])}{better}"


def scale_text(run) -> str:
    """Where the absolute scale of the running costs comes from, in words."""
    thermal = run.models.get("thermal")
    if thermal is not None and "Ph" in thermal.input_names:
        return (
            "Measured heating power was an input of the calibration: it fixes the room's "
            "absolute heat capacities and conductances [J/K, W/K], so the heating-energy "
            "intervals carry what the data say about them."
        )
    cfg = getattr(run, "config", None)
    pinned = [
        f"{what} {v:g} {unit}"
        for what, v, unit in (
            ("the room volume", getattr(cfg, "room_volume", None), "m³"),
            ("the air change rate", getattr(cfg, "air_change_rate", None), "1/h"),
        )
        if v is not None
    ]
    by = (
        f"the priors that pin that scale ({' and '.join(pinned)} given in the calibration "
        "file, with their spread)"
        if pinned
        else "the priors of the capacities and conductances alone (no room volume or air "
        "change rate was given: wide priors, wide intervals)"
    )
    return (
        "This room was calibrated without a known heat input, on temperature and RH: the "
        "data fix its time constants and gains, not its absolute heat and vapour "
        "conductances [W/K, kg/(s·Pa)]. The running costs (heating energy, water "
        f"removed) scale with those, so their intervals come from {by}, not from the "
        "measurements. The changes of temperature, RH and the indicators do not depend "
        "on that scale while a measure works within its capacity (the set-point or RH "
        "limit is held); a power or capacity limit [W, kg/h] acts against the "
        "conductances, so where it is reached they do. Only measured heating power as "
        "an input of the calibration fixes the "
        "scale from data (no shipped room with temperature and RH has it: the heated "
        "Ørholm store logged temperature and RH only, see the Ørholm check in the "
        "manual; the Armadillo test cell's heating power comes without RH)."
    )


def _energy(costs: dict) -> dict | None:
    """Annual energy quantiles [kWh/a] of a measure: its ``total_energy`` (per draw
    sum) when it has several energy columns, else its one column."""
    if "total_energy" in costs:
        return costs["total_energy"]
    cols = [c for c in _ENERGY if c in costs]
    return costs[cols[0]] if cols else None


def fig_tradeoff(proj, page_key: tuple, colour, legend) -> str:
    """Risk reduction vs annual energy: the first mould indicator and the chemical one
    computed (:data:`_TRADEOFF`), the improvement (change in the registry's better
    direction) against the measure's energy [kWh/a] (0 for a measure without one).
    ``colour(i)``: the page's colour of case ``i``; ``legend(fig, handles, labels,
    ncol)``: the page's legend below the axes."""
    import matplotlib

    iv = proj.summary.get("interventions") or {}
    names = _indicators(proj, page_key)
    mould = [n for n in _TRADEOFF[:2] if n in names][:1]
    names = (mould + [n for n in _TRADEOFF[2:] if n in names] + names)[:2]
    names = list(dict.fromkeys(names))
    if not iv or not names:
        return ""
    with matplotlib.rc_context(RC_PARAMS):
        fig = _figure(9.5, 4.2)
        axes = np.atleast_1d(fig.subplots(1, len(names)))
        handles, labels = [], []
        for ax, n in zip(axes, names, strict=True):
            info = indicator_info(n)
            for j, (mname, e) in enumerate(iv.items()):
                for i, lab in enumerate(proj.labels):
                    case = e["cases"][lab]
                    d = case["indicators"].get(n)
                    en = _energy(case["costs"])
                    if not d or d.get("q50") is None:
                        continue
                    x = en or {"q05": 0.0, "q50": 0.0, "q95": 0.0}
                    # improvement: positive = better (the registry's direction)
                    y = [-info.worse * d[k] for k in ("q05", "q50", "q95")]
                    h = ax.errorbar(
                        x["q50"],
                        y[1],
                        xerr=[[x["q50"] - x["q05"]], [x["q95"] - x["q50"]]],
                        yerr=[[y[1] - min(y[0], y[2])], [max(y[0], y[2]) - y[1]]],
                        fmt=_MARKERS[j % len(_MARKERS)],
                        color=colour(i),
                        capsize=2,
                        alpha=0.85,
                    )
                    if ax is axes[0]:
                        handles.append(h)
                        labels.append(f"{mname} — {lab}")
            ax.axhline(0.0, color="#888888", lw=0.8)
            ax.set_xlabel("annual energy of the measure [kWh/a]")
            ax.set_ylabel(f"improvement [{info.unit}]")
            ax.set_title(info.name, fontsize=9)
        fig.suptitle(
            "Improvement against doing nothing vs running cost (median and 5–95 % of the "
            "draws; above 0: better)"
        )
        legend(fig, handles, labels, ncol=min(3, max(1, len(labels))))
        return to_png_uri(fig)


def interventions_html(proj, run, page_key: tuple, colour, legend) -> str:
    """The section body (empty string when the projection has no interventions);
    ``colour``, ``legend``: the page's (see :func:`fig_tradeoff`)."""
    iv = proj.summary.get("interventions") or {}
    if not iv:
        return ""
    names = _indicators(proj, page_key)
    head = "".join(f"<th>{escape(indicator_info(n).label())}</th>" for n in names)
    parts = [
        "<p>Each measure is simulated for every posterior draw with the same parameters, "
        "the same noise realisation and the same weather as doing nothing, so the "
        "differences below are paired: a cell gives the median change (measure − "
        "nothing) with its 5–95 % interval over the draws and the share of draws in "
        "which the measure is better.</p>",
        f"<div class='note info'><p>{escape(scale_text(run))}</p></div>",
    ]
    notes = [(m, t) for m, e in iv.items() for t in e.get("notes") or []]
    if notes:
        parts.append(
            "<ul>" + "".join(f"<li>{escape(m)}: {escape(t)}</li>" for m, t in notes) + "</ul>"
        )
    for lab in proj.labels:
        rows = []
        for mname, e in iv.items():
            case = e["cases"][lab]
            cells = "".join(f"<td class='num'>{_cell(case['indicators'].get(n))}</td>"
                            for n in names)  # fmt: skip
            cost = "; ".join(
                f"{escape(COSTS[c][1])}: {fmt_interval_html(q['q50'], q['q05'], q['q95'])} "
                f"{escape(q['unit'])}"
                for c, q in case["costs"].items()
            )
            rows.append(f"<tr><td>{escape(mname)}</td>{cells}<td>{cost or '–'}</td></tr>")
        parts.append(
            f"<h3>{escape(lab)}</h3><div class='scroll'><table class='decision'><thead><tr>"
            f"<th>measure</th>{head}<th>running cost</th></tr></thead>"
            f"<tbody>{''.join(rows)}</tbody></table></div>"
        )
    probs = []
    for mname, e in iv.items():
        for lab in proj.labels:
            for p in e["cases"][lab]["probabilities"]:
                info = indicator_info(p["indicator"])
                probs.append(
                    f"<tr><td>{escape(mname)}</td><td>{escape(lab)}</td>"
                    f"<td>P({escape(info.name)} {p['op']} {fmt(p['value'])} "
                    f"{escape(info.unit)})</td><td class='num'>{fmt_pct(p['p_nothing'])}</td>"
                    f"<td class='num'>{fmt_pct(p['p_measure'])}</td></tr>"
                )
    if probs:
        parts.append(
            "<h3>Probability statements with and without each measure</h3>"
            "<div class='scroll'><table class='decision'><thead><tr><th>measure</th>"
            "<th>case</th><th>statement</th><th class='num'>doing nothing</th>"
            f"<th class='num'>with the measure</th></tr></thead><tbody>{''.join(probs)}"
            "</tbody></table></div>"
        )
    fig = fig_tradeoff(proj, page_key, colour, legend)
    if fig:
        parts.append(
            f"<figure id='fig-tradeoff'><img src='{fig}' alt='risk reduction against "
            "annual energy per measure and case'></figure>"
        )
    return "".join(parts)
