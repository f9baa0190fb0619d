"""Initial state integrated out, and the AR(1) + white noise model (issue 10).

The log-likelihood with the initial state integrated out is compared with a dense
multivariate normal log-density of the same problem (the initial-state prior adds
``s0² S Sᵀ`` to the noise covariance, S the free responses), and the ``ar1_white``
filter with statsmodels' unobserved-components model (AR(1) + irregular): both to
1e-8 relative, with gaps.
"""

from __future__ import annotations

import dataclasses
import math
from pathlib import Path

import numpy as np
import pandas as pd
import pytest
from scipy.stats import multivariate_normal

import heritage_bayes as hb
from heritage_bayes.errors import ConfigError
from heritage_bayes.inference.likelihoods import get_noise_model
from heritage_bayes.inference.parameters import parameters_for
from heritage_bayes.inference.posterior import LogPosterior
from heritage_bayes.rc.discretize import modal_form

TRUTH = {"Cw": 2e7, "Ci": 1e6, "Gw": 60.0, "Gi": 400.0, "Gfast": 30.0, "Gf": 5.0}
NOISE = {"sigma_Ti": 0.4, "phi_Ti": 0.85, "sigma_meas_Ti": 0.15}


def _inputs(n: int, seed: int = 0) -> np.ndarray:
    rng = np.random.default_rng(seed)
    t = np.arange(n)
    te = 8 + 6 * np.sin(2 * np.pi * t / 24) + np.cumsum(rng.normal(0, 0.3, n))
    return np.column_stack([te, np.full(n, 9.0)])


def _problem(noise_name, mode, n=240, seed=1):
    m = hb.model("thermal_2c", surfaces=())
    U = _inputs(n, seed)
    rng = np.random.default_rng(seed)
    y = rng.normal(12, 1.5, (n, 1))
    y[40:60] = np.nan
    y[::9] = np.nan
    noise = get_noise_model(noise_name)
    ps = parameters_for(m, noise, room_volume=200)
    lp = LogPosterior(
        m, ps, noise, U, y, warmup=0, init_window=48, initial_state=mode, initial_state_sd=2.5
    )
    theta = np.array([{**TRUTH, **NOISE}[k] for k in ps.names])
    return lp, theta


def _start_cov(lp: LogPosterior, tm: np.ndarray) -> np.ndarray:
    """Prior covariance of the free start deviation, from the eigen-decomposition of
    the continuous A (independent of the modal form): s0² (W W^T) on the free block,
    W = V diag(a) V⁻¹, a = (1 + (τ/h)²)^-1/2."""
    A = lp.model.state_space(dict(zip(lp.model.parameter_names, tm, strict=True)))[0]
    w, V = np.linalg.eig(A)
    tau = -1.0 / w.real
    a = 1.0 / np.sqrt(1.0 + (tau / lp.initial_state_horizon) ** 2)
    W = (V * a) @ np.linalg.inv(V)
    f = lp.x0_free
    P = lp.initial_state_sd**2 * (W @ W.T).real
    return P[np.ix_(f, f)] + (1e-6 * lp.initial_state_sd) ** 2 * np.eye(f.size)


def _dense(lp: LogPosterior, theta: np.ndarray) -> float:
    """The same log-likelihood as one multivariate normal density (reference)."""
    m, U, y = lp.model, lp.inputs, lp.observed[:, 0]
    tm = theta[: lp.n_model]
    noise = dict(zip(lp.params.names[lp.n_model :], theta[lp.n_model :], strict=True))
    xm = lp._x0_mean(modal_form(m, tm[None], lp.dt))[0]
    y0 = m.forward(tm[None], U, lp.dt, x0=xm[None])[0][0, :, 0]
    S = []
    for i in lp.x0_free:
        e = np.zeros(xm.size)
        e[i] = 1.0
        S.append(m.forward(tm[None], U, lp.dt, x0=(xm + e)[None])[0][0, :, 0] - y0)
    S = np.array(S).T if S else np.zeros((y0.size, 0))
    idx = np.flatnonzero(np.isfinite(y))
    lag = np.abs(idx[:, None] - idx[None, :])
    cov = noise["sigma_Ti"] ** 2 * noise.get("phi_Ti", 0.0) ** lag
    cov = cov + noise.get("sigma_meas_Ti", 0.0) ** 2 * np.eye(idx.size)
    cov = cov + S[idx] @ _start_cov(lp, tm) @ S[idx].T
    return float(multivariate_normal(y0[idx], cov).logpdf(y[idx]))


