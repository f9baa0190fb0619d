"""A chain the time budget stopped continues with the time later sections left
(:mod:`heritage_bayes.calibration.chains`).

The budget is squeezed, not timed: a wrapper of ``run_sampler`` gives the thermal
chain's first part (or every part) ``max_seconds=0``, so that it stops after its first
chunk whatever the machine's speed (the sampler always runs one chunk), while the run's
own budget (30 min) leaves the rest plenty; the hygric chain ends early at the step cap.
The sharing of the time left is checked on its own with the budget's clock replaced.
"""

from __future__ import annotations

import contextlib
import io
import json
from pathlib import Path
from types import SimpleNamespace

import numpy as np
import pytest
import yaml

import heritage_bayes.inference.sampler as sampler_mod
from heritage_bayes.calibration import chains
from heritage_bayes.calibration.calibrate import run_calibration
from heritage_bayes.calibration.convergence import unconverged_reasons
from heritage_bayes.cli import main
from heritage_bayes.config import parse_config
from heritage_bayes.inference.chainresult import ChainResult
from heritage_bayes.report.notes import run_notes
from heritage_bayes.run import load_run
from test_report import TINY

#: The tiny virtual monument: 400 steps in chunks of 100, no ladder (seconds a run).
CFG = dict(
    TINY,
    ladder=False,
    report=False,
    sampler={"max_steps": 400, "check_every": 100},
    optimizer={"maxiter": 10, "starts": 1, "popsize": 4},
)


def _squeeze(monkeypatch, *, again: bool) -> list:
    """Give the thermal chain's first part (``again``: every part) no time; return the
    list the calls are recorded in (checkpoint name, resume, max_seconds asked)."""
    real, calls = sampler_mod.run_sampler, []

    def squeezed(logpost, x, **kw):
        calls.append((Path(kw["checkpoint"]).name, kw["resume"], kw["max_seconds"]))
        if Path(kw["checkpoint"]).name == "chain_thermal.h5" and (again or not kw["resume"]):
            kw["max_seconds"] = 0.0
        return real(logpost, x, **kw)

    monkeypatch.setattr(sampler_mod, "run_sampler", squeezed)
    return calls


@pytest.fixture(scope="module")
def free_run(tmp_path_factory) -> Path:
    """No budget pressure: the chains run to the step cap."""
    out = tmp_path_factory.mktemp("free") / "run"
    run_calibration(parse_config(CFG), out_dir=out, quiet=True)
    return out


@pytest.fixture(scope="module")
def squeezed_run(tmp_path_factory) -> tuple[Path, list, str]:
    """The thermal chain's share spent after 100 steps; the hygric chain ends early."""
    mp = pytest.MonkeyPatch()
    out = tmp_path_factory.mktemp("squeezed") / "run"
    err = io.StringIO()
    try:
        calls = _squeeze(mp, again=False)
        with contextlib.redirect_stderr(err):
            run_calibration(parse_config(CFG), out_dir=out, quiet=False)
    finally:
        mp.undo()
    return out, calls, err.getvalue()


def _chain(run: Path, section: str) -> dict:
    s = json.loads((run / "summary.json").read_text(encoding="utf-8"))
    return s["models"][section]["chain"]


def test_a_chain_out_of_its_share_continues_with_the_time_left(squeezed_run):
    out, calls, err = squeezed_run
    # thermal: first part, then hygric, then thermal again from its checkpoint
    assert [(n, r) for n, r, _ in calls] == [
        ("chain_thermal.h5", False),
        ("chain_hygric.h5", False),
        ("chain_thermal.h5", True),
    ]
    assert calls[2][2] > 60  # the time hygric left: most of the 30 min budget
    ch = _chain(out, "thermal")
    assert ch["steps"] == 400 and ch["stopped_by"] == "max_steps", ch
    assert ch["continued"]["from_steps"] == 100 and ch["continued"]["left_by"] == ["hygric"]
    assert ch["continued"]["seconds_given"] == pytest.approx(calls[2][2])
    assert ch["resumed_from"] == 0  # nothing came from --resume
    assert "continued" not in _chain(out, "hygric")
    s = json.loads((out / "summary.json").read_text(encoding="utf-8"))
    assert s["timings"]["thermal_continuation_seconds"] > 0
    assert "hygric_continuation_seconds" not in s["timings"]
    # the console says what happened, and warns of no time out
    assert "[thermal] its share of the time budget ran out after 100 steps" in err
    assert "[thermal] the chain continues from 100 steps with the " in err
    assert "the hygric section left: reached the step cap sampler.max_steps at 400" in err
    assert "ran out after" not in err.replace("share of the time budget ran out after", "")
    # the report says it too
    notes = run_notes(s, [])
    note = next(
        n for n in notes if n["title"] == "The thermal chain was continued with the time left"
    )
    assert "continued from 100 steps" in note["text"] and "at 400 steps" in note["text"]


