"""A tempered likelihood: intervals as wide as the slow misfit the noise model leaves.

A noise model that is right leaves one-step innovations that are white. On data the
RC model did not generate (input errors of a sky model, weather between the hourly
readings, a slow boundary the model lumps), the innovations keep a slow correlation
that the noise model cannot describe (``ar1_white``'s error is capped at a day, see
:mod:`heritage_bayes.inference.likelihoods`), and the posterior treats hours that
share one slow error as independent evidence: too narrow along the slow directions
(the slowest time constant, the static gains, the split between outdoor air and a
fixed node). The likelihood is then tempered,

.. math::

    \\log p(\\theta \\mid y) = \\log p(\\theta) + \\log L(\\theta) / \\kappa,

with :math:`\\kappa` the ratio of the long-run variance of the standardised
innovations at the MAP to their variance (Newey & West [1]_, Bartlett window of
``bandwidth`` steps), at least 1: the number of hours that count as one independent
observation at low frequency. The posterior of a slowly varying quantity is then
widened by :math:`\\sqrt\\kappa`, the magnitude of a sandwich correction for a
misspecified likelihood (Müller [2]_) along the directions that the slow misfit
affects; a learning rate fixed before the sampling, as in the power posteriors of
Holmes & Walker [3]_. The noise model and the simulation are unchanged: the
simulation still carries the response, the tempering only says how much the data
can tell. White innovations give :math:`\\kappa = 1`: nothing changes.

References
----------
.. [1] W.K. Newey, K.D. West, "A simple, positive semi-definite, heteroskedasticity and
   autocorrelation consistent covariance matrix", *Econometrica* 55 (1987) 703-708.
.. [2] U.K. Müller, "Risk of Bayesian inference in misspecified models, and the
   sandwich covariance matrix", *Econometrica* 81 (2013) 1805-1849.
.. [3] C.C. Holmes, S.G. Walker, "Assigning a value to a power likelihood in a
   general Bayesian model", *Biometrika* 104 (2017) 497-503.
"""

from __future__ import annotations

import numpy as np

from heritage_bayes.inference.likelihoods import ar1_white_innovations

__all__ = [
    "innovations_at",
    "likelihood_temperature",
    "long_run_variance_ratio",
]


def innovations_at(logpost, theta: np.ndarray) -> np.ndarray:
    """(N, n_out) standardised one-step innovations of a log-posterior's noise model
    at parameter values ``theta`` (P,) (NaN where an observation is missing).

    State-space noise (``kalman``): the filter's own one-step predictions. Residual
    noise models: the residual of the simulation from the estimated initial state
    through :func:`ar1_white_innovations`.
    """
    theta = np.atleast_2d(np.asarray(theta, dtype=float))
    if hasattr(logpost, "parts"):  # segments between input gaps: each its own filter
        out = np.full(logpost.observed.shape, np.nan)
        for (a, b), part in zip(logpost.segments, logpost.parts, strict=True):
            out[a:b] = innovations_at(part, theta)
        return out
    if logpost.noise.statespace:
        mean, var = logpost.noise.one_step(logpost, theta)
        return ((logpost.observed - mean[0]) / np.sqrt(var[0])).astype(float)
    tm, tn = logpost.split(theta)
    Y, _ = logpost.simulate(tm, x0=logpost.initial_states(theta))
    resid = logpost.observed - Y[0]
    out = np.empty_like(resid)
    for o in range(resid.shape[1]):
        sigma, phi, w = (float(v[0]) for v in logpost.noise._split(tn, o))
        out[:, o] = ar1_white_innovations(resid[:, o], sigma, phi, w)
    return out


def long_run_variance_ratio(w: np.ndarray, bandwidth: int) -> float:
    """Long-run variance of a series over its variance, Newey-West (Bartlett window).

    .. math::

        \\kappa = 1 + 2\\sum_{l=1}^{L} \\left(1 - \\frac{l}{L+1}\\right)\\rho_l

    with :math:`\\rho_l` the lag-``l`` autocorrelation over the pairs both present
    (a series with gaps) and :math:`L` = ``bandwidth`` [steps]. 1 for a white series;
    the factor by which the variance of a mean over a long stretch exceeds the iid
    value. Not clipped (see :func:`likelihood_temperature`).
    """
    w = np.asarray(w, dtype=float).ravel()
    ok = np.isfinite(w)
    if ok.sum() < 2 * bandwidth + 2:
        raise ValueError(
            f"long-run variance: {int(ok.sum())} values present, expected at least "
            f"{2 * bandwidth + 2} for a bandwidth of {bandwidth} steps"
        )
    r = np.where(ok, w - w[ok].mean(), 0.0)
    var = float(np.sum(r * r)) / ok.sum()
    kappa = 1.0
    for lag in range(1, bandwidth + 1):
        both = ok[:-lag] & ok[lag:]
        if not both.any():
            continue
        rho = float(np.sum(r[:-lag] * r[lag:])) / both.sum() / var
        kappa += 2.0 * (1.0 - lag / (bandwidth + 1.0)) * rho
    return kappa


def likelihood_temperature(logpost, theta: np.ndarray, bandwidth: int) -> float:
    """The temperature :math:`\\kappa \\ge 1` of the likelihood (module docstring):
    the largest over the outputs of the long-run variance ratio of the standardised
    innovations at ``theta`` (the MAP), with a Bartlett window of ``bandwidth``
    steps; 1 when they are white or anti-correlated."""
    w = innovations_at(logpost, theta)
    kappa = max(long_run_variance_ratio(w[:, o], bandwidth) for o in range(w.shape[1]))
    return float(max(1.0, kappa)) if np.isfinite(kappa) else 1.0
