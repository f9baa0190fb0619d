"""The tempered likelihood (inference/tempering.py): the long-run variance ratio of the
innovations, the innovations themselves, and the temperature in the log-posterior."""

from __future__ import annotations

import numpy as np
import pytest

import heritage_bayes as hb
from heritage_bayes.inference.likelihoods import ar1_white_innovations, get_noise_model
from heritage_bayes.inference.parameters import parameters_for
from heritage_bayes.inference.posterior import LogPosterior
from heritage_bayes.inference.tempering import (
    innovations_at,
    likelihood_temperature,
    long_run_variance_ratio,
)


def _ar1(rng, n, phi, sd=1.0):
    e = np.empty(n)
    e[0] = rng.normal(0, sd)
    z = rng.normal(0, sd * np.sqrt(1 - phi**2), n)
    for k in range(1, n):
        e[k] = phi * e[k - 1] + z[k]
    return e


@pytest.mark.parametrize("phi", [0.0, 0.5, 0.8])
def test_long_run_variance_ratio_of_an_ar1(phi):
    """For an AR(1) the long-run variance ratio is (1 + φ)/(1 - φ) (1 for white noise);
    the Bartlett window of L lags underestimates it by about 2φ/((1-φ)²(L+1)) and the
    estimate's relative sd is sqrt(4L/(3N)) (Newey & West 1987): with N = 40 000 and
    L = 60, 4.5 %; the tolerance is 4 of those plus the window's bias."""
    rng = np.random.default_rng(5)
    n, L = 40_000, 60
    w = _ar1(rng, n, phi)
    w[1000:1300] = np.nan  # a gap: pairs across it are skipped
    exact = (1 + phi) / (1 - phi)
    bias = 2 * phi / ((1 - phi) ** 2 * (L + 1))
    got = long_run_variance_ratio(w, L)
    assert got == pytest.approx(exact - bias, rel=4 * np.sqrt(4 * L / (3 * n)))
    with pytest.raises(ValueError, match="bandwidth of 5000 steps"):
        long_run_variance_ratio(w[:9000], 5000)


def test_ar1_white_innovations_are_white_under_the_true_noise():
    """AR(1) + white residuals filtered with their own parameters give innovations of
    unit variance and no correlation: κ ≈ 1 (sd of the variance estimate √(2/N) ≈ 0.9 %
    for N = 25 000; κ's sd √(4L/3N) ≈ 5 % for L = 48)."""
    rng = np.random.default_rng(3)
    n, sigma, phi, w = 25_000, 0.3, 0.93, 0.1
    e = _ar1(rng, n, phi, sigma) + rng.normal(0, w, n)
    e[500:700] = np.nan
    v = ar1_white_innovations(e, sigma, phi, w)
    assert np.isnan(v[500:700]).all()
    assert np.nanvar(v) == pytest.approx(1.0, abs=4 * np.sqrt(2 / n))
    assert long_run_variance_ratio(v, 48) == pytest.approx(1.0, abs=4 * np.sqrt(4 * 48 / (3 * n)))
    # the raw residual is far from white: its ratio is (1 + φ)/(1 - φ) damped by w
    assert long_run_variance_ratio(e, 48) > 10


def _posterior(noise_name, y_extra):
    m = hb.model("thermal_2c", surfaces=())
    rng = np.random.default_rng(2)
    n = 600
    t = np.arange(n)
    U = np.column_stack([8 + 5 * np.sin(2 * np.pi * t / 24) + rng.normal(0, 1, n), np.full(n, 9.0)])
    theta_m = {"Cw": 2e7, "Ci": 1e6, "Gw": 60.0, "Gi": 400.0, "Gfast": 30.0, "Gf": 5.0}
    tm = np.array([[theta_m[k] for k in m.parameter_names]])
    y = m.forward(tm, U, 3600.0, u_init=U[:48].mean(axis=0))[0][0] + y_extra(rng, n)[:, None]
    noise = get_noise_model(noise_name)
    ps = parameters_for(m, noise, room_volume=200)
    lp = LogPosterior(m, ps, noise, U, y, warmup=0, init_window=48, initial_state="estimate")
    vals = {**theta_m, "sigma_Ti": 0.3, "phi_Ti": 0.9, "sigma_meas_Ti": 0.1, "q_Ti": 0.1}
    vals.update(q_Tw=0.01)
    return lp, np.array([vals[k] for k in ps.names])


@pytest.mark.parametrize("noise_name", ["ar1_white", "kalman"])
def test_temperature_divides_the_likelihood_only(noise_name):
    """log posterior = log prior + log L / κ; ``log_likelihood`` stays untempered; a
    slow error the noise model lacks (a random walk of 0.05 K/√h on top of white
    noise) gives κ > 1 at a bandwidth of a day, white data κ = 1 at most a little."""
    lp, theta = _posterior(noise_name, lambda rng, n: np.cumsum(rng.normal(0, 0.05, n)))
    x = lp.params.to_unconstrained(theta[None])
    base = lp(x)[0]
    ll = lp.log_likelihood(theta[None])[0]
    kappa = likelihood_temperature(lp, theta, 24)
    assert kappa > 1.5
    lp.temperature = kappa
    assert lp(x)[0] == pytest.approx(base - ll + ll / kappa, rel=1e-10)
    assert lp.log_likelihood(theta[None])[0] == pytest.approx(ll, rel=1e-12)
    w = innovations_at(lp, theta)
    assert w.shape == lp.observed.shape and np.isfinite(w).all()


