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

What the rest of the package asks of a noise model instead of testing its name (the
findings, the predictive bands, the projection and the report):

- ``capped_kinds``: the parameter kinds whose prior's upper bound is a cap per time
  step (a MAP there is a finding about the model);
- ``free_run_reason(o, name, noise, params)``: why output ``o``'s predictive bands
  use the free-run error instead of this model, or None; ``free_run_model()`` the
  noise model whose parameters that error fills; ``free_run_note`` what the report says;
- ``residual_view(resid, median)``: what the model expects of an output's residuals
  (the innovations that should be white, the expected lag-1 autocorrelation in words).

References
----------
.. [1] G.E.P. Box, G.M. Jenkins, G.C. Reinsel, *Time Series Analysis*, 4th ed., Wiley,
   2008 (AR(1) exact likelihood).
.. [2] H. Madsen, *Time Series Analysis*, Chapman & Hall/CRC, 2007.
"""

from __future__ import annotations

import math
from collections.abc import Mapping
from types import MappingProxyType
from typing import NamedTuple

import numpy as np

from heritage_bayes.inference.noise_kernels import _ar1_sample, _fused_kf, _kf_kernel
from heritage_bayes.inference.priors import Prior
from heritage_bayes.names import NOISE_MODELS

__all__ = [
    "NOISE_MODELS",
    "AR1Noise",
    "AR1WhiteNoise",
    "IIDNoise",
    "NoiseModel",
    "ResidualView",
    "ar1_innovations",
    "ar1_white_innovations",
    "find_noise_model",
    "fit_free_run_error",
    "get_noise_model",
    "noise_parameter_names",
    "register_noise",
    "residual_noise_models",
]


class ResidualView(NamedTuple):
    """What a noise model expects of one output's residuals (the report's check)."""

    #: Posterior median of the AR(1) coefficient of the model error; None without one.
    phi: float | None
    #: What is white when the noise model is right (NaN where a value is missing).
    innovations: np.ndarray
    #: Share of the residual variance in the AR(1) part: the residuals' expected
    #: autocorrelation at lag k >= 1 is ``acf_scale * phi**k``.
    acf_scale: float
    #: The lag-1 autocorrelation the model expects, in words.
    expects: str
    #: What ``innovations`` are, in words.
    subject: str


class NoiseModel:
    """Base class: see the module docstring for the interface.

    All noise models here are special cases of one Gaussian residual process, AR(1)
    model error plus white measurement noise, evaluated exactly by a scalar Kalman
    filter: ``iid`` has no AR part, ``ar1`` no white part.
    """

    #: The name a section's ``noise:`` chooses (:func:`register_noise`).
    name = "base"
    #: One line for the references, the command line and the settings.
    description = ""
    kinds: tuple[str, ...] = ()
    #: A state-space model (the stochastic RC model's own Kalman filter): the
    #: log-posterior filters the model's states instead of its residuals, and the fit
    #: section shows its one-step-ahead band. Such a model provides ``filter``,
    #: ``one_step`` and ``sample_statespace``
    #: (:class:`~heritage_bayes.inference.statespace.KalmanNoise`).
    statespace = False
    #: What a parameter of each kind is, for the tables (followed by its output).
    descriptions: Mapping[str, str] = MappingProxyType(
        {
            "sigma": "marginal sd of the model error of",
            "phi": "AR(1) coefficient (per time step) of the model error of",
            "sigma_meas": "sd of the white measurement noise of",
        }
    )
    #: Parameter kinds whose prior's upper bound is a cap per time step: a MAP at the
    #: cap says the model misses a slow process (a finding, not a prior bound).
    capped_kinds: tuple[str, ...] = ()
    #: What the report says when the predictive bands use the free-run error instead
    #: of this model (:meth:`free_run_reason`).
    free_run_note = (
        " The noise model's own error model leaves out the slow misfit; the bands use "
        "the free-run error instead: "
    )

    def unit(self, kind: str, output_unit: str, potential: str) -> str:
        """The unit of a parameter of ``kind``: a standard deviation in its output's
        unit ([K] or [Pa]), a coefficient per time step [-]. ``potential``: the
        domain's ([K] or [Pa])."""
        return output_unit if kind.startswith("sigma") else "-"

    def priors_for(self, dt: float = 3600.0) -> dict:
        """Default priors per (domain, kind) that differ from the package's
        (:func:`~heritage_bayes.inference.priors.default_prior`), for time step ``dt``
        [s]; a kind of its own needs one here."""
        return {}

    def free_run_reason(self, o: int, name: str, noise: np.ndarray, params) -> str | None:
        """Why the predictive bands of output ``o`` (named ``name``) use the free-run
        error (:func:`fit_free_run_error`) instead of this model's draws, or None to
        keep them. ``noise`` (K, q): the noise values of the draws; ``params``: the
        noise model's :class:`~heritage_bayes.inference.parameters.Parameter`, in the
        same order (their priors)."""
        return None

    def free_run_model(self) -> NoiseModel:
        """The noise model whose parameters (``sigma``, ``phi``, ``sigma_meas``) the
        free-run error fills: AR(1) + white noise."""
        return AR1WhiteNoise()

    def residual_view(self, resid: np.ndarray, median) -> ResidualView:
        """What this model expects of an output's residuals ``resid`` (NaN where
        missing); ``median(kind, absent=None)``: the posterior median of the output's
        noise parameter of that kind (``absent`` if the run has none). Here, and for a
        model without an AR part: the residuals themselves are white."""
        return ResidualView(
            None,
            ar1_innovations(resid, 0.0),
            1.0,
            f"the {self.name} noise model expects ≈ 0",
            "the residuals",
        )

    def nominal(self, output: str, observed, room, model) -> dict[str, float]:
        """The values of output ``output``'s noise parameters that describe a record's
        realised errors (the truth a synthetic record is checked against).

        ``observed`` the readings, ``room`` the room's true state and ``model`` the
        noise-free model's output, (N,) arrays in the output's unit ([°C] or [Pa]),
        NaN where missing: the model error is ``room - model``, the reading error
        (sensor noise, rounding) ``observed - room``. A noise model with a white part
        (a parameter of kind ``sigma_meas``) describes the two apart: ``sigma`` and
        ``phi`` are the RMS and lag-1 autocorrelation of the model error, ``sigma_meas``
        the RMS of the reading error. One without describes their sum, ``observed -
        model``, by the AR(1) process of the same variance and lag-1 autocorrelation
        (nominal values: the sum is not exactly AR(1)). A parameter of another kind
        has no nominal value and is left out.
        """
        specs = self.parameter_specs((output,))
        white = any(kind == "sigma_meas" for _, kind, _ in specs)
        sigma, phi = _rms_lag1(room - model if white else observed - model)
        values = {"sigma": sigma, "phi": phi}
        if white:
            values["sigma_meas"] = _rms_lag1(observed - room)[0]
        return {name: values[kind] for name, kind, _ in specs if kind in values}

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


