"""``projection.html``: the projection as a decision page in the house style
(:func:`heritage_bayes.report.page.render_page`, figures through
:mod:`heritage_bayes.report.figures.style`).

What a conservator reads, in order: a banner when the calibration did not converge;
the verdict (what changes at the warmest future: each key indicator's median, its
change with the 90 % interval and P(worse); the indicators constant in every draw
named once, in words, and given no interval or variance shares); per indicator (human
name and unit from :mod:`heritage_bayes.climate.risk.registry`) the baseline and each
scenario with its interval, the change against the baseline and the probability that
it is worse, and the ASHRAE classes in words (the required share of the hours, the best
class reached, the share of hours within each class); the probability of crossing each
named threshold; the seasonal cycle of the indoor T and RH (baseline vs scenarios, with
bands); the distributions of the key indicators per scenario; the measures
(interventions) against doing nothing, decision table first
(:mod:`heritage_bayes.projection.interventions_page`); where the uncertainty comes from
(figure and table of the decomposition of :mod:`heritage_bayes.projection.summary`);
what every indicator means (definition, source, period); the weather used.

Layout: every table has a fixed, small number of columns (or one column per case with
short numbers), text cells wrap, legends sit outside the axes: nothing is cut at
1280 px (checked in headless Chromium by ``tests/test_projection.py``).
"""

from __future__ import annotations

from html import escape

import numpy as np

from heritage_bayes.climate.risk.registry import headline_indicators, indicator_info
from heritage_bayes.format import fmt, fmt_interval_html, fmt_pct, prose_html
from heritage_bayes.report.figures.style import RC_PARAMS, _figure, to_png_uri

#: Indicators drawn in the figures (when computed), in this order (the registry's
#: ``headline`` entries).
KEY_INDICATORS = headline_indicators()
_CASE_COLOURS = ("#222222", "#1f5fa8", "#2e8b57", "#e08a00", "#c0392b", "#7b3fa0", "#8c564b",
                 "#17becf", "#bcbd22", "#e377c2")  # fmt: skip
_COMPONENT_COLOURS = {"parameter": "#1f5fa8", "noise": "#9aa5b1", "weather_year": "#2e8b57",
                      "scenario": "#e08a00"}  # fmt: skip
_COMPONENT_NAMES = {
    "parameter": "parameters of the room",
    "noise": "model error (noise)",
    "weather_year": "weather year",
    "scenario": "scenario",
}
_CSS = (
    "<style>table.decision, table.split, table.registry {width: 100%; table-layout: auto;}"
    " table.decision td.num {white-space: normal;}</style>"
)


def _colour(i: int) -> str:
    return _CASE_COLOURS[i % len(_CASE_COLOURS)]


def _key_names(proj) -> list[str]:
    """Key indicators computed and not constant (a constant one is said in words)."""
    ind = proj.summary["indicators"]
    return [n for n in KEY_INDICATORS if n in ind and not ind[n].get("degenerate")]


def _ashrae_html(proj) -> str:
    """The ASHRAE classes in words: the required share of the hours, the best class
    reached (share of the draws) and, per class, the share of hours within it (median
    [5 %, 95 %] over the draws), so that "none" comes with how close each class is."""
    import inspect

    from heritage_bayes.climate.risk.standards import ASHRAE_CLASSES, ashrae_classes

    s = proj.summary
    best = s.get("ashrae_best_class") or {}
    if not best:
        return ""
    need = inspect.signature(ashrae_classes).parameters["threshold"].default
    names = [c.name for c in ASHRAE_CLASSES if f"ashrae_{c.name}" in s["indicators"]]
    items = []
    for lab in proj.labels:
        per = {c: s["indicators"][f"ashrae_{c}"]["cases"][lab] for c in names}
        reached = {k: v for k, v in best[lab].items() if k != "none"}
        shares = ", ".join(
            f"{escape(c)} {_q_text(per[c])} %" for c in names if per[c]["q50"] is not None
        )
        close = max((c for c in names if per[c]["q50"] is not None),
                    key=lambda c: per[c]["q50"], default=None)  # fmt: skip
        if not reached:
            head = f"no class reaches the required {fmt(need)} % of the hours in any draw"
            if close is not None:
                head += f"; closest: {escape(close)} with {fmt(per[close]['q50'])} % (median)"
        else:
            head = "best class reached: " + ", ".join(
                f"{escape(k)} in {fmt_pct(v)} of the draws"
                for k, v in sorted(best[lab].items(), key=lambda kv: -kv[1])
            )
        items.append(
            f"<li><b>{escape(lab)}</b>: {head}. Share of the hours within each class: "
            f"{shares}.</li>"
        )
    return (
        f"<p>ASHRAE museum classes (a class is met when at least {fmt(need)} % of the "
        f"hours lie within its limits):</p><ul>{''.join(items)}</ul>"
    )


