"""The physical default priors of hygric_2c_fixed's fixed vapour-pressure node (Pf, Gf):
the prior functions, their reach through ``parameters_for``, the config key
``fixed_node_temperature``, its resolution from the data by ``prepare`` and its record
in a run's config.yaml."""

from __future__ import annotations

import math

import numpy as np
import pandas as pd
import pytest

import heritage_bayes as hb
from heritage_bayes.climate.psychro import saturation_vapour_pressure
from heritage_bayes.config import parse_config, prior_specs
from heritage_bayes.errors import ConfigError
from heritage_bayes.inference.likelihoods import get_noise_model
from heritage_bayes.inference.parameters import parameters_for
from heritage_bayes.inference.survey import (
    DELTA_AIR,
    RH_FIXED_NODE,
    SD_FLOOR,
    SIGMA_FIXED_NODE,
    fixed_vapour_pressure_prior,
    vapour_ground_prior,
)
from heritage_bayes.inputs import fixed_node_temperature

NOISE = get_noise_model("ar1_white")


def _prior(ps, name):
    return ps.parameters[ps.names.index(name)].prior


def test_pf_prior_is_lognormal_around_the_saturation_pressure_of_the_ground():
    """Median 0.9 × p_sat(T): 1 105.6 Pa at 10 °C (p_sat 1 228.1 Pa, IAPWS), sd of log
    0.25, bounds median × exp(±1.25); a temperature off the ground's range names the
    key."""
    p = fixed_vapour_pressure_prior(10.0)
    assert p.dist == "lognormal" and p.sigma == SIGMA_FIXED_NODE == 0.25
    assert p.mu == pytest.approx(RH_FIXED_NODE * 1228.1, rel=1e-4)
    assert p.mu == pytest.approx(0.9 * saturation_vapour_pressure(10.0))
    assert (p.lower, p.upper) == pytest.approx((p.mu * math.exp(-1.25), p.mu * math.exp(1.25)))
    # warmer ground, higher pressure: 6-7 % per kelvin near 10 °C
    ratio = fixed_vapour_pressure_prior(11.0).mu / p.mu
    assert 1.06 < ratio < 1.08
    for bad in (55.0, float("nan")):
        with pytest.raises(ConfigError, match="fixed_node_temperature"):
            fixed_vapour_pressure_prior(bad)


def test_gf_prior_is_diffusion_through_the_floor():
    """Median δ_air / s_d × area = 2e-10 / 0.5 × 80 = 3.2e-8 kg/(s·Pa), sd of log 1."""
    g = vapour_ground_prior(80.0)
    assert g.dist == "lognormal" and g.sigma == 1.0
    assert g.mu == pytest.approx(DELTA_AIR / SD_FLOOR * 80.0) == pytest.approx(3.2e-8)
    with pytest.raises(ConfigError, match="floor_area"):
        vapour_ground_prior(0.0)


def test_parameters_for_sets_the_fixed_node_priors_of_hygric_2c_fixed_only():
    """With the ground temperature and the floor area, hygric_2c_fixed's Pf and Gf get
    the physical priors; without them the former defaults stay; the thermal Gf keeps
    its own ground prior and hygric_2c has no fixed node; a user's prior wins."""
    hy = hb.model("hygric_2c_fixed")
    ps = parameters_for(hy, NOISE, floor_area=80, fixed_node_temperature=10.0)
    assert _prior(ps, "Pf") == fixed_vapour_pressure_prior(10.0)
    assert _prior(ps, "Gf") == vapour_ground_prior(80.0)
    old = parameters_for(hy, NOISE)
    assert (_prior(old, "Pf").dist, _prior(old, "Pf").upper) == ("uniform", 5000.0)
    assert _prior(old, "Gf").dist == "loguniform"
    th = hb.model("thermal_2c", surfaces=("S",))
    tps = parameters_for(th, NOISE, floor_area=80, fixed_node_temperature=10.0)
    assert _prior(tps, "Gf").mu == pytest.approx(0.4 * 80)  # W/K, ground_prior's
    h2 = parameters_for(hb.model("hygric_2c"), NOISE, floor_area=80, fixed_node_temperature=10.0)
    assert "Pf" not in h2.names and "Gf" not in h2.names
    user = parameters_for(
        hy,
        NOISE,
        prior_specs({"Pf": {"dist": "uniform", "lower": 0, "upper": 3000}}),
        fixed_node_temperature=10.0,
    )
    assert (_prior(user, "Pf").dist, _prior(user, "Pf").upper) == ("uniform", 3000.0)


