"""Where the walkers start: a dispersed population from the curvature at the MAP.

The default start (:func:`heritage_bayes.inference.sampler.start_ensemble`) puts the
walkers in a ball of 1e-3 around the MAP; the ensemble then spends its first thousands
of steps spreading over the posterior, and that transient enters the estimate of the
integrated autocorrelation time τ on the whole chain (the package's rule) and the
R-hat between walkers. :func:`laplace_ensemble` starts them instead from the Laplace
approximation N(x_MAP, H⁻¹) of the posterior in the sampler's coordinates (H the
Hessian of the negative log-posterior at the MAP, :func:`heritage_bayes.inference.
optimize.laplace`), i.e. already spread along the directions and to the widths the data
allow: an over-dispersed start in the sense of Gelman & Rubin [1]_ along a curved
ridge (the Gaussian is the ridge's tangent), the start Foreman-Mackey et al. [2]_
recommend (walkers from a sensible approximation of the posterior, not a point).

Directions of zero or negative curvature (a scale ridge only a prior closes, a MAP on a
bound) get at most the widest prior range (the floor of
:func:`heritage_bayes.inference.optimize.affine_coordinates`); draws are reflected off
the prior's bounds, and draws whose log-posterior is not finite (a wall the bounds do
not describe, e.g. an unstable network) are redrawn with the covariance halved each
round, ending in the MAP's 1e-3 ball if nothing else is finite.

An option (``sampler.start: laplace`` or ``auto``), not the default: where the data
leave parameters to the priors, walkers drawn over those flat directions can converge
later than the ball's (measured, with the commands: docs/science/benchmarks.md, "Where
the demo's thermal_4a spends its steps").

References
----------
.. [1] A. Gelman, D.B. Rubin, "Inference from iterative simulation using multiple
   sequences", Statist. Sci. 7 (1992) 457-472. doi:10.1214/ss/1177011136
.. [2] D. Foreman-Mackey, D.W. Hogg, D. Lang, J. Goodman, "emcee: The MCMC Hammer",
   PASP 125 (2013) 306, section 5. doi:10.1086/670067
"""

from __future__ import annotations

import numpy as np

# ``sampler.start: auto`` starts from the Laplace approximation the networks that are
# sampled along node time constants by default: at least this many capacity nodes
from heritage_bayes.inference.coordinates import MIN_NODES

__all__ = ["laplace_ensemble", "laplace_factor", "start_hessian"]


def start_hessian(logpost, lap, choice: str = "auto") -> np.ndarray | None:
    """The Hessian the walkers start from for ``sampler.start`` (None: the ball).

    ``"ball"``: None; ``"laplace"``: ``lap.hessian`` (None when the Laplace approximation
    could not be taken, ``lap`` None); ``"auto"``: as ``"laplace"`` for networks of
    :data:`~heritage_bayes.inference.coordinates.MIN_NODES` or more
    capacity nodes, the ball for smaller ones.

    Chosen by measured τ (docs/science/benchmarks.md, "Where the demo's thermal_4a
    spends its steps"). The two-node models keep the ball (their chains, which the
    statistical tests pin, unchanged). The default of ``sampler.start`` is ``"ball"``
    (see the module docstring).
    """
    if choice not in ("auto", "ball", "laplace"):
        raise ValueError(f"sampler.start must be 'auto', 'ball' or 'laplace' (got {choice!r})")
    if choice == "ball" or lap is None:
        return None
    if choice == "auto" and logpost.model.n_states < MIN_NODES:
        return None
    return lap.hessian


def laplace_factor(hessian: np.ndarray, bounds: tuple[np.ndarray, np.ndarray]) -> np.ndarray:
    """A square root L (L Lᵀ = Σ) of the Laplace covariance H⁻¹ [sampler units²].

    Eigenvalues of H below 1 / (widest prior range)² are raised to it: along a flat or
    negatively curved direction the start spreads at most over the widest prior range
    (log range for log-scale priors, 4 logit units for logit ones, 4 for unbounded).

    Parameters
    ----------
    hessian : (d, d) array
        Of the negative log-posterior at the MAP, in the sampler's coordinates.
    bounds : (lo, hi) arrays of shape (d,)
        The prior's support in the same coordinates (±inf where unbounded).
    """
    lo, hi = (np.asarray(b, dtype=float) for b in bounds)
    width = np.where(np.isfinite(hi - lo), hi - lo, 4.0)
    H = 0.5 * (np.asarray(hessian, dtype=float) + np.asarray(hessian, dtype=float).T)
    if not np.all(np.isfinite(H)):
        raise ValueError("the Hessian at the MAP is not finite")
    w, V = np.linalg.eigh(H)
    floor = 1.0 / float(np.max(width)) ** 2
    return V * (1.0 / np.sqrt(np.maximum(w, floor)))


def laplace_ensemble(
    logpost,
    x_map: np.ndarray,
    hessian: np.ndarray,
    nwalkers: int,
    rng: np.random.Generator,
    *,
    bounds: tuple[np.ndarray, np.ndarray],
    rounds: int = 12,
) -> tuple[np.ndarray, np.ndarray] | None:
    """Walkers drawn from N(x_MAP, H⁻¹) inside the support, all with a finite log-posterior.

    Parameters
    ----------
    logpost : callable
        Vectorised log-posterior on (K, d) in the sampler's coordinates.
    x_map : (d,) array
        The MAP (or the point the Hessian was taken at).
    hessian : (d, d) array
        Of the negative log-posterior there (:class:`~heritage_bayes.inference.optimize.
        LaplaceResult` ``.hessian``).
    nwalkers : int
    rng : numpy Generator
        Seeds the draws: same seed, same start.
    bounds : (lo, hi) arrays of shape (d,)
    rounds : int
        Redraws of the walkers whose log-posterior is not finite, the covariance
        halved each round.

    Returns
    -------
    (p0 (nwalkers, d), lp0 (nwalkers,)) or None
        None when walkers are still not finite after ``rounds`` redraws (the caller
        falls back to the ball around the MAP).
    """
    x_map = np.asarray(x_map, dtype=float)
    d = x_map.size
    lo, hi = (np.asarray(b, dtype=float) for b in bounds)
    L = laplace_factor(hessian, (lo, hi))
    width = hi - lo
    pad = np.where(np.isfinite(width), 1e-6 * width, 0.0)

    def draw(k: int, shrink: float) -> np.ndarray:
        p = x_map + shrink * rng.standard_normal((k, d)) @ L.T
        for _ in range(4):  # reflect off the walls
            p = np.where(p < lo, 2 * lo - p, p)
            p = np.where(p > hi, 2 * hi - p, p)
        return np.clip(p, lo + pad, hi - pad)

    p0 = draw(nwalkers, 1.0)
    lp0 = np.asarray(logpost(p0), dtype=float)
    shrink = 1.0
    for _ in range(rounds):
        bad = ~np.isfinite(lp0)
        if not bad.any():
            return p0, lp0
        shrink *= 0.5
        p0[bad] = draw(int(bad.sum()), shrink)
        lp0[bad] = logpost(p0[bad])
    return (p0, lp0) if np.all(np.isfinite(lp0)) else None
