"""Inputs as they were measured (issue 31): instantaneous readings with the first-order
hold, interval means with the zero-order hold on the interval they describe."""

from __future__ import annotations

import numpy as np
import pandas as pd
import pytest

import heritage_bayes as hb
from heritage_bayes.config import parse_config
from heritage_bayes.errors import ConfigError
from heritage_bayes.io import align, read_csv, read_epw, read_knmi_hourly
from heritage_bayes.models import build_model, input_hold_of

TAU = 1800.0  # [s] a fast air node: the hold matters most
P1 = {"Ci": TAU * 100.0, "Ge": 100.0}  # [J/K], [W/K]: tau = Ci/Ge


def _one_node():
    return hb.model("thermal_1c", surfaces=(), ground=False)


def _ramp_response(t, a, b, x0, tau=TAU):
    """Exact response of dT/dt = (a + b t - T)/tau from T(0) = x0 [°C], t [s]."""
    return a + b * (t - tau) + (x0 - a + b * tau) * np.exp(-t / tau)


def _hourly(values, start="2021-01-01", **attrs):
    idx = pd.date_range(start, periods=len(values), freq="1h", tz="UTC", name="time")
    df = pd.DataFrame({"Te": values}, index=idx)
    df.attrs = {"units": {"Te": "°C"}, "averaged": (), "interval": "1h"} | attrs
    return df


def test_linear_input_gives_the_analytic_foh_response():
    """Readings of an exactly linear Te, aligned and simulated with the first-order hold:
    the analytic ramp response at every grid instant to round-off; the zero-order hold of
    the hour means lags it by about half a step (b·dt/2 for a fast node)."""
    n, b = 48, 0.5 / 3600.0  # [K/s]: 0.5 K per hour
    t = np.arange(n + 1) * 3600.0
    a, x0 = 2.0, 2.0
    al = align(_hourly(a + b * t))
    assert al.slopes is not None
    np.testing.assert_allclose(al.slopes["Te"].to_numpy(), 0.5, rtol=0, atol=1e-12)
    np.testing.assert_allclose(al.frame["Te"].to_numpy(), a + b * (t[:-1] + 1800.0), atol=1e-12)
    m = _one_node().with_slopes(("Te",))
    assert m.input_names == ("Te", "Te_slope")
    U = np.column_stack([al.frame["Te"].to_numpy(), al.slopes["Te"].to_numpy()])
    y = hb.simulate(m, P1, U, x0=[x0])[:, 0]
    exact = _ramp_response(t[:-1], a, b, x0)
    np.testing.assert_allclose(y, exact, rtol=0, atol=1e-10)
    zoh = hb.simulate(_one_node(), P1, U[:, :1], x0=[x0])[:, 0]
    # in the ramp's steady state the ZOH of the hour means sits below the exact response by
    # b·dt/(1 - e^(-dt/tau)) - b·dt/2 - b·tau = 0.078 K here (solve x = a + b t + C)
    dt, e = 3600.0, np.exp(-3600.0 / TAU)
    lag = b * dt / (1 - e) - b * dt / 2 - b * TAU
    assert lag == pytest.approx(0.0782588, abs=1e-6)
    np.testing.assert_allclose(exact[-10:] - zoh[-10:], lag, atol=1e-9)
    # a slope column of zeros is the zero-order hold of the means, bit for bit
    U0 = U.copy()
    U0[:, 1] = 0.0
    np.testing.assert_array_equal(
        hb.simulate(m, P1, U0, x0=[x0]), hb.simulate(_one_node(), P1, U[:, :1], x0=[x0])
    )


