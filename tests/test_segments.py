"""Records split at input gaps too long to bridge: one likelihood over segments."""

from __future__ import annotations

import dataclasses
from pathlib import Path

import numpy as np
import pandas as pd
import pytest
import yaml

from heritage_bayes.calibration.calibrate import build_model
from heritage_bayes.calibration.ladder import section_log_posterior as _log_posterior
from heritage_bayes.config import parse_config, prior_specs
from heritage_bayes.inference.optimize import find_map
from heritage_bayes.inference.posterior import LogPosterior
from heritage_bayes.inference.results import fit_metrics
from heritage_bayes.inference.segments import (
    SegmentedLogPosterior,
    calibration_segments,
    segments_of,
)
from heritage_bayes.init_config import init_config
from heritage_bayes.prepare import prepare
from test_init_detect import _climate, _data, _hobo
from test_prepare import _csv_config, _load, _write_files

CONFIGS = Path(__file__).resolve().parents[1] / "configs"
GAP_START = pd.Timestamp("2019-01-25 05:00", tz="UTC")
GAP_HOURS = 35


def _demo_thermal(days_cal: int = 42):
    """The demo's room and priors, thermal only, without the logger's week-long gap."""
    raw = yaml.safe_load((CONFIGS / "demo.yaml").read_text(encoding="utf-8"))
    raw.pop("hygric")
    raw["data"]["demo"]["gap"] = None
    end = pd.Timestamp("2019-01-02") + pd.Timedelta(days=days_cal)
    raw["periods"] = {
        "calibration": {"start": "2019-01-02", "end": end.strftime("%Y-%m-%d")},
        "validation": {"start": "2019-03-01", "end": "2019-03-29"},
    }
    cfg = parse_config(raw)
    return cfg, prepare(cfg)


def _with_gap(prep):
    """The prepared demo with a 35-hour weather outage (the inputs bridged linearly as
    align does, and marked as a break) and the logger silent over the same hours."""
    frame = prep.frame.copy()
    rows = (frame.index >= GAP_START) & (frame.index < GAP_START + pd.Timedelta(hours=GAP_HOURS))
    k = np.flatnonzero(rows)
    for c in frame.attrs["inputs"]:
        if c in frame:
            v = frame[c].to_numpy(dtype=float).copy()
            v[k] = np.interp(k, [k[0] - 1, k[-1] + 1], v[[k[0] - 1, k[-1] + 1]])
            frame[c] = v
    frame.loc[rows, ["Ti"]] = np.nan
    return dataclasses.replace(prep, frame=frame, breaks=rows)


@pytest.fixture(scope="module")
def demo():
    return _demo_thermal()


def test_segments_of_drops_short_runs():
    br = np.zeros(20, dtype=bool)
    br[[5, 6, 9]] = True
    kept, dropped = segments_of(br, 3)
    assert kept == [(0, 5), (10, 20)] and dropped == [(7, 9)]


def test_gap_free_data_keep_the_single_record_likelihood(demo):
    """No break: the plain log-posterior, and a one-segment one is bit-identical to it."""
    cfg, prep = demo
    assert prep.breaks is None
    model = build_model(cfg, "thermal")
    lp = _log_posterior(cfg, prep, "thermal", model, cfg.thermal.priors)
    assert type(lp) is LogPosterior
    seg = SegmentedLogPosterior(
        lp.model, lp.params, lp.noise, lp.inputs, lp.observed, dt=lp.dt, warmup=lp.warmup,
        init_window=lp.init_window, initial_state=lp.initial_state,
        segments=((0, lp.inputs.shape[0]),),
    )  # fmt: skip
    theta = lp.params.transform(np.zeros((3, lp.ndim)))[0]
    assert np.array_equal(seg.log_likelihood(theta), lp.log_likelihood(theta))
    U = prep.model_inputs("thermal", model)
    a = seg.simulate_frame(theta, U, prep.calibration.start)[0]
    b = lp.simulate_frame(theta, U, prep.calibration.start)[0]
    assert np.array_equal(a, b)


