"""Node time-constant sampling coordinates (issue 28): a bijection with unit Jacobian,
the same posterior, and chains stored in the sampler's usual coordinates."""

from __future__ import annotations

import numpy as np
import pytest

import heritage_bayes as hb
from _chain_helpers import sunny_room_inputs
from heritage_bayes.config import prior_specs
from heritage_bayes.inference.coordinates import NodeTimeConstants, node_time_constants
from heritage_bayes.inference.likelihoods import get_noise_model
from heritage_bayes.inference.parameters import parameters_for
from heritage_bayes.inference.posterior import LogPosterior
from heritage_bayes.inference.sampler import run_sampler


def _logpost(name="thermal_2c", N=24 * 20, priors=None, seed=0):
    rng = np.random.default_rng(seed)
    m = hb.model(name, surfaces=("S",))
    U = sunny_room_inputs(m, N, rng)
    truth = dict(Cw=5e7, Ci=2e6, Gw=150.0, Gi=300.0, Gfast=80.0, Gf=30.0, fI_S=3.0, Ge=230.0)
    y = hb.simulate(m, {k: truth[k] for k in m.parameter_names}, U)[:, 0]
    noise = get_noise_model("ar1")
    ps = parameters_for(m, noise, prior_specs(priors or {}), room_volume=400)
    y = y + rng.normal(0, 0.1, N)
    return LogPosterior(m, ps, noise, U, y[:, None], warmup=24, init_window=24), truth


def _jacobian(c, y0: np.ndarray, h: float = 1e-6) -> np.ndarray:
    """(d, d) central-difference Jacobian dx/dy of the coordinates c at y0 (d,)."""
    d = y0.size
    J = np.empty((d, d))
    for j in range(d):
        e = np.zeros(d)
        e[j] = h
        J[:, j] = (c.to_x(y0 + e)[0] - c.to_x(y0 - e)[0]) / (2 * h)
    return J


def test_node_time_constants_are_capacity_over_attached_conductances():
    lp, truth = _logpost()
    c = NodeTimeConstants(lp)
    names = lp.params.free_names
    assert {names[k] for k, _ in c.nodes} == {"Cw", "Ci"}
    theta = np.array([[truth.get(n, 0.1) if n != "phi_Ti" else 0.5 for n in lp.params.names]])
    X = lp.params.to_unconstrained(theta)
    Y = c.to_y(X)
    # Cw: Gw (to Te) + Gi (to the air); Ci: Gi + Gfast (to Te) + Gf (to the ground)
    assert Y[0, names.index("Cw")] == pytest.approx(np.log(5e7 / (150.0 + 300.0)))
    assert Y[0, names.index("Ci")] == pytest.approx(np.log(2e6 / (300.0 + 80.0 + 30.0)))
    # the other coordinates are the sampler's own
    keep = [k for k in range(len(names)) if names[k] not in ("Cw", "Ci")]
    np.testing.assert_array_equal(Y[:, keep], X[:, keep])


def test_the_change_of_variables_is_a_bijection_with_unit_jacobian():
    lp, _ = _logpost()
    c = node_time_constants(lp)
    rng = np.random.default_rng(1)
    X = lp.params.to_unconstrained(lp.params.sample_prior(rng, 20))
    np.testing.assert_allclose(c.to_x(c.to_y(X)), X, rtol=0, atol=1e-12)
    # unit Jacobian: the log-density is the same at corresponding points
    np.testing.assert_allclose(c(c.to_y(X)), lp(X), rtol=1e-12)
    # and the map really has determinant 1 (central differences)
    J = _jacobian(c, c.to_y(X[:1])[0])
    assert np.linalg.det(J) == pytest.approx(1.0, abs=1e-6)
    # outside the prior's support (or non-finite) it is -inf, never an exception
    Y = c.to_y(X[:3])
    Y[0, 0] = np.nan
    Y[1, c.nodes[0][0]] = 1e3
    out = c(Y)
    assert out[0] == -np.inf and out[1] == -np.inf and np.isfinite(out[2])


