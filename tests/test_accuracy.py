"""The verdict tells the truth about accuracy: a model that does not reproduce the room
is red whatever the sampler did, and the verdict names the most likely missing physics
measured from the residuals and the model ladder."""

from __future__ import annotations

import numpy as np
import pytest

from heritage_bayes.report.accuracy import (
    DAILY_CYCLE_RATIO,
    DRIFT_RATIO,
    LADDER_MARGIN,
    MIN_COVERAGE90,
    MIN_FIT,
    NEARLY_CONSTANT_RESOLUTIONS,
    accuracy_failures,
    missing_physics,
    nearly_constant,
    residual_shape,
    resolutions,
)
from heritage_bayes.report.verdict import convergence_verdict


def _summary(fit_val=80.0, cov=0.9, fit_cal=85.0, sd=2.0, converged=True, ladder=None):
    return {
        "converged": converged,
        "converged_tau": converged,
        "max_rhat": 1.004,
        "min_ess_bulk": 1200,
        "criteria": {"max_rhat": 1.01, "min_ess_bulk": 400.0, "tau_factor": 50.0},
        "parameters": {"thermal.Ci": {"r_hat": 1.004, "ess_bulk": 1200}},
        "models": {
            "thermal": {
                "model": "thermal_1c",
                "state_names": ["Ti"],
                "input_names": ["Te", "Tf"],
                "chain": {"steps": 5000, "tau_max": 50.0, "converged_tau": converged},
            }
        },
        "metrics": {
            "thermal": {
                "Ti": {
                    "calibration": {"FIT": fit_cal, "SD": sd, "MAE": 0.3, "n": 480},
                    "validation": {"FIT": fit_val, "SD": sd, "coverage90": cov, "n": 240},
                }
            }
        },
        "ladder": ladder,
    }


def test_fit_and_coverage_thresholds_at_their_boundaries():
    ok = [{"section": "thermal", "output": "Ti", "adequate": True, "check": {}}]
    # coverage 0.9 of 240 hours: inside the binomial range, so green when accurate
    assert convergence_verdict(_summary(MIN_FIT), ok)["level"] == "green"
    v = convergence_verdict(_summary(MIN_FIT - 0.1), ok)
    assert v["level"] == "red" and v["title"] == "This model does not reproduce the room"
    assert "FIT 49.9 % on the validation period" in v["text"]
    assert "usable" not in v["text"] + v["advice"]
    assert "The sampler converged; the fault is the model" in v["text"]
    # the band: 75 % is enough for the accuracy rule (the coverage check then says amber)
    v = convergence_verdict(_summary(cov=MIN_COVERAGE90), ok)
    assert v["level"] == "amber" and not v["accuracy"]
    v = convergence_verdict(_summary(cov=MIN_COVERAGE90 - 0.001), ok)
    assert v["level"] == "red"
    assert "the 90 % band covers 74.9 % of the validation hours (at least 75 %)" in v["text"]
    # without a validation period the calibration FIT judges
    s = _summary(fit_cal=MIN_FIT - 1)
    del s["metrics"]["thermal"]["Ti"]["validation"]
    v = convergence_verdict(s, ok)
    assert v["level"] == "red" and "FIT 49.0 % on the calibration period" in v["text"]
    # not converged as well: both said in the title
    v = convergence_verdict(_summary(10.0, converged=False), ok)
    assert v["title"] == "This model does not reproduce the room — and not fully converged"


def test_nearly_constant_is_a_few_sensor_resolutions():
    res = {"Ti": 0.1}
    edge = NEARLY_CONSTANT_RESOLUTIONS * 0.1
    assert nearly_constant(edge, 0.1) and not nearly_constant(edge * 1.01, 0.1)
    assert not nearly_constant(None, 0.1) and not nearly_constant(0.3, None)
    # a nearly constant series is exempt from the FIT rule (FIT says nothing there) ...
    assert accuracy_failures(_summary(-98.0, sd=edge), res) == []
    # ... a varying one is not (the °F file read as °C: SD 10.8 K, FIT 1.2 %)
    f = accuracy_failures(_summary(1.2, sd=10.8), res)
    assert [x["fit"] for x in f] == [1.2]
    # the metrics table's note follows the same rule
    from heritage_bayes.report.sections.metrics import _nearly_constant
    from heritage_bayes.rundir.summary import FitMetrics

    def metrics(**v):
        return FitMetrics(section="thermal", output="Ti", period="validation", **v)

    bad = metrics(MAE=8.0, MSE=100.0, FIT=1.2, SD=10.8)
    assert _nearly_constant(bad, 0.1) == ""
    flat = metrics(MAE=0.4, MSE=0.25, FIT=-98.0, SD=0.3)
    assert "nearly constant" in _nearly_constant(flat, 0.1)
    assert _nearly_constant(flat, 0.05) == ""  # 0.3 K is 6 resolutions of 0.05 K


def test_vapour_pressure_resolution_is_one_percent_rh_of_saturation():
    rh = np.full(48, 50.0)
    pi = np.full(48, 852.5)  # 50 % at 15 °C: saturation 1705 Pa
    assert resolutions({"Pi": pi, "RHi": rh})["Pi"] == pytest.approx(17.05)
    assert resolutions({"Pi": pi})["Pi"] == pytest.approx(17.0)


