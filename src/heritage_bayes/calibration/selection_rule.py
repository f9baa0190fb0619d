"""The selection rule of ``model: auto`` and ``hbayes compare``: the screen's choice and
the ELPD on its tie.

Pure functions of the screen's rows (each rung's MAP validation FIT and size) and, in
``hbayes compare``, of the sampled candidates' ELPD: :func:`choose` is the screen's
choice, :func:`decide` the whole rule. The screen itself (the MAP searches) is
:mod:`heritage_bayes.calibration.selection`, which documents the rule and why FIT on validation.

References
----------
.. [1] R. Kramer, J. van Schijndel, H. Schellen, "Inverse modeling of simplified
   hygrothermal building models to predict and characterize indoor climates", Building
   and Environment 68 (2013) 87-99, doi:10.1016/j.buildenv.2013.06.019.
.. [2] T. Sivula, M. Magnusson, A. Vehtari, "Uncertainty in Bayesian leave-one-out
   cross-validation based model comparison", arXiv:2008.10296 (2020).
.. [3] A. Vehtari, D. Simpson, A. Gelman, Y. Yao, J. Gabry, "Pareto smoothed importance
   sampling", Journal of Machine Learning Research 25 (2024) 1-58.
"""

from __future__ import annotations

import math
from collections.abc import Mapping, Sequence

from heritage_bayes.errors import InputError

__all__ = [
    "MARGIN_FIT",
    "NEGLIGIBLE_ELPD",
    "PARETO_K_MAX",
    "choose",
    "decide",
    "row_score",
    "rule_text",
]

#: [percentage points of validation FIT] a richer rung must beat a simpler one by more
#: than this to be chosen; rungs within it of the choice tie with it.
MARGIN_FIT = 2.0


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
        ``best`` (the best-scoring label), ``tied`` (the other rungs within ``margin``
        of the best, best first), ``runner_up`` (the first of them, or None),
        ``scores`` and ``n_params`` (label -> value, the rungs scored) and ``margin``.

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
    rivals = sorted((t for t in ok if t is not pick), key=lambda t: -t[2])
    return {
        "choice": name,
        "score": what,
        "reason": reason,
        "best": best[1]["model"],
        "runner_up": rivals[0][1]["model"] if rivals else None,
        "tied": [t[1]["model"] for t in rivals],
        "scores": {t[1]["model"]: t[2] for t in scored},
        "n_params": {t[1]["model"]: int(t[1].get("n_params", 0)) for t in scored},
        "margin": margin,
    }


#: [nats] ELPD differences smaller than this are negligible whatever their SE (two
#: nearly identical models have a tiny SE of their difference); Sivula et al. (2020).
NEGLIGIBLE_ELPD = 4.0
#: Pareto k above which a PSIS-LOO estimate is not reliable (Vehtari et al. 2024).
PARETO_K_MAX = 0.7


def rule_text(score: str = "validation FIT", margin: float = MARGIN_FIT) -> str:
    """The selection rule in words, as the run, the report and the comparison state it."""
    return (
        f"each model's MAP scored by the {score} of its simulation; the simplest within "
        f"{margin:g} points of the best is chosen, and the others within {margin:g} points "
        "of the best tie with it. `hbayes compare` samples the choice and its best tied "
        "rival: their ELPD breaks the tie only when it is reliable (both chains converged; "
        f"for a blocked LOO, Pareto k at most {PARETO_K_MAX:g}) and the rival is ahead by "
        f"more than 2 SE and {NEGLIGIBLE_ELPD:g} nats; otherwise the screen's choice stands"
    )


def decide(
    rows: Sequence[Mapping],
    posteriors: Mapping[str, Mapping] | None = None,
    *,
    score: str = "validation ELPD",
    margin: float = MARGIN_FIT,
) -> dict:
    """The one selection rule of ``model: auto`` and ``hbayes compare``.

    First the screen (:func:`choose`): the simplest rung within ``margin`` FIT points of
    the best; the other rungs within the margin tie with it. Then, given posteriors of
    sampled candidates (``hbayes compare``), the ELPD may break a tie: a tied rival is
    taken when its ELPD beats the screen's choice by more than 2 SE of the difference
    and :data:`NEGLIGIBLE_ELPD`, and only when that is reliable (both chains converged;
    with ``score`` a blocked LOO, Pareto k at most :data:`PARETO_K_MAX`). Outside a tie
    the screen decides: a FIT difference beyond the margin is a difference of the
    simulation the report and projections use, where the ELPD scores each hour predicted
    from the previous hour's residual (the noise model); where the ELPD ranks a candidate
    outside the tie above the recommendation, the record says so.

    Parameters
    ----------
    rows : sequence of dict
        The screen's ladder rows (:func:`choose`).
    posteriors : mapping label -> dict, optional
        Per sampled candidate: ``elpd`` [nats], ``se`` (label -> SE of the pointwise
        difference to that candidate [nats]), ``converged`` (bool) and ``max_pareto_k``
        (of its blocked LOO, or None). None: the screen alone (``model: auto``).
    score : str
        The ELPD's name in the sentences: ``"validation ELPD"`` or ``"blocked LOO
        ELPD"`` (whose Pareto k counts).
    margin : float
        :data:`MARGIN_FIT`.

    Returns
    -------
    dict
        :func:`choose`'s keys, and ``model`` (the recommendation), ``decided_by``
        (``"screen"`` or ``"ELPD"``), ``tie`` (a sentence on the tie, or None) and
        ``posterior`` (None, or the ELPD stage: ``verdict``, ``reason``, ``rivals``,
        ``notes``).
    """
    sel = choose(rows, margin)
    out = {**sel, "model": sel["choice"], "decided_by": "screen", "posterior": None, "tie": None}
    if sel["tied"]:
        out["tie"] = (
            f"{', '.join(sel['tied'])} {'ties' if len(sel['tied']) == 1 else 'tie'} with it "
            f"(within {margin:g} points of the best): `hbayes compare` samples it and "
            f"{sel['runner_up']} and lets their ELPD break the tie where it is reliable"
        )
    if posteriors is not None:
        out["posterior"] = stage = _elpd_stage(sel, posteriors, score)
        out["model"], out["decided_by"] = stage.pop("model"), stage.pop("decided_by")
    return out


