"""emcee's moves by name, and the schedule and τ estimate of the convergence monitor.

:class:`Mixture` and :func:`register_move` (the ``sampler.moves`` choices, each
registered here with its description beside its moves), :func:`make_moves` (a
choice's emcee moves), :func:`_next_check` (when the monitor estimates τ),
:func:`_tau` (the integrated autocorrelation time per parameter, Goodman & Weare 2010;
Foreman-Mackey et al. 2013) and :class:`ChainBuffer` (the chain in memory while it
grows). Split from :mod:`heritage_bayes.inference.sampler`, which uses them.
"""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass

import emcee
import numpy as np

from heritage_bayes.inference.moves import BlockDEMove, GlobalDEMove
from heritage_bayes.names import MOVES

__all__ = ["MOVES", "ChainBuffer", "Mixture", "make_moves", "register_move"]


@dataclass(frozen=True)
class Mixture:
    """A ``sampler.moves`` choice: emcee moves, each taking a share of the steps.

    Attributes
    ----------
    name : str
        The name ``sampler.moves`` chooses.
    description : str
        One line for the references and the settings' description.
    parts : tuple of (callable, float)
        Per move, what builds it (an :class:`emcee.moves.Move` class, or any callable
        returning a move) and its share of the steps; the shares sum to 1.
    """

    name: str
    description: str
    parts: tuple[tuple[Callable[[], emcee.moves.Move], float], ...]

    def build(self, share: float = 1.0) -> list[tuple[emcee.moves.Move, float]]:
        """Fresh moves, as emcee's ``[(move, weight), ...]``, their weights scaled to sum
        to ``share``."""
        return [(make(), w * share) for make, w in self.parts]


def register_move(
    name: str, description: str, *parts: tuple[Callable[[], emcee.moves.Move], float]
) -> Mixture:
    """Register a ``sampler.moves`` choice: the one place a move mixture is listed. The
    settings' validation and description of ``sampler.moves``, the references and
    :func:`make_moves` read :data:`heritage_bayes.names.MOVES`, which this fills.

    Parameters
    ----------
    name : str
        A lowercase identifier, not yet taken.
    description : str
        What the mixture is, in one line.
    *parts : (callable, float)
        Per move, what builds it (no arguments) and its share of the steps.

    Raises
    ------
    ValueError
        The name is taken or not a lowercase identifier, the description is empty, or
        the shares are not positive or do not sum to 1.
    """
    shares = [w for _, w in parts]
    if not description or not shares or min(shares) <= 0 or not math.isclose(sum(shares), 1):
        raise ValueError(
            f"sampler move {name!r}: a description and moves whose positive shares sum "
            f"to 1 are required (got {description!r}, shares {shares})"
        )
    return MOVES.register(name, Mixture(name, description, tuple(parts)))


# The package's mixtures, the default first (emcee's defaults for each move: ``DEMove``
# γ₀ = 2.38 / √(2 d), ``DESnookerMove`` γ = 1.7, ``StretchMove`` a = 2).
register_move(
    "de_snooker",
    "differential evolution 80 %, snooker 20 %",
    (emcee.moves.DEMove, 0.8),
    (emcee.moves.DESnookerMove, 0.2),
)
register_move(
    "de_snooker_50",
    "differential evolution 50 %, snooker 50 %",
    (emcee.moves.DEMove, 0.5),
    (emcee.moves.DESnookerMove, 0.5),
)
register_move("de", "differential evolution", (emcee.moves.DEMove, 1.0))
register_move("stretch", "the affine-invariant stretch move", (emcee.moves.StretchMove, 1.0))
# DE with global independence proposals (heritage_bayes.inference.moves)
register_move(
    "de_global",
    "de_snooker whose DE part is replaced, for a walker in ten, by an independent draw "
    "from a Student-t fitted to the chain so far",
    (GlobalDEMove, 0.8),
    (emcee.moves.DESnookerMove, 0.2),
)
register_move("dime", "DE with those independent draws, no snooker", (GlobalDEMove, 1.0))


def make_moves(name: str, block=(), block_weight: float = 0.0):
    """emcee moves by name (:data:`MOVES`: ``de_snooker`` (default), ``de_snooker_50``,
    ``de``, ``stretch``, ``de_global``, ``dime`` and any registered with
    :func:`register_move`), as emcee's ``[(move, weight), ...]``.

    With a non-empty ``block`` (coordinate indices) and ``block_weight`` > 0, a
    :class:`~heritage_bayes.inference.moves.BlockDEMove` on those coordinates takes that
    share of the steps and the named moves the rest in their proportions; otherwise the
    list is the named moves alone (the same chain as before the block move existed).

    The snooker move alone is not offered: from the start ball (walkers 1e-3 apart) it
    does not spread the ensemble (docs/science/benchmarks.md, "Figures behind the code's
    choices"), its proposals lie along lines through other walkers."""
    if name not in MOVES:
        raise ValueError(f"sampler.moves must be one of {list(MOVES)} (got {name!r})")
    if not 0.0 <= block_weight < 1.0:
        raise ValueError(f"sampler.block_weight must lie in [0, 1) (got {block_weight})")
    if len(block) == 0 or block_weight == 0.0:
        return MOVES[name].build()
    return [*MOVES[name].build(1.0 - block_weight), (BlockDEMove(block), block_weight)]


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


