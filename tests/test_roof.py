"""Roofs as solar surfaces: ``data.roof``'s two slopes, their irradiance, their aperture
prior, and ``hbayes init`` writing the key for an attic."""

from __future__ import annotations

import numpy as np
import pandas as pd
import pvlib
import pytest

from heritage_bayes.climate.solar import roof_planes, surface_irradiance
from heritage_bayes.config import load_config, parse_config
from heritage_bayes.errors import ConfigError, InputError
from heritage_bayes.inference.survey import ROOF_APERTURE_PER_AREA
from heritage_bayes.init_config import init_config
from heritage_bayes.inputs import solar_inputs
from heritage_bayes.models import build_model
from heritage_bayes.run import section_parameters

SITE = {"latitude": 60.21, "longitude": 24.66, "altitude": 30.0}


def _config(roof, **data):
    return parse_config(
        {
            "name": "x",
            "data": {"demo": {}, "roof": roof, **data},
            "thermal": {"model": "thermal_1c"},
        }
    )


def test_the_slopes_face_away_from_the_ridge():
    assert roof_planes(45, 90) == {"roof_N": (45.0, 0.0), "roof_S": (45.0, 180.0)}
    assert roof_planes(30, 0) == roof_planes(30, 180) == roof_planes(30, 360)
    assert roof_planes(30, 0) == {"roof_E": (30.0, 90.0), "roof_W": (30.0, 270.0)}
    assert roof_planes(35, 45) == {"roof_SE": (35.0, 135.0), "roof_NW": (35.0, 315.0)}
    assert roof_planes(20, 30) == {"roof_120": (20.0, 120.0), "roof_300": (20.0, 300.0)}
    for pitch, ridge in ((0, 90), (90, 90), (45, -1), (45, 361)):
        with pytest.raises(InputError, match=r"roof: (pitch|ridge_azimuth) must be in"):
            roof_planes(pitch, ridge)


def test_roof_plane_irradiance_is_pvlibs_transposition():
    """Instantaneous readings with all three components: each slope's irradiance is
    pvlib's Perez transposition for its tilt and azimuth, computed here directly."""
    idx = pd.date_range("2011-06-21 04:00", "2011-06-21 17:00", freq="1h", tz="UTC")
    loc = pvlib.location.Location(SITE["latitude"], SITE["longitude"], altitude=30.0)
    weather = loc.get_clearsky(idx)[["ghi", "dni", "dhi"]] * 0.8  # a hazy clear day
    planes = roof_planes(40, 90)
    got = surface_irradiance(weather, SITE, planes, averaged=False)
    sun = pvlib.solarposition.get_solarposition(idx, SITE["latitude"], SITE["longitude"], 30.0)
    assert sun["zenith"].max() < 87  # no low-sun special case in this window
    for name, (tilt, az) in planes.items():
        want = pvlib.irradiance.get_total_irradiance(
            tilt,
            az,
            sun["apparent_zenith"],
            sun["azimuth"],
            weather["dni"],
            weather["ghi"],
            weather["dhi"],
            dni_extra=pvlib.irradiance.get_extra_radiation(idx.day_of_year),
            airmass=pvlib.atmosphere.get_relative_airmass(sun["apparent_zenith"]),
            albedo=0.2,
            model="perez",
        )["poa_global"]
        np.testing.assert_allclose(got[name], want.clip(lower=0), rtol=1e-9, atol=1e-9)
    # the south slope takes more sun than the north one, and at noon more than the horizontal
    assert got["roof_S"].sum() > 1.5 * got["roof_N"].sum()
    noon = got.index[np.argmax(got["roof_S"])]
    assert got.loc[noon, "roof_S"] > weather.loc[noon, "ghi"]


