"""The noise-model comparison of benchmarks/noise_default.py (the evidence behind the
default noise model, docs/science/noise.md): its config variants are valid configs with
the noise parameters renamed, and its rows read a run's ``summary.json`` as the report does.
"""

from __future__ import annotations

import sys
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT / "benchmarks"))

noise_default = pytest.importorskip("noise_default")

from heritage_bayes.calibration.calibrate import check_models  # noqa: E402
from heritage_bayes.config import load_config  # noqa: E402


def test_priors_follow_the_noise_model():
    priors = {
        "Ci": {"fixed": 1e6},
        "sigma_meas_Ti": {"fixed": 0.003},
        "phi_Ti": {"upper": 0.96},
        "sigma_Ti": {"upper": 2.0},
        "q_Tw": {"fixed": 1e-4},
    }
    kal = noise_default.translate_priors(priors, ["Ti"], "kalman")
    # ar1_white's reading noise is kalman's measurement noise; the AR part has no twin
    assert kal == {"Ci": {"fixed": 1e6}, "sigma_Ti": {"fixed": 0.003}, "q_Tw": {"fixed": 1e-4}}
    ar1w = noise_default.translate_priors(priors, ["Ti"], "ar1_white")
    assert "q_Tw" not in ar1w and ar1w["sigma_meas_Ti"] == {"fixed": 0.003}


def test_variants_of_the_shipped_configs_are_valid(shared_data):
    trh1 = load_config(ROOT / "configs" / "trh1_attic.yaml")
    kal = noise_default.variant(trh1, "kalman", None)
    assert (kal.thermal.noise, kal.hygric.noise, kal.ladder) == ("kalman", "kalman", False)
    assert {k: v.model_dump(exclude_none=True) for k, v in kal.thermal.priors.items()} == {
        "sigma_Ti": {"fixed": 0.003}
    }
    check_models(kal)  # every prior key names a parameter of the kalman model
    # and back: kalman's sigma_<out> becomes ar1_white's reading noise
    back = noise_default.variant(kal, "ar1_white", None)
    assert back.thermal.priors == trh1.thermal.priors
    check_models(back)

    arm = load_config(ROOT / "configs" / "armadillo.yaml")
    a = noise_default.variant(arm, "ar1_white", None, "2020-01-04 00:00")
    assert "q_Ti" not in a.thermal.priors
    check_models(a)
    assert (a.periods.calibration.end, a.periods.validation.start) == ("2020-01-04 00:00",) * 2
    assert a.periods.validation.end == arm.periods.calibration.end


def test_demo_variant_changes_only_the_data_seed():
    demo = load_config(ROOT / "configs" / "demo.yaml")
    v = noise_default.variant(demo, "kalman", 11)
    assert v.data.demo.seed == 11 and demo.data.demo.seed == 7
    assert v.data.demo.model_copy(update={"seed": 7}) == demo.data.demo
    assert v.seed == demo.seed  # the sampler's seed is the config's


def test_row_counts_truths_inside_and_their_distance():
    summary = {
        "converged": True,
        "max_rhat": 1.004,
        "min_ess_bulk": 900.0,
        "models": {"thermal": {"chain": {"steps": 8000, "tau_max": 133.0}}},
        "metrics": {"thermal": {"Ti": {"validation": {"FIT": 90.0, "coverage90": 0.9}}}},
        "derived": {
            "thermal.tau_1_h": {
                "truth": 104.0,
                "median": 110.0,
                "sd": 3.0,
                "q05": 105.0,
                "q95": 115.0,
            },
            "thermal.gain_Ti_Te": {
                "truth": 0.947,
                "median": 0.95,
                "sd": 0.01,
                "q05": 0.93,
                "q95": 0.97,
            },
            "thermal.tau_2_h": {"median": 0.4, "sd": 0.1, "q05": 0.2, "q95": 0.6},
        },
    }
    row = noise_default.row_of(summary)
    assert row["truths"]["thermal.tau_1_h"] == {"inside": False, "z": pytest.approx(-2.0)}
    assert row["truths"]["thermal.gain_Ti_Te"]["inside"] is True
    assert "thermal.tau_2_h" not in row["truths"]  # no truth: not counted
    assert row["metrics"]["thermal.Ti"]["FIT"] == 90.0
    assert row["chains"]["thermal"]["steps"] == 8000
