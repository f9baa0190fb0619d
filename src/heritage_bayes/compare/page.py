"""The comparison's outputs: trade-off figure, tables, comparison.html and .json.

Part of :mod:`heritage_bayes.compare` (see its documentation).
"""

from __future__ import annotations

import html
import math
from collections.abc import Sequence
from pathlib import Path

from markupsafe import Markup

from heritage_bayes.format import fmt, fmt_interval, prose_html, quantity_name, tick_names
from heritage_bayes.rc.catalog import CATALOG
from heritage_bayes.rundir.signals import DeferSignals


def fig_tradeoff(result: dict):
    """The paper's trade-off: accuracy against identifiability, one point per model.

    x: the share of well-identified directions, practical rank / number of free physical
    parameters (whiskers: the same with the variance-ratio threshold ten times stricter
    and ten times looser); y: the accuracy score relative to the best model, ±2 SE. The
    legend gives each model's practical and structural rank.
    """
    from heritage_bayes.report.figures.style import C_ALT, C_MODEL, _figure, tex_safe

    fig = _figure(7.5, 4.2)
    ax = fig.subplots()
    score = result["accuracy_score"]
    what = "validation ELPD" if score == "elpd_validation" else "blocked LOO ELPD"
    rec = result["recommendation"]["model"]
    markers = "osD^v<>p"
    others = ["0.35", C_ALT, "#2e8b57", "#8e44ad", "#b8860b"]
    for i, (m, info) in enumerate(result["models"].items()):
        idf = info["identifiability"]
        n = max(idf["n_free_physical"], 1)
        a = info["accuracy"][score]
        x = idf["practical_rank"] / n
        lo, hi = (r / n for r in idf.get("practical_rank_band", [idf["practical_rank"]] * 2))
        y, dse = a.get("diff_to_best", 0.0), a.get("dse_to_best") or 0.0
        colour = C_MODEL if m == rec else others[i % len(others)]
        label = (
            f"{tex_safe(m)}{' (recommended)' if m == rec else ''}: rank "
            f"{idf['practical_rank']} practical, {idf['structural_rank']} structural, "
            f"{idf['n_free_physical']} parameters"
        )
        ax.errorbar(
            x,
            y,
            xerr=[[x - lo], [hi - x]],
            yerr=2 * dse,
            fmt=markers[i % len(markers)],
            color=colour,
            capsize=4,
            ms=9 if m == rec else 7,
            label=label,
        )
    ax.axhline(0.0, color="0.7", lw=0.8)
    ax.set_xlim(-0.05, 1.05)
    ax.set_xlabel("well-identified directions: practical rank / parameters [-]")
    ax.set_ylabel(f"{what} − best [-] (±2 SE)")
    ax.set_title("accuracy vs identifiability (full posteriors)")
    ax.legend(loc="best", fontsize=8)
    return fig


def _f(x, fmt="{:.3g}") -> str:
    if x is None or (isinstance(x, float) and not math.isfinite(x)):
        return "–"
    if isinstance(x, bool):
        return "yes" if x else "no"
    return fmt.format(x)


def _table(head: Sequence[str], rows: Sequence[Sequence[str]], code: Sequence[int] = (0,)) -> str:
    """An HTML table; the columns ``code`` hold names the user types (model names,
    the Python names of quantities) and are set as code."""

    def cell(i: int, c: str) -> str:
        text = html.escape(c)
        if i in code and c:
            text = f"<code>{text}</code>"
        return f"<td class='num'>{text}</td>" if i and i not in code else f"<td>{text}</td>"

    h = "".join(f"<th scope='col'>{html.escape(c)}</th>" for c in head)
    body = "".join("<tr>" + "".join(cell(i, c) for i, c in enumerate(r)) + "</tr>" for r in rows)
    return (
        f"<div class='scroll'><table><thead><tr>{h}</tr></thead><tbody>{body}</tbody></table></div>"
    )


