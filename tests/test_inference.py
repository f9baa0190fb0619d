"""Priors and transforms, noise models, the vectorised log-posterior, MAP and sampler."""

import math

import numpy as np
import pytest
from scipy import integrate, stats

import heritage_bayes as hb
from heritage_bayes.config import prior_specs
from heritage_bayes.errors import ConfigError, InputError
from heritage_bayes.inference.likelihoods import AR1Noise, IIDNoise, _ar1_sample, get_noise_model
from heritage_bayes.inference.optimize import find_map
from heritage_bayes.inference.parameters import (
    Parameter,
    ParameterSet,
    owned_priors,
    parameters_for,
)
from heritage_bayes.inference.posterior import LogPosterior
from heritage_bayes.inference.priors import Prior, configured_prior, default_prior
from heritage_bayes.inference.sampler import run_sampler
from heritage_bayes.inference.survey import air_capacity_prior
from heritage_bayes.names import PRIOR_DISTRIBUTIONS
from heritage_bayes.rc.discretize import modal_form

PRIORS = [
    Prior("uniform", -2.0, 5.0),
    Prior("loguniform", 1e-2, 1e5),
    Prior("normal", 0.0, 10.0, mu=3.0, sigma=2.0),
    Prior("lognormal", 1e3, 1e8, mu=2e5, sigma=1.5),
]


@pytest.mark.parametrize("kind", ["capacity", "fraction"])
@pytest.mark.parametrize("prior", PRIORS, ids=lambda p: p.dist)
def test_transform_density_integrates_to_the_prior_mass(prior, kind):
    """exp(logpdf(θ(x)) + log|dθ/dx|) over x equals ∫ exp(logpdf(θ)) dθ over the bounds."""
    ps = ParameterSet([Parameter("p", "-", kind, prior)])

    def dens_x(x):
        return math.exp(ps.transform(np.array([[x]]))[1][0])

    a, b = prior._ab()
    lo, hi = (-60, 60) if kind == "fraction" else (a, b)
    mass_x = integrate.quad(dens_x, lo, hi, limit=400)[0]
    mass_theta = integrate.quad(
        lambda t: math.exp(prior.logpdf(np.array(t))),
        prior.lower,
        prior.upper,
        limit=400,
        points=[prior.mu or prior.lower],
    )[0]
    assert mass_x == pytest.approx(mass_theta, rel=1e-6)
    # round trip and bounds
    theta = prior.sample(np.random.default_rng(0), 200)
    assert np.all((theta >= prior.lower) & (theta <= prior.upper))
    back = ps.values(ps.to_unconstrained(theta[:, None]))[:, 0]
    np.testing.assert_allclose(back, theta, rtol=1e-9)


def test_vectorised_transform_matches_per_prior_path():
    ps = ParameterSet(
        [Parameter(f"p{i}", "-", "x", p) for i, p in enumerate(PRIORS)]
        + [Parameter("fixed", "-", "x", PRIORS[0], fixed=1.5)]
    )
    X = np.random.default_rng(1).normal(0, 3, (50, 4))
    theta, lp = ps.transform(X)
    ref = np.zeros(50)
    for j, p in enumerate(PRIORS):
        th, lj = p.from_unconstrained(X[:, j])
        np.testing.assert_allclose(theta[:, j], th, rtol=1e-13)
        ref += p.logpdf(th) + lj
    np.testing.assert_allclose(lp, ref, rtol=1e-12)
    assert np.all(theta[:, 4] == 1.5)
    # outside the bounds of a direct (log) coordinate: zero prior density
    out = ps.transform(np.array([[0.0, math.log(1e6), 0.0, 12.0]]))[1]
    assert out[0] == -np.inf


def test_a_prior_family_of_a_new_shape_reaches_the_vectorised_log_prior(monkeypatch):
    """A family that is neither flat nor normal in its sampling coordinate (a Laplace
    in log θ) is one object: the sampler's vectorised log-prior and the MAP search's
    ask it for its density, and agree with the per-prior path."""
    from heritage_bayes.names import DistributionName

    class _LogLaplace(DistributionName):
        log_scale = True
        centre = "median"
        span = 8.0

        def logpdf(self, theta, mu, sigma):
            lt = np.log(theta)
            return -lt - np.abs(lt - math.log(mu)) / sigma

        def ylogpdf(self, y, m, s):
            return -np.abs(y - m) / s

    monkeypatch.setitem(PRIOR_DISTRIBUTIONS, "loglaplace", _LogLaplace("a toy"))
    priors = [*PRIORS, Prior("loglaplace", 1e-3, 1e3, mu=2.0, sigma=0.5)]
    ps = ParameterSet([Parameter(f"p{i}", "-", "x", p) for i, p in enumerate(priors)])
    X = np.random.default_rng(2).normal(0, 2, (20, len(priors)))
    theta, lp = ps.transform(X)
    ref = sum(
        p.logpdf(theta[:, j]) + p.from_unconstrained(X[:, j])[1] for j, p in enumerate(priors)
    )
    np.testing.assert_allclose(lp, ref, rtol=1e-12)
    y = X[:, -1]
    np.testing.assert_array_equal(ps.log_density_y(X)[:, -1], -np.abs(y - math.log(2.0)) / 0.5)