def _verdict_html(proj) -> str:
    """The first screen: what changes at the most severe case (the key indicators'
    median change with its 90 % interval) and how sure (P(worse)); the indicators
    constant in every draw said once, in words."""
    from heritage_bayes.projection.decision import severe_case

    s = proj.summary
    base = proj.labels[0]
    items, worse, better = [], [], []
    if len(proj.labels) > 1:
        case = severe_case(s)
        for n in _key_names(proj):
            e = s["indicators"][n]
            ch = e["change"].get(case) or {}
            if ch.get("q50") is None:
                continue
            pw = ch.get("p_worse")
            sure = "" if pw is None else f"; worse in {fmt_pct(pw)} of the draws"
            name = indicator_info(n).name
            if pw is not None and pw >= 0.9:
                worse.append(name)
            elif pw is not None and pw <= 0.1:
                better.append(name)
            unit = "" if e["unit"] in ("-", "") else f" {escape(e['unit'])}"
            items.append(
                f"<li><b>{escape(name)}</b>: {fmt(e['cases'][base]['q50'])} → "
                f"{fmt(e['cases'][case]['q50'])}{unit}, change {_q_text(ch)}{sure}</li>"
            )
        sure = [
            f"worse in at least 90 % of the draws: {', '.join(worse)}" if worse else "",
            f"better in at least 90 %: {', '.join(better)}" if better else "",
        ]
        sure = "; ".join(t for t in sure if t) or "no key indicator changes in 90 % of the draws"
        head = (
            f"<p><b>At {escape(case)}</b> (the warmest future) against {escape(base)}, "
            f"{escape(sure)}. Per indicator: the median, and the change with its 90 % "
            "interval [5 %, 95 %] over the draws.</p>"
        )
    else:
        head = "<p>No future weather: the baseline only.</p>"
    const = [
        f"{indicator_info(n).name} {fmt(e['cases'][base]['q50'])}"
        + ("" if e["unit"] in ("-", "") else f" {e['unit']}")
        for n, e in s["indicators"].items()
        if e.get("degenerate")
    ]
    said = (
        "<p>Constant in every draw and case (no interval or source of uncertainty to "
        f"report): {escape('; '.join(const))}.</p>"
        if const
        else ""
    )
    body = f"<ul>{''.join(items)}</ul>" if items else ""
    return (
        f"<div class='note info' id='verdict'><strong>What changes</strong>{head}{body}{said}</div>"
    )


def _legend_below(fig, handles, labels, ncol: int) -> None:
    """A figure legend under the axes (never over the data)."""
    fig.legend(handles, labels, loc="outside lower center", ncol=ncol, frameon=False)


