"""The default noise model of a linear buffer with a sink at a temperature (``noise:
kalman`` at ``likelihood_temperature`` 2, ``config.models``) and the rule that fixes a
buffer's idle link to the outdoors at the MAP (``calibration.wall``)."""

import numpy as np
import pytest

import heritage_bayes as hb
from heritage_bayes.calibration.ladder import section_temperature
from heritage_bayes.calibration.wall import (
    DECOUPLED_RECORDS,
    config_with_fixed_walls,
    decoupled_wall,
    fix_decoupled_wall,
)
from heritage_bayes.config import ModelSection
from heritage_bayes.config.models import (
    FILTERED_SINK_LIKELIHOOD_TEMPERATURE,
    SINK_LIKELIHOOD_TEMPERATURE,
    SORPTION_LIKELIHOOD_TEMPERATURE,
)
from heritage_bayes.inference.likelihoods import get_noise_model
from heritage_bayes.inference.optimize import MAPResult
from heritage_bayes.inference.parameters import parameters_for
from heritage_bayes.inference.posterior import LogPosterior
from heritage_bayes.report.notes import _model_notes
from heritage_bayes.rundir.summary_parts import DecoupledWall, ModelInfo

KALMAN = get_noise_model("kalman")
AR1 = get_noise_model("ar1_white")


def _resolved(model, options, **kw):
    sec = ModelSection(model=model, options=options, **kw)
    m = hb.model(model, **sec.options.network_options())
    return sec.noise, section_temperature(sec, m)


@pytest.mark.parametrize("model", ["hygric_2c_fixed", "hygric_2c_sorption"])
def test_a_linear_buffer_with_a_sink_at_a_temperature_defaults_to_kalman_at_2(model):
    assert _resolved(model, {"sink": "temperature"}) == (
        "kalman",
        FILTERED_SINK_LIKELIHOOD_TEMPERATURE,
    )
    assert _resolved(model, {"sink": "temperature", "isotherm": "linear"})[0] == "kalman"


def test_where_the_filter_is_refused_the_default_stays_ar1_white():
    # the GAB buffer: the temperature as before (3 with a sink, 2 for a sorbing buffer)
    assert _resolved("hygric_2c_fixed", {"sink": "temperature", "isotherm": "gab"}) == (
        "ar1_white",
        SINK_LIKELIHOOD_TEMPERATURE,
    )
    assert _resolved("hygric_2c_sorption", {"sink": "temperature", "isotherm": "gab"}) == (
        "ar1_white",
        SORPTION_LIKELIHOOD_TEMPERATURE,
    )
    # a humidistat (a controlled room), no sink at a temperature, the ladder, other models
    for model, options in [
        ("hygric_2c_sorption", {"sink": "temperature", "humidistat": True}),
        ("hygric_2c_fixed", {"sink": "constant"}),
        ("hygric_2c_fixed", {}),
        ("hygric_2c", {}),
    ]:
        assert ModelSection(model=model, options=options).noise == "ar1_white", model
    assert ModelSection(model="auto", options={"sink": "temperature"}).noise == "ar1_white"


def test_an_explicit_noise_or_temperature_wins():
    sink = {"sink": "temperature"}
    assert _resolved("hygric_2c_fixed", sink, noise="ar1_white") == (
        "ar1_white",
        SINK_LIKELIHOOD_TEMPERATURE,
    )
    assert _resolved("hygric_2c_fixed", sink, likelihood_temperature=3) == ("kalman", 3.0)
    assert _resolved("hygric_2c_fixed", sink, noise="kalman") == ("kalman", 2.0)
    # the default is not the user's choice, and a run's config.yaml (a full dump) reads
    # back to the same section
    sec = ModelSection(model="hygric_2c_fixed", options=sink)
    assert "noise" not in sec.model_fields_set
    back = ModelSection.model_validate(sec.model_dump(mode="json"))
    assert (back.noise, back.temperature("hygric", 2, False, "temperature")) == ("kalman", 2.0)


def _room(gw, noise=KALMAN, N=24 * 60, seed=3):
    """hygric_2c (buffer Cw linked to the outdoors by Gw) on a synthetic record, its
    log-posterior under ``noise`` and the truth (every parameter) as the MAP."""
    m = hb.model("hygric_2c").with_slopes(["Pe"])
    rng = np.random.default_rng(seed)
    t = np.arange(N)
    pe = 1000 + 300 * np.sin(2 * np.pi * t / 24) + np.cumsum(rng.normal(0, 20, N))
    U = np.column_stack([pe, np.r_[np.diff(pe), 0.0]])
    truth = {"Cw": 0.05, "Ci": 3e-3, "Gw": gw, "Gi": 1e-7, "Gfast": 2e-7}
    y = m.forward(np.array([[truth[n] for n in m.parameter_names]]), U, 3600.0)[0][0, :, 0]
    y = y + rng.normal(0, 10, N)

    def build(priors=None):
        ps = parameters_for(m, noise, priors or {})
        return LogPosterior(m, ps, noise, U, y, warmup=24, init_window=100)

    lp = build()
    extra = {"sigma_Pi": 10.0, "q_Pw": 1.0, "q_Pi": 5.0, "phi_Pi": 0.5, "sigma_meas_Pi": 10.0}
    theta = np.array([{**truth, **extra}[n] for n in lp.params.names])
    return lp, theta, build


