"""The typed run summary (heritage_bayes.rundir.summary) and the labels of the formatter."""

from __future__ import annotations

import json

import pytest

from heritage_bayes.errors import InputError
from heritage_bayes.format import fmt_interval, prose_html, quantity_label, tick_names
from heritage_bayes.rundir.reader import SCHEMA_VERSION
from heritage_bayes.rundir.summary import RunSummary, load_summary

#: A summary as hbayes wrote it before the typed summary (no schema_version).
V1 = {
    "name": "demo",
    "seed": 1,
    "converged": True,
    "converged_tau": True,
    "max_rhat": 1.0119,
    "min_ess_bulk": 943.5,
    "criteria": {"max_rhat": 1.01, "min_ess_bulk": 400.0, "tau_factor": 50.0},
    "dt": 3600.0,
    "parameters": {
        "thermal.Ci": {
            "unit": "J/K",
            "kind": "capacity",
            "median": 1.13e6,
            "q05": 5.79e5,
            "q95": 1.91e6,
            "truth": 2.4e6,
            "fixed": None,
            "r_hat": 1.0012,
        },
        "thermal.Tf": {"unit": "°C", "kind": "constant", "fixed": 8.0, "median": 8.0},
    },
    "derived": {"thermal.tau_1_h": {"unit": "h", "median": 104.0, "q05": 103.1, "q95": 108.7}},
    "metrics": {"thermal": {"Ti": {"validation": {"FIT": 90.2, "n": 1056, "coverage90": 0.91}}}},
    "models": {"thermal": {"model": "thermal_2c", "noise": "ar1_white", "chain": {"steps": 9}}},
    "provenance": {"config": {"data": {"demo": {"seed": 7}}}},
    "timings": {"prepare_seconds": 1.9},
}


def test_a_version_1_summary_loads_typed(tmp_path):
    (tmp_path / "summary.json").write_text(json.dumps(V1))
    s = load_summary(tmp_path)
    assert s.schema_version == 1
    ci = s.estimate("thermal.Ci")
    assert (ci.median, ci.q05, ci.q95, ci.unit) == (1.13e6, 5.79e5, 1.91e6, "J/K")
    assert ci.free and ci.truth_inside is False and ci.section == "thermal"
    assert ci.label == "heat capacity of the air and fast contents Ci [J/K]"
    assert not s.estimate("thermal.Tf").free
    assert s.estimate("thermal.tau_1_h").label == "τ₁ [h]"
    assert s.metric("thermal", "Ti", "validation").FIT == 90.2
    assert s.metric("thermal", "Ti", "calibration") is None
    assert s.models["thermal"].model == "thermal_2c"
    assert s.seeds == {"calibration": 1, "synthetic data": 7}
    c = s.convergence
    assert c.converged and not c.saved_draws_ok  # 1.0119 > 1.01
    assert "max R-hat 1.012 and min bulk ESS 944" in c.draws_text
    assert s.to_dict()["schema_version"] == SCHEMA_VERSION
    assert "schema_version" not in V1  # to_dict copies


def test_the_parts_a_version_1_summary_lacks_read_as_absent():
    s = RunSummary.from_dict(json.loads(json.dumps(V1)))
    assert s.verdict is None and s.periods == () and s.longitude is None
    assert s.alignment.measurement_gaps == () and s.alignment.step == "?"
    info = s.models["thermal"]
    assert info.input_names is None and info.free_names == () and info.frozen_node is None
    assert not info.identifiability.recorded and info.identifiability.n_null == 0
    assert info.predictive_noise == {} and info.saturation is None


def test_the_verdict_the_report_records_reads_back_typed():
    verdict = {
        "level": "amber",
        "status": "checks failed",
        "title": "Converged, but the checks below fail",
        "text": "t",
        "reasons": ["thermal model (`thermal_2c`): all criteria met."],
        "advice": "",
    }
    s = RunSummary.from_dict({**V1, "schema_version": SCHEMA_VERSION, "verdict": verdict})
    assert s.verdict.to_dict() == verdict and s.to_dict()["verdict"] == verdict
    assert s.verdict.reasons == ("thermal model (`thermal_2c`): all criteria met.",)
    # a status this hbayes does not know is no verdict (the portfolio says so)
    assert RunSummary.from_dict({**V1, "verdict": {**verdict, "status": "?"}}).verdict is None


