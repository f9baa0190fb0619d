"""The bounded chain (``sampler.max_stored_steps``): thinned in place, resumed exactly.

A chain longer than ``max_rows`` steps is held every ``stride``-th step (issue 28: the
demo's thermal_4a chain at 171 500 steps was 0.9 GB in memory and on disk). What must
hold: the rows kept are exactly the steps of the stride of the unbounded chain (emcee's
chain itself does not change), τ is scaled back to steps, the stride never exceeds
τ/10, ``--resume`` after an interrupt rebuilds the same rows, and a chain shorter than
the bound is held as before.
"""

from __future__ import annotations

import h5py
import numpy as np
import pytest

from _chain_helpers import Ridge as _Ridge
from _chain_helpers import interrupt_at
from heritage_bayes.inference.monitor import ChainBuffer
from heritage_bayes.inference.sampler import run_sampler

KW = dict(seed=3, nwalkers=8, check_every=100, tau_factor=1e4, moves="stretch")


def test_buffer_keeps_the_steps_of_its_stride_whatever_the_chunks():
    rng = np.random.default_rng(0)
    x = rng.normal(size=(1000, 2, 3))
    lp = rng.normal(size=(1000, 2))
    buf = ChainBuffer(2, 3)
    for a, b in ((0, 130), (130, 131), (131, 500)):
        buf.append(x[a:b], lp[a:b])
    buf.halve()
    buf.halve()  # stride 4: steps 3, 7, 11, ...
    kept, _ = buf.append(x[500:1000], lp[500:1000])
    np.testing.assert_array_equal(buf.chain, x[3::4])
    np.testing.assert_array_equal(buf.log_prob, lp[3::4])
    np.testing.assert_array_equal(kept, x[503:1000:4])
    assert (buf.stride, buf.steps, buf.n) == (4, 1000, 250)
    other = ChainBuffer(2, 3, stride=4)
    other.load(buf.chain, buf.log_prob, 1000)
    np.testing.assert_array_equal(other.chain, buf.chain)
    with pytest.raises(ValueError, match="1000 steps at stride 4 has 250 rows"):
        other.load(buf.chain[:-1], buf.log_prob[:-1], 1000)


