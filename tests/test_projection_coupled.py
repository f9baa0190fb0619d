"""Projections of a hygric model that sorbs at the indoor temperature.

``hygric_2c_sorption`` takes ``Ti`` as an input: measured in the calibration, simulated
in a projection (the thermal model of the same draw, noise-free). A module-scoped
fixture calibrates the tiny virtual monument of the report tests with ``thermal_2c`` and
``hygric_2c_sorption`` (small budgets, not converged: enough draws to project).
"""

from __future__ import annotations

import copy

import numpy as np
import pytest

from heritage_bayes.calibration.calibrate import run_calibration
from heritage_bayes.config import parse_config
from heritage_bayes.errors import ConfigError, DataError
from heritage_bayes.projection import parse_projection_config, project
from heritage_bayes.run import load_run
from test_projection import PROJ
from test_report import TINY

DRAWS = 8


def _raw(hygric: dict, thermal: bool = True) -> dict:
    raw = copy.deepcopy(TINY)
    raw["hygric"] = hygric
    if thermal:
        raw["thermal"] = {"model": "thermal_2c"}
    else:
        del raw["thermal"]
    return raw


@pytest.fixture(scope="module")
def run_dir(tmp_path_factory):
    out = tmp_path_factory.mktemp("coupled") / "run"
    raw = _raw({"model": "hygric_2c_sorption"})
    run_calibration(parse_config(raw), out_dir=out, report=False, quiet=True)
    return out


def test_projection_gives_rh_draws(run_dir, tmp_path):
    vent = {"name": "half the ventilation", "ventilation": {"factor": 0.5}}
    heat = {"name": "heat", "heating": {"t_set": 12}}
    cfg = {**PROJ, "draws": DRAWS, "interventions": [vent, heat]}
    p = project(run_dir, cfg, out=tmp_path / "p")
    ds = p.dataset
    for res in p.interventions.values():
        assert all(np.isfinite(r.RHi_month).all() for r in res)
    # heating to 12 °C: a warmer room in winter and, the buffer sorbing at that Ti, a
    # lower RH than doing nothing; a heating energy for every draw
    nothing, heated = p.results[0], p.interventions["heat"][0]
    winter = np.isin(heated.months.month, [12, 1, 2])
    assert heated.Ti_month[:, winter].mean() >= 11.5
    assert heated.RHi_month[:, winter].mean() < nothing.RHi_month[:, winter].mean() - 5
    assert np.isfinite(heated.costs["heating_energy"]).all()
    assert ds.sizes["draw"] == DRAWS
    rh = ds["RHi_monthly"].values
    assert np.isfinite(rh).all() and (rh > 5).all() and (rh <= 100).all()
    ti = ds["Ti_monthly"].values  # the warmer scenario's room is warmer
    assert ti[1].mean() > ti[0].mean() + 1.0
    html = (tmp_path / "p" / "projection.html").read_text(encoding="utf-8")
    assert "hygric_2c_sorption" in html


def test_projected_series_is_the_models_own_simulation(run_dir):
    """On the baseline weather the projection's noise-free monthly means are those of the
    thermal draw simulated first and the hygric draw simulated on that ``Ti`` (the
    run's own models, outside the projection engine), draw by draw."""
    from heritage_bayes.climate.psychro import saturation_vapour_pressure
    from heritage_bayes.projection.engine import select_draws, simulate_cases
    from heritage_bayes.projection.weather import baseline_weather, model_inputs

    run = load_run(run_dir)
    pcfg = parse_projection_config({**PROJ, "draws": DRAWS})
    weather, site, _ = baseline_weather(run, pcfg)
    inp = model_inputs(run, pcfg, weather, site, "baseline")
    assert "Ti" not in inp.columns  # the future has no measured indoor temperature
    draws = select_draws(run, DRAWS, 5)
    res = simulate_cases(run, draws, [inp], seed=0, noise=False)[0]
    w = int(run.summary.get("init_steps", 720))
    mT, mH = run.models["thermal"], run.models["hygric"]
    UT = inp[list(mT.input_names)].to_numpy(float)
    Ti = mT.forward(draws.model["thermal"], UT, 3600.0, u_init=UT[:w].mean(axis=0))[0][..., 0]
    period = inp.index.tz_convert("UTC").tz_localize(None).to_period("M").asi8

    def months(x):  # calendar months in order of appearance (UTC)
        return [x[period == k].mean() for k in dict.fromkeys(period)]

    for j in range(DRAWS):
        UH = inp.assign(Ti=Ti[j])[list(mH.input_names)].to_numpy(float)
        P = draws.model["hygric"][j : j + 1]
        Pi = mH.forward(P, UH, 3600.0, u_init=UH[:w].mean(axis=0))[0]
        rh = np.clip(100 * Pi[0, :, 0] / saturation_vapour_pressure(Ti[j]), 0, 100)
        np.testing.assert_allclose(res.RHi_month[j], months(rh), rtol=1e-5)
        np.testing.assert_allclose(res.Ti_month[j], months(Ti[j]), rtol=1e-5)