def test_segments_likelihood_is_the_sum_of_single_segment_likelihoods(demo):
    cfg, prep = demo
    gp = _with_gap(prep)
    model = build_model(cfg, "thermal")
    lp = _log_posterior(cfg, gp, "thermal", model, cfg.thermal.priors)
    assert isinstance(lp, SegmentedLogPosterior) and len(lp.segments) == 2
    (a0, b0), (a1, b1) = lp.segments
    assert b0 < a1 and a1 - b0 == GAP_HOURS  # the gap's rows are in neither
    U = gp.model_inputs("thermal", model)[gp.calibration]
    Y = gp.observed("thermal", model)[gp.calibration]
    rng = np.random.default_rng(3)
    theta = lp.params.transform(0.3 * rng.standard_normal((4, lp.ndim)))[0]
    singles = [
        LogPosterior(model, lp.params, lp.noise, U[a:b], Y[a:b], dt=gp.dt, warmup=0,
                     init_window=gp.init_steps, initial_state="estimate")
        for a, b in lp.segments
    ]  # fmt: skip
    total = singles[0].log_likelihood(theta) + singles[1].log_likelihood(theta)
    assert np.isfinite(total).all()
    np.testing.assert_allclose(lp.log_likelihood(theta), total, rtol=1e-12)
    # the frame's simulation: nothing inside the gap, each segment from its own start
    Ys = lp.simulate_frame(theta[:1], gp.model_inputs("thermal", model), gp.calibration.start)[0]
    assert np.isnan(Ys[0, gp.breaks]).all() and np.isfinite(Ys[0, ~gp.breaks]).all()


def test_calibrates_across_a_35_hour_gap_as_well_as_without(demo):
    """MAP of the demo room (thermal_2c generated, thermal_2c fitted) with and without a
    35-h outage of weather and logger: the same truth recovered, and the validation FIT
    as good."""
    cfg, prep = demo
    gp = _with_gap(prep)
    model = build_model(cfg, "thermal")
    names = model.parameter_names
    truth = prep.truth["thermal"]
    out = {}
    for tag, p in (("gap-free", prep), ("gap", gp)):
        lp = _log_posterior(cfg, p, "thermal", model, cfg.thermal.priors)
        mp = find_map(lp, seed=1, maxiter=60, starts=2)
        U = p.model_inputs("thermal", model)
        ysim = lp.simulate_frame(mp.theta[None], U, p.calibration.start)[0][0, :, 0]
        obs = p.observed("thermal", model)[:, 0]
        err = {n: abs(mp.theta[i] / truth[n] - 1) for i, n in enumerate(names) if n in truth}
        fit = fit_metrics(obs[p.validation], ysim[p.validation])["FIT"]
        out[tag] = (err, fit)
    err0, fit0 = out["gap-free"]
    err1, fit1 = out["gap"]
    assert fit1 > fit0 - 2.0 and fit1 > 80.0, (fit0, fit1)
    for n in err0:
        assert err1[n] < 2 * err0[n] + 0.1, (n, err0[n], err1[n])


def test_prepare_splits_a_long_weather_gap(tmp_path):
    """A 35-hour weather outage inside the periods: no error any more, the rows marked
    as a break, and the calibration split into two segments."""
    _write_files(tmp_path, weather_gap=35)
    cfg = _load(tmp_path, _csv_config(tmp_path))
    prep = prepare(cfg)
    assert prep.breaks.sum() == 36  # 35 missing readings touch 36 hourly bins
    gaps = [g for g in prep.alignment["input_gaps"] if not g["filled"]]
    assert [(g["column"], g["n_missing"]) for g in gaps] == [("Te", 35), ("Pe", 35)]
    kept, dropped = calibration_segments(prep)
    assert len(kept) == 2 and not dropped


def test_init_proposes_the_year_across_an_outage(tmp_path):
    """A year of an FMI-style weather file with a 35-hour outage in April and a HOBO
    export with the logger silent for 35 hours in June: init proposes the calendar year
    (8 months to calibrate, 4 to validate, the coverage in the comment), not the longest
    stretch without a gap (April to February), and calibrate's data layer accepts it."""
    utc, te, ti, rh, ghi = _climate("2021-01-01", "2022-02-01", 25.0)
    wall = utc.tz_localize(None) + pd.Timedelta(hours=2)
    out_w = (utc >= "2021-04-12 07:00") & (
        utc < pd.Timestamp("2021-04-12 07:00", tz="UTC") + pd.Timedelta(hours=35)
    )
    wp = _data(tmp_path) / "fmi.csv"
    pd.DataFrame(
        {"t_UTC+2": wall.strftime("%Y-%m-%d %H:%M:%S"), "Te": te.round(2), "RHe": rh.round(1),
         "Rglob": ghi}
    )[~out_w].to_csv(wp, index=False)  # fmt: skip
    out_l = (utc >= "2021-06-20 00:00") & (utc < "2021-06-21 11:00")
    lp = _hobo(_data(tmp_path) / "logger.csv", wall[~out_l], ti[~out_l], rh[~out_l], "+02:00")
    out = tmp_path / "room" / "config.yaml"
    res = init_config(lp, wp, output=out, latitude=60.0, longitude=25.0)
    assert res.questions == []
    raw = yaml.safe_load(out.read_text(encoding="utf-8"))
    per = {k: (str(v["start"]), str(v["end"])) for k, v in raw["periods"].items() if k != "warmup"}
    assert per == {
        "calibration": ("2021-01-01", "2021-09-01"),
        "validation": ("2021-09-01", "2022-01-01"),
    }, per
    text = " ".join(out.read_text(encoding="utf-8").replace("#", " ").split())
    assert "a logger reading in 99.6% of the hours, a weather reading in 99.6%" in text
    raw.pop("hygric", None)  # the periods are what is tested here
    cfg = parse_config(raw, base_dir=str(out.parent), name="room")
    prep = prepare(cfg)
    kept, dropped = calibration_segments(prep)
    assert len(kept) == 2 and not dropped  # split at the weather's outage


