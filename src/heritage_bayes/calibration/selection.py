"""Automatic model selection: a MAP and validation-score screen of the model ladder.

``model: auto`` in a config section (and ``hbayes compare``'s first step) screens the
rungs of :data:`heritage_bayes.models.AUTO_LADDERS`, simplest first: each rung's MAP on
the calibration period (the MAP of its nested simpler rung carried over as one of the
starts of the search, :func:`unit_point`), then the
simulation from the MAP scored on the validation period by the paper's FIT [%]
(Kramer, van Schijndel & Schellen 2013). A MAP costs seconds where a posterior costs
minutes: only the model chosen is sampled.

**The choice rule** (:mod:`heritage_bayes.calibration.selection_rule`: :func:`choose`,
:func:`decide`): the score is the validation FIT of the section's
output (without a validation period, the calibration FIT after the warm-up). Among the
rungs scored, the simplest (fewest free parameters, then ladder order) whose score is
within :data:`MARGIN_FIT` points of the best is chosen: a richer model must beat a
simpler one by more than the margin to be taken. The other rungs within the margin of
the best **tie** with the choice. ``hbayes compare`` uses the same screen and choice, then
samples the choice and its best tied rival (the runner-up), and the ELPD of the two
posteriors breaks the tie only when it is reliable (:func:`decide`): one rule, so the two
commands recommend the same model unless reliable posteriors break the screen's tie, and
then both say so. A rung whose polished MAP starts end far apart gets more global
searches (:func:`restart_guard`).

Why FIT on validation and not an information criterion at the MAP: the hourly residuals
are strongly correlated and the likelihood is tempered, so AIC/BIC count nearly
dependent hours as independent evidence and favour the richest rung by hundreds of units
on a year of data; a held-out period scores what a user needs of the model — that it
reproduces the room on days it did not see — in the units the report states.

References
----------
.. [1] R. Kramer, J. van Schijndel, H. Schellen, "Inverse modeling of simplified
   hygrothermal building models to predict and characterize indoor climates", Building
   and Environment 68 (2013) 87-99, doi:10.1016/j.buildenv.2013.06.019.
"""

from __future__ import annotations

import math
import time
from collections.abc import Callable, Mapping, Sequence
from dataclasses import dataclass, field

import numpy as np

from heritage_bayes.calibration.ladder import ladder_row, rung_log_posterior
from heritage_bayes.calibration.selection_rule import (
    MARGIN_FIT,
    NEGLIGIBLE_ELPD,
    PARETO_K_MAX,
    choose,
    decide,
    row_score,
    rule_text,
)
from heritage_bayes.config.options import ModelOptions
from heritage_bayes.errors import ConfigError, InputError
from heritage_bayes.inference.likelihoods import get_noise_model
from heritage_bayes.inference.parameters import owned_priors
from heritage_bayes.models import AUTO, AUTO_LADDERS, rung_label
from heritage_bayes.rc.model import RCModel

__all__ = [
    "MARGIN_FIT",
    "NEGLIGIBLE_ELPD",
    "PARETO_K_MAX",
    "Screen",
    "choose",
    "chosen_section",
    "decide",
    "row_score",
    "rule_text",
    "screen",
    "screen_maps",
]

#: A parameter of a simpler rung whose value starts a richer rung's one of another name:
#: one node's total conductance to outdoors is the fast path's first guess.
_CARRY = {"Gfast": "Ge"}


@dataclass
class Screen:
    """What the screen of one section found: the ladder rows (the record), the choice
    and, per label, the model, log-posterior and MAP (reused by the caller)."""

    section: str
    rows: list[dict]
    choice: dict
    models: dict = field(default_factory=dict)
    logposts: dict = field(default_factory=dict)
    maps: dict = field(default_factory=dict)
    options: dict = field(default_factory=dict)  # label -> (catalogue name, own options)

    def record(self) -> dict:
        """The JSON record: ``rule``, ``rows`` and the decision (:func:`decide`: the
        choice, why, the tie) as summary.json's ``selection`` holds it."""
        return {
            "rule": rule_text(self.choice["score"], self.choice["margin"]),
            "rows": self.rows,
            **self.choice,
        }


