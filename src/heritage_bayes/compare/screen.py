"""The candidates' MAP screen before any is sampled, and the rule that keeps those within
reach of the best.

Part of :mod:`heritage_bayes.compare` (see its documentation). Each candidate's MAP is
found on exactly the log-posterior its calibration samples (its own config, the same
prepared data), so the MAP found here starts its chain; the MAP of a nested simpler
candidate (:data:`heritage_bayes.models.AUTO_LADDERS`) is carried over as one start of
the search. The score is the validation FIT of the simulation from the MAP
(:func:`heritage_bayes.selection.row_score`).
"""

from __future__ import annotations

import math
import time
from collections.abc import Callable, Mapping

from heritage_bayes.models import AUTO_LADDERS
from heritage_bayes.selection import MARGIN_FIT

__all__ = ["REACH_FIT", "screen_candidates", "within_reach"]

#: [percentage points of validation FIT] candidates whose MAP scores within this of the
#: best may be sampled (:func:`within_reach`). Wider than
#: :data:`heritage_bayes.selection.MARGIN_FIT`: the ELPD of the posteriors, not the
#: MAP's FIT, decides between those sampled.
REACH_FIT = 5.0


def within_reach(
    scores: Mapping[str, float],
    n_params: Mapping[str, int] | None = None,
    reach: float = REACH_FIT,
    margin: float = MARGIN_FIT,
) -> dict[str, str | None]:
    """Candidate -> None when it is sampled, else why it is screened out.

    ``scores``: candidate -> MAP validation score [%] (NaN: not scored, screened out);
    ``n_params``: candidate -> free parameters (default: all equal). Sampled, simplest
    first: a candidate within ``reach`` points of the best that beats every simpler
    candidate sampled by more than ``margin`` points (a richer model that adds nothing
    over a simpler one is not worth its posterior); then, were fewer than two taken,
    the best-scoring others (a comparison needs two posteriors).
    """
    n_params = n_params or {}
    ok = {m: s for m, s in scores.items() if math.isfinite(s)}
    if not ok:
        return {m: "screened out: no MAP score" for m in scores}
    best = max(ok.values())
    ranked = sorted(ok, key=lambda m: -ok[m])
    keep: list[str] = []
    why: dict[str, str] = {}
    for m in sorted(ok, key=lambda m: (n_params.get(m, 0), list(scores).index(m))):
        if ok[m] < best - reach:
            why[m] = (
                f"screened out: MAP validation FIT {ok[m]:.1f} %, {best - ok[m]:.1f} points "
                f"below the best ({ranked[0]}: {best:.1f} %; reach {reach:g} points)"
            )
            continue
        simpler = [k for k in keep if n_params.get(k, 0) < n_params.get(m, 0)]
        top = max(simpler, key=lambda k: ok[k]) if simpler else None
        if top is not None and ok[m] <= ok[top] + margin:
            why[m] = (
                f"screened out: MAP validation FIT {ok[m]:.1f} %, not more than {margin:g} "
                f"points above the simpler {top} ({ok[top]:.1f} %)"
            )
            continue
        keep.append(m)
    for m in ranked:
        if len(keep) >= 2:
            break
        if m not in keep:
            keep.append(m)
    return {m: None if m in keep else why.get(m, "screened out: no MAP score") for m in scores}


def screen_candidates(
    cands: Mapping, section: str, *, tell: Callable[[str], None]
) -> tuple[dict, dict, dict]:
    """MAP and ladder row of every candidate config: (label -> row, label -> MAP result,
    label -> score [%]). A candidate whose MAP cannot be found scores NaN (its row says
    why)."""
    from heritage_bayes.errors import ConfigError, InputError
    from heritage_bayes.inference.optimize import find_map
    from heritage_bayes.ladder import ladder_row, section_log_posterior
    from heritage_bayes.models import build_model
    from heritage_bayes.prepare import prepare
    from heritage_bayes.selection import _period, carried_start, row_score

    parents = {n: p for n, _, p in AUTO_LADDERS.get(section, ())}
    preps: dict = {}
    rows, maps, scores, lps = {}, {}, {}, {}
    n = len(cands)
    for k, (label, cand) in enumerate(cands.items(), 1):
        t0 = time.perf_counter()
        try:
            model = build_model(cand, section)
            key = tuple(model.input_names)
            if key not in preps:  # one preparation per set of inputs
                preps[key] = prepare(cand)
            prep = preps[key]
            sec = getattr(cand, section)
            lp = section_log_posterior(cand, prep, section, model, sec.priors)
            parent = parents.get(label)
            start = carried_start(lp, lps[parent], maps[parent]) if parent in maps else None
            opt = cand.optimizer
            mp = find_map(
                lp,
                seed=cand.seed,
                method=opt.method,
                popsize=opt.popsize,
                maxiter=opt.maxiter,
                starts=opt.starts,
                restarts=opt.restarts_for(model.n_states),
                start=start,
            )
            row = ladder_row(prep, section, model, lp, mp, label=label)
        except (ConfigError, InputError) as exc:
            rows[label], scores[label] = {"model": label, "error": str(exc)}, math.nan
            tell(f"screen {k}/{n}: {label}: no MAP ({exc})")
            continue
        row["map_seconds"] = time.perf_counter() - t0
        row["score"] = scores[label] = row_score(row, _period(prep))[0]
        rows[label], maps[label], lps[label] = row, mp, lp
        tell(
            f"screen {k}/{n}: {label}: {lp.ndim} free parameters, MAP validation FIT "
            f"{row['score']:.1f} % ({row['map_seconds']:.0f} s)"
        )
    return rows, maps, scores