def test_foh_model_matches_the_closed_form_discretisation():
    """modal_form's slope columns reproduce discretize_foh's B0, B1 on a 2-node room."""
    m = hb.model("thermal_2c", surfaces=("S",))
    p = dict(Cw=5e7, Ci=3e5, Gw=200.0, Gi=800.0, Gfast=150.0, Gf=20.0, fI_S=3.0)
    rng = np.random.default_rng(1)
    Ub = rng.normal(size=(60, m.n_inputs)) * [3.0, 100.0, 1.0] + [5.0, 100.0, 8.0]
    Ad, B0, B1, _ = hb.rc.discretize_foh(m, p, 3600.0)
    x = np.array([5.0, 5.0])
    ref = []
    for k in range(59):
        ref.append(x[m.state_names.index("Ti")])
        x = Ad @ x + B0 @ Ub[k] + B1 @ Ub[k + 1]
    mf = m.with_slopes(m.input_names)
    U = np.hstack([0.5 * (Ub[:-1] + Ub[1:]), np.diff(Ub, axis=0)])
    y = hb.simulate(mf, p, U, x0=[5.0, 5.0])[:, 0]
    np.testing.assert_allclose(y, ref, rtol=1e-12, atol=1e-9)
    # derived quantities and gains ignore the slope columns (zero in steady state)
    d = hb.rc.derived_quantities(mf, p)
    assert not any("slope" in k for k in d)
    assert d == pytest.approx(hb.rc.derived_quantities(m, p))


@pytest.mark.parametrize("label", ["end", "start"])
def test_interval_means_are_constant_over_the_interval_they_describe(tmp_path, label):
    """Hour means labelled at the end or at the start of their hour: the aligned row of
    [t_k, t_k + 1h) holds that hour's mean, its slope is zero, and the simulation is the
    exact response to a piecewise-constant input."""
    rng = np.random.default_rng(7)
    means = rng.normal(5.0, 3.0, 30)  # hour k: [00:00 + k h, 01:00 + k h)
    hours = pd.date_range("2021-01-01 00:00", periods=30, freq="1h")
    stamps = hours + (pd.Timedelta("1h") if label == "end" else pd.Timedelta(0))
    path = tmp_path / f"means_{label}.csv"
    pd.DataFrame({"t": stamps.strftime("%Y-%m-%d %H:%M"), "T": means}).to_csv(path, index=False)
    df = read_csv(
        path, time_column="t", timezone="UTC", columns={"Te": "T"}, averaged=["Te"], label=label
    )
    al = align(df, step="1h")
    assert al.frame.index[0] == pd.Timestamp("2021-01-01 00:00", tz="UTC")
    np.testing.assert_allclose(al.frame["Te"].to_numpy(), means[: len(al.frame)], atol=1e-12)
    np.testing.assert_array_equal(al.slopes["Te"].to_numpy(), 0.0)
    m = _one_node().with_slopes(("Te",))
    U = np.column_stack([al.frame["Te"].to_numpy(), al.slopes["Te"].to_numpy()])
    y = hb.simulate(m, P1, U, x0=[5.0])[:, 0]
    a = np.exp(-3600.0 / TAU)
    x, ref = 5.0, []
    for u in U[:, 0]:  # exact for an input constant over each step
        ref.append(x)
        x = a * x + (1 - a) * u
    np.testing.assert_allclose(y, ref, atol=1e-12)


def test_readers_state_the_sampling_of_their_columns(shared_data):
    """KNMI: T and U read at the hour (instantaneous), Q the mean of the hour ending at
    HH; EPW: dry bulb at the hour, radiation over the hour ending at the stamp. The
    aligned slopes follow: the readings' change over the hour, zero for the means."""
    knmi = read_knmi_hourly(shared_data / "knmi-debilt" / "uurgeg_260_2011-2020.txt.gz")
    assert knmi.attrs["averaged"] == ("ghi", "wind") and knmi.attrs["interval"] == "1h"
    assert "Te" not in knmi.attrs["averaged"]
    w = knmi.loc["2015-06-01":"2015-06-04"]
    al = align(w[["Te", "ghi"]])
    np.testing.assert_array_equal(al.slopes["ghi"].to_numpy(), 0.0)
    te = w["Te"]
    k = al.frame.index[3]
    assert al.slopes["Te"].iloc[3] == pytest.approx(
        te.loc[k + pd.Timedelta("1h")] - te.loc[k], abs=1e-12
    )
    epw = read_epw(shared_data / "epw" / "BEL_VLG_Uccle.064470_TMYx.2007-2021.epw")
    assert set(epw.attrs["averaged"]) == {"ghi", "dni", "dhi"}
    assert "Te" not in epw.attrs["averaged"]


