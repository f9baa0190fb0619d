"""``noise: kalman`` on the thermo-hygric coupled models (``inference.coupled_kalman``):
the LTI filter where the temperatures are constant, a dense Gaussian where they are not.
"""

import numpy as np
import pytest
from scipy.linalg import expm
from scipy.stats import multivariate_normal

import heritage_bayes as hb
from heritage_bayes.inference.likelihoods import get_noise_model
from heritage_bayes.inference.parameters import parameters_for
from heritage_bayes.inference.posterior import LogPosterior
from heritage_bayes.rc.sorption import BLOCK, P_REF, T_REF, coupled_block
from test_sorption import _weather as sorption_weather

DT = 3600.0
KALMAN = get_noise_model("kalman")


def _weather(N, seed=0):
    """test_sorption's weather, the change of Pe over each step and Pe observed with
    30 Pa of noise."""
    pe, ti, tf = sorption_weather(N, seed)
    obs = pe + np.random.default_rng([seed, 1]).normal(0, 30, N)
    return pe, np.r_[np.diff(pe), 0.0], ti, tf, obs


@pytest.mark.parametrize("init", ["estimate", "steady"])
@pytest.mark.parametrize("sorption", [True, False])
def test_constant_temperatures_give_the_lti_kalman_filter(sorption, init):
    """Ti ≡ Tf ≡ T_ref: the coupled filter's log-likelihood, one-step predictions and
    initial states are those of the LTI ``kalman`` on the equivalent linear network
    (hygric_2c with Gw = 0, Cw = Cm/psat(T_ref); hygric_2c_fixed with Pf = phi_f
    psat(T_ref)), over a record with a gap."""
    N = 800
    pe, dpe, _, _, obs = _weather(N, seed=1)
    obs[100:140] = np.nan
    const = np.full(N, T_REF)
    noise = [25.0, 4.0, 30.0]  # sigma_Pi [Pa], q_Pw, q_Pi [Pa/√h]
    if sorption:
        m = hb.model("hygric_2c_sorption").with_slopes(["Pe"])
        lin = hb.model("hygric_2c").with_slopes(["Pe"])
        th = np.array([[20.0, 1e-2, 3e-7, 5e-7, *noise]])
        thl = np.array([[20.0 / P_REF, 1e-2, 0.0, 3e-7, 5e-7, *noise]])
    else:
        m = hb.model("hygric_2c_fixed", sink="temperature").with_slopes(["Pe"])
        lin = hb.model("hygric_2c_fixed").with_slopes(["Pe"])
        p = [0.02, 3e-3, 2e-8, 1e-7, 2e-7, 5e-8]
        th = np.array([[*p, 0.85, *noise]])
        thl = np.array([[*p, 0.85 * P_REF, *noise]])
    U = np.column_stack([pe, dpe, const])
    kw = dict(warmup=24, init_window=100, initial_state=init)
    lp = LogPosterior(m, parameters_for(m, KALMAN), KALMAN, U, obs, **kw)
    lpl = LogPosterior(lin, parameters_for(lin, KALMAN), KALMAN, U[:, :2], obs, **kw)
    ll, ll_lin = lp.log_likelihood(th), lpl.log_likelihood(thl)
    assert np.isfinite(ll).all()
    np.testing.assert_allclose(ll, ll_lin, rtol=1e-10)
    np.testing.assert_allclose(
        lp.pointwise_log_likelihood(th), lpl.pointwise_log_likelihood(thl), rtol=1e-8
    )
    # the start's conditional mean: finite differences of the log-likelihood
    np.testing.assert_allclose(lp.initial_states(th), lpl.initial_states(thl), rtol=1e-5)
    for a, b in zip(KALMAN.one_step(lp, th), KALMAN.one_step(lpl, thl), strict=True):
        np.testing.assert_allclose(a, b, rtol=1e-9)


