"""Conservation-risk indicators: hand-worked values, edge cases, batch, NaN, errors, real data."""

from __future__ import annotations

import math

import numpy as np
import pandas as pd
import pytest

from heritage_bayes.climate import risk
from heritage_bayes.climate.risk._vtt import SENSITIVITY, vtt_loop
from heritage_bayes.errors import InputError

YEAR = 8760
R = 8.314462618


def hours(n=YEAR):
    return np.arange(n, dtype=float)


def synthetic_year(seed=0, n=YEAR):
    """An unheated-store-like year: seasonal and daily T, RH with noise."""
    rng = np.random.default_rng(seed)
    t = hours(n)
    T = 12 + 6 * np.sin(2 * np.pi * t / n) + 1.5 * np.sin(2 * np.pi * t / 24)
    T = T + rng.normal(0, 0.5, n)
    RH = 62 + 8 * np.sin(2 * np.pi * t / n + 1.0) + 6 * np.sin(2 * np.pi * t / 24)
    RH = np.clip(RH + rng.normal(0, 2, n), 0, 100)
    return T, RH


def hourly_index(n=YEAR, start="2021-01-01"):
    return pd.date_range(start, periods=n, freq="h")


# --------------------------------------------------------------------------------------
# Chemical decay
# --------------------------------------------------------------------------------------


def test_lifetime_multiplier_hand_values():
    # LM = (50/RH)^1.3 exp[Ea/R (1/T_K - 1/293.15)]
    assert risk.lifetime_multiplier(20.0, 50.0) == pytest.approx(1.0, abs=1e-12)
    # 15 °C: exp(100e3/8.314 * (1/288.15 - 1/293.15)) = exp(0.7119) = 2.038
    assert risk.lifetime_multiplier(15.0, 50.0) == pytest.approx(2.038, abs=2e-3)
    # halving RH: 2^1.3 = 2.462 ("more than double")
    assert risk.lifetime_multiplier(20.0, 25.0) == pytest.approx(2**1.3, rel=1e-12)
    # varnish, Ea = 70 kJ/mol: exp(70e3/R * 5.919e-5) = 1.646
    expected = math.exp(70e3 / R * (1 / 288.15 - 1 / 293.15))
    assert risk.lifetime_multiplier(15.0, 50.0, Ea=70e3) == pytest.approx(expected, rel=1e-12)
    assert expected == pytest.approx(1.646, abs=2e-3)
    # warmer and wetter shortens life (sign check)
    assert risk.lifetime_multiplier(25.0, 50.0) < 1.0
    assert risk.lifetime_multiplier(20.0, 70.0) < 1.0


def test_preservation_index_hand_values():
    # (95220 - 134.9*45)/(8.314*293.15) + 0.0284*45 - 28.023 = 9.833 -> e^9.833/365 = 51.1 y
    assert risk.preservation_index(20.0, 45.0) == pytest.approx(51.1, abs=0.2)
    assert risk.preservation_index(20.0, 70.0) == pytest.approx(26.0, abs=0.2)
    # colder is better; freezing gives a large finite value
    pi_frozen = risk.preservation_index(-10.0, 50.0)
    assert math.isfinite(pi_frozen) and pi_frozen > 1000


def test_twpi_and_twlm_are_harmonic_means():
    T = np.r_[np.full(100, 20.0), np.full(100, 10.0)]
    RH = np.r_[np.full(100, 45.0), np.full(100, 60.0)]
    p1, p2 = risk.preservation_index(20.0, 45.0), risk.preservation_index(10.0, 60.0)
    assert risk.twpi(T, RH) == pytest.approx(2 / (1 / p1 + 1 / p2), rel=1e-12)
    assert risk.twpi(T, RH) < 0.5 * (p1 + p2)  # not the arithmetic mean
    l1, l2 = risk.lifetime_multiplier(20.0, 45.0), risk.lifetime_multiplier(10.0, 60.0)
    assert risk.twlm(T, RH) == pytest.approx(2 / (1 / l1 + 1 / l2), rel=1e-12)
    # constant climate: TWPI = PI
    assert risk.twpi(np.full(10, 20.0), np.full(10, 45.0)) == pytest.approx(p1, rel=1e-12)


# --------------------------------------------------------------------------------------
# Mechanical
# --------------------------------------------------------------------------------------


