"""The fused, compiled risk pass (issue 12's performance target) against the numpy path.

:func:`heritage_bayes.climate.risk.fused.assess_fused` must give the table of
:func:`~heritage_bayes.climate.risk.assess_batch` (and of :func:`assess` row by row):

* the lifetime multipliers and the TWPI to 1e-12 relative: the vectorised exp/log are
  within 2 ulp (4.5e-16) of the C library's, and the hourly terms are summed in another
  order; over n ≤ 3e5 positive terms that is ≤ n·eps ≈ 7e-11 in the worst case and
  ~1e-15 in practice, 1e-12 leaves room;
* everything else bit for bit (the same arithmetic: moving averages by sequential
  cumulative sums, numpy's pairwise annual means, the comparisons, the EMC, the VTT
  recursion, exact order statistics for the EN 15757 percentiles). The count indicators
  (hours above LIM0, the ASHRAE and EN 15757 shares) could in principle differ when an
  hour sits within an ulp of a limit; on these seeded series they do not.

Series: seeded years of 8 759 h (a TMY on the UTC grid), 8 784 h (a leap year), 8 760 h
and partial years (20 000 h), RH pinned at 100 % (capped) and at 0 % for hours.
"""

from __future__ import annotations

import numpy as np
import pandas as pd
import pytest

from heritage_bayes.climate import risk
from heritage_bayes.climate._vecmath import psat_water, vcosh, vexp, vlog
from heritage_bayes.climate.psychro import saturation_vapour_pressure
from heritage_bayes.climate.risk._fused import pairwise_sum
from heritage_bayes.climate.risk.fused import assess_fused, fused_plan
from heritage_bayes.climate.risk.standards import ClimateClass
from heritage_bayes.errors import InputError

ROUNDED = ("lifetime_multiplier", "twpi")  # vectorised exp/log, other summation order
RTOL = 1e-12


def series(d, n, seed, *, wet=False):
    """``d`` seeded draws of ``n`` hours: seasonal and daily cycles, AR(1)-like noise."""
    rng = np.random.default_rng(seed)
    t = np.arange(n)
    T = 12 + 8 * np.sin(2 * np.pi * t / 8766) + 3 * np.sin(2 * np.pi * t / 24)
    T = T + np.cumsum(rng.normal(0, 0.2, (d, n)), axis=1) * 0.1 + rng.normal(0, 0.5, (d, n))
    mid = 88 if wet else 66
    RH = mid + 12 * np.sin(2 * np.pi * t / 8766 + 1) + 6 * np.sin(2 * np.pi * t / 24)
    RH = np.clip(RH + rng.normal(0, 3, (d, n)), 0, 100)
    return T, RH


def assert_same(ref: pd.DataFrame, got: pd.DataFrame):
    assert list(got.columns) == list(ref.columns)
    assert got.index.equals(ref.index)
    assert got.attrs["units"] == ref.attrs["units"]
    for c in ref.columns:
        a, b = ref[c], got[c]
        if not pd.api.types.is_float_dtype(a):
            assert a.dtype == b.dtype, c
            assert (a.astype(str) == b.astype(str)).all(), c
        elif c.startswith(ROUNDED):
            np.testing.assert_allclose(b, a, rtol=RTOL, atol=0, err_msg=c)
        else:
            np.testing.assert_array_equal(b, a, err_msg=c)


# ------------------------------------------------------------------ vectorised maths
def _vec(f, x):
    from numba import njit

    @njit(error_model="numpy")
    def loop(x, out):
        for i in range(x.size):
            out[i] = f(x[i])

    out = np.empty_like(x)
    loop(x, out)
    return out


def test_vectorised_exp_log_cosh_psat_agree_with_numpy():
    rng = np.random.default_rng(0)
    ulp2 = 4.5e-16  # 2 units in the last place
    x = rng.uniform(-708, 709, 200_000)
    np.testing.assert_allclose(_vec(vexp, x), np.exp(x), rtol=ulp2, atol=0)
    x = np.exp(rng.uniform(-700, 700, 200_000))
    np.testing.assert_allclose(_vec(vlog, x), np.log(x), rtol=ulp2, atol=0)
    x = rng.uniform(0.5, 2.0, 200_000)  # near 1: log small, relative error kept
    np.testing.assert_allclose(_vec(vlog, x), np.log(x), rtol=ulp2, atol=0)
    x = rng.uniform(-30, 30, 200_000)
    np.testing.assert_allclose(_vec(vcosh, x), np.cosh(x), rtol=ulp2, atol=0)
    # products with sqrt instead of pow(., 1.5), ...: relative 1e-14 on the pressure
    T = rng.uniform(-60, 99, 200_000)
    np.testing.assert_allclose(_vec(psat_water, T), saturation_vapour_pressure(T), rtol=2e-14)
    special = np.array([0.0, np.inf, -np.inf, np.nan, -1.0, 5e-324, 1e-310])
    with np.errstate(divide="ignore", invalid="ignore"):
        np.testing.assert_array_equal(_vec(vlog, special), np.log(special))
    special = np.array([0.0, np.inf, -np.inf, np.nan, 709.79, -745.2, 710.0, -800.0])
    with np.errstate(over="ignore"):
        np.testing.assert_array_equal(_vec(vexp, special), np.exp(special))