def screen(
    cfg,
    prep,
    section: str,
    rungs: Sequence[tuple[str, RCModel, str | None]],
    *,
    seed: int,
    deadline: float | None = None,
    say: Callable[[str], None] | None = None,
    margin: float = MARGIN_FIT,
    guarded: bool = True,
) -> Screen:
    """MAP of every rung of the section's ladder, its validation score and the choice.

    Parameters
    ----------
    cfg : CalibrationConfig
        The section's options, priors, noise model and the optimizer settings.
    prep : PreparedData
        Prepared for the richest rung (``build_model`` of ``model: auto``).
    section : {"thermal", "hygric"}
    rungs : sequence of (label, model, parent label or None)
        The section's ladder as the run built it
        (:func:`heritage_bayes.models.auto_rungs`).
    seed : int
        Seed of every rung's MAP search.
    deadline : float, optional
        A :func:`time.perf_counter` value: rungs not reached by then are left out
        (recorded as such); the first rung always runs.
    say : callable, optional
        Progress lines.
    margin : float
        :data:`MARGIN_FIT`.
    guarded : bool
        :func:`screen_maps`'s restart guard (default on).
    """
    say = say or (lambda msg: None)
    sec = getattr(cfg, section)
    own = {rung_label(n, o): (n, dict(o)) for n, o, _ in AUTO_LADDERS[section]}

    def build(model):
        return lambda: (
            prep,
            model,
            rung_log_posterior(cfg, prep, section, model, sec.initial_state),
        )

    rows, found = screen_maps(
        [(label, parent, build(model)) for label, model, parent in rungs],
        section,
        seed=seed,
        optimizer=cfg.optimizer,
        deadline=deadline,
        say=lambda msg: say(f"[{section}] {msg}"),
        guarded=guarded,
    )
    out = Screen(section, rows, {})
    for label, (model, lp, mp) in found.items():
        out.models[label], out.logposts[label], out.maps[label] = model, lp, mp
        out.options[label] = own[label]
    out.choice = decide([r for r in out.rows if "error" not in r], margin=margin)
    for r in out.rows:
        r["chosen"] = r["sampled"] = r["model"] == out.choice["choice"]
    say(f"[{section}] chosen: {out.choice['choice']}: {out.choice['reason']}")
    return out


def screen_maps(
    rungs: Sequence[tuple[str, str | None, Callable]],
    section: str,
    *,
    seed: int,
    optimizer,
    deadline: float | None = None,
    say: Callable[[str], None] | None = None,
    guarded: bool = True,
) -> tuple[list[dict], dict]:
    """The MAP screen's loop, shared by ``model: auto`` (:func:`screen`) and ``hbayes
    compare``: each rung's MAP and its ladder row, in turn.

    Parameters
    ----------
    rungs : sequence of (label, parent, build)
        ``build()`` returns (prepared data, model, log-posterior) of the rung; ``parent``
        is the label of its nested simpler rung (or None), whose MAP, when found
        before, is carried over as one start of the search (:func:`carried_start`).
        One global search per rung: the carried start puts the richer rung's search
        where the simpler one ended; where the polished starts end more than
        :data:`SPREAD_LOGPOST` apart, :func:`restart_guard` runs more searches.
    section : {"thermal", "hygric"}
    seed : int
        Seed of every rung's MAP search.
    optimizer : OptimizerSettings
        ``method``, ``popsize``, ``maxiter`` and ``starts`` of the search.
    deadline : float, optional
        A :func:`time.perf_counter` value: rungs not reached by then are left out
        (recorded as such); the first rung always runs.
    say : callable, optional
        A progress line per rung.
    guarded : bool
        Apply :func:`restart_guard` (default; False measures what it changes).

    Returns
    -------
    rows : list of dict
        Per rung, in order: its ladder row (:func:`heritage_bayes.calibration.ladder.ladder_row`,
        with ``parent``, ``seeded_from``, ``map_seconds`` and ``score``, the FIT
        compared, :func:`row_score`), or ``model`` and ``error`` (why not screened: a
        configuration or data error of the rung, or the time budget).
    found : dict
        label -> (model, log-posterior, MAP) of the rungs screened.
    """
    from heritage_bayes.inference.optimize import BudgetError, find_map

    say = say or (lambda msg: None)
    rows: list[dict] = []
    found: dict = {}
    n = len(rungs)
    for k, (label, parent, build) in enumerate(rungs, 1):
        head = {"model": label, "parent": parent}
        if k > 1 and deadline is not None and time.perf_counter() > deadline:
            rows.append({**head, "error": "not screened: the time budget ran out"})
            continue
        t0 = time.perf_counter()
        try:
            prep, model, lp = build()
            start = None
            if parent in found:
                start = carried_start(lp, found[parent][1], found[parent][2])
            search = dict(
                method=optimizer.method,
                popsize=optimizer.popsize,
                maxiter=optimizer.maxiter,
                starts=optimizer.starts,
                deadline=deadline if k > 1 else None,
            )
            mp = find_map(lp, seed=seed, start=start, **search)
            mp, guard = restart_guard(lp, mp, seed=seed, search=search) if guarded else (mp, None)
            if guard is not None:
                say(f"screen {k}/{n}: {label}: {guard['said']}")
            row = ladder_row(prep, section, model, lp, mp, label=label)
            if guard is not None:
                row["map_guard"] = guard
        except BudgetError:
            rows.append({**head, "error": "not screened: the time budget ran out"})
            continue
        except (ConfigError, InputError) as exc:
            rows.append({**head, "error": f"not screened: {exc}"})
            say(f"screen {k}/{n}: {label}: not screened ({exc})")
            continue
        row.update(parent=parent, seeded_from=parent if start is not None else None)
        row["map_seconds"] = time.perf_counter() - t0
        row["score"] = row_score(row, _period(prep))[0]
        rows.append(row)
        found[label] = (model, lp, mp)
        say(
            f"screen {k}/{n}: {label}: {lp.ndim} free parameters, {_fit_text(row)} "
            f"({row['map_seconds']:.0f} s)"
        )
    return rows, found


