"""The stochastic state-space likelihood of grey-box modelling: ``noise: kalman``.

The RC model itself carries the model error: process noise enters every node,

.. math::

    dx = (A x + B u)\\,dt + \\Sigma\\, dW, \\qquad
    y_k = C x_k + v_k,\\quad v_k \\sim N(0, \\sigma^2),

with :math:`\\Sigma = \\mathrm{diag}(q_j)` (``q_<node>`` [K/√h] or [Pa/√h]) and white
measurement noise ``sigma_<output>`` [K] or [Pa] (CTSM-R [1]_, pySIP [2]_). The error
then has the model's own time constants: it cannot carry a slow (seasonal) response the
model does not have, which is the trap of a free AR(1) residual.

Discretisation is exact in the modal coordinates :math:`z = T^{-1}x` of
:mod:`heritage_bayes.rc.discretize`: with :math:`\\tilde\\Sigma = T^{-1}\\Sigma`,

.. math::

    Q_d[i,j] = (\\tilde\\Sigma\\tilde\\Sigma^T)_{ij}\\,
    \\frac{1 - e^{-(\\lambda_i+\\lambda_j)\\Delta t}}{\\lambda_i + \\lambda_j},

and the Kalman filter runs on the decoupled modes (n ≤ 4 states), batched over walkers
in one compiled pass; missing observations are prediction-only steps. The initial
state is part of the filter: mean and covariance from
:class:`~heritage_bayes.inference.posterior.LogPosterior`'s initial-state prior (the
steady state of the mean inputs, sd ``initial_state_sd`` on the estimated nodes, damped
for modes slower than ``initial_state_horizon``), so
it is integrated out exactly as with the other noise models.

References
----------
.. [1] N.R. Kristensen, H. Madsen, S.B. Jørgensen, "Parameter estimation in stochastic
   grey-box models", *Automatica* 40 (2004) 225-237.
.. [2] L. Raillon, C. Ghiaus, "An efficient Bayesian experimental calibration of
   dynamic thermal models", *Energy* 152 (2018) 818-833 (pySIP).
.. [3] J. Durbin, S.J. Koopman, *Time Series Analysis by State Space Methods*, 2nd ed.,
   Oxford University Press, 2012, ch. 4.
"""

from __future__ import annotations

import math
from types import MappingProxyType

import numba
import numpy as np

from heritage_bayes.inference.coupled_kalman import coupled_kalman
from heritage_bayes.inference.likelihoods import NoiseModel, ResidualView, register_noise

__all__ = ["KalmanNoise", "modal_process_noise"]

_LOG2PI = math.log(2.0 * math.pi)


def modal_process_noise(mf, q: np.ndarray) -> np.ndarray:
    """(K, n, n) exact discrete process-noise covariance in modal coordinates.

    ``q`` (K, n): diffusion of each node [potential/√s].
    """
    St = mf.Tinv * q[:, None, :]  # T^-1 diag(q)
    SS = St @ np.swapaxes(St, 1, 2)
    lsum = mf.lam[:, :, None] + mf.lam[:, None, :]
    x = lsum * mf.dt
    with np.errstate(divide="ignore", invalid="ignore"):
        f = np.where(x > 1e-12, -np.expm1(-x) / np.where(lsum > 0, lsum, 1.0), mf.dt)
    return SS * f