def test_config_roof_replaces_the_facades_and_feeds_the_inputs():
    cfg = _config({"pitch": 45, "ridge_azimuth": 90})
    assert cfg.data.surfaces == {"roof_N": (45.0, 0.0), "roof_S": (45.0, 180.0)}
    # beside facades given explicitly; the resolved config reads back the same
    cfg = _config({"pitch": 30, "ridge_azimuth": 0}, surfaces={"S": [90, 180]})
    assert list(cfg.data.surfaces) == ["S", "roof_E", "roof_W"]
    again = parse_config(cfg.resolved())
    assert again.data.surfaces == cfg.data.surfaces and again.data.roof == cfg.data.roof
    # the model's apertures and the inputs I_<slope>
    model = build_model(_config({"pitch": 45, "ridge_azimuth": 90}), "thermal")
    assert {"fI_roof_N", "fI_roof_S"} <= set(model.parameter_names)
    idx = pd.date_range("2011-06-01", periods=72, freq="1h", tz="UTC")
    ghi = pvlib.location.Location(60.21, 24.66).get_clearsky(idx)["ghi"]
    weather = pd.DataFrame({"ghi": ghi, "Te": 15.0}, index=idx)
    irr, _, _ = solar_inputs(weather, SITE, cfg.data.surfaces, "measured")
    assert list(irr.columns) == ["I_S", "I_roof_E", "I_roof_W"]


@pytest.mark.parametrize(
    ("roof", "extra", "message"),
    [
        ({"pitch": 90, "ridge_azimuth": 90}, {}, r"data\.roof\.pitch: outside the allowed range"),
        ({"pitch": 0, "ridge_azimuth": 90}, {}, r"data\.roof\.pitch: outside the allowed range"),
        ({"pitch": 45, "ridge_azimuth": 400}, {}, r"data\.roof\.ridge_azimuth: outside"),
        ({"pitch": 45}, {}, r"data\.roof\.ridge_azimuth: required"),
        ({"pitch": 45, "ridge_azimuth": 90, "area": 0}, {}, r"data\.roof\.area: outside"),
        ({"pitch": 45, "ridge_azimuth": 90, "tilt": 3}, {}, r"data\.roof\.tilt"),
        (
            {"pitch": 45, "ridge_azimuth": 90},
            {"irradiance": "none"},
            "roof: given, but irradiance is 'none'",
        ),
        (
            {"pitch": 45, "ridge_azimuth": 90},
            {"surfaces": {"roof_S": [90, 180]}},
            r"surfaces\.roof_S: \[90\.0, 180\.0\], but the roof's plane of that name is "
            r"\[45, 180\]",
        ),
    ],
)
def test_config_errors_name_the_key(roof, extra, message):
    with pytest.raises(ConfigError, match=message):
        _config(roof, **extra)


def test_roof_area_sets_the_aperture_prior():
    cfg = _config({"pitch": 45, "ridge_azimuth": 90, "area": 200})
    model = build_model(cfg, "thermal")
    _, params = section_parameters(cfg, "thermal", model)
    for name in ("fI_roof_N", "fI_roof_S"):
        prior = params[name].prior
        assert prior.dist == "lognormal"
        assert prior.mu == pytest.approx(ROOF_APERTURE_PER_AREA * 100.0)
    without = _config({"pitch": 45, "ridge_azimuth": 90})
    _, wide = section_parameters(without, "thermal", build_model(without, "thermal"))
    assert wide["fI_roof_N"].prior.dist == "loguniform"
    with pytest.raises(ConfigError, match=r"glazing_area: \['roof_S'\] are roof slopes"):
        parse_config(
            {
                "name": "x",
                "data": {"demo": {}, "roof": {"pitch": 45, "ridge_azimuth": 90, "area": 90}},
                "glazing_area": {"roof_S": 2},
                "thermal": {"model": "thermal_1c"},
            }
        )