def _cfg(hold=None, demo=False):
    data = (
        {"demo": {}}
        if demo
        else {
            "weather": {"format": "knmi", "path": "w.txt"},
            "measurements": {
                "format": "csv",
                "path": "m.csv",
                "time_column": "t",
                "timezone": "UTC",
                "columns": {"Ti": "T"},
            },
        }
    )
    if hold is not None:
        data["input_hold"] = hold
    raw = {"data": data} | ({} if demo else {"site": {"latitude": 52.1, "longitude": 5.18}})
    return parse_config(raw | {"thermal": {"model": "thermal_2c"}}, base_dir=".")


def test_config_states_the_hold():
    """data.input_hold: exact (default for files: slope columns for every network input)
    or interval_mean (no slope columns; the demo's default, its generator's hold)."""
    assert input_hold_of(_cfg()) == "exact"
    m = build_model(_cfg(), "thermal")
    assert m.slope_inputs == m.network.inputs
    assert m.input_names[-len(m.slope_columns) :] == m.slope_columns
    assert build_model(_cfg("interval_mean"), "thermal").slope_inputs == ()
    assert input_hold_of(_cfg(demo=True)) == "interval_mean"
    assert input_hold_of(_cfg("exact", demo=True)) == "exact"
    with pytest.raises(ConfigError, match=r"input_hold"):
        _cfg("foh")
    from heritage_bayes.config import Data

    field = Data.model_fields["input_hold"]
    assert "first-order hold" in field.description


def test_slope_columns_join_the_inputs_before_the_outputs():
    """add_slope_columns (prepare and the projection's weather): each slope column after
    the inputs, before the outputs; the aligned change of a reading, zeros for an input
    made on the grid (Tf as an annual mean); flags and units follow the input."""
    from heritage_bayes.inputs import add_slope_columns

    te = 5.0 + np.arange(25.0)
    al = align(_hourly(te))
    frame = al.frame.copy()
    frame["Tf"] = 8.0
    frame["Ti"] = 10.0
    frame.attrs = {"units": {"Te": "°C", "Tf": "°C"}, "outputs": ("Ti",), "inputs": ("Te", "Tf")}
    flags = pd.DataFrame(False, index=frame.index, columns=frame.columns)
    flags.loc[flags.index[3], "Te"] = True
    m = hb.model("thermal_1c", surfaces=()).with_slopes(("Te", "Tf"))
    add_slope_columns(frame, [m], al.slopes, flags)
    assert list(frame.columns) == ["Te", "Tf", "Te_slope", "Tf_slope", "Ti"]
    assert list(flags.columns) == list(frame.columns) and flags["Te_slope"].iloc[3]
    np.testing.assert_array_equal(frame["Te_slope"], 1.0)
    np.testing.assert_array_equal(frame["Tf_slope"], 0.0)
    assert frame.attrs["units"]["Te_slope"] == "°C per step"
    assert frame.attrs["inputs"] == ("Te", "Tf", "Te_slope", "Tf_slope")
    assert frame.attrs["input_hold"] == "exact"
    U = frame[list(m.input_names)].to_numpy()
    assert np.isfinite(hb.simulate(m, {"Ci": 1e7, "Ge": 100.0, "Gf": 10.0}, U)).all()


def test_a_run_made_before_input_hold_keeps_its_hold():
    """load_run: a run whose summary recorded input names without slope columns (made
    before data.input_hold existed) is simulated as it was calibrated."""
    from heritage_bayes.run import hold_as_recorded

    m = build_model(_cfg(), "thermal")
    assert m.slope_inputs
    old = {"models": {"thermal": {"input_names": list(m.network.inputs)}}}
    assert hold_as_recorded({"thermal": m}, old)["thermal"].slope_inputs == ()
    new = {"models": {"thermal": {"input_names": list(m.input_names)}}}
    assert hold_as_recorded({"thermal": m}, new)["thermal"].slope_inputs == m.slope_inputs
    assert hold_as_recorded({"thermal": m}, {})["thermal"] is m
