"""Section 5, parameters: posterior median, interval, contraction and sampler checks.

Per section a table (with the Monte-Carlo standard error of the median and of the 5 %
and 95 % quantiles, ``arviz.mcse``, so that sampler noise can be told from posterior
width) and a prior-versus-posterior figure of every free parameter, noise parameters
included (log10 axis for log-scale priors, the prior's exact density drawn over the
posterior histogram).
"""

from __future__ import annotations

import math

import numpy as np

from heritage_bayes.format import fmt, fmt_int, fmt_interval, fmt_pct, prior_text, quantity_name
from heritage_bayes.inference.likelihoods import noise_parameter_names
from heritage_bayes.report.identifiable import mcse_cells, mcse_table, prior_density
from heritage_bayes.report.page import Section
from heritage_bayes.report.rundata import RunData, parameter_set, section_params
from heritage_bayes.report.sections._fragment import render_fragment
from heritage_bayes.report.verdict import ess_class, rhat_class
from heritage_bayes.rundir.summary import Convergence, ModelInfo

ID, TITLE = "parameters", "5. Parameters"


def parameter_tables(rd: RunData) -> list[dict]:
    """One table per model, every figure from the typed run summary."""
    rs = rd.summary
    r_ok, e_ok = rs.convergence.target_rhat, rs.convergence.target_ess
    draws_note = draws_sentence(rs.convergence)
    tables = []
    for m, info in rs.models.items():
        idf = info.identifiability
        params = [e for e in rs.parameters.values() if e.section == m]
        has_truth = any(e.truth is not None for e in params)
        mc = mcse_table(rd, [e.key for e in params if e.fixed is None])
        noise = noise_parameter_names(info.noise, info.output_names, info.state_names)
        rows = []
        for e in params:
            if e.name not in idf.parameters:
                id_text = "noise" if e.name in noise else "—"
            elif e.name in idf.identifiable:
                id_text = "yes"
            elif e.name in idf.identifiable_given_scale:
                id_text = "if scale pinned"
            else:
                id_text = "no"
            fixed = e.fixed is not None
            rows.append(
                {
                    "name": e.name,
                    "label": quantity_name(e.name, e.description, domain=m),
                    "unit": e.unit,
                    "prior": "fixed" if fixed else prior_text(e.prior),
                    "map": fmt(e.map),
                    "median": fmt(e.median),
                    "interval": "—" if fixed else fmt_interval(e.q05, e.q95),
                    "at_bound": e.at_bound,
                    "truth": fmt(e.truth) if e.truth is not None else "—",
                    "inside": e.truth_inside,
                    "contraction": "—" if e.contraction is None else fmt_pct(e.contraction),
                    "r_hat": "—" if e.r_hat is None else f"{e.r_hat:.3f}",
                    "r_cls": "" if e.r_hat is None else rhat_class(e.r_hat, r_ok),
                    "ess_bulk": fmt_int(e.ess_bulk),
                    "ess_tail": fmt_int(e.ess_tail),
                    "e_cls": "" if e.ess_bulk is None else ess_class(e.ess_bulk, e_ok),
                    "tau": fmt_int(e.tau),
                    "ident": id_text,
                    **mcse_cells(mc.get(e.key)),
                }
            )
        tables.append(
            {
                "section": m,
                "model": info.model,
                "noise": info.noise or "?",
                "rows": rows,
                "draws_note": draws_note,
                "has_truth": has_truth,
                "map_lp": fmt(info.map_log_posterior),
                "map_agreed": f"{info.map_agreed} of {info.map_starts}",
                "map_method": info.map_method,
                "prior_fig": _prior_figure(rd, m, info),
                "cap_h": None
                if info.time_constant_cap_h is None
                else fmt(info.time_constant_cap_h),
                "temperature": None
                if info.likelihood_temperature == 1.0
                else fmt(info.likelihood_temperature),
            }
        )
    return tables


def draws_sentence(conv: Convergence) -> str:
    """Which draws the tables' figures are on, in one sentence."""
    if conv.draws != "retained":
        return "Every figure of the tables is that of the draws saved in posterior.nc."
    return (
        f"R-hat and ESS are those of {conv.draws_where}, the draws the sampler's "
        "stopping rule checked; median, interval and MCSE those of the thinned draws of "
        "the posterior group."
    )


def _prior_figure(rd: RunData, m: str, info: ModelInfo):
    """Prior vs posterior of every free parameter of section ``m`` (None without the
    run's ParameterSet, e.g. a config that no longer matches the summary)."""
    from heritage_bayes.report.figures import fig_prior_posterior

    ps = parameter_set(rd, m)
    post = rd.idata.posterior
    if ps is None:
        return None
    params = section_params(rd.summary, m)
    panels = []
    for name in ps.free_names:
        key = f"{m}.{name}"
        if key not in post:
            continue
        p = ps[name]
        log = p.prior.log_scale
        x = np.asarray(post[key].values, dtype=float).reshape(-1)
        truth = params[name].truth if name in params else None
        if log:
            with np.errstate(divide="ignore", invalid="ignore"):
                x = np.log10(x)
            truth = math.log10(truth) if truth is not None and truth > 0 else None
        unit = p.unit if p.unit and p.unit != "-" else "-"
        px, py = prior_density(p.prior, log)
        panels.append(
            {
                "label": f"log10 {name} [{unit}]" if log else f"{name} [{unit}]",
                "post": x,
                "prior_x": px,
                "prior_y": py,
                "truth": truth,
            }
        )
    if not panels:
        return None
    return fig_prior_posterior(
        panels,
        title=f"{m} ({info.model}): prior (line) and posterior (histogram) of the free parameters",
    )


def section(ctx: dict) -> Section:
    """This section of the page, from the report context (figures already data URIs)."""
    return Section(TITLE, render_fragment("parameters.html", ctx), id=ID)