def _elpd_stage(sel: Mapping, post: Mapping[str, Mapping], score: str) -> dict:
    """:func:`decide`'s second step: the ELPD of the sampled candidates on the screen's
    tie (``sel``: :func:`choose`'s result)."""
    c, n, fit = sel["choice"], sel["n_params"], sel["scores"]
    elpd = {m: float(p["elpd"]) for m, p in post.items()}

    def se(a: str, b: str) -> float:
        v = (post[a].get("se") or {}).get(b)
        v = (post[b].get("se") or {}).get(a) if v is None else v
        return float(v) if v is not None and math.isfinite(v) else 0.0

    def beats(a: str, b: str) -> bool:
        return elpd[a] - elpd[b] > max(2.0 * se(a, b), NEGLIGIBLE_ELPD)

    def diff(a: str, b: str) -> str:
        return f"{elpd[a] - elpd[b]:+.1f} ± {se(a, b):.1f} nats"

    def unreliable(m: str) -> list[str]:
        why = [] if post[m].get("converged") is True else [f"{m}'s chain did not converge"]
        k = post[m].get("max_pareto_k")
        if "LOO" in score and k is not None and k > PARETO_K_MAX:
            why.append(f"{m}'s Pareto k {k:.2f} > {PARETO_K_MAX:g}")
        return why

    def on_screen(m: str) -> str:
        return f"MAP {sel['score']} {fit[m]:.1f} against {fit[c]:.1f} %"

    stage: dict = {"model": c, "decided_by": "screen", "score": score, "notes": []}
    if c not in post:
        return stage | {"verdict": "not sampled", "rivals": [], "reason": f"{c} not sampled"}
    rivals = [m for m in sel["tied"] if m in post]
    stage["rivals"] = rivals
    ahead = [m for m in rivals if beats(m, c)]
    if not rivals:
        stage["verdict"] = "no tie"
        stage["reason"] = f"no sampled rival ties with {c} on the screen, so the screen decides" + (
            " ("
            + "; ".join(f"{score} of {m}: {diff(m, c)} against it" for m in post if m != c)
            + ")"
            if len(post) > 1
            else ""
        )
    elif not ahead:
        stage["verdict"] = "not separated"
        stage["reason"] = (
            "; ".join(
                f"{m} ties with {c} on the screen ({on_screen(m)}) and its {score} "
                + (
                    f"is lower ({diff(m, c)})"
                    if beats(c, m)
                    else f"does not separate them ({diff(m, c)}, within 2 SE or "
                    f"{NEGLIGIBLE_ELPD:g} nats)"
                )
                for m in rivals
            )
            + f": the simpler {c} stands"
        )
    else:
        top = max(ahead, key=elpd.__getitem__)
        pick = min((m for m in ahead if not beats(top, m)), key=lambda m: (n.get(m, 0), -elpd[m]))
        head = (
            f"{pick} ties with {c} on the screen ({on_screen(pick)}) and its {score} is "
            f"higher ({diff(pick, c)}: more than 2 SE and {NEGLIGIBLE_ELPD:g} nats)"
        )
        why = unreliable(c) + unreliable(pick)
        if why:
            stage["verdict"] = "not reliable"
            stage["reason"] = (
                f"{head}, but that is not reliable ({'; '.join(why)}): the screen's choice "
                f"{c} stands, as `model: auto` chooses; longer chains (sampler.max_time) "
                "let the ELPD decide"
            )
        else:
            stage.update(model=pick, decided_by="ELPD", verdict="ELPD breaks the tie")
            stage["reason"] = (
                f"{head}, and reliable (both chains converged"
                + (f", Pareto k at most {PARETO_K_MAX:g}" if "LOO" in score else "")
                + f"): the ELPD breaks the tie, so {pick}, where `model: auto` (the "
                f"screen alone) samples {c}"
            )
    rec = stage["model"]
    best_fit = max(fit.values())
    for m in post:
        if m != rec and m not in rivals and m != c and beats(m, rec):
            stage["notes"].append(
                f"the {score} ranks {m} above {rec} ({diff(m, rec)}), but its MAP "
                f"{sel['score']} is {best_fit - fit.get(m, math.nan):.1f} points below the "
                f"best, outside the {sel['margin']:g}-point tie: the fit of the simulation, "
                f"which the report and projections use, decides there; the {score} scores "
                "each hour predicted from the previous hour's residual (the noise model)"
            )
    return stage
