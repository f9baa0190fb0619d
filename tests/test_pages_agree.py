"""The pages a conservator reads speak with one voice.

Module-scoped fixtures build, on the tiny virtual monument (10 + 5 days, 600 sampler
steps: seconds, not converged), the four pages of one demo: the comparison of
thermal_1c and thermal_2c with each run's report, and a calibration with both models,
its report and its projection (a morphed future, two measures). The tests check that
the same posterior prints the same digits on every page, that the visible prose names
no code identifier, that no page points at a staging folder, that a morphing run does
not speak of the KNMI'14 tables, and that a run whose saved draws fail its stated
criteria never gets a green verdict.
"""

from __future__ import annotations

import html as html_mod
import json
import re
import shutil
from html.parser import HTMLParser
from pathlib import Path

import numpy as np
import pytest
import yaml

from heritage_bayes._arviz import az
from heritage_bayes.calibration.calibrate import run_calibration
from heritage_bayes.cli import main
from heritage_bayes.climate.risk.registry import INDICATORS
from heritage_bayes.config import parse_config
from heritage_bayes.format import fmt, fmt_interval
from heritage_bayes.portfolio.rooms import room_row
from heritage_bayes.projection import project
from heritage_bayes.report import write_report
from heritage_bayes.rundir.summary import load_summary
from test_compare import MODELS, TINY  # the comparison's tiny room: thermal_2c + hygric_1c

PROJ = {
    "name": "tiny_projection",
    "draws": 12,
    "seed": 5,
    "morphing": [
        {"scenario": "warm", "horizon": 2050, "method": "shift", "deltas": {"Te": [2.0] * 12}}
    ],
    "risk": {"chunk_draws": 6},
    "interventions": [
        {
            "name": "conservation heating",
            "conservation_heating": {"rh_max": 50, "t_max": 22, "power_max": 2000},
        },
        {"name": "half ventilation", "ventilation": {"factor": 0.5}},
    ],
}


@pytest.fixture(scope="module")
def pages(tmp_path_factory) -> dict[str, Path]:
    d = tmp_path_factory.mktemp("pages")
    cfg = d / "tiny.yaml"
    cfg.write_text(yaml.safe_dump(TINY))
    cmp = d / "cmp"
    args = ["compare", str(cfg), "--models", ",".join(MODELS), "--out", str(cmp), "--quiet"]
    assert main([*args, "--workers", "1"]) == 0
    run = d / "run"
    run_calibration(parse_config(TINY), out_dir=run, report=True, quiet=True)
    project(run, PROJ, out=d / "proj")
    return {
        "cmp": cmp,
        "run": run,
        "report": run / "report.html",
        "comparison": cmp / "comparison.html",
        "projection": d / "proj" / "projection.html",
        **{f"report {m}": cmp / m / "report.html" for m in MODELS},
    }


def _rows(page: str, start: str) -> list[str]:
    table = page[page.index(start) :]
    table = table[: table.index("</table>")]
    return re.findall(r"<tr.*?</tr>", table, flags=re.S)


def test_every_parameter_prints_the_same_digits_on_every_page(pages):
    """Median and 90 % interval of every free parameter: summary.json (the typed
    summary), the run's report and the comparison print the same digits."""
    comparison = pages["comparison"].read_text(encoding="utf-8")
    checked = 0
    for m in MODELS:
        rs = load_summary(pages["cmp"] / m)
        raw = json.loads((pages["cmp"] / m / "summary.json").read_text())
        report = pages[f"report {m}"].read_text(encoding="utf-8")
        report_rows = _rows(report, 'id="table-params-thermal"')
        cmp_rows = _rows(comparison, f'<section id="model-{m}">')
        for e in rs.parameters.values():
            if not e.free:
                continue
            assert (e.median, e.q05, e.q95) == tuple(
                raw["parameters"][e.key][k] for k in ("median", "q05", "q95")
            )
            med, interval = fmt(e.median), fmt_interval(e.q05, e.q95)
            code = f'<code class="codename muted">{e.name}</code>'
            row = next(r for r in report_rows if code in r)
            assert f"<strong>{med}</strong>" in row and f">{interval}" in row, (m, e.key, row)
            row = next((r for r in cmp_rows if f"<td><code>{e.name}</code></td>" in r), None)
            if e.kind in ("sigma", "phi", "sigma_meas"):
                continue  # the comparison lists the model's physical parameters
            assert row is not None, (m, e.key)
            cells = re.findall(r"<td[^>]*>(.*?)</td>", row)
            assert med in cells and interval in cells, (m, e.key, cells)
            checked += 1
    assert checked >= 10


class _Prose(HTMLParser):
    """The visible text of a page outside code, pre, script and style elements."""

    SKIP = frozenset({"code", "pre", "script", "style", "kbd", "samp", "title"})
    VOID = frozenset({"br", "img", "meta", "link", "input", "hr", "col", "source", "wbr"})

    def __init__(self):
        super().__init__()
        self.stack: list[bool] = []
        self.text: list[str] = []

    def handle_starttag(self, tag, attrs):
        if tag not in self.VOID:
            self.stack.append(tag in self.SKIP)

    def handle_endtag(self, tag):
        if tag not in self.VOID and self.stack:
            self.stack.pop()

    def handle_data(self, data):
        if not any(self.stack):
            self.text.append(data)


