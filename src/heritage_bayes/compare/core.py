"""Side by side: the comparison of candidate runs and the recommendation.

Part of :mod:`heritage_bayes.compare` (see its documentation).
"""

from __future__ import annotations

import math
import warnings
from collections.abc import Mapping
from pathlib import Path

import numpy as np

from heritage_bayes._arviz import az
from heritage_bayes.calibration.selection_rule import NEGLIGIBLE_ELPD, decide, rule_text
from heritage_bayes.compare.identifiability import _identifiability
from heritage_bayes.compare.scores import (
    _block_se,
    blocked_loo_data,
    elpd_validation,
    tempered_loo,
)
from heritage_bayes.errors import InputError
from heritage_bayes.format import quantity_name
from heritage_bayes.rc.catalog import DomainView, model_ladder

__all__ = ["DEFAULT_MODELS", "NEGLIGIBLE_ELPD", "compare_runs", "recommend"]

#: Candidates when ``--models`` is not given: the model-order ladder of each section
#: (the catalogue entries marked ``ladder``, :func:`heritage_bayes.rc.catalog.model_ladder`).
DEFAULT_MODELS: Mapping[str, tuple[str, ...]] = DomainView(model_ladder)


def compare_runs(
    run_dirs: Mapping[str, str | Path],
    section: str,
    *,
    block_hours: float = 24.0,
    identified_factor: float = 2.0,
    practical_ratio: float = 0.01,
    seed: int = 0,
    screen_rows: list[dict] | None = None,
) -> dict:
    """Compare calibrated runs of one section on accuracy and identifiability, and
    recommend one by the selection rule of ``model: auto``
    (:func:`heritage_bayes.calibration.selection_rule.decide`): the screen's choice, unless the ELPD
    reliably breaks its tie.

    Parameters
    ----------
    run_dirs : mapping label -> run directory
        Runs of the same data, each with a model of ``section``.
    section : {"thermal", "hygric"}
    block_hours : float
        Block length of the blocked LOO and of the standard errors [h].
    identified_factor : float
        A quantity is identified when its 90 % interval spans at most this factor.
    practical_ratio : float
        Posterior/prior variance ratio below which a direction counts in the practical
        rank.
    seed : int
        Seed of the prior draws of the derived quantities.
    screen_rows : list of dict, optional
        The MAP screen's ladder rows of the candidates (``hbayes compare``'s screen).
        Without them (runs compared as they are), each run's own validation FIT (of
        its posterior-median simulation; calibration FIT without a validation period)
        stands in for the screen's score.

    Returns
    -------
    dict
        ``models`` (per label: accuracy, identifiability, convergence), ``loo_compare``
        (``az.compare`` on the blocked LOO), ``selection`` (the rule's record:
        :func:`heritage_bayes.calibration.selection_rule.decide`), ``recommendation``
        and the settings.
    """
    from heritage_bayes.run import load_run

    out_models: dict[str, dict] = {}
    val_pw: dict[str, tuple[np.ndarray, np.ndarray]] = {}
    loo_data = {}
    # one run in memory at a time: what the comparison keeps of each (block sums of
    # the log-likelihood, the posterior draws, pointwise validation densities) is small
    for label, path in run_dirs.items():
        run = load_run(path)
        if section not in run.models:
            raise InputError(f"{run.path}: the run has no {section!r} model")
        model = run.models[section]
        var = f"{section}.{model.output_names[0]}"
        acc: dict = {}
        rs = run.run_summary
        for period in ("calibration", "validation"):
            met = rs.metric(section, model.output_names[0], period)
            if met is not None:
                acc[period] = {k: getattr(met, k) for k in ("FIT", "MSE", "MAE", "coverage90")}
        ev = elpd_validation(run.idata, var, block_hours)
        if ev is not None:
            acc["elpd_validation"] = {k: ev[k] for k in ("elpd", "se", "n")}
            val_pw[label] = (ev["pointwise"], ev["times"])
        info = rs.models.get(section)
        temperature = info.likelihood_temperature if info else 1.0
        with warnings.catch_warnings():  # high Pareto k: recorded below, not printed
            warnings.simplefilter("ignore", UserWarning)
            # the draws of a tempered posterior need their own importance weights
            loo = tempered_loo(blocked_loo_data(run.idata, var, block_hours), var, temperature)
        loo_data[label] = loo
        k = np.asarray(loo.pareto_k)
        acc["loo_blocked"] = {
            "elpd": float(loo.elpd_loo),
            "se": float(loo.se),
            "p_loo": float(loo.p_loo),
            "n_blocks": int(k.size),
            "max_pareto_k": float(np.max(k)),
            "share_k_above_0.7": float(np.mean(k > 0.7)),
            "likelihood_temperature": temperature,
        }
        ident = _identifiability(
            run, section, seed=seed, identified_factor=identified_factor, ratio=practical_ratio
        )
        out_models[label] = {
            "model": model.name,
            "run_dir": str(run.path),
            "noise": info.noise if info else None,
            "periods": {p.name: p.to_dict() for p in rs.periods} or None,
            # the report's rule: the stopping rule met and the judged draws within the
            # stated criteria
            "converged": rs.convergence.converged and rs.convergence.draws_ok,
            "max_rhat": rs.convergence.max_rhat,
            "min_ess_bulk": rs.convergence.min_ess_bulk,
            "n_draws": int(run.idata.posterior.sizes["chain"] * run.idata.posterior.sizes["draw"]),
            "accuracy": acc,
            "identifiability": ident,
        }
    # differences in validation ELPD against the best, SE from daily block sums
    if len(val_pw) == len(run_dirs) and val_pw:
        best = max(val_pw, key=lambda m: out_models[m]["accuracy"]["elpd_validation"]["elpd"])
        pb, tb = val_pw[best]
        for label, (pw, t) in val_pw.items():
            common, ia, ib = np.intersect1d(t, tb, return_indices=True)
            d = pw[ia] - pb[ib]
            ev = out_models[label]["accuracy"]["elpd_validation"]
            ev["diff_to_best"] = float(d.sum())
            ev["dse_to_best"] = 0.0 if label == best else _block_se(d, common, block_hours)
        score = "elpd_validation"
    else:
        score = "loo_blocked"
    with warnings.catch_warnings():  # Pareto k (recorded) and arviz's pandas notices
        warnings.simplefilter("ignore")
        cmp = az.compare(loo_data, ic="loo")
    loo_table = {
        str(m): {
            c: _num(cmp.loc[m, c])
            for c in ("rank", "elpd_loo", "p_loo", "elpd_diff", "se", "dse", "weight")
        }
        for m in cmp.index
    }
    for m, row in loo_table.items():
        out_models[m]["accuracy"]["loo_blocked"]["diff_to_best"] = -row["elpd_diff"]
        out_models[m]["accuracy"]["loo_blocked"]["dse_to_best"] = row["dse"]
    rows = screen_rows if screen_rows is not None else _rows_of_runs(out_models)
    what = "validation ELPD" if score == "elpd_validation" else "blocked LOO ELPD"
    pairs = val_pw if score == "elpd_validation" else _loo_pointwise(loo_data)
    post = {
        m: {
            "elpd": info["accuracy"][score]["elpd"],
            "se": {o: _pair_se(pairs[m], pairs[o], block_hours, score) for o in pairs if o != m},
            "converged": info["converged"],
            "max_pareto_k": info["accuracy"]["loo_blocked"]["max_pareto_k"],
        }
        for m, info in out_models.items()
    }
    sel = decide(rows, post, score=what)
    sel["rule"] = rule_text(sel["score"], sel["margin"])
    return {
        "section": section,
        "models": out_models,
        "loo_compare": loo_table,
        "accuracy_score": score,
        "selection": sel,
        "recommendation": recommend(sel, out_models, score),
        "settings": {
            "block_hours": block_hours,
            "identified_factor": identified_factor,
            "practical_ratio": practical_ratio,
            "seed": seed,
            "method": {
                "calibration": f"blocked PSIS-LOO, blocks of {block_hours:g} h (`az.loo` "
                "over block sums of the pointwise log-likelihood; a tempered run's draws "
                "weighted by p^(-1/T))",
                "validation": "sum over validation hours of the log posterior-mean one-step "
                "predictive density (the validation ELPD); SE from block sums",
                "identified": f"90 % interval within a factor {identified_factor:g}",
                "practical_rank": f"directions with posterior/prior variance < {practical_ratio:g}",
            },
        },
    }


