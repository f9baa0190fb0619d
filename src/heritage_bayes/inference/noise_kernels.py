"""The compiled kernels of the Gaussian residual process behind the noise models of
:mod:`heritage_bayes.inference.likelihoods`: a stationary AR(1) model error plus white
measurement noise, evaluated exactly by a scalar Kalman filter (alone, ``_kf_kernel``,
or fused with the modal recursion of the RC model, ``_fused_kf``), and AR(1) draws.

References
----------
.. [1] G.E.P. Box, G.M. Jenkins, G.C. Reinsel, *Time Series Analysis*, 4th ed., Wiley,
   2008 (AR(1) exact likelihood).
.. [2] J. Durbin, S.J. Koopman, *Time Series Analysis by State Space Methods*, 2nd ed.,
   Oxford University Press, 2012, ch. 4.
"""

from __future__ import annotations

import math

import numba
import numpy as np

__all__ = ["ar1_predict"]

_LOG2PI = math.log(2.0 * math.pi)


@numba.njit(cache=True, nogil=True)
def _ar1_sample(z, phi, sigma, out):  # pragma: no cover
    """AR(1) with marginal sd sigma from standard normals z (K, N) into out (K, N)."""
    K, N = z.shape
    for p in range(K):
        ph = phi[p]
        c = sigma[p] * math.sqrt(1.0 - ph * ph)
        e = sigma[p] * z[p, 0]
        out[p, 0] = e
        for k in range(1, N):
            e = ph * e + c * z[p, k]
            out[p, k] = e


@numba.njit(inline="always", cache=True, nogil=True)
def ar1_predict(last, k, ph, P, s2):  # pragma: no cover - compiled
    """Prediction of the AR(1) model error at step ``k`` from its filtered variance
    ``P`` at the last observed step ``last`` (< 0: none yet): the factor
    :math:`\\phi^d` on the filtered mean and the predicted variance
    :math:`\\phi^{2d}P + \\sigma^2(1-\\phi^{2d})` (``s2`` = :math:`\\sigma^2`), exact across a gap
    of ``d = k - last`` steps; the stationary variance for the first observation."""
    if last < 0:
        return 0.0, s2
    d = k - last
    phd = ph if d == 1 else ph**d
    return phd, phd * phd * P + s2 * (1.0 - phd * phd)


@numba.njit(cache=True, nogil=True)
def _kf_kernel(Ysim, yobs, sigma, phi, w, point, want_point):  # pragma: no cover
    """Exact log-likelihood of r = yobs - ysim for AR(1) model error + white noise.

    The residual is :math:`r_k = \\eta_k + \\varepsilon_k` with :math:`\\eta` a stationary
    AR(1) of marginal sd ``sigma`` and coefficient ``phi``, :math:`\\varepsilon` white with
    sd ``w``: a scalar Kalman filter (prediction over d steps across a gap: mean
    :math:`\\phi^d m`, variance :math:`\\phi^{2d}P + \\sigma^2(1-\\phi^{2d})`). With
    ``w = 0`` it is exactly the AR(1) likelihood of ``_ar1_kernel``.
    """
    K, N = Ysim.shape
    out = np.empty(K)
    for p in range(K):
        s2 = sigma[p] * sigma[p]
        w2 = w[p] * w[p]
        ph = phi[p]
        tot = 0.0
        m = 0.0
        P = s2
        last = -1
        for k in range(N):
            y = yobs[k]
            if y != y:
                if want_point:
                    point[p, k] = np.nan
                continue
            phd, Pp = ar1_predict(last, k, ph, P, s2)
            mp = phd * m
            F = Pp + w2
            e = (y - Ysim[p, k]) - mp
            term = -0.5 * (_LOG2PI + math.log(F) + e * e / F)
            tot += term
            if want_point:
                point[p, k] = term
            g = Pp / F
            m = mp + g * e
            P = Pp * w2 / F
            last = k
        out[p] = tot
    return out


