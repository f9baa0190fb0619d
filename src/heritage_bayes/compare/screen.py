"""The candidates' MAP screen before any is sampled, and the rule that keeps those within
reach of the best.

Part of :mod:`heritage_bayes.compare` (see its documentation). Each candidate's MAP is
found on exactly the log-posterior its calibration samples (its own config, the same
prepared data), so the MAP found here starts its chain; the search is ``model: auto``'s
(:func:`heritage_bayes.selection.screen_maps`, one loop for both): the MAP of a nested
simpler candidate (:data:`heritage_bayes.models.AUTO_LADDERS`) carried over as one start
of one global search. The score is the validation FIT of the simulation from the MAP
(:func:`heritage_bayes.selection.row_score`).
"""

from __future__ import annotations

import math
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
    """MAP and ladder row of every candidate config, by the loop of ``model: auto``'s
    screen (:func:`heritage_bayes.selection.screen_maps`): (label -> row, label -> MAP
    result, label -> score [%]). A candidate whose MAP cannot be found scores NaN (its
    row says why)."""
    from heritage_bayes.ladder import section_log_posterior
    from heritage_bayes.models import build_model
    from heritage_bayes.prepare import prepare
    from heritage_bayes.selection import screen_maps

    parents = {n: p for n, _, p in AUTO_LADDERS.get(section, ())}
    preps: dict = {}

    def build(cand):
        def run():
            model = build_model(cand, section)
            key = tuple(model.input_names)
            if key not in preps:  # one preparation per set of inputs
                preps[key] = prepare(cand)
            sec = getattr(cand, section)
            lp = section_log_posterior(cand, preps[key], section, model, sec.priors)
            return preps[key], model, lp

        return run

    first = next(iter(cands.values()))
    rows, found = screen_maps(
        [(label, parents.get(label), build(c)) for label, c in cands.items()],
        section,
        seed=first.seed,
        optimizer=first.optimizer,
        say=tell,
    )
    rows = {r["model"]: r for r in rows}
    scores = {n: float(rows[n].get("score", math.nan)) for n in cands}
    return rows, {n: mp for n, (_, _, mp) in found.items()}, scores
