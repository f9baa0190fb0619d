"""Automatic model selection: the one rule of ``model: auto`` and ``hbayes compare``
(the screen's choice, the ELPD on its tie: a decision table on synthetic screens and
posteriors, no sampling), the candidates compare samples, and ``model: auto`` end to
end on a small demo problem."""

from __future__ import annotations

import json

import pytest
import yaml

from heritage_bayes.calibration.selection import MARGIN_FIT, choose, decide, row_score
from heritage_bayes.cli import main
from heritage_bayes.compare.screen import to_sample
from heritage_bayes.errors import InputError
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


def test_compare_samples_the_choice_and_its_best_tied_rival():
    n = {"thermal_1c": 7, "thermal_2c": 10, "thermal_4a": 13}

    def sample(scores):
        return to_sample(choose([_row(m, n[m], v) for m, v in scores.items()]))

    # TRH-1's year on 0971bd2: all three tie; 1c chosen, 4a (closest to the best) sampled
    v = sample({"thermal_1c": 82.8, "thermal_2c": 82.9, "thermal_4a": 83.8})
    assert v["thermal_1c"] is None and v["thermal_4a"] is None
    assert v["thermal_2c"].startswith("not sampled: ties with thermal_1c on the screen")
    # no tie: the choice and the best other (a comparison needs two); the third is out
    v = sample({"thermal_1c": 40.0, "thermal_2c": 80.0, "thermal_4a": 83.0})
    assert v["thermal_4a"] is None and v["thermal_2c"] is None
    assert v["thermal_1c"] == (
        "screened out: MAP validation FIT 40.0 %, 43.0 points below the best (thermal_4a: "
        f"83.0 %), outside the {MARGIN_FIT:g}-point tie: it cannot be recommended"
    )


def _post(elpd, converged=True, k=0.3, se=None):
    return {"elpd": elpd, "converged": converged, "max_pareto_k": k, "se": se or {}}


#: the screen of TRH-1's year on 0971bd2 (MAP validation FIT [%]): all three rungs tie
TRH1 = [_row("thermal_1c", 8, 82.8), _row("thermal_2c", 11, 82.9), _row("thermal_4a", 14, 83.8)]


def test_the_rule_without_posteriors_is_the_screen_and_names_the_tie():
    d = decide(TRH1)
    assert d["model"] == d["choice"] == "thermal_1c" and d["decided_by"] == "screen"
    assert d["tied"] == ["thermal_4a", "thermal_2c"] and d["posterior"] is None
    assert d["tie"].startswith("thermal_4a, thermal_2c tie with it (within 2 points")
    assert decide([_row("a", 5, 60.0), _row("b", 8, 80.0)])["tie"] is None


@pytest.mark.parametrize(
    ("post", "score", "model", "verdict", "words"),
    [
        # converged, rival ahead by > 2 SE and 4 nats: the ELPD breaks the tie
        (
            {"thermal_1c": _post(0.0), "thermal_4a": _post(176.2, se={"thermal_1c": 20.2})},
            "validation ELPD",
            "thermal_4a",
            "ELPD breaks the tie",
            "(+176.2 ± 20.2 nats: more than 2 SE and 4 nats), and reliable (both chains "
            "converged): the ELPD breaks the tie, so thermal_4a",
        ),
        # the same numbers, the rival's chain not converged (TRH-1 at 0971bd2)
        (
            {"thermal_1c": _post(0.0), "thermal_4a": _post(176.2, False, se={"thermal_1c": 20.2})},
            "validation ELPD",
            "thermal_1c",
            "not reliable",
            "but that is not reliable (thermal_4a's chain did not converge): the screen's "
            "choice thermal_1c stands",
        ),
        # ahead by 30 ± 20 nats: within 2 SE, not separated
        (
            {"thermal_1c": _post(0.0), "thermal_4a": _post(30.0, se={"thermal_1c": 20.0})},
            "validation ELPD",
            "thermal_1c",
            "not separated",
            "does not separate them (+30.0 ± 20.0 nats, within 2 SE or 4 nats)",
        ),
        # a tiny SE but a negligible difference (< 4 nats): not separated
        (
            {"thermal_1c": _post(0.0), "thermal_4a": _post(3.0, se={"thermal_1c": 0.1})},
            "validation ELPD",
            "thermal_1c",
            "not separated",
            "within 2 SE or 4 nats",
        ),
        # the rival lower: the simpler stands, the ELPD agreeing
        (
            {"thermal_1c": _post(0.0), "thermal_4a": _post(-50.0, se={"thermal_1c": 5.0})},
            "validation ELPD",
            "thermal_1c",
            "not separated",
            "its validation ELPD is lower (-50.0 ± 5.0 nats)",
        ),
        # blocked LOO: a Pareto k above 0.7 makes it unreliable, converged or not
        (
            {"thermal_1c": _post(0.0, k=0.9), "thermal_4a": _post(60.0, se={"thermal_1c": 5.0})},
            "blocked LOO ELPD",
            "thermal_1c",
            "not reliable",
            "thermal_1c's Pareto k 0.90 > 0.7",
        ),
        # ... which the validation ELPD (no importance sampling) does not depend on
        (
            {"thermal_1c": _post(0.0, k=0.9), "thermal_4a": _post(60.0, se={"thermal_1c": 5.0})},
            "validation ELPD",
            "thermal_4a",
            "ELPD breaks the tie",
            "the ELPD breaks the tie, so thermal_4a, where `model: auto` (the screen alone) "
            "samples thermal_1c",
        ),
    ],
)
def test_the_rules_decision_table(post, score, model, verdict, words):
    d = decide(TRH1, post, score=score)
    assert d["choice"] == "thermal_1c"  # the screen is the same with posteriors
    assert d["model"] == model and d["posterior"]["verdict"] == verdict
    assert d["decided_by"] == ("ELPD" if model != "thermal_1c" else "screen")
    assert words in d["posterior"]["reason"]


