"""Differential evolution with global independence proposals (``sampler.moves: dime`` and
``de_global``; :mod:`heritage_bayes.inference.moves`).

What must hold: the move leaves the target invariant (its Metropolis-Hastings factor is
right: checked where the global draws are every proposal, on a skewed target the t does
not match), its proposal is refitted only from rows up to the last convergence check,
so a chain resumed after an interrupt in the middle of a chunk is the uninterrupted
chain bit for bit, and on a ridge it mixes faster than plain differential evolution.
"""

from __future__ import annotations

import emcee
import numpy as np
import pytest
from scipy import stats
from threadpoolctl import threadpool_limits

from _chain_helpers import Ridge as _Ridge
from _chain_helpers import interrupt_at
from heritage_bayes.inference.monitor import _last_check, _next_check, make_moves
from heritage_bayes.inference.moves import MAX_FIT_POINTS, GlobalDEMove, refit_moves
from heritage_bayes.inference.sampler import run_sampler


def _skewed(X):
    """log density (up to a constant) of (a, b) with a ~ Gamma(3) (skewed) and
    b | a ~ N(a, 0.5²)."""
    X = np.atleast_2d(X)
    a, b = X[:, 0], X[:, 1]
    with np.errstate(invalid="ignore", divide="ignore"):
        out = 2.0 * np.log(a) - a - 0.5 * ((b - a) / 0.5) ** 2
    return np.where(a > 0, out, -np.inf)


def test_the_global_draws_alone_leave_a_skewed_target_invariant():
    # every proposal an independence draw from a symmetric t fitted once: only a right
    # MH factor gives the skewed marginal (mean 3, variance 3, skewness 2/sqrt(3))
    move = GlobalDEMove(p_global=1.0)
    rng = np.random.default_rng(0)
    a = rng.gamma(3.0, size=4000)
    assert move.fit(np.column_stack([a, a + rng.normal(0, 0.5, a.size)]))
    sampler = emcee.EnsembleSampler(16, 2, _skewed, vectorize=True, moves=[(move, 1.0)])
    sampler.random_state = np.random.RandomState(1).get_state()
    p0 = np.column_stack([np.full(16, 3.0), np.full(16, 3.0)]) + 0.1 * rng.normal(size=(16, 2))
    with threadpool_limits(limits=1, user_api="blas"):
        sampler.run_mcmc(p0, 3500)
    draws = sampler.get_chain(discard=500, flat=True)
    # acceptance ~0.76, τ ≈ 3 steps: ~16 000 effective draws; Monte-Carlo sd of the
    # mean 0.014, of the variance sqrt((μ4 - σ⁴)/n) = sqrt(36/16 000) = 0.05, of the
    # median 1/(2 f(m) sqrt(n)) = 0.016, of P(a > 6) sqrt(p(1-p)/n) = 0.002; tolerances
    # 4 sd (20 000 steps, seeds 1-3: mean 3.001/2.999/3.000, variance 3.015/2.985/3.007)
    a = draws[:, 0]
    assert np.mean(sampler.acceptance_fraction) > 0.6
    assert abs(a.mean() - 3.0) < 0.06
    assert abs(a.var() - 3.0) < 0.2
    assert abs(np.median(a) - stats.gamma(3).median()) < 0.065
    assert abs(np.mean(a > 6.0) - stats.gamma(3).sf(6.0)) < 0.008
    assert abs(np.var(draws[:, 1] - draws[:, 0]) - 0.25) < 0.02


def test_before_a_fit_the_move_is_emcee_de():
    f = _Ridge()
    kw = dict(seed=5, nwalkers=8, max_steps=400, check_every=1000, tau_factor=1e4)
    de = run_sampler(f, np.zeros(3), moves="de", **kw)
    glob = run_sampler(f, np.zeros(3), moves="dime", **kw)  # one chunk: never fitted
    np.testing.assert_array_equal(de.chain, glob.chain)


def test_on_a_ridge_it_mixes_faster_than_de_and_samples_the_target():
    f = _Ridge()
    kw = dict(seed=3, nwalkers=8, max_steps=6000, check_every=500, tau_factor=1e4)
    de = run_sampler(f, np.zeros(3), moves="de", **kw)
    glob = run_sampler(f, np.zeros(3), moves="dime", **kw)
    assert np.max(glob.tau) < 0.8 * np.max(de.tau)  # 8.2 against 11.7 steps (start included)
    draws = glob.chain[1000:].reshape(-1, 3)
    np.testing.assert_allclose(np.cov(draws, rowvar=False), f.cov, atol=0.08)
    np.testing.assert_allclose(draws.mean(axis=0), 0.0, atol=0.1)


def test_refit_uses_the_second_half_thinned_and_is_deterministic():
    rng = np.random.default_rng(2)
    chain = rng.normal(size=(3000, 8, 3))
    chain[:1500] += 100.0  # the first half (the spread from the start) is left out
    a, b = make_moves("dime"), make_moves("dime")
    refit_moves(a, chain)
    refit_moves(b, chain.copy())
    (ma, _), (mb, _) = a[0], b[0]
    np.testing.assert_array_equal(ma.mean, mb.mean)
    np.testing.assert_array_equal(ma.chol, mb.chol)
    assert np.all(np.abs(ma.mean) < 0.1)
    assert 1500 * 8 > MAX_FIT_POINTS  # the thinning was exercised
    # the t's covariance (scale × df / (df - 2)) is the rows' covariance
    np.testing.assert_allclose(ma.chol @ ma.chol.T * ma.df / (ma.df - 2), np.eye(3), atol=0.06)
    # de_global: the DE part carries the global draws, the snooker part does not
    kinds = [type(m) for m, _ in make_moves("de_global")]
    assert kinds == [GlobalDEMove, emcee.moves.DESnookerMove]


def test_a_degenerate_fit_keeps_the_move_as_it_was():
    move = GlobalDEMove()
    assert not move.fit(np.zeros((2, 3)))  # fewer points than dimensions + 1
    assert not move.fit(np.ones((50, 3)))  # singular
    assert move.mean is None
    with pytest.raises(ValueError, match="p_global"):
        GlobalDEMove(p_global=1.5)
    with pytest.raises(ValueError, match="df"):
        GlobalDEMove(df=2)


def test_last_check_is_the_check_at_or_before_a_step():
    checks = [0]
    while checks[-1] < 40_000:
        checks.append(_next_check(checks[-1], 500))
    for done in (0, 1, 499, 500, 501, 4999, 5000, 5001, 12_345, 39_999):
        expect = max(c for c in checks if c <= done)
        assert _last_check(done, 500) == expect


@pytest.mark.parametrize("max_rows", [None, 300])
def test_resume_mid_chunk_continues_the_global_chain_bit_for_bit(tmp_path, max_rows):
    f = _Ridge()
    kw = dict(seed=3, nwalkers=8, check_every=100, tau_factor=1e4, moves="dime", tag="t")
    kw["max_rows"] = max_rows
    a = run_sampler(f, np.zeros(3), max_steps=2500, checkpoint=tmp_path / "a.h5", **kw)

    # step 1650: in the middle of the chunk that ends at the check at 1 700
    interrupt_at(f, tmp_path / "c.h5", step=1650, max_steps=2500, **kw)
    c = run_sampler(f, np.zeros(3), max_steps=2500, checkpoint=tmp_path / "c.h5", resume=True, **kw)
    assert 1600 < c.resumed_from < 1700
    np.testing.assert_array_equal(c.chain, a.chain)
    np.testing.assert_array_equal(c.tau, a.tau)
    assert c.tau_history == a.tau_history
