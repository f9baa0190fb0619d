"""The likelihood of a thermo-hygric coupled model: its exact recursion and the noise
filter in one compiled pass.

A :class:`~heritage_bayes.rc.sorption.CoupledHygricModel` is linear time-varying in its
states given the temperatures, so it has no constant modal form for
:meth:`~heritage_bayes.inference.likelihoods.NoiseModel.filter_modal`. This module runs
its per-step transitions (:func:`heritage_bayes.rc.sorption.coupled_block`) through the
same Gaussian residual filter (stationary AR(1) model error plus white measurement
noise, exact across gaps) and returns the same sufficient statistics, with the basis of
the initial state in **physical** coordinates: the output is linear in the initial state
given the temperatures (the transitions do not depend on it), so the free responses of
the unit offsets of each node, propagated by the same transitions, give the gradient g
and curvature H with which :class:`~heritage_bayes.inference.posterior.LogPosterior`
integrates the initial state out exactly, as it does for the linear models.
"""

from __future__ import annotations

import math

import numba
import numpy as np

from heritage_bayes.inference import likelihoods
from heritage_bayes.inference.noise_kernels import ar1_predict
from heritage_bayes.rc import isotherm, sorption
from heritage_bayes.rc.isotherm import N_CELLS, ROW, gab_block, table_constants
from heritage_bayes.rc.sorption import BLOCK, coupled_block

__all__ = ["FIRST_PASS_STOP", "coupled_filter_stats"]

_LOG2PI = math.log(2.0 * math.pi)

#: Size [Pa per Pa of offset] of the initial state's free responses (and their filter
#: means) below which the first of the likelihood's two passes about a GAB buffer's
#: trajectory ends a walker's recursion (``stop`` of :func:`coupled_filter_stats`): the
#: steps after it would add to the start's gradient and curvature terms each below
#: this size relative to the first steps' and decaying at the buffer's own rate, so
#: that their sum is of that order times the steps the tail takes to decay.
FIRST_PASS_STOP = 1e-15
#: Steps per block of a recursion with a ``stop``: its free responses are checked at
#: each block's start (the transitions of the block's later steps are already computed).
STOP_BLOCK = 256


@numba.njit(cache=True, nogil=True, error_model="numpy", fastmath={"contract"})
def _coupled_kf(kp, ks, sb, slope, dt, x0, yobs, sigma, phi, w, nb, stop, acc):  # pragma: no cover
    """Recursion + residual filter + initial-state statistics of every walker.

    kp (K, 7) kernel parameters; ks (K,) the buffer's GAB multilayer factors
    (:func:`heritage_bayes.rc.isotherm.gab_block`, its transitions per step from the
    state; 0: the linear buffer) or an empty array; sb, slope: the step series of
    :meth:`~heritage_bayes.rc.sorption.CoupledHygricModel.series`; x0 (K, 2) initial
    states [Pa]; yobs (N,) observed ``Pi`` (NaN = excluded); sigma, phi, w (K,) noise
    parameters; nb: 2 (basis of both nodes) or 0; stop: 0, or end a walker's
    recursion at the first block (of :data:`STOP_BLOCK` steps) where its free
    responses have all fallen below ``stop`` [Pa per Pa] (the start's g, H complete;
    the log-likelihood then covers only the steps run); acc (3 + nb + nb², K), zeros, as
    :meth:`NoiseModel.filter_modal` (rows: sum log 2πF, sum e²/F, the steps run, g,
    lower triangle of H), in physical coordinates.
    """
    K = kp.shape[0]
    N = sb.shape[1]
    span = BLOCK if stop <= 0.0 else STOP_BLOCK  # steps between checks of the responses
    Mf = np.empty((6, BLOCK))
    tab = np.empty((N_CELLS, ROW))  # reserved, its rows written when first reached
    built = np.zeros(N_CELLS, dtype=np.bool_)
    st = np.empty(3)  # the GAB buffer's recursion: Pw, Pi, Pw a step earlier
    scratch = np.empty(BLOCK)
    for p in range(K):
        gab = ks.size > 0 and ks[p] > 0.0
        tc = table_constants(kp[p], ks[p] if gab else 0.0)
        built[:] = False
        st[0], st[1], st[2] = x0[p, 0], x0[p, 1], x0[p, 0]
        s2 = sigma[p] * sigma[p]
        w2 = w[p] * w[p]
        ph = phi[p]
        xw = x0[p, 0]
        xi = x0[p, 1]
        # free responses of unit offsets of Pw (u) and Pi (v), their filter means
        uw, ui, vw, vi = 1.0, 0.0, 0.0, 1.0
        mu = 0.0
        mv = 0.0
        m = 0.0
        Pv = 0.0
        last = -1
        conv = False
        lF = 0.0
        iF = 0.0
        g = 0.0
        a0 = 0.0
        a1 = 0.0
        gu = 0.0
        gv = 0.0
        huu = 0.0
        hvu = 0.0
        hvv = 0.0
        alive = nb > 0
        run = N
        for k0 in range(0, N, span):
            B = min(span, N - k0)
            if gab:
                gab_block(tc, tab, built, sb[:, k0:], B, dt, slope, st, Mf, scratch)
            else:
                coupled_block(kp[p], sb, dt, slope, k0, B, Mf)
            if alive:
                size = max(abs(uw), abs(ui), abs(vw), abs(vi), abs(mu), abs(mv))
                if size < stop:
                    run = k0
                    break
                # a free response that has decayed below 1e-280 Pa adds nothing: stop
                # it (else it sticks at the smallest subnormal, 20x slower arithmetic)
                if size < 1e-280:
                    alive = False
            for b in range(B):
                k = k0 + b
                y = yobs[k]
                if y == y:
                    if last >= 0 and k - last == 1 and conv:
                        phd = ph
                    else:
                        phd, Pp = ar1_predict(last, k, ph, Pv, s2)
                        F = Pp + w2
                        iF = 1.0 / F
                        g = Pp * iF
                        lF = _LOG2PI + math.log(F)
                        Pn = Pp * w2 * iF
                        conv = last >= 0 and k - last == 1 and abs(Pn - Pv) <= 1e-13 * Pn
                        Pv = Pn
                    e0 = (y - xi) - phd * m
                    m = phd * m + g * e0
                    a0 += lF
                    a1 += e0 * e0 * iF
                    if alive:
                        eu = ui - phd * mu
                        ev = vi - phd * mv
                        mu = phd * mu + g * eu
                        mv = phd * mv + g * ev
                        e0i = e0 * iF
                        gu += e0i * eu
                        gv += e0i * ev
                        huu += eu * eu * iF
                        hvu += ev * eu * iF
                        hvv += ev * ev * iF
                    last = k
                m0, m1, m2, m3, f0, f1 = Mf[0, b], Mf[1, b], Mf[2, b], Mf[3, b], Mf[4, b], Mf[5, b]
                xw, xi = m0 * xw + m1 * xi + f0, m2 * xw + m3 * xi + f1
                if alive:
                    uw, ui = m0 * uw + m1 * ui, m2 * uw + m3 * ui
                    vw, vi = m0 * vw + m1 * vi, m2 * vw + m3 * vi
        acc[0, p] = a0
        acc[1, p] = a1
        acc[2, p] = run
        if nb > 0:  # g (2), then the lower triangle of H (row-major 2 x 2)
            acc[3, p] = gu
            acc[4, p] = gv
            acc[5, p] = huu
            acc[7, p] = hvu
            acc[8, p] = hvv


