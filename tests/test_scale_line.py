"""The overall scale of a room without a measured heat input sampled on its own axis
(:mod:`heritage_bayes.inference.scale`): found, checked against the likelihood, an
exact change of variables, and a chain that spreads along it from the first step."""

from __future__ import annotations

import numpy as np
import pytest

import heritage_bayes as hb
from _chain_helpers import sunny_room_inputs
from heritage_bayes.config import prior_specs
from heritage_bayes.inference.coordinates import node_time_constants
from heritage_bayes.inference.likelihoods import get_noise_model
from heritage_bayes.inference.parameters import parameters_for
from heritage_bayes.inference.posterior import LogPosterior
from heritage_bayes.inference.sampler import run_sampler
from heritage_bayes.inference.scale import ScaleLine, scale_direction, scale_line

TRUTH = dict(Cw=5e7, Ci=2e6, Gw=150.0, Gi=300.0, Gfast=80.0, Gf=30.0, fI_S=3.0)


def _logpost(priors=None, N=24 * 12, seed=0):
    """A two-node room driven by the outdoor air, the sun and the ground, observed
    through its air temperature only: no heat input in watts."""
    rng = np.random.default_rng(seed)
    m = hb.model("thermal_2c", surfaces=("S",))
    U = sunny_room_inputs(m, N, rng)
    y = hb.simulate(m, {k: TRUTH[k] for k in m.parameter_names}, U)[:, 0]
    y = y + rng.normal(0, 0.1, N)
    noise = get_noise_model("ar1")
    ps = parameters_for(m, noise, prior_specs(priors or {}))
    return LogPosterior(m, ps, noise, U, y[:, None], warmup=24, init_window=24)


def _x(lp) -> np.ndarray:
    theta = [TRUTH.get(n, 0.1) if n != "phi_Ti" else 0.5 for n in lp.params.names]
    return lp.params.to_unconstrained(np.array([theta]))[0]


@pytest.fixture(scope="module")
def lp():
    return _logpost()


def test_the_scale_direction_is_found_and_the_likelihood_is_constant_along_it(lp):
    names = lp.params.free_names
    s = scale_direction(lp)
    assert {n for n, v in zip(names, s, strict=True) if v} == set(TRUTH)
    x = _x(lp)
    X = x + np.array([-2.0, 0.0, 3.0])[:, None] * s
    ll = lp.log_likelihood(lp.params.transform(X)[0])
    assert np.ptp(ll) < 1e-8 * abs(ll[1])
    c = scale_line(lp, None, x)
    assert isinstance(c, ScaleLine) and c.name == "log+scale"
    # one coordinate of the sampler moves the point along the scale, and only that
    Y = c.to_y(x[None])
    step = c.to_x(Y + 0.3 * np.eye(len(x))[c.index]) - c.to_x(Y)
    t = step[0, c.index]
    assert t != 0.0
    np.testing.assert_allclose(step[0], t * s, atol=1e-12)


def test_a_fixed_conductance_breaks_the_symmetry_and_the_coordinates_stay():
    lp = _logpost(priors={"Gw": {"fixed": 150.0}})
    assert scale_direction(lp) is not None  # the others still form a direction...
    assert scale_line(lp, None, _x(lp)) is None  # ...but the likelihood changes along it


LOGNORMAL_CI = {"Ci": {"dist": "lognormal", "median": 2e6, "sigma": 1.0}}


@pytest.mark.parametrize("priors", [None, LOGNORMAL_CI], ids=["loguniform", "lognormal"])
def test_the_change_of_variables_is_exact(lp, priors):
    lp = lp if priors is None else _logpost(priors=priors)
    c = scale_line(lp, None, _x(lp))
    assert c.cells == (1 if priors is None else 64)
    rng = np.random.default_rng(2)
    X = _x(lp) + 0.05 * rng.standard_normal((6, lp.ndim))
    Y = c.to_y(X)
    np.testing.assert_allclose(c.to_x(Y), X, rtol=0, atol=1e-10)
    # the density in the new coordinates is the log-posterior plus log|det dx/dy|
    y0, h = Y[0], 1e-6
    J = np.column_stack(
        [(c.to_x(y0 + h * e)[0] - c.to_x(y0 - h * e)[0]) / (2 * h) for e in np.eye(lp.ndim)]
    )
    assert c(Y[:1])[0] - lp(X[:1])[0] == pytest.approx(np.log(abs(np.linalg.det(J))), abs=1e-5)
    if priors is not None:
        return
    # log-uniform priors: the scale coordinate is logistic, whatever the other coordinates
    Y2 = c.spread(Y, rng)
    logistic = lambda v: -np.abs(v) - 2 * np.log1p(np.exp(-np.abs(v)))  # noqa: E731
    np.testing.assert_allclose(
        c(Y2) - logistic(Y2[:, c.index]), c(Y) - logistic(Y[:, c.index]), atol=1e-9
    )


def test_the_node_time_constants_carry_the_line_too(lp):
    inner = node_time_constants(lp)
    c = scale_line(lp, inner, _x(lp))
    assert isinstance(c, ScaleLine) and c.name == "node_tau+scale"
    X = _x(lp)[None] + np.zeros((1, lp.ndim))
    np.testing.assert_allclose(c.to_x(c.to_y(X)), X, atol=1e-10)


def test_the_chain_spreads_along_the_scale_from_the_first_steps(lp):
    x = _x(lp)
    s = scale_direction(lp)
    lo, hi = lp.params.bounds
    on = s == 1
    span = np.min(hi[on] - x[on]) - np.max(lo[on] - x[on])  # the line inside the priors
    c = scale_line(lp, None, x)
    ch = run_sampler(
        lp,
        x,
        seed=3,
        max_steps=100,
        coordinates=c,
        bounds=lp.params.bounds,
        max_rhat=None,
        min_ess=None,
        check_every=100,
    )
    assert ch.coordinates == "log+scale"
    # the walkers start spread over the prior's range along the line (drawn exactly),
    # not in a ball around the MAP, and stay spread
    for row in (ch.chain[0], ch.chain[-1]):
        t = row @ s / s.sum()
        assert np.ptp(t) > 0.5 * span
