"""Section 6, identifiability: structural check, derived quantities, correlations, ladder.

What the data can determine: the non-identifiable directions of each model, the
identifiable derived quantities (time constants, static gains, with the Monte-Carlo
standard errors of their medians and 5 %/95 % quantiles), the posterior correlation
matrix and corner plot, their priors against their posteriors, and the model-order
ladder (MAP fits of the neighbouring orders: accuracy vs identifiability).

The correlation matrix and the corner plot are drawn in *identifiable coordinates*
(:mod:`heritage_bayes.report.identifiable`): log10 of the time constants, the static
gains and one scale coordinate, log10 ΣC. In raw log-parameters, with only indoor
values measured, every C, G and aperture moves together along the scale ridge: their
correlations are all ±1.00 and a corner plot of them shows that ridge, not what the
data determined. The raw correlation matrix stays, smaller and after the others, for
what only it shows: which raw parameters ride on the ridge (±1) and which the data
leave to their prior (near 0, e.g. an aperture the irradiance cannot inform), and the
correlations between the noise parameters. The raw corner plot is dropped: its
diagonal is now the prior-versus-posterior figure of section 5 and its off-diagonal
panels were the ridge.
"""

from __future__ import annotations

import math

import numpy as np

from heritage_bayes.format import (
    fmt,
    fmt_int,
    fmt_interval,
    is_log_prior,
    quantity_name,
    tick_names,
)
from heritage_bayes.report.identifiable import (
    identifiable_coordinates,
    identifiable_correlation,
    mcse_cells,
    mcse_table,
)
from heritage_bayes.report.page import Section
from heritage_bayes.report.rundata import RunData, section_params
from heritage_bayes.report.sections._fragment import render_fragment
from heritage_bayes.rundir.summary import Identifiability, RunSummary

ID, TITLE = "identifiability", "6. Identifiability"

_CORNER_MAX = 3000  # posterior samples in a corner plot


def identifiability_context(rd: RunData) -> list[dict]:
    from heritage_bayes.report.figures import fig_correlation

    s = rd.summary
    out = []
    for m, info in s.models.items():
        idf = info.identifiability
        params = section_params(s, m)
        nulls = [
            {
                "label": d.label,
                "description": tick_names(d.description, params),
                "pinned_by": ", ".join(f"`{n}`" for n in d.pinned_by),
                "is_scale": d.is_scale,
            }
            for d in idf.null_directions
        ]
        summ_lines = [
            tick_names(ln.strip()[:1].upper() + ln.strip()[1:], params)
            for ln in idf.summary.splitlines()[1:]
            if ln.strip() and not ln.strip().startswith("- ")
        ]
        n_params, rank = idf.n_params, idf.rank
        if idf.recorded:
            if idf.n_null:
                verdict = (
                    f"{idf.n_null} combination(s) of the {n_params} model "
                    f"parameters cannot be determined from these inputs and outputs "
                    f"(rank {rank} of {n_params}), whatever the data quality."
                )
            else:
                verdict = (
                    f"All {n_params} model parameters are structurally "
                    f"identifiable (rank {rank} of {n_params})."
                )
        else:
            verdict = "The structural check was not recorded for this run."
        names = list(info.free_names)
        fig_raw = None
        if len(names) > 1:
            logs = [is_log_prior(params[n].prior if n in params else None) for n in names]
            fig_raw = fig_correlation(
                [f"log {n}" if lg else n for n, lg in zip(names, logs, strict=True)],
                np.asarray(info.correlation, dtype=float),
                title=f"{m}: raw parameters (log where the prior is)",
                max_size=5.5,
            )
        coords = identifiable_coordinates(rd, m)
        figs = _coordinate_figures(coords, f"{m} ({info.model})")
        out.append(
            {
                "section": m,
                "model": info.model,
                "verdict": verdict,
                "nulls": nulls,
                "control": sorted(idf.control.items()),
                "lines": summ_lines,
                "cond": fmt(idf.condition_number_identifiable),
                "corr_raw_fig": fig_raw,
                **figs,
                "scale": _scale_words(rd, m, idf, coords),
                "tradeoffs": tradeoff_words(coords),
                "derived": _derived_rows(s, m, mcse_table(rd, _derived_keys(s, m))),
            }
        )
    return out