def test_every_prior_family_is_tested_and_labelled():
    """The tests above cover each family of the registry; each describes itself."""
    assert {p.dist for p in PRIORS} == set(PRIOR_DISTRIBUTIONS)
    assert [p.describe() for p in PRIORS] == [
        "uniform[-2, 5]",
        "loguniform[0.01, 1e+05]",
        "normal(3, 2) on [0, 10]",
        "lognormal(median 2e+05, σ_log 1.5) on [1e+03, 1e+08]",
    ]


def test_owned_priors_keeps_those_of_the_model_and_its_noise_model():
    """A ladder rung keeps the section's priors its model or noise model names: a
    process-noise prior of a node it has, not one of a node it lacks."""
    names = ("Ci", "Cw", "sigma_Ti", "phi_Ti", "q_Ti", "q_Tw")
    priors = prior_specs({n: {"upper": 10.0} for n in names})
    one, two = hb.model("thermal_1c"), hb.model("thermal_2c")
    kalman = get_noise_model("kalman")
    assert set(owned_priors(priors, one, kalman)) == {"Ci", "sigma_Ti", "q_Ti"}
    assert set(owned_priors(priors, two, kalman)) == {"Ci", "Cw", "sigma_Ti", "q_Ti", "q_Tw"}
    assert set(owned_priors(priors, one, get_noise_model("ar1"))) == {"Ci", "sigma_Ti", "phi_Ti"}
    assert set(owned_priors(priors, two, get_noise_model("iid"))) == {"Ci", "Cw", "sigma_Ti"}


def test_prior_specs_and_errors_name_the_key():
    default = default_prior("thermal", "conductance")
    spec = prior_specs({"x": {"dist": "lognormal", "median": 100.0, "sigma": 0.5}})["x"]
    p = configured_prior(spec, default, where="x")
    assert p.lower == pytest.approx(100 * math.exp(-2.5))
    with pytest.raises(ConfigError, match=r"priors\.Gw\.lower: must be < upper \(got 500 >= 200\)"):
        prior_specs({"Gw": {"dist": "loguniform", "lower": 500, "upper": 200}})
    with pytest.raises(ConfigError, match=r"priors\.Gw\.low: unknown key; did you mean 'lower'"):
        prior_specs({"Gw": {"dist": "loguniform", "low": 1}})
    # bounds checked once merged with the default's: lower 0.01 W/K above this upper
    with pytest.raises(ConfigError, match=r"priors\.Gw\.lower: must be < upper"):
        configured_prior(prior_specs({"Gw": {"upper": 0.001}})["Gw"], default, where="priors.Gw")
    # a centre the default family has not: named, not ignored
    with pytest.raises(ConfigError, match=r"priors\.Gw\.median: a loguniform prior has no"):
        configured_prior(
            prior_specs({"Gw": {"median": 5, "sigma": 1}})["Gw"], default, where="priors.Gw"
        )
    m = hb.model("thermal_1c")
    with pytest.raises(ConfigError, match=r"thermal\.priors: unknown parameter\(s\) \['Gx'\]"):
        parameters_for(m, AR1Noise(), prior_specs({"Gx": {"fixed": 1}}), where="thermal.priors")
    with pytest.raises(ConfigError, match=r"priors\.Ge\.fixed: expected a number"):
        prior_specs({"Ge": {"fixed": "abc"}})
    with pytest.raises(ConfigError, match=r"priors\.Ge\.fixed: a conductance must be within"):
        parameters_for(m, AR1Noise(), prior_specs({"Ge": {"fixed": -1}}))
    given = prior_specs({"Ge": {"fixed": 50}, "Gf": {"upper": 10}})
    ps = parameters_for(m, AR1Noise(), given, room_volume=400)
    assert ps["Ge"].fixed == 50 and "Ge" not in ps.free_names
    assert ps["Gf"].prior.upper == 10 and ps["Gf"].prior.dist == "loguniform"
    # the room volume sets a log-normal prior on the air capacity around 5 x rho c V
    assert ps["Ci"].prior.dist == "lognormal"
    assert ps["Ci"].prior.mu == pytest.approx(5 * 1206 * 400)
    assert air_capacity_prior("hygric", 400).mu == pytest.approx(10 * 400 / (461.52 * 288.15))


def _ar1_cov(sigma, phi, idx):
    d = np.abs(idx[:, None] - idx[None, :])
    return sigma**2 * phi**d


