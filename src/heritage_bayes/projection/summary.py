r"""From per-draw indicators of every case to statements: quantiles, change relative to
the baseline, probabilities, and the decomposition of the uncertainty.

Decomposition (per horizon, and for the baseline alone; per indicator). With ``y``
the predictive value (the draw's noise realisation included) and ``x`` the noise-free
value of the same draw, for scenarios ``s``, posterior draws ``k`` and, for the
indicators computed per complete year, years ``j`` of the weather — population
variances, every group the same size, so that the law of total variance holds exactly:

.. math::

    \operatorname{Var}(y) = \underbrace{\operatorname{Var}_s \bar y_s}_{\text{scenario}}
    + \overline{\operatorname{Var}_k \bar y_{sk}}
    + \overline{\operatorname{Var}_j y_{skj}}

* **scenario**: the variance of the scenario means (0 with one scenario);
* **parameter** and **noise** (model error): the between-draw variance
  ``Var_k(ȳ) = Var(x̄) + Var(d̄) + 2 Cov(x̄, d̄)`` with ``d = y − x``, split in
  proportion to ``Var(x̄)`` (parameter) and ``Var(d̄)`` (noise): the covariance is
  shared the same way, so both parts are non-negative and add up to ``Var_k(ȳ)``;
* **weather year**: the within-draw variance over the years, ``Var_j(y)``, split the
  same way between ``Var_j(x)`` (weather year) and ``Var_j(d)`` (the year-to-year part
  of the noise, added to **noise**). Only for the per-year indicators
  (:data:`heritage_bayes.projection._stream.ANNUAL`), and only when the weather has
  more than one year; there the split is of **one year's value**. Other indicators
  (extremes over the period, shares over all hours) have no weather-year term.

The shares are the components over ``Var(y)``: non-negative, and they sum to 1 by
construction. An indicator constant in every draw (:func:`is_degenerate`, e.g. an EMC
minimum of 0 % or a dimensional change the same for every parameter draw) has no
variance to split: it is flagged ``degenerate`` and given no shares.

Each case's weather is one change per scenario (the KNMI'14 tables, one
set of morphing deltas, one file), so a climate-model range is not separated from the
scenario term unless each model is a case of its own.
Probabilities are proportions of draws; their Monte-Carlo standard error is
``sqrt(p (1 − p) / K)`` for ``K`` draws.
"""

from __future__ import annotations

import math

import numpy as np
import pandas as pd

from heritage_bayes.climate.risk.registry import indicator_info

#: Components of the decomposition, in the order of the page.
COMPONENTS = ("parameter", "noise", "weather_year", "scenario")


def worse_sign(name: str) -> int:
    """+1 if a higher value is worse for the collection, -1 if lower, 0 if neither."""
    return indicator_info(name).worse


def numeric_columns(df: pd.DataFrame) -> list[str]:
    return [c for c in df.columns if pd.api.types.is_float_dtype(df[c])]


def _q(x: np.ndarray) -> dict:
    x = x[np.isfinite(x)]
    if not x.size:
        return {"q05": None, "q50": None, "q95": None, "mean": None}
    q = np.quantile(x, [0.05, 0.5, 0.95])
    return {"q05": float(q[0]), "q50": float(q[1]), "q95": float(q[2]), "mean": float(x.mean())}


def is_degenerate(y: np.ndarray) -> bool:
    """True when the finite values of ``y`` are all equal (to 1e-12 of their magnitude:
    a variance of rounding error is not split into shares); False with no finite value."""
    v = np.asarray(y, float)
    v = v[np.isfinite(v)]
    return v.size > 0 and float(np.ptp(v)) <= 1e-12 * max(1.0, float(np.abs(v).max()))


def _proportional(a: np.ndarray, b: np.ndarray, axis: int) -> tuple[float, float]:
    """``Var(a + b)`` split into the parts of ``a`` and ``b`` in proportion to
    ``Var(a)`` and ``Var(b)`` (the covariance shared the same way): both non-negative,
    their sum ``Var(a + b)`` exactly; averaged over the other axes."""
    va, vb = a.var(axis=axis), b.var(axis=axis)
    tot = (a + b).var(axis=axis)
    den = va + vb
    with np.errstate(invalid="ignore", divide="ignore"):
        fa = np.where(den > 0, va / den, 0.5)
    return float((fa * tot).mean()), float(((1 - fa) * tot).mean())


