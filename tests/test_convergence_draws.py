"""Which draws the run's R-hat and ESS are on: every retained draw, not the thinned
subset ``posterior.nc``'s ``posterior`` group keeps.

Synthetic chains (no sampling) are fed to the function that computes the summary's
convergence figures (:func:`heritage_bayes.inference.interop.convergence_record`), and
its record to the verdict, the reasons of an unconverged run and the typed summary.
"""

from __future__ import annotations

import numpy as np
import pytest
import xarray as xr

from heritage_bayes.calibration.convergence import unconverged_reasons
from heritage_bayes.inference.interop import convergence_record, retained_dataset, retained_group
from heritage_bayes.inference.predictive import _saved_index
from heritage_bayes.report.verdict import convergence_verdict
from heritage_bayes.rundir.summary import RunSummary

W, D, N_SAVED = 32, 124, 1000  # 32 walkers × 124 retained draws; about 1 000 saved
NAMES = [f"thermal.p{i}" for i in range(10)]
GROUP = retained_group("thermal")


def _record(x: np.ndarray) -> dict:
    """The convergence record of retained draws ``x`` (params, walkers, draws), the
    ``posterior`` group keeping about :data:`N_SAVED` of them as a run does."""
    variables = {k: xr.DataArray(x[i], dims=("chain", "draw")) for i, k in enumerate(NAMES)}
    ds = retained_dataset(variables, _saved_index(W, D, N_SAVED))
    return convergence_record({GROUP: ds}, NAMES)


def _summary(rec: dict, *, converged: bool, retained: bool = True) -> dict:
    """A ``summary.json`` object with the record's figures (``retained`` False: as a
    run written before stated them, on the saved draws)."""
    cd = rec["convergence_draws"]
    if retained:
        figures = {"max_rhat": rec["max_rhat"], "min_ess_bulk": rec["min_ess_bulk"]}
        extra = {"convergence_draws": cd}
    else:
        figures = {"max_rhat": cd["saved_max_rhat"], "min_ess_bulk": cd["saved_min_ess_bulk"]}
        extra = {}
    return {
        "converged": converged,
        "converged_tau": converged,
        **figures,
        **extra,
        "criteria": {"max_rhat": 1.01, "min_ess_bulk": 400.0, "tau_factor": 50.0},
        "parameters": {
            k: {"r_hat": rec["r_hat"][k], "ess_bulk": rec["ess_bulk"][k]} for k in NAMES
        },
        "models": {
            "thermal": {
                "model": "thermal_1c",
                "identifiability": {"n_null": 0},
                "chain": {"steps": 20000, "tau_max": 150.0, "converged_tau": converged},
            }
        },
    }


@pytest.fixture(scope="module")
def mixed() -> dict:
    """A converged chain: independent draws, every walker the same distribution; the
    seed is one whose thinned subset (32 draws per walker) scatters above R-hat 1.01,
    as most seeds' do (docs/science/benchmarks.md, "Which draws the convergence
    figures are on")."""
    return _record(np.random.default_rng(0).standard_normal((len(NAMES), W, D)))


def test_a_converged_chain_is_converged_though_its_thinned_subset_scatters(mixed):
    cd = mixed["convergence_draws"]
    # the premise: the retained draws meet the criteria, the thinned subset does not
    assert mixed["max_rhat"] <= 1.01 and mixed["min_ess_bulk"] >= 400
    assert cd["saved_max_rhat"] > 1.01
    assert (cd["walkers"], cd["groups"], cd["saved_draws_per_walker"]) == (W, {GROUP: D}, 32)
    assert cd["on"] == "retained"
    s = _summary(mixed, converged=True)
    v = convergence_verdict(s)
    assert (v["level"], v["status"], v["title"]) == ("green", "converged", "Converged")
    assert "of the retained draws" in v["stats"] and f"{mixed['max_rhat']:.3f}" in v["stats"]
    # the rule names the draws judged and the thinned draws' figure beside, deciding nothing
    assert (
        "the 3 968 retained draws (32 walkers × 124; group `posterior_retained_thermal`"
        in (v["rule"])
    )
    assert f"max R-hat {cd['saved_max_rhat']:.3f}" in v["rule"] and "decide nothing" in v["rule"]
    assert v["models"] == ["thermal model (`thermal_1c`): all criteria met."]
    assert unconverged_reasons(s) == []
    conv = RunSummary.from_dict(s).convergence
    assert conv.draws == "retained" and conv.draws_ok and conv.saved_draws_ok
    assert conv.saved_max_rhat == cd["saved_max_rhat"]


def test_a_run_written_before_is_judged_on_its_saved_draws_as_it_was(mixed):
    """A summary without ``convergence_draws`` states the saved draws' figures; the
    verdict reads them as before: amber, naming the saved draws."""
    s = _summary(mixed, converged=True, retained=False)
    conv = RunSummary.from_dict(s).convergence
    assert conv.draws == "saved" and not conv.draws_ok and conv.saved_text == ""
    v = convergence_verdict(s)
    assert v["level"] == "amber" and "saved draws miss the criteria" in v["title"]
    assert "the draws saved in posterior.nc" in v["rule"]


def _unmixed(spread: float) -> dict:
    """The record of walkers that have not mixed: each about its own mean, the means
    ``spread`` posterior sd apart (sd of their scatter)."""
    rng = np.random.default_rng(3)
    x = rng.standard_normal((len(NAMES), W, D))
    x += spread * rng.standard_normal((len(NAMES), W, 1))
    return _record(x)


def test_an_unconverged_chain_is_still_amber_or_red():
    """Walkers that have not mixed fail R-hat on all their retained draws: not green,
    whatever the stopping rule said, and named as a reason when the rule did not
    declare convergence; far off, red."""
    rec = _unmixed(0.25)
    assert 1.01 < rec["max_rhat"] <= 1.05  # the premise: near, not at, convergence
    s = _summary(rec, converged=False)
    v = convergence_verdict(s)
    assert (v["level"], v["status"]) == ("amber", "not converged")
    assert "Nearly converged" in v["title"] and "the walkers disagree" in v["models"][0]
    reasons = unconverged_reasons(s)
    assert any(r.startswith(f"max R-hat {rec['max_rhat']:.3f}") for r in reasons), reasons
    # the stopping rule's word alone does not make it green
    v = convergence_verdict(_summary(rec, converged=True))
    assert v["level"] == "amber" and "retained draws miss the criteria" in v["title"]
    rec = _unmixed(1.0)
    assert rec["max_rhat"] > 1.05
    for converged in (False, True):
        v = convergence_verdict(_summary(rec, converged=converged))
        assert (v["level"], v["status"]) == ("red", "not converged"), converged


def test_record_without_any_named_parameter_says_which():
    """A record whose names are in no retained group is refused with the names and the
    groups, not an empty ``max()``'s bare error."""
    x = np.random.default_rng(3).normal(size=(len(NAMES), W, D))
    variables = {k: xr.DataArray(x[i], dims=("chain", "draw")) for i, k in enumerate(NAMES)}
    ds = retained_dataset(variables, _saved_index(W, D, N_SAVED))
    with pytest.raises(ValueError, match=r"hygric\.Cw.*posterior_retained_thermal"):
        convergence_record({GROUP: ds}, ["hygric.Cw"])
