"""Sampler start inside the support, run length from the chain and a time budget,
MAP-on-bound findings and the Laplace (practical identifiability) check."""

from __future__ import annotations

import itertools

import numpy as np
import pytest

from heritage_bayes.errors import InputError
from heritage_bayes.inference.optimize import find_map, laplace
from heritage_bayes.inference.sampler import _next_check, run_sampler, start_ensemble
from test_inference import _problem


class _BoxGauss:
    """N(mu, diag(sd²)) restricted to a box (hard walls), vectorised, with ``params``."""

    def __init__(self, mu, sd, lo, hi):
        self.mu, self.sd = np.asarray(mu, float), np.asarray(sd, float)
        self.lo, self.hi = np.asarray(lo, float), np.asarray(hi, float)
        self.calls = 0

    def __call__(self, X):
        self.calls += 1
        X = np.atleast_2d(X)
        inside = np.all((X >= self.lo) & (X <= self.hi), axis=1)
        lp = -0.5 * np.sum(((X - self.mu) / self.sd) ** 2, axis=1)
        return np.where(inside, lp, -np.inf)


def test_walkers_start_inside_the_support_when_the_map_is_on_or_beyond_a_bound():
    # the density peaks beyond the upper wall of x0 and at the lower wall of x1:
    # the MAP (on the walls) has half its neighbourhood outside the support
    f = _BoxGauss(mu=[2.0, 0.0], sd=[0.5, 0.5], lo=[-1.0, 0.0], hi=[1.0, 3.0])
    for x_map in ([1.0, 0.0], [1.5, -0.2]):  # on the bounds; outside them
        p0, lp0 = start_ensemble(
            f, np.array(x_map), 40, np.random.default_rng(3), bounds=(f.lo, f.hi)
        )
        assert p0.shape == (40, 2) and np.all(np.isfinite(lp0))
        assert np.all(p0 > f.lo) and np.all(p0 < f.hi)
        # centred near the (clipped) MAP: within the margin plus a few ball radii
        np.testing.assert_allclose(np.median(p0, axis=0), np.clip(x_map, f.lo, f.hi), atol=0.05)
    # the old start (a 1e-3 ball about a MAP on the wall) lost half the walkers:
    # the new one is valid at the first draw, in one call of the log-posterior
    f.calls = 0
    start_ensemble(f, np.array([1.0, 0.0]), 40, np.random.default_rng(4), bounds=(f.lo, f.hi))
    assert f.calls == 1
    # same seed, same start
    a = start_ensemble(f, np.array([1.0, 0.0]), 8, np.random.default_rng(5), bounds=(f.lo, f.hi))
    b = start_ensemble(f, np.array([1.0, 0.0]), 8, np.random.default_rng(5), bounds=(f.lo, f.hi))
    np.testing.assert_array_equal(a[0], b[0])


def test_start_fails_with_a_data_message_only_when_nothing_is_finite():
    def never(X):
        return np.full(np.atleast_2d(X).shape[0], -np.inf)

    with pytest.raises(InputError, match="check the data"):
        start_ensemble(never, np.zeros(2), 8, np.random.default_rng(0))


def test_sampler_runs_from_a_map_on_a_bound_and_samples_the_truncated_posterior():
    # 1-d half-normal on [0, inf) in 2 independent copies (walls at 0): the MAP is 0
    f = _BoxGauss(mu=[0.0, 0.0], sd=[1.0, 1.0], lo=[0.0, 0.0], hi=[np.inf, np.inf])
    res = run_sampler(
        f,
        np.zeros(2),
        seed=2,
        bounds=(f.lo, f.hi),
        nwalkers=16,
        max_steps=3000,
        check_every=500,
        tau_factor=30,
        moves="stretch",
    )
    X, _ = res.draws()
    x = X.reshape(-1, 2)
    # half-normal mean sqrt(2/π) = 0.798, sd 0.603; ESS-based tolerance (≥ 400 ESS: 4 SE)
    n_eff = max(400.0, x.shape[0] / 10)
    assert np.all(x >= 0)
    np.testing.assert_allclose(x.mean(axis=0), np.sqrt(2 / np.pi), atol=4 * 0.603 / np.sqrt(n_eff))
    assert res.stopped_by in ("converged", "max_steps")


