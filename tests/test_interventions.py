"""Interventions in projections (issue 29): pairing by construction, the physics of
conservation heating and dehumidification, running costs, the schema and the page.

One module-scoped tiny calibration (thermal_1c + hygric_1c as tests/test_projection.py,
a few seconds, not converged: enough draws) and one baseline year (the demo's TMY,
8759 h, of which 8760 - 1 complete-year hours: one year is simulated).
"""

from __future__ import annotations

import copy
from pathlib import Path

import numpy as np
import pytest

from heritage_bayes.calibration.calibrate import run_calibration
from heritage_bayes.config import parse_config
from heritage_bayes.errors import ConfigError
from heritage_bayes.projection import parse_projection_config, project
from heritage_bayes.projection.engine import select_draws, simulate_cases
from heritage_bayes.projection.interventions import Measure, measures_from_config
from heritage_bayes.projection.weather import baseline_weather, model_inputs
from test_report import TINY

DRAWS = 6
PROJ = {
    "draws": DRAWS,
    "seed": 2,
    "morphing": [
        {"scenario": "warm", "horizon": 2050, "method": "shift", "deltas": {"Te": [2.0] * 12}}
    ],
    "risk": {"chunk_draws": 4},
}


@pytest.fixture(scope="module")
def run(tmp_path_factory):
    from heritage_bayes.run import load_run

    out = tmp_path_factory.mktemp("interv") / "run"
    run_calibration(parse_config(copy.deepcopy(TINY)), out_dir=out, report=False, quiet=True)
    return load_run(out)


@pytest.fixture(scope="module")
def case(run):
    pcfg = parse_projection_config(PROJ)
    weather, site, _ = baseline_weather(run, pcfg)
    inputs = model_inputs(run, pcfg, weather, site, "baseline")
    draws = select_draws(run, DRAWS, 2)
    nothing = simulate_cases(run, draws, [inputs], seed=2, chunk=4)[0]
    return draws, inputs, nothing


def _with(run, case, measure):
    draws, inputs, _ = case
    return simulate_cases(run, draws, [inputs], seed=2, chunk=4, measure=measure)[0]


def test_a_measure_that_changes_nothing_is_do_nothing_in_every_draw(run, case):
    """Ventilation × 1 takes the same path as doing nothing: identical in every draw."""
    _, _, nothing = case
    same = _with(run, case, Measure("nothing", ventilation=1.0))
    cols = [c for c in nothing.predictive.columns if c != "ashrae_best_class"]
    d = same.predictive[cols].to_numpy(float) - nothing.predictive[cols].to_numpy(float)
    assert np.all((d == 0) | np.isnan(d))
    np.testing.assert_array_equal(same.Ti_month, nothing.Ti_month)


def test_a_dehumidifier_of_zero_capacity_changes_nothing(run, case):
    """Through the controller (model.forward) instead of the compiled pass: equal to
    rounding (1e-9 relative), the same noise draw added; no water removed."""
    _, _, nothing = case
    zero = _with(run, case, Measure("off", dehumidifier=(0.4, 0.0, 0.7)))
    cols = [c for c in nothing.predictive.columns if c != "ashrae_best_class"]
    np.testing.assert_allclose(
        zero.predictive[cols].to_numpy(float),
        nothing.predictive[cols].to_numpy(float),
        rtol=1e-9,
        atol=1e-9,
    )
    np.testing.assert_allclose(zero.RHi_month, nothing.RHi_month, rtol=1e-5)
    assert np.all(zero.costs["water_removed"] == 0)
    assert np.all(zero.costs["dehumidifier_energy"] == 0)


def test_conservation_heating_lowers_rh_and_raises_t_in_every_draw(run, case):
    _, _, nothing = case
    rh_now = float(np.nanmedian(nothing.RHi_month))
    target = max(30.0, rh_now - 15.0)  # [%] well below the room's typical RH
    heat = _with(run, case, Measure("ch", heating=(target / 100, -273.15, 25.0, np.inf)))
    assert np.all(heat.RHi_month.mean(axis=1) < nothing.RHi_month.mean(axis=1))
    assert np.all(heat.Ti_month.mean(axis=1) > nothing.Ti_month.mean(axis=1))
    assert np.all(heat.costs["heating_energy"] > 0)
    assert np.all(heat.costs["heating_peak"] > 0)
    # a lower cap t_max: less heat, a cooler and damper room, in every draw
    capped = _with(run, case, Measure("ch", heating=(target / 100, -273.15, 8.0, np.inf)))
    e, e8 = heat.costs["heating_energy"], capped.costs["heating_energy"]
    assert np.all(e8 < e)
    assert np.all(capped.Ti_month.mean(axis=1) < heat.Ti_month.mean(axis=1))
    assert np.all(capped.RHi_month.mean(axis=1) > heat.RHi_month.mean(axis=1))