def test_fixed_capacities_are_left_alone_and_fixed_conductances_count():
    lp, _ = _logpost(priors={"Ci": {"fixed": 2e6}, "Gf": {"fixed": 30.0}})
    c = node_time_constants(lp)
    names = lp.params.free_names
    assert [names[k] for k, _ in c.nodes] == ["Cw"]
    lp1, _ = _logpost("thermal_1c", priors={"Ci": {"fixed": 2e6}})
    assert node_time_constants(lp1) is None
    lp2, _ = _logpost("thermal_1c", priors={"Gf": {"fixed": 30.0}})
    c2 = node_time_constants(lp2)
    ((k, gs),) = c2.nodes
    assert (None, 30.0, True) in gs


def test_sampler_in_time_constant_coordinates_stores_the_usual_coordinates(tmp_path):
    lp, _ = _logpost(N=24 * 10)
    c = node_time_constants(lp)
    x0 = lp.params.to_unconstrained(
        np.array([[5e7, 2e6, 150.0, 300.0, 80.0, 30.0, 3.0, 0.1, 0.5]])
    )[0]
    kw = dict(seed=3, max_steps=200, check_every=100, tau_factor=1000, bounds=lp.params.bounds)
    a = run_sampler(lp, x0, coordinates=c, checkpoint=tmp_path / "a.h5", tag="t", **kw)
    b = run_sampler(lp, x0, coordinates=c, **kw)
    np.testing.assert_array_equal(a.chain, b.chain)  # same seed, same chain
    # the stored chain is in the log-posterior's coordinates: its log-prob matches
    np.testing.assert_allclose(lp(a.chain[-1]), a.log_prob[-1], rtol=1e-10)
    # a resumed chain (from the checkpoint, in x) continues in the same coordinates
    kw2 = {**kw, "max_steps": 300}
    r = run_sampler(
        lp, x0, coordinates=c, checkpoint=tmp_path / "a.h5", tag="t", resume=True, **kw2
    )
    full = run_sampler(lp, x0, coordinates=c, **kw2)
    assert r.resumed_from == 200
    np.testing.assert_array_equal(r.chain[:200], full.chain[:200])
    # the last state goes through x and back: equal up to round-off (1e-16 relative),
    # which the ensemble moves carry on (measured: 6e-9 relative after 100 steps)
    np.testing.assert_allclose(r.chain, full.chain, rtol=1e-6)


def test_a_converged_chain_is_compacted_and_a_resume_rebuilds_from_its_draws(tmp_path):
    """Lean outputs: the checkpoint of a converged chain keeps only the retained
    draws; --resume returns them (same draws, nothing sampled); a stricter rule that
    would need the dropped steps is refused with a message, not silently ignored."""
    import h5py

    from heritage_bayes.errors import InputError
    from heritage_bayes.inference.sampler import compact_checkpoint

    lp, truth = _logpost("thermal_1c", N=24 * 10)
    x0 = lp.params.to_unconstrained(np.array([[2e6, 230.0, 30.0, 3.0, 0.1, 0.5]]))[0]
    ck = tmp_path / "chain.h5"
    kw = dict(seed=2, check_every=100, tau_factor=5, min_ess=None, max_rhat=None)
    a = run_sampler(lp, x0, checkpoint=ck, tag="t", max_steps=5000, **kw)
    assert a.converged
    full_size = ck.stat().st_size
    compact_checkpoint(ck, "t", a, max_draws=400)
    assert ck.stat().st_size < full_size / 2
    with h5py.File(ck) as f:
        assert f["draws"].shape[1:] == (32, lp.ndim)
        # a trace of the whole chain for the report's plots, burn-in included
        k = int(f.attrs["trace_stride"])
        assert f["chain"].shape[0] == len(range(0, a.steps, k)) <= 400
        np.testing.assert_allclose(f["chain"][-1], a.chain[::k][-1], rtol=1e-6)
    b = run_sampler(lp, x0, checkpoint=ck, tag="t", max_steps=5000, resume=True, **kw)
    assert b.thinned and b.converged and b.steps == a.steps and b.resumed_from == a.steps
    for got, want in zip(b.draws(400), a.draws(400), strict=True):
        np.testing.assert_array_equal(got, want)
    assert (b.burn, b.thin) == (a.burn, a.thin)
    with pytest.raises(InputError, match="run without --resume"):
        run_sampler(lp, x0, checkpoint=ck, tag="t", resume=True, **{**kw, "tau_factor": 1e6})
    with pytest.raises(InputError, match="different configuration"):
        run_sampler(lp, x0, checkpoint=ck, tag="other", resume=True, **kw)
    # an unconverged chain is left whole: it is what --resume continues
    c = run_sampler(lp, x0, checkpoint=tmp_path / "c.h5", tag="t", max_steps=100, **kw)
    before = (tmp_path / "c.h5").read_bytes()
    compact_checkpoint(tmp_path / "c.h5", "t", c, max_draws=400)
    assert not c.converged and (tmp_path / "c.h5").read_bytes() == before


