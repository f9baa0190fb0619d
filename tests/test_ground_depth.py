"""A ground at an estimated depth: the Kusuda-Achenbach temperature written as the mean
plus two depth-weighted components of the surface cycle, and the thermal models that
take the components as inputs and estimate the depth ``zf`` [m]."""

from __future__ import annotations

import numpy as np
import pandas as pd
import pytest
from scipy.optimize import least_squares

from heritage_bayes.climate.ground import (
    GROUND_DEPTH,
    YEAR_DAYS,
    annual_components,
    damping,
    damping_depth,
    depth_factors,
    kusuda_achenbach,
)
from heritage_bayes.config import parse_config
from heritage_bayes.errors import ConfigError
from heritage_bayes.inference.priors import Prior, check_fixed, default_prior
from heritage_bayes.models import build_model
from heritage_bayes.rc.catalog import GROUND_CYCLE_INPUTS, GROUND_REFERENCE, model

T0 = pd.Timestamp("2021-01-20", tz="UTC").value / (86_400 * 10**9)  # coldest day [d]
PARAMS_1C = dict(Ci=2e7, Ge=40.0, Gf=60.0)


def test_decomposition_reproduces_kusuda_achenbach_at_fixed_depths():
    times = pd.date_range("2020-06-01", periods=3 * 365, freq="1D", tz="UTC")
    c, s = annual_components(times, 8.0, T0)
    for z in (0.0, 0.3, GROUND_DEPTH, 2.24, 4.0, 6.0):
        a, b = depth_factors(z)
        np.testing.assert_allclose(
            10.0 + a * c + b * s, kusuda_achenbach(times, 10.0, 8.0, T0, depth=z), atol=1e-12
        )
        ratio, lag = damping(z)
        assert np.hypot(a, b) == pytest.approx(ratio, rel=1e-12)
        assert np.arctan2(b, a) == pytest.approx(lag * 2 * np.pi / YEAR_DAYS, abs=1e-12)
    assert depth_factors(0.0) == (1.0, 0.0)  # the surface cycle itself
    assert damping_depth() == pytest.approx(2.2411, abs=1e-4)
    za = depth_factors(np.array([0.5, 2.0]))[0]  # vectorised over a batch of depths
    assert za.shape == (2,) and za[0] == pytest.approx(depth_factors(0.5)[0])


def test_depth_prior_bounds_and_validity():
    p = default_prior("thermal", "depth")
    assert (p.dist, p.lower, p.upper, p.mu, p.sigma) == ("lognormal", 0.5, 6.0, 2.0, 0.5)
    assert p.log_scale  # sampled in log z
    draws = p.sample(np.random.default_rng(0), 2000)
    assert draws.min() >= 0.5 and draws.max() <= 6.0
    assert np.median(draws) == pytest.approx(2.0, rel=0.1)
    m = model("thermal_1c", surfaces=(), ground="seasonal")
    info = {i.name: i for i in m.parameters}["zf"]
    assert (info.kind, info.unit) == ("depth", "m")
    P = np.array([[2e7, 40.0, 60.0, 1.0], [2e7, 40.0, 60.0, -0.5]])
    assert m.valid_mask(P).tolist() == [True, False]
    with pytest.raises(ValueError, match="depth zf must be >= 0"):
        m.check_values(P)
    with pytest.raises(ConfigError, match=r"a depth must be within \[0, 20\]"):
        check_fixed("thermal.priors.zf", "depth", -1.0)


def _inputs(times):
    """Daily inputs: Te the surface cycle plus weather noise; Tf at 1 m; the components."""
    c, s = annual_components(times, 8.0, T0)
    te = 9.0 + c + np.random.default_rng(1).normal(0.0, 2.0, len(times))
    a, b = depth_factors(GROUND_REFERENCE)
    return np.column_stack([te, 9.0 + a * c + b * s, c, s])