def decompose(y: np.ndarray, x: np.ndarray) -> dict:
    """The variance decomposition of the module docstring.

    Parameters
    ----------
    y, x : numpy.ndarray
        Predictive and noise-free values, shape (scenarios, draws) or (scenarios,
        draws, years). Draws with a non-finite value in any scenario or year are left
        out.

    Returns
    -------
    dict
        ``variance`` (component → variance, ``weather_year`` None without years),
        ``total`` and ``share`` (component → share of the total, None where the total
        is 0 or the component is absent), ``draws`` used and ``degenerate`` (the values
        are constant: no shares).
    """
    y = np.asarray(y, float)
    x = np.asarray(x, float)
    yearly = y.ndim == 3 and y.shape[2] > 1
    if y.ndim == 2:
        y, x = y[:, :, None], x[:, :, None]
    ok = np.isfinite(y).all(axis=(0, 2)) & np.isfinite(x).all(axis=(0, 2))
    y, x = y[:, ok], x[:, ok]
    if not ok.any() or is_degenerate(y[:, ok]):
        return {"variance": dict.fromkeys(COMPONENTS), "total": None,
                "share": dict.fromkeys(COMPONENTS), "draws": int(ok.sum()),
                "degenerate": bool(ok.any())}  # fmt: skip
    d = y - x
    scenario = float(y.mean(axis=(1, 2)).var())
    xb, db = x.mean(axis=2), d.mean(axis=2)  # (S, K): means over the years
    parameter, noise = _proportional(xb, db, axis=1)
    weather, noise_w = _proportional(x, d, axis=2)
    noise += noise_w
    total = float(y.var())
    parts = {"parameter": parameter, "noise": noise,
             "weather_year": weather if yearly else None, "scenario": scenario}  # fmt: skip
    if not yearly:
        parts["noise"] += weather  # 0 without years (one value per draw)
    share = {k: (v / total if (v is not None and total > 0) else None) for k, v in parts.items()}
    return {"variance": parts, "total": total, "share": share, "draws": int(ok.sum()),
            "degenerate": False}  # fmt: skip


def _annual(r, name: str):
    """(predictive, noise-free) per-year values of ``name`` in a case, or None."""
    names = list(getattr(r, "annual_names", ()) or ())
    if name not in names or r.annual_predictive is None:
        return None
    j = names.index(name)
    return r.annual_predictive[:, :, j], r.annual_parametric[:, :, j]


def _split(labels, horizons, results, names) -> dict:
    groups = {"baseline": [0]}
    for h in sorted({h for h in horizons if h is not None}):
        groups[str(h)] = [i for i, hh in enumerate(horizons) if hh == h]
    out = {}
    for key, idx in groups.items():
        rs = [results[i] for i in idx]
        per = {}
        for n in names:
            ann = [_annual(r, n) for r in rs]
            if all(a is not None for a in ann) and ann[0][0].shape[1] > 1:
                y = np.stack([a[0] for a in ann])
                x = np.stack([a[1] for a in ann])
                basis = f"one year's value ({ann[0][0].shape[1]} years of weather)"
            else:
                y = np.stack([r.predictive[n].to_numpy(float) for r in rs])
                x = np.stack([r.parametric[n].to_numpy(float) for r in rs])
                basis = "the value over the period"
            per[n] = decompose(y, x) | {"basis": basis}
        out[key] = {"cases": [labels[i] for i in idx], "indicators": per}
    return out


def summarize(labels, horizons, results, baseline: str, thresholds, units) -> dict:
    """The JSON-ready summary (see the module docstring).

    ``labels``: case labels, the baseline first; ``horizons``: their horizons (None for
    the baseline); ``results``: their :class:`~heritage_bayes.projection.cases.CaseResult`.
    Every share and probability is a fraction in [0, 1]; units are those of the
    indicator registry (:mod:`heritage_bayes.climate.risk.registry`).
    """
    base = results[0].predictive
    K = len(base)
    names = numeric_columns(base)
    ind: dict = {}
    for n in names:
        info = indicator_info(n)
        b = base[n].to_numpy(float)
        entry = {
            "name": info.name,
            "unit": units.get(n, info.unit),
            "definition": info.definition,
            "source": info.source,
            "period": info.period,
            "worse": info.worse,
            "cases": {},
            "change": {},
            "degenerate": is_degenerate(
                np.concatenate([r.predictive[n].to_numpy(float) for r in results])
            ),
        }
        for lab, r in zip(labels, results, strict=True):
            v = r.predictive[n].to_numpy(float)
            entry["cases"][lab] = _q(v) | {"parametric": _q(r.parametric[n].to_numpy(float))}
            if lab != baseline:
                d = v - b  # paired: same parameter and noise draws
                entry["change"][lab] = _q(d)
                if info.worse:
                    entry["change"][lab]["p_worse"] = float(np.mean(info.worse * d > 0))
        ind[n] = entry
    probs = []
    for t in thresholds:
        op, val = (">", t.above) if t.above is not None else ("<", t.below)
        info = indicator_info(t.indicator)
        row = {"indicator": t.indicator, "name": info.name, "op": op, "value": val,
               "unit": units.get(t.indicator, info.unit), "cases": {}}  # fmt: skip
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
    return {
        "draws": K,
        "indicators": ind,
        "probabilities": probs,
        "ashrae_best_class": classes,
        "uncertainty_split": _split(labels, horizons, results, names),
    }


def probability_table(summary: dict, labels) -> pd.DataFrame:
    """Rows: statements; columns: cases; values: probabilities."""
    rows = {}
    for p in summary["probabilities"]:
        key = f"P({p['name']} {p['op']} {p['value']:g} {p['unit']})".replace(" )", ")")
        rows[key] = {lab: p["cases"][lab]["p"] for lab in labels}
    return pd.DataFrame.from_dict(rows, orient="index", columns=list(labels))
