"""Controlled rooms (heritage_bayes.rc.control): thermostat, humidistat, sources.

- Exactness: the controlled recursion equals the linear model driven by the control
  flow it chose (ZOH, to rounding), and an ideal thermostat holds the set-point.
- Recovery: on synthetic data with known set-point, power limit and humidistat band,
  the MAP lies within 5 standard errors (from the numerical Hessian of the
  log-likelihood at the MAP) of the truth.
- Options: catalogue/YAML options, errors, switching control off, identifiability notes.
"""

import numpy as np
import pytest

import heritage_bayes as hb
from heritage_bayes.climate.psychro import saturation_vapour_pressure
from heritage_bayes.config import prior_specs
from heritage_bayes.inference.likelihoods import get_noise_model
from heritage_bayes.inference.optimize import find_map
from heritage_bayes.inference.parameters import parameters_for
from heritage_bayes.inference.posterior import LogPosterior
from heritage_bayes.rc.identify import structural_identifiability

DT = 3600.0
NET_T = dict(Cw=4e8, Ci=4e6, Gw=300.0, Gi=600.0, Gfast=150.0)
NET_H = dict(Cw=2e-2, Ci=2e-4, Gw=5e-9, Gi=4e-8, Gfast=3e-8)


def _weather(N, seed=0):
    rng = np.random.default_rng(seed)
    t = np.arange(N)
    te = 4 + 6 * np.sin(2 * np.pi * (t - 2000) / 8760) + 3 * np.sin(2 * np.pi * (t - 14) / 24)
    te = te + np.cumsum(rng.normal(0, 0.3, N)) * 0.2
    return te, rng


def test_thermostat_exact_zoh_and_holds_setpoint():
    N = 24 * 60
    te, _ = _weather(N)
    m = hb.model("thermal_2c", surfaces=(), ground=False, thermostat={"power_limit": True})
    assert m.parameter_names == (*NET_T, "Tset", "Pmax")
    p = dict(NET_T, Tset=12.0, Pmax=5000.0)
    P, _ = m.param_array(p)
    x0 = np.array([6.0, 8.0])
    Y, valid, Q = m.forward(P, te[:, None], DT, x0=x0, effort=True)
    assert valid.all() and Q.min() >= 0 and Q.max() == pytest.approx(5000.0)
    # the linear model with the chosen power as a known input reproduces it exactly
    mh = hb.model("thermal_2c", surfaces=(), ground=False, heating=True)
    yl = hb.simulate(mh, NET_T, np.column_stack([te, Q[0]]), x0=x0)
    np.testing.assert_allclose(Y[0, :, 0], yl[:, 0], rtol=0, atol=1e-9)
    # power below the limit: the air ends the step exactly at the set-point
    k = np.flatnonzero((Q[0, :-1] > 0) & (Q[0, :-1] < 5000.0))
    assert k.size > 10
    np.testing.assert_allclose(Y[0, k + 1, 0], 12.0, atol=1e-9)
    # an ideal thermostat never lets the air below the set-point (after the start)
    mi = hb.model("thermal_2c", surfaces=(), ground=False, thermostat=True)
    yi = hb.simulate(mi, dict(NET_T, Tset=12.0), te[:, None], x0=x0)
    assert yi[1:, 0].min() >= 12.0 - 1e-9
    free = hb.simulate(hb.model("thermal_2c", surfaces=(), ground=False), NET_T, te[:, None])
    assert free[:, 0].min() < 10.0  # the control matters in this weather


def test_switching_control_off_gives_the_free_running_room():
    N = 24 * 30
    te, _ = _weather(N)
    m = hb.model("thermal_2c", surfaces=(), ground=False, thermostat=True, source=True)
    p = dict(NET_T, Tset=14.0, Qs=300.0)
    off = m.with_control(False)
    assert off.parameter_names == m.parameter_names
    free = hb.simulate(hb.model("thermal_2c", surfaces=(), ground=False), NET_T, te[:, None])
    np.testing.assert_allclose(hb.simulate(off, p, te[:, None]), free, atol=1e-9)
    # the source alone: the linear model with a constant heating input
    src = m.with_control({"thermostat": False})
    mh = hb.model("thermal_2c", surfaces=(), ground=False, heating=True)
    ref = hb.simulate(mh, NET_T, np.column_stack([te, np.full(N, 300.0)]))
    np.testing.assert_allclose(hb.simulate(src, p, te[:, None]), ref, atol=1e-9)
    with pytest.raises(ValueError, match="unknown component"):
        m.with_control({"dehumidifier": False})


