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
    assert "max R-hat 1.012 and min bulk ESS 944" in c.saved_draws_text
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
