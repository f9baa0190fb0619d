"""``projection.html``: the projection on one self-contained page in the house style
(:func:`heritage_bayes.report.page.render_page`, figures through
:mod:`heritage_bayes.report.figures.style`)."""

from __future__ import annotations

from html import escape

import numpy as np

from heritage_bayes.report.figures.style import RC_PARAMS, _figure, to_png_uri
from heritage_bayes.report.format import fmt, fmt_pct

#: Indicators drawn as distributions (when computed).
_DIST = ("twpi", "emc_range", "vtt_mould_index_max", "en15757_outside")
_CASE_COLOURS = ("#222222", "#1f5fa8", "#2e8b57", "#e08a00", "#c0392b", "#7b3fa0", "#8c564b")


def _colour(i: int) -> str:
    return _CASE_COLOURS[i % len(_CASE_COLOURS)]


def _fig_fans(proj) -> str:
    import matplotlib

    ds = proj.dataset
    with matplotlib.rc_context(RC_PARAMS):
        fig = _figure(9.0, 5.2)
        axes = fig.subplots(2, 1, sharex=True)
        months = np.arange(1, 13)
        for ax, name, unit in ((axes[0], "Ti", "°C"), (axes[1], "RHi", "%")):
            arr = ds[f"{name}_monthly"].values  # (case, draw, 12)
            for i, lab in enumerate(proj.labels):
                q = np.nanquantile(arr[i], [0.05, 0.5, 0.95], axis=0)
                c = _colour(i)
                ax.fill_between(months, q[0], q[2], color=c, alpha=0.15, lw=0)
                ax.plot(months, q[1], color=c, lw=1.4, label=lab)
            ax.set_ylabel(f"indoor {name} [{unit}]")
        axes[1].set_xticks(months, ["J", "F", "M", "A", "M", "J", "J", "A", "S", "O", "N", "D"])
        axes[1].set_xlabel("calendar month (mean over the case's years)")
        axes[0].legend(ncol=min(4, len(proj.labels)), loc="best")
        axes[0].set_title("Monthly indoor climate: median and 5–95 % predictive band of the draws")
        return to_png_uri(fig)


def _fig_risk(proj) -> str:
    import matplotlib

    ds = proj.dataset
    names = [n for n in _DIST if n in ds]
    if not names:
        return ""
    with matplotlib.rc_context(RC_PARAMS):
        fig = _figure(9.0, 1.9 * len(names) + 0.6)
        axes = np.atleast_1d(fig.subplots(len(names), 1))
        for ax, n in zip(axes, names, strict=True):
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
            ax.set_xlabel(f"{n} [{ds[n].attrs.get('unit', '')}]")
        fig.suptitle("Risk indicators over the draws (box: 25–75 %, whiskers: 5–95 %)")
        return to_png_uri(fig)


def _q_text(d: dict | None) -> str:
    if not d or d.get("q50") is None:
        return "–"
    return f"{fmt(d['q50'])} [{fmt(d['q05'])}, {fmt(d['q95'])}]"


def _probability_html(proj) -> str:
    s = proj.summary
    head = "".join(f"<th>{escape(lab)}</th>" for lab in proj.labels)
    rows = []
    for p in s["probabilities"]:
        stmt = f"P({p['indicator']} {p['op']} {p['value']:g} {p['unit']})"
        cells = "".join(
            f"<td class='num'>{fmt(p['cases'][lab]['p'], 2)}</td>" for lab in proj.labels
        )
        rows.append(f"<tr><td>{escape(stmt)}</td>{cells}</tr>")
    K = s["draws"]
    se = 0.5 / np.sqrt(K)
    return (
        f"<div class='scroll'><table><thead><tr><th>statement</th>{head}</tr></thead>"
        f"<tbody>{''.join(rows)}</tbody></table></div>"
        f"<p>Proportions of {K} posterior draws, each simulated with a draw of its noise "
        f"model (predictive). Monte-Carlo standard error at most {fmt(se, 2)}.</p>"
    )