def accuracy_rows(result: dict) -> tuple[list[str], list[list[str]]]:
    """The accuracy table (also printed by the CLI)."""
    head = [
        "model",
        "FIT val [%]",
        "MSE val",
        "MAE val",
        "ELPD val",
        "Δ ± SE",
        "LOO cal (blocked)",
        "Δ ± SE",
        "max Pareto k",
        "converged",
    ]
    rows = []
    for m, info in result["models"].items():
        a = info["accuracy"]
        v = a.get("validation", {})
        ev = a.get("elpd_validation", {})
        lo = a["loo_blocked"]
        rows.append(
            [
                m,
                _f(v.get("FIT"), "{:.1f}"),
                _f(v.get("MSE"), "{:.3g}"),
                _f(v.get("MAE"), "{:.3g}"),
                _f(ev.get("elpd"), "{:.1f}"),
                f"{_f(ev.get('diff_to_best'), '{:.1f}')} ± {_f(ev.get('dse_to_best'), '{:.1f}')}",
                f"{_f(lo['elpd'], '{:.1f}')} ± {_f(lo['se'], '{:.1f}')}",
                f"{_f(lo.get('diff_to_best'), '{:.1f}')} ± {_f(lo.get('dse_to_best'), '{:.1f}')}",
                _f(lo["max_pareto_k"], "{:.2f}"),
                _f(info["converged"]),
            ]
        )
    return head, rows


def identifiability_rows(result: dict) -> tuple[list[str], list[list[str]]]:
    """The identifiability summary table (also printed by the CLI)."""
    head = [
        "model",
        "free physical",
        "structural rank",
        "practical rank",
        "contraction (median)",
        "widest 90 % interval",
        "parameters identified",
        "time constants identified",
        "derived not identified",
    ]
    rows = []
    for m, info in result["models"].items():
        i = info["identifiability"]
        w = i["widest_interval"]
        rows.append(
            [
                m,
                str(i["n_free_physical"]),
                _f(i["structural_rank"], "{}"),
                str(i["practical_rank"]),
                _f(i["contraction_median"], "{:.2f}"),
                f"{quantity_name(w['parameter'])}: {w['decades']:.1f} decades" if w else "–",
                f"{i['n_free_physical'] - len(i['parameters_not_identified'])} of "
                f"{i['n_free_physical']}",
                _f(i["time_constants_identified"]),
                ", ".join(
                    quantity_name(k).removeprefix("time constant ")
                    + (" (< time step)" if k in i["time_constants_below_step"] else "")
                    for k, e in i["derived"].items()
                    if not e["identified"]
                )
                or "–",
            ]
        )
    return head, rows


def _quantity_rows(info: dict) -> list[list[str]]:
    """One row per quantity: its label, its Python name, then the run's own figures
    (the medians and intervals its summary.json states, printed as its report does)."""
    rows = []
    i = info["identifiability"]
    for kind, table in (("parameter", i["parameters"]), ("derived", i["derived"])):
        for name, e in table.items():
            label = quantity_name(name, domain=info.get("section", ""))
            if e.get("fixed"):
                rows.append([label, name, kind, e.get("unit", ""), "fixed", "", "", "", ""])
                continue
            rows.append(
                [
                    label,
                    name,
                    kind,
                    e.get("unit", ""),
                    fmt(e.get("median")),  # the digits of the run's own report
                    fmt_interval(e.get("q05"), e.get("q95")),
                    _f(e.get("factor90"), "{:.3g}"),
                    _f(e.get("contraction"), "{:.3f}"),
                    _f(e.get("identified")),
                ]
            )
    return rows


def screen_rows(result: dict) -> tuple[list[str], list[list[str]]]:
    """The screen's table: each candidate's free parameters, calibration and validation
    FIT of the simulation from its MAP, and whether it was sampled or why not."""
    out = result.get("screened_out") or {}
    rows = []
    for r in (result.get("screen") or {}).get("rows", []):
        fit = r.get("fit") or {}
        cells = [
            _f(next(iter((fit.get(p) or {}).values()), {}).get("FIT"), "{:.1f}")
            for p in ("calibration", "validation")
        ]
        m = r.get("model", "?")
        what = (out.get(m) or {}).get("reason") or r.get("error") or "sampled"
        rows.append([m, _f(r.get("n_params"), "{:.0f}"), *cells, what])
    return ["model", "free parameters", "MAP FIT cal [%]", "MAP FIT val [%]", "outcome"], rows


