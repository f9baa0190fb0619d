"""The command line: exit codes, messages without tracebacks, a real (tiny) run."""

import json

import numpy as np
import pytest
import yaml

import heritage_bayes as hb
from heritage_bayes.cli import main
from heritage_bayes.run import load_run

TINY = {
    "name": "tiny",
    "building": "Test castle",
    "room": "Cellar",
    "seed": 3,
    "data": {"demo": {}},
    "room_volume": 400,
    "periods": {
        "calibration": {"start": "2019-01-02", "end": "2019-01-16"},
        "validation": {"start": "2019-01-16", "end": "2019-01-21"},
        "warmup": "2D",
        "init_window": "2D",
    },
    "thermal": {"model": "thermal_1c", "noise": "ar1"},
    "hygric": {"model": "hygric_1c", "noise": "ar1"},
    "sampler": {"max_steps": 400, "check_every": 200},
    "optimizer": {"maxiter": 20, "starts": 2},
    "ladder": False,
    "report": False,
}


def _write(path, cfg):
    path.write_text(yaml.safe_dump(cfg), encoding="utf-8")
    return path


def test_version_and_help(capsys):
    assert main(["--version"]) == 0
    assert hb.__version__ in capsys.readouterr().out
    assert main([]) == 2
    assert main(["models"]) == 0
    assert "thermal_4a" in capsys.readouterr().out


@pytest.mark.parametrize(
    ("mutate", "message"),
    [
        (lambda c: c.update(colour="red"), "colour: unknown key"),
        (lambda c: c["sampler"].update(max_steps=-5), "sampler.max_steps"),
        (lambda c: c["thermal"].update(model="thermal_9z"), "thermal.model: unknown model"),
        (
            lambda c: c["thermal"].update(
                priors={"Ge": {"dist": "loguniform", "lower": 500, "upper": 200}}
            ),
            r"thermal.priors.Ge.lower: must be < upper (got 500 >= 200)",
        ),
        (
            lambda c: c["thermal"].update(priors={"Gx": {"fixed": 1}}),
            "thermal.priors: unknown parameter(s) ['Gx']",
        ),
        (
            lambda c: c["periods"]["calibration"].update(start="2019-02-01"),
            "start must be before end",
        ),
    ],
)
def test_bad_configs_exit_2_with_the_key_path(tmp_path, capsys, mutate, message):
    cfg = json.loads(json.dumps(TINY))
    mutate(cfg)
    code = main(
        [
            "calibrate",
            str(_write(tmp_path / "bad.yaml", cfg)),
            "--out",
            str(tmp_path / "run"),
            "--quiet",
        ]
    )
    err = capsys.readouterr().err
    assert code == 2
    assert message in err
    assert "Traceback" not in err


def test_missing_config_and_bad_yaml_and_bad_data(tmp_path, capsys):
    assert main(["calibrate", str(tmp_path / "nope.yaml")]) == 2
    assert "config file not found" in capsys.readouterr().err
    (tmp_path / "broken.yaml").write_text("name: [unclosed\n", encoding="utf-8")
    assert main(["calibrate", str(tmp_path / "broken.yaml")]) == 2
    assert "line" in capsys.readouterr().err
    # measurements whose column is misspelt: a data error naming the key and the column
    (tmp_path / "logger.csv").write_text(
        "time,Temp\n2019-01-01 00:00,10\n2019-01-01 01:00,10.2\n", encoding="utf-8"
    )
    (tmp_path / "weather.csv").write_text(
        "time,Te\n2019-01-01 00:00,3\n2019-01-01 01:00,3.5\n", encoding="utf-8"
    )
    cfg = {k: v for k, v in TINY.items() if k not in ("data", "hygric", "periods")}
    cfg["data"] = {
        "weather": {
            "format": "csv",
            "path": "weather.csv",
            "time_column": "time",
            "timezone": "UTC",
        },
        "measurements": {
            "format": "csv",
            "path": "logger.csv",
            "time_column": "time",
            "timezone": "UTC",
            "columns": {"Ti": "TEMP"},
        },
        "irradiance": "none",
        "ground_temperature": {"mode": "constant", "value": 10},
    }
    code = main(
        [
            "calibrate",
            str(_write(tmp_path / "data.yaml", cfg)),
            "--out",
            str(tmp_path / "data_run"),
            "--quiet",
        ]
    )
    err = capsys.readouterr().err
    assert code == 2
    assert "data.measurements" in err and "TEMP" in err and "Traceback" not in err


