"""Did a finished calibration converge, and if not, why: the reasons ``summary.json``
records and the exit status scripts read.

Exit status of ``hbayes calibrate`` (and ``hbayes batch``): 0 converged, **3 finished but
not converged** (:data:`EXIT_UNCONVERGED`: the run directory is complete, but a chain
stopped at its budget, ``sampler.max_time`` or ``sampler.max_steps``, before the
convergence criteria held, so its posterior is not yet to be trusted), 2 a user error,
1 an internal error, 130 interrupted.

A chain has converged when it is ``sampler.tau_factor`` autocorrelation times long with
a stable τ estimate (Foreman-Mackey et al. 2013, emcee's guidance) and every free
parameter has a rank-normalised R-hat ≤ 1.01 and a bulk ESS ≥ 400 (Vehtari et al. 2021,
doi:10.1214/20-BA1221).
"""

from __future__ import annotations

import math
from collections.abc import Mapping
from typing import Any

from heritage_bayes.format import quantity_name
from heritage_bayes.rundir.summary_parts import Continuation

__all__ = ["EXIT_UNCONVERGED", "unconverged_reasons"]

#: Exit code of a run that finished but did not converge.
EXIT_UNCONVERGED = 3

_STOPPED_BY = {
    "max_seconds": "the time budget `sampler.max_time` ran out",
    "max_steps": "the step cap `sampler.max_steps` was reached",
}


def _num(value: Any) -> float:
    try:
        return float(value)
    except (TypeError, ValueError):
        return math.nan


def _words(key: str) -> str:
    """``thermal.phi_Ti`` -> ``thermal model: model-error autocorrelation of Ti``."""
    section = key.split(".", 1)[0] if "." in key else ""
    return f"{section} model: {quantity_name(key)}" if section else quantity_name(key)


def _grouped(n: float) -> str:
    """``68 000``: thousands separated by a space (SI style)."""
    return f"{round(n):,}".replace(",", " ")


def unconverged_reasons(summary: Mapping[str, Any]) -> list[str]:
    """Why a run did not converge, one sentence per failed criterion (empty: converged).

    A run the sampler's rule declared converged (``summary["converged"]`` true: τ, R-hat
    and ESS on all retained draws) has no reasons: the portfolio's "why not converged"
    column then stays empty for it. Otherwise the parameters' R-hat and bulk ESS
    (``parameters``: those of every retained draw; of the thinned draws saved in the
    ``posterior`` group in runs written before, docs/science/benchmarks.md, "Which draws
    the convergence figures are on") are checked against the criteria.

    Parameters
    ----------
    summary : mapping
        The content of ``summary.json`` (``models.<section>.chain``, ``parameters``,
        ``criteria``).

    Returns
    -------
    list of str
        E.g. ``"hygric: the time budget `sampler.max_time` ran out after 68 000 steps;
        τmax 1311 asks for about 65 550 steps (50 τ) with a stable τ"`` (a chain
        continued with the time later sections left says so: ``"after 15 600 steps
        (continued from 15 000 steps with the 6 min the hygric section left)"``),
        ``"max R-hat 1.034 (hygric model: moisture capacity of the buffering surfaces
        Cw) > 1.01"``.
    """
    if summary.get("converged") is True:
        return []
    reasons: list[str] = []
    criteria = summary.get("criteria") or {}
    factor = _num(criteria.get("tau_factor", 50.0))
    for section, info in (summary.get("models") or {}).items():
        chain = info.get("chain") or {}
        if chain.get("converged_tau", True):
            continue
        why = _STOPPED_BY.get(chain.get("stopped_by"), "the chain stopped")
        steps = int(_num(chain.get("steps", 0)) or 0)
        tau = _num(chain.get("tau_max"))
        need = (
            f"; τmax {tau:.0f} asks for about {_grouped(factor * tau)} steps ({factor:g} τ) "
            "with a stable τ"
            if math.isfinite(tau)
            else ""
        )
        more = Continuation.from_dict(chain.get("continued"))
        more = f" ({more.words})" if more is not None else ""
        reasons.append(f"{section}: {why} after {_grouped(steps)} steps{more}{need}")
    params = summary.get("parameters") or {}
    max_rhat, min_ess = _num(criteria.get("max_rhat")), _num(criteria.get("min_ess_bulk"))
    rhat = {k: _num(v.get("r_hat")) for k, v in params.items() if "r_hat" in v}
    ess = {k: _num(v.get("ess_bulk")) for k, v in params.items() if "ess_bulk" in v}
    worst = max(rhat, key=lambda k: rhat[k] if math.isfinite(rhat[k]) else math.inf, default=None)
    if worst is not None and not rhat[worst] <= max_rhat:
        reasons.append(f"max R-hat {rhat[worst]:.3f} ({_words(worst)}) > {max_rhat:g}")
    least = min(ess, key=lambda k: ess[k] if math.isfinite(ess[k]) else -math.inf, default=None)
    if least is not None and not ess[least] >= min_ess:
        reasons.append(f"min bulk ESS {ess[least]:.0f} ({_words(least)}) < {min_ess:g}")
    if not reasons and not summary.get("converged", True):
        reasons.append("the convergence criteria did not hold (see summary.json: criteria)")
    return reasons
