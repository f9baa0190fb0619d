"""Noise models: small strategy objects behind one interface.

A noise model turns simulated outputs and observations into a log-likelihood, batched
over parameter sets, with missing observations (NaN) masked, not interpolated. Each
output gets its own noise parameters: ``sigma_<output>`` (all), ``phi_<output>`` (``ar1``,
``ar1_white``) and ``sigma_meas_<output>`` (``ar1_white``, the default).

The three are one Gaussian residual process, a stationary AR(1) model error plus white
measurement noise, evaluated exactly by a scalar Kalman filter (``_kf_kernel``,
``_fused_kf``): ``iid`` has no AR part, ``ar1`` no white part. The fused pass also
returns the statistics with which :class:`~heritage_bayes.inference.posterior.LogPosterior`
integrates the initial state out exactly.

Interface (what :class:`~heritage_bayes.inference.posterior.LogPosterior` calls):

- ``parameter_specs(output_names, state_names=())`` -> list of (name, kind, output) with kind
  ``"sigma"``, ``"phi"`` or ``"sigma_meas"``; units follow the output (``sigma``,
  ``sigma_meas`` in [K] or [Pa], ``phi`` [-] per time step);
- ``loglik(Ysim, Yobs, noise)`` -> (K,) log-likelihood, ``Ysim`` (K, N, n_out) simulated,
  ``Yobs`` (N, n_out) observed with NaN = missing/excluded, ``noise`` (K, q) values;
- ``pointwise(Ysim, Yobs, noise)`` -> (K, N, n_out) log-likelihood terms (NaN where
  missing) summing to ``loglik`` (for LOO);
- ``sample(rng, noise, N)`` -> (K, N, n_out) noise realisations for posterior predictive
  bands.

- ``filter_modal(mf, U, z0, Yobs, noise, basis=...)`` -> sufficient statistics straight
  from a modal form (the sampler's hot path), ``loglik_modal`` their log-likelihood.

References
----------
.. [1] G.E.P. Box, G.M. Jenkins, G.C. Reinsel, *Time Series Analysis*, 4th ed., Wiley,
   2008 (AR(1) exact likelihood).
.. [2] H. Madsen, *Time Series Analysis*, Chapman & Hall/CRC, 2007.
"""

from __future__ import annotations

import math

import numba
import numpy as np

from heritage_bayes.inference.priors import Prior
from heritage_bayes.names import NOISE_MODELS as DECLARED

__all__ = [
    "NOISE_MODELS",
    "AR1Noise",
    "AR1WhiteNoise",
    "IIDNoise",
    "NoiseModel",
    "ar1_white_innovations",
    "fit_free_run_error",
    "get_noise_model",
    "register_noise",
]

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


