"""Differential evolution within a block of coordinates (``sampler.block_weight``;
:class:`heritage_bayes.inference.moves.BlockDEMove`).

What must hold: the move changes only its block; mixed with DE it leaves the target
invariant (a narrow ridge beside a flat, prior-bounded L-shaped region, the geometry
of a 4a network whose interior mass the data do not see) and crosses the L in fewer
steps; an interrupted chain resumes bit for bit; with no block, or a weight of 0, the
chain is the one of the named moves bit for bit; ``hbayes calibrate`` takes the block
from the Laplace check.
"""

from __future__ import annotations

from types import SimpleNamespace

import emcee
import numpy as np
import pytest
import yaml

from _chain_helpers import Ridge, interrupt_at
from heritage_bayes.config import chain_tag, parse_config
from heritage_bayes.config.sampler import BLOCK_WEIGHT
from heritage_bayes.errors import ConfigError
from heritage_bayes.inference.monitor import make_moves
from heritage_bayes.inference.moves import (
    BlockDEMove,
    unidentified_block,
)
from heritage_bayes.inference.sampler import run_sampler

_L = np.linalg.cholesky(np.array([[1.0, 0.995], [0.995, 1.0]]))
_LINV = np.linalg.inv(_L)


def _ridge_beside_l(X):
    """log density of (a, b) ~ N(0, [[1, 0.995], [0.995, 1]]) beside (c, e) uniform on
    an L: [0, 10]² with c < 1 or e < 1 (a mass that is invisible when either its
    capacity or its conductance is small)."""
    X = np.atleast_2d(X)
    z = X[:, :2] @ _LINV.T
    c, e = X[:, 2], X[:, 3]
    ok = (c > 0) & (c < 10) & (e > 0) & (e < 10) & ((c < 1) | (e < 1))
    return np.where(ok, -0.5 * np.sum(z * z, axis=1), -np.inf)


_KW = dict(nwalkers=10, max_steps=20_000, check_every=1000, tau_factor=1e4)
_X0 = np.array([0.0, 0.0, 0.5, 0.5])


def test_the_proposal_moves_the_block_only():
    move = BlockDEMove([2, 0, 2])
    np.testing.assert_array_equal(move.block, [0, 2])
    assert move.gamma0 == pytest.approx(2.38 / np.sqrt(4))
    rng = np.random.RandomState(0)
    s = rng.normal(size=(5, 4))
    c = [rng.normal(size=(5, 4))]
    move.setup(s)
    q, factors = move.get_proposal(s, c, np.random.RandomState(1))
    np.testing.assert_array_equal(q[:, [1, 3]], s[:, [1, 3]])
    assert np.all(q[:, [0, 2]] != s[:, [0, 2]])
    np.testing.assert_array_equal(factors, 0.0)
    with pytest.raises(ValueError, match="no coordinate"):
        BlockDEMove([])


def test_no_block_or_zero_weight_is_the_named_moves_chain_bit_for_bit():
    kw = dict(_KW, max_steps=1500, seed=4)
    ref = run_sampler(_ridge_beside_l, _X0, **kw)
    for block, w in (((), 0.3), ([2, 3], 0.0)):
        other = run_sampler(_ridge_beside_l, _X0, block=block, block_weight=w, **kw)
        np.testing.assert_array_equal(other.chain, ref.chain)
    assert [type(m) for m, _ in make_moves("de_snooker", (), 0.3)] == [
        emcee.moves.DEMove,
        emcee.moves.DESnookerMove,
    ]
    moves = make_moves("de_snooker", [2], 0.25)
    assert [w for _, w in moves] == pytest.approx([0.6, 0.15, 0.25])
    assert isinstance(moves[-1][0], BlockDEMove)
    with pytest.raises(ValueError, match="block_weight"):
        make_moves("de_snooker", [2], 1.0)