def _process_noise(p, r, q):
    """Exact process-noise covariance of a step with r held (Van Loan's matrix
    exponential of the ODE in (Pw, Pi))."""
    cw = p["Cm"] / P_REF
    A = np.array(
        [
            [-p["Gi"] * r / cw, p["Gi"] / cw],
            [p["Gi"] * r / p["Ci"], -(p["Gi"] + p["Gfast"] + p["Gf"]) / p["Ci"]],
        ]
    )
    W = np.diag(q) ** 2
    F = expm(np.block([[-A, W], [np.zeros((2, 2)), A.T]]) * DT)
    return F[2:, 2:].T @ F[:2, 2:]


def test_a_record_with_gaps_gives_the_dense_gaussian_likelihood():
    """Ti varying, a gap and scattered missing values: the filter's log-likelihood is
    the log density of the observed Pi under their joint Gaussian (the start's prior,
    every step's transition and process noise, the measurement noise), computed
    densely; and the per-step noise covariance is Van Loan's."""
    N = 60
    pe, dpe, ti, tf, obs = _weather(N, seed=3)
    obs[20:31] = np.nan
    obs[[5, 44]] = np.nan
    m = hb.model("hygric_2c_sorption", sink="temperature").with_slopes(["Pe"])
    p = dict(Cm=60.0, Ci=3e-3, Gi=1e-7, Gfast=2e-7, Gf=5e-8, phi_f=0.9)
    sigma, q = 20.0, np.array([3.0, 40.0])  # [Pa], [Pa/√h]
    U = np.column_stack([pe, dpe, ti, tf])
    P = np.array([[p[n] for n in m.parameter_names]])
    x0, P0 = np.array([[900.0, 1150.0]]), np.array([[[4e4, 1e4], [1e4, 9e4]]])
    theta = np.array([[*P[0], sigma, *q]])
    mf = LogPosterior(
        m, parameters_for(m, KALMAN), KALMAN, U, obs, warmup=0, initial_state="estimate"
    )._form(P)
    ll = KALMAN.filter(m, mf, U, obs[:, None], theta[:, P.shape[1] :], x0, P0)
    # dense: the stacked states' mean and covariance, step by step
    sb, slope = m.series(U)
    Mf = np.empty((6, BLOCK))
    coupled_block(m.kernel_parameters(P)[0], sb, DT, slope, 0, N, Mf)
    mean, cov = [x0[0]], [P0[0]]
    cross = [[P0[0]]]  # cross[k][j] = Cov(x_k, x_j), j <= k
    qs = q / np.sqrt(3600.0)
    for k in range(N - 1):
        M = Mf[:4, k].reshape(2, 2)
        Q = _process_noise(p, sb[2, k], qs)
        mean.append(M @ mean[-1] + Mf[4:, k])
        row = [M @ c for c in cross[-1]]
        cov.append(M @ cov[-1] @ M.T + Q)
        row.append(cov[-1])
        cross.append(row)
    ok = np.flatnonzero(np.isfinite(obs))
    C = np.array([[(cross[max(a, b)][min(a, b)])[1, 1] for b in ok] for a in ok])
    mu = np.array([mean[a][1] for a in ok])
    ref = multivariate_normal(mu, C + sigma**2 * np.eye(ok.size)).logpdf(obs[ok])
    np.testing.assert_allclose(ll, [ref], rtol=1e-9)
    # the filter's per-step covariance is the exact one of the step's dynamics
    from heritage_bayes.inference.coupled_kalman import noise_block

    Qb = np.empty((3, BLOCK))
    noise_block(m.kernel_parameters(P)[0], sb, DT, 0, N, qs[0], qs[1], Qb)
    for k in (0, 17, 40):
        Q = _process_noise(p, sb[2, k], qs)
        np.testing.assert_allclose(Qb[:, k], [Q[0, 0], Q[0, 1], Q[1, 1]], rtol=1e-9)
