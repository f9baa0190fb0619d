"""A buffer whose capacity follows its humidity (``rc.isotherm``, option ``isotherm:
gab``): the GAB slope, its linear limit, the recursion against a fine integration, its
tabulated transitions against the exact step."""

import numpy as np
import pytest
from scipy.integrate import quad, solve_ivp
from scipy.optimize import brentq

import heritage_bayes as hb
from heritage_bayes.climate.psychro import saturation_vapour_pressure as psat
from heritage_bayes.inference.coupled import FIRST_PASS_STOP, coupled_filter_stats
from heritage_bayes.inference.likelihoods import get_noise_model
from heritage_bayes.inference.parameters import parameters_for
from heritage_bayes.inference.posterior import LogPosterior
from heritage_bayes.rc.isotherm import (
    GAB_C,
    PHI_REF,
    gab_capacity_factor,
    gab_constants,
    gab_step,
)
from heritage_bayes.rc.sorption import P_REF, CoupledHygricModel

DT = 3600.0
CELLAR = dict(Cw=0.3, Ci=0.03, Gw=2e-8, Gi=8e-7, Gfast=4e-7, Gf=3e-8, phi_f=0.9)


def _gab(phi, k, c=GAB_C):
    """GAB moisture content per unit monolayer content (Anderson 1946)."""
    x = k * phi
    return c * x / ((1 - x) * (1 - x + c * x))


def _inputs(N, seed=0):
    rng = np.random.default_rng(seed)
    t = np.arange(N)
    pe = 1100 + 250 * np.sin(2 * np.pi * t / 24) + np.cumsum(rng.normal(0, 15, N))
    tf = 10 + 2 * np.sin(2 * np.pi * t / 700)
    return np.column_stack([pe, np.r_[np.diff(pe), 0.0], tf])


def test_the_capacity_is_the_gab_isotherm_slope():
    """C_w(φ)/C_w is du/dφ of the GAB isotherm (a central difference of u) over its value
    at the reference RH; 1 at K = 0 and at the reference RH."""
    phi = np.linspace(0.3, 1.0, 15)
    for k in (0.6, 0.75, 0.9):
        h = 1e-6
        slope = (_gab(phi + h, k) - _gab(phi - h, k)) / (2 * h)
        ref = (_gab(PHI_REF + h, k) - _gab(PHI_REF - h, k)) / (2 * h)
        np.testing.assert_allclose(gab_capacity_factor(phi, k), slope / ref, rtol=1e-7)
    assert np.all(gab_capacity_factor(phi, 0.0) == 1.0)
    assert gab_capacity_factor(PHI_REF, 0.8) == pytest.approx(1.0, rel=1e-14)


def test_a_closed_buffer_and_air_reach_the_gab_equilibrium():
    """A buffer and the air with (almost) no other exchange: the moisture of both
    (buffer along the GAB isotherm, the air's Ci·Pi) is conserved, so the equilibrium
    is where the isotherm puts it (to 1e-3 of the change of the buffer's RH)."""
    k = 0.8
    m = hb.model("hygric_2c_fixed", sink="constant", isotherm="gab")
    p = dict(Cw=0.2, Ci=0.15, Gw=0.0, Gi=3e-7, Gfast=1e-16, Gf=0.0, Pf=0.0, K_gab=k)
    x0 = np.array([0.5 * P_REF, 0.95 * P_REF])  # the buffer at 50 %, the air at 95 %
    N = 3000
    U = np.full((N, 1), 0.95 * P_REF)
    Y, valid = m.forward(np.array([[p[n] for n in m.parameter_names]]), U, DT, x0=x0)
    assert valid[0]

    def moisture(phi_w, pi):  # [kg], up to a constant
        buf = p["Cw"] * P_REF * quad(lambda f: gab_capacity_factor(f, k), 0.5, phi_w)[0]
        return buf + p["Ci"] * pi

    total = moisture(0.5, x0[1])
    eq = brentq(lambda f: moisture(f, f * P_REF) - total, 0.5, 0.95)
    assert Y[0, -1, 0] / P_REF == pytest.approx(eq, abs=1e-3 * (0.95 - 0.5))
    # the linear buffer's equilibrium differs by far more
    lin = (0.2 * P_REF * 0.5 + 0.15 * x0[1]) / (0.2 * P_REF + 0.15 * P_REF)
    assert abs(lin - eq) > 0.01