@pytest.mark.parametrize("n", [1, 7, 8, 100, 128, 129, 8759, 262_770])
def test_pairwise_sum_is_numpys(n):
    x = np.random.default_rng(n).normal(10, 5, n)
    assert pairwise_sum(x, 0, n) == np.add.reduce(x)
    if n > 1:  # np.add.reduceat: first value + pairwise sum of the rest
        assert x[0] + pairwise_sum(x, 1, n - 1) == np.add.reduceat(x, [0])[0]


# ------------------------------------------------------------------ same indicators
@pytest.mark.parametrize("n", [8759, 8760, 8784, 20_000])
def test_fused_equals_assess_batch(n):
    T, RH = series(5, n, seed=n)
    RH[0, 100:400] = 100.0  # saturated (capped) hours
    RH[1, 50:60] = 0.0  # bone-dry hours: lifetime multiplier infinite there
    RH[2] = np.clip(RH[2] + 30, 0, 100)  # wet: mould grows
    assert_same(risk.assess_batch(T, RH), assess_fused(T, RH))


def test_fused_row_equals_assess():
    T, RH = series(2, 8759, seed=1, wet=True)
    got = assess_fused(T, RH)
    for i in range(2):
        ref = risk.assess(T[i], RH[i]).set_index("indicator")
        for c in got.columns:
            if c == "ashrae_best_class":
                assert ref.loc[c, "rating"] == got.loc[i, c]
            elif c.startswith(ROUNDED):
                assert got.loc[i, c] == pytest.approx(ref.loc[c, "value"], rel=RTOL)
            else:
                assert got.loc[i, c] == ref.loc[c, "value"], c


OPTIONS = [
    {"ashrae": {"edges": "wrap"}, "en15757": {"edges": "wrap"}},
    {"ashrae": {"method": "setpoint", "nested": False, "T_setpoint": 18.0}},
    {"ashrae": {"RH_setpoint": 60, "threshold": 80, "window_days": 10}},
    {"en15757": {"min_band_mode": "width", "window_days": 20, "percentiles": (5, 95)}},
    {"ashrae": {"edges": "wrap", "window_days": 7}, "en15757": {"window_days": 40}},
    {"vtt": {"sensitivity": "MR", "frozen": "hold", "M0": 1.5}, "isopleth": {"growth_rate": 1}},
    {"lm": {"Ea": {"film": 90e3}, "T_ref": 18, "RH_ref": 45, "n": 1.0}},
    {"emc": {"coefficient": 0.002}},
    {
        "ashrae": {
            "classes": (
                ClimateClass("X", RH_short=8, T_short=3, T_season=(4, 6)),
                ClimateClass("Y", RH_range=(30, 70)),
            )
        }
    },
]


@pytest.mark.parametrize("opts", OPTIONS, ids=range(len(OPTIONS)))
def test_fused_equals_assess_batch_with_options(opts):
    T, RH = series(3, 8784, seed=7, wet=True)
    T[0, :200] -= 15  # frozen hours
    assert_same(risk.assess_batch(T, RH, **opts), assess_fused(T, RH, **opts))


@pytest.mark.parametrize("groups", [["chemical"], ["mechanical", "mould"], ["en15757"]])
def test_fused_indicator_groups(groups):
    T, RH = series(2, 8760, seed=3)
    assert_same(risk.assess_batch(T, RH, indicators=groups), assess_fused(T, RH, indicators=groups))


def test_fused_short_series_and_shared_temperature():
    T, RH = series(3, 2000, seed=4)
    short = ["mechanical"]
    assert_same(risk.assess_batch(T, RH, indicators=short), assess_fused(T, RH, indicators=short))
    with pytest.raises(InputError, match="at least one year"):
        assess_fused(T, RH)
    T, RH = series(3, 8760, seed=5)
    assert_same(risk.assess_batch(T[0], RH), assess_fused(T[0], RH))  # (hours,) broadcast


# ------------------------------------------------------------------ handed back to numpy
@pytest.mark.parametrize("nan_policy", ["propagate", "omit"])
def test_missing_hours_use_assess_batch(nan_policy):
    T, RH = series(3, 8760, seed=6)
    T[1, 500:520] = np.nan
    RH[2, 9] = np.nan
    ref = risk.assess_batch(T, RH, nan_policy=nan_policy)
    assert_same(ref, assess_fused(T, RH, nan_policy=nan_policy))
    with pytest.raises(InputError, match="nan_policy='raise'"):
        assess_fused(T, RH, nan_policy="raise")


def test_bad_input_raises_as_assess_batch():
    T, RH = series(2, 8760, seed=8)
    with pytest.raises(InputError, match="at most 100 %"):
        assess_fused(T, RH + 50)
    with pytest.raises(InputError, match="kelvin"):
        assess_fused(T + 273.15, RH)
    with pytest.raises(InputError, match="unknown option"):
        assess_fused(T, RH, vtt={"colour": "green"})


def test_plan_columns_are_those_of_assess_batch():
    T, RH = series(1, 8760, seed=9)
    plan = fused_plan(8760)
    assert plan.columns == tuple(risk.assess_batch(T, RH).columns)
    ref = risk.assess_batch(T, RH)
    assert_same(ref, plan.frame(plan.values(ref)))
