"""noise: kalman, the stochastic state-space likelihood (process noise on the nodes).

Cross-checked against statsmodels' Kalman filter on the same discrete state space
(transition, intercept, process-noise covariance from scipy's matrix exponential, the
initial state's prior as a known initialisation) and against a dense Gaussian density,
both to 1e-8 relative, with gaps.
"""

from __future__ import annotations

import numpy as np
import pytest
from scipy.linalg import expm
from scipy.stats import multivariate_normal

import heritage_bayes as hb
from heritage_bayes.calibration.convergence import EXIT_UNCONVERGED
from heritage_bayes.inference.likelihoods import get_noise_model
from heritage_bayes.inference.parameters import parameters_for
from heritage_bayes.inference.posterior import LogPosterior
from heritage_bayes.rc.discretize import modal_form

TRUTH = {"Cw": 2e7, "Ci": 1e6, "Gw": 60.0, "Gi": 400.0, "Gfast": 30.0, "Gf": 5.0}
DT = 3600.0


def _problem(n=150, mode="estimate", seed=2):
    m = hb.model("thermal_2c", surfaces=())
    rng = np.random.default_rng(seed)
    t = np.arange(n)
    U = np.column_stack([8 + 5 * np.sin(2 * np.pi * t / 24) + rng.normal(0, 1, n), np.full(n, 9.0)])
    y = rng.normal(12, 1.0, (n, 1))
    y[30:45] = np.nan
    y[::7] = np.nan
    noise = get_noise_model("kalman")
    ps = parameters_for(m, noise, room_volume=200)
    lp = LogPosterior(m, ps, noise, U, y, warmup=0, init_window=48, initial_state=mode)
    vals = {**TRUTH, "sigma_Ti": 0.2, "q_Tw": 0.05, "q_Ti": 0.3}
    return lp, np.array([vals[k] for k in ps.names])


def _discrete(lp, theta):
    """Physical discrete model by the block matrix exponential (Van Loan for Qd)."""
    m = lp.model
    p = dict(zip(m.parameter_names, theta[: lp.n_model], strict=True))
    A, B, C, _ = m.state_space(p)
    n, k = B.shape
    M = np.zeros((n + k, n + k))
    M[:n, :n], M[:n, n:] = A, B
    E = expm(M * DT)
    Ad, Bd = E[:n, :n], E[:n, n:]
    q = np.array([theta[lp.params.names.index(f"q_{s}")] for s in m.state_names]) / np.sqrt(3600)
    Qc = np.diag(q**2)
    V = np.zeros((2 * n, 2 * n))
    V[:n, :n], V[:n, n:], V[n:, n:] = -A, Qc, A.T
    F = expm(V * DT)
    Qd = F[n:, n:].T @ F[:n, n:]
    return Ad, Bd, C, Qd


def _x0_prior(lp, theta):
    mf = modal_form(lp.model, theta[None, : lp.n_model], DT)
    xm, P0 = lp._x0_prior(mf)
    return xm[0], P0[0]


def _statsmodels(lp, theta, y):
    """statsmodels' Kalman filter on the same discrete state space (the reference)."""
    sm = pytest.importorskip("statsmodels.tsa.statespace.mlemodel")
    Ad, Bd, C, Qd = _discrete(lp, theta)
    xm, P0 = _x0_prior(lp, theta)
    n = Ad.shape[0]
    mod = sm.MLEModel(y, k_states=n, k_posdef=n)
    mod["design"] = C
    mod["obs_cov"] = np.array([[0.2**2]])
    mod["transition"] = Ad
    mod["selection"] = np.eye(n)
    mod["state_cov"] = Qd
    mod["state_intercept"] = Bd @ lp.inputs.T  # (n, N): the input of step k moves k -> k+1
    mod.initialize_known(xm, P0 + 1e-300 * np.eye(n))
    return mod


def test_kalman_matches_statsmodels():
    lp, theta = _problem()
    mod = _statsmodels(lp, theta, lp.observed[:, 0])
    ref = mod.loglike([])
    ll = lp.log_likelihood(theta[None])[0]
    assert ll == pytest.approx(ref, rel=1e-8)