def _last_check(done: int, check_every: int) -> int:
    """The last convergence check at or before step ``done`` (0 before the first): the
    schedule of :func:`_next_check`."""
    last = 0
    while (b := _next_check(last, check_every)) <= done:
        last = b
    return last


def _tau(chain: np.ndarray, discard: float = 0.0) -> np.ndarray:
    """Integrated autocorrelation time per parameter [steps] of ``chain`` (steps,
    walkers, d), estimated on the steps after its first ``discard`` fraction."""
    start = int(discard * chain.shape[0])
    return emcee.autocorr.integrated_time(chain[start:], c=5, tol=0, quiet=True)


class ChainBuffer:
    """The chain (steps, walkers, d) and its log-probabilities, grown chunk by chunk in
    place, and thinned in place once it reaches ``max_rows``.

    The sampler appends a chunk after every convergence check and estimates τ (and
    R-hat) on the whole chain each time; a list of chunks concatenated for each check
    held the chain twice at every check (and three times at the R-hat check). Here the
    rows live in one array whose capacity grows by a quarter at a time (amortised
    copies, at most 25 % slack), and :attr:`chain` is a view of the rows filled
    (memory of a long chain: docs/science/benchmarks.md).

    Bounded (``max_rows``): the buffer holds every ``stride``-th step, the steps ``s``
    (0-based) with ``(s + 1) % stride == 0``; :meth:`halve` keeps every other row and
    doubles ``stride`` (the rows kept are again those of the rule, whatever the chunk
    sizes, so a resumed chain rebuilds the same rows). Who calls :meth:`halve` decides
    when (the sampler: only while the stride stays ≤ τ/10, see
    :func:`heritage_bayes.inference.sampler.run_sampler`). A chain shorter than
    ``max_rows`` steps is held as before, every step.
    """

    def __init__(self, nwalkers: int, d: int, capacity: int = 0, stride: int = 1):
        self._x = np.empty((capacity, nwalkers, d))
        self._lp = np.empty((capacity, nwalkers))
        self.n = 0
        #: steps per stored row
        self.stride = int(stride)
        #: steps appended so far (rows × stride, plus the steps after the last row)
        self.steps = 0

    def _keep(self, k: int) -> slice:
        """Rows of a chunk of ``k`` steps that follow the last appended step to keep."""
        first = (-(self.steps + 1)) % self.stride  # first s >= steps with (s+1) % stride == 0
        return slice(first, k, self.stride)

    def append(self, x: np.ndarray, lp: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """Add a chunk of consecutive steps, x (k, walkers, d) and lp (k, walkers);
        returns the rows kept (all of them at stride 1)."""
        keep = self._keep(x.shape[0])
        self.steps += x.shape[0]
        x, lp = x[keep], lp[keep]
        k = x.shape[0]
        if self.n + k > self._x.shape[0]:
            cap = max(self.n + k, int(1.25 * self._x.shape[0]))
            for name in ("_x", "_lp"):
                old = getattr(self, name)
                new = np.empty((cap, *old.shape[1:]), dtype=old.dtype)
                new[: self.n] = old[: self.n]
                setattr(self, name, new)
        self._x[self.n : self.n + k] = x
        self._lp[self.n : self.n + k] = lp
        self.n += k
        return x, lp

    def load(self, x: np.ndarray, lp: np.ndarray, steps: int) -> None:
        """Set the rows of a saved chain held at this buffer's ``stride`` (``steps``
        steps long: the rows of the rule, :meth:`append`'s docstring)."""
        expect = steps // self.stride
        if x.shape[0] != expect:
            raise ValueError(
                f"a chain of {steps} steps at stride {self.stride} has {expect} rows "
                f"(got {x.shape[0]})"
            )
        self._x, self._lp = np.array(x, dtype=float), np.array(lp, dtype=float)
        self.n, self.steps = x.shape[0], int(steps)

    def halve(self) -> None:
        """Keep every other row (the steps of the doubled stride) and double ``stride``."""
        self.stride *= 2
        keep = slice(1, self.n, 2)
        m = len(range(*keep.indices(self.n)))
        self._x[:m] = self._x[keep]
        self._lp[:m] = self._lp[keep]
        self.n = m

    @property
    def chain(self) -> np.ndarray:
        """(rows, walkers, d) view of the rows filled."""
        return self._x[: self.n]

    @property
    def log_prob(self) -> np.ndarray:
        """(rows, walkers) view of the rows filled."""
        return self._lp[: self.n]