def test_default_coordinates_re_coordinate_three_node_networks_only():
    from heritage_bayes.inference.coordinates import default_coordinates

    lp2, _ = _logpost("thermal_2c")
    assert default_coordinates(lp2) is None
    m = hb.model("thermal_4a", surfaces=("S",))
    noise = get_noise_model("ar1")
    U = np.ones((48, len(m.input_names)))
    lp4 = LogPosterior(m, parameters_for(m, noise), noise, U, np.ones((48, 1)), warmup=0)
    c = default_coordinates(lp4)
    names = lp4.params.free_names
    assert sorted(names[k] for k, _ in c.nodes) == ["Ci", "Cint", "Cw"]
    # fsol as the log of the air's share (measured: τmax of the demo 4a lower); the
    # apertures stay in log coordinates (measured: no gain)
    assert [names[k] for k, _, _ in c.shares] == ["fsol"] and c.splits == []


def test_sampler_coordinates_key_chooses_them_and_enters_the_chain_tag():
    """``sampler.coordinates``: auto is the size rule, log none, node_tau the node time
    constants of a two-node network too; a non-default choice changes the chain tag
    (``--resume`` refuses a chain sampled otherwise), the default leaves earlier tags."""
    from heritage_bayes.config import parse_config
    from heritage_bayes.config.calibration import chain_tag
    from heritage_bayes.errors import ConfigError
    from heritage_bayes.inference.coordinates import sampling_coordinates

    lp2, _ = _logpost("thermal_2c")
    assert sampling_coordinates(lp2, "auto") is None
    assert sampling_coordinates(lp2, "log") is None
    c = sampling_coordinates(lp2, "node_tau")
    assert isinstance(c, NodeTimeConstants) and len(c.nodes) == 2
    with pytest.raises(ValueError, match=r"sampler\.coordinates"):
        sampling_coordinates(lp2, "laplace")
    base = {"name": "t", "data": {"demo": {"seed": 7}}, "thermal": {"model": "thermal_2c"}}
    tags = {
        k: chain_tag(parse_config({**base, "sampler": {"coordinates": k}}))
        for k in ("auto", "log", "node_tau")
    }
    assert tags["auto"] == chain_tag(parse_config(base))
    assert len(set(tags.values())) == 3
    with pytest.raises(ConfigError, match="coordinates"):
        parse_config({**base, "sampler": {"coordinates": "laplace"}})


