"""The candidates' MAP screen before any is sampled, and the candidates it samples.

Part of :mod:`heritage_bayes.compare` (see its documentation). Each candidate's MAP is
found on exactly the log-posterior its calibration samples (its own config, the same
prepared data), so the MAP found here starts its chain; the search is ``model: auto``'s
(:func:`heritage_bayes.calibration.selection.screen_maps`, one loop for both): the MAP of a nested
simpler candidate (:data:`heritage_bayes.models.AUTO_LADDERS`) carried over as one start
of one global search, with the same restart guard. The score is the validation FIT of
the simulation from the MAP
(:func:`heritage_bayes.calibration.selection_rule.row_score`), the choice that of
``model: auto`` (:func:`heritage_bayes.calibration.selection_rule.choose`), and the
candidates sampled those whose posteriors can change it (:func:`to_sample`).
"""

from __future__ import annotations

import math
from collections.abc import Callable, Mapping

from heritage_bayes.models import AUTO_LADDERS

__all__ = ["screen_candidates", "to_sample"]


def to_sample(sel: Mapping) -> dict[str, str | None]:
    """Candidate -> None when it is sampled, else why not, from the screen's choice
    (:func:`heritage_bayes.calibration.selection_rule.choose`, ``sel``): the choice and
    its best tied rival (the runner-up: the only one whose ELPD may overturn the choice,
    :func:`heritage_bayes.calibration.selection_rule.decide`); without a tie, the choice
    and the best other candidate scored (a comparison needs two posteriors). Candidates not scored:
    screened out."""
    c, fit, tied = sel["choice"], sel["scores"], sel["tied"]
    second = sel["runner_up"] or max((m for m in fit if m != c), key=fit.__getitem__, default=None)
    best = max(fit.values())
    out: dict[str, str | None] = {}
    for m, s in fit.items():
        if m in (c, second):
            out[m] = None
        elif m in tied:
            out[m] = (
                f"not sampled: ties with {c} on the screen (MAP {sel['score']} {s:.1f} %), "
                f"but {second} ties closer to the best ({fit[second]:.1f} %) and is sampled"
            )
        else:
            out[m] = (
                f"screened out: MAP {sel['score']} {s:.1f} %, {best - s:.1f} points below "
                f"the best ({sel['best']}: {best:.1f} %), outside the {sel['margin']:g}-point "
                "tie: it cannot be recommended"
            )
    return out


def screen_candidates(
    cands: Mapping, models: Mapping, section: str, *, tell: Callable[[str], None]
) -> tuple[dict, dict, dict]:
    """MAP and ladder row of every candidate config (``models``: label -> its model, as
    built with the config), by the loop of ``model: auto``'s screen
    (:func:`heritage_bayes.calibration.selection.screen_maps`): (label -> row, label -> MAP
    result, label -> score [%]). A candidate whose MAP cannot be found scores NaN (its row
    says why)."""
    from heritage_bayes.calibration.ladder import section_log_posterior
    from heritage_bayes.calibration.selection import screen_maps
    from heritage_bayes.prepare import prepare

    parents = {n: p for n, _, p in AUTO_LADDERS.get(section, ())}
    preps: dict = {}

    def build(cand, model):
        def run():
            key = tuple(model.input_names)
            if key not in preps:  # one preparation per set of inputs
                preps[key] = prepare(cand, {section: model})
            sec = getattr(cand, section)
            lp = section_log_posterior(cand, preps[key], section, model, sec.priors)
            return preps[key], model, lp

        return run

    first = next(iter(cands.values()))
    rows, found = screen_maps(
        [(label, parents.get(label), build(c, models[label])) for label, c in cands.items()],
        section,
        seed=first.seed,
        optimizer=first.optimizer,
        say=tell,
    )
    rows = {r["model"]: r for r in rows}
    scores = {n: float(rows[n].get("score", math.nan)) for n in cands}
    return rows, {n: mp for n, (_, _, mp) in found.items()}, scores