def test_time_budget_stops_the_chain_between_chunks():
    f = _BoxGauss(mu=[0.0], sd=[1.0], lo=[-np.inf], hi=[np.inf])
    res = run_sampler(
        f, np.zeros(1), seed=1, nwalkers=8, max_steps=10_000, check_every=100, max_seconds=1e-9
    )
    # one chunk always runs; then the (spent) budget stops it, unconverged
    assert res.steps == 100 and res.stopped_by == "max_seconds" and not res.converged
    assert res.cpu_seconds > 0


def test_convergence_checks_space_out_with_the_chain_and_do_not_depend_on_resume():
    seq = [0]
    while seq[-1] < 20_000:
        seq.append(_next_check(seq[-1], 500))
    steps = np.diff(seq)
    assert steps[0] == 500 and np.all(steps % 500 == 0)
    assert np.all(steps[1:] >= steps[:-1])  # non-decreasing spacing
    assert np.all(steps[10:] <= 0.1 * np.array(seq[10:-1]) + 500)  # about 10 % of the chain
    # from any step inside a chunk, the next check is the same boundary
    for b0, b1 in itertools.pairwise(seq):
        assert _next_check(b0, 500) == b1 and _next_check(b1 - 1, 500) == b1


def test_at_bound_names_map_parameters_pressed_against_their_prior():
    lp, _ = _problem()
    ps = lp.params
    lo, hi = ps.bounds
    x = 0.5 * (np.where(np.isfinite(lo), lo, -1) + np.where(np.isfinite(hi), hi, 1))
    assert ps.at_bound(x) == []
    i = ps.free_names.index("Ge")
    x[i] = lo[i]
    j = ps.free_names.index("phi_Ti")  # logit coordinate: far out counts as the end
    x[j] = 30.0
    assert ps.at_bound(x) == [("Ge", "lower"), ("phi_Ti", "upper")]


def test_laplace_hessian_is_the_inverse_covariance_of_a_gaussian():
    rng = np.random.default_rng(0)
    A = rng.normal(size=(3, 3))
    cov = A @ A.T + 0.5 * np.eye(3)
    P = np.linalg.inv(cov)
    mu = np.array([0.3, -0.2, 0.1])

    class Gauss:
        params = type(
            "P",
            (),
            {"bounds": (np.full(3, -50.0), np.full(3, 50.0)), "free_names": ("a", "b", "c")},
        )()

        def __call__(self, X):
            D = np.atleast_2d(X) - mu
            return -0.5 * np.einsum("ki,ij,kj->k", D, P, D)

    res = laplace(Gauss(), mu)
    # central second differences are exact on a quadratic (rounding only)
    np.testing.assert_allclose(res.hessian, P, rtol=1e-5, atol=1e-6 * np.abs(P).max())
    np.testing.assert_allclose(res.sd, np.sqrt(np.diag(cov)), rtol=1e-5)
    assert res.unidentified == []  # sd ≤ 2 of a prior range of 100
    # conditional sd given "a": the inverse of the Hessian without a's row and column
    r = laplace(Gauss(), mu, given=("a",))
    np.testing.assert_allclose(r.sd[1:], np.sqrt(np.diag(np.linalg.inv(P[1:, 1:]))), rtol=1e-5)
    assert r.sd[0] == 0