def _indicator_html(proj) -> str:
    s = proj.summary
    futures = proj.labels[1:]
    head = "<th>indicator</th><th>unit</th>" + "".join(
        f"<th>{escape(lab)}</th>" for lab in proj.labels
    )
    head += "".join(f"<th>Δ {escape(lab)}</th><th>P(worse) {escape(lab)}</th>" for lab in futures)
    rows = []
    for n, e in s["indicators"].items():
        cells = "".join(f"<td class='num'>{_q_text(e['cases'][lab])}</td>" for lab in proj.labels)
        for lab in futures:
            ch = e["change"].get(lab)
            pw = ch.get("p_worse") if ch else None
            cells += f"<td class='num'>{_q_text(ch)}</td>"
            cells += f"<td class='num'>{'–' if pw is None else fmt(pw, 2)}</td>"
        rows.append(f"<tr><td>{escape(n)}</td><td>{escape(e['unit'])}</td>{cells}</tr>")
    cls = s.get("ashrae_best_class") or {}
    extra = ""
    if cls:
        items = "".join(
            f"<li>{escape(lab)}: "
            + ", ".join(f"{escape(k)} {fmt_pct(100 * v)}" for k, v in sorted(cls[lab].items()))
            + "</li>"
            for lab in proj.labels
        )
        extra = f"<p>Best ASHRAE class reached (share of draws):</p><ul>{items}</ul>"
    return (
        "<p>Median [5 %, 95 %] over the draws; Δ: change relative to the baseline, paired "
        "draw by draw (same parameters, same noise realisation); P(worse): share of draws "
        "in which the indicator gets worse for the collection.</p>"
        f"<div class='scroll'><table><thead><tr>{head}</tr></thead>"
        f"<tbody>{''.join(rows)}</tbody></table></div>{extra}"
    )


def _split_html(proj) -> str:
    split = proj.summary["uncertainty_split"]
    if not split:
        return "<p>No future horizon.</p>"
    out = []
    for h, per in split.items():
        rows = []
        for n, e in per.items():
            sh = e["share"]
            cells = "".join(
                f"<td class='num'>{'–' if sh[k] is None else fmt_pct(100 * sh[k])}</td>"
                for k in ("parameter", "model_error", "scenario")
            )
            rows.append(f"<tr><td>{escape(n)}</td>{cells}</tr>")
        n_s = next(iter(per.values()))["scenarios"] if per else 0
        out.append(
            f"<h3>Horizon {escape(h)} ({n_s} scenario{'s' if n_s != 1 else ''})</h3>"
            "<div class='scroll'><table><thead><tr><th>indicator</th><th>parameter</th>"
            "<th>model error</th><th>scenario</th></tr></thead>"
            f"<tbody>{''.join(rows)}</tbody></table></div>"
        )
    return (
        "<p>Share of the variance of each indicator: <b>parameter</b> — the spread of the "
        "noise-free simulations over the posterior draws; <b>model error</b> — what the "
        "noise draw changes, draw by draw; <b>scenario</b> — the spread of the "
        "predictive means over the horizon's scenarios.</p>" + "".join(out)
    )


def _weather_html(proj) -> str:
    rows = []
    for c in proj.summary["cases"]:
        w = c["weather"]
        method = w.get("method") or w.get("from", "")
        detail = ", ".join(
            f"{k}: {v}"
            for k, v in w.items()
            if k in ("scenario", "horizon", "region", "humidity", "path")
        )
        rows.append(
            f"<tr><td>{escape(c['label'])}</td><td>{escape(str(method))}</td>"
            f"<td>{escape(detail)}</td><td class='num'>{fmt(c['mean_Te'])}</td>"
            f"<td class='num'>{c['hours']}</td></tr>"
        )
    return (
        f"<p>Humidity under warming: <b>{escape(proj.summary['humidity'])}</b> (see "
        "heritage_bayes.climate.morph).</p><div class='scroll'><table><thead><tr><th>case"
        "</th><th>weather</th><th>details</th><th>mean Te [°C]</th><th>hours</th></tr>"
        f"</thead><tbody>{''.join(rows)}</tbody></table></div>"
    )


def render_projection_page(proj, run) -> str:
    """The HTML page of a projection."""
    from heritage_bayes._version import __version__
    from heritage_bayes.report.page import Section, render_page

    s = proj.summary
    assumptions = "".join(f"<li>{escape(a)}</li>" for a in s["assumptions"])
    noise = s.get("noise")
    noise_text = ", ".join(f"{k}: {v}" for k, v in (noise or {}).items())
    lead = (
        "<div class='note info'><p>"
        f"{s['draws']} posterior draws of the calibrated room, each simulated on the "
        f"baseline and on {len(proj.labels) - 1} future weather(s)"
        + (
            f", with a draw of its noise model ({escape(noise_text)})"
            if noise
            else ", noise-free (parameter uncertainty only)"
        )
        + ".</p></div>"
    )
    fans = _fig_fans(proj)
    risk = _fig_risk(proj)
    sections = [
        Section(
            "What the projection assumes",
            f"<ul>{assumptions}</ul>",
            id="assumptions",
            lead=lead,
        ),
        Section("Probability statements", _probability_html(proj), id="probabilities"),
        Section(
            "Indoor climate",
            f"<figure id='fig-fans'><img src='{fans}' alt='monthly fan charts'></figure>",
            id="climate",
        ),
        Section(
            "Risk for the collection",
            (
                f"<figure id='fig-risk'><img src='{risk}' alt='risk distributions'></figure>"
                if risk
                else ""
            )
            + _indicator_html(proj),
            id="risk",
        ),
        Section("Where the uncertainty comes from", _split_html(proj), id="uncertainty"),
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