def _se(lp, theta, names):
    """Standard errors of ``names`` (Gauss-Newton: Fisher information J^T J / sigma^2 of
    the simulated output's sensitivities, central differences)."""
    idx = [lp.params.names.index(n) for n in names]
    sigma = theta[lp.params.names.index("sigma_" + lp.model.output_names[0])]
    ok = np.isfinite(lp.observed[:, 0])
    cols = []
    for i in idx:
        h = 1e-4 * max(abs(theta[i]), 1e-6)
        tp, tm = theta.copy(), theta.copy()
        tp[i] += h
        tm[i] -= h
        Y, _ = lp.simulate(np.stack([tp, tm])[:, : lp.n_model])
        cols.append((Y[0, ok, 0] - Y[1, ok, 0]) / (2 * h))
    J = np.column_stack(cols)
    return np.sqrt(np.diag(np.linalg.inv(J.T @ J / sigma**2)))


def _fit(m, truth, U, y, free, seed):
    noise = get_noise_model("iid")
    priors = prior_specs({k: {"fixed": v} for k, v in truth.items() if k not in free})
    ps = parameters_for(m, noise, priors)
    lp = LogPosterior(m, ps, noise, U, y[:, None], warmup=48, init_window=1)
    mp = find_map(lp, seed=seed, maxiter=100, starts=2)
    return lp, mp.theta


def test_recovers_setpoint_and_power_limit():
    N = 24 * 90
    te, rng = _weather(N, seed=3)
    m = hb.model("thermal_2c", surfaces=(), ground=False, thermostat={"power_limit": True})
    truth = dict(NET_T, Tset=11.5, Pmax=2200.0)
    sd = 0.1
    y = hb.simulate(m, truth, te[:, None])[:, 0] + rng.normal(0, sd, N)
    lp, th = _fit(m, truth, te[:, None], y, ("Tset", "Pmax", "Gfast"), seed=1)
    names = ("Tset", "Pmax", "Gfast")
    se = _se(lp, th, names)
    for n, s in zip(names, se, strict=True):
        est = th[lp.params.names.index(n)]
        assert abs(est - truth[n]) < 5 * s, (n, est, truth[n], s)
    assert se[0] < 0.05 and se[1] / truth["Pmax"] < 0.05  # informative data


def test_recovers_humidistat_band_and_capacity():
    N = 24 * 90
    te, rng = _weather(N, seed=5)
    ti = 12 + 0.6 * (te - 4)  # indoor temperature [°C] (given, as in calibration)
    pe = 0.8 * saturation_vapour_pressure(te) + 150 * np.sin(np.arange(N) / 97.0)
    m = hb.model("hygric_2c", humidistat={"mode": "band", "capacity": True})
    assert m.input_names == ("Pe", "Ti")
    truth = dict(NET_H, RH_lo=0.38, RH_hi=0.46, M_dehum=5e-6, M_hum=2e-6)
    U = np.column_stack([pe, ti])
    Y, _, Q = m.forward(m.param_array(truth)[0], U, DT, effort=True)
    assert (Q < 0).mean() > 0.1 and (Q > 0).mean() > 0.05  # both sides act
    assert (Q == -5e-6).mean() > 0.05 and (Q == 2e-6).mean() > 0.05  # both capacities bind
    sd = 5.0  # [Pa]
    y = Y[0, :, 0] + rng.normal(0, sd, N)
    free = ("RH_lo", "RH_hi", "M_dehum", "M_hum")
    lp, th = _fit(m, truth, U, y, free, seed=2)
    se = _se(lp, th, free)
    for n, s in zip(free, se, strict=True):
        est = th[lp.params.names.index(n)]
        assert abs(est - truth[n]) < 5 * s, (n, est, truth[n], s)
    assert se[0] < 0.01 and se[1] < 0.01


