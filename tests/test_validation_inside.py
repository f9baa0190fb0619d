"""A validation inside the calibration period: held out of the fit as a logger gap is,
simulated through from the calibration's start."""

from __future__ import annotations

import dataclasses
from pathlib import Path

import numpy as np
import pytest
import yaml

from heritage_bayes.calibration.calibrate import build_model
from heritage_bayes.calibration.ladder import section_log_posterior
from heritage_bayes.calibration.outputs import _period_codes
from heritage_bayes.config import parse_config
from heritage_bayes.errors import ConfigError
from heritage_bayes.prepare import prepare

CONFIGS = Path(__file__).resolve().parents[1] / "configs"
CAL = {"start": "2019-01-02", "end": "2019-03-01"}
VAL = {"start": "2019-01-23", "end": "2019-02-06"}


def _raw(periods: dict) -> dict:
    """The demo's room and priors, thermal only, without the logger's week-long gap."""
    raw = yaml.safe_load((CONFIGS / "demo.yaml").read_text(encoding="utf-8"))
    raw.pop("hygric")
    raw["data"]["demo"]["gap"] = None
    raw["periods"] = periods
    return raw


def _error(periods: dict) -> str:
    with pytest.raises(ConfigError) as exc:
        parse_config(_raw(periods))
    return str(exc.value)


@pytest.fixture(scope="module")
def inside():
    cfg = parse_config(_raw({"calibration": CAL, "validation": VAL}))
    return cfg, prepare(cfg)


@pytest.mark.parametrize(
    ("val", "expected"),
    [
        ({"start": "2019-02-15", "end": "2019-03-10"}, "overlaps the calibration period"),
        ({"start": "2019-01-01", "end": "2019-03-05"}, "covers the calibration period"),
        ({"start": "2019-01-02", "end": "2019-01-20"}, "to validate at an end, let it start"),
        ({"start": "2019-02-10", "end": "2019-03-01"}, "inside it with calibration data on both"),
    ],
)
def test_a_validation_overlapping_the_calibration_must_lie_inside_it(val, expected):
    msg = _error({"calibration": CAL, "validation": val})
    assert "periods.validation: " in msg and expected in msg, msg


def test_the_warm_up_must_end_before_a_validation_inside():
    msg = _error({"calibration": CAL, "validation": VAL, "warmup": "30d"})
    assert "periods.warmup: 30D reaches the validation inside the calibration period" in msg
    parse_config(_raw({"calibration": CAL, "validation": VAL, "warmup": "7d"}))


def test_the_likelihood_holds_out_the_validation_hours(inside):
    """The validation's observations enter the likelihood as a logger gap would (NaN):
    changing them changes nothing; the same hours missing from a calibration without
    validation give the same log-likelihood; a change after the validation counts."""
    cfg, prep = inside
    assert prep.validation_inside
    cal, val = prep.calibration, prep.validation
    assert cal.start < val.start and val.stop < cal.stop
    model = build_model(cfg, "thermal")
    priors = cfg.thermal.priors

    def loglik(p):
        lp = section_log_posterior(cfg, p, "thermal", model, priors)
        return lp, lp.log_likelihood(theta)

    lp = section_log_posterior(cfg, prep, "thermal", model, priors)
    rng = np.random.default_rng(4)
    theta = lp.params.transform(0.3 * rng.standard_normal((3, lp.ndim)))[0]
    lp, ll = loglik(prep)
    rel = slice(val.start - cal.start, val.stop - cal.start)
    assert np.isnan(lp.observed[rel]).all()
    assert (
        np.isfinite(lp.observed[: rel.start]).all() and np.isfinite(lp.observed[rel.stop :]).all()
    )

    def shifted(rows, kelvin):
        frame = prep.frame.copy()
        ti = frame["Ti"].to_numpy(dtype=float).copy()
        ti[rows] += kelvin
        frame["Ti"] = ti
        return frame

    other = dataclasses.replace(prep, frame=shifted(val, 5.0))
    np.testing.assert_array_equal(loglik(other)[1], ll)
    gap = prep.frame.copy()
    gap.iloc[val, gap.columns.get_loc("Ti")] = np.nan
    as_gap = dataclasses.replace(prep, frame=gap, validation=None)
    np.testing.assert_allclose(loglik(as_gap)[1], ll, rtol=1e-12)
    after = dataclasses.replace(prep, frame=shifted(slice(val.stop, cal.stop), 0.5))
    assert not np.allclose(loglik(after)[1], ll)

    # simulated through: one run from the calibration's start, finite in the validation
    U = prep.model_inputs("thermal", model)
    Y = lp.simulate_frame(theta[:1], U, cal.start)[0][0, :, 0]
    assert np.isfinite(Y[cal]).all()
    # the calibration's rows: after the warm-up, without the validation
    fitted = prep.fitted_rows()
    assert not fitted[val].any() and fitted.sum() == cal.stop - cal.start - prep.warmup_steps - (
        val.stop - val.start
    )
    codes = _period_codes(prep)
    assert (codes[val] == 2).all() and (codes[val.stop : cal.stop] == 1).all()


def test_a_run_with_the_validation_inside_reports_it(tmp_path):
    """``hbayes calibrate``'s whole path (tiny budgets): the summary's periods, the
    validation figures of the hours held out, the report's header and ``hb.load_run``."""
    import heritage_bayes as hb
    from heritage_bayes.calibration.calibrate import run_calibration
    from heritage_bayes.report.build import build_context

    cfg = {
        "name": "inside",
        "seed": 3,
        "data": {"demo": {"seed": 7, "thermal_model": "thermal_2c"}, "irradiance": "none"},
        "periods": {
            "calibration": {"start": "2019-04-01", "end": "2019-04-15"},
            "validation": {"start": "2019-04-06", "end": "2019-04-09"},
        },
        "thermal": {"model": "thermal_1c"},
        "ladder": False,
        "sampler": {"max_steps": 100, "check_every": 50, "n_predictive": 20},
        "optimizer": {"maxiter": 15, "starts": 1, "popsize": 4},
    }
    out = tmp_path / "run"
    run_calibration(parse_config(cfg), out_dir=out, report=False, quiet=True)
    run = hb.load_run(out)
    per = {p.name: p for p in run.run_summary.periods}
    assert per["validation"].start.startswith("2019-04-06") and per["validation"].steps == 72
    assert per["calibration"].steps == 336
    codes = np.asarray(run.idata.constant_data["period"].values)
    assert (codes == 2).sum() == 72 and (codes == 1).sum() == 264
    val, cal = (run.run_summary.metric("thermal", "Ti", p) for p in ("validation", "calibration"))
    assert val.n == 72 and cal.n == 264 and np.isfinite(val.FIT), (val, cal)
    header = build_context(out)["header"]
    cal = next(p for p in header["periods"] if p["name"] == "calibration")
    assert "the validation inside it is held out of the fit" in cal["length"]