@pytest.mark.parametrize("noise_name", ["iid", "ar1", "ar1_white"])
@pytest.mark.parametrize("mode", ["estimate", "steady", {"Ti": 11.0}])
def test_integrated_likelihood_equals_dense_gaussian(noise_name, mode):
    lp, theta = _problem(noise_name, mode)
    ll = lp.log_likelihood(theta[None])[0]
    ref = _dense(lp, theta)
    assert ll == pytest.approx(ref, rel=1e-8, abs=1e-8)


def test_ar1_white_matches_statsmodels_unobserved_components():
    sm = pytest.importorskip("statsmodels.api")
    lp, theta = _problem("ar1_white", "steady", n=400, seed=3)
    tm = theta[: lp.n_model]
    ysim = lp.simulate(tm[None])[0][0, :, 0]
    r = lp.observed[:, 0] - ysim
    uc = sm.tsa.UnobservedComponents(r, irregular=True, autoregressive=1)
    s, ph, w = NOISE["sigma_Ti"], NOISE["phi_Ti"], NOISE["sigma_meas_Ti"]
    # statsmodels: irregular variance, AR innovation variance, AR coefficient
    ref = uc.loglike(np.array([w**2, s**2 * (1 - ph**2), ph]))
    ll = lp.log_likelihood(theta[None])[0]
    assert ll == pytest.approx(ref, rel=1e-8)


def test_estimated_initial_state_recovers_a_start_far_from_equilibrium():
    """A slow envelope 6 K colder than the steady state of its first month: the
    estimated start finds it (within its interval) and the static gain stays unbiased;
    the steady-state start without warm-up does not."""
    m = hb.model("thermal_2c", surfaces=())
    n = 24 * 60
    U = _inputs(n, seed=5)
    tm = np.array([TRUTH[k] for k in m.parameter_names])
    mf = modal_form(m, tm[None], 3600.0)
    x_ss = np.einsum("kij,kj->ki", mf.T, mf.steady_state_modal(U[:720].mean(axis=0)))[0]
    x_true = x_ss + np.array([-6.0, -3.0])
    y = m.forward(tm[None], U, 3600.0, x0=x_true[None])[0][0]
    y = y + np.random.default_rng(9).normal(0, 0.1, y.shape)
    noise = get_noise_model("iid")
    ps = parameters_for(m, noise, room_volume=200)
    theta = np.append(tm, 0.1)
    lp = LogPosterior(m, ps, noise, U, y, warmup=0, initial_state="estimate")
    x0 = lp.initial_states(theta[None])[0]
    Tw = m.state_names.index("Tw")
    assert abs(x0[Tw] - x_true[Tw]) < 0.5
    steady = LogPosterior(m, ps, noise, U, y, warmup=0, initial_state="steady")
    assert lp.log_likelihood(theta[None])[0] > steady.log_likelihood(theta[None])[0] + 100
    # draws of the initial state scatter around the conditional mean
    draws = np.array(
        [lp.initial_states(theta[None], np.random.default_rng(s))[0] for s in range(200)]
    )
    assert abs(draws[:, Tw].mean() - x0[Tw]) < 4 * draws[:, Tw].std() / np.sqrt(200) + 1e-9