def test_emc_wood_hand_value_and_shape():
    # W=380.2, K=0.81863, K1=5.9612, K2=2.6068, Kh=0.40931 -> 1800/W * 1.9582 = 9.27 %
    assert risk.emc_wood(20.0, 50.0) == pytest.approx(9.27, abs=0.02)
    assert risk.emc_wood(20.0, 0.0) == 0.0
    rh = np.linspace(10, 95, 18)
    emc = risk.emc_wood(20.0, rh)
    assert np.all(np.diff(emc) > 0)
    # roughly 12 % at 65 % RH, about 20 % at 90 % (Wood Handbook table)
    assert risk.emc_wood(20.0, 65.0) == pytest.approx(12.0, abs=0.5)
    assert 19 < risk.emc_wood(20.0, 90.0) < 22
    assert math.isfinite(risk.emc_wood(-5.0, 80.0))


def test_emc_range_and_dimensional_change():
    T = np.full(48, 20.0)
    RH = np.r_[np.full(24, 40.0), np.full(24, 60.0)]
    r = risk.emc_range(T, RH)
    lo, hi = risk.emc_wood(20.0, 40.0), risk.emc_wood(20.0, 60.0)
    assert (r.min, r.max, r.range) == pytest.approx((lo, hi, hi - lo))
    dc = risk.dimensional_change(T, RH)
    assert dc == pytest.approx(100 * 0.00369 * (hi - lo))
    assert risk.dimensional_change(T, RH, coefficient=0.00158) < dc


# --------------------------------------------------------------------------------------
# Mould: VTT and lowest isopleth
# --------------------------------------------------------------------------------------


def vtt_rate(T, RH, k1=1.0, M=0.0, RHcrit=None, A=1, B=7, C=2, W=0, SQ=0):
    """One hour of VTT growth, written out from Hukka & Viitanen / Ojanen."""
    if RHcrit is None:
        RHcrit = max(-0.00267 * T**3 + 0.160 * T**2 - 3.13 * T + 100, 80.0)
    x = (RHcrit - RH) / (RHcrit - 100)
    Mmax = A + B * x - C * x**2
    k2 = max(1 - math.exp(2.3 * (M - Mmax)), 0)
    return k1 * k2 / (24 * 7 * math.exp(-0.68 * math.log(T) - 13.9 * math.log(RH)
                                        + 0.14 * W - 0.33 * SQ + 66.02))  # fmt: skip


def test_vtt_stays_zero_below_rhcrit_and_grows_above():
    n = 2000
    M = risk.vtt_mould_index(np.full(n, 20.0), np.full(n, 79.0))
    assert np.all(M == 0.0)
    M = risk.vtt_mould_index(np.full(n, 20.0), np.full(n, 90.0))
    # RHcrit(20 °C) = 80.04 %: x = 0.4998, Mmax = 3.999, k2 = 1 - e^(-9.2)
    assert M[0] == pytest.approx(vtt_rate(20.0, 90.0), rel=1e-12)
    assert M[0] == pytest.approx(1.4164e-3, rel=1e-4)
    assert np.all(np.diff(M) > 0)
    # k2 caps the index at Mmax = 1 + 7*0.5 - 2*0.25 = 4 for 90 % at 20 °C
    M = risk.vtt_mould_index(np.full(30000, 20.0), np.full(30000, 90.0))
    assert 3.9 < M[-1] <= 4.0


def test_vtt_rhcrit_depends_on_temperature():
    # RHcrit(5 °C) = -0.00267*125 + 0.16*25 - 3.13*5 + 100 = 88.02 %
    n = 500
    assert risk.vtt_mould_index(np.full(n, 5.0), np.full(n, 87.5))[-1] == 0.0
    M = risk.vtt_mould_index(np.full(n, 5.0), np.full(n, 89.0))
    assert M[0] == pytest.approx(vtt_rate(5.0, 89.0), rel=1e-12)


def test_vtt_decline_when_dry():
    wet, dry = 600, 100
    T = np.full(wet + dry, 20.0)
    RH = np.r_[np.full(wet, 97.0), np.full(dry, 50.0)]
    M = risk.vtt_mould_index(T, RH)
    d = np.diff(M[wet - 1 :])  # d[k-1] = change in dry hour k
    assert M[wet - 1] > 1.0
    np.testing.assert_allclose(d[:6], -0.00133)
    np.testing.assert_allclose(d[6:24], 0.0)
    np.testing.assert_allclose(d[24:], -0.000667)
    # resistant class declines ten times slower
    M_r = risk.vtt_mould_index(T, RH, sensitivity="R", M0=1.0)
    np.testing.assert_allclose(np.diff(M_r[wet - 1 :])[:6], -0.000133)


