"""The "Measures" section of ``projection.html``: each intervention against doing nothing.

First the decision table (:mod:`heritage_bayes.projection.decision`): the measures
ranked by the change in one risk at the most severe case, with P(better), one running
energy per year and, with tariffs, its cost and CO₂; the figure of risk reduction
against that energy (one labelled marker per measure, 5–95 % intervals on both axes).
Below, per case (baseline, each scenario), a table of measures × indicators (the
paired change with its 5–95 % interval and the probability that the measure is
better) and every running cost with its interval; and, in words, where the absolute
scale of the costs comes from.
"""

from __future__ import annotations

from html import escape

import numpy as np

from heritage_bayes.climate.risk.registry import indicator_info
from heritage_bayes.format import fmt, fmt_interval_html, fmt_pct
from heritage_bayes.projection.interventions import COSTS
from heritage_bayes.report.figures.style import RC_PARAMS, _figure, to_png_uri

_MARKERS = ("o", "s", "D", "^", "v", "P", "X", "*")
_COLOURS = ("#1f5fa8", "#c0392b", "#2e8b57", "#e08a00", "#7b3fa0", "#8c564b", "#17becf",
            "#222222")  # fmt: skip
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


def _improvement(info, d: dict) -> list[float]:
    """(low, median, high) of the improvement (positive = better, the registry's
    direction) from a change's quantiles."""
    y = sorted(-info.worse * d[k] for k in ("q05", "q95"))
    return [y[0], -info.worse * d["q50"], y[1]]


#: Candidate label offsets from a marker [pt], in order of preference: the diagonals
#: (clear of the marker's own error bars), right, left, above, below, then the same
#: farther out (with a leader line).
_OFFSETS = [
    (dx * r, dy * r)
    for r in (1.0, 2.2, 3.6, 5.2)
    for dx, dy in ((5, 4), (5, -13), (-5, 4), (-5, -13), (7, -4), (-7, -4), (0, 8), (0, -16))
]


def _overlap(a, b) -> float:
    """Overlap area of two display boxes ``(x0, y0, x1, y1)`` [px²]."""
    w = min(a[2], b[2]) - max(a[0], b[0])
    h = min(a[3], b[3]) - max(a[1], b[1])
    return w * h if w > 0 and h > 0 else 0.0


def place_labels(ax, points, texts, colours) -> list:
    """Label each marker of ``ax`` without two labels overlapping.

    ``points`` are the markers in data coordinates. The figure is drawn once and its
    layout frozen; then, marker by marker from the most crowded, each label takes the
    first of :data:`_OFFSETS` whose box lies inside the axes and overlaps no placed
    label and no marker (a box of ±5 px around it); where none is free, the candidate
    with the least overlap. A label moved farther than the first ring is tied to its
    marker by a thin leader line. Returns the annotations (their boxes in display
    pixels are final: the layout does not move after this).
    """
    from matplotlib.backends.backend_agg import FigureCanvasAgg

    fig = ax.figure
    if not hasattr(fig.canvas, "get_renderer"):
        FigureCanvasAgg(fig)
    fig.draw_without_rendering()
    fig.set_layout_engine("none")  # the axes stay where the layout put them
    renderer = fig.canvas.get_renderer()
    to_px = ax.transData.transform
    pts = [tuple(to_px(p)) for p in points]
    frame = ax.get_window_extent(renderer)
    frame = (frame.x0, frame.y0, frame.x1, frame.y1)
    markers = [(x - 5, y - 5, x + 5, y + 5) for x, y in pts]
    scale = fig.dpi / 72.0
    # the most crowded marker first: it has the fewest free places
    crowd = [sum(np.hypot(x - u, y - v) < 60 for u, v in pts) for x, y in pts]
    order = sorted(range(len(pts)), key=lambda i: -crowd[i])
    placed: list[tuple] = []
    labels: list = [None] * len(pts)
    for i in order:
        probe = ax.text(0, 0, texts[i], fontsize=8, transform=None)
        ext = probe.get_window_extent(renderer)
        probe.remove()
        w, h = ext.width + 4, ext.height + 4  # with the label's white backing
        best, best_cost = None, float("inf")
        for k, (dx, dy) in enumerate(_OFFSETS):
            x0 = pts[i][0] + dx * scale - (w if dx < 0 else w / 2 if dx == 0 else 0)
            y0 = pts[i][1] + dy * scale
            box = (x0, y0, x0 + w, y0 + h)
            outside = (max(0.0, frame[0] - box[0]) + max(0.0, box[2] - frame[2])
                       + max(0.0, frame[1] - box[1]) + max(0.0, box[3] - frame[3]))  # fmt: skip
            cost = (sum(_overlap(box, b) for b in placed)
                    + sum(_overlap(box, m) for j, m in enumerate(markers) if j != i)
                    + outside * h)  # fmt: skip
            if cost < best_cost - 1e-9:
                best, best_cost = (k, box, dx, dy), cost
            if cost == 0.0:
                break
        k, box, dx, dy = best
        leader = (
            {"arrowstyle": "-", "color": colours[i], "lw": 0.6, "shrinkA": 0, "shrinkB": 3}
            if k >= 8  # beyond the first ring: a leader line to the marker
            else None
        )
        ann = ax.annotate(
            texts[i], points[i], xytext=(dx, dy), textcoords="offset points", fontsize=8,
            color=colours[i], annotation_clip=False, arrowprops=leader,
            bbox={"boxstyle": "round,pad=0.15", "fc": "white", "ec": "none", "alpha": 0.8},
            ha="right" if dx < 0 else "center" if dx == 0 else "left", va="bottom",
        )  # fmt: skip
        ann.set_in_layout(False)
        placed.append(box)
        labels[i] = ann
    return labels


