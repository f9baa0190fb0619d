"""``noise: kalman`` for the thermo-hygric coupled models: a Kalman filter over their
time-varying per-step transitions.

A :class:`~heritage_bayes.rc.sorption.CoupledHygricModel` with a linear buffer is linear
in its states :math:`x = (P_w, P_i)` [Pa] given the temperatures, with per-step
transitions :math:`M_k` and forcings :math:`f_k`
(:func:`heritage_bayes.rc.sorption.coupled_block`). With process noise at the nodes,

.. math::

    dx = (A(t)\\,x + b(t))\\,dt + \\Sigma\\,dW, \\qquad
    y_k = P_{i,k} + v_k,\\quad v_k \\sim N(0, \\sigma^2),

:math:`\\Sigma = \\mathrm{diag}(q_{P_w}, q_{P_i})` (``q_<node>`` [Pa/√h], as
:class:`~heritage_bayes.inference.statespace.KalmanNoise`), the state follows

.. math::

    x_{k+1} = M_k x_k + f_k + w_k, \\qquad w_k \\sim N(0, Q_k).

:math:`Q_k` is exact for the step's own linear dynamics (the temperatures held at the
step's mean, the model's exact step): in the step's symmetric coordinates
:math:`z = C^{1/2} (r P_w, P_i)`, :math:`S = V \\Lambda V^T`, the noise
:math:`\\tilde\\Sigma = V^T C^{1/2}\\,\\mathrm{diag}(r\\,q_{P_w}, q_{P_i})` gives

.. math::

    Q^{(\\Lambda)}_{ij} = (\\tilde\\Sigma\\tilde\\Sigma^T)_{ij}\\,
    \\frac{1 - e^{-(\\lambda_i+\\lambda_j)\\Delta t}}{\\lambda_i + \\lambda_j},

mapped back by :math:`V` and the coordinates' scalings (the modal discretisation of
:func:`heritage_bayes.inference.statespace.modal_process_noise`, per step). The
temperature's change within the step enters :math:`M_k` to first order
(:mod:`heritage_bayes.rc.sorption`), :math:`Q_k` not at all: :math:`Q_k` is that of
the step with :math:`r` held at its mean. With constant temperatures the transitions
are constant and the filter is the LTI one of ``noise: kalman``.

The filter runs the full 2×2 covariance recursion at every step (no steady state: the
transitions change with the temperature); a missing ``Pi`` is a prediction-only step,
so gaps are exact. **Initial state**: as for the linear models under ``noise: kalman``,
the filter starts from the initial state's prior mean and covariance
(:class:`~heritage_bayes.inference.posterior.LogPosterior`'s, at the reference
temperature), which integrates it out exactly. Compiled (numba), batched over
parameter sets, the transitions and noise covariances of a block of steps computed in
vectorised loops.

References
----------
.. [1] N.R. Kristensen, H. Madsen, S.B. Jørgensen, "Parameter estimation in stochastic
   grey-box models", *Automatica* 40 (2004) 225-237.
.. [2] J. Durbin, S.J. Koopman, *Time Series Analysis by State Space Methods*, 2nd ed.,
   Oxford University Press, 2012, ch. 4 (the time-varying filter).
"""

from __future__ import annotations

import math

import numba
import numpy as np

from heritage_bayes.rc import sorption
from heritage_bayes.rc.sorption import BLOCK, _gains, coupled_block, step_modes, walker_constants

__all__ = ["coupled_kalman", "noise_block"]

_LOG2PI = math.log(2.0 * math.pi)


@numba.njit(inline="always", cache=True, nogil=True, error_model="numpy")
def _phi(lam, il, dt, idt):  # pragma: no cover - compiled
    """``(1 - exp(-lam dt))/lam`` [s] (series for small ``lam dt``)."""
    return _gains(lam, il, dt, idt, False)[1]


@numba.njit(cache=True, nogil=True, error_model="numpy", fastmath={"contract"})
def noise_block(kp, sb, dt, k0, B, qw, qi, Qb):  # pragma: no cover - compiled
    """Process-noise covariances ``Q_k`` [Pa²] of steps ``k0 .. k0 + B - 1`` of one
    parameter set into ``Qb[:, :B]`` (rows: ``Q11``, ``Q12``, ``Q22`` of
    ``(Pw, Pi)``). ``kp``: one row of
    :meth:`~heritage_bayes.rc.sorption.CoupledHygricModel.kernel_parameters`; ``sb``
    the step series of :func:`~heritage_bayes.rc.sorption.fill_series`; ``qw``, ``qi``
    the diffusions of ``Pw`` and ``Pi`` [Pa/√s]."""
    c = walker_constants(kp)
    iw, s2 = c[0], c[1]
    idt = 1.0 / dt
    a2 = qi / s2
    A2 = a2 * a2
    for b in range(B):
        k = k0 + b
        sr, isr = sb[3, k], sb[4, k]
        cc, ss, cs, l1, l2, il1, il2 = step_modes(c, sb[2, k], sr, isr)
        a1 = sr * qw / iw  # C^1/2 diag(r qw, qi), C = diag(Cw/r, Ci)
        A1 = a1 * a1
        # V^T diag(A1, A2) V times the modes' integrals
        qa = (cc * A1 + ss * A2) * _phi(2.0 * l1, 0.5 * il1, dt, idt)
        qd = (ss * A1 + cc * A2) * _phi(2.0 * l2, 0.5 * il2, dt, idt)
        ls = l1 + l2
        qb = cs * (A1 - A2) * _phi(ls, 1.0 / ls, dt, idt)
        # back by V, then C^-1/2 and Pw = v/r
        e1 = iw * isr
        Qb[0, b] = e1 * e1 * (cc * qa + 2.0 * cs * qb + ss * qd)
        Qb[1, b] = e1 * s2 * (cs * (qd - qa) + (cc - ss) * qb)
        Qb[2, b] = s2 * s2 * (ss * qa - 2.0 * cs * qb + cc * qd)


