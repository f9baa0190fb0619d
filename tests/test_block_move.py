"""Differential evolution within a block of coordinates (``sampler.block_weight``;
:class:`heritage_bayes.inference.moves.BlockDEMove`).

What must hold: the move changes only its block; mixed with DE it leaves the target
invariant (a narrow ridge beside a flat, prior-bounded direction, the geometry of a
4a network whose interior mass the data do not see) and crosses the flat direction
in fewer steps; with no block, or a weight of 0, the chain is the one of the named
moves bit for bit; ``hbayes calibrate`` takes the block from the Laplace check.
"""

from __future__ import annotations

from types import SimpleNamespace

import emcee
import numpy as np
import pytest
import yaml

from heritage_bayes.config import chain_tag, parse_config
from heritage_bayes.config.sampler import BLOCK_WEIGHT
from heritage_bayes.errors import ConfigError
from heritage_bayes.inference.monitor import make_moves
from heritage_bayes.inference.moves import BlockDEMove, block_weight, unidentified_block
from heritage_bayes.inference.sampler import run_sampler

_L = np.linalg.cholesky(np.array([[1.0, 0.995], [0.995, 1.0]]))
_LINV = np.linalg.inv(_L)


def _ridge_beside_flat(X):
    """log density of (a, b) ~ N(0, [[1, 0.995], [0.995, 1]]) and c ~ U(0, 10)."""
    X = np.atleast_2d(X)
    z = X[:, :2] @ _LINV.T
    c = X[:, 2]
    return np.where((c > 0) & (c < 10), -0.5 * np.sum(z * z, axis=1), -np.inf)


_KW = dict(nwalkers=8, max_steps=20_000, check_every=1000, tau_factor=1e4)


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
    x0 = np.array([0.0, 0.0, 5.0])
    kw = dict(_KW, max_steps=1500, seed=4)
    ref = run_sampler(_ridge_beside_flat, x0, **kw)
    for block, w in (((), 0.3), ([2], 0.0)):
        other = run_sampler(_ridge_beside_flat, x0, block=block, block_weight=w, **kw)
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


def test_mixed_with_de_it_samples_the_target_and_crosses_the_flat_direction_faster():
    seed = 1
    x0 = np.array([0.0, 0.0, 5.0])
    de = run_sampler(_ridge_beside_flat, x0, seed=seed, **_KW)
    blk = run_sampler(_ridge_beside_flat, x0, seed=seed, block=[2], block_weight=0.3, **_KW)
    # measured (seeds 1-3): τ of c 13.9-15.0 steps with DE alone, 7.6-8.8 with the block
    # move; the ridge's τ rises by about 1 / (1 - 0.3) (15 -> 21-23)
    assert blk.tau[2] < 0.7 * de.tau[2]
    d = blk.chain[2000:].reshape(-1, 3)
    # 18 000 steps x 8 walkers, τ <= 23: at least 6 000 effective draws. Monte-Carlo sd
    # of c's mean sqrt(8.33 / 6 000) = 0.037, of its variance sqrt((125 - 69.4) / 6 000)
    # = 0.096, of the ridge's variances sqrt(2 / 6 000) = 0.018; tolerances 4 sd
    # (seeds 1-3: mean 4.965-4.996, variance 8.25-8.39, ridge variances 0.96-0.995)
    assert abs(d[:, 2].mean() - 5.0) < 0.15
    assert abs(d[:, 2].var() - 100.0 / 12.0) < 0.4
    np.testing.assert_allclose(
        np.cov(d[:, :2], rowvar=False), [[1.0, 0.995], [0.995, 1.0]], atol=0.075
    )
    assert d[:, 2].min() > 0.0 and d[:, 2].max() < 10.0


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
    assert block_weight(None, 3) == BLOCK_WEIGHT > 0
    assert block_weight(None, 2) == 0.0
    assert block_weight(0.3, 1) == 0.3
    # the default leaves the chain tag of earlier runs; a weight set changes it
    assert chain_tag(_cfg(", block_weight: 0.2")) != chain_tag(_cfg())
    with pytest.raises(ConfigError, match="block_weight"):
        _cfg(", block_weight: 1")
