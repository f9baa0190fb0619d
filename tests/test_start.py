"""The Laplace start of the walkers (heritage_bayes.inference.start)."""

from __future__ import annotations

import numpy as np

from heritage_bayes.inference.sampler import run_sampler
from heritage_bayes.inference.start import laplace_ensemble, laplace_factor
from test_convergence import _BoxGauss


def _correlated(rho: float = 0.95, sd=(1.0, 3.0)):
    """A correlated 2-d Gaussian's log-density and its exact Hessian (of -log p)."""
    S = np.array([[sd[0] ** 2, rho * sd[0] * sd[1]], [rho * sd[0] * sd[1], sd[1] ** 2]])
    H = np.linalg.inv(S)

    def f(X):
        X = np.atleast_2d(X)
        return -0.5 * np.einsum("ki,ij,kj->k", X, H, X)

    return f, S, H


def test_laplace_start_draws_the_gaussian_of_the_curvature_and_is_seeded():
    f, S, H = _correlated()
    inf = np.full(2, np.inf)
    p0, lp0 = laplace_ensemble(
        f, np.zeros(2), H, 4000, np.random.default_rng(1), bounds=(-inf, inf)
    )
    assert p0.shape == (4000, 2) and np.all(np.isfinite(lp0))
    np.testing.assert_allclose(lp0, f(p0))
    # sample covariance of 4000 draws: relative standard error of a variance √(2/n) = 2.2 %
    C = np.cov(p0.T)
    np.testing.assert_allclose(np.diag(C), np.diag(S), rtol=4 * np.sqrt(2 / 4000))
    corr = C[0, 1] / np.sqrt(C[0, 0] * C[1, 1])
    # the standard error of a correlation coefficient is (1 - ρ²)/√n
    assert abs(corr - 0.95) < 4 * (1 - 0.95**2) / np.sqrt(4000)
    L = laplace_factor(H, (-inf, inf))
    np.testing.assert_allclose(L @ L.T, S, rtol=1e-10)
    a = laplace_ensemble(f, np.zeros(2), H, 8, np.random.default_rng(7), bounds=(-inf, inf))
    b = laplace_ensemble(f, np.zeros(2), H, 8, np.random.default_rng(7), bounds=(-inf, inf))
    np.testing.assert_array_equal(a[0], b[0])


def test_flat_directions_spread_at_most_over_the_prior_and_walls_are_respected():
    # no curvature along x1 (a ridge only the prior's box closes), a wall at x0 = 0.2
    f = _BoxGauss(mu=[0.0, 0.0], sd=[1.0, 1e9], lo=[-5.0, -2.0], hi=[0.2, 2.0])
    H = np.diag([1.0, 0.0])
    lo, hi = f.lo, f.hi
    L = laplace_factor(H, (lo, hi))
    # floor of the eigenvalues: 1 / (widest range)² = 1 / 5.2²
    np.testing.assert_allclose(np.sqrt(np.linalg.eigvalsh(L @ L.T)), [1.0, 5.2])
    p0, lp0 = laplace_ensemble(f, np.zeros(2), H, 64, np.random.default_rng(2), bounds=(lo, hi))
    assert np.all(p0 > lo) and np.all(p0 < hi) and np.all(np.isfinite(lp0))
    # without a finite log-posterior anywhere: None (the sampler falls back to the ball)
    never = _BoxGauss(mu=[0.0, 0.0], sd=[1.0, 1.0], lo=[1.0, 1.0], hi=[0.0, 0.0])
    got = laplace_ensemble(never, np.zeros(2), H, 8, np.random.default_rng(0), bounds=(lo, hi))
    assert got is None
    res = run_sampler(f, np.zeros(2), seed=1, nwalkers=8, max_steps=100, start_hessian=H * 0)
    assert res.chain.shape == (100, 8, 2)


def test_a_laplace_start_is_already_spread_and_samples_the_same():
    """From a 1e-3 ball the first steps of the ensemble sample a point, not the
    posterior; from the Laplace start (exact here: a Gaussian) the first steps already
    have the posterior's spread along its ridge, and the chain converges by the rule
    and samples the same Gaussian."""
    f, S, H = _correlated(rho=0.99, sd=(1.0, 10.0))
    kw = dict(seed=4, nwalkers=16, max_steps=40_000, check_every=250)
    ball = run_sampler(f, np.zeros(2), init_ball=1e-3, **kw)
    lap = run_sampler(f, np.zeros(2), start_hessian=H, **kw)
    assert ball.converged and lap.converged
    sd = np.sqrt(np.diag(S))
    # spread over the walkers at step 10: 16 draws, the sd's relative standard error
    # is about 1/√(2 × 16) = 18 %, and the ball's is 1e-3 × 10 steps of DE at most
    first_lap = lap.chain[10].std(axis=0) / sd
    first_ball = ball.chain[10].std(axis=0) / sd
    assert np.all(np.abs(first_lap - 1.0) < 4 / np.sqrt(2 * 16))
    assert np.all(first_ball < 0.1)
    x = lap.draws()[0].reshape(-1, 2)
    n_eff = min(x.shape[0], lap.steps * 16 / np.max(lap.tau) / 2)
    assert np.all(np.abs(x.mean(axis=0) / (sd / np.sqrt(n_eff))) < 4)
    np.testing.assert_allclose(x.std(axis=0) / sd, 1.0, atol=4 / np.sqrt(2 * n_eff))


def test_sampler_start_key_chooses_the_laplace_start_for_rich_networks_only():
    """``sampler.start``: auto starts networks of three or more nodes from the Laplace
    approximation, smaller ones from the ball (their chains unchanged); ball and
    laplace force either; a Laplace approximation that could not be taken (None)
    falls back to the ball; the key changes the chain's tag only when not the default
    ball (Ørholm's thermal_4a converges from the ball, not from laplace)."""
    from pathlib import Path

    import pytest

    from heritage_bayes.config import load_config
    from heritage_bayes.config.calibration import chain_tag
    from heritage_bayes.inference.start import start_hessian
    from test_coordinates import _logpost

    class Lap:
        hessian = np.eye(2)

    lp2, _ = _logpost("thermal_2c")
    lp1, _ = _logpost("thermal_1c")
    assert start_hessian(lp2, Lap(), "auto") is None
    assert start_hessian(lp1, Lap(), "auto") is None
    assert start_hessian(lp2, Lap(), "laplace") is Lap.hessian
    assert start_hessian(lp2, None, "laplace") is None
    assert start_hessian(lp2, Lap(), "ball") is None
    lp4 = type("LP", (), {"model": type("M", (), {"n_states": 3})()})()
    assert start_hessian(lp4, Lap(), "auto") is Lap.hessian
    with pytest.raises(ValueError, match=r"sampler\.start"):
        start_hessian(lp2, Lap(), "centre")
    base = load_config(Path(__file__).resolve().parents[1] / "configs" / "demo.yaml")
    assert base.sampler.start == "ball"

    def with_start(v):
        return base.model_copy(update={"sampler": base.sampler.model_copy(update={"start": v})})

    assert chain_tag(with_start("ball")) == chain_tag(base)
    assert chain_tag(with_start("laplace")) != chain_tag(base)
    assert chain_tag(with_start("auto")) != chain_tag(base)