def register_noise(cls: type[NoiseModel]) -> type[NoiseModel]:
    """Register a noise model class under its ``name`` (a class decorator): the one
    place a noise model is listed. The command line's choices, the settings'
    validation of ``noise:``, the references and :func:`get_noise_model` read
    :data:`heritage_bayes.names.NOISE_MODELS`, which this fills.

    Raises
    ------
    ValueError
        ``cls.name`` is taken or not a lowercase identifier, or ``cls`` has no
        ``description`` of its own (not one inherited from the class it extends).
    """
    if not vars(cls).get("description"):
        raise ValueError(f"noise model {cls.name!r}: a description of its own is required")
    NOISE_MODELS.register(cls.name, cls)
    return cls


@register_noise
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
    description = "AR(1) model error + white sensor noise"
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

    capped_kinds = ("phi",)
    free_run_note = (
        " The noise model's correlation sits at its cap (about a day), so its error "
        "model leaves out the slow misfit; the bands use the free-run error instead: "
    )

    def priors_for(self, dt: float = 3600.0) -> dict:
        """Default priors that depend on the time step ``dt`` [s]: phi's cap."""
        cap = round(math.exp(-dt / 3600.0 / self.TAU_MAX_H), 4)
        return {(dom, "phi"): Prior("uniform", 0.0, cap) for dom in ("thermal", "hygric")}

    def free_run_reason(self, o, name, noise, params):
        """The median ``phi`` within 5 % of its cap's distance to 1: the model error
        describes only the misfit's fast part, and bands drawn from it would leave
        out the slow misfit."""
        i_phi = len(self.kinds) * o + self.kinds.index("phi")
        cap = params[i_phi].prior.upper
        if not np.median(noise[:, i_phi]) > cap - 0.05 * (1.0 - cap):
            return None
        return (
            f"phi_{name} at its cap {cap:g}: bands use the free-run error (AR(1) + "
            "white fitted to the calibration residuals of the posterior-median "
            "simulation)"
        )

    def free_run_model(self):
        return self

    def residual_view(self, resid, median):
        """The standardised one-step innovations of the AR(1) + white filter at the
        median parameters (:func:`ar1_white_innovations`)."""
        phi = median("phi")
        sigma, ph, w = (median(k, 0.0) for k in self.kinds)
        scale = sigma**2 / (sigma**2 + w**2)
        return ResidualView(
            phi,
            ar1_white_innovations(resid, sigma, ph, w),
            scale,
            f"the AR(1) + white noise model expects about {phi * scale:.2f}",
            "the standardised one-step innovations of the AR(1) + white model",
        )