#: [log-posterior units] polished starts of one search ending further apart than this
#: found separate optima (one holds e^-10 of the other's mass if as wide: the optimizer's
#: ``MODE_WINDOW``): the search is repeated from other seeds (:func:`restart_guard`).
SPREAD_LOGPOST = 10.0
#: Global searches the guard adds (seeds ``[seed, 1]``, ``[seed, 2]``, ...).
GUARD_SEARCHES = 2


def restart_guard(lp, mp, *, seed: int, search: Mapping) -> tuple:
    """A guard against a local optimum: where the polished starts of a rung's search
    (its population's best points; not the carried start, which often stays on the
    simpler rung's optimum, a saddle of the richer one) end more than
    :data:`SPREAD_LOGPOST` apart, the log-posterior has several optima within reach, so
    :data:`GUARD_SEARCHES` more global searches from other seeds run and the highest
    optimum is kept when it beats the first by more than the optimizer's ``MODE_PICK``.

    Returns
    -------
    (MAPResult, dict or None)
        The MAP kept and, when the guard ran, its record: ``spread`` of the first
        search's starts, the ``log_posteriors`` of the searches (the first first),
        ``moved`` (the MAP kept is another search's) and ``said``, a sentence.
    """
    from heritage_bayes.inference.optimize import MODE_PICK, BudgetError, find_map

    cands = [c for c in mp.candidates if math.isfinite(c)]
    carried = getattr(mp, "carried", None)
    if carried is not None and cands:  # the carried start may rest on the simpler optimum
        cands.remove(min(cands, key=lambda c: abs(c - carried)))
    spread = max(cands) - min(cands) if cands else 0.0
    if spread <= SPREAD_LOGPOST:
        return mp, None
    found = [mp]
    for j in range(1, GUARD_SEARCHES + 1):
        try:
            found.append(find_map(lp, seed=[seed, j], **search))
        except BudgetError:
            break
    best = max(found, key=lambda r: r.log_post)
    keep = best if best.log_post > mp.log_post + MODE_PICK else mp
    lps = [float(r.log_post) for r in found]
    said = (
        f"{len(cands)} starts of its MAP search ended {spread:.0f} log-posterior units apart "
        f"(several optima): {len(found) - 1} more searches from other seeds reached "
        + ", ".join(f"{v:.1f}" for v in lps[1:])
        + f" against {lps[0]:.1f}; "
        + ("the higher optimum is kept" if keep is not mp else "the first optimum stands")
    )
    return keep, {
        "spread": spread,
        "log_posteriors": lps,
        "moved": keep is not mp,
        "said": said,
    }


def unit_point(logpost, values: dict[str, float]) -> np.ndarray:
    """The unit-cube point of the free parameters (the search's coordinates) for the
    values given by name; a parameter not given, or outside its prior range, sits at the
    middle of its range [-]."""
    ps = logpost.params
    out = np.full(ps.ndim, 0.5)
    for j, name in enumerate(ps.free_names):
        v = values.get(name)
        if v is None or not np.isfinite(v) or (ps._log[j] and v <= 0):
            continue
        y = np.log(v) if ps._log[j] else v
        u = (y - ps._a[j]) / ps._w[j]
        if 0.0 < u < 1.0:
            out[j] = u
    return np.clip(out, 0.01, 0.99)


def carried_start(lp, parent_lp, parent_map):
    """A nested simpler model's MAP as a start of ``lp``'s search (the unit-cube point of
    :func:`unit_point`): its parameters by name, one
    node's total conductance as the fast path's; the others at mid-range."""
    values = dict(zip(parent_lp.params.names, map(float, parent_map.theta), strict=True))
    values.update({a: values[b] for a, b in _CARRY.items() if b in values and a not in values})
    return unit_point(lp, values)


def _fit_text(row: Mapping) -> str:
    fit = row.get("fit") or {}
    parts = []
    for period, short in (("calibration", "cal"), ("validation", "val")):
        for o, m in (fit.get(period) or {}).items():
            parts.append(f"FIT {o} {short} {m.get('FIT', math.nan):.1f} %")
    return ", ".join(parts) or "no fit"


def chosen_section(cfg, section: str, scr: Screen):
    """The config with the section's ``model: auto`` replaced by the screen's choice:
    its catalogue name, the configured options (``sink`` the rung's own) and those
    configured priors whose parameters exist in it."""
    name, own = scr.options[scr.choice["choice"]]
    sec = getattr(cfg, section)
    if sec.model != AUTO:
        raise ValueError(f"{section}.model is {sec.model!r}, not {AUTO!r}")
    model = scr.models[scr.choice["choice"]]
    given = {k: v for k, v in sec.options.given().items() if k != "sink"} | own
    options = ModelOptions.model_validate(given)
    priors = owned_priors(sec.priors, model, get_noise_model(sec.noise))
    new = sec.model_copy(update={"model": name, "options": options, "priors": priors})
    return cfg.model_copy(update={section: new})


def _period(prep) -> str:
    """The period whose FIT scores a rung: validation, else calibration."""
    return "validation" if prep.validation is not None else "calibration"