@pytest.mark.parametrize("phi", [0.0, 0.5, 0.95])
def test_ar1_likelihood_with_gaps_equals_multivariate_normal(phi):
    rng = np.random.default_rng(3)
    N = 60
    ysim = rng.normal(size=(2, N))
    yobs = rng.normal(size=N)
    yobs[[5, 6, 7, 30, 41]] = np.nan
    noise = np.array([[0.7, phi], [1.3, phi]])
    ll = AR1Noise().loglik(ysim[:, :, None], yobs[:, None], noise)
    idx = np.flatnonzero(np.isfinite(yobs))
    for k in range(2):
        ref = stats.multivariate_normal(np.zeros(idx.size), _ar1_cov(noise[k, 0], phi, idx)).logpdf(
            yobs[idx] - ysim[k, idx]
        )
        assert ll[k] == pytest.approx(ref, rel=1e-10)
    pw = AR1Noise().pointwise(ysim[:, :, None], yobs[:, None], noise)
    np.testing.assert_allclose(np.nansum(pw, axis=(1, 2)), ll, rtol=1e-12)
    assert np.isnan(pw[0, 5, 0])


def test_iid_likelihood_is_the_normal_density():
    rng = np.random.default_rng(4)
    ysim = rng.normal(size=(3, 40, 1))
    yobs = rng.normal(size=(40, 1))
    yobs[10] = np.nan
    sig = np.array([[0.5], [1.0], [2.0]])
    ll = IIDNoise().loglik(ysim, yobs, sig)
    ok = np.isfinite(yobs[:, 0])
    for k in range(3):
        ref = stats.norm(ysim[k, ok, 0], sig[k, 0]).logpdf(yobs[ok, 0]).sum()
        assert ll[k] == pytest.approx(ref, rel=1e-12)


def test_ar1_noise_sampler_has_the_right_moments():
    rng = np.random.default_rng(5)
    z = rng.standard_normal((4, 200_000))
    out = np.empty_like(z)
    _ar1_sample(z, np.full(4, 0.8), np.full(4, 2.0), out)
    x = out.reshape(-1)
    # sd 2 and lag-1 correlation 0.8, to within a few standard errors
    assert np.std(x) == pytest.approx(2.0, rel=0.02)
    r1 = np.mean([np.corrcoef(o[:-1], o[1:])[0, 1] for o in out])
    assert r1 == pytest.approx(0.8, abs=0.01)


def _problem(name="thermal_1c", N=24 * 30, seed=0, noise=("ar1", 0.15, 0.8), **kw):
    rng = np.random.default_rng(seed)
    m = hb.model(name, **({"surfaces": ("S",)} if name.startswith("thermal") else {}))
    t = np.arange(N)
    cols = []
    for nm in m.input_names:
        if nm == "Te":
            cols.append(
                5 + 4 * np.sin(2 * np.pi * (t - 14) / 24) + np.cumsum(rng.normal(0, 0.3, N))
            )
        elif nm.startswith("I_"):
            cols.append(
                np.clip(400 * np.sin(2 * np.pi * (t - 6) / 24), 0, None) * rng.uniform(0.2, 1.0, N)
            )
        elif nm == "Tf":
            cols.append(np.full(N, 10.0))
        elif nm == "Pe":
            cols.append(900 + np.cumsum(rng.normal(0, 15, N)))
    U = np.column_stack(cols)
    truth = {
        "thermal_1c": dict(Ci=5e6, Ge=200.0, Gf=30.0, fI_S=3.0),
        "hygric_2c": dict(Cw=0.5, Ci=0.03, Gw=2e-8, Gi=1e-6, Gfast=4e-7),
    }[name]
    y = hb.simulate(m, truth, U)[:, 0]
    kind, sd, phi = noise
    e = np.empty((1, N))
    _ar1_sample(
        rng.standard_normal((1, N)), np.array([phi if kind == "ar1" else 0.0]), np.array([sd]), e
    )
    nm = get_noise_model(kind)
    ps = parameters_for(m, nm, **kw)
    lp = LogPosterior(m, ps, nm, U, (y + e[0])[:, None], warmup=48, init_window=24)
    return lp, truth


def test_log_posterior_is_vectorised_and_never_raises():
    lp, truth = _problem()
    X = lp.params.to_unconstrained(lp.params.sample_prior(np.random.default_rng(0), 9))
    batch = lp(X)
    single = np.array([lp(x) for x in X])
    np.testing.assert_allclose(batch, single, rtol=1e-12)
    X[2, 0] = np.nan
    X[3, 1] = np.inf
    out = lp(X)
    assert out[2] == -np.inf and out[3] == -np.inf and np.isfinite(out[0])
    # non-physical parameter sets in the likelihood give -inf, not an exception
    theta = np.tile(lp.params.values(X[:1]), (2, 1))
    theta[1, 0] = -1.0  # negative capacity
    ll = lp.log_likelihood(theta)
    assert np.isfinite(ll[0]) and ll[1] == -np.inf