def test_internal_errors_exit_1(monkeypatch, tmp_path, capsys):
    import heritage_bayes.calibration.calibrate as calmod

    def boom(*a, **k):
        raise RuntimeError("a bug")

    monkeypatch.setattr(calmod, "run_calibration", boom)
    assert main(["calibrate", str(_write(tmp_path / "c.yaml", TINY))]) == 1
    assert "internal error" in capsys.readouterr().err


@pytest.fixture(scope="module")
def tiny_run(tmp_path_factory):
    d = tmp_path_factory.mktemp("cli")
    cfg = _write(d / "tiny.yaml", TINY)
    # 400 steps: the run finishes unconverged, exit code 3 (cli: EXIT_UNCONVERGED)
    assert main(["calibrate", str(cfg), "--out", str(d / "run"), "--quiet"]) == 3
    return d, cfg


def test_an_unconverged_run_exits_3_with_its_reasons(tiny_run, tmp_path, capsys):
    """400 steps is far below 50 τ: the run directory is complete, the exit code is 3,
    and summary.json names the reason for each chain."""
    d, cfg = tiny_run
    s = json.loads((d / "run" / "summary.json").read_text())
    assert s["converged"] is False
    reasons = s["unconverged_reasons"]
    assert any(
        r.startswith("thermal: the step cap `sampler.max_steps` was reached after 400 steps; τmax ")
        for r in reasons
    ), reasons
    assert main(["calibrate", str(cfg), "--out", str(tmp_path / "r"), "--no-report"]) == 3
    err = capsys.readouterr().err
    assert "hbayes: finished but NOT converged (exit code 3)" in err
    assert "thermal: the step cap `sampler.max_steps` was reached after 400 steps" in err
    assert "Traceback" not in err


def test_tiny_run_directory_and_load_run(tiny_run):
    d, _ = tiny_run
    run = d / "run"
    for name in ("posterior.nc", "summary.json", "config.yaml"):
        assert (run / name).is_file()
    assert not list(run.glob("*.tmp"))
    summary = json.loads((run / "summary.json").read_text())
    for key in ("converged", "max_rhat", "min_ess_bulk", "wall_seconds", "metrics", "parameters"):
        assert key in summary
    p = summary["parameters"]["thermal.Ge"]
    assert {"median", "q05", "q95", "r_hat", "ess_bulk", "tau", "unit"} <= set(p)
    m = summary["metrics"]["thermal"]["Ti"]
    assert {"MSE", "MAE", "FIT", "coverage50", "coverage90"} <= set(m["calibration"])
    assert "validation" in m and "combined" in summary["metrics"]
    r = load_run(run)
    assert set(r.sections) == {"thermal", "hygric"}
    for g in (
        "posterior",
        "sample_stats",
        "log_likelihood",
        "observed_data",
        "constant_data",
        "posterior_predictive",
    ):
        assert g in r.idata.groups()
    assert r.idata.posterior.attrs["seed"] == 3
    assert "thermal.tau_1_h" in r.idata.posterior
    U = r.idata.constant_data[list(r.models["thermal"].input_names)].to_dataframe()
    Y = r.simulate(U, "thermal", n_draws=5)
    assert Y.shape == (5, len(U), 1) and np.all(np.isfinite(Y))
    rh = r.simulate_rh(U, r.idata.constant_data[["Pe"]].to_dataframe(), n_draws=5)
    assert np.all((rh > 0) & (rh < 110))


