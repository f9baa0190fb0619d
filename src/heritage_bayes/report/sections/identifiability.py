"""Section 6, identifiability: structural check, derived quantities, correlations, ladder.

What the data can determine: the non-identifiable directions of each model, the
identifiable derived quantities (time constants, static gains), the posterior
correlation and corner plots, and the model-order ladder (MAP fits of the neighbouring
orders: accuracy vs identifiability).
"""

from __future__ import annotations

import math

import numpy as np

from heritage_bayes.report.format import fmt, fmt_int, is_log_prior
from heritage_bayes.report.page import Section
from heritage_bayes.report.rundata import RunData, section_params
from heritage_bayes.report.sections._fragment import render_fragment

ID, TITLE = "identifiability", "6. Identifiability"

_CORNER_MAX = 3000  # posterior samples in a corner plot


def identifiability_context(rd: RunData) -> list[dict]:
    from heritage_bayes.report.figures import fig_corner, fig_correlation

    s = rd.summary
    post = rd.idata.posterior
    out = []
    for m, info in (s.get("models") or {}).items():
        idf = info.get("identifiability") or {}
        params = section_params(s, m)
        nulls = [
            {
                "label": d.get("label", ""),
                "description": d.get("description", ""),
                "pinned_by": ", ".join(d.get("pinned_by") or []),
                "is_scale": bool(d.get("is_scale")),
            }
            for d in idf.get("null_directions") or []
        ]
        summ_lines = [
            ln.strip()[:1].upper() + ln.strip()[1:]
            for ln in str(idf.get("summary", "")).splitlines()[1:]
            if ln.strip() and not ln.strip().startswith("- ")
        ]
        n_params, rank = idf.get("n_params"), idf.get("rank")
        if idf:
            if idf.get("n_null", 0):
                verdict = (
                    f"{idf.get('n_null')} combination(s) of the {n_params} model "
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
        corr = (s.get("correlations") or {}).get(m) or {}
        names = list(corr.get("names") or [])
        logs = [is_log_prior((params.get(n) or {}).get("prior")) for n in names]
        fig_c = None
        if len(names) > 1:
            labels = [f"log {n}" if lg else n for n, lg in zip(names, logs, strict=True)]
            fig_c = fig_correlation(
                labels,
                np.asarray(corr.get("matrix"), dtype=float),
                title=f"{m} ({info.get('model', '')}): posterior "
                "correlations (log scale where the prior is)",
            )
        fig_k = None
        has_truth = False
        cols, labels, truths = [], [], []
        for n, lg in zip(names, logs, strict=True):
            key = f"{m}.{n}"
            if key not in post:
                continue
            x = np.asarray(post[key].values, dtype=float).reshape(-1)
            unit = (params.get(n) or {}).get("unit", "")
            t = (params.get(n) or {}).get("truth")
            if lg:
                with np.errstate(divide="ignore", invalid="ignore"):
                    x = np.log10(x)
                t = math.log10(t) if t is not None and t > 0 else None
                labels.append(f"log10 {n}\n[{unit}]" if unit and unit != "-" else f"log10 {n}")
            else:
                labels.append(f"{n}\n[{unit}]" if unit and unit != "-" else f"{n}\n[-]")
            cols.append(x)
            truths.append(t)
        if len(cols) > 1:
            X = np.column_stack(cols)
            X = X[np.all(np.isfinite(X), axis=1)]
            if X.shape[0] > _CORNER_MAX:
                idx = np.linspace(0, X.shape[0] - 1, _CORNER_MAX).round().astype(int)
                X = X[idx]
            has_truth = any(t is not None for t in truths)
            if X.shape[0] > X.shape[1]:
                fig_k = fig_corner(X, labels, truths if has_truth else None)
        out.append(
            {
                "section": m,
                "model": info.get("model", m),
                "verdict": verdict,
                "nulls": nulls,
                "control": sorted((idf.get("control") or {}).items()),
                "lines": summ_lines,
                "cond": fmt(idf.get("condition_number_identifiable")),
                "corr_fig": fig_c,
                "corner_fig": fig_k,
                "corner_truth": has_truth,
                "derived": _derived_rows(s, m, info),
            }
        )
    return out


def _derived_rows(s: dict, m: str, info: dict) -> dict:
    taus, gains = [], []
    outs = list(info.get("output_names") or [])
    for key, v in (s.get("derived") or {}).items():
        if not key.startswith(f"{m}."):
            continue
        name = key.split(".", 1)[1]
        r = v.get("r_hat")
        truth = v.get("truth")
        inside = None
        if truth is not None and v.get("q05") is not None and v.get("q95") is not None:
            inside = v["q05"] <= truth <= v["q95"]
        base = {
            "name": name,
            "r_hat": "—" if r is None else f"{r:.3f}",
            "ess": fmt_int(v.get("ess_bulk")),
            "truth": fmt(truth) if truth is not None else "—",
            "truth_d": fmt(_div(truth, 24)) if truth is not None else "—",
            "inside": inside,
        }
        if name.startswith("tau_") and name.endswith("_h"):
            k = name[4:-2]
            base.update(
                label=f"τ{k}",
                median_h=fmt(v.get("median")),
                int_h=f"{fmt(v.get('q05'))} … {fmt(v.get('q95'))}",
                median_d=fmt(_div(v.get("median"), 24)),
                int_d=f"{fmt(_div(v.get('q05'), 24))} … {fmt(_div(v.get('q95'), 24))}",
            )
            taus.append(base)
            continue
        label = name
        for prefix, words in (
            ("gain_", "static gain of {o} from {i}"),
            ("offset_", "steady-state offset of {o} from {i}"),
        ):
            if name.startswith(prefix):
                rest = name[len(prefix) :]
                o = next((o for o in outs if rest.startswith(o + "_")), None)
                if o is not None:
                    label = words.format(o=o, i=rest[len(o) + 1 :])
        base.update(
            label=label,
            unit=v.get("unit", ""),
            median=fmt(v.get("median")),
            interval=f"{fmt(v.get('q05'))} … {fmt(v.get('q95'))}",
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


def ladder_metrics(fit: dict | None, period: str) -> dict[str, dict]:
    """Fit metrics of a ladder row for one period: output -> {MSE, MAE, FIT}.

    Accepts ``fit[period]`` keyed by output (``{"Ti": {"FIT": ...}}``) or flat
    (``{"FIT": ...}``, returned under the key ``""``).
    """
    per = (fit or {}).get(period) or {}
    if any(k in per for k in ("FIT", "MSE", "MAE")):
        return {"": per}
    return {str(k): v for k, v in per.items() if isinstance(v, dict)}


def _ladder_cell(metrics: dict[str, dict], key: str) -> str:
    txt = _fit_txt if key == "FIT" else fmt
    if len(metrics) <= 1:
        return txt(next(iter(metrics.values()), {}).get(key))
    return "; ".join(f"{o}: {txt(v.get(key))}" for o, v in metrics.items())


def ladder_context(s: dict) -> dict | None:
    from heritage_bayes.report.figures import fig_ladder

    ladder = s.get("ladder")
    if not ladder:
        return None
    tables = []
    for domain, rows in ladder.items():
        out = []
        for r in rows or []:
            cal = ladder_metrics(r.get("fit"), "calibration")
            val = ladder_metrics(r.get("fit"), "validation")
            n_model = r.get("n_model_params")
            n_all = r.get("n_params")
            if n_model is not None and n_all is not None and n_all != n_model:
                n_text = f"{fmt_int(n_model)} + {fmt_int(n_all - n_model)} noise"
            else:
                n_text = fmt_int(n_all)
            labels = ", ".join(map(str, r.get("null_directions") or []))
            out.append(
                {
                    "model": r.get("model", "?"),
                    "n_params": n_text,
                    "rank": fmt_int(r.get("rank")),
                    "n_null": fmt_int(r.get("n_null")) + (f" ({labels})" if labels else ""),
                    "cond": fmt(r.get("condition_number_identifiable")),
                    "fit_cal": _ladder_cell(cal, "FIT"),
                    "fit_val": _ladder_cell(val, "FIT"),
                    "mse_cal": _ladder_cell(cal, "MSE"),
                    "mse_val": _ladder_cell(val, "MSE"),
                    "mae_cal": _ladder_cell(cal, "MAE"),
                    "mae_val": _ladder_cell(val, "MAE"),
                    "loglik": fmt(r.get("log_likelihood")),
                    "aic": fmt(r.get("aic")),
                    "bic": fmt(r.get("bic")),
                    "agreed": r.get("map_agreed", "—"),
                    "sampled": bool(r.get("sampled")),
                }
            )
        tables.append({"domain": domain, "rows": out})
    return {"tables": tables, "figure": fig_ladder(ladder)}


def _fit_txt(v) -> str:
    try:
        f = float(v)
    except (TypeError, ValueError):
        return "—"
    return f"{f:.1f}".replace("-", "−") if math.isfinite(f) else "—"


def section(ctx: dict) -> Section:
    """This section of the page, from the report context (figures already data URIs)."""
    return Section(TITLE, render_fragment("identifiability.html", ctx), id=ID)
