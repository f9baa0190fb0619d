"""Residual diagnostics for the report: is the noise model adequate?

Pure numpy on residual series with gaps (NaN). The report plots, for each calibrated
output, the autocorrelation function and the cumulative periodogram of the residuals
:math:`e_t = y'_t - \\tilde y_t` (measured minus the posterior-median simulation) over the
calibration period, and of the *innovations* left after the AR(1) noise model,
:math:`w_t = e_t - \\varphi e_{t-1}`. An adequate noise model leaves white innovations:
autocorrelations inside :math:`\\pm 1.96/\\sqrt{n}` and a cumulative periodogram inside the
Kolmogorov–Smirnov band around the diagonal. The AR(1) model itself expects the residual
autocorrelation :math:`\\rho_k = \\varphi^k` (lag-1 correlation :math:`\\approx\\varphi`).

References
----------
.. [1] G.E.P. Box, G.M. Jenkins, G.C. Reinsel, G.M. Ljung, "Time Series Analysis:
   Forecasting and Control", 5th ed., Wiley (2015), sections 2.1.6 (autocorrelation
   standard errors) and 8.2.4 (cumulative periodogram check).
"""

from __future__ import annotations

import numpy as np

from heritage_bayes.inference.likelihoods import ar1_innovations as innovations

__all__ = ["acf", "cumulative_periodogram", "innovations"]


def acf(e: np.ndarray, max_lag: int) -> tuple[np.ndarray, np.ndarray, int]:
    """Sample autocorrelation of a series with gaps.

    Parameters
    ----------
    e : (N,) array
        Residuals; NaN marks missing values.
    max_lag : int
        Largest lag [steps].

    Returns
    -------
    lags : (L,) int array
        0 … ``max_lag`` (capped at N − 2).
    rho : (L,) array
        :math:`\\rho_k = \\sum r_t r_{t+k} / \\sum r_t^2` over the pairs where both values
        exist, with :math:`r` the mean-removed residuals (the usual biased estimator
        where no value is missing). NaN where no pair exists.
    n : int
        Number of finite residuals (the white-noise band is :math:`\\pm 1.96/\\sqrt n`).
    """
    e = np.asarray(e, dtype=float)
    ok = np.isfinite(e)
    n = int(ok.sum())
    max_lag = int(max(0, min(max_lag, e.size - 2)))
    lags = np.arange(max_lag + 1)
    if n < 3:
        return lags, np.full(lags.size, np.nan), n
    r = np.where(ok, e - e[ok].mean(), 0.0)
    denom = float(np.sum(r * r))
    rho = np.full(lags.size, np.nan)
    if denom <= 0:
        return lags, rho, n
    for k in lags:
        both = ok[: e.size - k] & ok[k:]
        if both.any():
            rho[k] = float(np.sum(r[: e.size - k] * r[k:])) / denom
    return lags, rho, n


def cumulative_periodogram(e: np.ndarray) -> tuple[np.ndarray, np.ndarray, float]:
    """Normalised cumulative periodogram of a series with gaps.

    Missing values are set to the mean (zero after centring), which adds no
    correlation; the series should be evenly spaced.

    Returns
    -------
    f : (q,) array
        Frequencies [cycles per step], :math:`k/N` for k = 1 … ⌊N/2⌋.
    c : (q,) array
        :math:`C_k = \\sum_{j\\le k} I_j / \\sum_j I_j`; a white series follows
        :math:`C(f) = 2f` (the diagonal from 0 to 1 at the Nyquist frequency 0.5).
    band : float
        Half-width of the 95 % Kolmogorov–Smirnov band around the diagonal,
        :math:`1.36/\\sqrt{q - 1}` (Box & Jenkins).
    """
    e = np.asarray(e, dtype=float)
    ok = np.isfinite(e)
    if ok.sum() < 4:
        return np.array([]), np.array([]), float("nan")
    r = np.where(ok, e - e[ok].mean(), 0.0)
    N = r.size
    spec = np.abs(np.fft.rfft(r)) ** 2
    spec = spec[1 : N // 2 + 1]
    f = np.arange(1, N // 2 + 1) / N
    total = spec.sum()
    c = np.cumsum(spec) / total if total > 0 else np.full(f.size, np.nan)
    q = f.size
    band = 1.36 / np.sqrt(q - 1) if q > 1 else float("nan")
    return f, c, float(band)