def fig_tradeoff(proj, page_key: tuple) -> str:
    """Risk reduction vs annual energy at the decision table's case: one panel per
    indicator (the ranking one, then the first other of :data:`_TRADEOFF` computed),
    one marker per measure labelled beside it, 5–95 % bars on both axes; the energy is
    the per-draw total of the decision table [kWh/a] (0 for a measure without one)."""
    import matplotlib

    dec = proj.summary.get("decision") or {}
    iv = proj.summary.get("interventions") or {}
    if not dec or not dec.get("rank_by"):
        return ""
    case = dec["case"]
    names = _indicators(proj, page_key)
    names = list(dict.fromkeys([dec["rank_by"], *[n for n in _TRADEOFF if n in names]]))[:2]
    with matplotlib.rc_context(RC_PARAMS):
        fig = _figure(9.5, 4.4)
        axes = np.atleast_1d(fig.subplots(1, len(names)))
        all_marks = []
        for ax, n in zip(axes, names, strict=True):
            info = indicator_info(n)
            marks = []
            for j, row in enumerate(dec["measures"]):
                d = iv[row["name"]]["cases"][case]["indicators"].get(n)
                if not d or d.get("q50") is None:
                    continue
                x = row["energy_kwh"]
                y = _improvement(info, d)
                ax.errorbar(x["q50"], y[1],
                            xerr=[[x["q50"] - x["q05"]], [x["q95"] - x["q50"]]],
                            yerr=[[y[1] - y[0]], [y[2] - y[1]]],
                            fmt=_MARKERS[j % len(_MARKERS)], color=_COLOURS[j % len(_COLOURS)],
                            ms=6, capsize=2, elinewidth=0.8, alpha=0.9)  # fmt: skip
                marks.append(((x["q50"], y[1]), f"{j + 1}. {row['name']}",
                              _COLOURS[j % len(_COLOURS)]))  # fmt: skip
            ax.margins(x=0.25, y=0.15)  # room for the labels around the markers
            all_marks.append(marks)
            ax.axhline(0.0, color="#888888", lw=0.8)
            ax.set_xlabel("running energy of the measure [kWh/a]")
            ax.set_ylabel(f"improvement [{info.unit}]")
            ax.set_title(info.name, fontsize=9)
        fig.suptitle(
            f"{case}: improvement against doing nothing vs running energy (median and "
            "5–95 % of the draws; above 0: better)"
        )
        for ax, marks in zip(axes, all_marks, strict=True):
            if marks:  # after the layout: the labels placed in the axes' final pixels
                pts, texts, colours = zip(*marks, strict=True)
                place_labels(ax, pts, texts, colours)
        return to_png_uri(fig)


