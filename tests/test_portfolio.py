"""Portfolios on dask.distributed: validation up front, a failed room does not stop the
others, the overview table and page, --resume."""

import json
import re
import shutil

import pandas as pd
import pytest
import yaml

from heritage_bayes.cli import main
from heritage_bayes.errors import ConfigError
from heritage_bayes.portfolio import load_portfolio, run

pytest.importorskip("distributed")

TINY = {
    "name": "tiny",
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
    "sampler": {"max_steps": 200, "check_every": 100},
    "optimizer": {"maxiter": 10, "starts": 1},
    "ladder": False,
    "report": True,
}


PROJECTION = {  # a uniform warming of 2 K (morphing shift), few draws
    "draws": 20,
    "seed": 2,
    "morphing": [
        {"scenario": "warm", "horizon": 2050, "method": "shift", "deltas": {"Te": [2.0] * 12}}
    ],
    "thresholds": [{"indicator": "twpi", "below": 1000}],
}


def _write(path, obj):
    path.write_text(yaml.safe_dump(obj, sort_keys=False), encoding="utf-8")
    return path


@pytest.fixture(scope="module")
def portfolio_dir(tmp_path_factory):
    d = tmp_path_factory.mktemp("portfolio")
    _write(d / "room.yaml", TINY)
    pf = {
        "name": "three",
        "defaults": {"report": True},
        "rooms": [
            {"name": "a", "config": "room.yaml", "projection": "projection.yaml"},
            {"name": "b", "config": "room.yaml", "overrides": {"data": {"demo": {"seed": 11}}}},
            # valid config, but its periods lie outside the demo's weather year: fails
            # while it runs (data), and must not stop the others
            {
                "name": "bad",
                "config": "room.yaml",
                "overrides": {
                    "periods": {
                        "calibration": {"start": "2021-01-02", "end": "2021-01-16"},
                        "validation": {"start": "2021-01-16", "end": "2021-01-21"},
                    }
                },
            },
        ],
    }
    _write(d / "projection.yaml", PROJECTION)
    return d, _write(d / "portfolio.yaml", pf)


@pytest.fixture(scope="module")
def finished(portfolio_dir):
    d, pf = portfolio_dir
    code = main(["batch", str(pf), "--out", str(d / "out"), "--workers", "2", "--quiet"])
    return d, pf, code


def test_three_rooms_two_workers_one_bad(finished):
    d, _, code = finished
    assert code == 2  # a room failed on its data: a user error, reported by name
    out = d / "out"
    df = pd.read_csv(out / "portfolio.csv")
    assert set(df["room"]) == {"a", "b", "bad"}
    by = df.set_index("room")
    assert by.loc["a", "status"] == "done" and by.loc["b", "status"] == "done"
    assert by.loc["bad", "status"] == "failed"
    assert "not covered by every input" in by.loc["bad", "message"]
    # failed rooms come first in attention order; every room has a rank
    assert list(df["attention_rank"]) == [1, 2, 3] and df.iloc[0]["room"] == "bad"
    for room in ("a", "b"):
        summary = json.loads((out / room / "summary.json").read_text())
        assert by.loc[room, "thermal.Ti.FIT_cal"] == pytest.approx(
            summary["metrics"]["thermal"]["Ti"]["calibration"]["FIT"]
        )
        assert by.loc[room, "converged"] == summary["converged"]
        assert (out / room / "report.html").is_file()
        # the run is the room: its summary and report carry the room's name, not the
        # shared config's ("tiny")
        assert summary["name"] == room
        report = (out / room / "report.html").read_text(encoding="utf-8")
        assert f"run “{room}”" in report and "“tiny”" not in report
        # the status is the report's verdict (these tiny runs stop at their step cap)
        assert by.loc[room, "verdict"] == "not converged"
        assert f'class="verdict {by.loc[room, "verdict_level"]}"' in report
        # risk of the measured climate: less than a year logged, so only what does not
        # depend on the season covered, and the page says why
        assert by.loc[room, "emc_range_pct"] > 0 and pd.isna(by.loc[room, "twpi_years"])
        assert "less than a year" in by.loc[room, "risk_note"]
    # room a was projected: the warmer case shortens its chemical lifetime (TWPI)
    assert by.loc["a", "proj.case"] == "warm 2050"
    assert by.loc["a", "proj.twpi.change"] < 0 and by.loc["a", "proj.twpi.p_worse"] > 0.5
    assert by.loc["a", "proj.statement"] == "P(Time-weighted preservation index < 1000 years)"
    assert 0 <= by.loc["a", "proj.probability"] <= 1
    assert (out / "a" / "projection" / "projection.json").is_file()
    assert pd.isna(by.loc["b", "proj.case"])
    # the two good rooms differ (different logger seeds)
    assert by.loc["a", "thermal.Ti.FIT_cal"] != by.loc["b", "thermal.Ti.FIT_cal"]
    meta = json.loads((out / "portfolio.json").read_text())
    assert meta["rooms_total"] == 3 and len(meta["rows"]) == 3
    page = (out / "index.html").read_text()
    assert "href='a/report.html'" in page and "href='b/report.html'" in page
    assert "href='a/projection/projection.html'" in page
    assert "not covered by every input" in page
    assert "script-src 'sha256-" in page  # the sort script is the only one allowed
    assert not list(out.rglob("*.tmp"))