def _num(x):
    try:
        x = float(x)
    except (TypeError, ValueError):
        return None
    return x if math.isfinite(x) else None


def _tau_label(key: str) -> str:
    """``tau_2_h`` -> ``τ₂``: a time constant as the pages name it."""
    return quantity_name(key).removeprefix("time constant ")


def _rows_of_runs(models: dict) -> list[dict]:
    """Screen rows standing in for a MAP screen when runs are compared as they are:
    each run's own FIT per period (its posterior-median simulation) and its free
    physical parameters."""
    return [
        {
            "model": m,
            "n_params": info["identifiability"]["n_free_physical"],
            "fit": {
                p: {"y": {"FIT": info["accuracy"][p]["FIT"]}}
                for p in ("calibration", "validation")
                if (info["accuracy"].get(p) or {}).get("FIT") is not None
            },
        }
        for m, info in models.items()
    ]


def _loo_pointwise(loo_data: dict) -> dict:
    """label -> (the blocked LOO's terms, their blocks' start times)."""
    out = {}
    for m, loo in loo_data.items():
        li = loo.loo_i
        out[m] = (np.asarray(li.values, dtype=float).ravel(), np.asarray(li[li.dims[-1]].values))
    return out


def _pair_se(a: tuple, b: tuple, block_hours: float, score: str) -> float | None:
    """SE of the ELPD difference of two candidates over their common hours (validation:
    from daily block sums) or blocks (blocked LOO: blocks are independent terms)."""
    (pa, ta), (pb, tb) = a, b
    common, ia, ib = np.intersect1d(ta, tb, return_indices=True)
    if common.size < 2:
        return None
    d = pa[ia] - pb[ib]
    if score == "elpd_validation":
        return _num(_block_se(d, common, block_hours))
    return _num(math.sqrt(d.size * np.var(d, ddof=1)))


