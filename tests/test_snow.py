"""Snow on the roof: a degree-day snowpack from the weather takes the roof planes' sun."""

from __future__ import annotations

import numpy as np
import pandas as pd
import pvlib
import pytest

from heritage_bayes.climate import snow
from heritage_bayes.errors import DataError, InputError
from heritage_bayes.inputs import solar_inputs

SITE = {"latitude": 60.21, "longitude": 24.66, "altitude": 30.0}
SURFACES = {"roof_N": (45.0, 0.0), "roof_S": (45.0, 180.0), "S": (90.0, 180.0)}
ROOF = ("roof_N", "roof_S")


def test_snow_accumulates_below_the_threshold_and_melts_by_degree_days():
    te = np.array([-5.0, -5.0, 0.5, 1.2, 5.0])
    p = np.array([2.0, 3.0, 1.0, 4.0, 0.0])  # [mm per step]
    swe = snow.snowpack(te, p, 24.0)  # daily steps
    # snow at -5 and +0.5 °C (below +1), which melts 0.5 a; the rain at 1.2 °C adds nothing
    a = snow.MELT_FACTOR
    np.testing.assert_allclose(swe, [2.0, 5.0, 6.0 - 0.5 * a, 6.0 - 1.7 * a, 0.0])
    assert swe[3] > 0  # melting, not gone; gone at 5 °C
    # hourly steps melt a 24th as fast; a gap in Te holds the last value, in precip is none
    hourly = snow.snowpack([-1.0, np.nan, 3.0], [1.0, np.nan, 0.0], 1.0, swe0=2.0)
    np.testing.assert_allclose(hourly, [3.0, 3.0, 3.0 - 3.0 * a / 24.0])
    np.testing.assert_allclose(snow.snow_cover([0.0, 2.5, 5.0, 50.0]), [0.0, 0.5, 1.0, 1.0])
    with pytest.raises(InputError, match="precipitation: values >= 0 mm"):
        snow.snowpack([0.0], [-1.0], 1.0)
    with pytest.raises(InputError, match="one value per step"):
        snow.snowpack([0.0, 1.0], [0.0], 1.0)


def test_the_cover_takes_the_sun_and_the_daily_swing():
    i = np.array([300.0, 300.0, 300.0])
    te, tb = np.array([-8.0, -2.0, 4.0]), np.array([-5.0, -5.0, -5.0])
    np.testing.assert_allclose(snow.roof_under_snow(i, te, tb, 0.0), i)  # bare: unchanged
    k = 25.0 / snow.ROOF_ABSORPTANCE  # h_e / alpha [W/(m² K)]
    np.testing.assert_allclose(snow.roof_under_snow(i, te, tb, 1.0), k * (tb - te))
    half = snow.roof_under_snow(i, te, tb, 0.5)
    np.testing.assert_allclose(half, 0.5 * i + 0.5 * k * (tb - te))


def _weather(te: np.ndarray, precip: np.ndarray) -> pd.DataFrame:
    idx = pd.date_range("2011-03-01", periods=te.size, freq="1h", tz="UTC")
    ghi = pvlib.location.Location(60.21, 24.66).get_clearsky(idx)["ghi"].to_numpy()
    return pd.DataFrame({"ghi": ghi, "Te": te, "precip": precip}, index=idx)