def _fig_seasonal(proj) -> str:
    import matplotlib

    ds = proj.dataset
    months = np.arange(1, 13)
    with matplotlib.rc_context(RC_PARAMS):
        fig = _figure(9.0, 5.6)
        axes = fig.subplots(2, 1, sharex=True)
        # bands for the baseline and the warmest future (overlapping bands of every
        # case would hide each other); medians for all
        te = [c["mean_Te"] for c in proj.summary["cases"]]
        banded = {0, int(np.argmax(te))}
        handles = []
        for ax, name, label in (
            (axes[0], "Ti", "indoor temperature [°C]"),
            (axes[1], "RHi", "indoor relative humidity [%]"),
        ):
            arr = ds[f"{name}_monthly"].values  # (case, draw, 12)
            handles = []
            for i, _lab in enumerate(proj.labels):
                q = np.nanquantile(arr[i], [0.05, 0.5, 0.95], axis=0)
                c = _colour(i)
                if i in banded:
                    ax.fill_between(months, q[0], q[2], color=c, alpha=0.15, lw=0)
                (h,) = ax.plot(months, q[1], color=c, lw=1.6 if i == 0 else 1.2)
                handles.append(h)
            ax.set_ylabel(label)
        axes[1].set_xticks(months, ["J", "F", "M", "A", "M", "J", "J", "A", "S", "O", "N", "D"])
        axes[1].set_xlabel("calendar month (mean over the case's years)")
        warm = proj.labels[max(banded)]
        axes[0].set_title(
            "Seasonal cycle: median of the draws; 5–95 % predictive band for the baseline"
            + (f" and {warm}" if len(banded) > 1 else "")
        )
        _legend_below(fig, handles, proj.labels, ncol=min(5, len(proj.labels)))
        return to_png_uri(fig)