def test_resume_skips_finished_rooms(finished):
    d, pf, _ = finished
    out = d / "out"
    before = (out / "a" / "posterior.nc").stat().st_mtime_ns
    df = run(pf, out, workers=2, resume=True, quiet=True)
    by = df.set_index("room")
    assert by.loc["a", "status"] == "skipped" and by.loc["b", "status"] == "skipped"
    assert by.loc["bad", "status"] == "failed"
    assert (out / "a" / "posterior.nc").stat().st_mtime_ns == before
    assert by.loc["a", "thermal.Ti.FIT_cal"] == pytest.approx(
        pd.read_csv(out / "portfolio.csv").set_index("room").loc["a", "thermal.Ti.FIT_cal"]
    )


def test_batch_counts_unconverged_rooms_and_exits_3(finished, capsys):
    """The tiny rooms stop at their step cap: finished, unconverged. Without the failing
    room, batch exits 3 (EXIT_UNCONVERGED) and names each; the table says why."""
    d, _, _ = finished
    df = pd.read_csv(d / "out" / "portfolio.csv").set_index("room")
    for room in ("a", "b"):
        assert not df.loc[room, "converged"]
        assert "`sampler.max_steps` was reached" in df.loc[room, "unconverged_reasons"]
    index = (d / "out" / "index.html").read_text(encoding="utf-8")
    assert "why not converged" in index and "2 not converged" in index
    pf = yaml.safe_load((d / "portfolio.yaml").read_text(encoding="utf-8"))
    pf["rooms"] = pf["rooms"][:2]
    two = _write(d / "two.yaml", pf)
    shutil.copytree(d / "out", d / "out_two")  # the other tests read the fixture's out
    capsys.readouterr()
    assert main(["batch", str(two), "--out", str(d / "out_two"), "--resume", "--workers", "1"]) == 3
    err = capsys.readouterr().err
    assert "hbayes: room 'a' finished NOT converged: thermal: the step cap" in err
    assert "0 of 2 room(s) converged, 2 finished unconverged, 0 failed" in err


def test_every_bad_entry_reported_before_any_work(tmp_path, capsys):
    _write(tmp_path / "room.yaml", TINY)
    bad_model = dict(TINY, thermal={"model": "thermal_9z"})
    _write(tmp_path / "bad_model.yaml", bad_model)
    pf = _write(
        tmp_path / "p.yaml",
        {
            "rooms": [
                {"name": "ok", "config": "room.yaml"},
                {"name": "missing", "config": "nope.yaml"},
                {"name": "typo", "config": "room.yaml", "overrides": {"sampler": {"max_stepz": 5}}},
                {"name": "ok", "config": "room.yaml"},
                {"name": "model", "config": "bad_model.yaml"},
            ]
        },
    )
    with pytest.raises(ConfigError) as exc:
        load_portfolio(pf)
    msg = str(exc.value)
    assert "4 of 5 room(s) are invalid" in msg
    assert "rooms[1] (missing).config" in msg and "nope.yaml" in msg
    assert "max_stepz" in msg and "rooms[2] (typo)" in msg
    assert "used twice" in msg
    assert "rooms[4] (model)" in msg
    assert main(["batch", str(pf), "--out", str(tmp_path / "o"), "--quiet"]) == 2
    err = capsys.readouterr().err
    assert "nothing was run" in err and "Traceback" not in err
    assert not (tmp_path / "o").exists()