def recommend(sel: dict, models: dict, score: str) -> dict:
    """The comparison's recommendation: the selection rule's decision
    (:func:`heritage_bayes.calibration.selection_rule.decide`, ``sel``) in words, with
    the identifiability of the model recommended and the candidates not converged."""
    rec, stage = sel["model"], sel["posterior"] or {}
    if sel["decided_by"] == "ELPD":
        head = f"the ELPD breaks the screen's tie; the screen chose {sel['choice']}"
    else:
        head = "the screen's choice, as `model: auto` chooses"
    why = stage.get("reason", "")
    text = f"`{rec}`: {head} ({sel['reason']}). {why[:1].upper()}{why[1:]}."
    text += "".join(f" {n[0].upper()}{n[1:]}." for n in stage.get("notes", []))
    ident = models[rec]["identifiability"] if rec in models else None
    if ident is not None and ident["time_constants_identified"]:
        fast = ident["time_constants_below_step"]
        text += (
            " Its time constants longer than the time step are identified ("
            + ", ".join(_tau_label(k) for k in fast)
            + " shorter than the step: the data see only its static effect)."
            if fast
            else " All its time constants are identified."
        )
    elif ident is not None:
        text += (
            " Not all its time constants are identified ("
            + ", ".join(_tau_label(k) for k in ident["time_constants_not_identified"])
            + "): their intervals are wide."
        )
    unconverged = [m for m, info in models.items() if info.get("converged") is False]
    if unconverged:
        names = ", ".join(f"`{m}`" for m in unconverged)
        text += f" Not converged (R-hat/ESS/τ criteria), so its figures are provisional: {names}."
    return {
        "model": rec,
        "reason": text,
        "decided_by": sel["decided_by"],
        "screen_choice": sel["choice"],
        "agrees_with_screen": rec == sel["choice"],
        "best_accuracy": max(models, key=lambda m: models[m]["accuracy"][score]["elpd"]),
        "not_converged": unconverged,
        # the decision may change with longer chains: the rival's ELPD was not reliable,
        # or the model recommended did not converge
        "provisional": stage.get("verdict") == "not reliable" or rec in unconverged,
    }