@numba.njit(cache=True, nogil=True)
def _kalman_modal(ad, W, Qd, Cz, yobs, R, z, P, point, pred, want_point):  # pragma: no cover
    """Kalman filter on decoupled modes, batched over K parameter sets.

    ad (K, n); W (N, K, n) deterministic modal forcing per step; Qd (K, n, n); Cz (K,
    n_out, n); yobs (N, n_out) NaN = missing; R (K, n_out) measurement variances; z (K,
    n), P (K, n, n) the state at step 0 (updated in place). Returns (K,) log-likelihood;
    ``point`` (K, N, n_out) gets the one-step log predictive density of each
    observation when ``want_point``, and ``pred`` (2, K, N, n_out) the one-step-ahead
    predictive mean and variance of every output (missing ones included). Outputs are
    filtered one at a time (sequential processing, exact for independent measurement
    errors).

    Steady state: the covariance recursion does not depend on the data, only on which
    observations are present. Once a fully observed step leaves the predicted
    covariance unchanged to rounding (relative change ≤ 1e-15 of its largest entry),
    the gains of the following fully observed steps are those of that step, so only
    the mean is propagated (the result is the same to rounding); a missing value
    restarts the covariance recursion.
    """
    K, n = ad.shape
    N, n_out = yobs.shape
    out = np.zeros(K)
    PC = np.empty(n)
    Pold = np.empty((n, n))
    Gs = np.empty((n_out, n))  # steady gains P C^T / S per output
    Ss = np.empty(n_out)  # steady innovation variances
    for p in range(K):
        tot = 0.0
        steady = False
        fullprev = False
        for k in range(N):
            full = True
            for o in range(n_out):
                if yobs[k, o] != yobs[k, o]:
                    full = False
            if full and steady:
                for o in range(n_out):
                    yhat = 0.0
                    for i in range(n):
                        yhat += Cz[p, o, i] * z[p, i]
                    S = Ss[o]
                    e = yobs[k, o] - yhat
                    term = -0.5 * (_LOG2PI + math.log(S) + e * e / S)
                    tot += term
                    if want_point:
                        point[p, k, o] = term
                        pred[0, p, k, o] = yhat
                        pred[1, p, k, o] = S
                    for i in range(n):
                        z[p, i] += Gs[o, i] * e
                for i in range(n):
                    z[p, i] = ad[p, i] * z[p, i] + W[k, p, i]
                continue
            steady = False
            for o in range(n_out):
                y = yobs[k, o]
                if y != y and not want_point:
                    continue
                yhat = 0.0
                for i in range(n):
                    yhat += Cz[p, o, i] * z[p, i]
                S = R[p, o]
                for i in range(n):
                    acc = 0.0
                    for j in range(n):
                        acc += P[p, i, j] * Cz[p, o, j]
                    PC[i] = acc
                    S += Cz[p, o, i] * acc
                if want_point:
                    pred[0, p, k, o] = yhat
                    pred[1, p, k, o] = S
                    if y != y:
                        point[p, k, o] = np.nan
                        continue
                e = y - yhat
                term = -0.5 * (_LOG2PI + math.log(S) + e * e / S)
                tot += term
                if want_point:
                    point[p, k, o] = term
                Ss[o] = S
                for i in range(n):
                    Gs[o, i] = PC[i] / S
                    z[p, i] += PC[i] * e / S
                for i in range(n):
                    for j in range(n):
                        P[p, i, j] -= PC[i] * PC[j] / S
            # predict to the next step
            for i in range(n):
                z[p, i] = ad[p, i] * z[p, i] + W[k, p, i]
            dmax = 0.0
            pmax = 0.0
            for i in range(n):
                for j in range(n):
                    v = ad[p, i] * ad[p, j] * P[p, i, j] + Qd[p, i, j]
                    dmax = max(dmax, abs(v - Pold[i, j]))
                    pmax = max(pmax, abs(v))
                    Pold[i, j] = v
                    P[p, i, j] = v
            # two consecutive fully observed steps with the same predicted covariance
            steady = full and k > 0 and dmax <= 1e-15 * pmax and fullprev
            fullprev = full
        out[p] = tot
    return out


