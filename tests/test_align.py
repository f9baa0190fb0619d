"""align(): zero-order-hold grid convention, gap policy, report."""

from __future__ import annotations

import json

import numpy as np
import pandas as pd
import pytest

from _io_helpers import ESPOO, ORHOLM, knmi_2011_2020
from heritage_bayes.climate import surface_irradiance
from heritage_bayes.errors import DataError, InputError
from heritage_bayes.io import add_vapour_pressure, align, read_csv
from heritage_bayes.io.derive import RH_SENSOR_CEILING

T0 = pd.Timestamp("2021-01-01 00:00", tz="UTC")


def weather(n=48, freq="1h", start=T0, drop=(), attrs=True):
    """Te: instantaneous ramp 0.5 K/h; ghi: hour-ending average equal to its end hour."""
    idx = pd.date_range(start + pd.Timedelta(freq), periods=n, freq=freq)
    hours = (idx - T0) / pd.Timedelta("1h")
    df = pd.DataFrame({"Te": 0.5 * hours, "ghi": 10.0 * hours}, index=idx)
    df = df.drop(index=idx[list(drop)])
    if attrs:
        df.attrs = {"averaged": ("ghi",), "interval": freq, "source": "synthetic"}
    return df


def indoor(n=48, freq="1h", start=T0, offset="0h"):
    idx = pd.date_range(start + pd.Timedelta(offset), periods=n, freq=freq)
    hours = (idx - T0) / pd.Timedelta("1h")
    return pd.DataFrame({"Ti": 20.0 + 0.1 * hours}, index=idx)


# -- grid convention -------------------------------------------------------------------


def test_hour_ending_average_moves_to_interval_start():
    al = align(weather()[["ghi"]])
    f = al.frame
    assert f.index[0] == T0 and f.index.freq == pd.Timedelta("1h")
    # ghi stamped 01:00 (the mean over 00:00-01:00) is the input held over row 00:00
    assert f["ghi"].iloc[0] == 10.0 and f["ghi"].iloc[5] == 60.0
    assert f.index[-1] == T0 + pd.Timedelta("47h") and f["ghi"].iloc[-1] == 480.0
    assert al.frame.attrs["convention"] == "inputs: mean over [t, t+step); outputs: value at t"


def test_instantaneous_mean_over_bin():
    w = weather()
    al = align(w[["Te"]])
    f = al.frame
    assert f.index[0] == T0 + pd.Timedelta("1h")  # first reading
    np.testing.assert_allclose(f["Te"], 0.5 * (np.arange(len(f)) + 1.5))
    assert al.report.to_dict()["period"]["n_rows"] == 47


def test_period_is_intersection_of_inputs():
    al = align(weather())  # ghi covers [00:00, 48:00], Te [01:00, 48:00]
    assert al.frame.index[0] == T0 + pd.Timedelta("1h")
    assert al.frame.index[-1] == T0 + pd.Timedelta("47h")
    assert al.frame["ghi"].iloc[0] == 20.0
    np.testing.assert_allclose(al.frame["Te"].iloc[0], 0.75)


@pytest.mark.parametrize("step", ["30min", "2h", "3h", "90min"])
def test_resampling_is_exact_for_any_step(step):
    w = weather(n=24)
    al = align(w, step=step, start=T0 + pd.Timedelta("3h"), end=T0 + pd.Timedelta("21h"))
    dt = pd.Timedelta(step) / pd.Timedelta("1h")
    t0 = (al.frame.index - T0) / pd.Timedelta("1h")
    # Te = 0.5 t (linear): the bin mean is the value at the bin middle
    np.testing.assert_allclose(al.frame["Te"], 0.5 * (t0 + dt / 2))
    # ghi is piecewise constant 10*ceil(t): average over the bin numerically
    fine = np.linspace(0, 1, 3601)[:-1] + 0.5 / 3600
    expected = [np.mean(10 * np.ceil(a + fine * dt)) for a in t0]
    np.testing.assert_allclose(al.frame["ghi"], expected, rtol=1e-3)