def _coordinate_figures(coords: list, title: str) -> dict:
    """Correlation matrix, corner plot and prior-vs-posterior figure of the identifiable
    coordinates (figures None where there is too little to draw)."""
    from heritage_bayes.report.figures import fig_corner, fig_correlation, fig_prior_posterior

    out = {"corr_fig": None, "corner_fig": None, "corner_truth": False, "prior_fig": None}
    if not coords:
        return out
    labels = [c.label for c in coords]
    # two-line corner labels: the quantity, then its unit
    corner_labels = [lb.replace(" [", "\n[") for lb in labels]
    truths = [c.truth for c in coords]
    out["corner_truth"] = any(t is not None for t in truths)
    if len(coords) > 1:
        out["corr_fig"] = fig_correlation(
            labels,
            identifiable_correlation(coords),
            title=f"{title}: posterior correlations of τ, gains and scale",
        )
        X = np.column_stack([c.draws.reshape(-1) for c in coords])
        X = X[np.all(np.isfinite(X), axis=1)]
        if X.shape[0] > _CORNER_MAX:
            idx = np.linspace(0, X.shape[0] - 1, _CORNER_MAX).round().astype(int)
            X = X[idx]
        if X.shape[0] > X.shape[1]:
            out["corner_fig"] = fig_corner(
                X, corner_labels, truths if out["corner_truth"] else None, panel=1.3
            )
    out["prior_fig"] = fig_prior_posterior(
        [
            {
                "label": c.label,
                "post": c.draws.reshape(-1),
                "prior_draws": c.prior,
                "truth": c.truth,
            }
            for c in coords
        ],
        title=f"{title}: prior (push-forward, line) and posterior (histogram)",
    )
    return out


#: |posterior correlation| from which two identifiable coordinates are called a
#: weakly separated pair in words: at 0.8 each one's interval is 1/sqrt(1 - r²) = 1.7
#: times as wide as it would be with the other known (a hygric_2c_fixed fit of the demo
#: room, which has no fixed node: gain_Pi_Pe and offset_Pi_Pf at r = -0.80)
TRADEOFF_R = 0.8


def tradeoff_words(coords: list) -> list[str]:
    """Plain words for each pair of identifiable coordinates (time constants, gains,
    offsets, scale) whose posterior correlation reaches ±:data:`TRADEOFF_R`: the data
    determine mainly a combination of the two (how the response splits between outdoor
    air and a slow boundary, a fixed node's gain and its offset, envelope and interior
    mass), and each interval is wide because of that trade-off, by the factor
    :math:`1/\\sqrt{1 - r^2}` (the ratio of a Gaussian's marginal to its conditional
    standard deviation) over what it would be with the other quantity known."""
    from heritage_bayes.report.identifiable import identifiable_correlation

    if len(coords) < 2:
        return []
    r = identifiable_correlation(coords)
    out = []
    for i in range(len(coords)):
        for j in range(i + 1, len(coords)):
            rij = r[i, j]
            if not (np.isfinite(rij) and abs(rij) >= TRADEOFF_R):
                continue
            a, b = coords[i], coords[j]
            sign = "one rises as the other falls" if rij < 0 else "they rise and fall together"
            widen = 1.0 / math.sqrt(max(1.0 - rij * rij, 1e-12))
            out.append(
                f"{a.label} and {b.label} trade off (posterior correlation {rij:+.2f}: "
                f"{sign}). These data cannot separate the two well and determine mainly "
                f"a combination of them: each one's 90 % interval is about {widen:.1f} "
                "times as wide as it would be with the other known. The width is the "
                "data's, not a failure of the fit; knowledge of either (a prior) "
                "narrows the other."
            )
    return out


def _scale_words(rd: RunData, m: str, idf: Identifiability, coords: list) -> str:
    """Why the scale coordinate is there, for the figure captions ('' without one)."""
    from heritage_bayes.report.identifiable import scale_capacities

    if not coords or coords[-1].name != "scale":
        return ""
    caps = " + ".join(scale_capacities(rd.summary, m))
    if idf.has_scale_direction is False:
        return (
            f"Scale: log10 ΣC = log10({caps}), the total capacity; this model's inputs "
            "fix it (no scale direction in the structural check)."
        )
    return (
        f"Scale: log10 ΣC = log10({caps}), the total capacity. Scaling every capacity, "
        "conductance and aperture together leaves the simulated indoor climate "
        "unchanged, so the data cannot fix this direction: without a known heat or "
        "moisture input, only a prior on the room volume (the air capacity) or a "
        "measured air change rate does. The time constants and gains are free of it."
    )


def _derived_keys(s: RunSummary, m: str) -> list[str]:
    return [e.key for e in s.derived.values() if e.section == m]