def test_fused_likelihood_equals_simulate_then_likelihood():
    lp, _ = _problem("hygric_2c", noise=("ar1", 20.0, 0.7))
    lp.observed[100:130] = np.nan
    X = lp.params.to_unconstrained(lp.params.sample_prior(np.random.default_rng(2), 7))
    theta, _ = lp.params.transform(X)
    tm, tn = lp.split(theta)
    Y, _ = lp.simulate(tm)
    ref = lp.noise.loglik(Y, lp.observed, tn)
    mf = modal_form(lp.model, tm, lp.dt)
    z0 = mf.steady_state_modal(lp.u_init)
    fused = lp.noise.loglik_modal(mf, lp.inputs, z0, lp.observed, tn, max_block=500)
    np.testing.assert_allclose(fused, ref, rtol=1e-11)


def test_map_is_reproducible_and_finds_the_identifiable_quantities():
    lp, truth = _problem(room_volume=None)
    a = find_map(lp, seed=3, maxiter=60, starts=3)
    b = find_map(lp, seed=3, maxiter=60, starts=3)
    np.testing.assert_array_equal(a.theta, b.theta)
    assert a.n_starts == 3 and 1 <= a.n_agreed <= 3
    names = lp.params.names
    th = dict(zip(names, a.theta, strict=True))
    # time constant Ci/(Ge+Gf) and the gains are identifiable (the scale is not)
    tau_true = truth["Ci"] / (truth["Ge"] + truth["Gf"])
    assert th["Ci"] / (th["Ge"] + th["Gf"]) == pytest.approx(tau_true, rel=0.15)
    assert th["Ge"] / (th["Ge"] + th["Gf"]) == pytest.approx(200 / 230, rel=0.05)
    assert th["sigma_Ti"] == pytest.approx(0.15, rel=0.2)


def test_sampler_same_seed_same_chain_and_resume_continues_it(tmp_path):
    lp, _ = _problem(N=24 * 15)
    x0 = find_map(lp, seed=1, maxiter=30, starts=1).x
    kw = dict(seed=5, max_steps=300, check_every=100, tau_factor=1000)
    a = run_sampler(lp, x0, checkpoint=tmp_path / "a.h5", tag="t", **kw)
    b = run_sampler(lp, x0, checkpoint=tmp_path / "b.h5", tag="t", **kw)
    np.testing.assert_array_equal(a.chain, b.chain)
    assert a.chain.shape == (300, 32, lp.ndim)

    class Interrupting:
        """The log-posterior, interrupted (Ctrl-C) in the middle of the second chunk."""

        def __init__(self, lp, after):
            self.lp, self.n, self.after = lp, 0, after

        def __call__(self, X):
            self.n += 1
            if self.n == self.after:
                raise KeyboardInterrupt
            return self.lp(X)

    with pytest.raises(KeyboardInterrupt):
        run_sampler(
            Interrupting(lp, after=2 * 150 + 1), x0, checkpoint=tmp_path / "c.h5", tag="t", **kw
        )
    c = run_sampler(lp, x0, checkpoint=tmp_path / "c.h5", tag="t", resume=True, **kw)
    assert 0 < c.resumed_from < 300
    np.testing.assert_array_equal(c.chain, a.chain)
    with pytest.raises(InputError, match="different configuration"):
        run_sampler(lp, x0, checkpoint=tmp_path / "c.h5", tag="other", resume=True, **kw)


def test_floor_area_sets_the_ground_prior_of_thermal_models():
    """floor_area [m²]: Gf ~ lognormal(median 0.4 W/(m²K) × area, σ_log 1) on thermal
    models; a hygric model's Gf (to a fixed vapour pressure) gets its own, the vapour
    diffusion through the floor (tests/test_fixed_node.py); the config key reaches the
    parameters; a bad area is a ConfigError naming it."""
    import heritage_bayes as hb
    from heritage_bayes.config import parse_config
    from heritage_bayes.errors import ConfigError
    from heritage_bayes.inference.likelihoods import get_noise_model
    from heritage_bayes.inference.survey import U_GROUND, ground_prior
    from heritage_bayes.run import section_parameters

    noise = get_noise_model("ar1_white")
    th = hb.model("thermal_2c", surfaces=("S",))
    ps = parameters_for(th, noise, room_volume=400, floor_area=80)
    gf = ps.parameters[ps.names.index("Gf")].prior
    assert gf.dist == "lognormal" and gf.mu == pytest.approx(U_GROUND * 80) and gf.sigma == 1.0
    default = parameters_for(th, noise).parameters[ps.names.index("Gf")].prior
    assert default.dist == "loguniform"
    hy = hb.model("hygric_2c_fixed")
    hps = parameters_for(hy, noise, floor_area=80)
    assert hps.parameters[hps.names.index("Gf")].prior.mu == pytest.approx(3.2e-8)  # kg/(s·Pa)
    with pytest.raises(ConfigError, match="floor_area"):
        ground_prior(0.0)
    raw = {
        "data": {"demo": {"seed": 7}},
        "floor_area": 80,
        "thermal": {"model": "thermal_2c"},
    }
    cfg = parse_config(raw)
    _, ps2 = section_parameters(cfg, "thermal", hb.model("thermal_2c"), {})
    assert ps2.parameters[ps2.names.index("Gf")].prior.mu == pytest.approx(32.0)
    with pytest.raises(ConfigError, match="floor_area"):
        parse_config({**raw, "floor_area": -5})