def test_a_short_segment_is_dropped_with_a_note(tmp_path):
    """A calibration that starts 43 hours before a weather outage: that piece (shorter
    than the 2-day warm-up plus 48 h) is dropped, the console says so, and the
    calibration is fitted over the rest."""
    from heritage_bayes.calibration.calibrate import _say_segments

    _write_files(tmp_path, weather_gap=35)
    raw = _csv_config(tmp_path)
    raw["periods"]["calibration"]["start"] = "2020-01-20"
    prep = prepare(_load(tmp_path, raw))
    kept, dropped = calibration_segments(prep)
    assert len(kept) == 1 and dropped == [(0, 43)]
    lines = []

    class Say:
        def say(self, text):
            lines.append(text)

    _say_segments(Say(), prep)
    assert "1 segment(s) of 8.7 d" in lines[0]
    assert lines[1].startswith("data: calibration segment 2020-01-20 00:00 to 2020-01-21 18:00")
    cfg = _load(tmp_path, raw)
    lp = _log_posterior(cfg, prep, "thermal", build_model(cfg, "thermal"), cfg.thermal.priors)
    assert lp.segments == tuple(kept)
    assert np.isnan(lp.observed[:43]).all()


def test_a_controlled_room_restarts_steady_after_a_gap():
    """A thermostat (nonlinear, ``initial_state: steady`` with a warm-up): each segment
    its own warm-up and steady start; the sum of the segments' likelihoods."""
    import heritage_bayes as hb
    from heritage_bayes.inference.likelihoods import get_noise_model
    from heritage_bayes.inference.parameters import parameters_for

    rng = np.random.default_rng(5)
    N = 24 * 40
    k = np.arange(N)
    te = 2 + 6 * np.sin(2 * np.pi * k / 24) + 3 * np.sin(2 * np.pi * k / 240)
    m = hb.model("thermal_2c", surfaces=(), ground=False, thermostat=True)
    truth = {"Cw": 5e7, "Ci": 5e6, "Gw": 150.0, "Gi": 400.0, "Gfast": 60.0, "Tset": 12.0}
    truth = {n: truth.get(n, 1000.0) for n in m.parameter_names}
    y = hb.simulate(m, truth, te[:, None])[:, 0] + 0.1 * rng.standard_normal(N)
    noise = get_noise_model("iid")
    ps = parameters_for(m, noise, prior_specs({n: {"fixed": v} for n, v in truth.items()}))
    segs = ((0, 400), (440, N))
    lp = SegmentedLogPosterior(
        m, ps, noise, te[:, None], y[:, None], warmup=48, init_window=24, segments=segs
    )
    theta = np.array([[*truth.values(), 0.1]])
    single = [
        LogPosterior(m, ps, noise, te[a:b, None], y[a:b, None], warmup=48, init_window=24)
        for a, b in segs
    ]
    total = sum(p.log_likelihood(theta) for p in single)
    assert np.isfinite(total).all()
    np.testing.assert_allclose(lp.log_likelihood(theta), total, rtol=1e-12)
    Y = lp.simulate_frame(theta, te[:, None], 0)[0][0, :, 0]
    assert np.isnan(Y[400:440]).all() and np.isfinite(Y[:400]).all()
    assert np.nanmax(np.abs(Y[488:] - y[488:])) < 1.0  # after its warm-up: on the room
