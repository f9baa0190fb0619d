"""emcee's moves by name, and the schedule and τ estimate of the convergence monitor.

:data:`MOVES` and :func:`make_moves` (the ``sampler.moves`` key), :func:`_next_check`
(when the monitor estimates τ) and :func:`_tau` (the integrated autocorrelation time
per parameter, Goodman & Weare 2010; Foreman-Mackey et al. 2013). Split from
:mod:`heritage_bayes.inference.sampler`, which uses them.
"""

from __future__ import annotations

import emcee
import numpy as np

#: ``sampler.moves``: name -> [(emcee move class, weight), ...] (emcee's defaults for
#: each move: ``DEMove`` γ₀ = 2.38 / √(2 d), ``DESnookerMove`` γ = 1.7, ``StretchMove``
#: a = 2).
MOVES = {
    "de_snooker": ((emcee.moves.DEMove, 0.8), (emcee.moves.DESnookerMove, 0.2)),
    "de_snooker_50": ((emcee.moves.DEMove, 0.5), (emcee.moves.DESnookerMove, 0.5)),
    "de": ((emcee.moves.DEMove, 1.0),),
    "stretch": ((emcee.moves.StretchMove, 1.0),),
}


def make_moves(name: str):
    """emcee moves by name (:data:`MOVES`): ``de_snooker`` (default), ``de_snooker_50``,
    ``de`` or ``stretch``, as emcee's ``[(move, weight), ...]``.

    The snooker move alone is not offered: from the start ball (walkers 1e-3 apart) it
    does not spread the ensemble (a 3-d Gaussian: posterior sd 0.002 instead of 1 after
    20 000 steps), its proposals lie along lines through other walkers."""
    if name not in MOVES:
        raise ValueError(f"sampler.moves must be one of {sorted(MOVES)} (got {name!r})")
    return [(cls(), w) for cls, w in MOVES[name]]


def _next_check(done: int, check_every: int) -> int:
    """The first convergence check after step ``done``.

    Checks come every ``check_every`` steps, then every 10 % of the chain (in whole
    multiples of ``check_every``), so that the cost of estimating τ on the whole
    chain stays a small fraction of sampling on long runs. The sequence depends only
    on ``check_every``, so a resumed chain checks at the same steps.
    """
    b = 0
    while b <= done:
        b += check_every * max(1, b // (10 * check_every))
    return b


def _tau(chain: np.ndarray, discard: float = 0.0) -> np.ndarray:
    """Integrated autocorrelation time per parameter [steps] of ``chain`` (steps,
    walkers, d), estimated on the steps after its first ``discard`` fraction."""
    start = int(discard * chain.shape[0])
    return emcee.autocorr.integrated_time(chain[start:], c=5, tol=0, quiet=True)