def test_initial_state_config_errors():
    from heritage_bayes.config import parse_config
    from heritage_bayes.models import build_model, default_warmup, initial_state_of

    base = {
        "name": "t",
        "data": {"demo": {}},
        "thermal": {"model": "thermal_2c"},
    }

    def state(cfg):
        return initial_state_of(cfg, "thermal", build_model(cfg, "thermal"))

    def warmup(cfg):
        return default_warmup(cfg, {"thermal": build_model(cfg, "thermal")})

    cfg = parse_config(base)
    assert state(cfg) == "estimate"
    assert warmup(cfg) == pd.Timedelta(0)
    bad = parse_config({**base, "thermal": {"model": "thermal_2c", "initial_state": {"Tx": 3}}})
    with pytest.raises(ConfigError, match=r"thermal.initial_state: unknown node.*Tx"):
        state(bad)
    ctl = {"model": "thermal_2c", "options": {"thermostat": True}, "initial_state": "estimate"}
    with pytest.raises(ConfigError, match=r"thermal\.initial_state: 'estimate' needs a model"):
        state(parse_config({**base, "thermal": ctl}))
    ctl.pop("initial_state")
    cfg = parse_config({**base, "thermal": ctl})
    assert state(cfg) == "steady"
    assert warmup(cfg) == pd.Timedelta(days=14)


def test_free_run_error_fit_recovers_a_slow_error():
    """The predictive error model (fitted after calibration, phi up to 0.999) recovers a
    slow AR(1) + white process; tolerances: 5 asymptotic standard errors of the AR(1)
    estimates for n = 6000 (sd(phi) ~ sqrt((1 - phi²)/n), relative sd(sigma) ~
    sqrt((1 + phi²) / (2 n (1 - phi²))))."""
    from scipy.signal import lfilter

    from heritage_bayes.inference.likelihoods import fit_free_run_error

    rng = np.random.default_rng(0)
    n, phi, sigma, w = 6000, 0.99, 0.5, 0.1
    # stationary start, then the AR(1) recursion
    shocks = np.r_[rng.normal(0, sigma), rng.normal(0, sigma * np.sqrt(1 - phi**2), n - 1)]
    e = lfilter([1.0], [1.0, -phi], shocks)
    r = e + rng.normal(0, w, n)
    r[100:300] = np.nan
    fit = fit_free_run_error(r)
    assert fit["phi"] == pytest.approx(phi, abs=5 * np.sqrt((1 - phi**2) / n))
    rel = np.sqrt((1 + phi**2) / (2 * n * (1 - phi**2)))
    assert fit["sigma"] == pytest.approx(sigma, rel=5 * rel)
    assert fit["sigma_meas"] == pytest.approx(w, rel=0.2)


def test_predicted_vapour_pressure_is_limited_to_saturation():
    """Pi above saturation at the paired Ti condenses (capped), below 0 is floored; the
    shares of samples and hours where the limit acted are reported."""
    from types import SimpleNamespace

    from heritage_bayes.climate.psychro import saturation_vapour_pressure
    from heritage_bayes.inference.predictive import condensation_cap

    s = SimpleNamespace(model=SimpleNamespace(output_names=("Pi",)))
    ti = np.array([[10.0, 10.0, 20.0, 20.0], [10.0, 10.0, 20.0, 20.0]])
    ps = saturation_vapour_pressure(ti)
    factor = np.array([[0.5, 1.2, 0.9, 1.1], [0.5, 1.3, 0.9, 0.9]])  # draws x hours
    Ysim = (ps * factor)[..., None]
    Ypp = Ysim.copy()
    Ypp[0, 0, 0] = -5.0
    info = condensation_cap(s, None, Ysim, Ypp, {"Ti": (ti, ti)})
    assert np.all(Ypp[..., 0] <= ps + 1e-9) and np.all(Ypp >= 0)
    assert np.all(Ysim[..., 0] <= ps + 1e-9)
    rh = 100 * Ypp[..., 0] / ps
    assert rh.min() == 0.0 and rh.max() == pytest.approx(100.0)
    assert info["share_noise_free_samples"] == pytest.approx(3 / 8)
    assert info["share_hours_median_saturated"] == pytest.approx(1 / 4)  # hour 1 only
    assert info["share_predictive_below_zero"] == pytest.approx(1 / 8)


ARMADILLO = Path(__file__).resolve().parents[2] / "shared" / "data" / "armadillo"