@numba.njit(cache=True, nogil=True, error_model="numpy", fastmath={"contract"})
def _coupled_kalman(
    kp, sb, slope, dt, q, R, x0, P0, yobs, point, pred, want_point, out
):  # pragma: no cover
    """Kalman filter of every parameter set (module docstring).

    kp (K, 7) kernel parameters; sb, slope the step series; q (K, 2) diffusions
    [Pa/√s]; R (K,) measurement variances [Pa²]; x0 (K, 2), P0 (K, 2, 2) the initial
    state's mean [Pa] and covariance [Pa²]; yobs (N,) observed ``Pi`` (NaN: missing);
    out (K,) gets the log-likelihood; with ``want_point``, ``point`` (K, N) the one-step
    log predictive density of each observation (NaN where missing) and ``pred`` (2, K,
    N) the one-step-ahead predictive mean and variance of ``Pi`` (every row).
    """
    K = kp.shape[0]
    N = sb.shape[1]
    Mf = np.empty((6, BLOCK))
    Qb = np.empty((3, BLOCK))
    for p in range(K):
        xw, xi = x0[p, 0], x0[p, 1]
        p11, p12, p22 = P0[p, 0, 0], 0.5 * (P0[p, 0, 1] + P0[p, 1, 0]), P0[p, 1, 1]
        r2 = R[p]
        tot = 0.0
        for k0 in range(0, N, BLOCK):
            B = min(BLOCK, N - k0)
            coupled_block(kp[p], sb, dt, slope, k0, B, Mf)
            noise_block(kp[p], sb, dt, k0, B, q[p, 0], q[p, 1], Qb)
            for b in range(B):
                k = k0 + b
                y = yobs[k]
                S = p22 + r2
                if want_point:
                    pred[0, p, k] = xi
                    pred[1, p, k] = S
                    point[p, k] = np.nan
                if y == y:
                    e = y - xi
                    iS = 1.0 / S
                    term = -0.5 * (_LOG2PI + math.log(S) + e * e * iS)
                    tot += term
                    if want_point:
                        point[p, k] = term
                    xw += p12 * iS * e
                    xi += p22 * iS * e
                    p11 -= p12 * p12 * iS
                    p12 *= r2 * iS
                    p22 *= r2 * iS
                m0, m1, m2, m3 = Mf[0, b], Mf[1, b], Mf[2, b], Mf[3, b]
                xw, xi = m0 * xw + m1 * xi + Mf[4, b], m2 * xw + m3 * xi + Mf[5, b]
                # M P M^T + Q
                a11 = m0 * p11 + m1 * p12
                a12 = m0 * p12 + m1 * p22
                a21 = m2 * p11 + m3 * p12
                a22 = m2 * p12 + m3 * p22
                p11 = a11 * m0 + a12 * m1 + Qb[0, b]
                p12 = a11 * m2 + a12 * m3 + Qb[1, b]
                p22 = a21 * m2 + a22 * m3 + Qb[2, b]
        out[p] = tot


def coupled_kalman(noise_model, model, P, series, dt, Yobs, noise, x0_mean, P0, want_point=False):
    """(K,) log-likelihood of a coupled model under ``noise: kalman``.

    Parameters
    ----------
    noise_model : KalmanNoise
    model : CoupledHygricModel
        Linear buffer (no GAB isotherm).
    P : (K, n_params) array
        Model parameters, SI units.
    series : tuple
        :meth:`~heritage_bayes.rc.sorption.CoupledHygricModel.series` of the inputs.
    dt : float
        Time step [s].
    Yobs : (N, 1) array
        Observed ``Pi`` [Pa], NaN where missing or excluded.
    noise : (K, 3) array
        ``sigma_Pi`` [Pa], ``q_Pw``, ``q_Pi`` [Pa/√h].
    x0_mean, P0 : (K, 2), (K, 2, 2) arrays
        Initial state's mean [Pa] and covariance [Pa²].
    want_point : bool
        Also the one-step log predictive densities and predictive mean and variance,
        (K, N, 1) each: ``(loglik, point, mean, var)``, as
        :meth:`~heritage_bayes.inference.statespace.KalmanNoise.filter`.
    """
    if model.isotherm != "linear":
        raise ValueError(
            f"noise: 'kalman' filters a model linear in its state given the temperatures; "
            f"{model.name!r} has the {model.isotherm!r} isotherm (transitions that follow "
            "the state): use noise: ar1_white"
        )
    K = P.shape[0]
    N = Yobs.shape[0]
    R, q = noise_model.split_statespace(noise, 1)
    shape = (K, N) if want_point else (1, 1)
    point, pred, out = np.empty(shape), np.empty((2, *shape)), np.zeros(K)
    sb, slope = series
    _coupled_kalman(
        model.kernel_parameters(P),
        sb,
        slope,
        float(dt),
        np.ascontiguousarray(q, dtype=float),
        np.ascontiguousarray(R[:, 0], dtype=float),
        np.ascontiguousarray(np.where(np.isfinite(x0_mean), x0_mean, 0.0), dtype=float),
        np.ascontiguousarray(P0, dtype=float),
        np.ascontiguousarray(Yobs[:, 0], dtype=float),
        point,
        pred,
        bool(want_point),
        out,
    )
    if not want_point:
        return out
    return out, point[..., None], pred[0][..., None], pred[1][..., None]


sorption.stamp_cache(globals(), sorption, sorption._vecmath)