def render_comparison(result: dict) -> str:
    """``comparison.html``: the house page with the trade-off figure and the tables."""
    from heritage_bayes._version import __version__
    from heritage_bayes.report.figures import to_png_uri
    from heritage_bayes.report.page import Section, render_page

    rec = result["recommendation"]
    s = result["settings"]
    level = "amber" if rec.get("provisional") else "green"
    by = {"ELPD": "the posteriors' ELPD breaks the screen's tie", "screen": "the screen"}
    lead = (
        f"<div class='verdict {level}'><strong>Recommended: <code>"
        f"{html.escape(rec['model'])}</code></strong>"
        + (
            f" <span>(decided by {by.get(rec.get('decided_by'), 'the screen')}; "
            f"<code>model: auto</code> chooses <code>{html.escape(rec['screen_choice'])}"
            "</code>)</span>"
            if rec.get("screen_choice")
            else ""
        )
        + f"<p>{prose_html(tick_names(rec['reason'], [*CATALOG, *result['models']]))}</p></div>"
    )
    fig = fig_tradeoff(result)
    summary = (
        "<p>Each candidate was calibrated on the same data, noise model and prior "
        "knowledge, with full posteriors (its own run directory and report). Accuracy: "
        f"{prose_html(s['method']['validation'])}; on the calibration period "
        f"{prose_html(s['method']['calibration'])}: hourly data are not exchangeable, so "
        "whole blocks are left out. Identifiability: "
        f"a quantity counts as identified when its {html.escape(s['method']['identified'])}; "
        f"practical rank: {html.escape(s['method']['practical_rank'])}.</p>"
        f"<figure id='fig-tradeoff'><img src='{to_png_uri(fig)}' alt='accuracy against "
        "identifiability, one point per model'><figcaption>Accuracy (relative to the best "
        "model, ±2 SE) against the share of parameter directions the data identify "
        "(practical rank over the number of physical parameters; whiskers: threshold "
        "ten times stricter and looser).</figcaption>"
        "</figure>"
    )
    ha, ra = accuracy_rows(result)
    hi, ri = identifiability_rows(result)
    sections = [
        Section("Summary", summary, id="summary", lead=lead),
        Section("Accuracy", _table(ha, ra), id="accuracy"),
        Section("Identifiability", _table(hi, ri), id="identifiability"),
    ]
    if result.get("screen"):
        hs, rs = screen_rows(result)
        body = f"<p>{html.escape(result['screen']['rule'])}.</p>" + _table(hs, rs)
        sections.append(Section("Screen (MAP)", body, id="screen"))
    for m, info in result["models"].items():
        p = info.get("periods") or {}
        per = "; ".join(
            f"{k} {v['start'][:10]} – {v['end'][:10]}" for k, v in p.items() if isinstance(v, dict)
        )
        body = (
            f"<p>Noise model <code>{html.escape(str(info.get('noise')))}</code>; "
            f"{html.escape(per)}; "
            f"{info['n_draws']} posterior draws; max R-hat {_f(info.get('max_rhat'), '{:.3f}')}, "
            f"min bulk ESS {_f(info.get('min_ess_bulk'), '{:.0f}')}. Run directory: "
            f"<code>{html.escape(info['run_dir'])}</code>.</p>"
            + _table(
                [
                    "quantity",
                    "name",
                    "kind",
                    "unit",
                    "median",
                    "90 % interval",
                    "q95/q05",
                    "contraction",
                    "identified",
                ],
                _quantity_rows(info),
                code=(1,),
            )
        )
        title = Markup(f"Model <code>{html.escape(m)}</code>")  # a name the user types
        sections.append(Section(title, body, id=f"model-{m}"))
    c = result.get("config") or {}
    return render_page(
        f"Model comparison — {c.get('name') or ''}",
        sections,
        subtitle=" · ".join(x for x in (c.get("building"), c.get("room")) if x),
        generator=f"heritage_bayes {__version__}",
    )


def write_comparison(result: dict, out: str | Path) -> tuple[Path, Path]:
    """Write ``comparison.json`` and ``comparison.html`` into ``out`` (each atomically,
    the page rendered first; SIGINT/SIGTERM wait until both are written: never one
    comparison's data beside another's page)."""
    from heritage_bayes.inference.results import atomic_write_text, dump_json

    out = Path(out)
    page = render_comparison(result)
    with DeferSignals():
        dump_json(out / "comparison.json", result)
        atomic_write_text(out / "comparison.html", page)
    return out / "comparison.json", out / "comparison.html"
