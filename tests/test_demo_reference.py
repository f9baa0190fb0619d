"""The demo's numbers do not move: a guard for changes that should change no result.

``configs/demo.yaml`` is prepared (the virtual monument, its weather and solar inputs,
the calibration window) and each section's log-posterior is evaluated at one fixed
parameter vector: the demo's documented truth with fixed noise parameters. The
checksums of the inputs and observations, the log-likelihood, the log-posterior (priors,
time-constant prior, tempering) and the estimated initial state are compared with the
values stored below, to 12 significant digits: the same arithmetic gives the same bits,
and the margin only admits a numpy or BLAS that sums in another order. A refactoring
that moves code keeps them; a change that is meant to change a result records the new
values here (print them with ``_values()``) and says why in its commit.

Cost: one ``prepare`` of the demo and two likelihood evaluations (about 4 s of CPU).
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from heritage_bayes.calibration.ladder import section_log_posterior
from heritage_bayes.config import load_config
from heritage_bayes.demo import TRUE_HYGRIC, TRUE_THERMAL
from heritage_bayes.models import build_model
from heritage_bayes.prepare import prepare

DEMO = Path(__file__).resolve().parents[1] / "configs" / "demo.yaml"

#: The noise parameters of the fixed vector (the models' own parameters are the truth).
NOISE = {
    "sigma_Ti": 0.3, "phi_Ti": 0.9, "sigma_meas_Ti": 0.05,
    "sigma_Pi": 20.0, "phi_Pi": 0.9, "sigma_meas_Pi": 5.0,
}  # fmt: skip

#: section -> what ``_values`` returns, recorded on the demo as shipped.
REFERENCE = {
    "thermal": {
        "model": "thermal_2c",
        "names": tuple(
            "Cw Ci Gw Gi Gfast Gf fI_N fI_E fI_S fI_W sigma_Ti phi_Ti sigma_meas_Ti".split()
        ),
        "rows": 3192,
        "observed_finite": 3024,
        "inputs_sum": 1302804.2316580014,
        "observed_sum": 31721.5,
        "log_likelihood": 817.2380498599736,
        "log_posterior": 403.9691898802073,
        "initial_state": (3.00977928, 3.51576008),
    },
    "hygric": {
        "model": "hygric_2c",
        "names": ("Cw", "Ci", "Gw", "Gi", "Gfast", "sigma_Pi", "phi_Pi", "sigma_meas_Pi"),
        "rows": 3192,
        "observed_finite": 3024,
        "inputs_sum": 2538155.5292154853,
        "observed_sum": 2161617.5089357235,
        "log_likelihood": -9315.388600967863,
        "log_posterior": -9318.33017462033,
        "initial_state": (455.88499489, 605.14679626),
    },
}


@pytest.fixture(scope="module")
def demo():
    cfg = load_config(DEMO)
    return cfg, prepare(cfg)


def _values(cfg, prep, section: str) -> dict:
    """The numbers of :data:`REFERENCE` for one section of the demo."""
    model = build_model(cfg, section)
    lp = section_log_posterior(cfg, prep, section, model, getattr(cfg, section).priors)
    truth = TRUE_THERMAL if section == "thermal" else TRUE_HYGRIC
    theta = np.array([[truth.get(n, NOISE.get(n)) for n in lp.params.names]])
    u, y = prep.model_inputs(section, model), prep.observed(section, model)
    return {
        "model": model.name,
        "names": tuple(lp.params.names),
        "rows": len(u),
        "observed_finite": int(np.isfinite(y).sum()),
        "inputs_sum": float(np.nansum(u)),
        "observed_sum": float(np.nansum(y)),
        "log_likelihood": float(lp.log_likelihood(theta)[0]),
        "log_posterior": float(lp(lp.params.to_unconstrained(theta))[0]),
        "initial_state": tuple(float(v) for v in lp.initial_states(theta)[0]),
    }


@pytest.mark.parametrize("section", ["thermal", "hygric"])
def test_the_demo_gives_the_recorded_numbers(demo, section):
    got, ref = _values(*demo, section), REFERENCE[section]
    exact = ("model", "names", "rows", "observed_finite")
    assert {k: got[k] for k in exact} == {k: ref[k] for k in exact}
    for key in ("inputs_sum", "observed_sum", "log_likelihood", "log_posterior"):
        assert got[key] == pytest.approx(ref[key], rel=1e-12, abs=0), key
    # the stored start has 8 decimals
    np.testing.assert_allclose(got["initial_state"], ref["initial_state"], rtol=0, atol=1e-8)