def test_glazing_area_sets_the_aperture_priors():
    """glazing_area [m²] per surface: a log-normal prior on that surface's aperture fI,
    median 0.4 × the area (EN ISO 13790's collecting area), sd of log 0.7, bounds at
    ±5 sd; unlisted surfaces keep the default; a model without solar inputs (hygric)
    ignores it; a surface the model or data.surfaces lacks, an area ≤ 0 and a key with
    no solar input are ConfigErrors naming the key."""
    from heritage_bayes.config import parse_config
    from heritage_bayes.inference.survey import APERTURE_PER_GLAZING, aperture_prior
    from heritage_bayes.run import section_parameters

    p = aperture_prior(8.0)
    assert (p.dist, p.mu, p.sigma) == ("lognormal", pytest.approx(3.2), 0.7)
    assert APERTURE_PER_GLAZING == 0.4
    assert p.lower == pytest.approx(3.2 * math.exp(-3.5))
    assert p.upper == pytest.approx(3.2 * math.exp(3.5))
    noise = get_noise_model("ar1_white")
    th = hb.model("thermal_2c", surfaces=("N", "S"))
    ps = parameters_for(th, noise, glazing_area={"S": 8.0})
    prior = {q.name: q.prior for q in ps.parameters}
    assert prior["fI_S"] == aperture_prior(8.0)
    assert prior["fI_N"] == default_prior("thermal", "gain")
    # an explicit prior in the section still wins over the survey's
    ps = parameters_for(
        th,
        noise,
        prior_specs({"fI_S": {"dist": "uniform", "lower": 0, "upper": 5}}),
        glazing_area={"S": 8},
    )
    assert {q.name: q.prior for q in ps.parameters}["fI_S"].dist == "uniform"
    with pytest.raises(ConfigError, match=r"glazing_area: surface\(s\) \['E'\]"):
        parameters_for(th, noise, glazing_area={"E": 4.0})
    with pytest.raises(ConfigError, match=r"glazing_area\.S"):
        parameters_for(th, noise, glazing_area={"S": -1.0})
    hy = hb.model("hygric_2c")
    assert (
        parameters_for(hy, noise, glazing_area={"S": 8.0}).names == parameters_for(hy, noise).names
    )
    raw = {
        "data": {"demo": {"seed": 7}},
        "glazing_area": {"N": 1, "S": 8},
        "thermal": {"model": "thermal_2c"},
    }
    cfg = parse_config(raw)
    _, ps2 = section_parameters(cfg, "thermal", hb.model("thermal_2c"), {})
    got = {q.name: q.prior for q in ps2.parameters}
    assert got["fI_N"].mu == pytest.approx(0.4) and got["fI_S"].mu == pytest.approx(3.2)
    assert got["fI_E"] == default_prior("thermal", "gain")
    for bad, match in (
        ({"X": 1}, r"glazing_area: surface\(s\) \['X'\] are not in data.surfaces"),
        ({"N": 0}, "glazing_area: every area must be > 0"),
        ({"N": "abc"}, "glazing_area.N"),
    ):
        with pytest.raises(ConfigError, match=match):
            parse_config({**raw, "glazing_area": bad})
    with pytest.raises(ConfigError, match=r"glazing_area: given, but data\.irradiance is .none."):
        parse_config({**raw, "data": {"demo": {"seed": 7}, "irradiance": "none"}})