def test_laplace_sees_the_scale_ridge_and_a_coordinate_the_data_do_not_pin():
    lp, _ = _problem()
    x_map = find_map(lp, seed=1, maxiter=40, starts=1).x
    res = laplace(lp, x_map)
    w = np.linalg.eigvalsh(res.hessian)
    # the 1c room without a known heat input: C and G scale together (one flat direction)
    assert abs(w[0]) < 1e-5 * w[-1] and w[1] > 1e-4 * w[-1]
    assert "Ci" in res.unidentified
    # given the scale (Ci pinned, as calibrate does through the scale reference): all pinned
    assert laplace(lp, x_map, given=("Ci",)).unidentified == []

    class Padded:  # plus a coordinate the likelihood ignores: its sd is its prior's
        params = type(
            "P",
            (),
            {
                "bounds": (np.r_[lp.params.bounds[0], 0.0], np.r_[lp.params.bounds[1], 1.0]),
                "free_names": (*lp.params.free_names, "extra"),
            },
        )()

        def __call__(self, X):
            X = np.atleast_2d(X)
            inside = (X[:, -1] >= 0) & (X[:, -1] <= 1)
            return np.where(inside, lp(X[:, :-1]), -np.inf)

    r2 = laplace(Padded(), np.r_[x_map, 0.5], given=("Ci",))
    assert r2.unidentified == ["extra"]


class _CorrGauss:
    """A strongly correlated 2-d Gaussian (a straight ridge), vectorised, with params."""

    cov = np.array([[1.0, 0.98], [0.98, 1.0]]) * 0.04
    mu = np.array([1.0, -0.5])
    prec = np.linalg.inv(cov)
    params = type(
        "P", (), {"bounds": (np.full(2, -20.0), np.full(2, 20.0)), "free_names": ("a", "b")}
    )()

    def __call__(self, X):
        D = np.atleast_2d(X) - self.mu
        return -0.5 * np.einsum("ki,ij,kj->k", D, self.prec, D)


