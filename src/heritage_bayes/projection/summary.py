"""From per-draw indicators of every case to statements: quantiles, change relative to
the baseline, probabilities, and the split of the uncertainty.

Uncertainty split (per horizon, per indicator; variances over draws):

* **parameter**: the variance of the indicator of the noise-free simulations (posterior
  spread of the building's parameters), averaged over the horizon's scenarios;
* **model error**: the variance of what the noise draw changes, ``var(predictive −
  noise-free)`` draw by draw, averaged over the scenarios;
* **scenario**: the variance over the horizon's scenarios of the predictive mean.

Shares are of the sum of the three. Probabilities are proportions of draws; their
Monte-Carlo standard error is ``sqrt(p (1 − p) / K)`` for ``K`` draws.
"""

from __future__ import annotations

import math

import numpy as np
import pandas as pd

#: +1: a higher value is worse for the collection; -1: a lower value is worse.
WORSE = {
    "twpi": -1,
    "lifetime_multiplier": -1,
    "emc_min": -1,
    "emc_max": 1,
    "emc_range": 1,
    "dimensional_change": 1,
    "metal_corrosion": 1,
    "vtt_mould_index_max": 1,
    "hours_above_LIM": 1,
    "en15757_outside": 1,
}


def worse_sign(name: str) -> int:
    for k, v in WORSE.items():
        if name == k or name.startswith(k):
            return v
    return 0


def numeric_columns(df: pd.DataFrame) -> list[str]:
    return [c for c in df.columns if pd.api.types.is_float_dtype(df[c])]


def _q(x: np.ndarray) -> dict:
    x = x[np.isfinite(x)]
    if not x.size:
        return {"q05": None, "q50": None, "q95": None, "mean": None}
    q = np.quantile(x, [0.05, 0.5, 0.95])
    return {"q05": float(q[0]), "q50": float(q[1]), "q95": float(q[2]), "mean": float(x.mean())}


def summarize(labels, horizons, results, baseline: str, thresholds, units) -> dict:
    """The JSON-ready summary (see the module docstring).

    ``labels``: case labels, the baseline first; ``horizons``: their horizons (None for
    the baseline); ``results``: their :class:`~heritage_bayes.projection.engine.CaseResult`.
    """
    base = results[0].predictive
    K = len(base)
    names = numeric_columns(base)
    ind: dict = {}
    for n in names:
        b = base[n].to_numpy(float)
        entry = {"unit": units.get(n, ""), "worse": worse_sign(n), "cases": {}, "change": {}}
        for lab, r in zip(labels, results, strict=True):
            v = r.predictive[n].to_numpy(float)
            entry["cases"][lab] = _q(v) | {"parametric": _q(r.parametric[n].to_numpy(float))}
            if lab != baseline:
                d = v - b  # paired: same parameter and noise draws
                entry["change"][lab] = _q(d)
                s = worse_sign(n)
                if s:
                    entry["change"][lab]["p_worse"] = float(np.mean(s * d > 0))
        ind[n] = entry
    probs = []
    for t in thresholds:
        if t.indicator not in base.columns:
            continue
        op, val = (">", t.above) if t.above is not None else ("<", t.below)
        row = {"indicator": t.indicator, "op": op, "value": val, "unit": units.get(t.indicator, "")}
        row["cases"] = {}
        for lab, r in zip(labels, results, strict=True):
            v = r.predictive[t.indicator].to_numpy(float)
            p = float(np.mean(v > val) if op == ">" else np.mean(v < val))
            row["cases"][lab] = {"p": p, "mc_se": math.sqrt(p * (1 - p) / K)}
        probs.append(row)
    classes = {}
    if "ashrae_best_class" in base.columns:
        for lab, r in zip(labels, results, strict=True):
            vc = r.predictive["ashrae_best_class"].astype(str).value_counts(normalize=True)
            classes[lab] = {str(k): float(v) for k, v in vc.items()}
    split = {}
    for h in sorted({h for h in horizons if h is not None}):
        rs = [r for r, hh in zip(results, horizons, strict=True) if hh == h]
        split[str(h)] = {}
        for n in names:
            par = np.array([np.nanvar(r.parametric[n].to_numpy(float)) for r in rs])
            err = np.array(
                [
                    np.nanvar(r.predictive[n].to_numpy(float) - r.parametric[n].to_numpy(float))
                    for r in rs
                ]
            )
            means = np.array([np.nanmean(r.predictive[n].to_numpy(float)) for r in rs])
            parts = {
                "parameter": float(par.mean()),
                "model_error": float(err.mean()),
                "scenario": float(means.var()) if len(rs) > 1 else 0.0,
            }
            total = sum(parts.values())
            shares = {k: (v / total if total > 0 else None) for k, v in parts.items()}
            split[str(h)][n] = {"variance": parts, "share": shares, "scenarios": len(rs)}
    return {
        "draws": K,
        "indicators": ind,
        "probabilities": probs,
        "ashrae_best_class": classes,
        "uncertainty_split": split,
    }


def probability_table(summary: dict, labels) -> pd.DataFrame:
    """Rows: statements; columns: cases; values: probabilities."""
    rows = {}
    for p in summary["probabilities"]:
        key = f"P({p['indicator']} {p['op']} {p['value']:g} {p['unit']})".replace(" )", ")")
        rows[key] = {lab: p["cases"][lab]["p"] for lab in labels}
    return pd.DataFrame.from_dict(rows, orient="index", columns=list(labels))