def _fig_risk(proj) -> str:
    import matplotlib

    ds = proj.dataset
    names = _key_names(proj)
    if not names:
        return ""
    ncol = 2 if len(names) > 1 else 1
    nrow = -(-len(names) // ncol)
    with matplotlib.rc_context(RC_PARAMS):
        fig = _figure(9.5, 0.35 * len(proj.labels) * nrow + 0.9 * nrow + 0.6)
        axes = np.atleast_1d(fig.subplots(nrow, ncol)).ravel()
        for ax, n in zip(axes, names, strict=False):
            data = [v[np.isfinite(v)] for v in ds[n].values]
            ok = [i for i, v in enumerate(data) if v.size]
            if ok:
                bp = ax.boxplot(
                    [data[i] for i in ok],
                    positions=ok,
                    orientation="horizontal",
                    whis=(5, 95),
                    showfliers=False,
                    patch_artist=True,
                )
                for j, patch in enumerate(bp["boxes"]):
                    patch.set_facecolor(_colour(ok[j]))
                    patch.set_alpha(0.35)
            ax.set_yticks(range(len(proj.labels)), proj.labels)
            ax.invert_yaxis()
            ax.set_title(indicator_info(n).label(), fontsize=9)
        for ax in axes[len(names) :]:
            ax.set_visible(False)
        fig.suptitle("Indicators over the draws per scenario (box: 25–75 %, whiskers: 5–95 %)")
        return to_png_uri(fig)


def _fig_split(proj) -> str:
    import matplotlib

    split = proj.summary["uncertainty_split"]
    names = _key_names(proj)
    if not names or not split:
        return ""
    groups = list(split)
    with matplotlib.rc_context(RC_PARAMS):
        fig = _figure(9.0, 0.9 + 0.32 * len(names) * len(groups) + 0.25 * len(groups))
        axes = np.atleast_1d(fig.subplots(len(groups), 1, sharex=True))
        handles = {}
        for ax, g in zip(axes, groups, strict=True):
            per = split[g]["indicators"]
            for row, n in enumerate(names):
                left = 0.0
                for comp, col in _COMPONENT_COLOURS.items():
                    share = (per[n]["share"] or {}).get(comp)
                    if share is None or share <= 0:
                        continue
                    handles[comp] = ax.barh(row, 100 * share, left=left, color=col, height=0.7)
                    left += 100 * share
            ax.set_yticks(range(len(names)), [indicator_info(n).name for n in names])
            ax.invert_yaxis()
            title = "baseline" if g == "baseline" else f"horizon {g}"
            ax.set_title(f"{title} ({', '.join(split[g]['cases'])})", fontsize=9)
            ax.set_xlim(0, 100)
        axes[-1].set_xlabel("share of the variance [%]")
        comps = [c for c in _COMPONENT_COLOURS if c in handles]
        _legend_below(fig, [handles[c] for c in comps], [_COMPONENT_NAMES[c] for c in comps], 4)
        return to_png_uri(fig)


def _q_text(d: dict | None) -> str:
    if not d or d.get("q50") is None:
        return "–"
    return fmt_interval_html(d["q50"], d["q05"], d["q95"])


def _banner(proj) -> str:
    s = proj.summary
    if s.get("converged", True):
        return ""
    from heritage_bayes.projection import UNCONVERGED_TEXT

    reasons = "".join(f"<li>{prose_html(r)}</li>" for r in s.get("unconverged_reasons") or [])
    return (
        "<div class='note red' id='unconverged'><strong>Calibration not converged</strong>"
        f"<p>{escape(UNCONVERGED_TEXT[:1].upper() + UNCONVERGED_TEXT[1:])}. Continue it "
        "(<code>hbayes calibrate … --resume</code>) and project again before acting on "
        "these numbers.</p>" + (f"<ul>{reasons}</ul>" if reasons else "") + "</div>"
    )


def _decision_html(proj) -> str:
    s = proj.summary
    rows = []
    for n, e in s["indicators"].items():
        if e.get("degenerate") or n.startswith("ashrae_"):
            continue  # said in words (the summary, the ASHRAE sentence below)
        info = indicator_info(n)
        span = len(proj.labels)
        for j, lab in enumerate(proj.labels):
            ch = e["change"].get(lab)
            pw = ch.get("p_worse") if ch else None
            head = ""
            if j == 0:
                head = (
                    f"<td rowspan='{span}'><b>{escape(info.name)}</b>"
                    f"<br><small>[{escape(e['unit'])}]</small></td>"
                )
            rows.append(
                f"<tr>{head}<td>{escape(lab)}</td><td class='num'>{_q_text(e['cases'][lab])}</td>"
                f"<td class='num'>{'–' if ch is None else _q_text(ch)}</td>"
                f"<td class='num'>{'–' if pw is None else fmt_pct(pw)}</td></tr>"
            )
    extra = _ashrae_html(proj)
    const = [n for n, e in s["indicators"].items() if e.get("degenerate")]
    if const:
        extra += (
            "<p>Left out of this table, constant in every draw and case (see the summary "
            f"at the top): {escape(', '.join(indicator_info(n).name for n in const))}.</p>"
        )
    return (
        "<p>Median [5 %, 95 %] over the posterior draws, each with a draw of the model "
        "error. <b>Change</b>: against the baseline, paired draw by draw (same room "
        "parameters, same noise realisation). <b>P(worse)</b>: share of the draws in "
        "which the indicator gets worse for the collection. Definitions and periods: "
        "<a href='#indicators'>Indicators</a>.</p>"
        "<div class='scroll'><table class='decision'><thead><tr><th>indicator</th>"
        "<th>case</th><th>value</th><th>change vs baseline</th><th>P(worse)</th>"
        f"</tr></thead><tbody>{''.join(rows)}</tbody></table></div>{extra}"
    )


def _probability_html(proj) -> str:
    s = proj.summary
    head = "".join(f"<th class='num'>{escape(lab)}</th>" for lab in proj.labels)
    rows = []
    for p in s["probabilities"]:
        stmt = f"P({p['name']} {p['op']} {p['value']:g} {p['unit']})"
        cells = "".join(
            f"<td class='num'>{fmt_pct(p['cases'][lab]['p'])}</td>" for lab in proj.labels
        )
        rows.append(f"<tr><td>{escape(stmt)}</td>{cells}</tr>")
    K = s["draws"]
    se = 0.5 / np.sqrt(K)
    return (
        f"<div class='scroll'><table><thead><tr><th>statement</th>{head}</tr></thead>"
        f"<tbody>{''.join(rows)}</tbody></table></div>"
        f"<p>Shares of {K} posterior draws, each simulated with a draw of its noise "
        f"model (predictive). Monte-Carlo standard error at most {fmt_pct(se, 1)}.</p>"
    )


def _scenario_caveat(proj) -> str:
    """What the scenario share leaves out, said of the weather this projection used
    (the KNMI'14 tables, morphing deltas or future files), never of another kind."""
    methods = {str(c["weather"].get("method", "")) for c in proj.summary["cases"]}
    said = []
    if any(m.startswith("KNMI'14") for m in methods):
        said.append("The KNMI'14 tables give one change per scenario")
    if any(m.startswith("morphing") for m in methods):
        said.append("each morphing case applies one set of monthly changes")
    if any(m.startswith("user-supplied") for m in methods):
        said.append("each future weather file is one realisation")
    if not said:
        return ""
    text = "; ".join(said)
    return (
        f"{text[0].upper()}{text[1:]}, so the spread between climate models is not "
        "separated from the scenario (give each model's weather as a case of its own to "
        "see it)."
    )


def _split_html(proj) -> str:
    split = proj.summary["uncertainty_split"]
    fig = _fig_split(proj)
    out = [f"<figure id='fig-split'><img src='{fig}' alt='variance decomposition'></figure>"]
    everywhere = {n for n, e in proj.summary["indicators"].items() if e.get("degenerate")}
    for g, block in split.items():
        rows, here = [], []
        for n, e in block["indicators"].items():
            sh = e["share"]
            if e.get("degenerate"):  # no variance to split
                if n not in everywhere:  # (those constant everywhere: said at the top)
                    here.append(indicator_info(n).name)
                continue
            cells = "".join(
                f"<td class='num'>{'–' if sh.get(k) is None else fmt_pct(min(1.0, sh[k]))}</td>"
                for k in _COMPONENT_NAMES
            )
            rows.append(
                f"<tr><td>{escape(indicator_info(n).name)}</td>{cells}"
                f"<td>{escape(e['basis'])}</td></tr>"
            )
        title = "Baseline" if g == "baseline" else f"Horizon {g}"
        head = "".join(f"<th class='num'>{escape(v)}</th>" for v in _COMPONENT_NAMES.values())
        out.append(
            f"<h3>{escape(title)} ({escape(', '.join(block['cases']))})</h3>"
            f"<div class='scroll'><table class='split'><thead><tr><th>indicator</th>{head}"
            f"<th>of</th></tr></thead><tbody>{''.join(rows)}</tbody></table></div>"
            + (
                f"<p>The same in every draw here (no shares): {escape(', '.join(here))}.</p>"
                if here
                else ""
            )
        )
    years = {c["years"] for c in proj.summary["cases"]}
    note = ""
    if years == {1}:
        note = (
            "<div class='note amber'><p>The weather is one year: its year-to-year "
            "variability is not in this projection (no weather-year share). A baseline "
            "of several years (e.g. ten years of station data) puts it in.</p></div>"
        )
    return (
        "<p>Shares of the variance of each indicator (they add up to 100 %): "
        "<b>parameters of the room</b> — the spread of the noise-free simulations over "
        "the posterior draws; <b>model error</b> — what the noise draw adds; <b>weather "
        "year</b> — the spread between the years of the weather (per-year indicators "
        "only, for one year's value); <b>scenario</b> — the spread of the scenario means "
        f"at a horizon. {_scenario_caveat(proj)} Where the model "
        "error is correlated with the parameters, the covariance is shared in proportion "
        "to the two variances.</p>" + note + "".join(out)
    )


def _registry_html(proj) -> str:
    rows = []
    for n in proj.summary["indicators"]:
        i = indicator_info(n)
        rows.append(
            f"<tr><td><b>{escape(i.name)}</b><br><small><code>{escape(n)}</code></small></td>"
            f"<td>{escape(i.unit)}</td><td>{escape(i.definition)}</td>"
            f"<td>{escape(i.source)}</td><td>{escape(i.period)}</td></tr>"
        )
    return (
        "<div class='scroll'><table class='registry'><thead><tr><th>indicator</th>"
        "<th>unit</th><th>definition</th><th>source</th><th>period</th></tr></thead>"
        f"<tbody>{''.join(rows)}</tbody></table></div>"
    )


def _weather_html(proj) -> str:
    mode = str(proj.summary["humidity"])
    rows = []
    for c in proj.summary["cases"]:
        w = c["weather"]
        method = w.get("method") or w.get("from", "")
        detail = ", ".join(
            f"{k}: `{v}`" if k == "humidity" else f"{k}: {v}".replace("`", "")
            for k, v in w.items()
            if k in ("scenario", "horizon", "region", "humidity", "path")
        )
        rows.append(
            f"<tr><td>{escape(c['label'])}</td><td>{escape(str(method))}</td>"
            f"<td>{prose_html(detail)}</td><td class='num'>{fmt(c['mean_Te'])}</td>"
            f"<td class='num'>{c['years']}</td><td class='num'>{c['hours_dropped']}</td></tr>"
        )
    return (
        f"<p>Humidity under warming: <b>{_HUMIDITY_WORDS.get(mode, escape(mode))}</b> "
        f"(<code>humidity: {escape(mode)}</code>). Every indicator is computed over the complete "
        "years of the weather (blocks of 8760 h from its start); the hours after the "
        "last complete year are not simulated.</p><div class='scroll'><table><thead><tr>"
        "<th>case</th><th>weather</th><th>details</th><th class='num'>mean Te [°C]</th>"
        "<th class='num'>complete years</th><th class='num'>hours left out</th></tr>"
        f"</thead><tbody>{''.join(rows)}</tbody></table></div>"
    )


#: What each ``humidity`` mode of the projection config does, in words.
_HUMIDITY_WORDS = {
    "constant_rh": "outdoor relative humidity kept as it was (the vapour pressure rises "
    "with the warming)",
    "constant_vapour_pressure": "outdoor vapour pressure kept as it was (the relative "
    "humidity falls with the warming)",
    "table": "outdoor relative humidity changed as the KNMI'14 tables give",
}


def _models_text(run) -> str:
    """`` (models a, b ...)`` of the run, and what a hygric model sorbing at the indoor
    temperature is driven by in a projection."""
    models = getattr(run, "models", None) or {}
    if not models:
        return ""
    text = " (models " + ", ".join(f"<code>{escape(m.name)}</code>" for m in models.values())
    from heritage_bayes.projection.weather import coupled_columns

    if "hygric" in models and "thermal" in models and coupled_columns(run, "hygric"):
        text += "; the hygric buffer sorbs at each draw's simulated indoor temperature"
    return text + ")"


def render_projection_page(proj, run) -> str:
    """The HTML page of a projection (see the module docstring)."""
    from heritage_bayes._version import __version__
    from heritage_bayes.report.page import Section, render_page

    s = proj.summary
    assumptions = "".join(f"<li>{escape(a)}</li>" for a in s["assumptions"])
    noise = s.get("noise")
    noise_text = ", ".join(f"{k}: `{v}`" for k, v in (noise or {}).items())
    lead = (
        _CSS
        + _banner(proj)
        + _verdict_html(proj)
        + "<div class='note info'><p>"
        + f"{s['draws']} posterior draws of the calibrated room{_models_text(run)}, each "
        + "simulated on the "
        + f"baseline and on {len(proj.labels) - 1} future weather(s)"
        + (
            f", with a draw of its noise model ({prose_html(noise_text)})"
            if noise
            else ", noise-free (parameter uncertainty only)"
        )
        + ".</p></div>"
    )
    seasonal = _fig_seasonal(proj)
    risk = _fig_risk(proj)
    from heritage_bayes.projection.interventions_page import interventions_html

    measures = interventions_html(proj, run, KEY_INDICATORS)
    sections = [
        Section(
            "What the projection assumes", f"<ul>{assumptions}</ul>", id="assumptions", lead=lead
        ),
        Section("Baseline and scenarios", _decision_html(proj), id="decision"),
        Section("Probability statements", _probability_html(proj), id="probabilities"),
        Section(
            "Indoor climate",
            f"<figure id='fig-seasonal'><img src='{seasonal}' alt='seasonal cycle of the "
            "indoor temperature and RH'></figure>",
            id="climate",
        ),
        Section(
            "Risk for the collection",
            f"<figure id='fig-risk'><img src='{risk}' alt='indicator distributions'></figure>"
            if risk
            else "<p>No key indicator computed.</p>",
            id="risk",
        ),
        *(
            [Section("Measures against doing nothing", measures, id="interventions")]
            if measures
            else []
        ),
        Section("Where the uncertainty comes from", _split_html(proj), id="uncertainty"),
        Section("Indicators", _registry_html(proj), id="indicators"),
        Section("Weather", _weather_html(proj), id="weather"),
    ]
    cfg = run.config
    title = f"Projection — {cfg.building or cfg.name or 'room'}"
    return render_page(
        title,
        sections,
        subtitle=str(cfg.room or ""),
        generator=f"heritage_bayes {__version__}",
        header_note=f"run: {run.path}",
    )