def test_vtt_sensitivity_classes_order():
    n = 3000
    T, RH = np.full(n, 22.0), np.full(n, 95.0)
    peaks = [risk.vtt_mould_index(T, RH, sensitivity=s)[-1] for s in ("VS", "S", "MR", "R")]
    assert peaks[0] > peaks[1] > peaks[2] > peaks[3] > 0
    spruce = risk.vtt_mould_index(T, RH, species="spruce")[-1]
    kiln = risk.vtt_mould_index(T, RH, surface="kiln-dried")[-1]
    assert spruce < peaks[0] < kiln


def test_vtt_freezing():
    n = 200
    T, RH = np.full(n, -5.0), np.full(n, 100.0)
    assert np.all(risk.vtt_mould_index(T, RH) == 0.0)  # no growth at T <= 0 °C
    M = risk.vtt_mould_index(T, RH, M0=2.0)  # frozen hours count as unfavourable
    assert M[5] == pytest.approx(2.0 - 6 * 0.00133)
    assert np.all(risk.vtt_mould_index(T, RH, M0=2.0, frozen="hold") == 2.0)


def test_vtt_numba_matches_python_reference():
    rng = np.random.default_rng(3)
    T = rng.uniform(-5, 35, (3, 3000))
    RH = rng.uniform(60, 100, (3, 3000))
    T[1, 100:130] = np.nan
    for omit in (False, True):
        for cls in ("VS", "MR"):
            k1l, k1h, A, B, C, RHmin, Cmat = SENSITIVITY[cls]
            args = (k1l, k1h, A, B, C, RHmin, Cmat, 0.0, 0.0, 0.5, True, omit)
            ref = np.empty_like(T)
            peak_ref = vtt_loop(T, RH, *args, ref)
            pol = "omit" if omit else "propagate"
            got = risk.vtt_mould_index(T, RH, sensitivity=cls, M0=0.5, nan_policy=pol)
            np.testing.assert_allclose(got, ref, rtol=1e-12, equal_nan=True)
            np.testing.assert_allclose(np.fmax.reduce(got, axis=1)[[0, 2]], peak_ref[[0, 2]])


def test_lowest_isopleth_hand_values():
    # 100 [0.02633 cosh(0.10083 (20 - 30)) + 0.7153] = 75.62 %
    assert risk.lowest_isopleth(20.0) == pytest.approx(75.6, abs=0.05)
    assert risk.lowest_isopleth(30.0) == pytest.approx(100 * (0.02633 + 0.7153))
    assert risk.lowest_isopleth(30.0, growth_rate=4) == pytest.approx(100 * (0.02633 + 0.8701))
    T = np.linspace(0, 40, 9)
    assert np.all(risk.lowest_isopleth(T, 1) > risk.lowest_isopleth(T, 0.5))
    assert risk.lowest_isopleth(-1.0) > 100.0  # nothing counts below freezing


def test_hours_above_isopleth():
    T = np.full(YEAR, 20.0)
    RH = np.full(YEAR, 50.0)
    RH[1000:1100] = 80.0
    assert risk.hours_above_isopleth(T, RH) == pytest.approx(100.0)
    assert risk.hours_above_isopleth(T, RH, growth_rate=0.5) == 0.0  # LIM0.5(20) = 80.8 %
    two = np.r_[RH, RH]
    assert risk.hours_above_isopleth(np.r_[T, T], two) == pytest.approx(100.0)  # per year
    assert risk.hours_above_isopleth(np.r_[T, T], two, per_year=False) == 200.0
    assert risk.hours_above_isopleth(np.full(YEAR, -5.0), np.full(YEAR, 100.0)) == 0.0
    with pytest.raises(InputError, match="at least one year"):
        risk.hours_above_isopleth(T[:100], RH[:100])
    assert risk.hours_above_isopleth(T[:1200], RH[:1200], per_year=False) == 100.0


# --------------------------------------------------------------------------------------
# ASHRAE and EN 15757
# --------------------------------------------------------------------------------------


def test_constant_climate_ashrae_and_en15757():
    T, RH = np.full(YEAR, 18.0), np.full(YEAR, 50.0)
    res = risk.ashrae_classes(T, RH)
    assert list(res.share.index) == ["AA", "As", "A", "B", "C", "D"]
    np.testing.assert_allclose(res.share, 100.0)
    assert res.best == "AA"
    assert (res.T_setpoint, res.RH_setpoint) == pytest.approx((18.0, 50.0))
    band = risk.en15757_band(RH)
    assert band.share_outside == 0.0
    assert (band.lower_offset, band.upper_offset) == (-10.0, 10.0)
    np.testing.assert_allclose(band.seasonal, 50.0)
    np.testing.assert_allclose(band.upper - band.lower, 20.0)