def test_a_newer_schema_is_refused_with_the_file_named(tmp_path):
    (tmp_path / "summary.json").write_text(json.dumps({**V1, "schema_version": 99}))
    with pytest.raises(InputError, match=r"summary\.json.*schema 99.*upgrade heritage_bayes"):
        load_summary(tmp_path)
    with pytest.raises(InputError, match="schema"):
        RunSummary.from_dict({**V1, "schema_version": "2"})


def test_labels_name_every_quantity_in_words():
    cases = {
        ("thermal.tau_2_h", "h"): "τ₂ [h]",
        ("thermal.gain_Ti_Te", "-"): "gain from outdoor air [-]",
        ("thermal.gain_Ti_I_N", "K/(W/m²)"): "gain from sun on the north facade [K/(W/m²)]",
        ("thermal.fI_E", "m²"): "solar aperture, east facade [m²]",
        ("thermal.fI_roof_E", "m²"): "solar aperture, east slope of the roof [m²]",
        ("thermal.gain_Ti_I_roof_SW", "-"): "gain from sun on the south-west slope of the roof [-]",
        ("thermal.fI_dome", "m²"): "solar aperture, surface dome [m²]",
        ("thermal.sigma_meas_Ti", "K"): "measurement noise of Ti [K]",
        ("hygric.Cw", "kg/Pa"): "moisture capacity of the buffering surfaces Cw [kg/Pa]",
        ("thermal.Cw", "J/K"): "heat capacity of the envelope Cw [J/K]",
    }
    for (name, unit), label in cases.items():
        assert quantity_label(name, unit) == label
    # without a section an ambiguous name keeps the model's own words
    assert quantity_label("Cw", "", "the walls") == "the walls"
    assert fmt_interval(5.79e5, 1.91e6) == "[5.79×10⁵, 1.91×10⁶]"


def test_prose_sets_names_as_code_and_escapes():
    text = tick_names("scaling Cw, Ci and fI_N <together>; Cint stays", ["Cw", "Ci", "fI_N"])
    assert prose_html(text) == (
        "scaling <code>Cw</code>, <code>Ci</code> and <code>fI_N</code> &lt;together&gt;; "
        "Cint stays"
    )


def _rung(model, n, n_model, fit_val, **extra):
    """A ladder row as ``summary.json`` holds it (the screen's keys in ``extra``)."""
    return {
        "model": model,
        "n_params": n,
        "n_model_params": n_model,
        "fit": {
            "calibration": {"Pi": {"MSE": 577.7, "MAE": 19.69, "FIT": 63.29, "SD": 65.5, "n": 192}},
            "validation": {
                "Pi": {"MSE": 500.3, "MAE": 18.42, "FIT": fit_val, "SD": 63.9, "n": 120}
            },
        },
        "log_likelihood": -806.12,
        "aic": 1626.24,
        "bic": 1649.04,
        "rank": n_model,
        "n_null": 2,
        "null_directions": ["overall scale", "direction 2"],
        "condition_number_identifiable": 1.52,
        "map_agreed": "2/2",
        "sampled": False,
        **extra,
    }