def test_power_limit_bounds_the_peak(run, case):
    heat = _with(run, case, Measure("ch", heating=(0.3, -273.15, 30.0, 200.0)))
    assert np.all(heat.costs["heating_peak"] <= 0.2 + 1e-12)  # [kW]


def test_heating_schedule(run, case):
    """A thermostat at 10 °C raises the mean T and lowers the mean RH in every draw;
    16 °C on Sunday mornings (UTC+1) costs more energy in every draw."""
    from heritage_bayes.rc.calendar import parse_weekly

    _, _, nothing = case
    base = _with(run, case, Measure("t", thermostat=(10.0, None, None, np.inf)))
    assert np.all(base.Ti_month.mean(axis=1) > nothing.Ti_month.mean(axis=1))
    assert np.all(base.RHi_month.mean(axis=1) < nothing.RHi_month.mean(axis=1))
    cal = parse_weekly({"weekly": ["Sun 08-12"], "timezone": "UTC+1"})
    use = _with(run, case, Measure("s", thermostat=(10.0, 16.0, cal, np.inf)))
    assert np.all(use.costs["heating_energy"] > base.costs["heating_energy"])
    assert np.all(base.costs["heating_energy"] > 0)


def test_dehumidifier_lowers_rh_and_removes_water(run, case):
    _, _, nothing = case
    dry = _with(run, case, Measure("dh", dehumidifier=(0.45, 5.0 / 3600, 0.7)))
    assert np.all(dry.RHi_month.mean(axis=1) < nothing.RHi_month.mean(axis=1))
    w = dry.costs["water_removed"].to_numpy()
    assert np.all(w > 0)
    assert np.all(dry.costs["dehumidifier_peak"] <= 5.0 + 1e-9)  # [kg/h] capacity
    np.testing.assert_allclose(dry.costs["dehumidifier_energy"], 0.7 * w)
    # the temperature is not touched by a dehumidifier
    np.testing.assert_allclose(dry.Ti_month, nothing.Ti_month, rtol=1e-5)


def test_schema():
    ok = {
        **PROJ,
        "interventions": [
            {"name": "ch", "conservation_heating": {"rh_max": 65, "t_max": 20, "t_min": 5}},
            {"name": "dh", "dehumidification": {"rh_max": 60, "capacity": 0.5}},
            {"name": "less air", "ventilation": {"factor": 0.5}},
            {
                "name": "services",
                "heating": {"t_set": 8, "t_use": 16, "weekly": ["Sun 08-12"], "timezone": "UTC+1"},
                "dehumidification": {"rh_max": 60, "capacity": 0.5},
            },
        ],
    }
    ok["interventions"] += [
        {"name": "ch+dh", "conservation_heating": {"rh_max": 70, "t_max": 18},
         "dehumidification": {"rh_max": 60, "capacity": 0.5}},
        {"name": "band", "humidistat_band": {"rh_min": 45, "rh_max": 60,
         "dehumidifier_capacity": 1.8, "humidifier_capacity": 0.36,
         "humidifier_energy_per_kg": 0.75}},
    ]  # fmt: skip
    ms = measures_from_config(parse_projection_config(ok))
    assert ms[4].heating == (0.7, -273.15, 18.0, np.inf) and ms[4].dehumidifier[0] == 0.6
    assert ms[5].humidistat == pytest.approx((0.45, 0.6, 0.0005, 0.0001, 0.05, None, 0.75))
    assert ms[0].heating == (0.65, 5.0, 20.0, np.inf)
    assert ms[1].dehumidifier == (0.6, 0.5 / 3600, None)
    assert ms[2].ventilation == 0.5
    assert ms[3].thermostat[:2] == (8.0, 16.0) and ms[3].thermostat[2].hours_per_week == 4
    assert ms[3].dehumidifier is not None
    bad = [
        ({"name": "x", "conservation_heating": {"rh_max": 65, "t_max": 20, "power": 1}},
         "power"),
        ({"name": "x", "dehumidification": {"rh_max": 60}}, "capacity"),
        ({"name": "x"}, "give a change"),
        ({"name": "x", "dehumidification": {"rh_max": 60, "capacity": 1},
          "humidistat_band": {"rh_min": 40, "rh_max": 60, "dehumidifier_capacity": 1,
                              "humidifier_capacity": 1}}, "both humidistats"),
        ({"name": "x", "humidistat_band": {"rh_min": 60, "rh_max": 50,
          "dehumidifier_capacity": 1, "humidifier_capacity": 1}}, "rh_min"),
        ({"name": "x", "humidistat_band": {"rh_min": 50, "rh_max": 60, "differential": 5,
          "dehumidifier_capacity": 1, "humidifier_capacity": 1}}, "chase each other"),
        ({"name": "do nothing", "ventilation": {"factor": 0.5}}, "names doing nothing"),
        ({"name": "x", "conservation_heating": {"rh_max": 65, "t_min": 20, "t_max": 10}},
         "t_min"),
        ({"name": "x", "ventilation": {"factor": -1}}, "factor"),
        ({"name": "x", "heating": {"t_set": 8, "t_use": 16}}, "together"),
        ({"name": "x", "heating": {"t_set": 8, "t_use": 16, "weekly": ["Sun 25-26"]}},
         "heating"),
        ({"name": "x", "heating": {"t_set": 8},
          "conservation_heating": {"rh_max": 65, "t_max": 20}}, "give one"),
    ]  # fmt: skip
    for item, needle in bad:
        with pytest.raises(ConfigError, match=needle):
            parse_projection_config({**PROJ, "interventions": [item]})
    with pytest.raises(ConfigError, match="repeated"):
        parse_projection_config({**PROJ, "interventions": [ok["interventions"][2]] * 2})