def test_seasonal_ground_at_depth_equals_the_input_ground_at_that_depth():
    """The model's ground at the depth zf with the mean offset dTf is the input ground
    of that depth, dTf warmer (the offset's prior: normal about 0 K, sd 1 K)."""
    times = pd.date_range("2020-01-01", periods=730, freq="1D", tz="UTC")
    U = _inputs(times)
    seasonal = model("thermal_1c", surfaces=(), ground="seasonal")
    fixed = model("thermal_1c", surfaces=(), ground=True)
    assert seasonal.input_names == ("Te", "Tf", *GROUND_CYCLE_INPUTS)
    for z, offset in ((GROUND_REFERENCE, 0.0), (2.7, 0.0), (2.7, -1.3)):
        tf = kusuda_achenbach(times, 9.0, 8.0, T0, depth=z) + offset
        P = np.array([[*PARAMS_1C.values(), z, offset]])
        y, ok = seasonal.forward(P, U, 86_400.0)
        y_ref, _ = fixed.forward(
            np.array([list(PARAMS_1C.values())]), np.column_stack([U[:, 0], tf]), 86_400.0
        )
        assert ok.all()
        np.testing.assert_allclose(y, y_ref, atol=1e-9)
    offset = next(p for p in seasonal.parameters if p.name == "dTf")
    assert (offset.kind, offset.unit) == ("offset", "K")
    assert default_prior("thermal", "offset") == Prior("normal", -5.0, 5.0, 0.0, 1.0)


def test_a_known_depth_is_recovered_from_a_small_synthetic_series():
    times = pd.date_range("2019-01-01", periods=3 * 365, freq="1D", tz="UTC")
    U = _inputs(times)
    m = model("thermal_1c", surfaces=(), ground="seasonal")
    truth = np.array([[*PARAMS_1C.values(), 3.0, 0.0]])
    y = m.forward(truth, U, 86_400.0)[0][0, :, 0]
    y = y + np.random.default_rng(2).normal(0.0, 0.1, len(y))  # sensor noise [K]

    def resid(x):  # log Ge, log Gf, zf; Ci known
        P = np.array([[PARAMS_1C["Ci"], np.exp(x[0]), np.exp(x[1]), x[2], 0.0]])
        return m.forward(P, U, 86_400.0)[0][0, :, 0] - y

    fit = least_squares(resid, [np.log(20.0), np.log(20.0), 1.0], bounds=([-5, -5, 0.2], [9, 9, 6]))
    assert fit.x[2] == pytest.approx(3.0, abs=0.15)
    assert np.exp(fit.x[1]) == pytest.approx(60.0, rel=0.1)


def _config(**gt):
    raw = {
        "data": {
            "weather": {"format": "knmi", "path": "w.txt"},
            "measurements": {"format": "csv", "path": "m.csv", "time_column": "t"},
            "irradiance": "none",
        },
        "thermal": {"model": "thermal_2c"},
    }
    if gt:
        raw["data"]["ground_temperature"] = gt
    return parse_config(raw)


def test_the_default_ground_of_files_estimates_its_depth():
    m = build_model(_config(), "thermal")
    assert "zf" in m.parameter_names and {"Tf", *GROUND_CYCLE_INPUTS} <= set(m.input_names)
    for gt in ({"mode": "seasonal", "depth": 1.0}, {"mode": "annual_mean"}):
        m = build_model(_config(**gt), "thermal")
        assert "zf" not in m.parameter_names and "Tf_cos" not in m.input_names


def test_prepared_columns_move_tf_to_any_depth():
    """Tf at 1 m (the files' default input) plus the depth-weighted cycle columns is the
    seasonal ground at that depth; without a cycle to fit, zero columns, said so."""
    from heritage_bayes.inputs import ground_cycle_inputs, seasonal_ground_temperature

    idx = pd.date_range("2021-01-01", periods=400 * 24, freq="1h", tz="UTC")
    w = 2 * np.pi / YEAR_DAYS
    days = idx.as_unit("ns").asi8 / (86_400 * 10**9)
    te = pd.Series(9.0 - 7.0 * np.cos(w * (days - T0)) + 3 * np.sin(2 * np.pi * idx.hour / 24), idx)
    times = idx[::24] + pd.Timedelta("30min")
    tf, _ = seasonal_ground_temperature(te, times)
    cols, note = ground_cycle_inputs(te, times)
    assert note.startswith("depth estimated (zf)")
    a_r, b_r = depth_factors(GROUND_REFERENCE)
    for z in (0.5, 2.0, 5.0):
        a, b = depth_factors(z)
        moved = tf + (a - a_r) * cols["Tf_cos"] + (b - b_r) * cols["Tf_sin"]
        np.testing.assert_allclose(moved, seasonal_ground_temperature(te, times, z)[0], atol=1e-9)
    short, note = ground_cycle_inputs(te.iloc[: 24 * 60], times)
    assert not short["Tf_cos"].any() and not short["Tf_sin"].any()
    assert note.startswith("depth not estimable; no seasonal cycle: Te spans 60 days")
