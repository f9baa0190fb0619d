"""Automatic model selection: a MAP and validation-score screen of the model ladder.

``model: auto`` in a config section (and ``hbayes compare``'s first step) screens the
rungs of :data:`heritage_bayes.models.AUTO_LADDERS`, simplest first: each rung's MAP on
the calibration period (the MAP of its nested simpler rung carried over as one of the
starts of the search, :func:`unit_point`), then the
simulation from the MAP scored on the validation period by the paper's FIT [%]
(Kramer, van Schijndel & Schellen 2013). A MAP costs seconds where a posterior costs
minutes: only the model chosen is sampled.

**The choice rule** (:func:`choose`): the score is the validation FIT of the section's
output (without a validation period, the calibration FIT after the warm-up). Among the
rungs scored, the simplest (fewest free parameters, then ladder order) whose score is
within :data:`MARGIN_FIT` points of the best is chosen: a richer model must beat a
simpler one by more than the margin to be taken. A rung within the margin of the choice
is its **runner-up** (a tie: the posteriors, ``hbayes compare --models A,B``, weigh them
by ELPD).

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

from heritage_bayes.errors import ConfigError, InputError
from heritage_bayes.inference.likelihoods import get_noise_model
from heritage_bayes.inference.parameters import owned_priors
from heritage_bayes.ladder import ladder_row, rung_log_posterior
from heritage_bayes.models import AUTO, AUTO_LADDERS, auto_rungs, rung_label

__all__ = [
    "MARGIN_FIT",
    "Screen",
    "choose",
    "chosen_section",
    "row_score",
    "screen",
    "screen_maps",
]

#: [percentage points of validation FIT] a richer rung must beat a simpler one by more
#: than this to be chosen; rungs within it of the choice tie with it.
MARGIN_FIT = 2.0

#: A parameter of a simpler rung whose value starts a richer rung's one of another name:
#: one node's total conductance to outdoors is the fast path's first guess.
_CARRY = {"Gfast": "Ge"}


def row_score(row: Mapping, period: str | None = None) -> tuple[float, str]:
    """(score [%], what it is) of a ladder row: the FIT of ``period`` (the mean over the
    outputs); by default the validation FIT where the row has one, else the calibration
    FIT. NaN when the row has none."""
    for p in (period,) if period else ("validation", "calibration"):
        per = (row.get("fit") or {}).get(p) or {}
        vals = [v.get("FIT") for v in per.values() if isinstance(v, Mapping)]
        vals = [float(v) for v in vals if v is not None and math.isfinite(float(v))]
        if vals:
            return sum(vals) / len(vals), f"{p} FIT"
    return math.nan, f"{period or 'no'} FIT"


def choose(rows: Sequence[Mapping], margin: float = MARGIN_FIT) -> dict:
    """The screen's choice among ladder rows (each with ``model``, ``n_params``, ``fit``;
    rows in ladder order): the simplest whose score (:func:`row_score`) is within
    ``margin`` points of the best.

    Returns
    -------
    dict
        ``choice`` (label), ``score`` (what was compared), ``reason`` (a sentence),
        ``best`` (the best-scoring label), ``runner_up`` (the best other rung within
        ``margin`` of the choice, or None) and ``margin``.

    Raises
    ------
    InputError
        No row has a finite score (every rung failed).
    """
    # one period for every row: the validation FIT when any row has one
    has_val = any((r.get("fit") or {}).get("validation") for r in rows)
    period = "validation" if has_val else "calibration"
    scored = [(i, r, *row_score(r, period)) for i, r in enumerate(rows)]
    scored = [t for t in scored if math.isfinite(t[2])]
    if not scored:
        raise InputError("model: auto: no model of the ladder could be fitted and scored")
    what = scored[0][3]
    best = max(scored, key=lambda t: t[2])
    ok = [t for t in scored if t[2] >= best[2] - margin]
    pick = min(ok, key=lambda t: (int(t[1].get("n_params", 0)), t[0]))
    name, s = pick[1]["model"], pick[2]
    if pick is best:
        reason = f"the best {what} of the ladder ({s:.1f} %)"
        simpler = [t for t in scored if t[1].get("n_params", 0) < pick[1].get("n_params", 0)]
        if simpler:
            nxt = max(simpler, key=lambda t: t[2])
            reason += (
                f", more than {margin:g} points above the best simpler model "
                f"({nxt[1]['model']}: {nxt[2]:.1f} %)"
            )
    else:
        reason = (
            f"{what} {s:.1f} %, within {margin:g} points of the best, {best[1]['model']} "
            f"({best[2]:.1f} %), with fewer parameters ({pick[1].get('n_params')} against "
            f"{best[1].get('n_params')}): a richer model must beat it by more than "
            f"{margin:g} points"
        )
    rivals = [t for t in ok if t is not pick]
    runner = max(rivals, key=lambda t: t[2])[1]["model"] if rivals else None
    return {
        "choice": name,
        "score": what,
        "reason": reason,
        "best": best[1]["model"],
        "runner_up": runner,
        "margin": margin,
    }


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
        """The JSON record: ``rule``, ``rows`` and the choice (summary.json, comparison)."""
        return {
            "rule": f"the simplest model whose {self.choice['score']} is within "
            f"{self.choice['margin']:g} points of the best (MAP of each rung; a richer "
            f"model must beat a simpler one by more than {self.choice['margin']:g} points)",
            "rows": self.rows,
            **self.choice,
        }


def screen(
    cfg,
    prep,
    section: str,
    *,
    seed: int,
    deadline: float | None = None,
    say: Callable[[str], None] | None = None,
    margin: float = MARGIN_FIT,
) -> Screen:
    """MAP of every rung of the section's ladder, its validation score and the choice.

    Parameters
    ----------
    cfg : CalibrationConfig
        The section's options, priors, noise model and the optimizer settings.
    prep : PreparedData
        Prepared for the richest rung (``build_model`` of ``model: auto``).
    section : {"thermal", "hygric"}
    seed : int
        Seed of every rung's MAP search.
    deadline : float, optional
        A :func:`time.perf_counter` value: rungs not reached by then are left out
        (recorded as such); the first rung always runs.
    say : callable, optional
        Progress lines.
    margin : float
        :data:`MARGIN_FIT`.
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

    rungs = [(label, parent, build(model)) for label, model, parent in auto_rungs(cfg, section)]
    rows, found = screen_maps(
        rungs,
        section,
        seed=seed,
        optimizer=cfg.optimizer,
        deadline=deadline,
        say=lambda msg: say(f"[{section}] {msg}"),
    )
    out = Screen(section, rows, {})
    for label, (model, lp, mp) in found.items():
        out.models[label], out.logposts[label], out.maps[label] = model, lp, mp
        out.options[label] = own[label]
    out.choice = choose([r for r in out.rows if "error" not in r], margin)
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
) -> tuple[list[dict], dict]:
    """The MAP screen's loop, shared by ``model: auto`` (:func:`screen`) and ``hbayes
    compare``: each rung's MAP and its ladder row, in turn.

    Parameters
    ----------
    rungs : sequence of (label, parent, build)
        ``build()`` returns (prepared data, model, log-posterior) of the rung; ``parent``
        is the label of its nested simpler rung (or None), whose MAP, when found
        before, is carried over as one start of the search (:func:`carried_start`).
        One global search per rung (no restarts): the carried start puts the richer
        rung's search where the simpler one ended.
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

    Returns
    -------
    rows : list of dict
        Per rung, in order: its ladder row (:func:`heritage_bayes.ladder.ladder_row`,
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
            mp = find_map(
                lp,
                seed=seed,
                method=optimizer.method,
                popsize=optimizer.popsize,
                maxiter=optimizer.maxiter,
                starts=optimizer.starts,
                deadline=deadline if k > 1 else None,
                start=start,
            )
            row = ladder_row(prep, section, model, lp, mp, label=label)
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
    options = {k: v for k, v in sec.options.items() if k != "sink"} | own
    priors = owned_priors(sec.priors, model, get_noise_model(sec.noise))
    new = sec.model_copy(update={"model": name, "options": options, "priors": priors})
    return cfg.model_copy(update={section: new})


def _period(prep) -> str:
    """The period whose FIT scores a rung: validation, else calibration."""
    return "validation" if prep.validation is not None else "calibration"