def test_envelope_area_bounds_the_envelope_node():
    """envelope_area [m²]: 0.1 W/(m²K) × area ≤ Gw ≤ 25 W/(m²K) × area (a passive-house
    wall; the exterior film, EN ISO 6946) and Cw ≤ 7.5 MJ/(m²K) × area (3 m of
    granite), the family and Cw's lower bound the defaults'; 4a's interior mass keeps
    its defaults; a hygric buffer's Gw ≤ 2e-9 kg/(m²·s·Pa) × area
    (s_d 0.1 m) and Cw ≤ 0.04 kg/(m²·Pa) × area (10 cm of wood at 0 °C); the config key reaches the
    parameters; the sampler's support follows the bound; an area that puts a bound
    below the default's lower one is a ConfigError naming the key."""
    import heritage_bayes as hb
    from heritage_bayes.config import parse_config
    from heritage_bayes.errors import ConfigError
    from heritage_bayes.inference.likelihoods import get_noise_model
    from heritage_bayes.inference.survey import (
        C_BUFFER_MAX,
        C_ENVELOPE_MAX,
        G_VAPOUR_MAX,
        G_VAPOUR_MIN,
        H_EXTERIOR,
        U_ENVELOPE_MIN,
        envelope_priors,
    )
    from heritage_bayes.run import section_parameters

    noise = get_noise_model("ar1_white")
    th = hb.model("thermal_4a", surfaces=("S",))
    ps = parameters_for(th, noise, envelope_area=259.0)
    prior = {p.name: p.prior for p in ps.parameters}
    assert prior["Gw"].upper == pytest.approx(25.0 * 259.0) == H_EXTERIOR * 259.0
    assert prior["Cw"].upper == pytest.approx(7.5e6 * 259.0) == C_ENVELOPE_MAX * 259.0
    assert prior["Gw"].lower == pytest.approx(0.1 * 259.0) == U_ENVELOPE_MIN * 259.0
    assert prior["Cw"].lower == default_prior("thermal", "capacity").lower
    for name, kind in (("Gw", "conductance"), ("Cw", "capacity")):
        d = default_prior("thermal", kind)
        assert prior[name].dist == d.dist
        assert prior[name].upper < d.upper
    assert prior["Cint"] == default_prior("thermal", "capacity")
    assert prior["Gint"] == default_prior("thermal", "conductance")
    assert prior["Gi"] == default_prior("thermal", "conductance")
    # the sampler cannot leave the bounded support
    lo, hi = ps.bounds
    j = ps.free_names.index("Gw")
    assert np.exp(hi[j]) == pytest.approx(H_EXTERIOR * 259.0)
    hy = hb.model("hygric_2c")
    hps = parameters_for(hy, noise, envelope_area=259.0)
    hprior = {p.name: p.prior for p in hps.parameters}
    assert hprior["Gw"].upper == pytest.approx(2e-9 * 259.0) == G_VAPOUR_MAX * 259.0
    assert hprior["Cw"].upper == pytest.approx(0.04 * 259.0) == C_BUFFER_MAX * 259.0
    # the buffer's link to outdoors: no tighter than s_d = 100 m of envelope
    assert hprior["Gw"].lower == pytest.approx(2e-12 * 259.0) == G_VAPOUR_MIN * 259.0
    assert hprior["Cw"].lower == default_prior("hygric", "capacity").lower
    for name, kind in (("Gw", "conductance"), ("Cw", "capacity")):
        assert hprior[name].dist == default_prior("hygric", kind).dist
    assert hprior["Gi"] == default_prior("hygric", "conductance")
    with pytest.raises(ConfigError, match="envelope_area"):
        envelope_priors(1e-4)
    raw = {"data": {"demo": {"seed": 7}}, "envelope_area": 259, "thermal": {"model": "thermal_2c"}}
    cfg = parse_config(raw)
    _, ps2 = section_parameters(cfg, "thermal", hb.model("thermal_2c"), {})
    assert ps2.parameters[ps2.names.index("Gw")].prior.upper == pytest.approx(6475.0)
    with pytest.raises(ConfigError, match="envelope_area"):
        parse_config({**raw, "envelope_area": 0})


def test_interior_area_sets_a_lognormal_prior_on_gint():
    """interior_area [m²]: Gint log-normal, median 5 W/(m²K) × area (EN ISO 6946's
    interior convection plus the air node's share of radiation), sd of log 0.7, bounds
    ±5 sd; a model without an interior mass (2c, hygric) keeps every default; a prior
    the config states on Gint wins; the config key reaches the parameters; an area ≤ 0
    is a ConfigError naming the key."""
    from heritage_bayes.config import parse_config
    from heritage_bayes.inference.survey import H_INTERIOR, interior_prior
    from heritage_bayes.run import section_parameters

    noise = get_noise_model("ar1_white")
    th = hb.model("thermal_4a", surfaces=("S",))
    prior = {p.name: p.prior for p in parameters_for(th, noise, interior_area=80.0).parameters}
    g = prior["Gint"]
    assert H_INTERIOR == 5.0
    assert (g.dist, g.mu, g.sigma) == ("lognormal", pytest.approx(400.0), 0.7)
    assert (g.lower, g.upper) == (
        pytest.approx(400 * math.exp(-3.5)),
        pytest.approx(400 * math.exp(3.5)),
    )
    # the prior's median and spread as stated: P(Gint < 400) = 1/2, P(Gint < 400 e^0.7) ≈ Φ(1)
    rng = np.random.default_rng(3)
    draws = g.sample(rng, 20_000)
    assert np.mean(draws < 400.0) == pytest.approx(0.5, abs=4 * 0.5 / np.sqrt(20_000))
    assert np.mean(draws < 400.0 * math.exp(0.7)) == pytest.approx(
        stats.norm.cdf(1.0), abs=4 * 0.5 / np.sqrt(20_000)
    )
    for name in ("Cint", "Gi", "Gw", "Cw", "Ci"):
        kind = "capacity" if name.startswith("C") else "conductance"
        assert prior[name] == default_prior("thermal", kind)
    for m in (hb.model("thermal_2c", surfaces=("S",)), hb.model("hygric_2c")):
        base = parameters_for(m, noise).to_dict()
        assert parameters_for(m, noise, interior_area=80.0).to_dict() == base
    own = prior_specs({"Gint": {"dist": "loguniform", "lower": 10, "upper": 1000}})
    stated = {
        p.name: p.prior for p in parameters_for(th, noise, own, interior_area=80.0).parameters
    }
    assert (stated["Gint"].dist, stated["Gint"].lower, stated["Gint"].upper) == (
        "loguniform",
        10,
        1000,
    )
    raw = {"data": {"demo": {"seed": 7}}, "interior_area": 120, "thermal": {"model": "thermal_4a"}}
    cfg = parse_config(raw)
    _, ps = section_parameters(cfg, "thermal", hb.model("thermal_4a", surfaces=("S",)), {})
    assert ps.parameters[ps.names.index("Gint")].prior.mu == pytest.approx(600.0)
    with pytest.raises(ConfigError, match="interior_area"):
        parse_config({**raw, "interior_area": 0})
    with pytest.raises(ConfigError, match="interior_area"):
        interior_prior(-1.0)