def _fmt_q(d: dict | None, unit: str = "") -> str:
    if not d or d.get("q50") is None:
        return "–"
    return fmt_interval_html(d["q50"], d["q05"], d["q95"]) + (f" {escape(unit)}" if unit else "")


def decision_html(proj) -> str:
    """The decision table (:mod:`heritage_bayes.projection.decision`): measures ranked
    by the change in the chosen risk at the most severe case, with its interval and
    P(better), one total running energy per year and, with tariffs, its cost and CO₂."""
    dec = proj.summary.get("decision") or {}
    if not dec or not dec.get("rank_by"):
        return ""
    info = indicator_info(dec["rank_by"])
    tariffs = dec.get("tariffs")
    co2 = bool(tariffs) and tariffs.get("electricity_co2_kg_per_kwh") is not None
    head = (
        f"<th>measure</th><th>change in {escape(info.label())}</th><th>P(better)</th>"
        "<th>running energy [kWh/a]</th>"
        + ("<th>cost [EUR/a]</th>" if tariffs else "")
        + ("<th>CO₂ [kg/a]</th>" if co2 else "")
    )
    rows = []
    for rank, row in enumerate(dec["measures"], 1):
        c = row["change"] or {}

        def money(q, row=row):
            return _fmt_q(q) if row["has_energy"] else "none"

        energy = _fmt_q(row["energy_kwh"]) if row["has_energy"] else "none"
        if row["energy_missing"]:
            energy += f"<br><small>without the {escape(' and '.join(row['energy_missing']))} " \
                      "(no energy per kg given)</small>"  # fmt: skip
        pb = c.get("p_better")
        rows.append(
            f"<tr><td>{rank}. {escape(row['name'])}</td><td class='num'>{_fmt_q(c)}</td>"
            f"<td class='num'>{'–' if pb is None else fmt_pct(pb)}</td>"
            f"<td class='num'>{energy}</td>"
            + (f"<td class='num'>{money(row['cost_eur'])}</td>" if tariffs else "")
            + (f"<td class='num'>{money(row['co2_kg'])}</td>" if co2 else "")
            + "</tr>"
        )
    if tariffs:
        money = (
            f"Cost at {fmt(tariffs['heat_eur_per_kwh'])} EUR per kWh of heat and "
            f"{fmt(tariffs['electricity_eur_per_kwh'])} EUR per kWh of electricity"
            + (
                f"; CO₂ at {fmt(tariffs['heat_co2_kg_per_kwh'])} and "
                f"{fmt(tariffs['electricity_co2_kg_per_kwh'])} kg/kWh"
                if co2
                else ""
            )
            + " (the projection file's tariffs), per draw, then its interval."
        )
    else:
        money = "Give tariffs in the projection file for the annual cost and CO₂."
    return (
        f"<p><b>Which measure, at {escape(dec['case'])}</b> (the warmest future): ranked by "
        f"the median change in {escape(info.name)} against doing nothing, best first; "
        "median [5 %, 95 %] over the draws, paired draw by draw. <b>P(better)</b>: share "
        "of the draws in which the measure is better. <b>Running energy</b>: per draw the "
        "sum of the heat delivered and the units' electricity, then its interval. "
        f"{money}</p><div class='scroll'><table class='decision' id='decision-table'>"
        f"<thead><tr>{head}</tr></thead><tbody>{''.join(rows)}</tbody></table></div>"
    )


def interventions_html(proj, run, page_key: tuple) -> str:
    """The section body (empty string when the projection has no interventions): the
    decision table first, then the figure and the per-case detail tables."""
    iv = proj.summary.get("interventions") or {}
    if not iv:
        return ""
    names = _indicators(proj, page_key)
    head = "".join(f"<th>{escape(indicator_info(n).label())}</th>" for n in names)
    fig = fig_tradeoff(proj, page_key)
    parts = [
        decision_html(proj),
        f"<figure id='fig-tradeoff'><img src='{fig}' alt='risk reduction against "
        "running energy per measure'></figure>"
        if fig
        else "",
        "<h3>Every case and indicator</h3><p>Each measure is simulated for every "
        "posterior draw with the same parameters, "
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
    return "".join(parts)