#: ``selection``, ``ladder`` and ``provenance`` as ``hbayes calibrate`` writes them
#: (``model: auto`` in the hygric section: the screen's rows are its ladder)
SCREENED = {
    "selection": {
        "hygric": {
            "rule": "each model's MAP scored by the validation FIT of its simulation",
            "rows": [
                _rung("hygric_1c", 4, 2, -48.8, parent=None, seeded_from=None, score=-48.8),
                _rung(
                    "hygric_2c",
                    7,
                    5,
                    64.99,
                    sampled=True,
                    chosen=True,
                    parent="hygric_1c",
                    seeded_from="hygric_1c",
                    map_seconds=0.16,
                    score=64.99,
                    map_guard={
                        "spread": 31.0,
                        "log_posteriors": [-806.1, -806.1],
                        "moved": False,
                        "said": "3 starts ended 31 units apart",
                    },
                ),
                {
                    "model": "hygric_2c_fixed",
                    "parent": "hygric_2c",
                    "error": "not screened: the time budget ran out",
                },
            ],
            "choice": "hygric_2c",
            "score": "validation FIT",
            "reason": "the best validation FIT of the ladder (65.0 %)",
            "best": "hygric_2c",
            "runner_up": None,
            "tied": [],
            "scores": {"hygric_1c": -48.8, "hygric_2c": 64.99},
            "n_params": {"hygric_1c": 4, "hygric_2c": 7},
            "margin": 2.0,
            "model": "hygric_2c",
            "decided_by": "screen",
            "posterior": None,
            "tie": "hygric_2c_fixed ties with it (within 2 points of the best)",
            "screen_seconds": 13.9,
        }
    },
    "provenance": {
        "config": {"name": "demo", "data": {"demo": {"seed": 7}}},
        "config_sha256": "ab",
    },
}
SCREENED["ladder"] = {"hygric": SCREENED["selection"]["hygric"]["rows"]}


def test_the_ladder_selection_and_provenance_as_written_read_typed():
    """The parts of ``summary.json`` on the model choice and the provenance, as a run
    writes them, read typed and render as before; the file is written back unchanged."""
    from heritage_bayes.report.sections.identifiability import ladder_context

    d = json.loads(json.dumps({**V1, **SCREENED}))
    s = RunSummary.from_dict(d)
    assert s.to_dict() == {**d, "schema_version": SCHEMA_VERSION}
    one, two, out = s.ladder["hygric"]
    assert (one.model, one.n_params, one.n_model_params, one.rank, one.sampled) == (
        "hygric_1c", 4, 2, 2, False,
    )  # fmt: skip
    assert one.fits("validation")["Pi"].FIT == -48.8 and one.fits("validation")["Pi"].n == 120
    assert two.sampled and two.chosen and two.seeded_from == "hygric_1c"
    assert two.map_guard.said == "3 starts ended 31 units apart" and two.map_guard.spread == 31.0
    assert out.error == "not screened: the time budget ran out" and out.fits("validation") == {}
    sel = s.selection["hygric"]
    assert (sel.choice, sel.best, sel.runner_up, sel.tied, sel.margin) == (
        "hygric_2c", "hygric_2c", None, (), 2.0,
    )  # fmt: skip
    assert sel.rows == s.ladder["hygric"] and sel.scores["hygric_2c"] == 64.99
    assert s.provenance.recorded and s.provenance.config_sha256 == "ab"
    assert s.provenance.snapshot() == SCREENED["provenance"]["config"]
    assert s.seeds == {"calibration": 1, "synthetic data": 7}
    ctx = ladder_context(s)
    (table,) = ctx["tables"]
    assert table["selection"] == (
        "model: auto — hygric_2c chosen by the screen: the best validation FIT of the ladder "
        "(65.0 %). Rule: each model's MAP scored by the validation FIT of its simulation. "
        "Hygric_2c_fixed ties with it (within 2 points of the best). "
        "hygric_2c: 3 starts ended 31 units apart."
    )
    first, second, third = table["rows"]
    assert first == {
        "model": "hygric_1c", "n_params": "2 + 2 noise", "rank": "2",
        "n_null": "2 (overall scale, direction 2)", "cond": "1.52", "fit_cal": "63.3",
        "fit_val": "−48.8", "mse_cal": "578", "mse_val": "500", "mae_cal": "19.7",
        "mae_val": "18.4", "loglik": "−806", "aic": "1626", "bic": "1649",
        "agreed": "2/2", "sampled": False,
    }  # fmt: skip
    assert (
        second["sampled"]
        and third["model"] == "hygric_2c_fixed (not screened: the time budget ran out)"
    )
    assert (third["fit_val"], third["n_params"], third["agreed"]) == ("—", "—", "—")


def test_a_summary_without_ladder_selection_or_provenance():
    s = RunSummary.from_dict({k: v for k, v in V1.items() if k != "provenance"})
    assert s.ladder == {} and s.selection == {} and not s.provenance.recorded
    assert s.seeds == {"calibration": 1} and s.provenance.snapshot() == {}