@pytest.mark.skipif(not ARMADILLO.is_dir(), reason="needs ../shared/data/armadillo")
def test_armadillo_from_yaml_fits_with_its_initial_state_estimated():
    """configs/armadillo.yaml (pySIP's TwTi_RoRi as a custom network): the cell starts
    far from the steady state of its mean inputs; with the start estimated the MAP
    simulation fits within pySIP's RMSE (0.85 K), the steady start does not."""
    from heritage_bayes.calibration.ladder import section_log_posterior as _log_posterior
    from heritage_bayes.config import load_config
    from heritage_bayes.inference.optimize import find_map
    from heritage_bayes.models import build_model
    from heritage_bayes.prepare import prepare

    cfg = load_config(Path(__file__).resolve().parents[1] / "configs" / "armadillo.yaml")
    prep = prepare(cfg)
    m = build_model(cfg, "thermal")
    rmse = {}
    for mode in ("estimate", "steady"):
        lp = _log_posterior(cfg, prep, "thermal", m, cfg.thermal.priors, initial_state=mode)
        mp = find_map(lp, seed=1, method="differential_evolution", maxiter=100)
        y = lp.simulate_frame(mp.theta[None], prep.model_inputs("thermal", m), 0)[0][0, :, 0]
        obs = prep.observed("thermal", m)[:, 0]
        rmse[mode] = float(np.sqrt(np.nanmean((obs - y) ** 2)))
        if mode == "estimate":
            x0 = lp.initial_states(mp.theta[None])[0]
            assert np.isfinite(obs).sum() == 232
            assert abs(x0[m.state_names.index("Ti")] - obs[0]) < 1.0  # the start, found
    assert rmse["estimate"] <= 0.85
    assert rmse["steady"] > rmse["estimate"]
    # pySIP's own likelihood (process noise on the nodes): its log-likelihood, ~ +329
    kal = cfg.thermal.model_copy(update={"noise": "kalman"})
    cfg = cfg.model_copy(update={"thermal": kal})
    lp = _log_posterior(cfg, prep, "thermal", m, cfg.thermal.priors)
    mp = find_map(lp, seed=1, method="differential_evolution", maxiter=100)
    assert lp.log_likelihood(mp.theta[None])[0] >= 325
    x0 = lp.initial_states(mp.theta[None])
    y = lp.simulate_frame(mp.theta[None], prep.model_inputs("thermal", m), 0, x0=x0)[0][0, :, 0]
    assert np.sqrt(np.nanmean((prep.observed("thermal", m)[:, 0] - y) ** 2)) <= 0.85


def test_a_frozen_node_is_named():
    """A node whose time constant is many records long keeps its start value: the check
    that warns before sampling (heritage_bayes.rc.derived.frozen_time_constant)."""
    from heritage_bayes.demo import TRUE_THERMAL
    from heritage_bayes.rc.derived import FROZEN_RECORDS, frozen_time_constant, time_constants

    m = hb.model("thermal_2c")
    truth = {k: TRUE_THERMAL[k] for k in m.parameter_names}
    record = 90 * 86400.0  # three months [s]
    assert frozen_time_constant(m, truth, record) is None  # the demo room: τ1 104 h
    frozen = {**truth, "Cw": truth["Cw"] * 1e4, "Gw": truth["Gw"] * 1e-2}
    tau = time_constants(m, frozen)[0]
    assert tau > FROZEN_RECORDS * record
    assert frozen_time_constant(m, frozen, record) == pytest.approx(tau)
    # the threshold is the record times FROZEN_RECORDS, exactly
    assert frozen_time_constant(m, frozen, tau / FROZEN_RECORDS * 1.001) is None
    assert frozen_time_constant(m, frozen, tau / FROZEN_RECORDS * 0.999) == pytest.approx(tau)


def _frozen(lp: LogPosterior, tm: np.ndarray, cw_factor: float) -> np.ndarray:
    """Model parameters ``tm`` with the envelope made far slower: Cw × ``cw_factor``,
    Gw / 100."""
    out = tm.copy()
    names = list(lp.model.parameter_names)
    out[names.index("Cw")] *= cw_factor
    out[names.index("Gw")] *= 1e-2
    return out