def test_off_phase_instantaneous_series_matches_quadrature():
    idx = pd.date_range("2021-01-01 00:20", periods=30, freq="1h", tz="UTC")
    rng = np.random.default_rng(1)
    te = pd.DataFrame({"Te": rng.normal(5, 2, 30)}, index=idx)
    al = align(te)
    x = (idx - T0) / pd.Timedelta("1s")
    for t, value in al.frame["Te"].items():
        a = (t - T0) / pd.Timedelta("1s")
        q = np.linspace(a, a + 3600, 20001)
        assert value == pytest.approx(np.trapezoid(np.interp(q, x, te["Te"]), q) / 3600)


def test_measurements_are_instants():
    al = align(weather(), indoor(offset="30min"))  # readings at hh:30
    f = al.frame
    # value at t_k interpolated between the hh-1:30 and hh:30 readings
    hours = (f.index - T0) / pd.Timedelta("1h")
    np.testing.assert_allclose(f["Ti"], 20.0 + 0.1 * hours)
    assert al.outputs == ("Ti",) and al.inputs == ("Te", "ghi")
    assert not al.flags["Ti"].any()


def test_averaged_measurement_taken_at_mid_interval():
    m = indoor(offset="1h")
    m.attrs = {"averaged": ("Ti",), "interval": "1h"}
    al = align(weather(), m)
    hours = (al.frame.index - T0) / pd.Timedelta("1h")
    np.testing.assert_allclose(al.frame["Ti"], 20.0 + 0.1 * (hours + 0.5), equal_nan=True)


# -- gap policy ----------------------------------------------------------------------------


def test_short_input_gap_filled_and_flagged():
    w = weather(drop=(9, 10, 11))  # Te readings at 10:00, 11:00, 12:00 missing; ghi too
    al = align(w)
    f, flags = al.frame, al.flags
    ref = align(weather()).frame
    np.testing.assert_allclose(f["Te"], ref["Te"])  # linear data: interpolation is exact
    np.testing.assert_allclose(
        f["ghi"].drop(index=f.index[8:11]), ref["ghi"].drop(index=f.index[8:11])
    )
    # ghi stamped 10:00..12:00 cover [09:00, 12:00): rows 09, 10, 11 are flagged
    assert flags.index[flags["ghi"]].hour.tolist() == [9, 10, 11]
    # Te readings 10..12 influence bins from 09:00 to 12:00 (both neighbours' bins)
    assert flags.index[flags["Te"]].hour.tolist() == [9, 10, 11, 12]
    rep = al.report
    assert rep.interpolated == {"Te": 3, "ghi": 3}
    assert rep.flagged_rows == {"Te": 4, "ghi": 3}
    gap = rep.input_gaps[0].to_dict()
    assert gap == {
        "column": "Te", "start": "2021-01-01T10:00:00Z", "end": "2021-01-01T12:00:00Z",
        "n_missing": 3, "length": "3h", "length_hours": 3.0, "filled": True,
    }  # fmt: skip


def test_nan_values_are_gaps_too():
    w = weather()
    w.iloc[5:7, 0] = np.nan
    al = align(w)
    assert al.report.interpolated["Te"] == 2 and al.report.interpolated["ghi"] == 0


def test_long_input_gap_raises_with_list_and_start_avoids_it():
    w = weather(n=72, drop=range(9, 19))  # 10 h missing
    with pytest.raises(DataError) as err:
        align(w)
    msg = str(err.value)
    assert "2 input gap(s) longer than max_gap=6h" in msg
    assert "Te: 2021-01-01 10:00 to 2021-01-01 19:00 UTC (10h, 10 missing)" in msg
    assert "start=/end=" in msg
    al = align(w, start="2021-01-01 20:00")
    assert al.frame.index[0] == pd.Timestamp("2021-01-01 20:00", tz="UTC")
    assert not al.flags.any().any() and al.report.input_gaps == []
    assert len(align(w, max_gap="12h").report.input_gaps) == 2


def test_max_gap_zero_means_no_filling():
    with pytest.raises(DataError, match="max_gap=0s"):
        align(weather(drop=(5,)), max_gap="0h")