def _optimum(unit, log_post):
    from heritage_bayes.inference.optimize import MAPResult

    u = np.asarray(unit, dtype=float)
    return MAPResult(x=u, theta=u, log_post=log_post, n_starts=1, n_agreed=1, unit=u)


def test_restarts_report_separate_optima_and_keep_the_first_unless_clearly_worse():
    """Two optima 0.6 apart in the unit cube: with a deep valley between them (two narrow
    bumps) they are two modes; with a shallow one (two wide bumps) one; a restart's
    optimum replaces the first search's only when higher by more than MODE_PICK; optima
    more than MODE_WINDOW below the best are not modes."""
    from heritage_bayes.inference.optimize import MODE_PICK, MODE_WINDOW, _with_modes

    a, b = np.array([0.2, 0.5]), np.array([0.8, 0.5])

    def objective(width, ha=0.0, hb=0.0):
        def f(S):
            S = np.atleast_2d(S)
            da = ((S - a) ** 2).sum(axis=1) / (2 * width**2)
            db = ((S - b) ** 2).sum(axis=1) / (2 * width**2)
            return -np.logaddexp(ha - da, hb - db)

        return f

    narrow = objective(0.05)  # valley at 0.5: 0.3² / (2 × 0.05²) = 18 units deep
    r = _with_modes([_optimum(a, 0.0), _optimum(b, -1.0)], narrow)
    assert r.restarts == 2 and np.array_equal(r.unit, a) and r.log_post == 0.0
    assert [m["log_posterior"] for m in r.modes] == [0.0, -1.0]
    wide = objective(0.3)  # valley 0.5 units deep: one broad mode
    assert len(_with_modes([_optimum(a, 0.0), _optimum(b, 0.0)], wide).modes) == 1
    # the first is kept unless a restart is clearly higher
    r = _with_modes([_optimum(a, -(MODE_PICK - 0.5)), _optimum(b, 0.0)], narrow)
    assert np.array_equal(r.unit, a) and len(r.modes) == 2
    r = _with_modes([_optimum(a, -(MODE_PICK + 0.5)), _optimum(b, 0.0)], narrow)
    assert np.array_equal(r.unit, b) and r.modes[0]["log_posterior"] == 0.0
    # far below the best: not a mode (the search's local optimum, 790 vs 938 on the demo)
    r = _with_modes([_optimum(a, -(MODE_WINDOW + 1)), _optimum(b, 0.0)], narrow)
    assert np.array_equal(r.unit, b) and len(r.modes) == 1


def test_restarts_on_a_ridge_find_one_mode_and_keep_the_first_search():
    """thermal_1c without a room volume: the overall scale of C and G is a ridge of
    equal height. The restarts end at different points of it, which are not modes; the
    MAP is the first search's, as without restarts; the summary records both."""
    from heritage_bayes.inference.optimize import MODE_DISTANCE, _Objective, _search

    lp, _ = _problem(room_volume=None)
    one = find_map(lp, seed=3, maxiter=60, starts=2)
    three = find_map(lp, seed=3, maxiter=60, starts=2, restarts=3)
    np.testing.assert_array_equal(one.x, three.x)
    assert three.restarts == 3 and len(three.modes) == 1 and one.modes == []
    # the restarts did end at different points of the ridge
    obj = _Objective(lp)
    ends = [_search(lp, obj, s, "differential_evolution", 10, 60, 2) for s in (3, [3, 1], [3, 2])]
    assert max(np.abs(e.unit - ends[0].unit).max() for e in ends[1:]) > MODE_DISTANCE
    d = three.to_dict(lp.params.names)
    assert (
        d["restarts"] == 3
        and len(d["modes"]) == 1
        and "restarts" not in one.to_dict(lp.params.names)
    )
    with pytest.raises(ValueError, match="restarts"):
        find_map(lp, seed=3, restarts=0)


