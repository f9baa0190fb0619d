"""Psychrometrics against tabulated IAPWS values."""

import numpy as np
import pytest

from heritage_bayes.climate import (
    absolute_humidity,
    dew_point,
    relative_humidity,
    saturation_vapour_pressure,
    vapour_pressure,
)


@pytest.mark.parametrize(
    ("T", "expected"),
    [(0.01, 611.657), (20.0, 2339.2), (30.0, 4246.9), (50.0, 12352.0), (100.0, 101418.0)],
)
def test_saturation_over_water_matches_iapws_table(T, expected):
    # IAPWS-95 saturation table values; the formulation is accurate to < 0.01 %
    assert saturation_vapour_pressure(T) == pytest.approx(expected, rel=2e-4)


def test_saturation_over_ice():
    # Wagner et al. (2011): 611.657 Pa at the triple point, 259.87 Pa at -10 °C,
    # 103.26 Pa at -20 °C
    assert saturation_vapour_pressure(0.01, over="ice") == pytest.approx(611.657, rel=1e-6)
    assert saturation_vapour_pressure(-10.0, over="ice") == pytest.approx(259.87, rel=5e-4)
    assert saturation_vapour_pressure(-20.0, over="ice") == pytest.approx(103.26, rel=5e-4)
    auto = saturation_vapour_pressure(np.array([-10.0, 10.0]), over="auto")
    assert auto[0] == pytest.approx(saturation_vapour_pressure(-10.0, over="ice"))
    assert auto[1] == pytest.approx(saturation_vapour_pressure(10.0))


def test_rh_vapour_pressure_round_trip_and_dew_point():
    T = np.linspace(-15, 35, 11)
    RH = np.linspace(20, 100, 11)
    Pv = vapour_pressure(T, RH)
    np.testing.assert_allclose(relative_humidity(T, Pv), RH, rtol=1e-12)
    Td = dew_point(T, RH)
    np.testing.assert_allclose(saturation_vapour_pressure(Td), Pv, rtol=1e-9)
    assert dew_point(20.0, 100.0) == pytest.approx(20.0, abs=1e-9)
    # about 9.27 °C at 20 °C / 50 %
    assert dew_point(20.0, 50.0) == pytest.approx(9.27, abs=0.01)
    assert np.isnan(dew_point(20.0, 0.0))


def test_absolute_humidity():
    # 20 °C, 50 %: 1169.6 Pa / (461.52 J/(kg K) * 293.15 K) = 8.645 g/m³
    assert absolute_humidity(20.0, 50.0) == pytest.approx(8.645, abs=2e-3)


def test_bad_phase_is_rejected():
    with pytest.raises(ValueError, match="over must be"):
        saturation_vapour_pressure(10.0, over="steam")