def test_options_errors_and_identifiability_notes():
    with pytest.raises(ValueError, match="thermostat needs a thermal model"):
        hb.model("hygric_2c", thermostat=True)
    with pytest.raises(ValueError, match=r"humidistat\.mode"):
        hb.model("hygric_2c", humidistat={"mode": "sometimes"})
    with pytest.raises(ValueError, match=r"thermostat\.pmax: unknown key"):
        hb.model("thermal_2c", thermostat={"pmax": True})
    m = hb.model(
        "thermal_1c",
        surfaces=(),
        ground=False,
        thermostat={"schedule": "in_use", "conservation": True},
    )
    assert m.input_names == ("Te", "in_use", "Pi")
    assert m.parameter_names[-3:] == ("Tset", "Tset_use", "RH_ch")
    with pytest.raises(ValueError, match="RH_lo <= RH_hi"):
        hb.simulate(
            hb.model("hygric_1c", humidistat="band"),
            dict(Ci=1e-3, Gfast=1e-8, RH_lo=0.6, RH_hi=0.5),
            np.full((5, 2), 800.0),
        )
    ms = hb.model("hygric_2c", humidistat="dehumidifier", source=True)
    r = structural_identifiability(ms, dict(NET_H, RH_hi=0.55, Ms=1e-5), DT)
    assert set(r.control) == {"RH_hi", "Ms"}
    assert "overall-scale" in r.control["Ms"] and "hours in which" in r.control["RH_hi"]
    assert r.has_scale_direction  # the network part is still free-running


def test_the_rc_catalogue_takes_typed_options_only():
    """Below the settings nothing parses: ``rc.model`` takes a typed ``Control`` and the
    network's keywords, and refuses a control keyword or one the model cannot have."""
    from heritage_bayes.rc import Control
    from heritage_bayes.rc import model as rc_model

    m = rc_model("thermal_2c", Control(thermostat=True, power_limit=True), ground=False)
    assert m.parameter_names[-2:] == ("Tset", "Pmax")
    assert (
        m.parameter_names
        == hb.model("thermal_2c", ground=False, thermostat={"power_limit": True}).parameter_names
    )
    with pytest.raises(ValueError, match=r"unknown option\(s\) \['thermostat'\]"):
        rc_model("thermal_2c", thermostat=True)
    with pytest.raises(ValueError, match="a thermostat needs a thermal model"):
        rc_model("hygric_2c", Control(thermostat=True))
    with pytest.raises(ValueError, match="not available for a thermo-hygric coupled model"):
        rc_model("hygric_2c_sorption", Control(source=True))
    with pytest.raises(ValueError, match=r"Control\.humidistat: expected one of"):
        Control(humidistat="sometimes")