class NoiseModel:
    """Base class: see the module docstring for the interface.

    All noise models here are special cases of one Gaussian residual process, AR(1)
    model error plus white measurement noise, evaluated exactly by a scalar Kalman
    filter: ``iid`` has no AR part, ``ar1`` no white part.
    """

    name = "base"
    kinds: tuple[str, ...] = ()

    def parameter_specs(self, output_names, state_names=()) -> list[tuple[str, str, str]]:
        """[(parameter name, kind, output)] in the order of the noise vector.

        ``state_names`` (the model's nodes) is taken by every noise model so that callers
        need not ask which kind they hold: the residual models here have no per-node
        parameter, ``kalman`` has its process noise ``q_<node>``."""
        return [(f"{k}_{o}", k, o) for o in output_names for k in self.kinds]

    def _split(self, noise: np.ndarray, o: int):
        """(sigma, phi, sigma_meas) of output ``o``, each (K,) (zeros where absent)."""
        q = len(self.kinds)
        zero = np.zeros(noise.shape[0])
        return tuple(
            np.ascontiguousarray(noise[:, q * o + self.kinds.index(k)]) if k in self.kinds else zero
            for k in ("sigma", "phi", "sigma_meas")
        )

    def loglik(self, Ysim, Yobs, noise, context=None) -> np.ndarray:
        K, _, n_out = Ysim.shape
        total = np.zeros(K)
        dummy = np.empty((1, 1))
        for o in range(n_out):
            sigma, phi, w = self._split(noise, o)
            yo = np.ascontiguousarray(Yobs[:, o])
            total += _kf_kernel(
                np.ascontiguousarray(Ysim[:, :, o]), yo, sigma, phi, w, dummy, False
            )
        return total

    def filter_modal(
        self, mf, U, z0, Yobs, noise, *, basis: bool = False, max_block: int = 2**20
    ) -> np.ndarray:
        """Sufficient statistics of the log-likelihood straight from a modal form.

        One compiled pass over time: the modal recursion from ``z0`` (K, n), the noise
        filter, and with ``basis=True`` the statistics of the free responses of the n
        modal initial offsets (see ``_fused_kf``), from which the initial state is
        estimated or integrated out exactly.

        Returns
        -------
        (3 + nb + nb², K) array
            Row 0: sum of log(2 pi F); row 1: sum of e²/F; rows 3..3+nb: g; then the
            lower triangle of H (row-major, nb × nb). nb = n if ``basis`` else 0.
        """
        K, n = mf.lam.shape
        n_out = mf.Cz.shape[1]
        nb = n if basis else 0
        pars = [self._split(noise, o) for o in range(n_out)]
        sigma, phi, w = (np.ascontiguousarray(np.stack([p[i] for p in pars])) for i in range(3))
        Bcat = np.swapaxes(mf.Bdz, 0, 1).reshape(n * K, -1).T  # (m, n*K)
        ecat = mf.edz.T.reshape(n * K)
        ad = np.ascontiguousarray(mf.ad.T.reshape(n * K))
        z = np.ascontiguousarray(z0.T.reshape(n * K))
        pw = np.ones(n * K)
        Cz = np.ascontiguousarray(np.transpose(mf.Cz, (1, 2, 0)))
        Yobs = np.ascontiguousarray(Yobs)
        mres = np.zeros((n_out, K))
        mbas = np.zeros((n_out, nb, K))
        Pv = np.zeros((n_out, K))
        last = np.full(n_out, -1, dtype=np.int64)
        conv = np.full((n_out, 3, K), np.nan)
        act = np.array([nb], dtype=np.int64)
        acc = np.zeros((3 + nb + nb * nb, K))
        rows = max(256, max_block // max(K * n, 1))
        for k0 in range(0, U.shape[0], rows):
            W = U[k0 : k0 + rows] @ Bcat
            if ecat.any():
                W += ecat
            _fused_kf(
                ad, W, z, pw, Cz, Yobs, k0, sigma, phi, w, mres, mbas, Pv, last, conv, act, acc
            )
        return acc

    def loglik_modal(self, mf, U, z0, Yobs, noise, max_block: int = 2**20) -> np.ndarray:
        """(K,) log-likelihood straight from a modal form, without storing outputs.

        Equivalent to ``loglik(modal_simulate(mf, U, z0), Yobs, noise)``, fused into one
        compiled pass over time (the hot path of the sampler).
        """
        acc = self.filter_modal(mf, U, z0, Yobs, noise, max_block=max_block)
        return -0.5 * (acc[0] + acc[1])

    def pointwise(self, Ysim, Yobs, noise, context=None) -> np.ndarray:
        K, N, n_out = Ysim.shape
        out = np.empty((K, N, n_out))
        for o in range(n_out):
            sigma, phi, w = self._split(noise, o)
            point = np.empty((K, N))
            _kf_kernel(
                np.ascontiguousarray(Ysim[:, :, o]),
                np.ascontiguousarray(Yobs[:, o]),
                sigma,
                phi,
                w,
                point,
                True,
            )
            out[:, :, o] = point
        return out

    def sample(self, rng: np.random.Generator, noise: np.ndarray, N: int, n_out: int) -> np.ndarray:
        K = noise.shape[0]
        out = np.empty((K, N, n_out))
        for o in range(n_out):
            sigma, phi, w = self._split(noise, o)
            z = rng.standard_normal((K, N))
            e = np.empty((K, N))
            _ar1_sample(z, phi, sigma, e)
            if "sigma_meas" in self.kinds:
                e += w[:, None] * rng.standard_normal((K, N))
            out[:, :, o] = e
        return out


class IIDNoise(NoiseModel):
    """Independent Gaussian errors with standard deviation ``sigma_<output>``.

    Overconfident for hourly data with autocorrelated residuals: prefer ``ar1``.
    """

    name = "iid"
    kinds = ("sigma",)


class AR1Noise(NoiseModel):
    """Stationary Gaussian AR(1) errors: :math:`\\varepsilon_k = \\phi\\varepsilon_{k-1}
    + \\eta_k`, parameterised by the *marginal* standard deviation ``sigma_<output>``
    (:math:`\\mathrm{Var}\\,\\eta = \\sigma^2(1-\\phi^2)`) and ``phi_<output>``.

    The exact likelihood (first observation from the stationary distribution) handles
    gaps exactly: observations :math:`d` steps apart have conditional mean
    :math:`\\phi^d r_{prev}` and variance :math:`\\sigma^2(1-\\phi^{2d})`. The default,
    because hourly residuals of simple RC models are strongly autocorrelated and an iid
    likelihood makes posteriors and predictive bands overconfident.
    """

    name = "ar1"
    kinds = ("sigma", "phi")


class AR1WhiteNoise(NoiseModel):
    """Model error plus sensor noise: a latent stationary AR(1) process
    :math:`\\eta_k` (marginal sd ``sigma_<output>``, coefficient ``phi_<output>``) plus
    white measurement noise :math:`\\varepsilon_k` (sd ``sigma_meas_<output>``):
    :math:`r_k = \\eta_k + \\varepsilon_k`.

    This is the shape of real logs: a slowly varying model error (what the RC model
    does not resolve: an unmodelled heat source, a wrong solar aperture on one day) on
    top of the logger's own noise and rounding. A single AR(1) fitted to such residuals
    estimates a compromise coefficient (0.4-0.75 where 0.90-0.95 was
    generated) and under-weights slow errors: its intervals come out too narrow. The exact
    likelihood is a scalar Kalman filter on the residual process (ARMA(1,1) in
    disguise [1]_, [3]_), exact across gaps; its cost is one more division and
    logarithm per observation than AR(1).

    References
    ----------
    .. [3] J. Durbin, S.J. Koopman, *Time Series Analysis by State Space Methods*,
       2nd ed., Oxford University Press, 2012, ch. 4.
    """

    name = "ar1_white"
    kinds = ("sigma", "phi", "sigma_meas")
    #: The model error's correlation time tau_e = -dt/ln(phi) is capped at about a day
    #: (24.5 h: phi <= 0.96 at hourly steps, 0.98 at half-hourly ones). Without a cap the
    #: likelihood prefers a near-random-walk error that carries the slow (seasonal)
    #: response while the simulated room goes flat (measured: docs/science/noise.md,
    #: "Figures behind the code's choices"). What persists for longer than a day is the
    #: model's to explain; a posterior
    #: piled up at the cap says the model misses a slow process (the run says so).
    #: Override with a prior on ``phi_<output>``.
    TAU_MAX_H = 24.5

    def priors_for(self, dt: float = 3600.0) -> dict:
        """Default priors that depend on the time step ``dt`` [s]: phi's cap."""
        cap = round(math.exp(-dt / 3600.0 / self.TAU_MAX_H), 4)
        return {(dom, "phi"): Prior("uniform", 0.0, cap) for dom in ("thermal", "hygric")}


def ar1_white_innovations(e: np.ndarray, sigma: float, phi: float, w: float) -> np.ndarray:
    """Standardised one-step innovations of ``ar1_white`` (AR(1) error of marginal sd
    ``sigma`` and coefficient ``phi`` plus white noise of sd ``w``): the scalar Kalman
    filter of :class:`heritage_bayes.inference.likelihoods.AR1WhiteNoise`, exact across
    gaps (NaN where a value is missing). White, unit variance if the noise model is
    right. ``ar1`` is ``w = 0``, ``iid`` is ``phi = w = 0``.
    """
    e = np.asarray(e, dtype=float)
    out = np.full(e.shape, np.nan)
    s2, w2 = sigma * sigma, w * w
    m, P, last = 0.0, s2, -1
    for k in range(e.size):
        if not np.isfinite(e[k]):
            continue
        if last < 0:
            mp, Pp = 0.0, s2
        else:
            phd = phi ** (k - last)
            mp, Pp = phd * m, phd * phd * P + s2 * (1.0 - phd * phd)
        F = Pp + w2
        v = e[k] - mp
        out[k] = v / np.sqrt(F)
        g = Pp / F
        m, P, last = mp + g * v, Pp * w2 / F, k
    return out


#: The implementations of the noise models declared in
#: :data:`heritage_bayes.names.NOISE_MODELS` (name -> class), filled by
#: :func:`register_noise`.
NOISE_MODELS: dict[str, type[NoiseModel]] = {}


def register_noise(cls: type[NoiseModel]) -> type[NoiseModel]:
    """Register a noise model class under its declared ``name`` (a class decorator).

    Raises
    ------
    ValueError
        ``cls.name`` is not declared in :data:`heritage_bayes.names.NOISE_MODELS`
        (:func:`heritage_bayes.names.declare_noise`), or already has a class.
    """
    if cls.name not in DECLARED or cls.name in NOISE_MODELS:
        raise ValueError(
            f"noise model {cls.name!r}: declare its name first "
            "(heritage_bayes.names.declare_noise), once"
        )
    NOISE_MODELS[cls.name] = cls
    return cls


for _cls in (IIDNoise, AR1Noise, AR1WhiteNoise):
    register_noise(_cls)


def fit_free_run_error(residual: np.ndarray, phi_max: float = 0.999) -> dict[str, float]:
    """Maximum-likelihood AR(1) + white parameters of a free-run residual series.

    The error model of *prediction*: with the model's parameters fixed, the residual of
    its free-run simulation (gaps as NaN) is described by an AR(1) error (marginal sd
    ``sigma``, coefficient ``phi`` up to ``phi_max``) plus white noise ``sigma_meas``.
    Fitted after calibration, it cannot flatten the model (the model is fixed), so its
    correlation need not be capped; its marginal sd is the size of the slow misfit that
    a capped noise model leaves out of its bands.
    """
    from scipy.optimize import minimize

    r = np.ascontiguousarray(residual, dtype=float)
    ok = np.isfinite(r)
    if ok.sum() < 10:
        raise ValueError("fewer than 10 finite residuals to fit a free-run error model")
    ysim = np.zeros((1, r.size))  # the residual is the series itself
    dummy = np.empty((1, 1))
    sd = float(np.sqrt(np.mean(r[ok] ** 2)))

    def unpack(x):
        return (
            np.array([math.exp(x[0])]),
            np.array([phi_max / (1.0 + math.exp(-x[1]))]),
            np.array([math.exp(x[2])]),
        )

    def nll(x):
        sigma, phi, w = unpack(x)
        v = -_kf_kernel(ysim, r, sigma, phi, w, dummy, False)
        return float(v[0]) if np.isfinite(v[0]) else 1e300

    best = None
    for phi0 in (0.5, 0.9, 0.99):
        x0 = [math.log(sd), math.log(phi0 / (phi_max - phi0)), math.log(0.2 * sd)]
        res = minimize(
            nll, x0, method="Nelder-Mead", options={"xatol": 1e-6, "fatol": 1e-6, "maxiter": 4000}
        )
        if best is None or res.fun < best.fun:
            best = res
    sigma, phi, w = unpack(best.x)
    return {
        "sigma": float(sigma[0]),
        "phi": float(phi[0]),
        "sigma_meas": float(w[0]),
        "log_likelihood": float(-best.fun),
    }


def get_noise_model(name: str) -> NoiseModel:
    """Noise model by name (:data:`NOISE_MODELS`: ``"ar1_white"``, ``"ar1"``, ``"iid"``,
    ``"kalman"``, and any registered with :func:`register_noise`)."""
    # "kalman" (inference/statespace.py) registers itself in NOISE_MODELS; the package
    # imports that module, so no import back from here (no import cycle)
    try:
        return NOISE_MODELS[name]()
    except KeyError:
        raise ValueError(
            f"unknown noise model {name!r}; available: {sorted(NOISE_MODELS)}"
        ) from None
