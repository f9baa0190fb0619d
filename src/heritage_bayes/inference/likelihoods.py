"""Noise models: small strategy objects behind one interface.

A noise model turns simulated outputs and observations into a log-likelihood, batched
over parameter sets, with missing observations (NaN) masked, not interpolated. Each
output gets its own noise parameters (``sigma_<output>``, and ``phi_<output>`` for AR(1)).

Interface (what :class:`~heritage_bayes.inference.posterior.LogPosterior` calls):

- ``parameter_specs(output_names)`` -> list of (name, kind) with kind ``"sigma"`` or
  ``"phi"``; units follow the output (``sigma`` in [K] or [Pa], ``phi`` [-]);
- ``loglik(Ysim, Yobs, noise)`` -> (K,) log-likelihood, ``Ysim`` (K, N, n_out) simulated,
  ``Yobs`` (N, n_out) observed with NaN = missing/excluded, ``noise`` (K, q) values;
- ``pointwise(Ysim, Yobs, noise)`` -> (K, N, n_out) log-likelihood terms (NaN where
  missing) summing to ``loglik`` (for LOO);
- ``sample(rng, noise, N)`` -> (K, N, n_out) noise realisations for posterior predictive
  bands.

A Kalman-filter (stochastic state-space) likelihood fits the same interface: it would
also need the modal form and the inputs, which the posterior can pass as ``context``.

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

__all__ = ["NOISE_MODELS", "AR1Noise", "IIDNoise", "NoiseModel", "get_noise_model"]

_LOG2PI = math.log(2.0 * math.pi)


@numba.njit(cache=True, nogil=True)
def _ar1_kernel(Ysim, yobs, sigma, phi, point, want_point):  # pragma: no cover
    """Exact AR(1) Gaussian log-likelihood of residuals r = yobs - ysim with gaps.

    ``sigma`` is the *marginal* standard deviation of the residual process, so for two
    observations d steps apart the conditional mean is phi**d r_prev and the conditional
    variance sigma² (1 - phi**(2d)); the first observation has variance sigma².
    """
    K, N = Ysim.shape
    out = np.empty(K)
    for p in range(K):
        s2 = sigma[p] * sigma[p]
        ph = phi[p]
        tot = 0.0
        prev = 0.0
        last = -1
        for k in range(N):
            y = yobs[k]
            if y != y:  # NaN: missing or excluded
                if want_point:
                    point[p, k] = np.nan
                continue
            r = y - Ysim[p, k]
            if last < 0:
                m = 0.0
                v = s2
            else:
                d = k - last
                phd = ph if d == 1 else ph**d
                m = phd * prev
                v = s2 * (1.0 - phd * phd)
            e = r - m
            term = -0.5 * (_LOG2PI + math.log(v) + e * e / v)
            tot += term
            if want_point:
                point[p, k] = term
            prev = r
            last = k
        out[p] = tot
    return out


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


@numba.njit(cache=True, nogil=True)
def _fused_ar1(ad, W, z, Cz, yobs, k0, sigma, phi, prev, last, tot):  # pragma: no cover
    """Modal recursion + AR(1) log-likelihood in one pass over a block of rows.

    Mode-major layout so that the loops over parameter sets are contiguous (SIMD):
    ad, z (n*K,) with index j*K + p; W (Nb, n*K) forcing rows k0..k0+Nb-1;
    Cz (n_out, n, K); yobs (N, n_out) with NaN = excluded; sigma, phi, prev, tot
    (n_out, K); last (n_out,) index of the previous observation (shared by all
    parameter sets, since the observation mask is). Same likelihood as ``_ar1_kernel``.
    """
    Nb, Kn = W.shape
    n_out, n, K = Cz.shape
    s2 = sigma * sigma
    v1 = s2 * (1.0 - phi * phi)
    lv1 = np.log(v1) + _LOG2PI
    iv1 = 1.0 / v1
    acc = np.empty(K)
    for k in range(Nb):
        kk = k0 + k
        for o in range(n_out):
            y = yobs[kk, o]
            if y != y:
                continue
            acc[:] = 0.0
            for j in range(n):
                for p in range(K):
                    acc[p] += Cz[o, j, p] * z[j * K + p]
            lk = last[o]
            if lk >= 0 and kk - lk == 1:
                for p in range(K):
                    r = y - acc[p]
                    e = r - phi[o, p] * prev[o, p]
                    tot[o, p] -= 0.5 * (lv1[o, p] + e * e * iv1[o, p])
                    prev[o, p] = r
            else:
                for p in range(K):
                    r = y - acc[p]
                    if lk < 0:
                        v = s2[o, p]
                        e = r
                    else:
                        phd = phi[o, p] ** (kk - lk)
                        v = s2[o, p] * (1.0 - phd * phd)
                        e = r - phd * prev[o, p]
                    tot[o, p] -= 0.5 * (_LOG2PI + math.log(v) + e * e / v)
                    prev[o, p] = r
            last[o] = kk
        for i in range(Kn):
            z[i] = ad[i] * z[i] + W[k, i]


class NoiseModel:
    """Base class: see the module docstring for the interface."""

    name = "base"
    kinds: tuple[str, ...] = ()

    def parameter_specs(self, output_names) -> list[tuple[str, str, str]]:
        """[(parameter name, kind, output)] in the order of the noise vector."""
        return [(f"{k}_{o}", k, o) for o in output_names for k in self.kinds]

    def _split(self, noise: np.ndarray, o: int):
        q = len(self.kinds)
        sigma = np.ascontiguousarray(noise[:, q * o])
        phi = np.ascontiguousarray(noise[:, q * o + 1]) if q > 1 else np.zeros(noise.shape[0])
        return sigma, phi

    def loglik(self, Ysim, Yobs, noise, context=None) -> np.ndarray:
        K, _, n_out = Ysim.shape
        total = np.zeros(K)
        dummy = np.empty((1, 1))
        for o in range(n_out):
            sigma, phi = self._split(noise, o)
            total += _ar1_kernel(
                Ysim[:, :, o], np.ascontiguousarray(Yobs[:, o]), sigma, phi, dummy, False
            )
        return total

    def loglik_modal(self, mf, U, z0, Yobs, noise, max_block: int = 2**20) -> np.ndarray:
        """(K,) log-likelihood straight from a modal form, without storing outputs.

        Equivalent to ``loglik(modal_simulate(mf, U, z0), Yobs, noise)``, fused into one
        compiled pass over time (the hot path of the sampler).
        """
        K, n = mf.lam.shape
        n_out = mf.Cz.shape[1]
        q = len(self.kinds)
        # mode-major (j, p) layouts for the compiled pass
        sigma = np.ascontiguousarray(noise[:, 0::q][:, :n_out].T)
        phi = np.ascontiguousarray(noise[:, 1::q][:, :n_out].T) if q > 1 else np.zeros((n_out, K))
        Bcat = np.swapaxes(mf.Bdz, 0, 1).reshape(n * K, -1).T  # (m, n*K)
        ecat = mf.edz.T.reshape(n * K)
        ad = np.ascontiguousarray(mf.ad.T.reshape(n * K))
        z = np.ascontiguousarray(z0.T.reshape(n * K))
        Cz = np.ascontiguousarray(np.transpose(mf.Cz, (1, 2, 0)))
        Yobs = np.ascontiguousarray(Yobs)
        prev = np.zeros((n_out, K))
        last = np.full(n_out, -1, dtype=np.int64)
        tot = np.zeros((n_out, K))
        rows = max(256, max_block // max(K * n, 1))
        for k0 in range(0, U.shape[0], rows):
            W = U[k0 : k0 + rows] @ Bcat
            if ecat.any():
                W += ecat
            _fused_ar1(ad, W, z, Cz, Yobs, k0, sigma, phi, prev, last, tot)
        return tot.sum(axis=0)

    def pointwise(self, Ysim, Yobs, noise, context=None) -> np.ndarray:
        K, N, n_out = Ysim.shape
        out = np.empty((K, N, n_out))
        for o in range(n_out):
            sigma, phi = self._split(noise, o)
            point = np.empty((K, N))
            _ar1_kernel(Ysim[:, :, o], np.ascontiguousarray(Yobs[:, o]), sigma, phi, point, True)
            out[:, :, o] = point
        return out

    def sample(self, rng: np.random.Generator, noise: np.ndarray, N: int, n_out: int) -> np.ndarray:
        K = noise.shape[0]
        out = np.empty((K, N, n_out))
        for o in range(n_out):
            sigma, phi = self._split(noise, o)
            z = rng.standard_normal((K, N))
            e = np.empty((K, N))
            _ar1_sample(z, phi, sigma, e)
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


NOISE_MODELS: dict[str, type[NoiseModel]] = {"iid": IIDNoise, "ar1": AR1Noise}


def get_noise_model(name: str) -> NoiseModel:
    """Noise model by name (``"iid"`` or ``"ar1"``)."""
    try:
        return NOISE_MODELS[name]()
    except KeyError:
        raise ValueError(
            f"unknown noise model {name!r}; available: {sorted(NOISE_MODELS)}"
        ) from None