def test_outside_the_tie_the_screen_decides_and_a_disagreeing_elpd_is_said():
    rows = [_row("thermal_1c", 8, 70.0), _row("thermal_2c", 11, 83.0)]  # 2c clearly ahead
    post = {"thermal_1c": _post(100.0, se={"thermal_2c": 10.0}), "thermal_2c": _post(0.0)}
    d = decide(rows, post)
    assert d["model"] == "thermal_2c" and d["posterior"]["verdict"] == "no tie"
    (note,) = d["posterior"]["notes"]
    assert note.startswith("the validation ELPD ranks thermal_1c above thermal_2c (+100.0")
    assert "13.0 points below the best, outside the 2-point tie" in note
    # the unconverged choice itself: nothing to overturn, the screen decides
    post["thermal_2c"]["converged"] = False
    assert decide(rows, post)["model"] == "thermal_2c"


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


def test_model_auto_and_compare_screen_alike_and_choose_alike(tmp_path):
    """The same config screened by ``model: auto`` and by ``hbayes compare`` (its
    candidates, the same ladder): the same rows scored alike and the same choice; with
    posteriors that do not reliably break the tie, compare's recommendation is that
    choice."""
    from heritage_bayes.calibration.selection import screen
    from heritage_bayes.compare.orchestrate import _candidate_config
    from heritage_bayes.compare.screen import screen_candidates
    from heritage_bayes.config import load_config
    from heritage_bayes.models import AUTO_LADDERS, models_of
    from heritage_bayes.prepare import prepare

    raw = {**AUTO, "hygric": None, "optimizer": {"maxiter": 10, "starts": 1, "popsize": 4}}
    p = tmp_path / "auto.yaml"
    p.write_text(yaml.safe_dump(raw), encoding="utf-8")
    cfg = load_config(p)
    models, rungs = models_of(cfg)
    auto = screen(cfg, prepare(cfg, models), "thermal", rungs["thermal"], seed=cfg.seed)
    names = [n for n, _, _ in AUTO_LADDERS["thermal"]]
    built = {n: _candidate_config(cfg, "thermal", n) for n in names}
    cands, models = {n: c for n, (c, _) in built.items()}, {n: m for n, (_, m) in built.items()}
    rows, _, scores = screen_candidates(cands, models, "thermal", tell=lambda m: None)
    assert [r["model"] for r in auto.rows] == names
    for r in auto.rows:
        assert scores[r["model"]] == pytest.approx(r["score"], abs=1e-6), r["model"]
    sel = choose(list(rows.values()))
    assert sel["choice"] == auto.choice["choice"] and sel["tied"] == auto.choice["tied"]
    # posteriors that cannot overturn it (the rival unconverged): the same model
    post = {m: {"elpd": 0.0, "converged": False, "max_pareto_k": 0.2} for m in names}
    post[sel["choice"]]["converged"] = True
    assert decide(list(rows.values()), post)["model"] == auto.choice["model"]


def test_the_restart_guard_runs_only_where_the_starts_disagree(monkeypatch):
    """Starts within 10 log-posterior units (the carried start left out): no more
    searches; further apart: two more from other seeds, a higher optimum kept only when
    it beats the first by more than the optimizer's MODE_PICK, and said in words."""
    import heritage_bayes.inference.optimize as opt
    from heritage_bayes.calibration.selection import GUARD_SEARCHES, SPREAD_LOGPOST, restart_guard

    def result(lp, cands, carried=None):
        return opt.MAPResult(
            x=None, theta=None, log_post=lp, n_starts=len(cands), n_agreed=1,
            candidates=cands, carried=carried,
        )  # fmt: skip

    seeds = []
    later = iter([-990.0, -1001.0])

    def fake(lp, *, seed, **kw):
        seeds.append(seed)
        return result(next(later), [-990.0])

    monkeypatch.setattr(opt, "find_map", fake)
    # the carried start stayed on the simpler optimum 250 units lower: no guard
    mp = result(-1000.0, [-1000.0, -1001.0, -1250.0], carried=-1250.0)
    assert restart_guard(None, mp, seed=4, search={}) == (mp, None) and not seeds
    # the search's own starts 12 units apart: two more searches; the first beaten by 10
    mp = result(-1000.0, [-1000.0, -1000.0 - SPREAD_LOGPOST - 2.0])
    kept, g = restart_guard(None, mp, seed=4, search={})
    assert seeds == [[4, k] for k in range(1, GUARD_SEARCHES + 1)]
    assert kept.log_post == -990.0 and g["moved"] and g["spread"] == pytest.approx(12.0)
    assert g["said"].endswith("reached -990.0, -1001.0 against -1000.0; the higher optimum is kept")