#: snake_case (``sigma_meas_Ti``, ``fI_N``) and dotted names (``thermal.tau_2_h``);
#: file names (``posterior.nc``) are not code names
_SNAKE = re.compile(r"(?<![\w./-])[A-Za-z][A-Za-z0-9]*_[A-Za-z0-9_]+(?![\w/])")
_DOTTED = re.compile(r"(?<![\w./-])[a-z][a-z0-9_]*(?:\.[a-z_][a-z0-9_]*)+(?![\w/(])")
_FILE = re.compile(r"\.(nc|json|ya?ml|h5|html|csv|txt|epw|py)$")
_WORDS = {"e.g", "i.e"}
#: indicator keys of the risk registry (``twpi``), as whole words
_KEYS = re.compile(r"(?<![\w.])(" + "|".join(map(re.escape, INDICATORS)) + r")(?![\w])")


def code_names(page: str) -> list[str]:
    p = _Prose()
    p.feed(page)
    text = " ".join(p.text)
    found = {m.group(0) for r in (_SNAKE, _DOTTED, _KEYS) for m in r.finditer(text)}
    return sorted(n for n in found if n not in _WORDS and not _FILE.search(n))


def test_the_scanner_finds_code_names():
    page = (
        "<p>The τ₂ of <code>thermal.tau_2_h</code> in posterior.nc, e.g. this.</p>"
        "<p>gain_Ti_I_N and thermal.likelihood_temperature and P(twpi &lt; 25)</p>"
    )
    assert code_names(page) == ["gain_Ti_I_N", "thermal.likelihood_temperature", "twpi"]


def test_no_code_names_in_the_prose_and_no_staging_folder(pages):
    for name in ("report", "comparison", "projection", "report thermal_2c"):
        page = pages[name].read_text(encoding="utf-8")
        assert code_names(page) == [], name  # the parser reads the entities
        assert ".partial" not in html_mod.unescape(page), name


def test_a_morphing_run_does_not_speak_of_the_knmi_tables(pages):
    page = html_mod.unescape(pages["projection"].read_text(encoding="utf-8"))
    assert "morph" in page.lower()
    assert "KNMI'14" not in page and "KNMI’14" not in page and "KNMI" not in page


def _verdict_level(page: str) -> str:
    return re.search(r'<div id="verdict" class="verdict (\w+)"', page).group(1)


def test_a_run_whose_retained_draws_fail_its_criteria_is_never_green(pages, tmp_path):
    """The run's retained draws (the group the R-hat and ESS are computed on), as arviz
    recomputes R-hat and ESS from posterior.nc, miss the criteria the run states: the
    verdict is not green even when the summary says the stopping rule was met, and the
    page states the rule it applied and the draws it is on."""
    run = tmp_path / "run"
    shutil.copytree(pages["run"], run)
    rs = load_summary(run)
    idata = az.from_netcdf(run / "posterior.nc")
    rhat, ess = 0.0, np.inf
    for m in rs.models:
        free = [e.key for e in rs.parameters.values() if e.free and e.section == m]
        group = idata[f"posterior_retained_{m}"]
        diag = az.summary(group, var_names=free, kind="diagnostics", round_to="none")
        rhat, ess = max(rhat, diag["r_hat"].max()), min(ess, diag["ess_bulk"].min())
    conv = rs.convergence
    assert not (rhat <= conv.target_rhat and ess >= conv.target_ess)  # the premise
    assert (conv.draws, conv.max_rhat, conv.min_ess_bulk) == ("retained", rhat, ess)
    assert not conv.draws_ok
    assert _verdict_level(pages["report"].read_text(encoding="utf-8")) != "green"
    # calibrate's report recorded its verdict in summary.json
    assert rs.verdict.level == _verdict_level(pages["report"].read_text(encoding="utf-8"))
    # as if the stopping rule had been met
    raw = json.loads((run / "summary.json").read_text())
    raw.update(converged=True, converged_tau=True, unconverged_reasons=[])
    for info in raw["models"].values():
        info["chain"]["converged_tau"] = True
    (run / "summary.json").write_text(json.dumps(raw))
    (run / "report.html").unlink()
    page = write_report(run).read_text(encoding="utf-8")
    assert _verdict_level(page) != "green"
    assert "Rule applied: green only when" in page
    assert "retained draws (" in html_mod.unescape(page)
    # summary.json records the verdict the page shows; the portfolio's row reads it
    v = load_summary(run).verdict
    assert v.level == _verdict_level(page) and v.title in html_mod.unescape(page)
    row = room_row(run)
    assert (row["verdict_level"], row["verdict_title"]) == (v.level, v.title)
    assert row["verdict"] == v.status