@pytest.fixture(scope="module")
def projected(run, tmp_path_factory):
    cfg = {
        **PROJ,
        "interventions": [
            {"name": "conservation heating",
             "conservation_heating": {"rh_max": 50, "t_max": 22, "power_max": 2000}},
            {"name": "dehumidifier",
             "dehumidification": {"rh_max": 50, "capacity": 1.0, "energy_per_kg": 0.7}},
            {"name": "half ventilation", "ventilation": {"factor": 0.5}},
        ],
        "tariffs": {"electricity_eur_per_kwh": 0.3, "heat_eur_per_kwh": 0.12,
                    "electricity_co2_kg_per_kwh": 0.4, "heat_co2_kg_per_kwh": 0.2},
    }  # fmt: skip
    return project(run, cfg, out=tmp_path_factory.mktemp("interv_p") / "p")


def test_project_compares_measures_and_draws_the_page(projected):
    p = projected
    iv = p.summary["interventions"]
    assert list(iv) == ["conservation heating", "dehumidifier", "half ventilation"]
    for e in iv.values():
        assert set(e["cases"]) == set(p.labels)
        for d in e["cases"]["warm 2050"]["indicators"].values():
            assert d["p_better"] is None or 0 <= d["p_better"] <= 1
            assert d["q05"] is None or d["q05"] <= d["q50"] <= d["q95"]
    ch = iv["conservation heating"]["cases"]["warm 2050"]
    assert ch["costs"]["heating_energy"]["q50"] > 0
    assert ch["costs"]["heating_peak"]["q95"] <= 2.0 + 1e-9
    assert iv["half ventilation"]["notes"]  # thermal_1c has no separate Gfast
    ds = p.dataset
    assert list(ds["measure"].values) == list(iv)
    e = ds["cost_heating_energy"].sel(measure="conservation heating", case="warm 2050")
    assert float(e.median()) == pytest.approx(ch["costs"]["heating_energy"]["q50"], rel=1e-5)
    assert np.isnan(ds["cost_heating_energy"].sel(measure="dehumidifier")).all()
    assert ds["twpi_measure"].dims == ("measure", "case", "draw")
    import pandas as pd

    csv = pd.read_csv(p.paths["csv"])  # the measures' rows follow doing nothing's
    assert list(dict.fromkeys(csv["measure"])) == ["do nothing", *iv]
    row = csv[(csv.measure == "conservation heating") & (csv.indicator == "twpi")
              & (csv.case == "warm 2050")].iloc[0]  # fmt: skip
    d = ch["indicators"]["twpi"]
    assert row["change_vs"] == "do nothing"
    assert row["p_better"] == pytest.approx(d["p_better"], rel=1e-5)
    assert row["change_q50"] == pytest.approx(d["q50"], rel=1e-5)  # the CSV keeps 6 digits
    tw = ds["twpi_measure"].sel(measure="conservation heating", case="warm 2050")
    assert row["q50"] == pytest.approx(float(tw.median()), rel=1e-5)
    cost = csv[(csv.indicator == "cost_heating_energy") & (csv.case == "warm 2050")]
    assert list(cost["measure"]) == ["conservation heating"]
    assert cost["q50"].iloc[0] == pytest.approx(ch["costs"]["heating_energy"]["q50"], rel=1e-5)
    assert set(csv[csv.measure == "do nothing"]["change_vs"].dropna()) == {"baseline"}
    html = Path(p.paths["html"]).read_text(encoding="utf-8")
    assert 'id="interventions"' in html
    assert "id='fig-tradeoff'" in html
    assert "priors" in html  # the absolute scale is said to come from the priors