def test_same_seed_same_posterior_and_resume(tiny_run, tmp_path):
    d, cfg = tiny_run
    assert main(["calibrate", str(cfg), "--out", str(tmp_path / "again"), "--quiet"]) == 3
    a = load_run(d / "run").idata.posterior
    b = load_run(tmp_path / "again").idata.posterior
    for v in a.data_vars:
        np.testing.assert_array_equal(a[v].values, b[v].values)
    # resuming a finished run continues from the saved chain and succeeds
    assert (
        main(["calibrate", str(cfg), "--out", str(tmp_path / "again"), "--resume", "--quiet"]) == 3
    )
    s = json.loads((tmp_path / "again" / "summary.json").read_text())
    assert s["models"]["thermal"]["chain"]["resumed_from"] >= 400


def test_resume_may_extend_a_run(tiny_run, tmp_path):
    d, _ = tiny_run
    cfg = json.loads(json.dumps(TINY))
    cfg["sampler"]["max_steps"] = 600  # longer: the chain tag ignores run-length settings
    path = _write(tmp_path / "longer.yaml", cfg)
    import shutil

    shutil.copytree(d / "run", tmp_path / "run")
    code = main(["calibrate", str(path), "--out", str(tmp_path / "run"), "--resume", "--quiet"])
    s = json.loads((tmp_path / "run" / "summary.json").read_text())
    assert code == (0 if s["converged"] else 3)
    chain = s["models"]["thermal"]["chain"]
    assert chain["resumed_from"] == 400
    # the block move is recorded: a one-node model has none (weight 0) whatever is flagged
    flagged = s["models"]["thermal"]["practical_identifiability"]["unidentified"]
    assert chain["block_move"] == {"parameters": flagged, "weight": 0.0}
    assert chain["steps"] == 600 or chain["converged_tau"]


def test_air_change_rate_sets_the_ventilation_prior_of_both_models(tiny_run, tmp_path):
    cfg = json.loads(json.dumps(TINY))
    cfg["air_change_rate"] = 0.5
    cfg["sampler"]["max_steps"] = 200
    path = _write(tmp_path / "ach.yaml", cfg)
    assert main(["calibrate", str(path), "--out", str(tmp_path / "run"), "--quiet"]) == 3
    s = json.loads((tmp_path / "run" / "summary.json").read_text())
    # hygric_1c's single conductance is Gfast; thermal_1c has none (Ge is total)
    assert s["parameters"]["hygric.Gfast"]["prior"].startswith("lognormal")
    assert s["parameters"]["hygric.Gfast"]["prior_spec"]["median"] == pytest.approx(
        400 * 0.5 / 3600 / (461.52 * 288.15)
    )


@pytest.mark.parametrize("sigterm", [True, False])
def test_an_interrupt_swallowed_by_a_callback_is_delivered_again(monkeypatch, capsys, sigterm):
    """A KeyboardInterrupt (Ctrl-C or SIGTERM) raised inside a callback Python cannot
    propagate from (a finaliser, the import system) reaches sys.unraisablehook; main()
    delivers it again, so a long run stops (exit 130) instead of sampling on."""
    import sys
    import time
    import types

    import heritage_bayes.cli as cli

    def command(argv):
        exc = cli._Terminated() if sigterm else KeyboardInterrupt()
        sys.unraisablehook(types.SimpleNamespace(exc_value=exc, exc_type=type(exc)))
        for _ in range(2000):  # the run goes on: it must be stopped from outside
            time.sleep(0.005)
        return 0

    import signal

    monkeypatch.setattr(cli, "_main", command)
    # a fresh interpreter's Ctrl-C handler (an earlier test of the session may have left
    # another one installed)
    old = signal.signal(signal.SIGINT, signal.default_int_handler)
    try:
        assert main(["calibrate", "x.yaml"]) == 130
    finally:
        signal.signal(signal.SIGINT, old)
    what = "terminated (SIGTERM)" if sigterm else "interrupted"
    assert f"hbayes: {what}" in capsys.readouterr().err