def test_the_modes_finding_names_where_the_optima_differ():
    """The warning of a multimodal MAP search: each other optimum's height and the
    parameters in which it differs (at most four, farthest first), with both values,
    and the ways out (a survey's area, a prior, the smaller model)."""
    from types import SimpleNamespace

    from heritage_bayes.calibration.findings import modes_finding

    names = ["Cw", "Cint", "Gint", "fsol", "sigma_Ti"]
    kept = {"log_posterior": 938.0, "theta": np.array([1.2e8, 1e4, 400, 0.41, 0.2])}
    kept["unit"] = np.array([0.5, 0.0, 0.5, 0.41, 0.3])
    other = {"log_posterior": 938.75, "theta": np.array([7.7e7, 4.4e7, 433, 0.0, 0.2])}
    other["unit"] = np.array([0.48, 0.45, 0.51, 0.0, 0.3])
    s = SimpleNamespace(
        name="thermal",
        logpost=SimpleNamespace(params=SimpleNamespace(names=names, free_names=names)),
        map=SimpleNamespace(modes=[kept, other], restarts=3),
    )
    msg = modes_finding(s, "thermal_2c")
    assert msg.startswith("[thermal] the MAP search found 2 separate optima")
    assert "(3 searches)" in msg and "log-posterior 938.0;" in msg
    assert "log-posterior 938.8 with Cint 1e+04 vs 4.4e+07, fsol 0.41 vs 0" in msg
    assert "Cw 1.2e+08" not in msg and "Gint 400" not in msg  # 0.02 apart: not named
    assert "multimodal" in msg and "(thermal.model: thermal_2c)" in msg
    assert "smaller model" not in modes_finding(s, None)


def test_what_the_package_asks_of_a_noise_model_instead_of_its_name():
    """The findings, the predictive bands, the projection and the report read these
    answers of the noise model; none of them tests its name."""
    from heritage_bayes.inference.likelihoods import (
        AR1WhiteNoise,
        ar1_innovations,
        ar1_white_innovations,
        find_noise_model,
        noise_parameter_names,
    )

    white, kalman = get_noise_model("ar1_white"), get_noise_model("kalman")
    assert white.capped_kinds == ("phi",) and kalman.capped_kinds == ()
    # bands: ar1_white's own model unless phi sits at its cap; kalman's never
    ps = parameters_for(hb.model("thermal_1c"), white, room_volume=400).parameters[-3:]
    cap = ps[1].prior.upper
    low, high = np.array([[0.3, 0.5, 0.1]] * 5), np.array([[0.3, cap, 0.1]] * 5)
    assert white.free_run_reason(0, "Ti", low, ps) is None
    assert white.free_run_reason(0, "Ti", high, ps).startswith(f"phi_Ti at its cap {cap:g}")
    assert get_noise_model("ar1").free_run_reason(0, "Ti", low[:, :2], ps) is None
    assert kalman.free_run_reason(0, "Ti", low, ps).startswith("process noise")
    assert white.free_run_model() is white
    assert isinstance(kalman.free_run_model(), AR1WhiteNoise)
    # the report's residual check
    e = np.random.default_rng(3).normal(size=50)
    medians = {"sigma": 0.5, "phi": 0.8, "sigma_meas": 0.2}
    view = white.residual_view(e, lambda k, absent=None: medians.get(k, absent))
    np.testing.assert_array_equal(view.innovations, ar1_white_innovations(e, 0.5, 0.8, 0.2))
    assert view.phi == 0.8 and view.acf_scale == pytest.approx(0.25 / 0.29)
    ar1 = get_noise_model("ar1").residual_view(e, lambda k, absent=None: medians.get(k, absent))
    np.testing.assert_array_equal(ar1.innovations, ar1_innovations(e, 0.8))
    iid = get_noise_model("iid").residual_view(e, lambda k, absent=None: medians.get(k, absent))
    assert iid.phi is None and np.array_equal(iid.innovations, e)
    # the noise parameters of a run's section, by the noise model's own names
    assert noise_parameter_names("kalman", ("Ti",), ("Ti", "Tw")) == {"sigma_Ti", "q_Ti", "q_Tw"}
    assert noise_parameter_names("ar1", ("Ti",)) == {"sigma_Ti", "phi_Ti"}
    assert find_noise_model("written_by_a_later_version") is None
    assert noise_parameter_names("written_by_a_later_version", ("Ti",)) == frozenset()