def test_ashrae_short_term_rh_fluctuations():
    # ±7 %RH daily swing around 50 %: beyond AA/As (±5), within A (±10)
    t = hours()
    T = np.full(YEAR, 20.0)
    RH = 50 + 7 * np.sin(2 * np.pi * t / 24)
    res = risk.ashrae_classes(T, RH, edges="wrap")  # periodic: no edge effects
    assert res.best == "A"
    assert res.share["A"] == 100.0
    # AA, As: |RH - 50| <= 5 at 7 of every 12 hourly samples of 7 sin(2πt/24)
    assert res.share["AA"] == pytest.approx(100 * 7 / 12, abs=1e-9)
    assert res.share["As"] == pytest.approx(100 * 7 / 12, abs=1e-9)
    # with truncated windows the seasonal estimate is biased by ~0.1 %RH at the ends
    assert risk.ashrae_classes(T, RH).share["As"] == pytest.approx(100 * 7 / 12, abs=0.5)
    np.testing.assert_allclose(res.share_T, 100.0)


def test_ashrae_seasonal_temperature_against_pandas_rolling():
    t = hours()
    T = 18 + 7 * np.sin(2 * np.pi * t / YEAR)
    RH = np.full(YEAR, 50.0)
    res = risk.ashrae_classes(T, RH, nested=False)
    # independent seasonal component: pandas centred rolling mean, truncated at the ends
    s = pd.Series(T).rolling(721, center=True, min_periods=1).mean().to_numpy()
    m = T.mean()
    ok_aa = (np.abs(s - m) <= 5) & (np.abs(T - s) <= 2)
    assert res.share_T["AA"] == pytest.approx(100 * ok_aa.mean(), abs=1e-9)
    ok_as = (s - m >= -10) & (s - m <= 5) & (np.abs(T - s) <= 2)
    assert res.share_T["As"] == pytest.approx(100 * ok_as.mean(), abs=1e-9)
    assert res.share_T["B"] == 100.0
    # "setpoint" method is more lenient when the season overshoots its allowance
    lenient = risk.ashrae_classes(T, RH, method="setpoint", nested=False)
    assert lenient.share_T["AA"] >= res.share_T["AA"]


def test_ashrae_nesting_threshold_and_setpoint():
    T, RH = np.full(YEAR, 18.0), np.full(YEAR, 80.0)  # stable but damp
    assert risk.ashrae_classes(T, RH).best is None
    assert risk.ashrae_classes(T, RH).share["AA"] == 0.0
    assert risk.ashrae_classes(T, RH, nested=False).best == "AA"
    # 96 % of hours compliant: achieved at threshold 95, not at 99
    RH = np.full(YEAR, 50.0)
    RH[: int(0.04 * YEAR)] = 58.0
    assert risk.ashrae_classes(T, RH, RH_setpoint=50.0).best == "AA"
    # at 99 %, As (the set point may follow the 30-day mean) and no longer AA
    assert risk.ashrae_classes(T, RH, RH_setpoint=50.0, threshold=99).best == "As"
    # an explicit set point: 18 °C is 4 K below 22 °C (within AA's seasonal ±5 K) but
    # 7 K below 25 °C (beyond AA, within As's −10 K)
    assert risk.ashrae_classes(T, np.full(YEAR, 50.0), T_setpoint=22.0).best == "AA"
    res = risk.ashrae_classes(T, np.full(YEAR, 50.0), T_setpoint=25.0)
    assert res.share["AA"] == 0.0
    assert res.best == "As"
    assert res.T_setpoint == 25.0


def test_en15757_band_noise_and_min_band_modes():
    rng = np.random.default_rng(1)
    RH = 55 + 10 * np.sin(2 * np.pi * hours() / YEAR) + rng.normal(0, 8, YEAR)
    band = risk.en15757_band(RH)
    # percentile band wider than ±10: the share outside is 14 % by construction
    assert band.lower_offset < -10 and band.upper_offset > 10
    assert band.share_outside == pytest.approx(14.0, abs=0.1)
    # seasonal cycle = centred 30-day moving average (independent: pandas)
    s = pd.Series(RH).rolling(721, center=True, min_periods=1).mean().to_numpy()
    np.testing.assert_allclose(band.seasonal, s, atol=1e-9)
    # narrow fluctuations: the minimum band takes over
    small = 55 + rng.normal(0, 1, YEAR)
    half = risk.en15757_band(small)
    assert (half.lower_offset, half.upper_offset) == (-10.0, 10.0)
    assert half.share_outside == 0.0
    width = risk.en15757_band(small, min_band_mode="width")
    assert width.upper_offset - width.lower_offset == pytest.approx(10.0)
    assert width.share_outside < 1.0
    wrapped = risk.en15757_band(RH, edges="wrap")
    assert wrapped.share_outside == pytest.approx(14.0, abs=0.1)