@pytest.mark.shared_data
def test_init_writes_the_roof_for_an_attic_and_not_for_the_room_below(shared_data, tmp_path):
    d = shared_data / "trh1-espoo-attic"
    site = {"latitude": 60.21, "longitude": 24.66}
    res = init_config(
        d / "roofmiddle_airmiddle.csv", d / "fmi.csv", output=tmp_path / "a.yaml", **site
    )
    assert res.questions == []
    assert "  roof: {pitch: 45, ridge_azimuth: 90}" in res.text.splitlines()
    assert "CHECK the pitch" in res.text and "init's defaults" in res.text
    assert any(f.startswith("roof: the room looks like an attic") for f in res.findings)
    cfg = load_config(tmp_path / "a.yaml")
    assert cfg.data.surfaces == {"roof_N": (45.0, 0.0), "roof_S": (45.0, 180.0)}
    assert cfg.data.weather.columns["wind"] == "ws"  # FMI's wind speed: the sun on the roof
    assert cfg.data.weather.columns["precip"] == "precip"  # and the snow on it
    # no floor on the soil: Tf at a fixed 1 m, no depth to estimate
    assert (cfg.data.ground_temperature.mode, cfg.data.ground_temperature.depth) == ("seasonal", 1)
    # the heated room below: neither its name nor its daily swing (0.2 of outdoors') says roof
    res = init_config(d / "indoor1.csv", d / "fmi.csv", output=tmp_path / "b.yaml", **site)
    assert "roof:" not in res.text
    below = load_config(tmp_path / "b.yaml").data
    assert below.surfaces == {"H": (0.0, 0.0)}
    assert below.ground_temperature.depth is None  # its ground's depth is estimated


def test_wind_weight_is_iso_6946s_share_reaching_the_attic():
    from heritage_bayes.climate.solair import (
        REFERENCE_WIND,
        ROOF_INNER_CONDUCTANCE,
        exterior_surface_coefficient,
        roof_wind_weight,
    )

    # R_se 0.04 m² K/W at the standard 4 m/s (ISO 6946 annex C: 4 + 4 v + 0.9 × 4.6)
    assert 1 / exterior_surface_coefficient(REFERENCE_WIND) == pytest.approx(0.0414, abs=5e-4)
    assert roof_wind_weight(REFERENCE_WIND) == pytest.approx(1.0)
    u = ROOF_INNER_CONDUCTANCE
    calm = (24.14 + u) / (8.14 + u)
    assert roof_wind_weight([0.0])[0] == pytest.approx(calm, rel=1e-3)
    w = roof_wind_weight(np.linspace(0, 20, 41))
    assert (np.diff(w) < 0).all() and w[-1] > 0  # more wind, less of the sun inside
    # no conductance to the attic: the share goes as 1/h_e
    assert roof_wind_weight(8.0, 0.0) == pytest.approx(24.14 / 40.14, rel=1e-3)
    for bad in ([-1.0], [np.nan]):
        with pytest.raises(InputError, match="wind speed: finite values >= 0 m/s"):
            roof_wind_weight(bad)
    with pytest.raises(InputError, match="inner_conductance"):
        roof_wind_weight(1.0, -2.0)


def test_wind_weights_the_roof_planes_only():
    """The slopes' irradiance times the wind weight, a facade's unchanged; no wind column:
    nothing changes; gaps in the wind are interpolated."""
    from heritage_bayes.climate.solair import roof_wind_weight
    from heritage_bayes.errors import DataError

    cfg = _config({"pitch": 30, "ridge_azimuth": 0}, surfaces={"S": [90, 180]})
    idx = pd.date_range("2011-06-01", periods=48, freq="1h", tz="UTC")
    ghi = pvlib.location.Location(60.21, 24.66).get_clearsky(idx)["ghi"]
    wind = np.where(np.arange(48) < 24, 0.0, 8.0)
    weather = pd.DataFrame({"ghi": ghi, "Te": 15.0, "wind": wind}, index=idx)
    roof = ("roof_E", "roof_W")
    plain, _, _ = solar_inputs(weather.drop(columns="wind"), SITE, cfg.data.surfaces, "measured")
    got, _, detail = solar_inputs(weather, SITE, cfg.data.surfaces, "measured", roof=roof)
    w = roof_wind_weight(wind)
    for c in ("I_roof_E", "I_roof_W"):
        np.testing.assert_allclose(got[c], plain[c] * w)
    np.testing.assert_allclose(got["I_S"], plain["I_S"])
    assert "weighted by the wind" in detail
    same, _, _ = solar_inputs(weather.drop(columns="wind"), SITE, cfg.data.surfaces, "measured",
                              roof=roof)  # fmt: skip
    np.testing.assert_allclose(same["I_roof_E"], plain["I_roof_E"])
    gappy = weather.assign(wind=np.where(np.arange(48) == 30, np.nan, wind))
    filled, _, _ = solar_inputs(gappy, SITE, cfg.data.surfaces, "measured", roof=roof)
    np.testing.assert_allclose(filled["I_roof_E"], got["I_roof_E"])
    with pytest.raises(DataError, match=r"data\.weather: column 'wind': wind speed"):
        solar_inputs(weather.assign(wind=-1.0), SITE, cfg.data.surfaces, "measured", roof=roof)