def test_simulated_ti_keeps_the_calibrated_hygric_fit(run_dir):
    """Present-day weather, the calibration period: the hygric series driven by the
    thermal model's Ti fits the measured Pi about as well as the calibrated model's own
    simulation driven by the measured Ti (what the posterior was fitted on)."""
    from heritage_bayes.prepare import prepare

    run = load_run(run_dir)
    prep = prepare(run.config)
    f = prep.frame.iloc[prep.calibration]
    f = f.assign(Ti=f["Ti"].interpolate(limit_direction="both"))  # the input: gaps filled
    mT, mH = run.models["thermal"], run.models["hygric"]
    PT = mT.param_array(run.draws("thermal", 4, seed=1))[0]
    PH = mH.param_array(run.draws("hygric", 4, seed=1))[0]
    UT = f[list(mT.input_names)].to_numpy(float)
    UH = f[list(mH.input_names)].to_numpy(float)
    w = prep.init_steps
    obs = f["Pi"].to_numpy(float)
    Ti = mT.forward(PT, UT, prep.dt, u_init=UT[:w].mean(axis=0))[0][..., 0]
    own = mH.forward(PH, UH, prep.dt, u_init=UH[:w].mean(axis=0))[0][..., 0]
    for j in range(4):
        U2 = UH.copy()
        U2[:, list(mH.input_names).index("Ti")] = Ti[j]
        sim = mH.forward(PH[j : j + 1], U2, prep.dt, u_init=U2[:w].mean(axis=0))[0][0, :, 0]
        rmse_sim, rmse_own = (np.sqrt(np.nanmean((y - obs) ** 2)) for y in (sim, own[j]))
        assert rmse_sim < 1.1 * rmse_own + 1.0, (j, rmse_sim, rmse_own)


def test_hygric_run_without_thermal_model_is_refused(tmp_path):
    out = tmp_path / "run"
    raw = _raw({"model": "hygric_2c_sorption"}, thermal=False)
    run_calibration(parse_config(raw), out_dir=out, report=False, quiet=True)
    with pytest.raises(DataError) as e:
        project(out, {**PROJ, "draws": 4}, out=tmp_path / "p")
    msg = str(e.value)
    assert "hygric_2c_sorption" in msg and "Ti" in msg and "thermal model" in msg


def test_controlled_measure_is_refused_with_its_name(run_dir, tmp_path):
    dry = {"name": "dry", "dehumidification": {"rh_max": 60, "capacity": 0.5}}
    cfg = {**PROJ, "draws": 4, "interventions": [dry]}
    with pytest.raises(ConfigError, match=r"'dry'.*hygric_2c_sorption"):
        project(run_dir, cfg, out=tmp_path / "p")


def test_sink_at_the_ground_temperature_projects(tmp_path):
    """A sorbing buffer and a vapour sink at the ground temperature: the sink's ``Tf``
    is the thermal side's ground temperature projection, ``Ti`` each draw's own."""
    out = tmp_path / "run"
    raw = _raw({"model": "hygric_2c_sorption", "options": {"sink": "temperature"}})
    run_calibration(parse_config(raw), out_dir=out, report=False, quiet=True)
    p = project(out, {**PROJ, "draws": 4}, out=tmp_path / "p")
    rh = p.dataset["RHi_monthly"].values
    assert np.isfinite(rh).all() and (rh <= 100).all()