def test_config_key_reaches_the_priors_and_is_range_checked():
    raw = {
        "data": {"demo": {}},
        "floor_area": 80,
        "fixed_node_temperature": 9.5,
        "hygric": {"model": "hygric_2c_fixed"},
    }
    cfg = parse_config(raw)
    from heritage_bayes.run import section_parameters

    _, ps = section_parameters(cfg, "hygric", hb.model("hygric_2c_fixed"), {})
    assert _prior(ps, "Pf").mu == pytest.approx(fixed_vapour_pressure_prior(9.5).mu)
    with pytest.raises(ConfigError, match="fixed_node_temperature"):
        parse_config({**raw, "fixed_node_temperature": 80})


def test_fixed_node_temperature_from_the_data():
    """The thermal model's Tf over the calibration rows, else the constant, else the
    annual mean outdoor temperature over those rows; no Te and nothing else: an error
    that names the key."""
    idx = pd.date_range("2019-01-01", periods=24 * 400, freq="1h", tz="UTC")
    # a sine of one year around 10 °C: its 365-day running mean is 10 °C everywhere
    days = (idx - idx[0]) / pd.Timedelta(days=365)
    te = pd.Series(10.0 + 8.0 * np.sin(2 * np.pi * np.asarray(days)), index=idx)
    frame = pd.DataFrame({"Pe": 1000.0}, index=idx[:2000])
    rows = slice(100, 1900)
    got = fixed_node_temperature(frame, rows, te)
    assert got["value"] == pytest.approx(10.0, abs=0.05)
    assert "annual mean" in got["method"]
    assert fixed_node_temperature(frame, rows, te, constant=8.25)["value"] == 8.25
    with_tf = frame.assign(Tf=np.where(np.arange(2000) < 100, 99.0, 7.5))
    assert fixed_node_temperature(with_tf, rows, te)["value"] == 7.5
    with pytest.raises(ConfigError, match="fixed_node_temperature"):
        fixed_node_temperature(frame, rows, None)


def test_prepare_resolves_the_temperature_for_a_fixed_node_only():
    """prepare() records the Pf prior's temperature when the hygric model has the fixed
    node and the config does not give it; the demo's annual mean there is its
    Greensboro TMY3's (15.0 °C, the mean of the typical year)."""
    from heritage_bayes.prepare import prepare

    raw = {
        "data": {"demo": {}, "ground_temperature": {"mode": "annual_mean"}},
        "periods": {
            "calibration": {"start": "2019-01-02", "end": "2019-02-15"},
            "validation": {"start": "2019-02-15", "end": "2019-03-01"},
        },
        "hygric": {"model": "hygric_2c_fixed"},
    }
    prep = prepare(parse_config(raw))
    got = prep.sources["fixed_node_temperature"]
    assert 14.0 < got["value"] < 16.0 and "annual mean" in got["method"]
    given = prepare(parse_config({**raw, "fixed_node_temperature": 12.0}))
    assert "fixed_node_temperature" not in given.sources
    plain = prepare(parse_config({**raw, "hygric": {"model": "hygric_2c"}}))
    assert "fixed_node_temperature" not in plain.sources


def test_a_run_records_the_temperature_and_its_readers_rebuild_the_prior(tmp_path):
    """A tiny hygric_2c_fixed calibration (a week of the demo, 100 steps) writes the
    resolved ``fixed_node_temperature`` into its config.yaml; the loaded run's config
    rebuilds the Pf prior the chain sampled (summary's prior_spec)."""
    import yaml

    from heritage_bayes.calibration.calibrate import run_calibration
    from heritage_bayes.run import load_run, section_parameters

    raw = {
        "name": "fixed",
        "seed": 3,
        "data": {"demo": {"seed": 7}},
        "room_volume": 400,
        "floor_area": 80,
        "periods": {
            "calibration": {"start": "2019-02-01", "end": "2019-02-08"},
            "validation": {"start": "2019-02-08", "end": "2019-02-10"},
            "init_window": "2d",
        },
        "hygric": {"model": "hygric_2c_fixed"},
        "sampler": {"max_steps": 100, "check_every": 50, "max_draws": 100, "n_predictive": 10},
        "optimizer": {"maxiter": 10, "starts": 1, "popsize": 4},
        "ladder": False,
        "report": False,
    }
    out = run_calibration(parse_config(raw), out_dir=tmp_path / "run", quiet=True)
    written = yaml.safe_load((out / "config.yaml").read_text(encoding="utf-8"))
    t = written["fixed_node_temperature"]
    assert 14.0 < t < 16.0  # Greensboro's typical year
    run = load_run(out)
    assert run.config.fixed_node_temperature == t
    _, ps = section_parameters(run.config, "hygric", run.models["hygric"])
    sampled = run.summary["parameters"]["hygric.Pf"]["prior_spec"]
    assert sampled == _prior(ps, "Pf").to_dict() == fixed_vapour_pressure_prior(t).to_dict()
    assert run.summary["parameters"]["hygric.Gf"]["prior_spec"]["median"] == pytest.approx(3.2e-8)
