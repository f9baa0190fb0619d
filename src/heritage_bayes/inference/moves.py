"""Ensemble moves beyond emcee's own: differential evolution within a block of
coordinates (:class:`BlockDEMove`), and differential evolution mixed with global
independence proposals (the idea of DIME, Boehl [1]_), made resume-invariant
(:class:`GlobalDEMove`).

Differential evolution (ter Braak & Vrugt [2]_) moves each walker along the difference
of two others: on a long, curved ridge the steps stay short, and a direction the data
leave to the prior (thermal_4a's interior mass on a room without one) is crossed by a
random walk. :class:`GlobalDEMove` replaces, for each walker with probability
``p_global``, the DE proposal by an independent draw from a multivariate Student-t
fitted to the chain so far; accepted with the Metropolis-Hastings ratio of an
independence sampler, such a draw can land anywhere on the posterior in one step.

Unlike DIME, which updates its proposal distribution after every step from the
current ensemble, the t here is refitted only at the sampler's convergence checks
(:meth:`GlobalDEMove.fit`), from the second half of the chain stored up to that check:
within a chunk of steps the move is a fixed Markov kernel, and a chain resumed after an
interrupt refits from the same rows (the checks fall at fixed step counts), so it
continues bit for bit. The refits change less and less as the chain grows (diminishing
adaptation, Roberts & Rosenthal [3]_).

References
----------
.. [1] G. Boehl, "Ensemble MCMC sampling for robust Bayesian inference", SSRN 4250395
   (2022); the DIME move of the ``dime_sampler`` package.
.. [2] C. J. F. ter Braak and J. A. Vrugt, "Differential evolution Markov chain with
   snooker updater and fewer chains", Statistics and Computing 18 (2008) 435-446.
.. [3] G. O. Roberts and J. S. Rosenthal, "Coupling and ergodicity of adaptive Markov
   chain Monte Carlo algorithms", J. Appl. Probab. 44 (2007) 458-475.
.. [4] J. A. Vrugt, C. J. F. ter Braak, C. G. H. Diks, B. A. Robinson, J. M. Hyman,
   D. Higdon, "Accelerating Markov chain Monte Carlo simulation by differential
   evolution with self-adaptive randomized subspace sampling", Int. J. Nonlinear Sci.
   Numer. Simul. 10 (2009) 273-290 (DREAM: DE proposals on a subset of the coordinates).
"""

from __future__ import annotations

import emcee
import numpy as np

__all__ = [
    "BlockDEMove",
    "GlobalDEMove",
    "refit_moves",
    "unidentified_block",
]

#: at most this many points (walkers × rows) enter a fit of the global proposal
MAX_FIT_POINTS = 8000


class BlockDEMove(emcee.moves.DEMove):
    """Differential evolution restricted to a block of coordinates: each walker moves
    along the difference of two others in those coordinates only, the rest unchanged.

    Meant for the parameters the data leave to their priors (thermal_4a's interior mass
    ``Cint``, ``Gint`` and ``fsol`` on a room without one): along them the posterior is
    wide and nearly independent of the identified parameters, but a full DE step also
    moves the identified ones, along narrow curved ridges, and is rejected most of the
    time (the acceptance: docs/science/benchmarks.md, "Sampler moves, ensemble size and
    the estimate of τ"), so the wide directions are crossed by a random walk of short
    steps. A step within the block leaves the identified parameters where they are (a
    Metropolis-within-Gibbs update; DE proposals on a subspace as in DREAM [4]_), with
    DE's scale for the block's dimension, γ₀ = 2.38 / √(2 k) for k coordinates.

    The proposal is symmetric (the pair of walkers and the block do not depend on the
    walker's position; the reverse step takes the same pair in the other order), so it
    leaves the posterior invariant as emcee's ``DEMove`` does. Independent draws of the
    block from a Student-t fitted to the chain (as :class:`GlobalDEMove` makes for all
    coordinates) were tried and made the chain slower (docs/science/benchmarks.md, "A
    block move"): a t fitted to an L-shaped region holds walkers in the region's arms.

    Parameters
    ----------
    block : sequence of int
        Indices of the coordinates to move (emcee's coordinates: where a network is
        sampled along node time constants, a capacity's index holds its node's log time
        constant).
    **kwargs
        Passed to :class:`emcee.moves.DEMove` (``sigma``; ``gamma0`` defaults as above).
    """

    def __init__(self, block, **kwargs):
        self.block = np.unique(np.asarray(block, dtype=int))
        if self.block.size == 0:
            raise ValueError("BlockDEMove: the block holds no coordinate")
        kwargs.setdefault("gamma0", 2.38 / np.sqrt(2 * self.block.size))
        super().__init__(**kwargs)

    def get_proposal(self, s, c, random):
        # emcee's DE proposal (its pair of walkers and γ, the same random draws), kept
        # in the block's coordinates only
        full, factors = super().get_proposal(s, c, random)
        q = np.array(s, dtype=float, copy=True)
        q[:, self.block] = full[:, self.block]
        return q, factors


