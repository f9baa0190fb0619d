"""Identifiability from full posteriors: contraction, practical rank, widest interval.

Part of :mod:`heritage_bayes.compare` (see its documentation).
"""

from __future__ import annotations

import math
from collections.abc import Sequence

import numpy as np


def _posterior_flat(idata, names: Sequence[str]) -> np.ndarray:
    post = idata.posterior
    return np.column_stack([post[n].values.reshape(-1) for n in names])


def _prior_pushforward(run, section: str, n: int, seed: int):
    """Prior draws of the model parameters (K, P) and their derived quantities
    (:meth:`heritage_bayes.run.Run.prior_pushforward`, shared with the report)."""
    return run.prior_pushforward(section, n, seed)


def _contraction(post: np.ndarray, prior: np.ndarray) -> float | None:
    """1 - Var(post)/Var(prior), on the log scale when both are positive."""
    post = post[np.isfinite(post)]
    prior = prior[np.isfinite(prior)]
    if post.size < 2 or prior.size < 2:
        return None
    if np.all(post > 0) and np.all(prior > 0):
        post, prior = np.log(post), np.log(prior)
    vp = float(np.var(prior))
    if not vp > 0:
        return None
    return float(1.0 - np.var(post) / vp)


def _interval(x: np.ndarray, stated=None) -> dict:
    """Median and 90 % interval of the draws ``x``: those the run's summary.json states
    (``stated``: its :class:`~heritage_bayes.rundir.summary.Estimate`, computed from the
    same saved draws, so every page prints the same digits), else computed here (a run
    written before the summary stated them)."""
    if stated is not None and None not in (stated.median, stated.q05, stated.q95):
        q05, q50, q95 = stated.q05, stated.median, stated.q95
    else:
        x = x[np.isfinite(x)]
        q05, q50, q95 = np.quantile(x, [0.05, 0.5, 0.95])
    factor = float(q95 / q05) if q05 > 0 and q95 > 0 else None
    return {"median": float(q50), "q05": float(q05), "q95": float(q95), "factor90": factor}


def _practical_rank(post: np.ndarray, prior_var: np.ndarray, ratio: float) -> tuple[int, list]:
    """Directions with posterior variance below ``ratio`` x the prior's (whitened)."""
    if post.shape[1] == 0:
        return 0, []
    z = post / np.sqrt(prior_var)
    cov = np.atleast_2d(np.cov(z, rowvar=False))
    ev = np.sort(np.linalg.eigvalsh(cov))
    return int(np.sum(ev < ratio)), [float(e) for e in ev]


def _identifiability(run, section: str, *, seed: int, identified_factor: float, ratio: float):
    summ = run.summary
    rs = run.run_summary
    model = run.models[section]
    idata = run.idata
    P_prior, dq_prior = _prior_pushforward(run, section, 20000, seed)
    params = {}
    free, prior_var, post_cols = [], [], []
    for j, name in enumerate(model.parameter_names):
        key = f"{section}.{name}"
        est = rs.parameters.get(key)
        x = idata.posterior[key].values.reshape(-1)
        fixed = est is not None and est.fixed is not None
        entry = {"unit": est.unit if est else "", "kind": est.kind if est else "", "fixed": fixed}
        if not fixed:
            entry.update(_interval(x, est))
            entry["contraction"] = _contraction(x, P_prior[:, j])
            f = entry["factor90"]
            entry["identified"] = bool(f is not None and f <= identified_factor)
            pos = np.all(P_prior[:, j] > 0) and np.all(x > 0)
            free.append(name)
            pr = np.log(P_prior[:, j]) if pos else P_prior[:, j]
            prior_var.append(float(np.var(pr)))
            post_cols.append(np.log(x) if pos else x)
        params[name] = entry
    derived = {}
    for k, prior in dq_prior.items():
        key = f"{section}.{k}"
        if key not in idata.posterior:
            continue
        x = idata.posterior[key].values.reshape(-1)
        if not np.all(np.isfinite(x)):
            continue
        entry = {
            "unit": idata.posterior[key].attrs.get("unit", ""),
            **_interval(x, rs.derived.get(key)),
        }
        entry["contraction"] = _contraction(x, prior)
        f = entry["factor90"]
        entry["identified"] = bool(f is not None and f <= identified_factor)
        derived[k] = entry
    post = np.column_stack(post_cols) if post_cols else np.zeros((1, 0))
    prank, eig = _practical_rank(post, np.asarray(prior_var), ratio)
    ev = np.asarray(eig)
    # how the practical rank depends on its threshold: ratio / 10 to ratio x 10
    prank_band = [int(np.sum(ev < ratio / 10)), int(np.sum(ev < ratio * 10))]
    ident = summ["models"][section].get("identifiability") or {}
    widest = None
    for name in free:
        e = params[name]
        if e.get("factor90"):
            dec = math.log10(e["factor90"])
            if widest is None or dec > widest["decades"]:
                widest = {"parameter": name, "decades": dec, "q05": e["q05"], "q95": e["q95"]}
    # time constants shorter than the time step act within one step: hourly data see
    # only their static effect, so they neither can nor need to be identified
    dt_h = rs.dt / 3600.0
    taus = {k: v for k, v in derived.items() if k.startswith("tau_") and v["median"] >= dt_h}
    fast = sorted(k for k in derived if k.startswith("tau_") and k not in taus)
    contr = [params[n]["contraction"] for n in free if params[n]["contraction"] is not None]
    return {
        "parameters": params,
        "derived": derived,
        "n_free_physical": len(free),
        "structural_rank": ident.get("rank"),
        "structural_n_params": ident.get("n_params"),
        "practical_rank": prank,
        "practical_eigenvalues": eig,
        "practical_rank_band": prank_band,
        "widest_interval": widest,
        "time_constants_identified": all(v["identified"] for v in taus.values()),
        "time_constants_not_identified": sorted(k for k, v in taus.items() if not v["identified"]),
        "time_constants_below_step": fast,
        "parameters_not_identified": sorted(n for n in free if not params[n]["identified"]),
        "contraction_median": float(np.median(contr)) if contr else None,
        "contraction_min": float(np.min(contr)) if contr else None,
        "contraction_max": float(np.max(contr)) if contr else None,
    }