def test_series_in_series_out():
    idx = hourly_index()
    T, RH = synthetic_year()
    Ts, RHs = pd.Series(T, index=idx), pd.Series(RH, index=idx)
    band = risk.en15757_band(RHs)
    assert isinstance(band.upper, pd.Series) and band.upper.index.equals(idx)
    assert isinstance(band.outside, pd.Series)
    M = risk.vtt_mould_index(Ts, RHs)
    assert isinstance(M, pd.Series) and M.index.equals(idx)
    pi = risk.preservation_index(Ts, RHs)
    assert isinstance(pi, pd.Series)
    assert isinstance(risk.emc_wood(20.0, 50.0), float)
    assert isinstance(risk.lowest_isopleth(Ts), pd.Series)
    assert risk.twpi(Ts, RHs) == pytest.approx(risk.twpi(T, RH))


# --------------------------------------------------------------------------------------
# assess, batch
# --------------------------------------------------------------------------------------


def test_assess_table():
    T, RH = synthetic_year()
    table = risk.assess(T, RH)
    assert list(table.columns) == ["indicator", "value", "unit", "rating", "hours"]
    assert set(table["hours"]) == {len(T)} and table.attrs["hours_dropped"] == 0
    t = table.set_index("indicator")
    assert t.loc["twpi", "value"] == pytest.approx(risk.twpi(T, RH))
    assert t.loc["twpi", "unit"] == "years"
    assert t.loc["lifetime_multiplier[paper]", "value"] == pytest.approx(risk.twlm(T, RH))
    assert t.loc["lifetime_multiplier[varnish]", "value"] == pytest.approx(
        risk.twlm(T, RH, Ea=70e3)
    )
    assert t.loc["vtt_mould_index_max", "value"] == pytest.approx(risk.vtt_mould_index(T, RH).max())
    ash = risk.ashrae_classes(T, RH)
    for c in ("AA", "As", "A", "B", "C", "D"):
        assert t.loc[f"ashrae_{c}", "value"] == pytest.approx(ash.share[c])
    assert t.loc["ashrae_best_class", "rating"] == (ash.best or "none")
    assert t.loc["en15757_outside", "value"] == pytest.approx(risk.en15757_band(RH).share_outside)
    tow = 8760 * np.mean((RH > 80) & (T > 0))
    assert t.loc["time_of_wetness", "value"] == pytest.approx(tow, rel=1e-12)
    assert t.loc["time_of_wetness", "unit"] == "h/year"
    grades = {"", "good", "OK", "risk", "AA", "As", "A", "B", "C", "D", "none"}
    assert set(t["rating"]) <= grades | {f"τ{i}" for i in range(1, 6)}
    # options reach the functions; unknown options are rejected
    t2 = risk.assess(T, RH, vtt={"sensitivity": "R"}, lm={"Ea": {"film": 90e3}})
    assert "lifetime_multiplier[film]" in set(t2["indicator"])
    with pytest.raises(InputError, match="unknown option"):
        risk.assess(T, RH, vtt={"sensitivty": "R"})
    with pytest.raises(InputError, match="sensitivity"):
        risk.assess(T, RH, vtt={"sensitivity": "very"})


def test_assess_short_series_and_groups():
    T, RH = synthetic_year(n=2000)
    with pytest.raises(InputError, match=r"at least one year.*got 2000 h"):
        risk.assess(T, RH)
    # TWPI and time of wetness depend on the season covered: a year or more only
    with pytest.raises(InputError, match=r"\['chemical'\].*indicators=\['mechanical'\]"):
        risk.assess(T, RH, indicators=["chemical", "mechanical"])
    t = risk.assess(T, RH, indicators=["mechanical"])
    assert "emc_range" in set(t["indicator"]) and "twpi" not in set(t["indicator"])
    with pytest.raises(InputError, match="indicators"):
        risk.assess(T, RH, indicators=["chemistry"])


