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
from heritage_bayes.report.identifiable import mcse_cells, mcse_table, prior_density
from heritage_bayes.report.page import Section
from heritage_bayes.report.rundata import RunData, parameter_set, section_params
from heritage_bayes.report.sections._fragment import render_fragment
from heritage_bayes.report.verdict import ess_class, rhat_class

ID, TITLE = "parameters", "5. Parameters"


def parameter_tables(rd: RunData) -> list[dict]:
    s = rd.summary
    crit = s.get("criteria") or {}
    r_ok = float(crit.get("max_rhat", 1.01))
    e_ok = float(crit.get("min_ess_bulk", 400.0))
    tables = []
    for m, info in (s.get("models") or {}).items():
        ident = (info.get("identifiability") or {}).get("parameters") or {}
        params = section_params(s, m)
        has_truth = any(v.get("truth") is not None for v in params.values())
        mc = mcse_table(rd, [f"{m}.{n}" for n, v in params.items() if v.get("fixed") is None])
        rows = []
        for name, v in params.items():
            fixed = v.get("fixed")
            r, e = v.get("r_hat"), v.get("ess_bulk")
            idf = ident.get(name)
            if idf is None:
                id_text = "noise" if v.get("kind") in ("sigma", "phi", "sigma_meas") else "—"
            elif idf.get("identifiable"):
                id_text = "yes"
            elif idf.get("identifiable_given_scale"):
                id_text = "if scale pinned"
            else:
                id_text = "no"
            truth = v.get("truth")
            inside = None
            if truth is not None and v.get("q05") is not None:
                inside = v["q05"] <= truth <= v["q95"]
            rows.append(
                {
                    "name": name,
                    "label": quantity_name(name, v.get("description"), domain=m),
                    "unit": v.get("unit", ""),
                    "prior": "fixed" if fixed is not None else prior_text(v.get("prior")),
                    "map": fmt(v.get("map")),
                    "median": fmt(v.get("median")),
                    "interval": "—"
                    if fixed is not None
                    else fmt_interval(v.get("q05"), v.get("q95")),
                    "at_bound": v.get("at_bound"),
                    "truth": fmt(truth) if truth is not None else "—",
                    "inside": inside,
                    "contraction": "—"
                    if v.get("contraction") is None
                    else fmt_pct(v["contraction"]),
                    "r_hat": "—" if r is None else f"{r:.3f}",
                    "r_cls": "" if r is None else rhat_class(r, r_ok),
                    "ess_bulk": fmt_int(e),
                    "ess_tail": fmt_int(v.get("ess_tail")),
                    "e_cls": "" if e is None else ess_class(e, e_ok),
                    "tau": fmt_int(v.get("tau")),
                    "ident": id_text,
                    **mcse_cells(mc.get(f"{m}.{name}")),
                }
            )
        mp = info.get("map") or {}
        tables.append(
            {
                "section": m,
                "model": info.get("model", m),
                "noise": info.get("noise", "?"),
                "rows": rows,
                "has_truth": has_truth,
                "map_lp": fmt(mp.get("log_posterior")),
                "map_agreed": f"{mp.get('agreed', '?')} of {mp.get('starts', '?')}",
                "map_method": mp.get("method", "?"),
                "prior_fig": _prior_figure(rd, m, info),
                "cap_h": None
                if info.get("time_constant_cap_h") is None
                else fmt(info["time_constant_cap_h"]),
                "temperature": None
                if (info.get("likelihood_temperature") or 1.0) == 1.0
                else fmt(info["likelihood_temperature"]),
            }
        )
    return tables


def _prior_figure(rd: RunData, m: str, info: dict):
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
        truth = (params.get(name) or {}).get("truth")
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
        title=f"{m} ({info.get('model', '')}): prior (line) and posterior (histogram) "
        "of the free parameters",
    )


def section(ctx: dict) -> Section:
    """This section of the page, from the report context (figures already data URIs)."""
    return Section(TITLE, render_fragment("parameters.html", ctx), id=ID)
