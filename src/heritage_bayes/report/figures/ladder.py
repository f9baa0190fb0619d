"""The model-order ladder: accuracy vs number of parameters and identifiability (section 6)."""

from __future__ import annotations

from collections.abc import Mapping, Sequence

import numpy as np

from heritage_bayes.report.figures.style import (
    C_ALT,
    C_MODEL,
    _figure,
    tex_safe,
)
from heritage_bayes.rundir.summary import LadderRow


def fig_ladder(ladder: Mapping[str, Sequence[LadderRow]]):
    """Accuracy vs identifiability of the model ladder (MAP fits): ``ladder`` is
    section -> its rows (:attr:`heritage_bayes.rundir.summary.RunSummary.ladder`).

    Left: validation (filled) and calibration (open) FIT against the number of model
    parameters; right: validation FIT against the condition number of the identifiable
    part (log scale), labelled with the number of non-identifiable directions.
    """
    fig = _figure(11, 3.9)
    a0, a1 = fig.subplots(1, 2)
    colours = [C_MODEL, C_ALT, "#2e8b57", "#8e44ad"]
    for (domain, rows), c in zip(ladder.items(), colours, strict=False):
        xs, fc, fv, cond, lab, nn = [], [], [], [], [], []
        for r in rows:
            xs.append(_num(r.n_params if r.n_model_params is None else r.n_model_params))
            fc.append(_first_fit(r, "calibration"))
            fv.append(_first_fit(r, "validation"))
            cond.append(_num(r.condition_number_identifiable))
            lab.append(tex_safe(r.model) + (" *" if r.sampled else ""))
            nn.append(r.n_null)
        xs = np.asarray(xs, dtype=float)
        a0.plot(xs, fv, "o-", color=c, label=f"{tex_safe(domain)}: validation")
        a0.plot(xs, fc, "o--", mfc="white", color=c, label=f"{tex_safe(domain)}: calibration")
        for x, y, t in zip(xs, fv, lab, strict=True):
            if np.isfinite(x) and np.isfinite(y):
                a0.annotate(t, (x, y), textcoords="offset points", xytext=(4, 4), fontsize=7)
        ok = np.isfinite(cond) & np.isfinite(fv)
        a1.plot(np.asarray(cond)[ok], np.asarray(fv)[ok], "o", color=c, label=f"{tex_safe(domain)}")
        for x, y, t, k in zip(cond, fv, lab, nn, strict=True):
            if np.isfinite(x) and np.isfinite(y):
                a1.annotate(
                    f"{t} ({k} null)", (x, y), textcoords="offset points", xytext=(4, 4), fontsize=7
                )
    a0.set_xlabel("number of model parameters [-]")
    a0.set_ylabel("FIT [%]")
    a0.set_title("accuracy vs model order (MAP)")
    a0.legend(loc="lower right")
    a1.set_xscale("log")
    a1.set_xlabel("condition number of the identifiable part [-]")
    a1.set_ylabel("validation FIT [%]")
    a1.set_title("accuracy vs identifiability (* = calibrated here)")
    a1.legend(loc="lower right")
    return fig


def _first_fit(row: LadderRow, period: str) -> float:
    """FIT [%] of a ladder row's period (its first output's)."""
    first = next(iter(row.fits(period).values()), None)
    return _num(None if first is None else first.FIT)


def _num(v) -> float:
    try:
        return float(v)
    except (TypeError, ValueError):
        return float("nan")