def test_kalman_matches_a_dense_gaussian():
    lp, theta = _problem(n=90)
    Ad, Bd, C, Qd = _discrete(lp, theta)
    xm, P0 = _x0_prior(lp, theta)
    N, n = lp.inputs.shape[0], Ad.shape[0]
    # stacked: x_k = Ad^k x0 + sum_j Ad^(k-1-j) (Bd u_j + w_j)
    mean = np.empty(N)
    G = np.zeros((N, n))  # d y_k / d x0
    H = np.zeros((N, N, n))  # d y_k / d w_j
    x, Ak = xm.copy(), np.eye(n)
    for k in range(N):
        mean[k] = (C @ x)[0]
        G[k] = (C @ Ak)[0]
        for j in range(k):
            H[k, j] = (C @ np.linalg.matrix_power(Ad, k - 1 - j))[0]
        x = Ad @ x + Bd @ lp.inputs[k]
        Ak = Ad @ Ak
    cov = G @ P0 @ G.T + np.einsum("kjn,nm,ljm->kl", H, Qd, H) + 0.2**2 * np.eye(N)
    ok = np.isfinite(lp.observed[:, 0])
    ref = multivariate_normal(mean[ok], cov[np.ix_(ok, ok)]).logpdf(lp.observed[ok, 0])
    assert lp.log_likelihood(theta[None])[0] == pytest.approx(ref, rel=1e-8)
    # the conditional posterior of the initial state, as the dense Gaussian gives it
    Sig = cov[np.ix_(ok, ok)]
    dense_x0 = xm + P0 @ G[ok].T @ np.linalg.solve(Sig, lp.observed[ok, 0] - mean[ok])
    x0 = lp.initial_states(theta[None])[0]
    assert np.allclose(x0, dense_x0, rtol=1e-7, atol=1e-7)
    # one-step predictive terms add up to the log-likelihood
    pw = lp.pointwise_log_likelihood(theta[None])
    assert np.nansum(pw) == pytest.approx(ref, rel=1e-8)


@pytest.mark.parametrize("gaps", [False, True])
def test_kalman_steady_gains_match_statsmodels(gaps):
    """Long gap-free stretches: the filter switches to its steady-state gains once the
    covariance has converged (and back to the full recursion after a gap); the
    log-likelihood still equals statsmodels' full recursion to 1e-8."""
    lp, theta = _problem(n=1500)
    y = np.random.default_rng(4).normal(12, 1.0, 1500)
    if gaps:
        y[700:730] = np.nan
        y[1100] = np.nan
    lp.observed[:, 0] = y
    mod = _statsmodels(lp, theta, y)
    ref = mod.loglike([])
    assert lp.log_likelihood(theta[None])[0] == pytest.approx(ref, rel=1e-8)
    # the one-step terms agree with statsmodels' too (llf_obs), gaps excluded
    pw = lp.pointwise_log_likelihood(theta[None])[0, :, 0]
    res = mod.ssm.filter()
    ok = np.isfinite(y)
    assert np.allclose(pw[ok], res.llf_obs[ok], rtol=1e-8, atol=1e-10)
    # one-step-ahead predictive mean and variance at every row (gaps included)
    mean, var = lp.noise.one_step(lp, theta[None])
    assert np.allclose(mean[0, :, 0], res.forecasts[0], rtol=1e-10, atol=1e-8)
    assert np.allclose(var[0, :, 0], res.forecasts_error_cov[0, 0], rtol=1e-8)


def test_free_run_predictive_noise_moments():
    """The free-run predictive noise (process noise through the modes + measurement
    noise) has mean 0 and the variance C P_k C^T + sigma² with P_{k+1} = Ad P_k Ad^T + Qd,
    P_0 = 0: checked per step on 4000 seeded draws within 5 standard errors."""
    lp, theta = _problem(n=60)
    Ad, _, C, Qd = _discrete(lp, theta)
    K, N = 4000, 60
    mf = modal_form(lp.model, np.repeat(theta[None, : lp.n_model], K, 0), DT)
    tn = np.repeat(theta[None, lp.n_model :], K, 0)
    e = lp.noise.sample_statespace(np.random.default_rng(7), mf, tn, N, 1)[:, :, 0]
    P = np.zeros_like(Ad)
    var = np.empty(N)
    for k in range(N):
        var[k] = (C @ P @ C.T)[0, 0] + 0.2**2
        P = Ad @ P @ Ad.T + Qd
    assert np.all(np.abs(e.mean(0)) < 5 * np.sqrt(var / K))
    assert np.all(np.abs(e.var(0, ddof=1) - var) < 5 * var * np.sqrt(2 / (K - 1)))