def test_shipped_interventions_config_validates():
    from heritage_bayes.projection import load_projection_config

    cfg = load_projection_config(
        Path(__file__).resolve().parents[1] / "configs" / "projection_interventions.yaml"
    )
    ms = measures_from_config(cfg)
    assert [m.name for m in ms] == [
        "conservation heating", "dehumidifier", "half the ventilation", "humidistat band",
        "conservation heating + dehumidifier",
    ]  # fmt: skip
    assert ms[0].heating == (0.65, -273.15, 22.0, 5000.0) and ms[2].ventilation == 0.5
    assert ms[3].humidistat[:2] == (0.4, 0.6) and ms[3].humidistat[4] == pytest.approx(0.05)
    assert ms[4].heating is not None and ms[4].dehumidifier is not None


@pytest.mark.browser
@pytest.mark.parametrize("size", [(1280, 800), (1920, 1080)])
def test_measures_section_in_headless_chromium(projected, size):
    """The measures section and its figure sit in the page; no table wider than its
    container at 1280 and 1920 px, and no word or number of a cell cut in two."""
    from heritage_bayes.report._browser import find_chromium, open_page
    from test_projection import _LAYOUT_JS

    chromium = find_chromium()
    if chromium is None:
        pytest.skip("chromium not installed: the page was not opened in a real browser")
    res = open_page(
        Path(projected.paths["html"]),
        chromium=chromium,
        width=size[0],
        height=size[1],
        extra_js=_LAYOUT_JS,
    )
    assert res.errors == [], res.errors
    assert "interventions" in res.dom["sections"]
    assert "fig-tradeoff" in res.dom["figures"]
    lay = res.dom["extra"]
    for t in lay["tables"]:
        assert t["w"] <= t["cw"] + 0.5 and t["right"] <= lay["width"], t
    for d in lay["scrolls"]:
        assert d["sw"] <= d["cw"], d
    assert lay["docw"] <= lay["width"] and lay["right"] <= lay["width"]
    # no cell cut mid-word or mid-number ("conservatio n heating", "[0.71 6, 0.727 ]")
    assert lay["broken"] == [], lay["broken"]


def test_measures_the_run_cannot_take_are_refused():
    """A controller on an already controlled model, ventilation without any Gfast:
    ConfigError naming the measure (hbayes project exits 2 before simulating)."""
    from types import SimpleNamespace

    import heritage_bayes as hb

    heated = SimpleNamespace(
        models={
            "thermal": hb.model("thermal_1c", thermostat=True),
            "hygric": hb.model("hygric_1c"),
        }
    )
    with pytest.raises(ConfigError, match=r"'ch'.*already controlled"):
        Measure("ch", heating=(0.6, -273.15, 20.0, np.inf)).check(heated)
    Measure("dh", dehumidifier=(0.6, 1e-4, None)).check(heated)  # the hygric one is free
    no_gfast = SimpleNamespace(models={"thermal": hb.model("thermal_1c")})
    with pytest.raises(ConfigError, match=r"'air'.*Gfast"):
        Measure("air", ventilation=0.5).check(no_gfast)


REFERENCE_MEASURES = (
    Measure("ch", heating=(0.5, 5.0, 22.0, 400.0)),
    Measure("dh", dehumidifier=(0.5, 2.0 / 3600, 0.7)),
    Measure("t", thermostat=(8.0, None, None, 300.0)),
)