def test_unreachable_scheduler_is_a_user_error(tmp_path, capsys):
    _write(tmp_path / "room.yaml", TINY)
    pf = _write(tmp_path / "p.yaml", {"rooms": [{"name": "a", "config": "room.yaml"}]})
    code = main(
        ["batch", str(pf), "--scheduler", "tcp://127.0.0.1:9", "--out", str(tmp_path / "o")]
    )
    assert code == 2
    err = capsys.readouterr().err
    assert "tcp://127.0.0.1:9" in err and "Traceback" not in err


def test_shipped_portfolio_validates():
    from pathlib import Path

    pf = load_portfolio(Path(__file__).parents[1] / "configs" / "portfolio_demo.yaml")
    assert len(pf.rooms) >= 3
    assert len({json.dumps(r.raw, sort_keys=True, default=str) for r in pf.rooms}) == len(pf.rooms)


@pytest.mark.browser
def test_index_sorts_in_headless_chromium(finished):
    from heritage_bayes.report._browser import find_chromium, open_page

    chromium = find_chromium()
    if chromium is None:
        pytest.skip("chromium not installed (Debian package 'chromium'; .ci/run installs it)")
    d, _, _ = finished
    # click "room" twice (ascending, then descending) and read the first column of rooms
    js = """(() => {
      const table = document.getElementById('table-calibration');
      const ths = Array.from(table.querySelectorAll('th'));
      const th = ths.find(h => h.textContent.trim() === 'room');
      const col = ths.indexOf(th);
      const rooms = () => Array.from(table.querySelectorAll('tbody tr'))
        .map(r => r.cells[col].textContent.trim());
      const before = rooms();
      th.click(); const asc = rooms();
      th.click(); const desc = rooms();
      return {before, asc, desc,
              links: table.querySelectorAll('a[href$="report.html"]').length};
    })()"""
    res = open_page(d / "out" / "index.html", chromium=chromium, extra_js=js)
    assert res.errors == [], res.errors  # CSP: the hashed sort script is allowed
    external = [u for u in res.requests[1:] if not u.startswith("data:")]
    assert external == []
    got = res.dom["extra"]
    assert got["before"][0] == "bad"  # attention order: the failed room first
    assert got["asc"] == ["a", "b", "bad"] and got["desc"] == ["bad", "b", "a"]
    assert got["links"] == 2


def test_index_speaks_in_percent_and_names_the_indicators_at_risk(tmp_path):
    """Shares and probabilities in % as on the rooms' reports (not 0.91), and the
    indicators rated "risk" named, not only counted."""
    from types import SimpleNamespace

    from heritage_bayes.portfolio.page import render_index

    df = pd.DataFrame(
        [
            {
                "attention_rank": 1,
                "room": "crypt",
                "status": "done",
                "thermal.Ti.coverage90_val": 0.913,
                "risk_flags": 2,
                "risk_flagged": "vtt_mould_index_max, en15757_outside",
                "proj.twpi.p_worse": 1.0,
                "proj.probability": 0.25,
            }
        ]
    )
    pf = SimpleNamespace(rooms=[object()], name="p", notes="")
    page = render_index(pf, df, tmp_path)
    cells = [re.sub(r"<[^>]+>", "", c) for c in re.findall(r"<td[^>]*>(.*?)</td>", page)]
    assert "91 %" in cells and "100 %" in cells and "25 %" in cells
    assert "0.91" not in cells and "1.00" not in cells
    flagged = next(c for c in cells if c.startswith("2: "))
    assert "mould" in flagged.lower() and "EN 15757" in flagged
    assert "vtt_mould_index_max" not in flagged