def test_kalman_run_has_one_step_bands(tmp_path):
    """A calibration with ``noise: kalman`` stores one-step-ahead predictive samples
    (the filter's prediction of each hour from the measurements before it), their band
    coverage per period, and the report shows them beside the free-run band."""
    import json

    import yaml

    from heritage_bayes._arviz import az
    from heritage_bayes.cli import main

    cfg = {
        "name": "tiny_kalman",
        "seed": 3,
        "data": {"demo": {"seed": 7}},
        "periods": {
            "calibration": {"start": "2019-02-01", "end": "2019-02-11"},
            "validation": {"start": "2019-02-11", "end": "2019-02-16"},
        },
        "room_volume": 400,
        "air_change_rate": 0.5,
        "thermal": {"model": "thermal_1c", "noise": "kalman"},
        "ladder": False,
        "sampler": {"max_steps": 400, "check_every": 200, "n_predictive": 64},
        "optimizer": {"maxiter": 20, "starts": 2, "popsize": 4},
    }
    p = tmp_path / "k.yaml"
    p.write_text(yaml.safe_dump(cfg))
    out = tmp_path / "run"
    # 400 steps: the run finishes unconverged (exit code 3, EXIT_UNCONVERGED); the bands
    # are written all the same
    assert main(["calibrate", str(p), "--out", str(out), "--quiet"]) == EXIT_UNCONVERGED
    idata = az.from_netcdf(out / "posterior.nc")
    pp = idata.posterior_predictive
    y1 = pp["thermal.Ti_1step"].values.reshape(-1, pp.sizes["time"])
    yf = pp["thermal.Ti"].values.reshape(-1, pp.sizes["time"])
    obs = idata.observed_data["Ti"].reindex(time=pp["time"]).values
    assert np.isfinite(y1).all()
    # the filter tracks the measurements: one-step bands much narrower than free-run
    w1 = np.subtract(*np.quantile(y1, [0.95, 0.05], axis=0))
    wf = np.subtract(*np.quantile(yf, [0.95, 0.05], axis=0))
    assert np.median(w1) < np.median(wf)
    # its one-step mean of one draw is KalmanNoise.one_step's (calibration frame)
    s = json.loads((out / "summary.json").read_text())
    met = s["metrics"]["thermal"]["Ti"]
    for period in ("calibration", "validation"):
        c = met[period]["coverage90_1step"]
        codes = idata.constant_data["period"].reindex(time=pp["time"]).values
        rows = (codes == (1 if period == "calibration" else 2)) & np.isfinite(obs)
        lo, hi = np.quantile(y1[:, rows], [0.05, 0.95], axis=0)
        assert c == pytest.approx(np.mean((obs[rows] >= lo) & (obs[rows] <= hi)), abs=1e-9)
    html = (out / "report.html").read_text()
    assert "fig-fit-thermal-Ti-1step" in html and "one step ahead" in html
    # the residual check (section 7, the verdict's) is on the filter's one-step
    # innovations, not on the free-run residuals that carry the accumulated process noise
    assert "one-step-ahead innovations are" in html


def test_kalman_free_run_bands_use_the_free_run_error():
    """``kalman``'s free-run bands are drawn from the free-run error (AR(1) + white fitted
    to the calibration residuals of the posterior-median simulation, as ``ar1_white``'s
    at its cap), not from the process noise propagated without the data, which covered
    99.9-100 % of the demo's validation hours (docs/science/noise.md). The posterior's
    own noise vector is left alone."""
    from types import SimpleNamespace

    from heritage_bayes.inference.likelihoods import AR1WhiteNoise, fit_free_run_error
    from heritage_bayes.inference.predictive import predictive_noise

    lp, theta = _problem(n=400)
    rng = np.random.default_rng(5)
    ysim = np.full((3, 400, 1), 12.0)  # three draws, the same simulation
    obs = 12.0 + np.cumsum(rng.normal(0, 0.1, 400))[:, None]  # a slow free-run misfit
    s = SimpleNamespace(name="thermal", model=lp.model, logpost=lp)
    fitted = np.zeros(400, dtype=bool)
    fitted[20:300] = True  # the calibration after its warm-up
    prep = SimpleNamespace(observed=lambda name, m: obs, fitted_rows=lambda: fitted)
    tn = np.repeat(theta[None, lp.n_model :], 3, 0)
    keep = tn.copy()
    nm, noise, info = predictive_noise(s, prep, ysim, tn)
    assert isinstance(nm, AR1WhiteNoise)
    fit = fit_free_run_error(obs[20:300, 0] - 12.0)
    assert noise.shape == (3, 3)
    np.testing.assert_allclose(
        noise, np.tile([fit["sigma"], fit["phi"], fit["sigma_meas"]], (3, 1))
    )
    assert info["Ti"]["sigma"] == fit["sigma"] and "one-step" in info["Ti"]["reason"]
    np.testing.assert_array_equal(tn, keep)