def _derived_rows(s: RunSummary, m: str, mc: dict | None = None) -> dict:
    taus, gains = [], []
    for e in s.derived.values():
        if e.section != m:
            continue
        name, truth = e.name, e.truth
        base = {
            "name": name,
            "r_hat": "—" if e.r_hat is None else f"{e.r_hat:.3f}",
            "ess": fmt_int(e.ess_bulk),
            "truth": fmt(truth) if truth is not None else "—",
            "truth_d": fmt(_div(truth, 24)) if truth is not None else "—",
            "inside": e.truth_inside,
            **mcse_cells((mc or {}).get(e.key)),
        }
        if name.startswith("tau_") and name.endswith("_h"):
            base.update(
                label=quantity_name(name).removeprefix("time constant "),
                median_h=fmt(e.median),
                int_h=fmt_interval(e.q05, e.q95),
                median_d=fmt(_div(e.median, 24)),
                int_d=fmt_interval(_div(e.q05, 24), _div(e.q95, 24)),
            )
            taus.append(base)
            continue
        base.update(
            label=quantity_name(name, domain=m),
            name=name,
            unit=e.unit,
            median=fmt(e.median),
            interval=fmt_interval(e.q05, e.q95),
        )
        gains.append(base)
    return {
        "taus": taus,
        "gains": gains,
        "tau_truth": any(r["inside"] is not None for r in taus),
        "gain_truth": any(r["inside"] is not None for r in gains),
    }


def _div(v, d):
    return None if v is None else float(v) / d


def _ladder_cell(metrics, key: str) -> str:
    """One cell of the ladder's table: ``key`` (FIT, MSE, MAE) of each output
    (``metrics``: output -> :class:`~heritage_bayes.rundir.summary.RungFit`)."""
    txt = _fit_txt if key == "FIT" else fmt
    if len(metrics) <= 1:
        first = next(iter(metrics.values()), None)
        return txt(None if first is None else getattr(first, key))
    return "; ".join(f"{o}: {txt(getattr(v, key))}" for o, v in metrics.items())


def ladder_context(s: RunSummary) -> dict | None:
    """The model-order ladder's tables and figure (None without a ladder), with the
    screen's choice where ``model: auto`` chose the model."""
    from heritage_bayes.report.figures import fig_ladder

    if not s.ladder:
        return None
    tables = []
    for domain, rows in s.ladder.items():
        out = []
        for r in rows:
            cal, val = r.fits("calibration"), r.fits("validation")
            n_model, n_all = r.n_model_params, r.n_params
            if n_model is not None and n_all is not None and n_all != n_model:
                n_text = f"{fmt_int(n_model)} + {fmt_int(n_all - n_model)} noise"
            else:
                n_text = fmt_int(n_all)
            labels = ", ".join(r.null_directions)
            out.append(
                {
                    "model": r.model + (f" ({r.error})" if r.error else ""),
                    "n_params": n_text,
                    "rank": fmt_int(r.rank),
                    "n_null": fmt_int(r.n_null) + (f" ({labels})" if labels else ""),
                    "cond": fmt(r.condition_number_identifiable),
                    "fit_cal": _ladder_cell(cal, "FIT"),
                    "fit_val": _ladder_cell(val, "FIT"),
                    "mse_cal": _ladder_cell(cal, "MSE"),
                    "mse_val": _ladder_cell(val, "MSE"),
                    "mae_cal": _ladder_cell(cal, "MAE"),
                    "mae_val": _ladder_cell(val, "MAE"),
                    "loglik": fmt(r.log_likelihood),
                    "aic": fmt(r.aic),
                    "bic": fmt(r.bic),
                    "agreed": "—" if r.map_agreed is None else r.map_agreed,
                    "sampled": r.sampled,
                }
            )
        tables.append({"domain": domain, "rows": out, "selection": _selection_text(s, domain)})
    return {"tables": tables, "figure": fig_ladder(s.ladder)}


def _selection_text(s: RunSummary, domain: str) -> str | None:
    """``model: auto``: the model the screen chose, why, and the rule (None otherwise)."""
    sel = s.selection.get(domain)
    if sel is None:
        return None
    text = f"model: auto — {sel.choice} chosen by the screen: {sel.reason}. Rule: {sel.rule}."
    if sel.tie:
        text += f" {sel.tie[0].upper()}{sel.tie[1:]}."
    for r in sel.rows:  # the restart guard, where it ran
        if r.map_guard is not None and r.map_guard.said:
            text += f" {r.model}: {r.map_guard.said}."
    return text


def _fit_txt(v) -> str:
    try:
        f = float(v)
    except (TypeError, ValueError):
        return "—"
    return f"{f:.1f}".replace("-", "−") if math.isfinite(f) else "—"


def section(ctx: dict) -> Section:
    """This section of the page, from the report context (figures already data URIs)."""
    return Section(TITLE, render_fragment("identifiability.html", ctx), id=ID)