def _logpost_4a(surfaces=("S", "N"), priors=None):
    m = hb.model("thermal_4a", surfaces=surfaces)
    noise = get_noise_model("ar1")
    U = np.ones((48, len(m.input_names)))
    ps = parameters_for(m, noise, prior_specs(priors or {}))
    return LogPosterior(m, ps, noise, U, np.ones((48, 1)), warmup=0)


def test_split_solar_apertures_are_sampled_as_the_aperture_to_the_air():
    """thermal_4a: log fI_s is replaced by log(fI_s (1 - fsol)) (the aperture to the air
    node [m²]), fsol's logit coordinate kept; then log of the aperture to the mass is
    that coordinate plus logit(fsol): both linear. A bijection with unit Jacobian.
    Opt-in (``solar=True``): on the demo it left fsol's τ unchanged."""
    lp = _logpost_4a()
    c = node_time_constants(lp, solar=True)
    names = lp.params.free_names
    ((f, lo, width, gains),) = c.splits
    assert names[f] == "fsol" and (lo, width) == (0.0, 1.0)
    assert sorted(names[g] for g in gains) == ["fI_N", "fI_S"]
    rng = np.random.default_rng(2)
    theta = lp.params.sample_prior(rng, 30)
    X = lp.params.to_unconstrained(theta)
    Y = c.to_y(X)
    fsol = theta[:, lp.params.names.index("fsol")]
    for s in ("S", "N"):
        fI = theta[:, lp.params.names.index(f"fI_{s}")]
        k = names.index(f"fI_{s}")
        np.testing.assert_allclose(Y[:, k], np.log(fI * (1 - fsol)), rtol=1e-12)
        np.testing.assert_allclose(Y[:, k] + Y[:, f], np.log(fI * fsol), rtol=1e-10)
    np.testing.assert_allclose(c.to_x(Y), X, rtol=0, atol=1e-12)
    np.testing.assert_allclose(c(Y), lp(X), rtol=1e-12)
    J = _jacobian(c, Y[0])
    d = J.shape[0]
    assert np.linalg.det(J) == pytest.approx(1.0, abs=1e-6)
    # the fsol column of the Jacobian is dlog fI_s/dv = σ(v) off the diagonal: not zero
    assert abs(J[gains[0], f]) > 1e-3
    # the default (solar=False, what hbayes samples in): the apertures stay in the log
    # coordinates; measured no gain in τ on the demo (benchmarks/README.md)
    c0 = node_time_constants(lp)
    assert c0.splits == []
    keep = [k for k in range(d) if k not in [n for n, _ in c0.nodes]]
    np.testing.assert_array_equal(c0.to_y(X)[:, keep], X[:, keep])


def test_split_solar_prior_narrower_than_the_unit_interval_and_fixed_fsol():
    """A prior on fsol over [lo, lo + w] ⊂ [0, 1] uses log(1 - f) directly; a fixed fsol
    or a fixed aperture leaves nothing (or only the free apertures) to re-coordinate."""
    lp = _logpost_4a(priors={"fsol": {"dist": "uniform", "lower": 0.2, "upper": 0.9}})
    c = node_time_constants(lp, solar=True)
    ((f, lo, width, _),) = c.splits
    assert (lo, width) == pytest.approx((0.2, 0.7))
    rng = np.random.default_rng(3)
    X = lp.params.to_unconstrained(lp.params.sample_prior(rng, 10))
    np.testing.assert_allclose(c.to_x(c.to_y(X)), X, rtol=0, atol=1e-12)
    theta = lp.params.values(X)
    k = lp.params.free_names.index("fI_S")
    fs = theta[:, lp.params.names.index("fsol")]
    fI = theta[:, lp.params.names.index("fI_S")]
    np.testing.assert_allclose(c.to_y(X)[:, k], np.log(fI * (1 - fs)), rtol=1e-12)
    assert (
        node_time_constants(_logpost_4a(priors={"fsol": {"fixed": 0.3}}), solar=True).splits == []
    )
    c1 = node_time_constants(_logpost_4a(priors={"fI_N": {"fixed": 1.0}}), solar=True)
    names = c1.logpost.params.free_names
    assert [names[g] for g in c1.splits[0][3]] == ["fI_S"]


