"""Automatic model selection: the screen's choice rule (``model: auto``), compare's
reach rule, and ``model: auto`` end to end on a small demo problem."""

from __future__ import annotations

import json
import math

import pytest
import yaml

from heritage_bayes.cli import main
from heritage_bayes.compare.screen import REACH_FIT, within_reach
from heritage_bayes.errors import InputError
from heritage_bayes.selection import MARGIN_FIT, choose, row_score
from test_compare import TINY


def _row(model: str, n: int, val: float | None, cal: float = 80.0) -> dict:
    fit = {"calibration": {"Ti": {"FIT": cal}}}
    if val is not None:
        fit["validation"] = {"Ti": {"FIT": val}}
    return {"model": model, "n_params": n, "fit": fit}


def test_the_richer_model_wins_when_it_beats_the_margin():
    rows = [_row("thermal_1c", 7, 60.0), _row("thermal_2c", 10, 79.0), _row("thermal_4a", 13, 84.1)]
    c = choose(rows)
    assert c["choice"] == "thermal_4a" and c["best"] == "thermal_4a"
    assert c["runner_up"] is None  # 2c is 5.1 points below: no tie
    assert "more than 2 points above the best simpler model (thermal_2c: 79.0 %)" in c["reason"]


def test_the_richer_model_must_not_win_within_the_margin():
    # 4a is better, but by less than the margin: the simpler model is chosen, 4a ties
    rows = [_row("thermal_1c", 7, 50.0), _row("thermal_2c", 10, 82.5), _row("thermal_4a", 13, 84.0)]
    c = choose(rows)
    assert c["choice"] == "thermal_2c" and c["best"] == "thermal_4a"
    assert c["runner_up"] == "thermal_4a"
    assert f"within {MARGIN_FIT:g} points of the best, thermal_4a (84.0 %)" in c["reason"]
    # exactly at the margin the simpler model still stands; just beyond it, it falls
    edge = [_row("a", 5, 80.0), _row("b", 8, 80.0 + MARGIN_FIT)]
    assert choose(edge)["choice"] == "a"
    assert choose([_row("a", 5, 80.0), _row("b", 8, 80.1 + MARGIN_FIT)])["choice"] == "b"


def test_the_choice_is_by_parameters_not_ladder_order_and_skips_unscored_rungs():
    rows = [
        _row("hygric_1c", 5, float("nan")),  # no score (failed simulation)
        _row("hygric_2c", 8, 64.9),
        _row("hygric_2c_sorption", 7, 64.0),  # fewer parameters, within the margin
    ]
    assert choose(rows)["choice"] == "hygric_2c_sorption"
    # without a validation period the calibration FIT is the score
    assert row_score(_row("m", 3, None, cal=71.0)) == (71.0, "calibration FIT")
    with pytest.raises(InputError, match="no model of the ladder"):
        choose([_row("m", 3, float("nan"), cal=float("nan"))])


def test_compare_samples_those_within_reach_and_at_least_two():
    n = {"thermal_1c": 7, "thermal_2c": 10, "thermal_4a": 13}
    v = within_reach({"thermal_1c": 40.0, "thermal_2c": 80.0, "thermal_4a": 83.0}, n)
    assert v["thermal_2c"] is None and v["thermal_4a"] is None
    assert v["thermal_1c"].startswith("screened out: MAP validation FIT 40.0 %, 43.0 points")
    assert f"reach {REACH_FIT:g} points" in v["thermal_1c"]
    # a richer model that adds nothing over a simpler one within reach is not sampled
    # (TRH-1's attic: 2c collapses onto 1c, 80.4 % each, 4a 84.1 %)
    v = within_reach({"thermal_1c": 80.4, "thermal_2c": 80.4, "thermal_4a": 84.1}, n)
    assert v["thermal_1c"] is None and v["thermal_4a"] is None
    assert v["thermal_2c"] == (
        f"screened out: MAP validation FIT 80.4 %, not more than {MARGIN_FIT:g} points "
        "above the simpler thermal_1c (80.4 %)"
    )
    # one far ahead: the runner-up is still sampled (a comparison needs two)
    v = within_reach({"a": 10.0, "b": 90.0, "c": 20.0, "d": math.nan})
    assert [m for m, why in v.items() if why is None] == ["b", "c"]
    assert v["d"] == "screened out: no MAP score"