class GlobalDEMove(emcee.moves.DEMove):
    """Differential evolution with, per walker and step, probability ``p_global`` of an
    independence proposal from a multivariate Student-t fitted to the chain.

    Parameters
    ----------
    p_global : float
        Probability that a walker's proposal is the global draw (DIME's default 0.1).
    df : float
        Degrees of freedom of the Student-t (heavier tails than the posterior: DIME's
        default 10).
    **kwargs
        Passed to :class:`emcee.moves.DEMove` (``sigma``, ``gamma0``).

    Notes
    -----
    Before the first :meth:`fit` the move is emcee's ``DEMove``. The t's scale matrix is
    the fitted covariance × (df − 2)/df, so that its covariance is the chain's.
    """

    #: default of ``p_global``
    P_GLOBAL = 0.1

    def __init__(self, p_global: float | None = None, df: float = 10.0, **kwargs):
        p_global = self.P_GLOBAL if p_global is None else p_global
        if not 0.0 <= p_global <= 1.0:
            raise ValueError(f"p_global must lie in [0, 1] (got {p_global})")
        if df <= 2:
            raise ValueError(f"df must exceed 2 (got {df})")
        self.p_global = float(p_global)
        self.df = float(df)
        self.mean: np.ndarray | None = None
        self.chol: np.ndarray | None = None
        super().__init__(**kwargs)

    def fit(self, points: np.ndarray) -> bool:
        """Fit the global proposal to ``points`` (n, d) in the sampler's coordinates;
        False (and the move stays as it was) when they do not define a proper t."""
        points = np.asarray(points, dtype=float)
        n, d = points.shape
        if n <= d or not np.all(np.isfinite(points)):
            return False
        mean = points.mean(axis=0)
        cov = np.cov(points, rowvar=False).reshape(d, d) * (self.df - 2.0) / self.df
        if not np.all(np.diag(cov) > 0):  # a coordinate that never moved
            return False
        cov = cov + 1e-12 * np.diag(np.diag(cov))
        try:
            chol = np.linalg.cholesky(cov)
        except np.linalg.LinAlgError:
            return False
        self.mean, self.chol = mean, chol
        return True

    def _log_q(self, x: np.ndarray) -> np.ndarray:
        """log density of the t at rows of ``x``, up to a constant."""
        from scipy.linalg import solve_triangular

        z = solve_triangular(self.chol, (x - self.mean).T, lower=True)
        m = np.sum(z * z, axis=0)
        return -0.5 * (self.df + x.shape[1]) * np.log1p(m / self.df)

    def get_proposal(self, s, c, random):
        q, factors = super().get_proposal(s, c, random)
        if self.mean is None or self.p_global == 0.0:
            return q, factors
        ns, d = s.shape
        pick = random.rand(ns) < self.p_global
        k = int(pick.sum())
        if k == 0:
            return q, factors
        z = random.randn(k, d)
        w = random.chisquare(self.df, size=k) / self.df
        new = self.mean + (z @ self.chol.T) / np.sqrt(w)[:, None]
        q = q.copy()
        q[pick] = new
        factors = factors.copy()
        factors[pick] = self._log_q(s[pick]) - self._log_q(new)
        return q, factors


def refit_moves(moves, chain: np.ndarray, to_y=None) -> None:
    """Refit every :class:`GlobalDEMove` among emcee's ``[(move, weight), ...]`` to the
    second half of ``chain`` (rows, walkers, d), its rows thinned evenly to at most
    :data:`MAX_FIT_POINTS` points and mapped by ``to_y`` (n, d) -> (n, d) into the
    sampler's coordinates (None: already there). A deterministic function of the rows,
    so a resumed chain refits identically."""
    movers = [m for m, _ in moves if isinstance(m, GlobalDEMove)]
    if not movers or chain.shape[0] < 2:
        return
    rows = chain[chain.shape[0] // 2 :]
    step = max(1, int(np.ceil(rows.shape[0] * rows.shape[1] / MAX_FIT_POINTS)))
    pts = rows[::step].reshape(-1, rows.shape[2])
    if to_y is not None:
        pts = to_y(pts)
    for m in movers:
        m.fit(pts)


def unidentified_block(logpost, laplace) -> list[int]:
    """Free-parameter indices of what the Laplace check flags as practically not
    identified (:func:`heritage_bayes.inference.optimize.laplace`'s ``unidentified``):
    the block of :class:`BlockDEMove` in ``hbayes calibrate``. Empty when the check
    found nothing or could not be made (``laplace`` None). A deterministic function of
    the MAP, so a resumed run builds the same moves."""
    if laplace is None:
        return []
    names = list(logpost.params.free_names)
    return [names.index(n) for n in laplace.unidentified if n in names]