def test_mixed_with_de_it_samples_the_target_and_crosses_the_l_faster():
    de = run_sampler(_ridge_beside_l, _X0, seed=1, **_KW)
    blk = run_sampler(_ridge_beside_l, _X0, seed=1, block=[2, 3], block_weight=0.3, **_KW)
    # measured (seeds 1-3): τ of the L's coordinates at most 224 / 133 / 190 steps with
    # DE alone, 78 / 73 / 71 with the block move; the ridge's τ 53-57 -> 65-74
    assert max(blk.tau[2:]) < 0.7 * max(de.tau[2:])
    d = blk.chain[2000:].reshape(-1, 4)
    # 18 000 steps x 10 walkers, τ <= 80: at least 2 200 effective draws. Exact: P(c < 1)
    # = 10/19 = 0.526, E[c] = 54.5/19 = 2.868, var c = 9.47; Monte-Carlo sd 0.011,
    # 0.066; the ridge's variances sqrt(2 / 2 200) = 0.03; tolerances 4 sd (seeds 1-3:
    # 0.522-0.533, 2.805-2.890, 0.90-0.98; DE alone on seed 3: 0.461, 3.247)
    assert abs(np.mean(d[:, 2] < 1.0) - 10.0 / 19.0) < 0.045
    assert abs(d[:, 2].mean() - 54.5 / 19.0) < 0.26
    np.testing.assert_allclose(
        np.cov(d[:, :2], rowvar=False), [[1.0, 0.995], [0.995, 1.0]], atol=0.12
    )
    assert np.isfinite(_ridge_beside_l(d)).all()


@pytest.mark.parametrize("max_rows", [None, 300])
def test_resume_mid_chunk_continues_the_block_chain_bit_for_bit(tmp_path, max_rows):
    f = Ridge()
    kw = dict(seed=3, nwalkers=8, check_every=100, tau_factor=1e4, tag="t", max_rows=max_rows)
    # moves "de": two log-posterior calls a step, as interrupt_at counts (the snooker
    # move splits the ensemble in four)
    kw.update(moves="de", block=[2], block_weight=0.3)
    a = run_sampler(f, np.zeros(3), max_steps=2500, checkpoint=tmp_path / "a.h5", **kw)
    # step 1650: in the middle of the chunk that ends at the check at 1 700
    interrupt_at(f, tmp_path / "c.h5", step=1650, max_steps=2500, **kw)
    c = run_sampler(f, np.zeros(3), max_steps=2500, checkpoint=tmp_path / "c.h5", resume=True, **kw)
    assert 1600 < c.resumed_from < 1700
    np.testing.assert_array_equal(c.chain, a.chain)
    assert c.tau_history == a.tau_history


class _Laplace:
    def __init__(self, names):
        self.unidentified = names


class _LogPost:
    params = SimpleNamespace(free_names=("Cw", "Ci", "Cint", "Gint", "fsol", "sigma_Ti"))


def test_the_block_is_what_the_laplace_check_flags():
    assert unidentified_block(_LogPost, _Laplace(["Cint", "Gint", "fsol"])) == [2, 3, 4]
    assert unidentified_block(_LogPost, _Laplace([])) == []
    assert unidentified_block(_LogPost, None) == []


def _cfg(extra: str = ""):
    text = (
        "name: t\ndata: {demo: {seed: 3}}\n"
        "periods: {calibration: {start: 2019-01-02, end: 2019-01-20}}\n"
        "thermal: {model: thermal_1c}\n"
        f"sampler: {{max_time: 1min{extra}}}\n"
    )
    return parse_config(yaml.safe_load(text), source="t.yaml")


def test_the_config_key_its_default_and_the_chain_tag():
    assert _cfg().sampler.block_weight is None
    # unset: the block move for networks of three or more nodes only
    assert _cfg().sampler.block_weight_for(3) == BLOCK_WEIGHT > 0
    assert _cfg().sampler.block_weight_for(2) == 0.0
    assert _cfg(", block_weight: 0.3").sampler.block_weight_for(1) == 0.3
    # the default leaves the chain tag of earlier runs; a weight set changes it
    assert chain_tag(_cfg(", block_weight: 0.2")) != chain_tag(_cfg())
    with pytest.raises(ConfigError, match="block_weight"):
        _cfg(", block_weight: 1")