def test_measurement_gaps_stay_nan_and_are_reported():
    m = indoor().drop(index=indoor().index[10:14])
    al = align(weather(), m)
    f = al.frame
    assert f["Ti"].isna().sum() == 4
    assert al.report.measurement_missing == {"Ti": 4}
    gap = al.report.measurement_gaps[0]
    assert (gap.start.hour, gap.end.hour, gap.n_missing) == (10, 13, 4)
    assert not al.flags["Ti"].any()


def test_period_limited_by_measurements_and_rows_dropped():
    m = indoor(n=10, start=T0 + pd.Timedelta("5h"))
    al = align(weather(), m)
    assert al.frame.index[0] == T0 + pd.Timedelta("5h")
    assert al.frame.index[-1] == T0 + pd.Timedelta("14h")
    rep = al.report.to_dict()
    assert rep["rows_in"] == {"weather": 48, "measurements": 10}
    assert rep["rows_dropped"]["weather"] > 30 and rep["rows_dropped"]["measurements"] == 0


def test_report_is_json_serialisable():
    m = indoor().drop(index=indoor().index[10:14])
    al = align(weather(drop=(3,)), m)
    text = json.dumps(al.report.to_dict())
    back = json.loads(text)
    assert back["period"] == {
        "start": "2021-01-01T01:00:00Z", "end": "2021-01-03T00:00:00Z",
        "step": "1h", "n_rows": 47,
    }  # fmt: skip
    assert back["averaged_inputs"] == ["ghi"] and back["outputs"] == ["Ti"]
    assert back["sources"][0]["source"] == "synthetic"


# -- options and errors ----------------------------------------------------------------------


def test_start_end_outside_inputs():
    with pytest.raises(DataError, match="not covered by every input: Te covers"):
        align(weather(), start="2020-12-31")
    with pytest.raises(DataError, match="empty period"):
        align(weather(), start="2021-01-01 05:00", end="2021-01-01 05:30")
    al = align(weather(), start="2021-01-01 05:00", end="2021-01-01 08:00")
    assert len(al.frame) == 3  # end is exclusive


def test_errors_on_bad_tables():
    w = weather()
    with pytest.raises(DataError, match="appear in more than one table"):
        align(w, w[["Te"]])
    naive = w.tz_localize(None)
    with pytest.raises(DataError, match="tz-aware"):
        align(naive)
    irregular = w.copy()
    irregular.index = irregular.index.insert(5, T0 + pd.Timedelta("5h30min")).delete(6)
    irregular = irregular.sort_index()
    with pytest.raises(DataError, match="regular grid"):
        align(irregular)
    with pytest.raises(InputError, match="step"):
        align(w, step="-1h")
    with pytest.raises(InputError, match="averaged: unknown"):
        align(w, averaged=("Tx",))
    with pytest.raises(TypeError):
        align(w, maxgap="2h")


def test_attrs_absent_default_and_override():
    w = weather(attrs=False)
    assert align(w).report.averaged_inputs == ("ghi",)
    al = align(w, averaged=())
    assert al.report.averaged_inputs == ()
    # ghi now read as instantaneous: mean of 10 and 20 over [01:00, 02:00)
    assert al.frame["ghi"].iloc[0] == 15.0


def test_several_weather_tables_with_solar():
    w = weather()
    w.index = w.index + pd.Timedelta("2000D")
    s = surface_irradiance(w, {"latitude": 52, "longitude": 5, "altitude": 0})
    al = align([w, s])
    assert al.inputs == ("Te", "ghi", "N", "E", "S", "W")
    assert set(al.report.averaged_inputs) == {"ghi", "N", "E", "S", "W"}


# -- real data -------------------------------------------------------------------------------


@pytest.mark.shared_data
def test_knmi_year_averages_conserved(shared_data):
    k = knmi_2011_2020(shared_data)
    al = align(k[["Te", "RHe", "ghi"]], start="2015-01-01", end="2016-01-01")
    f = al.frame
    assert len(f) == 8760 and not f.isna().any().any()
    native = k["ghi"].loc["2015-01-01 01:00":"2016-01-01 00:00"]
    assert f["ghi"].sum() == pytest.approx(native.sum())
    assert f["ghi"].iloc[12] == native.iloc[12]  # row 12:00 = stamp 13:00


