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

__all__ = ["REACH_FIT", "screen_candidates", "within_reach"]

#: [percentage points of validation FIT] candidates whose MAP scores within this of the
#: best are sampled (at least the best two: a comparison needs two posteriors). Wider
#: than :data:`heritage_bayes.selection.MARGIN_FIT`: the ELPD of the posteriors, not the
#: MAP's FIT, decides between those sampled.
REACH_FIT = 5.0


def within_reach(scores: Mapping[str, float], reach: float = REACH_FIT) -> dict[str, str | None]:
    """Candidate -> None when it is sampled, else why it is screened out.

    ``scores``: candidate -> MAP validation score [%] (NaN: not scored, screened out).
    Sampled: every candidate within ``reach`` points of the best score, and at least the
    best two scored.
    """
    ok = {m: s for m, s in scores.items() if math.isfinite(s)}
    if not ok:
        return {m: "no MAP score" for m in scores}
    best = max(ok.values())
    ranked = sorted(ok, key=lambda m: -ok[m])
    keep = {m for m in ok if ok[m] >= best - reach} | set(ranked[:2])
    out: dict[str, str | None] = {}
    for m, s in scores.items():
        if m in keep:
            out[m] = None
        elif not math.isfinite(s):
            out[m] = "screened out: no MAP score"
        else:
            out[m] = (
                f"screened out: MAP validation FIT {s:.1f} %, {best - s:.1f} points below "
                f"the best ({ranked[0]}: {best:.1f} %; reach {reach:g} points)"
            )
    return out


def screen_candidates(
    cands: Mapping, section: str, *, tell: Callable[[str], None]
) -> tuple[dict, dict, dict]:
    """MAP and ladder row of every candidate config: (label -> row, label -> MAP result,
    label -> score [%]). A candidate whose MAP cannot be found scores NaN (its row says
    why)."""
    from heritage_bayes.calibrate import _log_posterior
    from heritage_bayes.errors import ConfigError, InputError
    from heritage_bayes.inference.optimize import find_map
    from heritage_bayes.ladder import ladder_row
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
            lp = _log_posterior(cand, prep, section, model, sec.priors)
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