@pytest.mark.parametrize("measure", REFERENCE_MEASURES, ids=lambda m: m.name)
def test_the_compiled_pass_equals_the_reference_controller(run, case, measure):
    """One controller at a time, the coupled compiled kernel (both models stepped
    together, draws over threads) gives what ``ControlledModel.forward`` against the
    other model's free-running series gives (the previous implementation): the same
    recursion in another order of summation, so equal to 1e-9 relative in every
    indicator, monthly mean and running cost of every draw."""
    draws, inputs, _ = case
    got = simulate_cases(run, draws, [inputs], seed=2, chunk=4, measure=measure)[0]
    ref = simulate_cases(run, draws, [inputs], seed=2, chunk=4, measure=measure, compiled=False)[0]
    cols = [c for c in got.predictive.columns if c != "ashrae_best_class"]
    np.testing.assert_allclose(
        got.predictive[cols].to_numpy(float), ref.predictive[cols].to_numpy(float),
        rtol=1e-9, atol=1e-9,
    )  # fmt: skip
    np.testing.assert_allclose(got.RHi_month, ref.RHi_month, rtol=1e-5)
    np.testing.assert_allclose(got.Ti_month, ref.Ti_month, rtol=1e-5)
    assert list(got.costs.columns) == list(ref.costs.columns)
    np.testing.assert_allclose(got.costs.to_numpy(), ref.costs.to_numpy(), rtol=1e-9)
    assert got.costs.to_numpy().max() > 0  # the controller acted


def _series(run, case, measure):
    """Noise-free hourly ``Ti`` [°C], ``Pi`` [Pa] and the running costs of every draw
    with ``measure`` (the compiled kernel, as the projection steps it)."""
    from heritage_bayes.projection import engine

    draws, inputs, _ = case
    P = measure.params(run, draws.model)
    c = engine.Case(*[None] * 8)
    c.U = {s: inputs[list(m.input_names)].to_numpy(float) for s, m in run.models.items()}
    c.Ut = {s: np.ascontiguousarray(u.T) for s, u in c.U.items()}
    c.N = len(inputs)
    modal = {s: engine._modal_form(m, P[s], 3600.0, free=True) for s, m in run.models.items()}
    k = len(draws.index)
    ctrl = measure.controller_arrays(k, modal, run, P)
    cost = np.zeros((k, 6))
    Y = engine._coupled_series(c, modal, ctrl, np.zeros(c.N), range(k), 720, cost)
    return Y["thermal"], Y["hygric"], measure.costs(cost, 3600.0, 1.0)


def test_humidistat_band_holds_the_band_with_hysteresis(run, case):
    """A band of unlimited capacity: at the end of every hour the vapour pressure lies
    within the band at the sensed temperature (to 1e-9); with a 5 % RH differential
    the dehumidifier runs on to rh_max - 5 % (hours that end exactly there) and, the
    room kept drier on average, removes more water than a modulating unit (differential
    0) in every draw."""
    from heritage_bayes.climate.psychro import saturation_vapour_pressure as ps

    band = (0.40, 0.55, np.inf, np.inf)  # rh_min, rh_max [-], capacities [kg/s]: ideal
    T, P, c0 = _series(run, case, Measure("b0", humidistat=(*band, 0.0, None, 0.75)))
    s = ps(T[:, :-1])
    assert np.all(P[:, 1:] <= 0.55 * s * (1 + 1e-9))
    assert np.all(P[:, 1:] >= 0.40 * s * (1 - 1e-9))
    assert np.all(c0["water_removed"] > 0) and np.all(c0["water_added"] > 0)
    np.testing.assert_allclose(c0["humidifier_energy"], 0.75 * c0["water_added"])
    assert "dehumidifier_energy" not in c0  # no energy per kg given
    T5, P5, c5 = _series(run, case, Measure("b5", humidistat=(*band, 0.05, None, None)))
    np.testing.assert_array_equal(T5, T)  # a humidistat does not touch the temperature
    at_off = np.isclose(P5[:, 1:], 0.50 * s, rtol=1e-9, atol=0)
    assert np.all(at_off.sum(axis=1) > 0)
    assert np.all(P5[:, 1:] <= 0.55 * s * (1 + 1e-9))
    assert np.all(c5["water_removed"] > c0["water_removed"])


def test_humidifier_only_band_raises_a_dry_room(run, case):
    """A band above the room's RH with a humidifier only: the monthly RH rises in every
    draw, water is added, none removed, the temperature untouched."""
    _, _, nothing = case
    lo = min(95.0, float(np.nanmax(nothing.RHi_month)) + 5.0) / 100
    wet = _with(run, case, Measure("hum", humidistat=(lo, 0.99, 0.0, 1.0, 0.0, None, None)))
    assert np.all(wet.RHi_month.mean(axis=1) > nothing.RHi_month.mean(axis=1))
    assert np.all(wet.costs["water_added"] > 0)
    assert "water_removed" not in wet.costs.columns
    np.testing.assert_allclose(wet.Ti_month, nothing.Ti_month, rtol=1e-5)