def test_the_continued_chain_is_the_chain_given_more_time(squeezed_run, free_run):
    """The continuation resumes the same chain: its draws are bit for bit those of a run
    without budget pressure (the seed contract), and so are the hygric chain's."""
    a = load_run(squeezed_run[0]).idata
    b = load_run(free_run).idata
    for g in a.groups():
        for v in a[g].data_vars:
            if np.issubdtype(a[g][v].dtype, np.number):
                np.testing.assert_array_equal(a[g][v].values, b[g][v].values, err_msg=f"{g}/{v}")
    for sec in ("thermal", "hygric"):
        ca, cb = _chain(squeezed_run[0], sec), _chain(free_run, sec)
        for k in ("steps", "burn", "thin", "tau_max", "tau_history", "stopped_by"):
            assert ca[k] == cb[k], (sec, k)
    assert "continued" not in _chain(free_run, "thermal")


def test_a_chain_still_out_of_time_says_so_and_exits_3(tmp_path, monkeypatch, capsys, free_run):
    """Continued but squeezed again: the chain stops by time after one more chunk; the
    warning, the reasons, the report's note and the exit code say so."""
    cfg = tmp_path / "c.yaml"
    cfg.write_text(yaml.safe_dump(CFG), encoding="utf-8")
    calls = _squeeze(monkeypatch, again=True)
    code = main(["calibrate", str(cfg), "--out", str(tmp_path / "run")])
    err = capsys.readouterr().err
    assert code == 3, err
    assert [n for n, _, _ in calls] == ["chain_thermal.h5", "chain_hygric.h5", "chain_thermal.h5"]
    ch = _chain(tmp_path / "run", "thermal")
    assert ch["steps"] == 200 and ch["stopped_by"] == "max_seconds", ch
    assert ch["continued"]["from_steps"] == 100
    assert "ran out of time again at 200 steps" in err
    assert "[thermal] the time budget sampler.max_time = 30min ran out after 200 steps " in err
    assert "(continued from 100 steps with the " in err
    s = json.loads((tmp_path / "run" / "summary.json").read_text(encoding="utf-8"))
    why = unconverged_reasons(s)
    assert any(r.startswith("thermal: the time budget") and "continued from 100" in r for r in why)
    note = next(n for n in run_notes(s, []) if n["title"] == "The thermal chain ran out of time")
    assert "even continued from 100 steps" in note["text"]
    # --resume of that run continues the same chain: the draws of the unsqueezed run
    monkeypatch.undo()
    again = ["calibrate", str(cfg), "--out", str(tmp_path / "run"), "--resume", "--quiet"]
    assert main(again) == 3
    ch = _chain(tmp_path / "run", "thermal")
    assert ch["resumed_from"] == 200 and ch["steps"] == 400 and "continued" not in ch
    a, b = load_run(tmp_path / "run").idata.posterior, load_run(free_run).idata.posterior
    for v in a.data_vars:
        np.testing.assert_array_equal(a[v].values, b[v].values, err_msg=v)


# ---------------------------------------------------------------------- the sharing
def _section(name: str, stopped_by: str, steps: int = 100) -> SimpleNamespace:
    chain = SimpleNamespace(
        stopped_by=stopped_by,
        steps=steps,
        tau=np.array([10.0]),
        resumed_from=0,
        wall_seconds=1.0,
        cpu_seconds=1.0,
    )
    return SimpleNamespace(name=name, chain=chain, continued=None, timings={})


class _Say:
    def __init__(self):
        self.lines, self.warnings = [], []

    def say(self, msg):
        self.lines.append(msg)

    def warn(self, msg):
        self.warnings.append(msg)