def test_the_linear_limit_is_todays_model():
    """K_gab = 0: the simulation and the log-likelihood (initial state integrated out) of
    today's model to rounding; the default ``isotherm`` builds today's model."""
    N = 1200
    U = _inputs(N)
    rng = np.random.default_rng(3)
    obs = hb.simulate(hb.model("hygric_2c_fixed", sink="temperature"), CELLAR, U[:, [0, 2]], DT)
    obs = obs[:, 0] + rng.normal(0, 20, N)
    obs[300:350] = np.nan
    lin = hb.model("hygric_2c_fixed", sink="temperature").with_slopes(["Pe"])
    gab = hb.model("hygric_2c_fixed", sink="temperature", isotherm="gab").with_slopes(["Pe"])
    assert type(lin) is CoupledHygricModel
    assert type(hb.model("hygric_2c_fixed", sink="temperature", isotherm="linear")) is type(
        hb.model("hygric_2c_fixed", sink="temperature")
    )
    P = np.array([[CELLAR[n] for n in lin.parameter_names]])
    Pg = np.column_stack([P, [0.0]])
    np.testing.assert_allclose(gab.forward(Pg, U, DT)[0], lin.forward(P, U, DT)[0], rtol=1e-12)
    nm = get_noise_model("ar1_white")
    kw = dict(warmup=0, init_window=48, initial_state="estimate")
    lp = LogPosterior(lin, parameters_for(lin, nm), nm, U, obs, **kw)
    lpg = LogPosterior(gab, parameters_for(gab, nm), nm, U, obs, **kw)
    noise = [[20.0, 0.5, 5.0]]
    np.testing.assert_allclose(
        lpg.log_likelihood(np.column_stack([Pg, noise])),
        lp.log_likelihood(np.column_stack([P, noise])),
        rtol=1e-10,
    )
    with pytest.raises(ValueError, match="isotherm: Input should be 'linear' or 'gab'"):
        hb.model("hygric_2c_sorption", isotherm="bet")