def test_conservation_heating_with_a_dehumidifier_is_one_coupled_room(run, case):
    """Conservation heating to 60 % with a dehumidifier at 50 %, stepped together: the
    dehumidifier lowers the vapour pressure the heating reads, so the pair heats less
    than conservation heating alone in every draw and is never warmer in any hour; the
    heating's warmer air holds more vapour at the dehumidifier's limit, so the vapour
    pressure is never below the dehumidifier's alone (to 1e-9: the controllers are
    monotone in what they read, the RC networks positive systems); the monthly RH below
    conservation heating alone in every draw."""
    ch = (0.60, -273.15, 25.0, np.inf)
    dh = (0.50, 1.0 / 3600, None)
    both = _with(run, case, Measure("both", heating=ch, dehumidifier=dh))
    heat = _with(run, case, Measure("ch", heating=ch))
    assert np.all(both.costs["heating_energy"] < heat.costs["heating_energy"])
    assert np.all(both.RHi_month.mean(axis=1) < heat.RHi_month.mean(axis=1))
    Tb, Pb, _ = _series(run, case, Measure("both", heating=ch, dehumidifier=dh))
    Th, Ph, _ = _series(run, case, Measure("ch", heating=ch))
    Td, Pd, _ = _series(run, case, Measure("dh", dehumidifier=dh))
    assert np.all(Tb <= Th + 1e-9) and np.any(Tb < Th - 1e-3)
    assert np.all(Tb >= Td - 1e-9)  # Td: free-running (a dehumidifier does not heat)
    # (to 1e-9 of the magnitude: some draws of this fixture's run go below 0 Pa, where
    # a factor (1 - 1e-9) would move the bound the other way)
    assert np.all(Pb >= Pd - 1e-9 * np.abs(Pd)) and np.all(Pb <= Ph + 1e-9 * np.abs(Ph))


def test_a_calibrated_constant_source_stays_with_the_measure(run, case):
    """A thermal model with a constant heat gain (``options.source``, as Ørholm's) is
    free-running: a measure may add a thermostat. One that never acts (set-point
    -100 °C) gives doing nothing's indicators (``ControlledModel.forward`` with the
    source) to 1e-9 in every draw: the source's forcing and steady state are carried
    into the compiled pass; a set-point of 15 °C heats (the same noise draw added: no
    month colder, the coldest warmer by more than 1 K)."""
    from types import SimpleNamespace

    import heritage_bayes as hb
    from heritage_bayes.projection.engine import Draws

    draws, inputs, _ = case
    th = hb.model("thermal_1c", source=True)
    src = SimpleNamespace(
        models={"thermal": th, "hygric": run.models["hygric"]}, summary=run.summary,
        run_summary=run.run_summary, path=run.path,
    )  # fmt: skip
    P = np.column_stack([draws.model["thermal"], np.full(len(draws.index), 300.0)])  # Qs [W]
    assert th.parameter_names[-1] == "Qs"
    d = Draws(draws.index, {**draws.model, "thermal": P}, draws.noise, draws.noise_models)
    nothing = simulate_cases(src, d, [inputs], seed=2, chunk=4)[0]
    never = Measure("off", thermostat=(-100.0, None, None, np.inf))
    off = simulate_cases(src, d, [inputs], seed=2, chunk=4, measure=never)[0]
    cols = [c for c in nothing.predictive.columns if c != "ashrae_best_class"]
    np.testing.assert_allclose(
        off.predictive[cols].to_numpy(float), nothing.predictive[cols].to_numpy(float),
        rtol=1e-9, atol=1e-9,
    )  # fmt: skip
    assert np.all(off.costs["heating_energy"] == 0)
    heat = Measure("on", thermostat=(15.0, None, None, np.inf))
    warm = simulate_cases(src, d, [inputs], seed=2, chunk=4, measure=heat)[0]
    # the same noise draw: a thermostat never cools a month, and warms the cold ones
    assert np.all(warm.Ti_month >= nothing.Ti_month - 1e-4)
    assert np.all(warm.Ti_month.min(axis=1) > nothing.Ti_month.min(axis=1) + 1.0)
    assert np.all(warm.costs["heating_energy"] > 0)