def test_schedule_and_conservation_heating():
    N = 24 * 40
    te, _ = _weather(N)
    use = ((np.arange(N) % 168) // 24 == 6) & ((np.arange(N) % 24 >= 8) & (np.arange(N) % 24 < 12))
    pv = np.full(N, 900.0)  # vapour pressure [Pa]
    m = hb.model(
        "thermal_2c",
        surfaces=(),
        ground=False,
        thermostat={"schedule": "in_use", "conservation": True},
    )
    p = dict(NET_T, Tset=5.0, Tset_use=18.0, RH_ch=0.6)
    U = np.column_stack([te, use.astype(float), pv])
    y = hb.simulate(m, p, U)[:, 0]
    # conservation heating: RH at the simulated temperature never above 60 %
    rh = pv[1:] / saturation_vapour_pressure(y[1:])
    assert rh.max() <= 0.6 + 2e-3  # Magnus inverse vs IAPWS: within 0.1 K
    # in the hours of use the service set-point holds (ideal heating)
    k = np.flatnonzero(use[:-1])
    assert y[k + 1].min() >= 18.0 - 1e-9


@pytest.mark.parametrize("name", ["orholm", "annisse"])
def test_case_study_configs_build_controlled_models(name):
    from pathlib import Path

    from heritage_bayes.calibration.calibrate import check_models
    from heritage_bayes.config import load_config
    from heritage_bayes.models import build_model

    cfg = load_config(Path(__file__).resolve().parents[1] / "configs" / f"{name}.yaml")
    check_models(cfg)  # models and priors build without data
    th = build_model(cfg, "thermal")
    assert "Tset" in th.parameter_names and "Qs" in th.parameter_names
    assert th.with_control(False).control.enabled == frozenset()


def test_derived_quantities_of_a_controlled_model_are_the_networks():
    """A humidistat adds the input Ti, which is not a column of the linear network's B:
    the static gains are those of the free-running network (configs/orholm.yaml)."""
    from heritage_bayes.rc.catalog import model
    from heritage_bayes.rc.control_spec import Control
    from heritage_bayes.rc.derived import derived_quantities, derived_units

    m = model("hygric_2c", Control(humidistat="band"))
    assert m.input_names == ("Pe", "Ti")
    p = dict(Cw=0.5, Ci=0.03, Gw=2e-8, Gi=1e-6, Gfast=4.2e-7, RH_lo=0.4, RH_hi=0.6)
    d = derived_quantities(m, p)
    assert set(d) == set(derived_units(m)) == {"tau_1_h", "tau_2_h", "gain_Pi_Pe"}
    free = derived_quantities(model("hygric_2c"), {k: v for k, v in p.items() if "RH" not in k})
    assert d["gain_Pi_Pe"] == pytest.approx(free["gain_Pi_Pe"]) and d["gain_Pi_Pe"] > 0.99


# ---------------------------------------------------------------------------------------
# weekly hours of use (heritage_bayes.rc.calendar)
# ---------------------------------------------------------------------------------------


def test_weekly_calendar_fractions_are_exact():
    import pandas as pd

    from heritage_bayes.rc.calendar import parse_weekly

    cal = parse_weekly({"weekly": ["Sun 08:30-10", "Mon-Fri 23-24", "Sat,Sun 14-15"]})
    assert cal.hours_per_week == pytest.approx(1.5 + 5 + 2)
    idx = pd.date_range("2024-01-07 07:00", periods=4, freq="1h", tz="UTC")  # a Sunday
    np.testing.assert_allclose(cal.fraction(idx, 3600.0), [0.0, 0.5, 1.0, 0.0], atol=1e-12)
    # any step: the integral over whole weeks is the hours of use (10-min and 7-h steps)
    for freq, dt in (("10min", 600.0), ("7h", 25200.0)):
        idx = pd.date_range("2024-01-01", periods=int(2 * 7 * 86400 / dt), freq=freq, tz="UTC")
        assert cal.fraction(idx, dt).sum() * dt / 3600 == pytest.approx(2 * cal.hours_per_week)
    # the local clock: fixed offset vs daylight-saving time
    sun = parse_weekly({"weekly": ["Sun 10-11"], "timezone": "Europe/Copenhagen"})
    win = pd.DatetimeIndex(["2024-01-07 09:00"], tz="UTC")  # 10:00 CET
    summ = pd.DatetimeIndex(["2024-07-07 08:00"], tz="UTC")  # 10:00 CEST
    assert sun.fraction(win, 3600.0)[0] == 1.0 and sun.fraction(summ, 3600.0)[0] == 1.0
    fixed = parse_weekly({"weekly": ["Sun 10-11"], "timezone": "UTC+1"})
    assert fixed.fraction(summ, 3600.0)[0] == 0.0
    for bad, match in (
        ({"weekly": ["Sun 12-08"]}, r"weekly\[0\].*not after the start"),
        ({"weekly": ["Sunday 8-12"]}, r"weekly\[0\].*not 'DAYS"),
        ({"weekly": ["Sun 8-12", "Xyz 1-2"]}, r"weekly\[1\].*unknown day 'Xyz'"),
        ({"weekly": ["Sun 8-25"]}, r"00:00-24:00"),
        ({"weekly": []}, r"weekly: expected a list"),
        ({"weekly": ["Sun 8-12"], "clock": "UTC"}, r"unknown key\(s\) \['clock'\]"),
        ({"weekly": ["Sun 8-12"], "timezone": "Mars/Olympus"}, r"timezone: unknown timezone"),
    ):
        with pytest.raises(ValueError, match=match):
            parse_weekly(bad, "thermostat.schedule")


def test_recovers_service_setpoint_of_a_weekly_schedule():
    """A church heated to Tset_use on Sunday mornings (local UTC+1 clock), Tset otherwise,
    with a power limit: the set-points and the power are recovered from 90 days (MAP
    within 5 standard errors of the truth, as above)."""
    import pandas as pd

    from heritage_bayes.inputs import calendar_inputs

    N = 24 * 90
    te, rng = _weather(N, seed=7)
    opts = {"power_limit": True, "schedule": {"weekly": ["Sun 08-12"], "timezone": "UTC+1"}}
    m = hb.model("thermal_2c", surfaces=(), ground=False, thermostat=opts)
    assert m.input_names == ("Te", "hours_of_use")
    idx = pd.date_range("2016-01-04", periods=N, freq="1h", tz="UTC")  # a Monday
    use = calendar_inputs([m], idx, DT)["hours_of_use"]
    assert use.sum() == 4 * 12 and use[24 * 6 + 7 : 24 * 6 + 11].min() == 1.0  # 08-12 UTC+1
    truth = dict(NET_T, Tset=10.0, Tset_use=14.0, Pmax=9000.0)
    U = np.column_stack([te, use])
    Y, _, Q = m.forward(m.param_array(truth)[0], U, DT, effort=True)
    k = np.flatnonzero(use[:-1] > 0)
    # informative data: in the hours of use the heating is either at its limit (the
    # warm-up) or holds the service set-point
    limited = Q[0, k] == 9000.0
    held = np.abs(Y[0, k + 1, 0] - 14.0) < 1e-9
    assert 0.2 < limited.mean() < 0.8 and (limited | held).all()
    sd = 0.1
    y = Y[0, :, 0] + rng.normal(0, sd, N)
    free = ("Tset", "Tset_use", "Pmax")
    lp, th = _fit(m, truth, U, y, free, seed=3)
    se = _se(lp, th, free)
    for n, s in zip(free, se, strict=True):
        est = th[lp.params.names.index(n)]
        assert abs(est - truth[n]) < 5 * s, (n, est, truth[n], s)
    assert se[0] < 0.01 and se[1] < 0.1 and se[2] / truth["Pmax"] < 0.01


def test_weekly_schedule_from_a_config_builds_its_input_and_names_key_paths():
    from heritage_bayes.config import parse_config
    from heritage_bayes.errors import ConfigError
    from heritage_bayes.models import build_model
    from heritage_bayes.prepare import prepare

    def cfg(schedule):
        return parse_config(
            {
                "data": {"demo": {}},
                "thermal": {
                    "model": "thermal_2c",
                    "options": {"ground": False, "thermostat": {"schedule": schedule}},
                },
                "periods": {
                    "calibration": {"start": "2019-01-02", "end": "2019-01-20"},
                    "validation": {"start": "2019-01-20", "end": "2019-01-27"},
                },
            }
        )

    prep = prepare(cfg({"weekly": ["Sun 09-12"], "timezone": "Europe/Amsterdam"}))
    use = prep.frame["hours_of_use"]
    sundays = use[use > 0].index.tz_convert("Europe/Amsterdam")
    assert set(sundays.day_name()) == {"Sunday"} and set(sundays.hour) == {9, 10, 11}
    assert prep.sources["calendar"]["hours_of_use"]["hours_per_week"] == 3.0
    m = build_model(cfg({"weekly": ["Sun 09-12"]}), "thermal")
    assert m.input_names[-1] == "hours_of_use"
    np.testing.assert_array_equal(prep.model_inputs("thermal", m)[:, -1], use.to_numpy())
    with pytest.raises(
        ConfigError, match=r"\n  thermal\.options\.thermostat\.schedule\.weekly\[0\]"
    ):
        cfg({"weekly": ["Sun 9-"]})  # refused when the config is loaded