def test_init_reads_a_wind_speed_column(tmp_path):
    """A weather file's wind speed (FMI's 'ws') is mapped to 'wind'; its direction is
    not."""
    from heritage_bayes.io.loggers import inspect_table

    idx = pd.date_range("2011-06-01", periods=200, freq="1h")
    text = "t,Te,RHe,ws,wd\n" + "\n".join(
        f"{t:%Y-%m-%d %H:%M:%S},{10 + i % 7},{80 - i % 9},{(i % 11) * 0.7:.1f},{i % 360}"
        for i, t in enumerate(idx)
    )
    p = tmp_path / "fmi.csv"
    p.write_text(text, encoding="utf-8")
    lay = inspect_table(p)
    assert lay.first("wind").name == "ws" and lay.first("wind").unit == "m/s"
    assert [c.name for c in lay.columns if c.kind is None] == ["wd"]


def test_a_skyline_shades_the_low_sun_on_the_roof_planes_only():
    """Below the roof's skyline the slopes get the isotropic sky without the beam, above it
    the unshaded transposition; a facade beside them is unchanged; horizon 0 is the
    unshaded surface; the config's default and its bounds."""
    idx = pd.date_range("2011-03-20 04:00", "2011-03-20 16:00", freq="1h", tz="UTC")
    loc = pvlib.location.Location(SITE["latitude"], SITE["longitude"], altitude=30.0)
    weather = loc.get_clearsky(idx)[["ghi", "dni", "dhi"]]
    planes = {"roof_S": (45.0, 180.0), "S": (90.0, 180.0)}
    open_sky = surface_irradiance(weather, SITE, planes, averaged=False)
    shaded = surface_irradiance(weather, SITE, planes, averaged=False, horizon=20.0)
    pd.testing.assert_frame_equal(
        surface_irradiance(weather, SITE, planes, averaged=False, horizon=0.0), open_sky
    )
    elevation = loc.get_solarposition(idx)["elevation"].to_numpy()
    low, high = (elevation > 3) & (elevation < 20), elevation > 20
    assert low.any() and high.any()
    np.testing.assert_allclose(shaded["roof_S"][high], open_sky["roof_S"][high])
    iso = (weather["dhi"] * (1 + np.cos(np.radians(45))) / 2
           + weather["ghi"] * 0.2 * (1 - np.cos(np.radians(45))) / 2)  # fmt: skip
    np.testing.assert_allclose(shaded["roof_S"][low], iso[low], rtol=1e-9)
    assert (shaded["roof_S"][low] < 0.6 * open_sky["roof_S"][low]).all()
    with pytest.raises(InputError, match=r"horizon must be in \[0, 45\]"):
        surface_irradiance(weather, SITE, planes, horizon=50.0)
    # solar_inputs: the roof planes shaded, the facade not
    ghi = weather.assign(Te=5.0)
    plain, _, _ = solar_inputs(ghi, SITE, planes, "measured")
    got, _, detail = solar_inputs(ghi, SITE, planes, "measured", roof=("roof_S",),
                                  roof_horizon=20.0)  # fmt: skip
    np.testing.assert_allclose(got["I_S"], plain["I_S"])
    assert (got["I_roof_S"] <= plain["I_roof_S"] + 1e-9).all()
    assert got["I_roof_S"].sum() < plain["I_roof_S"].sum()
    assert "shaded below 20°" in detail
    # the config: 20° by default, 0 for a roof open to the horizon, bounded
    assert _config({"pitch": 45, "ridge_azimuth": 90}).data.roof.horizon == 20.0
    assert _config({"pitch": 45, "ridge_azimuth": 90, "horizon": 0}).data.roof.horizon == 0.0
    with pytest.raises(ConfigError, match=r"data\.roof\.horizon: outside"):
        _config({"pitch": 45, "ridge_azimuth": 90, "horizon": 60})