def test_one_pass_pairs_measures_with_the_same_doing_nothing(run, case):
    """``simulate_measures`` (what ``hbayes project`` runs): its doing nothing is
    ``simulate_cases``' to the bit, a measure that changes nothing gives it in every
    draw, and a controlled measure gives what its own pass gives (the same noise)."""
    from heritage_bayes.projection.engine import simulate_measures

    draws, inputs, nothing = case
    same = Measure("same", ventilation=1.0)
    dry = Measure("dh", dehumidifier=(0.5, 2.0 / 3600, None))
    got, per = simulate_measures(run, draws, [inputs], [same, dry], seed=2, chunk=4)
    cols = [c for c in nothing.predictive.columns if c != "ashrae_best_class"]
    ref = nothing.predictive[cols].to_numpy(float)
    np.testing.assert_array_equal(got[0].predictive[cols].to_numpy(float), ref)
    np.testing.assert_array_equal(got[0].parametric[cols].to_numpy(float),
                                  nothing.parametric[cols].to_numpy(float))  # fmt: skip
    np.testing.assert_array_equal(per["same"][0].predictive[cols].to_numpy(float), ref)
    alone = _with(run, case, dry)
    np.testing.assert_array_equal(
        per["dh"][0].predictive[cols].to_numpy(float), alone.predictive[cols].to_numpy(float)
    )
    np.testing.assert_array_equal(per["dh"][0].costs.to_numpy(), alone.costs.to_numpy())


def _quantiles(x):
    return np.quantile(np.asarray(x, float), [0.05, 0.5, 0.95])


def test_decision_table_ranks_measures_and_totals_their_energy(projected):
    """The decision table of projection.json against the per-draw arrays of the
    dataset, recomputed here: the paired change of the ranking risk (default: hours
    above LIM0, mould) at the warmest future with P(better), ranked best first; one
    total energy per draw (heat + electricity) and, with the tariffs, cost and CO2."""
    import json

    p = projected
    dec = json.loads(Path(p.paths["json"]).read_text())["decision"]
    assert dec["case"] == "warm 2050" and dec["rank_by"] == "hours_above_LIM0"
    ds = p.dataset.sel(case="warm 2050")
    improvement = {}
    for row in dec["measures"]:
        m = ds.sel(measure=row["name"])
        d = (m["hours_above_LIM0_measure"] - ds["hours_above_LIM0"]).values.astype(float)
        q = _quantiles(d)
        np.testing.assert_allclose(
            [row["change"][k] for k in ("q05", "q50", "q95")], q, rtol=1e-4, atol=1e-3
        )  # fmt: skip  (float32 in the file)
        assert row["change"]["p_better"] == pytest.approx(np.mean(d < 0))
        improvement[row["name"]] = -q[1]
        heat = np.nan_to_num(m["cost_heating_energy"].values.astype(float))
        elec = sum(np.nan_to_num(m[f"cost_{c}_energy"].values.astype(float))
                   for c in ("dehumidifier", "humidifier") if f"cost_{c}_energy" in m)  # fmt: skip
        total = heat + elec
        np.testing.assert_allclose([row["energy_kwh"][k] for k in ("q05", "q50", "q95")],
                                   _quantiles(total), rtol=1e-4, atol=1e-3)  # fmt: skip
        np.testing.assert_allclose(row["cost_eur"]["q50"], np.median(0.12 * heat + 0.3 * elec),
                                   rtol=1e-4, atol=1e-4)  # fmt: skip
        np.testing.assert_allclose(row["co2_kg"]["q50"], np.median(0.2 * heat + 0.4 * elec),
                                   rtol=1e-4, atol=1e-4)  # fmt: skip
    names = [r["name"] for r in dec["measures"]]
    assert set(names) == {"conservation heating", "dehumidifier", "half ventilation"}
    assert [improvement[n] for n in names] == sorted(improvement.values(), reverse=True)
    # the page: the decision table opens the section, in the same order
    html = Path(p.paths["html"]).read_text(encoding="utf-8")
    sec = html[html.index('id="interventions"') :]
    table = sec[
        sec.index("id='decision-table'") : sec.index("</table>", sec.index("decision-table"))
    ]
    assert sec.index("decision-table") < sec.index("Every case and indicator")
    assert [table.index(f"{i}. {n}") for i, n in enumerate(names, 1)] == sorted(
        table.index(f"{i}. {n}") for i, n in enumerate(names, 1)
    )
    assert "cost [EUR/a]" in table and "CO₂ [kg/a]" in table