#: test_compare's tiny demo room (its periods, room volume, seed), both sections auto
AUTO = {
    **TINY,
    "name": "auto",
    "data": {"demo": {"seed": 7}},
    "thermal": {"model": "auto"},
    "hygric": {"model": "auto", "noise": "ar1"},
    "sampler": {"max_steps": 200, "check_every": 100, "max_draws": 100, "n_predictive": 10},
    "optimizer": {"maxiter": 15, "starts": 1, "popsize": 4},
}


def test_model_auto_end_to_end(tmp_path, capsys):
    """``model: auto`` on the demo: every rung screened with progress lines, the choice
    sampled from its screened MAP and named in the run's config, the screen recorded in
    summary.json (the ladder) and shown in the report's ladder section."""
    cfg = tmp_path / "auto.yaml"
    cfg.write_text(yaml.safe_dump(AUTO), encoding="utf-8")
    rc = main(["calibrate", str(cfg), "--out", str(tmp_path / "run")])
    err = capsys.readouterr().err
    assert rc in (0, 3), err  # 3: finished, not converged (200 steps)
    run = tmp_path / "run"
    summary = json.loads((run / "summary.json").read_text())
    config = yaml.safe_load((run / "config.yaml").read_text())
    for section, n in (("thermal", 3), ("hygric", 6)):
        sel = summary["selection"][section]
        assert f"[{section}] screen {n}/{n}: " in err
        assert f"[{section}] chosen: {sel['choice']}: {sel['reason']}" in err
        assert f"[{section}] {config[section]['model']}: the screen's MAP starts" in err
        assert sel["choice"].split(" ")[0] == config[section]["model"]
        assert summary["ladder"][section] == sel["rows"]
        rows = {r["model"]: r for r in sel["rows"]}
        assert len(rows) == n and rows[sel["choice"]]["sampled"]
        assert all({"n_params", "fit", "score"} <= set(r) for r in rows.values())
        best = max(r["score"] for r in rows.values())
        assert rows[sel["choice"]]["score"] >= best - sel["margin"]
    assert summary["models"]["thermal"]["model"] == config["thermal"]["model"]
    assert "hygric_2c_fixed (sink: temperature)" in {
        r["model"] for r in summary["selection"]["hygric"]["rows"]
    }
    assert "auto" in (run / "config.original.yaml").read_text()
    page = (run / "report.html").read_text()
    assert "chosen by the screen" in page and summary["selection"]["thermal"]["reason"] in page


#: Ctrl-C in the middle of the second rung's MAP search (its third batch of
#: log-posterior evaluations), as a terminal delivers it
_SIGINT_IN_SCREEN = """
import os, signal, sys
signal.signal(signal.SIGINT, signal.default_int_handler)
import heritage_bayes.inference.optimize as _o
_orig, _n = _o._Objective.__init__, [0, 0]
def _init(self, *a, **k):
    _orig(self, *a, **k)
    _n[0] += 1
    if _n[0] == 2:
        call = self._values
        def _values(S):
            _n[1] += 1
            if _n[1] == 3:
                print("SIGINT-SENT", file=sys.stderr, flush=True)
                os.kill(os.getpid(), signal.SIGINT)
            return call(S)
        self._values = _values
_o._Objective.__init__ = _init
from heritage_bayes.cli import main
sys.exit(main(sys.argv[1:]))
"""


def test_ctrl_c_in_the_auto_screen_stops_the_run_at_once(tmp_path):
    """SIGINT while ``model: auto`` screens its ladder (the second rung's MAP search)
    ends ``hbayes calibrate`` with 130: the search stops at once (no later rung screened,
    no chain started) and the folder is as before (no run, staging folder or lock)."""
    import subprocess
    import sys

    from test_faults import _clean, _env
    from test_paths import snapshot

    work = tmp_path / "w"
    work.mkdir()
    cfg = work / "auto.yaml"
    cfg.write_text(yaml.safe_dump({**AUTO, "hygric": None}), encoding="utf-8")
    before = snapshot(work)
    p = subprocess.run(
        [sys.executable, "-c", _SIGINT_IN_SCREEN, "calibrate", str(cfg), "--out", str(work / "r")],
        capture_output=True,
        text=True,
        env=_env(),
        check=False,
    )
    err = p.stderr
    assert p.returncode == 130 and "SIGINT-SENT" in err and "interrupted" in err, err
    assert "[thermal] screen 1/3: thermal_1c" in err and "screen 2/3" not in err, err
    assert "chosen:" not in err and "emcee" not in err and _clean(err), err
    assert snapshot(work) == before, sorted(work.rglob("*"))