def test_bounded_chain_is_the_full_chain_thinned_and_tau_is_scaled_back():
    f = _Ridge()
    full = run_sampler(f, np.zeros(3), max_steps=3000, **KW)
    bounded = run_sampler(f, np.zeros(3), max_steps=3000, max_rows=400, **KW)
    s = bounded.stride
    # thinned down to the bound plus a chunk, unless the next halving would pass τ/10
    rows, tau_then = bounded.chain.shape[0], bounded.tau_history[-2][1]
    assert s >= 4 and (rows <= 400 + 100 or 2 * s > tau_then / 10)
    assert s <= tau_then / 10
    np.testing.assert_array_equal(bounded.chain, full.chain[s - 1 :: s])
    np.testing.assert_array_equal(bounded.log_prob, full.log_prob[s - 1 :: s])
    assert bounded.steps == 3000 and bounded.acceptance == pytest.approx(full.acceptance)
    # τ of the thinned chain × stride: the unthinned τ (46 steps here). For an AR(1)
    # of τ 46 thinned by 4, τ' = s (1 + ρ^s)/(1 - ρ^s) = 46.0: the bias is nil; what is
    # left is the estimator's window on a different number of lags (measured 0.3 %)
    np.testing.assert_allclose(bounded.tau, full.tau, rtol=0.05)
    assert bounded.tau_history[:3] == full.tau_history[:3]  # before the first halving
    # draws come from the same steps: burn and thin are in steps
    X, _ = bounded.draws()
    assert X.shape[1] == len(range(bounded.burn // s, 3000 // s, max(1, bounded.thin // s)))


def test_a_chain_shorter_than_the_bound_is_unchanged(tmp_path):
    f = _Ridge()
    a = run_sampler(f, np.zeros(3), max_steps=600, checkpoint=tmp_path / "a.h5", tag="t", **KW)
    b = run_sampler(
        f, np.zeros(3), max_steps=600, max_rows=600, checkpoint=tmp_path / "b.h5", tag="t", **KW
    )
    np.testing.assert_array_equal(a.chain, b.chain)
    assert b.stride == 1 and b.n_steps is None and a.tau_history == b.tau_history
    with h5py.File(tmp_path / "a.h5") as fa, h5py.File(tmp_path / "b.h5") as fb:
        assert fa.attrs["commit"] == fb.attrs["commit"]


def test_resume_after_an_interrupt_rebuilds_the_same_thinned_chain(tmp_path):
    f = _Ridge()
    kw = dict(KW, max_rows=300, tag="t")
    a = run_sampler(f, np.zeros(3), max_steps=2500, checkpoint=tmp_path / "a.h5", **kw)
    assert a.stride >= 4

    # Ctrl-C in the middle of a chunk after the chain was thinned twice
    interrupt_at(f, tmp_path / "c.h5", step=1650, max_steps=2500, **kw)
    with h5py.File(tmp_path / "c.h5") as fc:
        rows_saved = fc["chain"].shape[0]
    c = run_sampler(f, np.zeros(3), max_steps=2500, checkpoint=tmp_path / "c.h5", resume=True, **kw)
    assert 1000 < c.resumed_from < 2500 and c.resumed_from % c.stride != 0
    assert rows_saved == c.resumed_from // c.stride  # thinned on disk too
    np.testing.assert_array_equal(c.chain, a.chain)
    np.testing.assert_array_equal(c.tau, a.tau)
    assert c.tau_history == a.tau_history and c.steps == a.steps == 2500
    # and the checkpoint of the resumed run holds the same rows as the uninterrupted one
    with h5py.File(tmp_path / "a.h5") as fa, h5py.File(tmp_path / "c.h5") as fc:
        np.testing.assert_array_equal(fa["chain"][...], fc["chain"][...])


def test_the_stride_never_exceeds_a_tenth_of_tau():
    # independent Gaussian draws, walkers spread from the start: τ 9 then 18 steps at
    # the first checks, so a stride of 2 would pass τ/10 and the chain grows past the
    # bound; once τ ≥ 20 (τ 21.5 at step 300) it is thinned
    def iid(X):
        return -0.5 * np.sum(np.atleast_2d(X) ** 2, axis=1)

    kw = dict(KW, max_rows=200, init_ball=1.0)
    short = run_sampler(iid, np.zeros(2), max_steps=300, **kw)
    assert [round(h[1]) for h in short.tau_history[:2]] == [9, 18]
    assert short.stride == 1 and short.chain.shape[0] == 300
    longer = run_sampler(iid, np.zeros(2), max_steps=1500, **kw)
    assert longer.stride == 2 and all(h[1] >= 20 for h in longer.tau_history[2:])


def test_a_bound_below_two_steps_is_refused():
    from heritage_bayes.errors import InputError

    with pytest.raises(InputError, match=r"sampler\.max_stored_steps: expected at least 2"):
        run_sampler(_Ridge(), np.zeros(3), max_steps=100, max_rows=1, **KW)


def test_a_converged_thinned_chain_compacts_with_its_trace_stride_in_steps(tmp_path):
    f = _Ridge()
    kw = dict(KW, tau_factor=30, max_rhat=None, min_ess=None)
    res = run_sampler(
        f, np.zeros(3), max_steps=5000, max_rows=300, checkpoint=tmp_path / "c.h5", tag="t",
        compact=True, **kw,
    )  # fmt: skip
    assert res.converged and res.stride >= 2
    with h5py.File(tmp_path / "c.h5") as h:
        rows = h["chain"].shape[0]
        # the trace spans the whole chain: rows × trace_stride ≈ the steps
        assert abs(rows * int(h.attrs["trace_stride"]) - res.steps) <= h.attrs["trace_stride"]