def test_tradeoff_figure_has_one_labelled_marker_per_measure(projected, monkeypatch):
    from heritage_bayes.projection import interventions_page
    from heritage_bayes.projection.page import KEY_INDICATORS

    figs = []
    monkeypatch.setattr(interventions_page, "to_png_uri", lambda fig: figs.append(fig) or "x")
    interventions_page.fig_tradeoff(projected, KEY_INDICATORS)
    (fig,) = figs
    # each label: the measure's rank in the decision table and its name
    ranked = projected.summary["decision"]["measures"]
    names = sorted(f"{i}. {m['name']}" for i, m in enumerate(ranked, 1))
    assert len(names) == len(projected.summary["interventions"])
    for ax in fig.axes:
        assert len(ax.containers) == len(names)  # one errorbar (marker) per measure
        assert sorted(t.get_text() for t in ax.texts) == names
    assert not fig.legends and all(ax.get_legend() is None for ax in fig.axes)


def test_rank_by_and_tariffs_are_validated(run):
    bad = [
        ({"tariffs": {"electricity_eur_per_kwh": -1, "heat_eur_per_kwh": 0.1}},
         "electricity_eur_per_kwh"),
        ({"tariffs": {"electricity_eur_per_kwh": 0.3, "heat_eur_per_kwh": 0.1,
                      "heat_co2_kg_per_kwh": 0.2}}, "both"),
        ({"tariffs": {"electricity_eur_per_kwh": 0.3}}, "heat_eur_per_kwh"),
    ]  # fmt: skip
    for extra, needle in bad:
        with pytest.raises(ConfigError, match=needle):
            parse_projection_config({**PROJ, **extra})
    # refused before anything is simulated: an unknown name, an indicator without a
    # direction (the EN 15757 band's offset: neither higher nor lower is worse)
    for name, needle in (("mould", "unknown indicator"), ("en15757_upper_offset", "direction")):
        with pytest.raises(ConfigError, match=needle):
            project(run, {**PROJ, "interventions_rank_by": name}, write=False)


def test_tradeoff_labels_do_not_overlap_when_measures_cluster():
    """Five measures within a few pixels of each other (the demo's cluster near zero
    energy) and one apart: every label drawn inside the axes, no two labels and no
    label and another measure's marker overlapping."""
    import itertools

    from heritage_bayes.projection.interventions_page import place_labels
    from heritage_bayes.report.figures.style import _figure

    fig = _figure(9.5, 4.4)
    ax = fig.subplots()
    pts = [(0.0, 1.0), (0.5, 1.02), (1.0, 0.98), (0.2, 1.01), (0.8, 0.99), (4000.0, 3.0)]
    texts = [f"{i + 1}. measure number {i + 1}" for i in range(len(pts))]
    for x, y in pts:
        ax.plot([x], [y], "o")
    ax.margins(x=0.25, y=0.15)
    labels = place_labels(ax, pts, texts, ["k"] * len(pts))
    fig.draw_without_rendering()
    r = fig.canvas.get_renderer()
    from matplotlib.text import Text

    boxes = [Text.get_window_extent(a, r) for a in labels]  # the text, not its leader
    frame = ax.get_window_extent(r)
    for b in boxes:
        assert frame.x0 - 1 <= b.x0 and b.x1 <= frame.x1 + 1, (b, frame)
        assert frame.y0 - 1 <= b.y0 and b.y1 <= frame.y1 + 1, (b, frame)
    for a, b in itertools.combinations(boxes, 2):
        assert not a.overlaps(b), (a, b)
    px = [ax.transData.transform(p) for p in pts]
    for i, b in enumerate(boxes):
        for j, (x, y) in enumerate(px):
            if i != j:
                assert not (b.x0 < x < b.x1 and b.y0 < y < b.y1), (texts[i], j)


@pytest.mark.browser
def test_measures_section_on_a_phone_has_no_horizontal_scroll(projected):
    """At 390 px the page with its measures section (decision table, trade-off figure,
    per-case tables) is no wider than the screen, and no cell cuts a word or number."""
    from _browser_checks import phone_layout

    lay = phone_layout(Path(projected.paths["html"]), extra="""
      (() => { const s = document.getElementById('interventions');
               return s ? s.getBoundingClientRect().right : null; })()""")  # fmt: skip
    assert lay["extra"] is not None and lay["extra"] <= lay["W"]
    assert lay["broken"] == [], lay["broken"]