def test_likelihood_temperature_config_reaches_the_posterior():
    """``thermal.likelihood_temperature`` (default 2 for a thermal section of one or two
    capacity nodes, 1 for a richer one and for a hygric one; at least 1): the section's
    LogPosterior divides its log-likelihood by it (the prior untouched), and a
    temperature below 1 is a ConfigError naming the key."""
    from heritage_bayes.calibration.ladder import section_log_posterior as _log_posterior
    from heritage_bayes.config import parse_config
    from heritage_bayes.errors import ConfigError
    from heritage_bayes.models import build_model
    from heritage_bayes.prepare import prepare

    raw = {
        "data": {"demo": {"seed": 7}},
        "periods": {
            "calibration": {"start": "2019-01-02", "end": "2019-01-20"},
            "validation": {"start": "2019-01-20", "end": "2019-01-25"},
        },
        "thermal": {"model": "thermal_1c", "likelihood_temperature": 2.0},
    }
    cfg = parse_config(raw)
    assert cfg.thermal.likelihood_temperature == 2.0
    prep = prepare(cfg)
    m = build_model(cfg, "thermal")
    lp2 = _log_posterior(cfg, prep, "thermal", m, {})
    cfg1 = parse_config({**raw, "thermal": {"model": "thermal_1c", "likelihood_temperature": 1}})
    lp1 = _log_posterior(cfg1, prep, "thermal", m, {})
    assert (lp1.temperature, lp2.temperature) == (1.0, 2.0)
    # the defaults by domain: 2 for the thermal section, 1 for the hygric one
    cfg_d = parse_config(
        {**raw, "thermal": {"model": "thermal_1c"}, "hygric": {"model": "hygric_1c"}}
    )
    assert cfg_d.thermal.likelihood_temperature is None
    assert _log_posterior(cfg_d, prep, "thermal", m, {}).temperature == 2.0
    prep_d = prepare(cfg_d)
    lp_h = _log_posterior(cfg_d, prep_d, "hygric", build_model(cfg_d, "hygric"), {})
    assert lp_h.temperature == 1.0
    # ... and 2 for a hygric model whose buffer sorbs at the materials' temperature
    cfg_s = parse_config({**raw, "hygric": {"model": "hygric_2c_sorption"}})
    m_s = build_model(cfg_s, "hygric")
    assert m_s.sorption and cfg_s.hygric.likelihood_temperature is None
    assert _log_posterior(cfg_s, prepare(cfg_s), "hygric", m_s, {}).temperature == 2.0
    # ... 2 for one with a vapour sink at a temperature (a cellar's ground) and a linear
    # wall (under its default noise, kalman), 3 with a GAB wall (ar1_white), 1 with a
    # constant fixed node
    for sink, iso, want in (
        ("temperature", "linear", ("kalman", 2.0)),
        ("temperature", "gab", ("ar1_white", 3.0)),
        ("constant", "linear", ("ar1_white", 1.0)),
    ):
        hyg = {"model": "hygric_2c_fixed", "options": {"sink": sink, "isotherm": iso}}
        cfg_k = parse_config({**raw, "hygric": hyg})
        m_k = build_model(cfg_k, "hygric")
        lp_k = _log_posterior(cfg_k, prepare(cfg_k), "hygric", m_k, {})
        got = (lp_k.noise.name, lp_k.temperature)
        assert (getattr(m_k, "sink", "constant"), got) == (sink, want)
    # ... and 1 for a thermal network of more than two capacity nodes (thermal_4a),
    # unless the config sets it
    cfg_4a = parse_config({**raw, "thermal": {"model": "thermal_4a"}})
    m4 = build_model(cfg_4a, "thermal")
    assert m4.n_states > 2
    assert _log_posterior(cfg_4a, prepare(cfg_4a), "thermal", m4, {}).temperature == 1.0
    assert (
        cfg_4a.thermal.model_copy(update={"likelihood_temperature": 2.0}).temperature(
            "thermal", m4.n_states
        )
        == 2.0
    )
    values = {"Ci": 2e7, "Ge": 150.0, "Gf": 25.0, "sigma_Ti": 0.2, "phi_Ti": 0.9}
    theta = np.array(
        [[values.get(n, 1.0 if n.startswith("fI") else 0.1) for n in lp1.params.names]]
    )
    theta = np.vstack([theta, theta * np.where(np.array(lp1.params.names) == "Ge", 1.5, 1.0)])
    x = lp1.params.to_unconstrained(theta)
    ll = lp1.log_likelihood(theta)
    assert np.isfinite(ll).all()
    d1, d2 = lp1(x), lp2(x)
    # the same prior in both: the difference is half the log-likelihood
    np.testing.assert_allclose(d1 - d2, ll / 2.0, rtol=1e-9)
    with pytest.raises(ConfigError, match="likelihood_temperature"):
        parse_config({**raw, "thermal": {"model": "thermal_1c", "likelihood_temperature": 0.5}})