def test_batch_equals_loop_of_single_series():
    draws = np.array([synthetic_year(seed=s) for s in range(4)])
    T, RH = draws[:, 0], draws[:, 1]
    RH[2] = np.clip(RH[2] + 20, 0, 100)  # one damp draw
    batch = risk.assess_batch(T, RH, chunk_size=3)
    assert list(batch.index) == [0, 1, 2, 3]
    for i in range(4):
        single = risk.assess(T[i], RH[i]).set_index("indicator")
        for name in batch.columns:
            if name == "ashrae_best_class":
                assert batch.loc[i, name] == single.loc[name, "rating"]
            else:
                assert batch.loc[i, name] == pytest.approx(single.loc[name, "value"], rel=1e-12)
    # the individual functions give per-draw arrays equal to per-row calls
    np.testing.assert_allclose(
        risk.twpi(T, RH), [risk.twpi(a, b) for a, b in zip(T, RH, strict=True)]
    )
    M = risk.vtt_mould_index(T, RH)
    np.testing.assert_allclose(M[2], risk.vtt_mould_index(T[2], RH[2]))
    ash = risk.ashrae_classes(T, RH)
    np.testing.assert_allclose(ash.share.loc[1], risk.ashrae_classes(T[1], RH[1]).share)
    en = risk.en15757_band(RH)
    assert en.share_outside[3] == risk.en15757_band(RH[3]).share_outside
    # one temperature series shared by all RH draws
    shared = risk.assess_batch(T[0], RH)
    assert shared.loc[1, "twpi"] == pytest.approx(risk.twpi(T[0], RH[1]))


def test_summarize():
    draws = np.array([synthetic_year(seed=s) for s in range(5)])
    per_draw = risk.assess_batch(draws[:, 0], draws[:, 1])
    summ = risk.summarize(per_draw, quantiles=(0.1, 0.5, 0.9))
    assert list(summ.columns) == ["indicator", "unit", "mean", "q10", "q50", "q90", "rating"]
    s = summ.set_index("indicator")
    assert s.loc["twpi", "q50"] == pytest.approx(per_draw["twpi"].median())
    assert s.loc["twpi", "unit"] == "years"
    assert s.loc["ashrae_best_class", "rating"].endswith("%")
    with pytest.raises(InputError, match="quantiles"):
        risk.summarize(per_draw, quantiles=(5, 50))


# --------------------------------------------------------------------------------------
# NaN policy
# --------------------------------------------------------------------------------------


def test_nan_policies():
    T, RH = synthetic_year()
    RHn = RH.copy()
    RHn[[10, 500, 501]] = np.nan
    keep = ~np.isnan(RHn)
    assert math.isnan(risk.twpi(T, RHn))
    assert risk.twpi(T, RHn, nan_policy="omit") == pytest.approx(risk.twpi(T[keep], RH[keep]))
    with pytest.raises(InputError, match="3 NaN"):
        risk.twpi(T, RHn, nan_policy="raise")
    r = risk.emc_range(T, RHn, nan_policy="omit")
    assert r.max == pytest.approx(risk.emc_range(T[keep], RH[keep]).max)
    assert math.isnan(risk.emc_range(T, RHn).max)
    assert math.isnan(risk.en15757_band(RHn).share_outside)
    assert 0 < risk.en15757_band(RHn, nan_policy="omit").share_outside < 20
    ash = risk.ashrae_classes(T, RHn, nan_policy="omit")
    assert ash.share.notna().all() and ash.best is not None
    assert risk.ashrae_classes(T, RHn).share.isna().all()
    table = risk.assess(T, RHn, nan_policy="omit")
    assert table["value"].notna().all()
    assert set(table["hours"]) == {len(T) - 3}  # computed on the valid hours, stated
    with pytest.raises(InputError, match="3 NaN"):  # the default refuses a gap
        risk.assess(T, RHn)
    # propagate (asked for): every indicator NaN
    assert risk.assess(T, RHn, nan_policy="propagate")["value"].isna().all()
    with pytest.raises(InputError, match="nan_policy"):
        risk.twpi(T, RH, nan_policy="skip")


def test_vtt_nan_policy():
    n = 400
    T = np.full(n, 20.0)
    RH = np.full(n, 95.0)
    RHn = RH.copy()
    RHn[100:110] = np.nan
    M_prop = risk.vtt_mould_index(T, RHn)
    assert np.all(np.isnan(M_prop[100:]))
    assert np.all(np.isfinite(M_prop[:100]))
    M_omit = risk.vtt_mould_index(T, RHn, nan_policy="omit")
    assert np.all(np.isnan(M_omit[100:110]))
    # the state is carried across the gap: same as the series without those hours
    M_ref = risk.vtt_mould_index(T[:-10], RH[:-10])
    np.testing.assert_allclose(M_omit[110:], M_ref[100:], rtol=1e-12)


# --------------------------------------------------------------------------------------
# Errors
# --------------------------------------------------------------------------------------