def _fine(p, U, x0, k):
    """Pi at every step's start by one solve_ivp of the nonlinear ODE over the record
    (Pe linear within a step, Tf held): the buffer's capacity C_w(P_w / p_sat(T_ref))."""
    sink = p["phi_f"] * psat(U[:, 2])

    def f(t, x):
        j = min(int(t // DT), U.shape[0] - 1)
        u = U[j, 0] + U[j, 1] * (t / DT - j - 0.5)
        cw = p["Cw"] * gab_capacity_factor(x[0] / P_REF, k)
        fw = p["Gi"] * (x[1] - x[0]) + p["Gw"] * (u - x[0])
        fi = p["Gfast"] * (u - x[1]) + p["Gi"] * (x[0] - x[1]) + p["Gf"] * (sink[j] - x[1])
        return [fw / cw, fi / p["Ci"]]

    t = np.arange(U.shape[0]) * DT
    s = solve_ivp(f, (0, t[-1]), x0, t_eval=t, rtol=1e-10, atol=1e-6, max_step=DT / 8)
    return s.y


def test_recursion_error_against_a_fine_integration():
    """Hourly steps of a fast buffer (τ about 10 h) whose capacity changes by a factor
    of more than 1.5 along its path: within 0.1 Pa of the ODE's solution over swings of
    more than 200 Pa."""
    N = 200
    U = _inputs(N, seed=5)
    p = dict(CELLAR, Cw=0.05, Gi=1.5e-6)
    k = 0.95
    m = hb.model("hygric_2c_fixed", sink="temperature", isotherm="gab").with_slopes(["Pe"])
    x0 = [0.6 * P_REF, 1000.0]
    Y, valid = m.forward(np.array([[*[p[n] for n in m.parameter_names[:-1]], k]]), U, DT, x0=x0)
    pw, ref = _fine(p, U, x0, k)
    assert valid[0]
    cap = gab_capacity_factor(pw / P_REF, k)
    assert cap.max() / cap.min() > 1.5 and np.ptp(ref) > 200
    assert np.max(np.abs(Y[0, :, 0] - ref)) < 0.1


def _exact(m, P, U, x0):
    """Pi at every step's start by the exact step (:func:`gab_step`: the closed-form
    eigen-decomposition and exponentials of each step), one step at a time."""
    sb, slope = m.series(U)
    kp, ks = m.kernel_parameters(P), m.shape(P)
    out = np.empty((P.shape[0], U.shape[0]))
    for p in range(P.shape[0]):
        gc = gab_constants(kp[p], ks[p])
        (xw, xi), xp = x0[p], x0[p, 0]
        for k in range(U.shape[0]):
            out[p, k] = xi
            m0, m1, m2, m3, f0, f1 = gab_step(gc, xw, xp, sb, k, DT, 1 / DT, slope)
            xp = xw
            xw, xi = m0 * xw + m1 * xi + f0, m2 * xw + m3 * xi + f1
    return out


def test_the_tabulated_transitions_equal_the_exact_step():
    """The simulation's transitions read from the table of the step's matrix functions
    (Chebyshev interpolants in ρ = r/f) equal the exact step's to 1e-10 relative: a
    sorbing buffer at a varying Ti with a sink at Tf, 8 parameter sets spread by e^±2
    around an attic's, K_gab over its prior range."""
    N = 600
    rng = np.random.default_rng(11)
    U = _inputs(N, seed=2)
    t = np.arange(N)
    ti = 12 + 8 * np.sin(2 * np.pi * (t - 15) / 24) + rng.normal(0, 0.5, N)
    U = np.column_stack([U[:, :2], ti, U[:, 2]])
    m = hb.model("hygric_2c_sorption", sink="temperature", isotherm="gab").with_slopes(["Pe"])
    assert m.input_names == ("Pe", "Pe_slope", "Ti", "Tf")
    base = dict(Cm=40.0, Ci=1.4e-3, Gi=1.2e-7, Gfast=2.5e-7, Gf=3e-8, phi_f=0.9, K_gab=0.75)
    P = np.array([base[n] for n in m.parameter_names]) * np.exp(rng.uniform(-2, 2, (8, 7)))
    P[:, -2] = rng.uniform(0.5, 1.0, 8)
    P[:, -1] = np.r_[0.75, rng.uniform(0.05, 1.9, 7)]
    x0 = np.column_stack([rng.uniform(0.3, 0.9, 8) * P_REF, np.full(8, 1000.0)])
    Y, valid = m.forward(P, U, DT, x0=x0)
    assert valid.all()
    ref = _exact(m, P, U, x0)
    np.testing.assert_allclose(Y[:, :, 0], ref, rtol=1e-10, atol=0)


def test_a_start_far_from_the_prior_mean_is_found_along_its_own_path():
    """A slow GAB wall that starts 400 Pa below the prior mean (the steady state of the
    first inputs): the start's quadratic form taken about the prior mean's trajectory
    (whose capacity is not the one the wall crosses) misplaces the conditional mean of
    the start and costs log-likelihood at the true parameters; taken once more about
    the trajectory from that conditional mean, the start is found to within 5 % of its
    offset, and the true parameters' likelihood is that of their own path."""
    N = 720
    U = _inputs(N, seed=2)
    p = dict(CELLAR, Cw=1.5, K_gab=1.0)
    m = hb.model("hygric_2c_fixed", sink="temperature", isotherm="gab").with_slopes(["Pe"])
    P = np.array([[p[n] for n in m.parameter_names]])
    steady = m.steady_state(P, U[:48].mean(axis=0))[0]
    x0 = steady - [400.0, 150.0]
    obs = m.forward(P, U, DT, x0=x0)[0][0] + np.random.default_rng(4).normal(0, 2.0, (N, 1))
    nm = get_noise_model("ar1_white")
    kw = dict(warmup=0, init_window=48, initial_state="estimate")
    lp = LogPosterior(m, parameters_for(m, nm), nm, U, obs, **kw)
    theta = np.column_stack([P, [[2.0, 0.5, 2.0]]])
    found = lp.initial_states(theta)[0]
    ll = lp.log_likelihood(theta)[0]
    lp._relinearise = False  # the quadratic form about the prior mean's trajectory only
    once = lp.initial_states(theta)[0]
    assert np.all(np.abs(found - x0) < 0.05 * 400.0), (found, x0)
    assert np.abs(once - x0).max() > 4 * np.abs(found - x0).max(), (once, found, x0)
    assert ll > lp.log_likelihood(theta)[0] + 100.0


def test_the_first_pass_ends_where_the_start_is_forgotten():
    """The likelihood's first pass about a GAB wall's prior-mean trajectory keeps only the
    start's conditional mean, and ends each walker where the start's free responses have
    died. On a record 60 to 150 times the fast walls' time constants: their first pass
    stops before the record's end (a slow wall's runs it all), the start's gradient and
    curvature it gives equal those of the whole record to 1e-10, and so do the
    log-likelihood and the start's conditional mean, for walkers whose start lies near
    and 400 Pa away from the prior mean; the far start does take the second pass (it
    moves the likelihood)."""
    N = 8760
    U = _inputs(N, seed=3)
    m = hb.model("hygric_2c_fixed", sink="temperature", isotherm="gab").with_slopes(["Pe"])
    cw = np.array([0.005, 0.015, 0.0035, 1.5])  # the last a slow wall
    P = np.array([[dict(CELLAR, Cw=c, K_gab=0.9)[n] for n in m.parameter_names] for c in cw])
    nm = get_noise_model("ar1_white")
    theta = np.column_stack([P, np.tile([2.0, 0.5, 2.0], (4, 1))])
    steady = m.steady_state(P[:1], U[:48].mean(axis=0))[0]
    rng = np.random.default_rng(6)
    for offset in (0.0, 400.0):
        x0 = steady - [offset, 0.0]
        obs = m.forward(P[:1], U, DT, x0=x0)[0][0] + rng.normal(0, 2.0, (N, 1))
        lp = LogPosterior(m, parameters_for(m, nm), nm, U, obs, warmup=0, init_window=48,
                          initial_state="estimate")  # fmt: skip
        ll, start = lp.log_likelihood(theta), lp.initial_states(theta)
        tm, tn = lp.split(theta)
        xm = lp._x0_mean(lp._form(tm))
        first, whole = (
            coupled_filter_stats(
                m, tm, lp._series, xm, lp.observed, nm, tn, basis=True, dt=DT, stop=stop
            )
            for stop in (FIRST_PASS_STOP, 0.0)
        )
        assert np.all(first[2, :3] < N) and first[2, 1] > first[2, 0], first[2]
        assert first[2, 3] == N
        np.testing.assert_allclose(first[3:], whole[3:], rtol=1e-10, atol=0)
        lp._first_pass_stop = 0.0
        np.testing.assert_allclose(ll, lp.log_likelihood(theta), rtol=1e-10, atol=0)
        np.testing.assert_allclose(start, lp.initial_states(theta), rtol=1e-10, atol=0)
        if offset:
            lp._relinearise = False
            assert ll[0] > lp.log_likelihood(theta)[0] + 1.0