def _hours(days):
    return np.datetime64("2019-04-01T00:00", "ns") + np.arange(24 * days) * np.timedelta64(1, "h")


def test_residual_shape_measures_daily_cycle_and_drift_at_the_thresholds():
    t = _hours(20)
    h = np.arange(t.size) % 24
    sun = np.cos(2 * np.pi * (h - 14) / 24)  # peaks at 14 h
    y = 20 + 2.0 * sun
    # a residual cycle just above DAILY_CYCLE_RATIO of the measured one: strong
    r = 1.001 * DAILY_CYCLE_RATIO * 2.0 * sun
    s = residual_shape(r, y, t, longitude=0.0, resolution=0.1)
    assert s["daily_amplitude"] == pytest.approx(DAILY_CYCLE_RATIO * 2.0, rel=0.01)
    assert s["daily"] and s["sunlit"] and s["peak_hour"] == 14 and not s["slow"]
    s = residual_shape(0.998 * r, y, t, longitude=0.0, resolution=0.1)
    assert not s["daily"]
    # below one sensor resolution a cycle is not strong, whatever the ratio
    assert not residual_shape(r, y, t, longitude=0.0, resolution=0.51)["daily"]
    # the longitude shifts UTC to solar time: 14 h UTC is 9 h at 75° W
    assert residual_shape(r, y, t, longitude=-75.0, resolution=0.1)["peak_hour"] == 9
    # drift: day means of RMS DRIFT_RATIO x the measured SD (here a steady offset)
    sd = float(np.std(y))
    step = np.full(t.size, DRIFT_RATIO * sd * 1.001)
    assert residual_shape(step, y, t)["slow"]
    assert not residual_shape(0.998 * step, y, t)["slow"]
    assert residual_shape(r[:47], y[:47], t[:47]) is None


def test_missing_physics_names_the_ladders_better_rung():
    ladder = {
        "thermal": [
            {"model": "thermal_1c", "sampled": True, "fit": {}},
            {"model": "thermal_2c", "fit": {"validation": {"Ti": {"FIT": 81.8}}}},
            {"model": "thermal_4a", "fit": {"validation": {"Ti": {"FIT": 83.0}}}},
        ]
    }
    s = _summary(2.6, ladder=ladder)
    f = accuracy_failures(s)
    words = " ".join(missing_physics(s, f, {}))
    assert "`thermal_4a` reproduces Ti with FIT 83.0 % on the validation period" in words
    assert "calibrate `thermal_4a`" in words
    # a rung better by less than the margin is not named; one still failing is not advised
    ladder["thermal"][1:] = [
        {"model": "thermal_2c", "fit": {"validation": {"Ti": {"FIT": 2.6 + LADDER_MARGIN}}}}
    ]
    words = " ".join(missing_physics(s, f, {}))
    assert "thermal_2c" in words and "still below 50 %" in words and "calibrate" not in words
    ladder["thermal"][1]["fit"]["validation"]["Ti"]["FIT"] = 2.5 + LADDER_MARGIN
    assert missing_physics(s, f, {}) == []


def test_a_model_without_sun_on_the_demo_is_red_and_named(tmp_path):
    """The virtual monument (generated with thermal_2c and measured sun) calibrated with
    one node and no solar input: red, and the advice names the missing sun from the
    residuals' daily cycle (measured: ±0.45 K, a third of the measured cycle, largest at
    14 h solar time) and the slow drift."""
    from heritage_bayes.calibration.calibrate import run_calibration
    from heritage_bayes.config import parse_config
    from heritage_bayes.report.build import build_context

    cfg = {
        "name": "no-sun",
        "seed": 3,
        "data": {"demo": {"seed": 7, "thermal_model": "thermal_2c"}, "irradiance": "none"},
        "periods": {
            "calibration": {"start": "2019-04-01", "end": "2019-04-21"},
            "validation": {"start": "2019-04-21", "end": "2019-05-01"},
        },
        "thermal": {"model": "thermal_1c"},
        "ladder": False,
        "sampler": {"max_steps": 100, "check_every": 50},
        "optimizer": {"maxiter": 15, "starts": 1, "popsize": 4},
    }
    out = tmp_path / "run"
    run_calibration(parse_config(cfg), out_dir=out, report=False, quiet=True)
    v = build_context(out)["verdict"]
    assert v["level"] == "red" and v["title"].startswith("This model does not reproduce")
    assert "usable" not in v["text"] + v["advice"]
    assert "the sun — the model has no solar input" in v["advice"]
    assert "a slow drift" in v["advice"] and "thermal_2c" in v["advice"]


def test_calibrate_warns_when_the_model_does_not_reproduce_the_room(tmp_path, capsys):
    import json

    from heritage_bayes.cli import _converged_or_3

    (tmp_path / "summary.json").write_text(json.dumps(_summary(2.6)))
    assert _converged_or_3(tmp_path) == 0  # converged: the exit code follows the sampler
    err = capsys.readouterr().err
    assert "this model does not reproduce the room: Ti (thermal): FIT 2.6 %" in err
    (tmp_path / "summary.json").write_text(json.dumps(_summary(80.0)))
    assert _converged_or_3(tmp_path) == 0 and capsys.readouterr().err == ""