def test_errors_on_bad_input():
    T, RH = synthetic_year()
    with pytest.raises(
        InputError, match=r"RH looks like a fraction \(max 0\.93\); expected percent 0–100"
    ):
        risk.twpi(T, np.linspace(0.3, 0.93, YEAR))
    with pytest.raises(InputError, match="looks like a fraction"):
        risk.lifetime_multiplier(20.0, 0.5)
    with pytest.raises(InputError, match=r"at most 100 %.*np.clip"):
        risk.emc_wood(20.0, 101.0)
    with pytest.raises(InputError, match="negative"):
        risk.preservation_index(20.0, -1.0)
    with pytest.raises(InputError, match="kelvin"):
        risk.twpi(T + 273.15, RH)
    with pytest.raises(InputError, match=r"same shape.*\(8760,\).*\(8759,\)"):
        risk.twpi(T, RH[:-1])
    with pytest.raises(InputError, match="matching shapes"):
        risk.emc_wood(np.ones(3) * 20, np.ones(4) * 50)
    with pytest.raises(InputError, match="DataFrame"):
        risk.twpi(pd.DataFrame({"T": T}), RH)
    with pytest.raises(InputError, match="3-D"):
        risk.twpi(T.reshape(1, 1, -1), RH.reshape(1, 1, -1))
    with pytest.raises(InputError, match="at least one year"):
        risk.en15757_band(RH[:5000])
    with pytest.raises(InputError, match="assess_batch"):
        risk.assess(np.tile(T, (2, 1)), np.tile(RH, (2, 1)))
    with pytest.raises(InputError, match="sensitivity must be one of 'VS', 'S', 'MR', 'R'"):
        risk.vtt_mould_index(T, RH, sensitivity="high")
    with pytest.raises(InputError, match="growth_rate"):
        risk.lowest_isopleth(20.0, growth_rate=1.5)
    with pytest.raises(InputError, match="min_band_mode"):
        risk.en15757_band(RH, min_band_mode="total")
    with pytest.raises(InputError, match="method"):
        risk.ashrae_classes(T, RH, method="martens")
    with pytest.raises(InputError, match="threshold"):
        risk.ashrae_classes(T, RH, threshold=0.95 * 0)
    with pytest.raises(InputError, match="T is None"):
        risk.twpi(None, RH)
    with pytest.raises(InputError, match="must be a dict of options"):
        risk.assess(T, RH, vtt=["VS"])
    with pytest.raises(InputError, match="T_setpoint"):
        risk.ashrae_classes(T, RH, T_setpoint="20")
    with pytest.raises(TypeError):
        risk.twpi(T, RH, nan=True)  # unknown keywords are not swallowed
    assert issubclass(InputError, ValueError)


def test_errors_on_irregular_or_misaligned_index():
    T, RH = synthetic_year()
    idx = hourly_index()
    gap = idx.delete(100)
    with pytest.raises(InputError, match=r"regular hourly.*step of 0 days 02:00:00"):
        risk.twpi(pd.Series(T[:-1], index=gap), pd.Series(RH[:-1], index=gap))
    with pytest.raises(InputError, match="different indices"):
        risk.twpi(pd.Series(T, index=idx), pd.Series(RH, index=hourly_index(start="2022-01-01")))
    # a Series with a plain RangeIndex is taken as hourly
    assert math.isfinite(risk.twpi(pd.Series(T), pd.Series(RH)))


# --------------------------------------------------------------------------------------
# Real data: Ørholm storage building (National Museum of Denmark)
# --------------------------------------------------------------------------------------


@pytest.mark.shared_data
def test_orholm_measured_year(shared_data):
    path = shared_data / "orholm" / "oerholm-indoor-climate-data_2009-2021.csv"
    if not path.is_file():
        pytest.skip(f"{path} not found")
    raw = pd.read_csv(path, sep=";", skipinitialspace=True)
    raw.columns = raw.columns.str.strip()
    when = pd.to_datetime(raw["DATE AND TIME"].str.strip(), format="%d-%m-%Y %H:%M")
    data = raw[["TEMP C", "%RH"]].astype(float).set_axis(when)
    # local clock time: the autumn hour repeats, the spring hour is missing
    with pytest.raises(InputError, match="regular hourly"):
        risk.twpi(data["TEMP C"].loc["2011"], data["%RH"].loc["2011"])
    year = data[~data.index.duplicated()].resample("h").mean().loc["2011"]
    assert len(year) == YEAR
    T, RH = year["TEMP C"], year["%RH"]
    assert T.isna().sum() < 24  # a few hours at most

    table = risk.assess(T, RH, nan_policy="omit").set_index("indicator")
    v = table["value"]
    assert 40 < v["twpi"] < 120  # ~16 °C, ~50 % store: PI(16 °C, 50 %) = 74 y
    assert 1.2 < v["lifetime_multiplier[paper]"] < 2.5
    assert 7 < v["emc_min"] <= v["emc_max"] < 12.5
    assert v["vtt_mould_index_max"] < 0.1
    assert v["hours_above_LIM0"] < 100
    assert 0 <= v["en15757_outside"] <= 20
    shares = [v[f"ashrae_{c}"] for c in ("AA", "As", "A", "B", "C", "D")]
    assert all(0 <= s <= 100 for s in shares)
    assert shares == sorted(shares)  # nested classes
    assert v["ashrae_D"] == 100.0
    assert table.loc["ashrae_best_class", "rating"] in {"AA", "As", "A", "B", "C", "D"}