@register_noise
class KalmanNoise(NoiseModel):
    """Process noise on every node of the RC model + white measurement noise (see the
    module docstring). Parameters: ``q_<node>`` per state node and ``sigma_<output>``."""

    name = "kalman"
    description = "a Kalman filter on the stochastic RC model"
    kinds = ("sigma",)
    statespace = True
    descriptions = MappingProxyType(
        {
            **NoiseModel.descriptions,
            "diffusion": "process-noise diffusion (per square root of an hour) of node",
        }
    )
    free_run_note = (
        " The process noise is estimated for one-step prediction (the one-step band "
        "below); propagated without the data it is not the error of a free run, so "
        "these bands use the free-run error: "
    )

    def unit(self, kind, output_unit, potential):
        """The diffusion ``q_<node>`` in [potential/√h]; the measurement sd in the
        output's unit."""
        return (
            f"{potential}/√h" if kind == "diffusion" else super().unit(kind, output_unit, potential)
        )

    def residual_view(self, resid, median, one_step=None):
        """What the filter leaves white: its one-step-ahead innovations ``one_step``
        (measured minus the one-step prediction from the measurements before, NaN where
        missing), not the free-run residuals ``resid``, which carry the process noise
        accumulated over the slowest time constant. Without ``one_step`` (a run written
        before it was kept) the residuals themselves, as for a model without an AR part.
        """
        if one_step is None:
            return super().residual_view(resid, median)
        return ResidualView(
            None,
            np.asarray(one_step, dtype=float),
            1.0,
            "a state-space model's free-run residuals carry its accumulated process "
            "noise; its one-step innovations should be white",
            "the filter's one-step-ahead innovations",
        )

    def free_run_reason(self, o, name, noise, params):
        """Always: the process noise is estimated for one-step-ahead prediction, and
        propagated without the data it is not the error of a free run."""
        return (
            "process noise is estimated for one-step prediction: free-run bands use the "
            "free-run error (AR(1) + white fitted to the calibration residuals of the "
            "posterior-median simulation)"
        )

    def parameter_specs(self, output_names, state_names=()) -> list[tuple[str, str, str]]:
        specs = [(f"sigma_{o}", "sigma_meas", o) for o in output_names]
        return specs + [(f"q_{s}", "diffusion", s) for s in state_names]

    def split_statespace(self, noise: np.ndarray, n_out: int):
        """(K, n_out) measurement variances [potential²], (K, n) diffusions [per √s]."""
        sig = noise[:, :n_out]
        q = noise[:, n_out:] / math.sqrt(3600.0)  # [potential/√h] -> [potential/√s]
        return sig * sig, q

    def filter(self, model, mf, U, Yobs, noise, x0_mean, P0, want_point=False, series=None):
        """(K,) log-likelihood from a modal form, inputs ``U`` (N, m), initial mean
        ``x0_mean`` (K, n) and covariance ``P0`` (K, n, n) in physical coordinates.

        With ``want_point``: ``(loglik, point, mean, var)``, the (K, N, n_out) one-step
        log predictive densities (NaN where missing) and the one-step-ahead predictive
        mean and variance of each output given the observations before it (the
        measurement noise included; defined at missing rows too).

        A time-varying model (:class:`~heritage_bayes.rc.sorption.CoupledHygricModel`):
        the filter over its per-step transitions
        (:func:`~heritage_bayes.inference.coupled_kalman.coupled_kalman`), its
        parameters ``mf.theta`` (:meth:`LogPosterior._form`), ``series`` the model's
        :meth:`series` of ``U`` (computed here when None).
        """
        if model.time_varying:
            series = model.series(U) if series is None else series
            return coupled_kalman(
                self, model, mf.theta, series, mf.dt, Yobs, noise, x0_mean, P0, want_point
            )
        K, n = mf.lam.shape
        n_out = mf.Cz.shape[1]
        R, q = self.split_statespace(noise, n_out)
        Qd = modal_process_noise(mf, q)
        n_in = U.shape[1]
        W = (U @ mf.Bdz.reshape(K * n, n_in).T).reshape(U.shape[0], K, n)  # (N, K, n)
        if mf.ez.any():
            W += mf.edz[None]
        z = np.ascontiguousarray(mf.to_modal(x0_mean))
        Ti = mf.Tinv
        P = np.ascontiguousarray(Ti @ P0 @ np.swapaxes(Ti, 1, 2))
        shape = (K, Yobs.shape[0], n_out) if want_point else (1, 1, 1)
        point, pred = np.empty(shape), np.empty((2, *shape))
        ll = _kalman_modal(
            np.ascontiguousarray(mf.ad),
            np.ascontiguousarray(W),
            np.ascontiguousarray(Qd),
            np.ascontiguousarray(mf.Cz),
            np.ascontiguousarray(Yobs, dtype=float),
            np.ascontiguousarray(R),
            z,
            P,
            point,
            pred,
            want_point,
        )
        return (ll, point, pred[0], pred[1]) if want_point else ll

    def one_step(self, logpost, theta: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """One-step-ahead predictive mean and variance (K, N, n_out) [°C, K²] or [Pa,
        Pa²] of the outputs over a posterior's record for values ``theta`` (K, P): the
        filter's prediction of each row from the observations before it (initial state
        from its prior), measurement noise included. Bands: mean ± z·√var."""
        theta = np.atleast_2d(np.asarray(theta, dtype=float))
        tm, tn = logpost.split(theta)
        with np.errstate(all="ignore"):
            mf = logpost._form(tm)
            _, _, mean, var = self.filter(
                logpost.model,
                mf,
                logpost.inputs,
                logpost.observed,
                tn,
                *logpost._x0_prior(mf),
                True,
                logpost._series,
            )
        mean[~mf.valid], var[~mf.valid] = np.nan, np.nan
        return mean, var

    def sample_statespace(self, rng, mf, noise, N: int, n_out: int) -> np.ndarray:
        """(K, N, n_out) free-run predictive noise: the process noise propagated through
        the model's modes, plus measurement noise (added to a noise-free simulation).
        A time-varying model's ``mf`` is its network's at the reference temperature
        (:meth:`LogPosterior._form`): its modes stand for the per-step ones."""
        K, n = mf.lam.shape
        R, q = self.split_statespace(noise, n_out)
        Qd = modal_process_noise(mf, q)
        L = np.linalg.cholesky(Qd + 1e-30 * np.eye(n))
        d = np.zeros((K, n))
        out = np.empty((K, N, n_out))
        for k in range(N):
            out[:, k, :] = np.einsum("koj,kj->ko", mf.Cz, d)
            d = mf.ad * d + np.einsum("kij,kj->ki", L, rng.standard_normal((K, n)))
        return out + np.sqrt(R)[:, None, :] * rng.standard_normal((K, N, n_out))