@register_noise
class AR1Noise(NoiseModel):
    """Stationary Gaussian AR(1) errors: :math:`\\varepsilon_k = \\phi\\varepsilon_{k-1}
    + \\eta_k`, parameterised by the *marginal* standard deviation ``sigma_<output>``
    (:math:`\\mathrm{Var}\\,\\eta = \\sigma^2(1-\\phi^2)`) and ``phi_<output>``.

    The exact likelihood (first observation from the stationary distribution) handles
    gaps exactly: observations :math:`d` steps apart have conditional mean
    :math:`\\phi^d r_{prev}` and variance :math:`\\sigma^2(1-\\phi^{2d})`. Preferred to
    ``iid`` because hourly residuals of simple RC models are strongly autocorrelated and an iid
    likelihood makes posteriors and predictive bands overconfident.
    """

    name = "ar1"
    description = "a single AR(1) error"
    kinds = ("sigma", "phi")

    def residual_view(self, resid, median):
        """The AR(1) innovations :math:`e_t - \\varphi e_{t-1}` at the median
        :math:`\\varphi`."""
        phi = median("phi")
        if phi is None:
            return super().residual_view(resid, median)
        return ResidualView(
            phi,
            ar1_innovations(resid, phi),
            1.0,
            f"the AR(1) noise model expects ≈ φ = {phi:.2f}",
            "the innovations left after the AR(1) model",
        )


@register_noise
class IIDNoise(NoiseModel):
    """Independent Gaussian errors with standard deviation ``sigma_<output>``.

    Overconfident for hourly data with autocorrelated residuals: prefer ``ar1``.
    """

    name = "iid"
    description = "independent errors"
    kinds = ("sigma",)


def _rms_lag1(r: np.ndarray) -> tuple[float, float]:
    """RMS and lag-1 autocorrelation (about zero) of a series with NaNs."""
    ok = np.isfinite(r)
    sigma = float(np.sqrt(np.mean(r[ok] ** 2)))
    pair = ok[1:] & ok[:-1]
    num = float(np.sum(r[1:][pair] * r[:-1][pair]))
    den = float(np.sqrt(np.sum(r[1:][pair] ** 2) * np.sum(r[:-1][pair] ** 2)))
    return sigma, (num / den if den > 0 else 0.0)


def ar1_innovations(e: np.ndarray, phi: float) -> np.ndarray:
    """AR(1) innovations :math:`w_t = e_t - \\varphi e_{t-1}` (NaN where either is missing).

    The first value is NaN. ``phi = 0`` returns the residuals themselves (iid noise).
    """
    e = np.asarray(e, dtype=float)
    w = np.full(e.shape, np.nan)
    if e.size > 1:
        w[1:] = e[1:] - phi * e[:-1]
    if phi == 0:
        w[0] = e[0]
    return w


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


def find_noise_model(name: str | None) -> NoiseModel | None:
    """The noise model a run names, or None for a name this version does not know (a
    run written by another version)."""
    cls = NOISE_MODELS.get(name or "")
    return None if cls is None else cls()


def noise_parameter_names(name: str | None, output_names, state_names=()) -> frozenset[str]:
    """The names of the noise parameters of noise model ``name`` for a model's outputs
    and nodes (empty for a name this version does not know)."""
    nm = find_noise_model(name)
    if nm is None:
        return frozenset()
    return frozenset(n for n, _, _ in nm.parameter_specs(output_names, state_names))


def residual_noise_models() -> list[str]:
    """The registered noise models of the residuals (not ``statespace``), in the
    registry's order (the default first): those a model without a constant modal
    form (controlled, or coupled to a temperature) can take."""
    return [name for name, cls in NOISE_MODELS.items() if not cls.statespace]


def get_noise_model(name: str) -> NoiseModel:
    """Noise model by name (:data:`NOISE_MODELS`: ``"ar1_white"``, ``"ar1"``, ``"iid"``,
    ``"kalman"``, and any registered with :func:`register_noise`)."""
    try:
        return NOISE_MODELS[name]()
    except KeyError:
        raise ValueError(
            f"unknown noise model {name!r}; available: {sorted(NOISE_MODELS)}"
        ) from None