def test_yearly_indicators_accept_a_typical_year_on_a_grid():
    """An aligned TMY/EPW year has 8759 hours (issue 12): counted as a year."""
    T, RH = synthetic_year(n=8759)
    t = risk.assess(T, RH).set_index("indicator")
    assert np.isfinite(t.loc["vtt_mould_index_max", "value"])
    assert np.isfinite(t.loc["en15757_outside", "value"])
    with pytest.raises(InputError, match=r"at least one year.*8736 h.*got 8735 h"):
        risk.assess(T[:8735], RH[:8735])


def test_annual_indicators_use_complete_years_only():
    """TWPI and the annual counts of a year and a half equal those of its first year
    (the half year after it is left out, and counted), and do not depend on the
    month the year starts in: the same year rotated (June-May) gives the same values."""
    T, RH = synthetic_year(n=8760 + 4380, seed=3)
    RH = np.clip(RH + 12.0, 0.0, 100.0)  # damp: a time of wetness of hundreds of hours
    full = risk.assess(T, RH).set_index("indicator")
    assert full.loc["time_of_wetness", "value"] > 500
    first = risk.assess(T[:8760], RH[:8760]).set_index("indicator")
    assert risk.assess(T, RH).attrs["hours_dropped"] == 4380
    for name in ("twpi", "time_of_wetness", "hours_above_LIM0", "lifetime_multiplier[paper]"):
        assert full.loc[name, "value"] == pytest.approx(first.loc[name, "value"], rel=1e-12)
        assert full.loc[name, "hours"] == 8760
    rolled = risk.assess(np.roll(T[:8760], -3624), np.roll(RH[:8760], -3624))
    rolled = rolled.set_index("indicator")
    for name in ("twpi", "time_of_wetness", "hours_above_LIM0", "lifetime_multiplier[paper]"):
        assert rolled.loc[name, "value"] == pytest.approx(first.loc[name, "value"], rel=1e-9)
    # a January-May record is refused for them (it would give a far longer TWPI)
    with pytest.raises(InputError, match="at least one year"):
        risk.assess(T[:3624], RH[:3624], indicators=["chemical"])


def test_registry_covers_every_column():
    from heritage_bayes.climate.risk.registry import check_indicator_names, indicator_info

    T, RH = synthetic_year()
    batch = risk.assess_batch(T[None], RH[None])
    for c in batch.columns:
        info = indicator_info(c)
        assert info.unit == batch.attrs["units"][c]
        assert info.definition and info.source and info.period
    assert indicator_info("ashrae_AA").name == "Hours within ASHRAE class AA"
    assert indicator_info("lifetime_multiplier[paper]").worse == -1
    with pytest.raises(InputError, match=r"known: .*twpi"):
        indicator_info("metal_corrosion")
    with pytest.raises(InputError, match=r"thresholds\[1\].indicator.*'twpix'.*'twpi'"):
        check_indicator_names(["twpi", "twpix"], batch.columns, "thresholds")


def test_registry_markdown_for_the_docs():
    from heritage_bayes.climate.risk.registry import INDICATORS, as_markdown

    md = as_markdown()
    rows = [r for r in md.splitlines() if r.startswith("| `")]
    assert len(rows) == len(INDICATORS)
    assert all(r.count(" | ") == 6 for r in rows)
    assert "`en15757_outside_baseline`" in md and "ISO 9223" in md


def test_time_of_wetness_needs_wet_and_above_freezing():
    """ISO 9223: hours with RH > 80 % and T > 0 °C; frozen or dry hours do not count."""
    n = 8760
    wet_warm = risk.assess(np.full(n, 5.0), np.full(n, 95.0), indicators=["chemical"])
    frozen = risk.assess(np.full(n, -5.0), np.full(n, 95.0), indicators=["chemical"])
    dry = risk.assess(np.full(n, 5.0), np.full(n, 80.0), indicators=["chemical"])
    tow = [t.set_index("indicator").loc["time_of_wetness"] for t in (wet_warm, frozen, dry)]
    assert [v["value"] for v in tow] == [8760.0, 0.0, 0.0]
    assert [v["rating"] for v in tow] == ["τ5", "τ1", "τ1"]