def test_the_roof_planes_under_snow_and_nothing_without_precipitation_or_frost():
    n = 96
    te = np.where(np.arange(n) < 48, -6.0 + 3 * np.sin(np.arange(n) / 24 * 2 * np.pi), 8.0)
    precip = np.where(np.arange(n) < 6, 2.0, 0.0)  # 12 mm of snow, then a thaw
    weather = _weather(te, precip)
    plain, _, _ = solar_inputs(weather.drop(columns="precip"), SITE, SURFACES, "measured",
                               roof=ROOF)  # fmt: skip
    got, _, detail = solar_inputs(weather, SITE, SURFACES, "measured", roof=ROOF)
    assert "under the snow of a degree-day snowpack" in detail
    np.testing.assert_allclose(got["I_S"], plain["I_S"])  # a facade: no snow on it
    noon = 10  # day 1 at 10 UTC: covered, in sun
    assert plain["I_roof_S"].iloc[noon] > 100
    day_mean = pd.Series(te, weather.index).rolling("24h", min_periods=1).mean()
    base = (1.0 - snow.BASE_WARMTH) * day_mean.iloc[noon]  # drawn towards 0 °C
    want = 25.0 / snow.ROOF_ABSORPTANCE * (base - te[noon])
    assert got["I_roof_S"].iloc[noon] == pytest.approx(want, rel=1e-6)  # no sun, the swing
    # thawed (8 °C melts 1 mm/h): the bare roof again by the last day
    np.testing.assert_allclose(got["I_roof_S"].iloc[-24:], plain["I_roof_S"].iloc[-24:])
    # no day below 0 °C: identical inputs; a negative precipitation: the column named
    warm, _, warm_detail = solar_inputs(_weather(te + 10, precip), SITE, SURFACES, "measured",
                                        roof=ROOF)  # fmt: skip
    pd.testing.assert_frame_equal(warm, solar_inputs(_weather(te + 10, precip).drop(
        columns="precip"), SITE, SURFACES, "measured", roof=ROOF)[0])  # fmt: skip
    assert "snow" not in warm_detail
    with pytest.raises(DataError, match=r"data\.weather: column 'precip': precipitation"):
        solar_inputs(_weather(te, -precip), SITE, SURFACES, "measured", roof=ROOF)


def test_init_reads_a_precipitation_column(tmp_path):
    """A weather file's precipitation (FMI's 'precip') is mapped to 'precip' [mm]."""
    from heritage_bayes.io.loggers import inspect_table

    idx = pd.date_range("2011-06-01", periods=200, freq="1h")
    text = "t,Te,RHe,precip,wd\n" + "\n".join(
        f"{t:%Y-%m-%d %H:%M:%S},{10 + i % 7},{80 - i % 9},{(i % 5) * 0.2:.1f},{i % 360}"
        for i, t in enumerate(idx)
    )
    p = tmp_path / "fmi.csv"
    p.write_text(text, encoding="utf-8")
    lay = inspect_table(p)
    assert lay.first("precip").name == "precip" and lay.first("precip").unit == "mm"


def test_the_snow_base_lies_between_the_air_and_a_melting_base(monkeypatch):
    """The cover's outer face under snow: the air's 24-hour mean drawn BASE_WARMTH of the
    way to 0 °C; 0 leaves the air's mean, 1 a melting base at 0 °C."""
    assert 0.0 < snow.BASE_WARMTH < 1.0
    n = 72
    te = -10.0 + 4.0 * np.sin(np.arange(n) / 24 * 2 * np.pi)  # a cold spell, frost all along
    weather = _weather(te, np.where(np.arange(n) < 4, 3.0, 0.0))
    k, late = 25.0 / snow.ROOF_ABSORPTANCE, slice(24, None)  # covered from the first hours
    day_mean = pd.Series(te, weather.index).rolling("24h", min_periods=1).mean().to_numpy()
    cols, w = {}, snow.BASE_WARMTH
    for warm in (0.0, w, 1.0):
        monkeypatch.setattr(snow, "BASE_WARMTH", warm)
        got = solar_inputs(weather, SITE, SURFACES, "measured", roof=ROOF)[0]["I_roof_N"]
        cols[warm] = got.to_numpy()[late]
    np.testing.assert_allclose(cols[0.0], k * (day_mean - te)[late], rtol=1e-9)
    np.testing.assert_allclose(cols[1.0], k * (0.0 - te)[late], rtol=1e-9)
    # in frost the drawn base is warmer than the air's mean, colder than 0 °C
    np.testing.assert_allclose(cols[w], (1 - w) * cols[0.0] + w * cols[1.0], rtol=1e-9)
    assert (cols[0.0] < cols[w]).all() and (cols[w] < cols[1.0]).all()
