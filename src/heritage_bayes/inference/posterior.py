"""Vectorised log-posterior over a batch of walkers.

``LogPosterior(X)`` takes an unconstrained (K, d) array (emcee's ``vectorize=True``) and
returns (K,) log-posterior values. One call does, for all K parameter sets at once: the
transform and log-prior (with Jacobian), the batched modal decomposition and exact ZOH
discretization, one BLAS product for the modal forcing, the compiled modal recursion,
and the compiled noise-model likelihood. Non-physical or non-finite parameter sets give
``-inf``, never an exception.

Initial state: the steady state of the mean input over the first ``init_window`` steps
(30 days by default in configs), followed by a warm-up period (``warmup`` steps, default two weeks)
whose observations are excluded from the likelihood. This absorbs the start-up
transient of all but the slowest modes without adding the initial states as parameters;
for envelopes with time constants of months, lengthen the warm-up.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from heritage_bayes.inference.likelihoods import NoiseModel
from heritage_bayes.inference.parameters import ParameterSet
from heritage_bayes.rc.discretize import modal_form
from heritage_bayes.rc.model import RCModel

__all__ = ["LogPosterior"]


@dataclass
class LogPosterior:
    """Log-posterior of an RC model with a noise model, vectorised over walkers.

    Parameters
    ----------
    model : RCModel
    params : ParameterSet
        Model parameters (in ``model.parameter_names`` order) followed by the noise
        model's parameters.
    noise : NoiseModel
    inputs : (N, m) array
        Model inputs on the simulation grid (finite).
    observed : (N, n_out) array
        Observations; NaN where missing. Rows before ``warmup`` are ignored.
    dt : float
        Time step [s].
    warmup : int
        Number of initial steps excluded from the likelihood.
    init_window : int
        Steps averaged for the steady-state initial condition.
    """

    model: RCModel
    params: ParameterSet
    noise: NoiseModel
    inputs: np.ndarray
    observed: np.ndarray
    dt: float = 3600.0
    warmup: int = 336
    init_window: int = 720

    def __post_init__(self):
        self.inputs = np.ascontiguousarray(self.inputs, dtype=float)
        obs = np.array(self.observed, dtype=float, copy=True)
        if obs.ndim == 1:
            obs = obs[:, None]
        obs[: self.warmup] = np.nan
        self.observed = obs
        self.n_model = len(self.model.parameter_names)
        self.u_init = self.inputs[: max(1, self.init_window)].mean(axis=0)
        if np.all(np.isnan(obs)):
            raise ValueError("no observations left after the warm-up period")

    @property
    def ndim(self) -> int:
        return self.params.ndim

    def split(self, theta: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """All values (K, P) -> model parameters (K, P_model), noise (K, q)."""
        return theta[:, : self.n_model], theta[:, self.n_model :]

    def simulate(
        self,
        theta_model: np.ndarray,
        inputs: np.ndarray | None = None,
        u_init: np.ndarray | None = None,
    ) -> tuple[np.ndarray, np.ndarray]:
        """Noise-free outputs (K, N, n_out) and validity (K,) for model parameters."""
        U = self.inputs if inputs is None else inputs
        u0 = self.u_init if u_init is None else u_init
        return self.model.forward(theta_model, U, self.dt, u_init=u0)

    def _loglik(self, theta: np.ndarray) -> np.ndarray:
        """(K,) log-likelihood for valid-shaped values (K, P); -inf where invalid."""
        tm, tn = self.split(theta)
        if self.model.control is not None:
            # a controlled room: a nonlinear simulator batched over walkers, then the
            # noise model's likelihood of the simulated outputs
            with np.errstate(all="ignore"):
                Y, valid = self.simulate(tm)
                ll = self.noise.loglik(Y, self.observed, tn)
            ll[~valid] = -np.inf
            ll[~np.isfinite(ll)] = -np.inf
            return ll
        with np.errstate(all="ignore"):
            mf = modal_form(self.model, tm, self.dt)
            z0 = mf.steady_state_modal(self.u_init)
            z0 = np.where(np.isfinite(z0), z0, 0.0)
            ll = self.noise.loglik_modal(mf, self.inputs, z0, self.observed, tn)
        ll[~mf.valid] = -np.inf
        ll[~np.isfinite(ll)] = -np.inf
        return ll

    def __call__(self, X: np.ndarray) -> np.ndarray:
        X = np.asarray(X, dtype=float)
        single = X.ndim == 1
        X = np.atleast_2d(X)
        out = np.full(X.shape[0], -np.inf)
        ok = np.all(np.isfinite(X), axis=1)
        if ok.any():
            theta, lp = self.params.transform(X[ok])
            inside = np.isfinite(lp)  # outside the prior support: no simulation
            val = np.full(lp.shape, -np.inf)
            if inside.any():
                val[inside] = lp[inside] + self._loglik(theta[inside])
            val[~np.isfinite(val)] = -np.inf
            out[ok] = val
        return out[0] if single else out

    def log_likelihood(self, theta: np.ndarray) -> np.ndarray:
        """(K,) log-likelihood for parameter values (K, P) (model then noise)."""
        return self._loglik(np.atleast_2d(np.asarray(theta, dtype=float)))

    def pointwise_log_likelihood(self, theta: np.ndarray) -> np.ndarray:
        """(K, N, n_out) log-likelihood terms (NaN where excluded), for LOO."""
        tm, tn = self.split(np.atleast_2d(theta))
        Y, _ = self.simulate(tm)
        return self.noise.pointwise(Y, self.observed, tn)