@numba.njit(cache=True, nogil=True)
def _fused_kf(
    ad, W, z, pw, Cz, yobs, k0, sigma, phi, w, mres, mbas, Pv, last, conv, act, acc
):  # pragma: no cover
    """Modal recursion + Gaussian noise filter + initial-state statistics, one pass.

    Mode-major layout so that the loops over parameter sets are contiguous (SIMD):
    ad, z, pw (n*K,) with index j*K + p (``pw`` = ad**k, the free response of a unit
    modal initial perturbation); W (Nb, n*K) forcing rows k0..k0+Nb-1; Cz (n_out, n, K);
    yobs (N, n_out) with NaN = excluded; sigma, phi, w, mres, Pv (n_out, K) noise
    parameters, filter mean of the residual and filter variance; mbas (n_out, nb, K)
    filter means of the nb basis series (nb = n when the initial state is estimated,
    else 0); last (n_out,) previous observed row; conv (n_out, 3, K) the converged
    filter (log 2 pi F, 1/F, gain) once the scalar Riccati recursion is stationary, with
    conv[o, 0, 0] = nan until then (reset by a gap). ``acc`` (3 + nb + nb*nb, K)
    collects sum log(2 pi F), sum e0²/F, (unused), g_j = sum e0 eb_j/F and the lower
    triangle of H_ij = sum eb_i eb_j/F, where e0 are the innovations of the residual
    with the mean initial state and eb_j those of basis series j, so that the
    log-likelihood with modal initial offset dz is ``-0.5 (acc0 + acc1 - 2 g.dz +
    dz.H.dz)`` (the gains do not depend on the data). ``act`` (1,) is the number of
    basis series still alive: modes come sorted from slow to fast (``eigh``), and a fast
    mode's free response and filter means decay within a few hundred steps (values below
    1e-280 are flushed to zero), after which it adds nothing and is skipped.
    """
    Nb, Kn = W.shape
    n_out, n, K = Cz.shape
    nb = mbas.shape[1]
    s2 = sigma * sigma
    w2 = w * w
    ysim = np.empty(K)
    eb = np.empty((nb, K))
    ph_b = np.empty(K)
    g_b = np.empty(K)
    iF_b = np.empty(K)
    e_b = np.empty(K)
    nba = act[0]
    for k in range(Nb):
        kk = k0 + k
        for o in range(n_out):
            y = yobs[kk, o]
            if y != y:
                continue
            ysim[:] = 0.0
            for j in range(n):
                for p in range(K):
                    ysim[p] += Cz[o, j, p] * z[j * K + p]
            lk = last[o]
            if lk >= 0 and kk - lk == 1 and conv[o, 0, 0] == conv[o, 0, 0]:
                # stationary filter: constant variance, gain and log-determinant
                if nba == 0:
                    for p in range(K):
                        ph = phi[o, p]
                        e0 = (y - ysim[p]) - ph * mres[o, p]
                        mres[o, p] = ph * mres[o, p] + conv[o, 2, p] * e0
                        acc[0, p] += conv[o, 0, p]
                        acc[1, p] += e0 * e0 * conv[o, 1, p]
                else:
                    for p in range(K):
                        ph = phi[o, p]
                        e0 = (y - ysim[p]) - ph * mres[o, p]
                        mres[o, p] = ph * mres[o, p] + conv[o, 2, p] * e0
                        acc[0, p] += conv[o, 0, p]
                        acc[1, p] += e0 * e0 * conv[o, 1, p]
                        ph_b[p] = ph
                        g_b[p] = conv[o, 2, p]
                        iF_b[p] = conv[o, 1, p]
                        e_b[p] = e0 * conv[o, 1, p]
            else:
                d = kk - lk
                stat = lk >= 0 and d == 1
                for p in range(K):
                    if lk < 0:
                        phd = 0.0
                        Pp = s2[o, p]
                    else:
                        phd = phi[o, p] if d == 1 else phi[o, p] ** d
                        Pp = phd * phd * Pv[o, p] + s2[o, p] * (1.0 - phd * phd)
                    F = Pp + w2[o, p]
                    iF = 1.0 / F
                    g = Pp * iF
                    lF = _LOG2PI + math.log(F)
                    e0 = (y - ysim[p]) - phd * mres[o, p]
                    mres[o, p] = phd * mres[o, p] + g * e0
                    Pnew = Pp * w2[o, p] * iF
                    if abs(Pnew - Pv[o, p]) > 1e-13 * (Pnew + 1e-300):
                        stat = False
                    Pv[o, p] = Pnew
                    acc[0, p] += lF
                    acc[1, p] += e0 * e0 * iF
                    ph_b[p] = phd
                    g_b[p] = g
                    iF_b[p] = iF
                    e_b[p] = e0 * iF
                    conv[o, 0, p] = lF
                    conv[o, 1, p] = iF
                    conv[o, 2, p] = g
                if not stat:
                    conv[o, 0, 0] = np.nan
            for j in range(nba):
                for p in range(K):
                    e = Cz[o, j, p] * pw[j * K + p] - ph_b[p] * mbas[o, j, p]
                    mbas[o, j, p] = ph_b[p] * mbas[o, j, p] + g_b[p] * e
                    eb[j, p] = e
                    acc[3 + j, p] += e_b[p] * e
            for i in range(nba):
                for j in range(i + 1):
                    r = 3 + nb + i * nb + j
                    for p in range(K):
                        acc[r, p] += eb[i, p] * eb[j, p] * iF_b[p]
            last[o] = kk
        for i in range(Kn):
            z[i] = ad[i] * z[i] + W[k, i]
        if nba:
            for i in range(nba * K):
                pw[i] *= ad[i]
            # a free response decays geometrically but sticks at the smallest subnormal
            # (ad > 1/2 rounds it back up), where arithmetic is ~20x slower: below
            # 1e-280 it adds nothing to the sums, so it is flushed to zero
            j = nba - 1
            dead = True
            for p in range(K):
                if abs(pw[j * K + p]) < 1e-280:
                    pw[j * K + p] = 0.0
                else:
                    dead = False
            if dead:
                for o in range(n_out):
                    for p in range(K):
                        if abs(mbas[o, j, p]) < 1e-280:
                            mbas[o, j, p] = 0.0
                        else:
                            dead = False
            if dead:
                nba -= 1
    act[0] = nba