def test_fsol_sampled_as_the_log_of_the_air_share_with_its_jacobian():
    """air_share=True: fsol's coordinate is log(1 - fsol) [-]; the log-density in it is
    the log-posterior plus log|dv/dy| (v = logit fsol), checked against a numerical
    determinant, for the default prior on [0, 1] and a narrower one."""
    for priors in ({}, {"fsol": {"dist": "uniform", "lower": 0.2, "upper": 0.9}}):
        lp = _logpost_4a(priors=priors)
        c = node_time_constants(lp, air_share=True)
        names = lp.params.free_names
        ((k, lo, width),) = c.shares
        assert names[k] == "fsol"
        rng = np.random.default_rng(4)
        theta = lp.params.sample_prior(rng, 10)
        X = lp.params.to_unconstrained(theta)
        Y = c.to_y(X)
        fsol = theta[:, lp.params.names.index("fsol")]
        np.testing.assert_allclose(Y[:, k], np.log1p(-fsol), rtol=1e-12)
        np.testing.assert_allclose(c.to_x(Y), X, rtol=0, atol=1e-10)
        for i in range(3):
            logdet = np.log(abs(np.linalg.det(_jacobian(c, Y[i]))))
            assert c(Y[i : i + 1])[0] - lp(X[i : i + 1])[0] == pytest.approx(logdet, abs=1e-6)
        # outside the support (fsol < lo or > lo + width): -inf, never an exception
        Y[0, k] = 0.5  # 1 - fsol > 1
        # fsol above the prior's upper bound (fsol = 1 for the prior on [0, 1])
        Y[1, k] = np.log1p(-(lo + width)) - 0.1 if lo + width < 1 else -np.inf
        out = c(Y[:3])
        assert out[0] == -np.inf and out[1] == -np.inf and np.isfinite(out[2])
    assert node_time_constants(_logpost_4a(), air_share=False).shares == []


def test_series_coordinates_of_a_node_between_two_conductances_have_unit_jacobian():
    """``series=True``: the envelope node's Gw and Gi sampled as the log of their series
    conductance Gw Gi / (Gw + Gi) [W/K] and the log of their ratio; a bijection with
    |Jacobian| 1, so the log-density is unchanged."""
    lp, truth = _logpost()
    c = node_time_constants(lp, series=True)
    names = lp.params.free_names
    # (the conductance to the other node first, then the one to the boundary)
    assert [(names[a], names[b]) for a, b in c.pairs] == [("Gi", "Gw")]
    theta = np.array([[truth.get(n, 0.1) if n != "phi_Ti" else 0.5 for n in lp.params.names]])
    Y = c.to_y(lp.params.to_unconstrained(theta))
    assert Y[0, names.index("Gi")] == pytest.approx(np.log(150.0 * 300.0 / 450.0))
    assert Y[0, names.index("Gw")] == pytest.approx(np.log(300.0 / 150.0))
    assert Y[0, names.index("Cw")] == pytest.approx(np.log(5e7 / 450.0))
    rng = np.random.default_rng(2)
    X = lp.params.to_unconstrained(lp.params.sample_prior(rng, 20))
    np.testing.assert_allclose(c.to_x(c.to_y(X)), X, rtol=0, atol=1e-11)
    # the round trip through softplus costs ~1e-15 in x, which log-densities of 1e7
    # (prior draws far from the data) turn into ~1e-12 relative
    np.testing.assert_allclose(c(c.to_y(X)), lp(X), rtol=1e-9)
    J = _jacobian(c, c.to_y(X[:1])[0])
    assert abs(np.linalg.det(J)) == pytest.approx(1.0, abs=1e-6)
    assert node_time_constants(lp).pairs == []  # opt-in