@pytest.fixture
def budget(monkeypatch):
    """The budget's clock fixed at 1000 s; each continuation takes 0 s of it and ends
    as ``ends`` says (section -> stopped_by)."""
    given, ends = [], {}

    def fake_run(s, say, seconds, *, resume, label=""):
        given.append((s.name, seconds, resume))
        return ChainResult(
            chain=np.zeros((150, 2, 1)),
            log_prob=np.zeros((150, 2)),
            accepted=np.zeros(2),
            tau=np.array([10.0]),
            stopped_by=ends.get(s.name, "converged"),
            resumed_from=100,
            wall_seconds=1.0,
            cpu_seconds=1.0,
        )

    monkeypatch.setattr(chains, "_now", lambda: 1000.0)
    monkeypatch.setattr(chains, "run_chain", fake_run)
    return given, ends


def _cfg():
    return parse_config(CFG)


def test_one_chain_out_of_time_gets_all_the_time_left(budget):
    given, _ = budget
    secs = [_section("thermal", "max_seconds"), _section("hygric", "converged")]
    say = _Say()
    chains.continue_chains(_cfg(), secs, 1600.0, say)
    assert given == [("thermal", 600.0, True)]
    assert secs[0].continued == {"from_steps": 100, "seconds_given": 600.0, "left_by": ["hygric"]}
    assert secs[0].chain.steps == 150 and secs[0].chain.cpu_seconds == 2.0
    assert secs[0].chain.resumed_from == 0 and not say.warnings
    assert "with the 10 min the hygric section left" in say.lines[0]


def test_two_chains_out_of_time_share_the_time_left(budget):
    given, ends = budget
    ends["a"] = "max_seconds"  # a runs out again: b gets half of what is left
    secs = [_section("a", "max_seconds"), _section("b", "max_seconds"), _section("c", "max_steps")]
    say = _Say()
    chains.continue_chains(_cfg(), secs, 1600.0, say)
    assert given == [("a", 300.0, True), ("b", 600.0, True)]  # the clock stood still
    assert secs[0].continued["left_by"] == ["c"] and secs[1].continued["left_by"] == ["c"]
    assert len(say.warnings) == 1 and say.warnings[0].startswith("[a] the time budget")


def test_no_time_left_or_no_budget_continues_nothing(budget):
    given, _ = budget
    secs = [_section("thermal", "max_seconds"), _section("hygric", "max_seconds")]
    say = _Say()
    chains.continue_chains(_cfg(), secs, 999.0, say)  # the budget is spent
    assert given == [] and all(s.continued is None for s in secs)
    assert [w.split(" the time budget ")[0] for w in say.warnings] == ["[thermal]", "[hygric]"]
    assert "continued" not in say.warnings[0]
    chains.continue_chains(_cfg(), [_section("thermal", "converged")], None, _Say())
    assert given == []


# ---------------------------------------------------------------------- the sampler
def test_a_chain_resumed_chunk_by_chunk_is_the_uninterrupted_chain(tmp_path):
    """Stopped by time after every chunk and resumed each time, a chain takes the same
    steps and stops where the uninterrupted one does: a resumed chain decides on τ's
    stability against the check before the one it stopped at, as it did then (decided
    against that check itself, τ is always "stable" and the chain stopped at once)."""
    from test_convergence import _BoxGauss

    f = _BoxGauss(mu=[0.0, 0.0, 0.0], sd=[1.0, 3.0, 0.3], lo=[-np.inf] * 3, hi=[np.inf] * 3)
    kw = dict(seed=1, nwalkers=8, max_steps=20_000, check_every=100, tau_factor=20)
    kw |= dict(max_rhat=None, min_ess=None, checkpoint=tmp_path / "c.h5", tag="t")
    full = sampler_mod.run_sampler(f, np.zeros(3), **{**kw, "checkpoint": tmp_path / "f.h5"})
    assert full.converged and full.steps > 300  # several checks: τ settles first
    part = sampler_mod.run_sampler(f, np.zeros(3), max_seconds=0.0, **kw)
    parts = 1
    while part.stopped_by == "max_seconds":
        part = sampler_mod.run_sampler(f, np.zeros(3), max_seconds=0.0, resume=True, **kw)
        parts += 1
    assert part.converged and part.steps == full.steps and parts == full.steps // 100
    np.testing.assert_array_equal(part.chain, full.chain)
    assert part.tau_history == full.tau_history
