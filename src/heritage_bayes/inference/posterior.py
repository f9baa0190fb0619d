"""Vectorised log-posterior over a batch of walkers.

``LogPosterior(X)`` takes an unconstrained (K, d) array (emcee's ``vectorize=True``) and
returns (K,) log-posterior values. One call does, for all K parameter sets at once: the
transform and log-prior (with Jacobian), the batched modal decomposition and exact ZOH
discretization, one BLAS product for the modal forcing, the compiled modal recursion,
and the compiled noise-model likelihood. Non-physical or non-finite parameter sets give
``-inf``, never an exception.

Initial state (``initial_state``)
----------------------------------
``"estimate"`` (the default for linear models): the state at the first calibration step
is :math:`x_0 = \\bar x + \\delta x`, :math:`\\bar x` the steady state of the mean inputs
over the first ``init_window`` steps and :math:`\\delta x \\sim N(0, s_0^2 S S^T)` with
:math:`s_0` = ``initial_state_sd`` (10 K, 500 Pa by default: weakly informative) and
:math:`S = T\\,\\mathrm{diag}(a_j)\\,T^{-1}`, :math:`a_j = (1+(\\tau_j/h)^2)^{-1/2}`: each
mode's share of the deviation is damped once its time constant :math:`\\tau_j` exceeds
the horizon h (``initial_state_horizon``, by default the calibration record; all
:math:`a_j = 1` give the isotropic :math:`s_0^2 I`). Why: a mode much slower than the
record barely moves over it, so a free start makes it a free constant offset, which a
misspecified model uses to absorb what it lacks (measured: docs/science/noise.md,
"Figures behind the code's choices"). Modes faster than the record (the τ of 2-3 weeks
of thick masonry in three months) keep nearly all of :math:`s_0`: the damping leaves
them estimated. The outputs are linear in :math:`x_0` and every noise model here is
Gaussian, so :math:`\\delta x` is **integrated out exactly** for each parameter set: one
compiled pass gives the filter innovations of the residual and of the n free responses
:math:`C A_d^k`, hence the quadratic form in :math:`\\delta x`, and

.. math::

    \\log p(y\\mid\\theta) = \\ell_0 + \\tfrac12 g^T M^{-1} g - \\tfrac12\\log\\det M
    - \\tfrac12\\log\\det P_0, \\qquad M = H + P_0^{-1},\\ P_0 = s_0^2 S S^T .

Why integrate rather than sample or profile: sampling adds n strongly correlated
dimensions to emcee (the slow node's start trades against the static gains); profiling
(the maximum over :math:`\\delta x`) ignores its uncertainty and is biased for short
records; the marginal costs about one more simulated series per state and keeps the
posterior of :math:`\\theta` exact. The conditional posterior
:math:`N(M^{-1}g, M^{-1})` of :math:`\\delta x` is drawn per posterior draw
(:meth:`LogPosterior.initial_states`) and reported. No warm-up is needed: a slow
envelope that starts weeks away from equilibrium (thick masonry, a test cell opened
the day before) is estimated, not assumed away [1]_. ``"steady"``: the old start,
:math:`x_0 = \\bar x`, usually with a warm-up excluded from the likelihood (the only
choice for controlled rooms, whose simulator is not linear in the state). A mapping
``{node: value}`` fixes those nodes [°C or Pa] and estimates the others.

References
----------
.. [1] N.R. Kristensen, H. Madsen, S.B. Jørgensen, "Parameter estimation in stochastic
   grey-box models", *Automatica* 40 (2004) 225-237 (initial states estimated with the
   parameters).
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass
from typing import Any

import numpy as np

from heritage_bayes.inference.coupled import FIRST_PASS_STOP, coupled_filter_stats
from heritage_bayes.inference.likelihoods import NoiseModel, residual_noise_models
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
        Steps averaged for the steady-state initial condition (the prior mean of the
        initial state).
    initial_state : {"estimate", "steady"} or mapping node -> value
        See the module docstring.
    initial_state_sd : float, optional
        Prior sd of the estimated initial deviation [K] or [Pa] (default 10 K / 500 Pa).
    time_constant_cap : float, optional
        Scale [s] of the soft prior on every time constant,
        :math:`p(\\tau_j) \\propto 1/(1 + (\\tau_j/\\tau_{cap})^2)` (see
        :meth:`time_constant_log_prior`); None or ``math.inf``: none.
    initial_state_horizon : float, optional
        Time [s] beyond which a mode's start deviation is damped (see the module
        docstring); default the length of ``inputs``; ``math.inf`` switches it off.
    temperature : float
        Divides the log-likelihood in the log-posterior (a tempered likelihood,
        :mod:`heritage_bayes.inference.tempering`); default 1 (none).
        :meth:`log_likelihood` and the pointwise terms stay untempered.
    """

    model: RCModel
    params: ParameterSet
    noise: NoiseModel
    inputs: np.ndarray
    observed: np.ndarray
    dt: float = 3600.0
    warmup: int = 336
    init_window: int = 720
    initial_state: Any = "steady"
    initial_state_sd: float | None = None
    initial_state_horizon: float | None = None
    time_constant_cap: float | None = None
    temperature: float = 1.0

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
        self._setup_initial_state()

    def _setup_initial_state(self) -> None:
        """Resolve ``initial_state`` into fixed node values and estimated nodes."""
        states = self.model.state_names
        mode = self.initial_state
        self.x0_fixed: dict[int, float] = {}
        if isinstance(mode, Mapping):
            unknown = [k for k in mode if k not in states]
            if unknown:
                raise ValueError(
                    f"initial_state: unknown node(s) {unknown}; the nodes of "
                    f"{self.model.name!r} are {list(states)}"
                )
            self.x0_fixed = {states.index(k): float(v) for k, v in mode.items()}
            free = [i for i in range(len(states)) if i not in self.x0_fixed]
        elif mode == "estimate":
            free = list(range(len(states)))
        elif mode == "steady":
            free = []
        else:
            raise ValueError(
                f"initial_state: expected 'estimate', 'steady' or a mapping node -> value "
                f"(got {mode!r})"
            )
        self._time_varying = self.model.time_varying
        # transitions that follow the state: the start's quadratic form re-centred
        self._relinearise = self._time_varying and self.model.isotherm != "linear"
        self._first_pass_stop = FIRST_PASS_STOP  # 0: the first pass over the whole record
        if self._relinearise and self.noise.statespace:
            raise ValueError(
                f"noise: {self.noise.name!r} filters a model linear in its state; the "
                f"{self.model.isotherm!r} isotherm of {self.model.name!r} follows its state: "
                f"use one of {', '.join(residual_noise_models())}"
            )
        # the per-step series of the inputs (saturation ratios), once
        self._series = self.model.series(self.inputs) if self._time_varying else None
        if self.model.control is not None and self.noise.statespace:
            raise ValueError(
                f"noise: {self.noise.name!r} filters a model that is linear in its state; "
                f"{self.model.name!r} is controlled (thermostat/humidistat): use one of "
                f"{', '.join(residual_noise_models())}"
            )
        if free and self.model.control is not None:
            raise ValueError(
                f"initial_state: {mode!r} needs a model that is linear in its state; "
                f"{self.model.name!r} is controlled (thermostat/humidistat), use 'steady' "
                "with a warm-up"
            )
        self.x0_free = np.array(free, dtype=int)
        sd = self.initial_state_sd
        if sd is None:
            sd = 10.0 if self.model.domain == "thermal" else 500.0
        if not sd > 0:
            raise ValueError(f"initial_state_sd: must be > 0 (got {sd})")
        self.initial_state_sd = float(sd)
        h = self.initial_state_horizon
        if h is None:
            h = self.record_seconds
        if not h > 0:
            raise ValueError(f"initial_state_horizon: must be > 0 s (got {h})")
        self.initial_state_horizon = float(h)
        cap = self.time_constant_cap
        if cap is not None and not cap > 0:
            raise ValueError(f"time_constant_cap: must be > 0 s (got {cap})")

    def time_constant_log_prior(self, theta_model: np.ndarray) -> np.ndarray:
        """(K,) log of the soft prior on the time constants, :math:`-\\sum_j
        \\log(1 + (\\tau_j/\\tau_{cap})^2)` (0 without ``time_constant_cap``).

        A joint prior on the capacities and conductances, stated on what the data see:
        no node of a building envelope or its contents relaxes over more than about a
        year (2 m of stone: about 50 days), so a time constant beyond the cap is
        penalised (Cauchy-like tail) but not forbidden. Why: a mode many records long
        barely moves and explains the record as well as a constant does, so it forms a
        second posterior branch as likely as the physical one, between which the chain
        mixes slowly (measured: docs/science/models.md, "Figures behind the code's
        choices").
        """
        cap = self.time_constant_cap
        K = theta_model.shape[0]
        if cap is None or not np.isfinite(cap):
            return np.zeros(K)
        with np.errstate(all="ignore"):
            out = -np.log1p((1.0 / (self.decay_rates(theta_model) * cap)) ** 2).sum(axis=1)
        return np.where(np.isfinite(out), out, -np.inf)

    def decay_rates(self, theta_model: np.ndarray) -> np.ndarray:
        """(K, n) decay rates [1/s] of the model's modes, ascending (the slowest first):
        the eigenvalues of :math:`C^{-1/2} G C^{-1/2}`, i.e. 1/τ of each mode."""
        with np.errstate(all="ignore"):
            c, G, _, _ = self.model.network_matrices(theta_model)
            r = 1.0 / np.sqrt(c)
            return np.linalg.eigvalsh(r[:, :, None] * G * r[:, None, :])

    def data_hash(self) -> str:
        """SHA-256 (16 hex digits) of the inputs and observations (what a chain
        checkpoint must have been sampled on)."""
        import hashlib

        h = hashlib.sha256()
        for a in (self.inputs, self.observed):
            a = np.ascontiguousarray(a, dtype=float)
            h.update(str(a.shape).encode())
            h.update(a.tobytes())
        return h.hexdigest()[:16]

    @property
    def record_seconds(self) -> float:
        """Length of the calibration record [s] (warm-up included)."""
        return self.inputs.shape[0] * self.dt

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
        x0: np.ndarray | None = None,
    ) -> tuple[np.ndarray, np.ndarray]:
        """Noise-free outputs (K, N, n_out) and validity (K,) for model parameters,
        from initial states ``x0`` (K, n) if given, else the steady state of ``u_init``."""
        U = self.inputs if inputs is None else inputs
        u0 = self.u_init if u_init is None else u_init
        return self.model.forward(theta_model, U, self.dt, u_init=u0, x0=x0)

    def simulate_frame(
        self,
        theta: np.ndarray,
        inputs: np.ndarray,
        start: int = 0,
        rng: np.random.Generator | None = None,
        x0: np.ndarray | None = None,
    ) -> tuple[np.ndarray, np.ndarray]:
        """Noise-free outputs (K, N, n_out) over a whole frame of ``inputs`` (N, m)
        whose row ``start`` is the first calibration step, for parameter values (K, P).

        From row ``start`` on, the simulation starts from :meth:`initial_states` (a draw
        of the estimated initial state with ``rng``, else its conditional mean); rows
        before it (a validation period that precedes the calibration) are simulated
        from the steady state of their own first ``init_window`` inputs. ``x0`` (K, n)
        overrides the initial states.
        """
        theta = np.atleast_2d(np.asarray(theta, dtype=float))
        tm = theta[:, : self.n_model]
        U = np.ascontiguousarray(inputs, dtype=float)
        if x0 is None:
            x0 = self.initial_states(theta, rng)
        if x0 is None:  # controlled: its own start from the mean inputs
            u0 = U[start : start + max(1, self.init_window)].mean(axis=0)
            Y, valid = self.model.forward(tm, U[start:], self.dt, u_init=u0)
        else:
            Y, valid = self.model.forward(tm, U[start:], self.dt, x0=x0)
        if start > 0:
            u0 = U[: max(1, self.init_window)].mean(axis=0)
            Yb, vb = self.model.forward(tm, U[:start], self.dt, u_init=u0)
            Y, valid = np.concatenate([Yb, Y], axis=1), valid & vb
        return Y, valid

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
            mf = self._form(tm)
            if self.noise.statespace:
                ll = self.noise.filter(
                    self.model, mf, self.inputs, self.observed, tn, *self._x0_prior(mf),
                    series=self._series,
                )  # fmt: skip
            else:
                ll = self._marginal(mf, tn)[0]
        ll[~mf.valid] = -np.inf
        ll[~np.isfinite(ll)] = -np.inf
        return ll

    def _form(self, tm: np.ndarray):
        """The modal form of model parameters (K, P_model); for a time-varying model
        (:class:`~heritage_bayes.rc.sorption.CoupledHygricModel`) that of its network at
        the reference temperature (validity, time constants, the initial state's prior
        covariance), carrying the parameters for its exact recursion."""
        mf = modal_form(self.model, tm, self.dt)
        if self._time_varying:
            mf.theta = tm
            mf.valid = mf.valid & self.model.valid_mask(tm)
        return mf

    def _x0_mean(self, mf) -> np.ndarray:
        """(K, n) prior mean of the initial state [°C or Pa]: the steady state of the
        mean inputs over ``init_window`` (of a time-varying model: at their mean
        temperatures), with the fixed nodes set."""
        if self._time_varying:
            x = self.model.steady_state(mf.theta, self.u_init)
        else:
            x = np.einsum("kij,kj->ki", mf.T, mf.steady_state_modal(self.u_init))
        for i, v in self.x0_fixed.items():
            x[:, i] = v
        return np.where(np.isfinite(x), x, 0.0)

    def _x0_cov(self, mf) -> np.ndarray:
        r"""(K, nf, nf) prior covariance of the estimated nodes' deviation [K², Pa²]:
        :math:`s_0^2 S S^T` (free block), :math:`S = T\,\mathrm{diag}(a_j)\,T^{-1}`,
        :math:`a_j = (1 + (\tau_j/h)^2)^{-1/2}` with ``initial_state_horizon`` h."""
        free = self.x0_free
        with np.errstate(all="ignore"):
            tau = 1.0 / mf.lam
            a = 1.0 / np.sqrt(1.0 + (tau / self.initial_state_horizon) ** 2)
            a = np.where(np.isfinite(a), a, 0.0)
            S = mf.T @ (a[:, :, None] * mf.Tinv)
            Sf = S[:, free, :]
            cov = self.initial_state_sd**2 * (Sf @ np.swapaxes(Sf, 1, 2))
        nf = free.size
        bad = ~np.all(np.isfinite(cov), axis=(1, 2))
        cov[bad] = np.eye(nf) * self.initial_state_sd**2
        # a floor far below any physical start uncertainty keeps it invertible
        floor = (1e-6 * self.initial_state_sd) ** 2
        return cov + floor * np.eye(nf)

    def _x0_prior(self, mf) -> tuple[np.ndarray, np.ndarray]:
        """Initial-state prior: mean (K, n) and covariance (K, n, n) [°C², Pa²]."""
        xm = self._x0_mean(mf)
        K, n = xm.shape
        P0 = np.zeros((K, n, n))
        f = self.x0_free
        if f.size:
            P0[:, f[:, None], f[None, :]] = self._x0_cov(mf)
        return xm, P0

    def _statespace_x0(self, mf, tn, xm):
        """Conditional posterior of the estimated initial nodes under ``noise: kalman``:
        mean (K, nf) and covariance (K, nf, nf) [°C or Pa].

        With the start fixed, the filter's log-likelihood is exactly quadratic in it (the
        gains do not depend on the data), so its gradient g and curvature H follow from
        filter runs at the prior mean and at unit offsets of each node (and pairs), and
        the posterior is N(M⁻¹g, M⁻¹) with M = H + P0⁻¹ around the prior mean (P0:
        ``_x0_cov``).
        """
        K, n = xm.shape
        free = list(self.x0_free)
        zero = np.zeros((K, n, n))

        def ll(offset):
            return self.noise.filter(
                self.model, mf, self.inputs, self.observed, tn, xm + offset, zero,
                series=self._series,
            )  # fmt: skip

        def unit(*idx):
            d = np.zeros((K, n))
            for i, sgn in idx:
                d[:, i] += sgn
            return d

        nf = len(free)
        l0 = ll(np.zeros((K, n)))
        lp = {i: ll(unit((i, 1.0))) for i in free}
        lm = {i: ll(unit((i, -1.0))) for i in free}
        g = np.stack([(lp[i] - lm[i]) / 2.0 for i in free], axis=1)
        H = np.zeros((K, nf, nf))
        for a, i in enumerate(free):
            H[:, a, a] = -(lp[i] + lm[i] - 2.0 * l0)
            for b in range(a):
                j = free[b]
                hij = -(ll(unit((i, 1.0), (j, 1.0))) - lp[i] - lp[j] + l0)
                H[:, a, b] = H[:, b, a] = hij
        M = H + np.linalg.inv(self._x0_cov(mf))
        cov = np.linalg.inv(M)
        return xm[:, free] + np.einsum("kij,kj->ki", cov, g), cov

    def _marginal(self, mf, tn: np.ndarray, conditional: bool = False):
        """(K,) log-likelihood with the initial-state deviation integrated out, and with
        ``conditional`` its conditional posterior mean (K, nf) and covariance
        (K, nf, nf) [°C or Pa] for the estimated nodes ``x0_free``.

        A model whose transitions follow its state (``isotherm: gab``) is linear in the
        start only about one trajectory: the quadratic form is taken about the
        trajectory from the prior mean, then once more about the one from the
        conditional mean it gives (a Gauss-Newton step on the start, the prior still
        centred on the prior mean), so that the free responses follow the capacity
        along the path the data put the buffer on. Of the first pass only that mean is
        kept: each walker's recursion ends once the start's free responses have decayed
        below :data:`~heritage_bayes.inference.coupled.FIRST_PASS_STOP` (the rest of
        the record would add to the start's gradient and curvature only terms below
        that relative size, decaying)."""
        xm = self._x0_mean(mf)
        twice = self._relinearise and self.x0_free.size > 0
        stop = self._first_pass_stop if twice else 0.0
        out = self._integrate(mf, tn, xm, xm, conditional or twice, stop)
        if twice:
            at = xm.copy()
            at[:, self.x0_free] = np.where(np.isfinite(out[1]), out[1], xm[:, self.x0_free])
            out = self._integrate(mf, tn, at, xm, conditional)
        return out

    def _integrate(self, mf, tn, at, xm, conditional: bool, stop: float = 0.0):
        """:meth:`_marginal` with the filter's quadratic form in the start taken about
        the trajectory from ``at`` (K, n) and the start's prior centred on ``xm``
        [°C or Pa]: with e = x0 - at, μ = xm - at and b = g + P0⁻¹μ the integral
        adds ½ bᵀM⁻¹b - ½ μᵀP0⁻¹μ - ½ log det M - ½ log det P0; the conditional mean
        is ``at + M⁻¹b``. ``stop``: :func:`coupled_filter_stats`'s (a time-varying
        model; its log-likelihood then covers only the steps run)."""
        free = self.x0_free
        nf = free.size
        if self._time_varying:  # the basis in physical coordinates
            acc = coupled_filter_stats(
                self.model, mf.theta, self._series, at, self.observed, self.noise, tn,
                basis=nf > 0, dt=self.dt, stop=stop,
            )  # fmt: skip
            Tinv = np.broadcast_to(np.eye(at.shape[1]), mf.Tinv.shape)
        else:
            acc = self.noise.filter_modal(
                mf, self.inputs, mf.to_modal(at), self.observed, tn, basis=nf > 0
            )
            Tinv = mf.Tinv
        ll = -0.5 * (acc[0] + acc[1])
        if nf == 0:
            return ll, None, None
        K, n = mf.lam.shape
        g = acc[3 : 3 + n].T  # (K, n) modal
        H = np.zeros((K, n, n))
        tri = acc[3 + n :].T.reshape(K, n, n)
        il = np.tril_indices(n)
        H[:, il[0], il[1]] = tri[:, il[0], il[1]]
        H = H + np.swapaxes(np.tril(H, -1), 1, 2)
        # modal offset dz = Tinv dx: the statistics in physical coordinates [°C, Pa]
        Bx = Tinv[:, :, free]  # (K, n, nf)
        gx = np.einsum("kjf,kj->kf", Bx, g)
        Hx = np.swapaxes(Bx, 1, 2) @ H @ Bx
        P = self._x0_cov(mf)
        sgn, logdet_p = np.linalg.slogdet(P)
        Pinv = np.linalg.inv(P)
        Pinv = 0.5 * (Pinv + np.swapaxes(Pinv, 1, 2))
        M = Hx + Pinv
        mu = (xm - at)[:, free]
        gx = gx + np.einsum("kij,kj->ki", Pinv, mu)
        ll = ll - 0.5 * np.einsum("ki,kij,kj->k", mu, Pinv, mu)
        ok = np.all(np.isfinite(M), axis=(1, 2)) & np.isfinite(ll) & (sgn > 0)
        M[~ok] = np.eye(nf)
        gx[~ok] = 0.0
        try:
            L = np.linalg.cholesky(M)
        except np.linalg.LinAlgError:
            L = np.empty_like(M)
            for k in range(K):
                try:
                    L[k] = np.linalg.cholesky(M[k])
                except np.linalg.LinAlgError:
                    L[k] = np.eye(nf)
                    ok[k] = False
        w = np.linalg.solve(L, gx[..., None])[..., 0]
        logdet = 2.0 * np.log(np.diagonal(L, axis1=1, axis2=2)).sum(axis=1)
        ll = ll + 0.5 * (w * w).sum(axis=1) - 0.5 * logdet - 0.5 * logdet_p
        ll[~ok] = -np.inf
        if not conditional:
            return ll, None, None
        Minv = np.linalg.inv(M)
        mean = np.einsum("kij,kj->ki", Minv, gx)
        return ll, at[:, free] + mean, Minv

    def initial_states(
        self, theta: np.ndarray, rng: np.random.Generator | None = None
    ) -> np.ndarray | None:
        """(K, n) initial states [°C or Pa] at the first calibration step for parameter
        values (K, P) (model then noise): the conditional posterior mean of the estimated
        nodes, or a draw from it with ``rng``; the steady state with ``"steady"``. None
        for a controlled model (its simulator finds its own start from ``u_init``).
        """
        theta = np.atleast_2d(np.asarray(theta, dtype=float))
        if self.model.control is not None:
            return None
        tm, tn = self.split(theta)
        with np.errstate(all="ignore"):
            mf = self._form(tm)
            x0 = self._x0_mean(mf)
            if self.x0_free.size and self.noise.statespace:
                mean, cov = self._statespace_x0(mf, tn, x0)
                if rng is not None:
                    Lc = np.linalg.cholesky(cov + 1e-12 * np.eye(cov.shape[-1]))
                    mean = mean + np.einsum("kij,kj->ki", Lc, rng.standard_normal(mean.shape))
                x0[:, self.x0_free] = mean
            elif self.x0_free.size:
                _, mean, cov = self._marginal(mf, tn, conditional=True)
                if rng is not None:
                    cov = 0.5 * (cov + np.swapaxes(cov, 1, 2))
                    Lc = np.linalg.cholesky(cov + 1e-12 * np.eye(cov.shape[-1]))
                    mean = mean + np.einsum("kij,kj->ki", Lc, rng.standard_normal(mean.shape))
                x0[:, self.x0_free] = mean
        return x0

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
                th = theta[inside]
                val[inside] = (
                    lp[inside]
                    + self.time_constant_log_prior(th[:, : self.n_model])
                    + self._loglik(th) / self.temperature
                )
            val[~np.isfinite(val)] = -np.inf
            out[ok] = val
        return out[0] if single else out

    def log_likelihood(self, theta: np.ndarray) -> np.ndarray:
        """(K,) log-likelihood for parameter values (K, P) (model then noise)."""
        return self._loglik(np.atleast_2d(np.asarray(theta, dtype=float)))

    def pointwise_log_likelihood(self, theta: np.ndarray) -> np.ndarray:
        """(K, N, n_out) log-likelihood terms (NaN where excluded), for LOO."""
        theta = np.atleast_2d(theta)
        tm, tn = self.split(theta)
        if self.noise.statespace:  # one-step predictive densities
            mf = self._form(tm)
            return self.noise.filter(
                self.model, mf, self.inputs, self.observed, tn, *self._x0_prior(mf), True,
                self._series,
            )[1]  # fmt: skip
        Y, _ = self.simulate(tm, x0=self.initial_states(theta))
        return self.noise.pointwise(Y, self.observed, tn)