def coupled_filter_stats(model, P, series, x0, Yobs, noise_model, noise, *, basis, dt, stop=0.0):
    """Sufficient statistics of the log-likelihood of a coupled model (the layout of
    :meth:`~heritage_bayes.inference.likelihoods.NoiseModel.filter_modal`, the basis in
    physical coordinates: the node order of ``model.state_names``).

    Parameters
    ----------
    model : CoupledHygricModel
    P : (K, n_params) array
        Model parameters, SI units.
    series : tuple
        :meth:`~heritage_bayes.rc.sorption.CoupledHygricModel.series` of the inputs.
    x0 : (K, 2) array
        Initial states [Pa] (the prior mean).
    Yobs : (N, 1) array
        Observed ``Pi`` [Pa], NaN where missing or excluded.
    noise_model : NoiseModel
        A residual noise model (``iid``, ``ar1``, ``ar1_white``).
    noise : (K, q) array
        Its parameter values.
    basis : bool
        Also the statistics of the initial state's free responses.
    dt : float
        Time step [s].
    stop : float
        0 (the whole record), or the size [Pa per Pa of offset] of the initial state's
        free responses and their filter means below which a walker's recursion ends:
        its gradient and curvature (rows ``3..``) are then complete to terms of that
        relative size, its log-likelihood (rows 0, 1) covers only the steps run (row 2:
        their number). For the first of two passes, of which only the conditional
        mean of the start is kept.
    """
    K = P.shape[0]
    nb = 2 if basis else 0
    sigma, phi, w = noise_model._split(noise, 0)
    acc = np.zeros((3 + nb + nb * nb, K))
    x = np.ascontiguousarray(np.where(np.isfinite(x0), x0, 0.0))
    ks = model.shape(P) if model.isotherm == "gab" else np.empty(0)
    _coupled_kf(
        model.kernel_parameters(P),
        np.ascontiguousarray(ks, dtype=float),
        *series,
        float(dt),
        x,
        np.ascontiguousarray(Yobs[:, 0]),
        sigma,
        phi,
        w,
        nb,
        float(stop),
        acc,
    )
    return acc


sorption.stamp_cache(globals(), sorption, isotherm, sorption._vecmath, likelihoods)