@pytest.mark.shared_data
def test_trh1_attic_with_measured_radiation(shared_data):
    folder = shared_data / "trh1-espoo-attic"
    fmi = read_csv(folder / "fmi.csv", time_column="t_UTC+2", timezone="UTC+2",
                   columns={"Te": "Te", "RHe": "RHe", "ghi": "Rglob", "dhi": "Rdif"},
                   averaged=())  # fmt: skip
    attic = read_csv(folder / "roofmiddle_airmiddle.csv", time_column="t_UTC+2",
                     timezone="UTC+2", columns={"Ti": "T", "RHi": "RH"})  # fmt: skip
    roof = surface_irradiance(fmi, ESPOO, {"roof_N": (27, 0), "roof_S": (27, 180)})
    assert roof.attrs["averaged"] == ()  # instantaneous in, instantaneous out
    al = align([add_vapour_pressure(fmi), roof], add_vapour_pressure(attic))
    assert al.outputs == ("Ti", "RHi", "Pi")
    assert len(al.frame) == 13920 and not al.frame.drop(columns="Pi").isna().any().any()
    # the attic's air reaches saturation: readings at the sensor's ceiling are censored
    at_ceiling = (al.frame["RHi"] >= RH_SENSOR_CEILING).to_numpy()
    assert 0 < at_ceiling.sum() < 100
    assert np.array_equal(al.frame["Pi"].isna().to_numpy(), at_ceiling)
    assert al.frame["roof_S"].sum() > al.frame["roof_N"].sum()


@pytest.mark.shared_data
def test_orholm_with_dmi_and_clear_sky_proxy(shared_data):
    folder = shared_data / "orholm"
    dmi = read_csv(folder / "DMI_outdoor-climate-data_2009-2021.csv", sep=";",
                   time_column=("Year", "Month", "Day", "Hour (UTC)"),
                   time_format="%Y %m %d %H", timezone="UTC",
                   columns={"Te": "TEMP C", "RHe": "%RH"})  # fmt: skip
    ind = read_csv(folder / "oerholm-indoor-climate-data_2009-2021.csv", sep=";",
                   time_column="DATE AND TIME", time_format="%d-%m-%Y %H:%M",
                   timezone="Europe/Copenhagen", columns={"Ti": "TEMP C", "RHi": "%RH"},
                   duplicates="first")  # fmt: skip
    dmi = dmi.loc["2010-01-01":"2011-12-31"]
    solar = surface_irradiance(dmi, ORHOLM, clear_sky=True)
    al = align([add_vapour_pressure(dmi), solar], add_vapour_pressure(ind))
    assert "clear-sky proxy" in al.frame.attrs["irradiance_source"]
    rep = al.report.to_dict()
    assert any("clear-sky proxy" in s.get("irradiance_source", "") for s in rep["sources"])
    # the ~29-day logger gap of December 2010 stays NaN
    assert rep["measurement_missing"]["Ti"] > 24 * 28
    longest = max(rep["measurement_gaps"], key=lambda g: g["length_hours"])
    assert longest["start"].startswith("2010-12") and longest["length_hours"] > 24 * 28
    assert not al.frame[list(al.inputs)].isna().any().any()


def test_indoor_vapour_pressure_censored_at_the_sensor_ceiling():
    idx = pd.date_range("2021-01-01", periods=4, freq="1h", tz="UTC")
    df = pd.DataFrame(
        {"Ti": 10.0, "RHi": [50.0, 98.9, RH_SENSOR_CEILING, 100.0], "Te": 5.0, "RHe": 100.0},
        index=idx,
    )
    out = add_vapour_pressure(df)
    pi = out["Pi"].to_numpy()
    assert np.isfinite(pi[:2]).all() and np.isnan(pi[2:]).all()
    assert np.isfinite(out["Pe"].to_numpy()).all()  # outdoors at saturation (fog): a reading
    assert f"NaN where RHi >= {RH_SENSOR_CEILING:g} %" in out.attrs["derived"]["Pi"]