@pytest.mark.browser
@pytest.mark.parametrize("width", [1280, 390])
def test_index_fits_the_screen_with_its_projection_columns(finished, width):
    """At 1280 px the three tables fit the page (the projection columns on screen, no
    sideways scroll); at 390 px each room is a card: nothing wider than the screen."""
    from _browser_checks import phone_layout

    d, _, _ = finished
    lay = phone_layout(d / "out" / "index.html", width=width, extra="""
      (() => { const t = document.getElementById('table-projection');
               const r = t.getBoundingClientRect();
               return {right: r.right, height: r.height,
                       text: t.innerText, status: document.getElementById(
                         'table-calibration').innerText}; })()""")  # fmt: skip
    proj = lay["extra"]
    assert proj["right"] <= lay["W"] and proj["height"] > 0, proj
    assert "warm 2050" in proj["text"]  # the case and the statement in words
    assert "P(Time-weighted preservation index < 1000 years)" in proj["text"]
    assert "not converged" in proj["status"] and "failed" in proj["status"]


def _summary(converged: bool, rhat: float, fit: float = 90.0, truth: float | None = None):
    """A summary with one measured output: FIT on validation, a derived quantity with a
    known true value (inside its interval unless ``truth`` says otherwise)."""
    return {
        "converged": converged,
        "converged_tau": converged,
        "max_rhat": rhat,
        "min_ess_bulk": 500.0,
        "models": {},
        "parameters": {},
        "derived": {"thermal.tau_1_h": {"median": 10.0, "q05": 9.0, "q95": 11.0, "sd": 0.5,
                                        "unit": "h", "truth": 10.0 if truth is None else truth}},
        "metrics": {"thermal": {"Ti": {"validation": {"FIT": fit, "n": 100, "coverage90": 0.9}}}},
    }  # fmt: skip


@pytest.mark.parametrize(
    ("summary", "level", "title", "status"),
    [
        (_summary(True, 1.005), "green", "Converged", "converged"),
        (_summary(True, 1.005, truth=20.0), "amber", "Converged, but the checks below fail",
         "checks failed"),
        (_summary(True, 1.03), "amber", "Stopping rule met, but the saved draws miss the "
         "criteria", "checks failed"),
        (_summary(True, 1.005, fit=20.0), "red", "This model does not reproduce the room",
         "checks failed"),
        (_summary(True, 1.03, fit=20.0), "red", "This model does not reproduce the room — and "
         "not fully converged", "not converged"),
        (_summary(False, 1.2, fit=20.0), "red", "This model does not reproduce the room — and "
         "NOT CONVERGED", "not converged"),
        (_summary(False, 1.03), "amber", "Nearly converged — use with care", "not converged"),
        (_summary(False, 1.2), "red", "NOT CONVERGED — do not use these results yet",
         "not converged"),
    ],
)  # fmt: skip
def test_a_rooms_status_is_its_reports_verdict(summary, level, title, status):
    """The status is the one verdict the report computes (and records in summary.json
    when it writes the page), read back typed: it never contradicts the report the row
    links (a run that met its stopping rule but whose saved draws fail is 'not
    converged' when its report's headline says so)."""
    from heritage_bayes.portfolio.rooms import report_status
    from heritage_bayes.report.verdict import convergence_verdict, verdict_record
    from heritage_bayes.rundir.summary import RunSummary

    verdict = convergence_verdict(summary)
    assert (verdict["level"], verdict["title"], verdict["status"]) == (level, title, status)
    recorded = {**summary, "verdict": verdict_record(verdict).to_dict()}
    got = report_status(RunSummary.from_dict(json.loads(json.dumps(recorded))))
    assert got == {"verdict": status, "verdict_level": level, "verdict_title": title}
    # no report written: the run's own decision, said so
    got = report_status(RunSummary.from_dict(summary))
    assert got["verdict"] == ("converged" if summary["converged"] else "not converged")
    assert "no report" in got["verdict_title"]