def test_slow_modes_start_near_their_steady_state():
    """The start prior damps each mode by a = (1 + (τ/h)²)^-1/2 (h: the horizon, by
    default the record): the isotropic s0² I when nothing is slower than the horizon,
    and a frozen mode (τ = 100 h) cannot act as a free offset."""
    lp, theta = _problem("ar1_white", "estimate")
    m = lp.model
    tm = theta[: lp.n_model]
    frozen = _frozen(lp, tm, 1e4)
    for h, horizon in ((lp.initial_state_horizon, "record"), (math.inf, "none")):
        lp_h = dataclasses.replace(lp, initial_state_horizon=h)
        assert lp_h.initial_state_horizon == (240 * 3600.0 if horizon == "record" else h)
        mf = modal_form(m, np.stack([tm, frozen]), lp.dt)
        P = lp_h._x0_cov(mf)
        # the slow modal coordinate z = Tinv x: its prior variance is (s0 a)², a of its τ
        tau = 1.0 / mf.lam
        z = mf.Tinv @ P @ np.swapaxes(mf.Tinv, 1, 2)
        for k in range(2):
            j = int(np.argmax(tau[k]))
            a = 1.0 / np.hypot(1.0, tau[k, j] / h)
            zz = mf.Tinv[k] @ (2.5**2 * np.eye(2)) @ mf.Tinv[k].T
            assert z[k, j, j] == pytest.approx(a**2 * zz[j, j], rel=1e-4)
        if horizon == "none":
            np.testing.assert_allclose(P, np.broadcast_to(2.5**2 * np.eye(2), P.shape), atol=1e-9)
        else:  # frozen: the slow mode's start sd is below s0 / 10
            assert tau[1].max() > 10 * h
    with pytest.raises(ValueError, match="initial_state_horizon"):
        dataclasses.replace(lp, initial_state_horizon=0.0)


def test_time_constant_cap_is_a_soft_prior_on_every_mode():
    """log p = -Σ log(1 + (τ_j/cap)²), added to the log-posterior and not to the
    likelihood; a frozen envelope (τ1 ≈ 1.7e5 h) pays about 6 nats with a one-year
    cap, the demo-like room (τ1 63 h) 5e-5; the config's defaults: a year for thermal
    models, none for hygric ones."""
    from heritage_bayes.config import ModelSection
    from heritage_bayes.rc.derived import time_constants

    lp, theta = _problem("ar1_white", "estimate")
    cap = 365 * 86400.0
    capped = dataclasses.replace(lp, time_constant_cap=cap)
    tm = theta[: lp.n_model]
    frozen = _frozen(lp, tm, 1e3)
    th = np.stack([theta, np.concatenate([frozen, theta[lp.n_model :]])])
    tau = time_constants(lp.model, th[:, : lp.n_model])  # [s]
    expected = -np.log1p((tau / cap) ** 2).sum(axis=1)
    got = capped.time_constant_log_prior(th[:, : lp.n_model])
    np.testing.assert_allclose(got, expected, rtol=1e-10)
    assert got[0] > -1e-3 and got[1] < -5.0
    X = lp.params.to_unconstrained(th)
    np.testing.assert_allclose(capped(X) - lp(X), expected, rtol=1e-9)
    np.testing.assert_array_equal(capped.log_likelihood(th), lp.log_likelihood(th))
    assert np.all(lp.time_constant_log_prior(th[:, : lp.n_model]) == 0.0)
    assert ModelSection(model="thermal_2c").cap_seconds("thermal") == cap
    assert ModelSection(model="hygric_2c").cap_seconds("hygric") == math.inf
    assert (
        ModelSection(model="thermal_2c", time_constant_cap="none").cap_seconds("thermal")
        == math.inf
    )
    assert (
        ModelSection(model="thermal_2c", time_constant_cap="90d").cap_seconds("thermal")
        == 90 * 86400.0
    )
    with pytest.raises(ValueError, match="duration"):
        ModelSection(model="thermal_2c", time_constant_cap="a year")