def test_the_rule_fixes_an_idle_buffer_link_at_its_floor():
    lp, theta, build = _room(gw=1e-11)  # Cw/Gw about 1 000 records
    wall = decoupled_wall(lp, theta)
    assert wall is not None and wall.parameter == "Gw" and wall.capacity == "Cw"
    assert wall.floor == lp.params["Gw"].prior.lower
    assert wall.records >= DECOUPLED_RECORDS and wall.delta_log_posterior > -0.5
    x = lp.params.to_unconstrained(theta[None])[0]
    mp = MAPResult(x=x, theta=theta, log_post=-1.0, n_starts=1, n_agreed=1)
    lp2, mp2, priors = fix_decoupled_wall(wall, build, {}, mp)
    assert priors["Gw"].fixed == wall.floor and not lp2.params["Gw"].free
    assert lp2.ndim == lp.ndim - 1 and mp2.x.shape == (lp2.ndim,)
    assert mp2.theta[lp2.params.names.index("Gw")] == wall.floor
    np.testing.assert_allclose(lp2(mp2.x[None])[0], lp(x[None])[0] + wall.delta_log_posterior)
    # a prior the user sets is a decision taken; the residual noise models mix along it
    assert decoupled_wall(lp, theta, priors={"Gw": object()}) is None
    lpa, thetaa, _ = _room(gw=1e-11, noise=AR1)
    assert decoupled_wall(lpa, thetaa) is None


def test_the_rule_leaves_an_exchanging_buffer_free():
    lp, theta, _ = _room(gw=5e-8)  # Cw/Gw 12 days: a fifth of the record
    assert decoupled_wall(lp, theta) is None
    # idle by its exchange time (about 240 records), but with a precise fit (1 Pa, little
    # process noise) the log-posterior drops by tens of nats at the floor: not fixed
    lp, theta, _ = _room(gw=4e-11)
    n = lp.params.names
    theta[[n.index("sigma_Pi"), n.index("q_Pw"), n.index("q_Pi")]] = [1.0, 0.01, 0.01]
    at = theta.copy()
    at[n.index("Gw")] = lp.params["Gw"].prior.lower
    drop = np.diff(lp(lp.params.to_unconstrained(np.vstack([theta, at]))))[0]
    assert 0.05 / 4e-11 / lp.record_seconds > DECOUPLED_RECORDS and drop < -10
    assert decoupled_wall(lp, theta) is None


def test_the_finding_is_recorded_and_read_back():
    w = DecoupledWall("Gw", "Cw", 1e-12, 4.9e-10, 3.8e6, 427.0, 0.01)
    d = w.to_dict()
    assert DecoupledWall.from_dict(d) == w and DecoupledWall.from_dict(None) is None
    info = ModelInfo.from_dict("hygric", {"model": "hygric_2c_fixed", "decoupled_wall": d})
    assert info.decoupled_wall == w
    assert ModelInfo.from_dict("hygric", {"model": "hygric_2c"}).decoupled_wall is None
    assert "Gw fixed at its prior's floor 1e-12" in w.text("hygric")
    notes = _model_notes("hygric", info)
    assert any("fixed at its floor" in n["title"] for n in notes)


class _S:
    def __init__(self, name, fixed):
        self.name, self.fixed_priors = name, fixed


def test_the_run_config_records_the_fixed_link():
    from heritage_bayes.config import prior_specs
    from heritage_bayes.config.calibration import parse_config

    cfg = parse_config(
        {
            "data": {"demo": {}},
            "hygric": {"model": "hygric_2c_fixed", "options": {"sink": "temperature"}},
        }
    )
    assert config_with_fixed_walls(cfg, [_S("hygric", None)]) is None
    fixed = prior_specs({"Gw": {"fixed": 1e-12}})
    out = config_with_fixed_walls(cfg, [_S("hygric", fixed)])
    assert out.hygric.priors["Gw"].fixed == 1e-12 and out.hygric.noise == "kalman"
    assert "Gw" not in cfg.hygric.priors
    assert out.resolved()["hygric"]["priors"]["Gw"] == {"fixed": 1e-12}


def test_the_model_page_names_the_cellars_default():
    """``hbayes models NAME`` says that a sink at a temperature changes the default noise
    model of the models it does (and only of those)."""
    from heritage_bayes.models import describe_model

    for name in ("hygric_2c_fixed", "hygric_2c_sorption"):
        text = describe_model(name)
        assert f"the default is 'kalman' at likelihood temperature {2:g}" in text
        assert "the default is 'kalman'" not in describe_model(name, "kalman")
    assert "the default is 'kalman'" not in describe_model("hygric_2c")
    assert FILTERED_SINK_LIKELIHOOD_TEMPERATURE == 2.0


def test_priors_on_the_ar1_noise_keep_it_for_a_sink():
    """A config that sets a prior on ``phi_Pi`` or ``sigma_meas_Pi`` (a logger's known
    resolution, say) has chosen the AR(1) noise, which the filter would refuse: the
    cellar's default does not override it."""
    sink = {"sink": "temperature"}
    for name in ("phi_Pi", "sigma_meas_Pi"):
        sec = ModelSection(model="hygric_2c_fixed", options=sink, priors={name: {"fixed": 0.5}})
        assert sec.noise == "ar1_white"
    sec = ModelSection(model="hygric_2c_fixed", options=sink, priors={"Gw": {"fixed": 1e-12}})
    assert sec.noise == "kalman"