def test_laplace_coordinates_keep_the_distribution_and_their_jacobian_integrates():
    from scipy import stats

    from heritage_bayes.inference.optimize import affine_coordinates

    f = _CorrGauss()
    aff = affine_coordinates(f, laplace(f, f.mu))
    # the Jacobian: ∫ p(x(z)) |det L| dz = ∫ p(x) dx (grid quadrature, both 2π sqrt|Σ|)
    g = np.linspace(-8, 8, 401)
    Z = np.stack(np.meshgrid(g, g, indexing="ij"), -1).reshape(-1, 2)
    mass_z = np.exp(aff(Z)).sum() * (g[1] - g[0]) ** 2
    np.testing.assert_allclose(mass_z, 2 * np.pi * np.sqrt(np.linalg.det(f.cov)), rtol=1e-6)
    np.testing.assert_allclose(aff.to_z(aff.to_x(Z[:5])), Z[:5], atol=1e-12)
    # the same posterior sampled in both coordinate systems
    kw = dict(seed=3, nwalkers=16, max_steps=2000, check_every=500, tau_factor=20)
    a = run_sampler(f, f.mu, **kw)
    b = run_sampler(aff, aff.to_z(f.mu)[0], **kw)

    def independent(res):
        # the second half of the chain (past the walkers' expansion from their start
        # ball, which a 2τ burn-in does not cover when τ is a few steps), one step per
        # 2τ: nearly independent draws, as the KS test assumes
        c = res.chain
        return c[c.shape[0] // 2 :: int(np.ceil(2 * np.max(res.tau)))].reshape(-1, 2)

    xa, xb = independent(a), aff.to_x(independent(b))
    # KS on the identifiable sum and along the ridge
    for v in (np.array([1.0, 1.0]), np.array([1.0, -1.0])):
        p = stats.ks_2samp(xa @ v, xb @ v).pvalue
        assert p > 1e-3
    np.testing.assert_allclose(xb.mean(0), f.mu, atol=4 * 0.2 / np.sqrt(400))


def test_report_notes_name_a_map_on_a_bound_over_parameterisation_and_a_spent_budget():
    from heritage_bayes.report.verdict import run_notes

    s = {
        "irradiance_source": "measured",
        "parameters": {},
        "models": {
            "thermal": {
                "map_at_bound": [["Cint", "lower"]],
                "practical_identifiability": {"unidentified": ["Gint", "phi_Ti"]},
                "chain": {"stopped_by": "max_seconds"},
            },
            "hygric": {"map_at_bound": [], "practical_identifiability": None, "chain": {}},
        },
    }
    notes = run_notes(s, [])
    assert [n["title"] for n in notes] == [
        "The thermal MAP lies on a prior bound",
        "The thermal model is over-parameterised for these data",
        "The thermal chain ran out of time",
    ]
    assert "Cint (lower)" in notes[0]["text"]
    assert "Gint" in notes[1]["text"] and "phi_Ti" not in notes[1]["text"]
    # a frozen node (heritage_bayes.rc.derived.frozen_time_constant) is named too
    s["models"]["thermal"]["frozen_node"] = {"tau_h": 5.4e4, "records": 25.3, "start_free": True}
    notes = run_notes(s, [])
    frozen = [n for n in notes if n["title"] == "A thermal node barely moves over the record"]
    assert len(frozen) == 1
    assert "5.4e+04 h, 25 times" in frozen[0]["text"] and "free offset" in frozen[0]["text"]
    assert "posterior has two modes" not in frozen[0]["text"]
    # held to the steady state (the damped start), and a second posterior branch
    s["models"]["thermal"]["frozen_node"]["start_free"] = False
    s["models"]["thermal"]["frozen_share"] = 0.21
    text = next(n for n in run_notes(s, []) if n["title"] == frozen[0]["title"])["text"]
    assert "held to the steady state" in text and "21% of the posterior draws" in text
    # no frozen MAP, but a branch of the posterior: a note of its own; 4 % is noise
    s["models"]["thermal"]["frozen_node"] = None
    titles = [n["title"] for n in run_notes(s, [])]
    assert "Some thermal draws freeze a node" in titles and frozen[0]["title"] not in titles
    s["models"]["thermal"]["frozen_share"] = 0.04
    assert "Some thermal draws freeze a node" not in [n["title"] for n in run_notes(s, [])]


def test_tau_without_the_start_transient_is_not_inflated_and_samples_the_same():
    """Walkers started in a small ball 15 sd away from the mode first drift and spread
    (a non-stationary start): τ on the whole chain is inflated by it, τ on the second
    half is not; ``tau_discard=0.5`` estimates τ there and keeps draws only from there,
    which sample N(0, 1). It need not stop sooner: the estimate of τ on half the chain
    is noisier, so its 5 % stability test passes later (with numpy 2.4 / arviz 0.23:
    τ 4.4 → 9.0 → 7.9 between checks, stable at 2 000 steps, against 1 250 for the
    whole-chain rule; an earlier environment's stream stopped it sooner)."""
    from heritage_bayes.inference.sampler import _tau

    f = _BoxGauss(mu=[0.0, 0.0], sd=[1.0, 1.0], lo=[-np.inf] * 2, hi=[np.inf] * 2)
    kw = dict(seed=5, nwalkers=16, max_steps=20_000, check_every=250, init_ball=1e-3)
    full = run_sampler(f, np.array([15.0, -15.0]), **kw)
    half = run_sampler(f, np.array([15.0, -15.0]), tau_discard=0.5, **kw)
    assert full.converged and half.converged
    # the transient inflates τ of the whole chain, not of its second half
    assert np.max(_tau(full.chain, 0.5)) < 0.8 * np.max(_tau(full.chain))
    np.testing.assert_allclose(half.tau, _tau(half.chain, 0.5))
    assert half.steps <= 2 * full.steps and half.burn >= half.steps // 2
    X, _ = half.draws()
    x = X.reshape(-1, 2)
    n_eff = min(x.shape[0], half.steps * 16 / np.max(half.tau))  # ≥ 50 × 16 by the rule
    np.testing.assert_allclose(x.mean(axis=0), 0.0, atol=4 / np.sqrt(n_eff))
    np.testing.assert_allclose(x.std(axis=0), 1.0, atol=4 / np.sqrt(2 * n_eff))
    with pytest.raises(InputError, match="tau_discard"):
        run_sampler(f, np.zeros(2), tau_discard=1.0, **kw)


def test_every_moves_choice_of_the_config_builds_emcee_moves_and_samples():
    """``sampler.moves``: the schema's choices are the sampler's, each an emcee move
    mixture whose weights sum to 1; an unknown name is refused; each samples a
    Gaussian (the mean within 4 standard errors of the ESS the rule guarantees)."""
    import emcee

    from heritage_bayes.config.sampler import SamplerSettings
    from heritage_bayes.inference.monitor import MOVES, make_moves

    field = SamplerSettings.model_fields["moves"]
    choices = next(m.names for m in field.metadata if hasattr(m, "names"))
    assert set(choices) == set(MOVES)
    f = _BoxGauss(mu=[1.0, -2.0, 0.5], sd=[1.0, 2.0, 0.5], lo=[-np.inf] * 3, hi=[np.inf] * 3)
    for name in choices:
        mv = make_moves(name)
        assert all(isinstance(m, emcee.moves.Move) for m, _ in mv)
        assert sum(w for _, w in mv) == pytest.approx(1.0)
        res = run_sampler(f, f.mu, seed=3, nwalkers=16, max_steps=20_000, moves=name)
        assert res.converged, name
        x = res.draws()[0].reshape(-1, 3)
        n_eff = res.steps * 16 / np.max(res.tau) / 2  # at least 25 × 16 (half: burn-in)
        z = (x.mean(axis=0) - f.mu) / (f.sd / np.sqrt(n_eff))
        assert np.all(np.abs(z) < 4), (name, z)
        np.testing.assert_allclose(x.std(axis=0) / f.sd, 1.0, atol=4 / np.sqrt(2 * n_eff))
    with pytest.raises(ValueError, match="sampler"):
        make_moves("walk")


def test_a_converged_run_has_no_reasons_even_when_its_saved_draws_scatter():
    """summary.converged is the sampler's rule on all retained draws; the R-hat of the
    ~1 000 saved draws may scatter above 1.01 on a converged run (Ørholm's thermal_4a:
    1.018): no reason is listed then, while the same numbers on an unconverged run are
    named."""
    from heritage_bayes.calibration.convergence import unconverged_reasons

    summary = {
        "converged": True,
        "criteria": {"tau_factor": 50.0, "max_rhat": 1.01, "min_ess_bulk": 400},
        "models": {"thermal": {"chain": {"converged_tau": True, "steps": 12000}}},
        "parameters": {"thermal.phi_Ti": {"r_hat": 1.018, "ess_bulk": 1004.0}},
    }
    assert unconverged_reasons(summary) == []
    reasons = unconverged_reasons({**summary, "converged": False})
    assert reasons == ["max R-hat 1.018 (thermal model: model-error autocorrelation of Ti) > 1.01"]


def test_report_notes_name_separate_optima():
    """A MAP search whose restarts found separate optima (summary.json's
    models.<m>.map.modes): an amber note with their heights and the parameters in
    which they differ most (a factor of 3, or 0.1 for a fraction), farthest first."""
    from heritage_bayes.report.verdict import run_notes

    modes = [
        {
            "log_posterior": 937.98,
            "values": {"Cw": 1.19e8, "Cint": 1e4, "Gint": 400.0, "fsol": 0.41},
        },
        {
            "log_posterior": 938.08,
            "values": {"Cw": 9.2e8, "Cint": 7.2e7, "Gint": 420.0, "fsol": 0.175},
        },
    ]
    s = {
        "irradiance_source": "measured",
        "parameters": {},
        "models": {"thermal": {"map": {"restarts": 3, "modes": modes}}},
    }
    (note,) = run_notes(s, [])
    assert note["title"] == "The thermal posterior has separate optima"
    assert note["level"] == "amber"
    assert "(3 global searches" in note["text"]
    assert "started at log-posterior 938.0, the other is at 938.1 (" in note["text"]
    assert "(Cint 1e+04 vs 7.2e+07, fsol 0.41 vs 0.175, Cw 1.19e+08 vs 9.2e+08)" in note["text"]
    assert "Gint 400" not in note["text"]  # 5 % apart: not named
    s["models"]["thermal"]["map"]["modes"] = modes[:1]
    assert run_notes(s, []) == []
    s["models"]["thermal"]["map"] = {"log_posterior": 937.98}  # one search: no modes key
    assert run_notes(s, []) == []
