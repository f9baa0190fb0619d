"""hbayes init proposes the model the data call for (heritage_bayes.init_model): a
dehumidified heated store, a sunlit attic, a crawlspace with a vapour sink, each written
in tmp_path as a HOBO export with an FMI-style weather file; the measured evidence goes
into the config's comments, the proposal into its keys."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pandas as pd
import pytest

from heritage_bayes.climate.psychro import relative_humidity, saturation_vapour_pressure
from heritage_bayes.config import load_config
from heritage_bayes.init_config import init_config
from heritage_bayes.init_model import propose_model
from heritage_bayes.io.clock import solar_noon_utc
from test_init_detect import _fmi

SITE = {"latitude": 60.2, "longitude": 24.7}


def _weather(days: int, seed: int = 5):
    """Hourly UTC stamps from 2013-01-01, Te [°C], RHe [%], ghi [W/m²], solar hour [h]."""
    rng = np.random.default_rng(seed)
    utc = pd.date_range("2013-01-01", periods=24 * days, freq="1h", tz="UTC")
    noon = solar_noon_utc(utc.normalize().tz_localize(None), SITE["longitude"])
    h = np.asarray((utc - utc.normalize()) / pd.Timedelta(hours=1)) - np.asarray(noon)
    doy = np.asarray(utc.day_of_year)
    clouds = np.repeat(rng.uniform(0.3, 1.0, days), 24)
    ghi = np.round(600 * clouds * (0.5 + 0.5 * np.sin(np.pi * doy / 365)), 1)
    ghi = np.round(ghi * np.exp(-((h / 3.0) ** 2)), 1)
    day = np.cos(2 * np.pi * (h - 2.4) / 24)
    te = 4 - 10 * np.cos(2 * np.pi * (doy - 15) / 365) + 4 * day + rng.normal(0, 0.3, h.size)
    rhe = np.clip(78 - 15 * day + rng.normal(0, 6, h.size), 30, 100)
    return utc, te, rhe, ghi


def _smooth(x, halflife: float):
    return pd.Series(x).ewm(halflife=halflife).mean().to_numpy()


def _write(tmp_path: Path, utc, te, rhe, ghi, ti, rhi) -> tuple[Path, Path]:
    wp = _fmi(tmp_path, utc, te, rhe, ghi)
    d = wp.parent
    lines = ['"Plot Title: room"', '"#","Date Time, GMT+02:00","Temp, °C","RH, %"']
    stamps = utc.tz_localize(None) + pd.Timedelta(hours=2)
    lines += [
        f"{i + 1},{t:%m/%d/%y %I:%M:%S %p},{a:.3f},{b:.2f}"
        for i, (t, a, b) in enumerate(zip(stamps, ti, rhi, strict=True))
    ]
    lp = d / "logger.csv"
    lp.write_text("\n".join(lines) + "\n", encoding="utf-8")
    return lp, wp


def _init(tmp_path, ti, rhi, weather):
    lp, wp = _write(tmp_path, *weather, ti, rhi)
    out = tmp_path / "room" / "config.yaml"
    res = init_config(lp, wp, output=out, **SITE)
    assert res.questions == []
    text = out.read_text()
    # the evidence as comments above the keys: every measured line, wrapped
    flat = "".join(x[6:] for x in text.splitlines() if x.startswith("#   ")).replace(" ", "")
    for f in res.findings:
        if f.startswith("model: "):
            assert f[len("model: ") :].replace(" ", "") in flat
    return res, load_config(out), "\n".join(res.findings)


def _store(days: int):
    """A heated store: a thermostat floor at 10 °C, the air 4 K above outdoors in summer,
    RH held at 46-52 % by a dehumidifier."""
    w = _weather(days)
    rng = np.random.default_rng(7)
    ti = np.maximum(_smooth(w[1], 48) + 4, 10 + rng.normal(0, 0.05, w[1].size))
    rhi = 49 + 2 * np.sin(np.arange(ti.size) / 30) + rng.normal(0, 0.5, ti.size)
    return ti, rhi, w


def test_a_dehumidified_heated_store(tmp_path):
    ti, rhi, w = _store(240)
    res, cfg, text = _init(tmp_path, ti, rhi, w)
    # 160 days: which of two or three nodes is not a signature: the ladder's screen
    assert cfg.thermal.model == "auto"
    assert cfg.thermal.options.given()["thermostat"] is True
    assert cfg.thermal.options.given()["source"] is True
    assert cfg.hygric.model == "hygric_1c"
    assert cfg.hygric.options.given() == {"humidistat": "band"}
    # the evidence, with the measured numbers, as comments above the keys
    assert "a heating floor: the indoor daily minimum sat at 9.9 °C" in text
    # the set-point's prior at the measured floor: no "heating off" mode below every hour
    tset = cfg.thermal.priors["Tset"]
    assert (tset.dist, tset.mean, tset.sigma) == ("normal", 9.9, 1.0)
    assert "a normal prior 9.9 ± 1 K" in text
    assert "held in a narrow band: a humidistat or dehumidifier" in text
    assert "RH band: indoors 47-51 % (4.5 points, 5-95 %)" in text
    assert "model: auto screens thermal_1c, thermal_2c and thermal_4a" in text
    # 240 days, the middle third validates (held out): 159 days calibrate around it
    assert any(f.startswith("model: 159 days of calibration data") for f in res.findings)


def test_a_short_record_keeps_the_one_node_models(tmp_path):
    ti, rhi, w = _store(45)
    _, cfg, text = _init(tmp_path, ti, rhi, w)
    assert (cfg.thermal.model, cfg.hygric.model) == ("thermal_1c", "hygric_1c")
    # 45 days: a third validates (the middle, held out of the calibration around it)
    cal, val = cfg.periods.calibration, cfg.periods.validation
    t = pd.Timestamp
    assert t(cal.start) < t(val.start) < t(val.end) < t(cal.end)
    days = (t(cal.end) - t(cal.start) - (t(val.end) - t(val.start))).days
    assert 28 <= days <= 31
    assert f"{days} days of calibration data (< 60): the one-node model" in text
    assert cfg.hygric.options.given() == {"humidistat": "band"}  # the control, whatever the length


def test_a_sunlit_attic_with_sorption(tmp_path):
    # the roof: a daily swing twice the outdoors'; the timber releases vapour as it warms
    w = _weather(240)
    utc, te, rhe, ghi = w
    ti = _smooth(te, 2) + 0.03 * _smooth(ghi, 1.5)
    ps = saturation_vapour_pressure(ti)
    pe = rhe / 100 * saturation_vapour_pressure(te)
    pi = _smooth(pe, 24) + 0.12 * (ps - _smooth(ps, 24))
    rhi = np.clip(relative_humidity(ti, pi), 1, 99)
    _, cfg, text = _init(tmp_path, ti, rhi, w)
    assert cfg.thermal.model == "auto" and "thermostat" not in cfg.thermal.options.given()
    assert "(ratio 1.55): larger indoors: the sun heats the room" in text
    # a swing larger than outdoors: the roof's two slopes at init's default (45°, E-W ridge)
    assert cfg.data.surfaces == {"roof_N": (45.0, 0.0), "roof_S": (45.0, 180.0)}
    assert cfg.hygric.model == "hygric_2c_sorption"
    assert "it follows the room's temperature: sorption" in text


def test_a_crawlspace_with_a_vapour_sink(tmp_path):
    # cold, its RH following the season (55-75 %) under the outdoors' 78 %: the damp
    # soil's cold surface takes vapour out of the air
    w = _weather(240)
    utc, te, rhe, ghi = w
    ti = _smooth(te, 72) + 1
    doy = np.asarray(utc.day_of_year)
    rng = np.random.default_rng(11)
    rhi = 65 + 10 * np.cos(2 * np.pi * (doy - 15) / 365) + rng.normal(0, 3, ti.size)
    _, cfg, text = _init(tmp_path, ti, rhi, w)
    assert cfg.hygric.model == "hygric_2c_fixed"
    assert cfg.hygric.options.given() == {"sink": "temperature"}
    assert "smaller indoors: damped by the envelope" in text
    assert "-135 Pa from outdoors on average, below in 7 of 8 months: a vapour sink" in text


@pytest.mark.parametrize("rh_half_width, band", [(2.0, True), (20.0, False)])
def test_the_rh_band_threshold(rh_half_width, band):
    utc, te, rhe, _ = _weather(30)
    ti = pd.Series(_smooth(te, 24) + 2, index=utc)
    rhi = pd.Series(50 + rh_half_width * np.sin(np.arange(utc.size) / 40), index=utc)
    p = propose_model(
        ti,
        pd.Series(te, index=utc),
        rhi,
        pd.Series(rhe, index=utc),
        start="2013-01-01",
        mid="2013-01-21",
        end="2013-01-31",
        heated=(float("nan"), 0, 30),
    )
    assert ("humidistat" in p.hygric_options) is band
    # a vapour pressure near the outdoor one: no sink, no source
    assert "sink" not in p.hygric_options and "source" not in p.hygric_options
    assert p.thermal_model == "thermal_1c" and p.thermal_options == {}


@pytest.mark.parametrize("offset_pa, key", [(-150.0, "sink"), (0.0, None), (150.0, "source")])
def test_sink_and_source_from_the_mean_vapour_pressure(offset_pa, key):
    utc, te, rhe, _ = _weather(120)
    ti = _smooth(te, 48) + 2
    pe = rhe / 100 * saturation_vapour_pressure(te)
    rng = np.random.default_rng(2)
    rhi = relative_humidity(ti, _smooth(pe, 24) + offset_pa) + rng.normal(0, 4, ti.size)
    p = propose_model(
        *(pd.Series(x, index=utc) for x in (ti, te, rhi, rhe)),
        start="2013-01-01",
        mid="2013-03-20",
        end="2013-05-01",
        heated=(float("nan"), 0, 120),
    )
    assert {k for k in ("sink", "source") if k in p.hygric_options} == ({key} - {None})
    # the sink names its model; a source names none: 78 days to calibrate, the ladder's
    # screen chooses (model: auto); the RH held near the outdoors' reads as a band
    assert p.hygric_model == {"sink": "hygric_2c_fixed", "source": "auto"}.get(key, "hygric_1c")


def test_sorption_with_a_wet_offset_writes_no_source_the_model_cannot_take(tmp_path):
    # the attic above, 150 Pa wetter than outdoors: both signatures; the sorbing buffer has
    # no source term, so init writes none (the loader would refuse it) and says why
    w = _weather(240)
    utc, te, rhe, ghi = w
    ti = _smooth(te, 2) + 0.03 * _smooth(ghi, 1.5)
    ps = saturation_vapour_pressure(ti)
    pe = rhe / 100 * saturation_vapour_pressure(te)
    pi = _smooth(pe, 24) + 150 + 0.12 * (ps - _smooth(ps, 24))
    rhi = np.clip(relative_humidity(ti, pi), 1, 99)
    _, cfg, text = _init(tmp_path, ti, rhi, w)
    assert cfg.hygric.model == "hygric_2c_sorption"
    assert "source" not in cfg.hygric.options.given()
    assert "a moisture source (source: true" in text
    assert "the sorbing buffer has no moisture source term" in text
