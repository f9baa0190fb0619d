"""The YAML schema: the example configs load, and bad configs give key-path messages."""

from __future__ import annotations

import json
import os
from pathlib import Path

import pandas as pd
import pytest
import yaml

from heritage_bayes.config import Periods, config_hash, load_config, parse_config
from heritage_bayes.errors import ConfigError, InputError

CONFIGS = Path(__file__).resolve().parents[1] / "configs"

DEMO = {"data": {"demo": {}}, "thermal": {"model": "thermal_4a"}}


def _error(raw) -> str:
    with pytest.raises(ConfigError) as exc:
        parse_config(raw)
    return str(exc.value)


def _with(**sections) -> dict:
    raw = json.loads(json.dumps(DEMO))
    raw.update(sections)
    return raw


def _csv_data(**extra) -> dict:
    data = {
        "weather": {"format": "csv", "path": "w.csv", "time_column": "t", "timezone": "UTC"},
        "measurements": {"format": "csv", "path": "m.csv", "time_column": "t", "timezone": "UTC"},
        "irradiance": "none",
    }
    data.update(extra)
    return data


# ---------------------------------------------------------------------------------------
# valid configs
# ---------------------------------------------------------------------------------------


@pytest.mark.parametrize("name", ["demo", "orholm", "annisse", "trh1_attic"])
def test_example_configs_load(name):
    cfg = load_config(CONFIGS / f"{name}.yaml")
    assert cfg.name == name
    assert cfg.thermal is not None and cfg.hygric is not None
    assert cfg.periods.calibration is not None and cfg.periods.validation is not None
    resolved = cfg.resolved()
    json.dumps(resolved)  # serialisable
    assert "base_dir" not in resolved
    # the resolved config is itself a valid config, with the same hash
    again = parse_config(resolved, base_dir=cfg.base_dir)
    assert config_hash(again) == config_hash(cfg)


def test_example_config_paths_resolve_beside_the_repo():
    cfg = load_config(CONFIGS / "orholm.yaml")
    weather = cfg.path(cfg.data.weather.path)
    # ../shared beside the checkout (compared without resolving links: shared/ may be one)
    expected = (
        CONFIGS.parents[1]
        / "shared"
        / "data"
        / "orholm"
        / ("DMI_outdoor-climate-data_2009-2021.csv")
    )
    assert os.path.normpath(weather) == os.path.normpath(expected)


def test_portable_config_makes_every_data_path_absolute():
    """A run's config.yaml re-runs (and projects) from any folder: the KNMI weather file
    of a demo driven by De Bilt weather too (a relative path was resolved against the
    run directory: right only for runs two levels below the checkout)."""
    cfg = load_config(CONFIGS / "debilt_demo.yaml")
    rel = cfg.data.demo.weather_path
    assert not os.path.isabs(rel if isinstance(rel, str) else rel[0])
    d = cfg.portable()
    p = d["data"]["demo"]["weather_path"]
    p = p if isinstance(p, str) else p[0]
    assert os.path.isabs(p)
    expected = CONFIGS.parents[1] / "shared" / "data" / "knmi-debilt"
    assert os.path.normpath(os.path.dirname(p)) == os.path.normpath(expected)
    # and the portable config is itself valid wherever it is parsed
    assert parse_config(d, base_dir="/").data.demo.weather_path == d["data"]["demo"]["weather_path"]


def test_demo_config_values():
    cfg = load_config(CONFIGS / "demo.yaml")
    assert cfg.data.demo is not None and cfg.site is None
    assert cfg.data.demo.gap == ("2019-03-10", "2019-03-17")
    assert cfg.periods.calibration.start == "2019-01-02"  # a YAML date kept as text
    assert cfg.room_volume == 400 and cfg.air_change_rate == 0.5
    assert cfg.thermal.model == "thermal_2c" and cfg.thermal.noise == "ar1_white"
    assert cfg.hygric.priors["Gw"].dist == "lognormal"
    assert cfg.hygric.model == "hygric_2c" and cfg.hygric.noise == "ar1_white"


def test_yaml_dates_and_offsets_are_accepted():
    raw = yaml.safe_load(
        """
        data: {demo: {gap: [2019-02-01, 2019-02-03T12:00:00]}}
        thermal: {model: thermal_4a}
        periods:
          calibration: {start: 2019-01-02, end: "2019-04-01T00:00+01:00"}
        """
    )
    cfg = parse_config(raw)
    assert cfg.periods.calibration.end == "2019-04-01T00:00+01:00"
    assert cfg.data.demo.gap[1].startswith("2019-02-03T12:00")


def test_single_measurement_table_becomes_a_list():
    cfg = parse_config({"data": _csv_data(), "thermal": {"model": "thermal_4a"}})
    assert isinstance(cfg.data.measurements, list) and len(cfg.data.measurements) == 1


def test_site_from_epw_or_tmy3_file_is_enough():
    data = _csv_data(irradiance="measured")
    data["weather"] = {"format": "epw", "path": "uccle.epw"}
    parse_config({"data": data, "thermal": {"model": "thermal_4a"}})


# ---------------------------------------------------------------------------------------
# error messages
# ---------------------------------------------------------------------------------------


def test_unknown_top_level_key_lists_allowed_keys():
    msg = _error(_with(modle="x"))
    assert "modle: unknown key; allowed keys: name, building, room" in msg
    assert "base_dir" not in msg


def test_unknown_nested_key_names_its_path():
    raw = {"data": _csv_data(), "thermal": {"model": "thermal_4a"}}
    raw["data"]["weather"]["colums"] = {"Te": "T"}
    msg = _error(raw)
    assert (
        "data.weather.colums: unknown key; did you mean 'columns'? Allowed keys: format, path, "
        "time_column" in msg
    )


def test_unknown_key_in_second_measurement_table_has_index():
    data = _csv_data()
    data["measurements"] = [data["measurements"], dict(data["measurements"], bogus=1)]
    msg = _error({"data": data, "thermal": {"model": "thermal_4a"}})
    assert "data.measurements[1].bogus: unknown key" in msg


def test_wrong_type_says_what_was_found():
    msg = _error(_with(seed="abc"))
    assert "seed: Input should be a valid integer" in msg and "(got 'abc')" in msg
    msg = _error(_with(site={"latitude": 100, "longitude": 5}))
    assert "site.latitude" in msg and "(got 100)" in msg
    msg = _error(_with(data={"demo": {"sensor_noise_T": -1}}))
    assert "data.demo.sensor_noise_T" in msg and "(got -1)" in msg


def test_durations_are_normalised_for_pandas():
    cfg = parse_config(_with(periods={"warmup": "3d", "init_window": "36H"}))
    assert (cfg.periods.warmup, cfg.periods.init_window) == (
        pd.Timedelta(days=3),
        pd.Timedelta(hours=36),
    )
    assert Periods().init_window == pd.Timedelta(days=30)
    # written back as text that reads the same
    assert cfg.resolved()["periods"]["warmup"] == "3D"
    assert cfg.resolved()["periods"]["init_window"] == "1D12h"
    # no warm-up unless asked for or a model starts from the steady state
    assert Periods().warmup is None


def test_bad_duration():
    msg = _error(_with(periods={"warmup": "two weeks"}))
    assert "periods.warmup: expected a duration such as '1h'" in msg
    assert msg.count("(got ") == 1
    msg = _error(_with(data={"demo": {}, "step": "0h"}))
    assert "data.step: must be positive (got '0h')" in msg


def test_priors_key_path():
    """A prior is checked when the config is loaded: every error names its key path, what
    was expected and what was found."""
    for spec, expected in (
        ({"lower": 500, "upper": 200}, "thermal.priors.Gw.lower: must be < upper (got 500 >= 200)"),
        ({"dist": "lognormal", "median": 1}, "thermal.priors.Gw: a lognormal prior needs median"),
        ({"dist": "normal", "median": 1, "sigma": 1}, "thermal.priors.Gw.median: a normal prior"),
        ({"fixed": 1, "upper": 2}, "thermal.priors.Gw.fixed: cannot be combined with ['upper']"),
        ({"sigma": 0}, "thermal.priors.Gw.sigma: must be > 0 (got 0)"),
        ({"lowr": 1}, "thermal.priors.Gw.lowr: unknown key; did you mean 'lower'?"),
        ({"upper": True}, "thermal.priors.Gw.upper: expected a number (got True)"),
    ):
        msg = _error(_with(thermal={"model": "thermal_4a", "priors": {"Gw": spec}}))
        assert expected in msg, msg


def test_priors_are_typed_and_written_back_as_given():
    """A spec is typed (numbers stay as written: ``10`` an integer, YAML 1.1's text ``1e4``
    a float) and written back with the keys given, so that a run's config.yaml and
    chain tag are those of the file."""
    given = {"Gw": {"dist": "loguniform", "lower": 0.1, "upper": 10}, "Gf": {"fixed": 0}}
    cfg = parse_config(_with(thermal={"model": "thermal_2c", "priors": given}))
    assert cfg.thermal.priors["Gw"].upper == 10 and cfg.thermal.priors["Gf"].fixed == 0
    assert cfg.resolved()["thermal"]["priors"] == given
    cfg = parse_config(_with(thermal={"model": "thermal_2c", "priors": {"Gw": {"upper": "1e4"}}}))
    assert cfg.thermal.priors["Gw"].upper == 1e4


def test_priors_must_be_mappings():
    msg = _error(_with(thermal={"model": "thermal_4a", "priors": {"Gw": 5}}))
    assert "thermal.priors.Gw: expected a mapping such as {dist: loguniform" in msg
    assert "(got 5)" in msg


@pytest.mark.parametrize(
    ("start", "end"),
    [("2019-04-01", "2019-01-01"), ("2019-01-01", "2019-01-01")],
)
def test_start_not_before_end(start, end):
    msg = _error(_with(periods={"calibration": {"start": start, "end": end}}))
    assert f"periods.calibration: start must be before end (got {start} >= {end})" in msg


def test_bad_date():
    msg = _error(_with(periods={"calibration": {"start": "yesterday", "end": "2019-01-01"}}))
    assert "periods.calibration: start/end must be dates such as 2019-01-01" in msg


def test_period_rules():
    cal = {"start": "2019-01-01", "end": "2019-04-01"}
    msg = _error(_with(periods={"validation": cal}))
    assert "periods.calibration: required when 'validation' is given" in msg
    msg = _error(
        _with(
            periods={"calibration": cal, "validation": {"start": "2019-03-01", "end": "2019-05-01"}}
        )
    )
    assert "periods.validation: overlaps the calibration period" in msg
    msg = _error(_with(periods={"calibration": cal, "warmup": "100d"}))
    assert "periods.warmup: 100D is not shorter than the calibration period" in msg


def test_missing_required_keys():
    msg = _error({"thermal": {"model": "thermal_4a"}})
    assert "data: required" in msg
    msg = _error(_with(thermal={"noise": "ar1"}))
    assert "thermal.model: required" in msg
    data = _csv_data()
    del data["weather"]["format"]
    msg = _error({"data": data, "thermal": {"model": "thermal_4a"}})
    assert "data.weather.format: required" in msg
    data = _csv_data()
    del data["measurements"]["time_column"]
    msg = _error({"data": data, "thermal": {"model": "thermal_4a"}})
    assert "data.measurements.time_column: required for format 'csv'" in msg


def test_needs_a_model_and_data():
    assert "give at least one of 'thermal' and 'hygric'" in _error({"data": {"demo": {}}})
    msg = _error({"data": {"weather": _csv_data()["weather"]}, "thermal": {"model": "x"}})
    assert "give either 'demo' or both 'weather' and 'measurements'" in msg
    msg = _error({"data": dict(_csv_data(), demo={}), "thermal": {"model": "x"}})
    assert "'demo' generates its own data" in msg


def test_options_must_fit_the_format():
    data = _csv_data()
    data["weather"] = {"format": "knmi", "path": "a.txt", "sep": ";", "timezone": "UTC"}
    msg = _error({"data": data, "thermal": {"model": "thermal_4a"}})
    assert "data.weather.timezone: only for format 'csv' (format is 'knmi'); also sep" in msg
    data = _csv_data()
    data["weather"]["year"] = 2019
    msg = _error({"data": data, "thermal": {"model": "thermal_4a"}})
    assert "data.weather.year: only for formats 'epw' and 'tmy3'" in msg
    data = _csv_data()
    data["weather"]["path"] = ["a.csv", "b.csv"]
    msg = _error({"data": data, "thermal": {"model": "thermal_4a"}})
    assert "data.weather.path: a list of files is only for format 'knmi'" in msg


def test_ground_temperature_rules():
    def gt(spec):
        return _error(_with(data={"demo": {}, "ground_temperature": spec}))

    assert "data.ground_temperature.value: required for mode 'constant'" in gt({"mode": "constant"})
    assert "data.ground_temperature.value: only for mode 'constant'" in gt({"value": 10})
    assert "data.ground_temperature.column: required for mode 'column'" in gt({"mode": "column"})
    msg = gt(
        {
            "mode": "column",
            "column": "T",
            "source": {"format": "csv", "path": "x.csv", "time_column": "t", "columns": {}},
        }
    )
    assert "data.ground_temperature.source.columns: not used here" in msg


def test_surfaces_rules():
    msg = _error(_with(data={"demo": {}, "irradiance": "none", "surfaces": {"S": [90, 180]}}))
    assert "data.surfaces: given, but irradiance is 'none'" in msg
    msg = _error(_with(data={"demo": {}, "surfaces": {"S": [90, 400]}}))
    assert "data.surfaces.S: azimuth must be within 0..360° (got 400.0)" in msg
    msg = _error(_with(data={"demo": {}, "surfaces": {"roof-E": [30, 90]}}))
    assert "data.surfaces: 'roof-E': surface names must be letters" in msg


def test_site_rules():
    assert "site: the demo uses the site of its weather file" in _error(
        _with(site={"latitude": 52, "longitude": 5})
    )
    msg = _error({"data": _csv_data(irradiance="measured"), "thermal": {"model": "thermal_4a"}})
    assert "site: required (latitude, longitude)" in msg


def test_demo_truth_sections():
    msg = _error(_with(data={"demo": {"truth": {"thermic": {"Gw": 1}}}}))
    assert "data.demo.truth.thermic" in msg


def test_not_a_mapping():
    with pytest.raises(ConfigError, match="expected a YAML mapping at the top level"):
        parse_config([1, 2])


def test_yaml_syntax_error_has_line_and_column(tmp_path):
    path = tmp_path / "bad.yaml"
    path.write_text("name: x\ndata:\n  demo: {seed: 1\nthermal: {model: thermal_4a}\n")
    with pytest.raises(ConfigError) as exc:
        load_config(path)
    msg = str(exc.value)
    assert str(path) in msg and "not valid YAML at line 4, column" in msg


def test_scientific_notation_is_a_number_as_written(tmp_path):
    """YAML 1.1 (PyYAML) reads 1.3e7 and 1e7 as text; a config reads them as numbers,
    and what YAML 1.1 already read (ints, dotted floats, text) is unchanged."""
    from heritage_bayes.config import load_yaml_text, read_yaml

    text = (
        "a: 1.3e7\nb: 1e7\nc: -5E-3\nd: 2e+8\ne: .5e3\nf: 1.0e+7\ng: 12\nh: 1_000\n"
        "i: 1e\nj: e7\nk: '1e7'\nl: 0x1f\nm: 1.5\n"
    )
    got = load_yaml_text(text, source="t")
    assert got == {
        "a": 1.3e7, "b": 1e7, "c": -5e-3, "d": 2e8, "e": 500.0, "f": 1e7, "g": 12,
        "h": 1000, "i": "1e", "j": "e7", "k": "1e7", "l": 31, "m": 1.5,
    }  # fmt: skip
    assert isinstance(got["b"], float) and isinstance(got["g"], int)
    path = tmp_path / "c.yaml"
    path.write_text(text)
    assert read_yaml(path)[0] == got
    path.write_text(
        "data: {demo: {seed: 7}}\n"
        "thermal:\n  model: thermal_4a\n"
        "  priors: {Cint: {dist: lognormal, median: 1.3e7, sigma: 1}}\n"
    )
    assert load_config(path).thermal.priors["Cint"].median == 1.3e7


def test_missing_file(tmp_path):
    with pytest.raises(ConfigError, match="config file not found"):
        load_config(tmp_path / "nope.yaml")


def test_errors_are_input_errors_without_chained_tracebacks():
    with pytest.raises(InputError) as exc:
        parse_config(_with(bogus=1))
    assert exc.value.__cause__ is None and exc.value.__suppress_context__


def test_name_defaults_to_file_stem(tmp_path):
    path = tmp_path / "my_room.yaml"
    path.write_text(yaml.safe_dump(DEMO))
    cfg = load_config(path)
    assert cfg.name == "my_room"
    assert cfg.path("data.csv") == tmp_path.resolve() / "data.csv"


def test_optimizer_restarts_key_its_default_and_the_chain_tag():
    """optimizer.restarts: unset, 3 global searches for networks of three or more nodes
    and 1 below (their MAP as before); set, that many for every network; unset keys
    added later (restarts, interior_area) leave the chain tag of earlier runs, set
    ones change it."""
    from heritage_bayes.config import chain_tag
    from heritage_bayes.config.sampler import RESTARTS

    cfg = parse_config(_with())
    assert cfg.optimizer.restarts is None and cfg.interior_area is None
    assert cfg.optimizer.restarts_for(3) == RESTARTS == 3
    assert cfg.optimizer.restarts_for(2) == cfg.optimizer.restarts_for(1) == 1
    two = parse_config(_with(optimizer={"restarts": 2}))
    assert two.optimizer.restarts_for(1) == two.optimizer.restarts_for(4) == 2
    assert chain_tag(two) != chain_tag(cfg)
    assert chain_tag(parse_config(_with(interior_area=80))) != chain_tag(cfg)
    blob = json.dumps(cfg.resolved(), sort_keys=True, default=str)
    assert '"restarts": null' in blob and '"interior_area": null' in blob
    for bad in (0, 21, "many"):
        assert "optimizer.restarts" in _error(_with(optimizer={"restarts": bad}))


# -- model options: typed when the config is loaded ---------------------------------------


def test_model_options_are_typed_at_load_and_echoed_as_written():
    raw = _with(
        thermal={
            "model": "thermal_2c",
            "options": {"ground": False, "thermostat": True, "source": True},
        },
        hygric={"model": "hygric_2c", "options": {"humidistat": "dehumidifier"}},
    )
    cfg = parse_config(raw)
    th, hy = cfg.thermal.options, cfg.hygric.options
    assert th.network_options() == {"ground": False}
    c = th.control()
    assert (c.thermostat, c.power_limit, c.source, c.humidistat) == (True, False, True, None)
    assert hy.control().humidistat == "dehumidifier" and hy.network_options() == {}
    # the run's config.yaml and the hashes read the options as the user wrote them
    assert cfg.resolved()["thermal"]["options"] == raw["thermal"]["options"]
    assert cfg.resolved()["hygric"]["options"] == {"humidistat": "dehumidifier"}


def test_model_option_errors_name_the_key_expected_and_found():
    msg = _error(_with(thermal={"model": "thermal_2c", "options": {"thermostat": 3}}))
    assert "thermal.options.thermostat: expected true, false or a mapping" in msg
    assert "(got 3)" in msg
    msg = _error(_with(thermal={"model": "thermal_2c", "options": {"humidistat": "band"}}))
    assert "thermal.options.humidistat: a humidistat controls the air of a hygric" in msg
    msg = _error(_with(hygric={"model": "hygric_2c", "options": {"humidistat": {"capacty": True}}}))
    assert "hygric.options.humidistat.capacty: unknown key; did you mean 'capacity'?" in msg
    msg = _error(_with(thermal={"model": "thermal_2c", "options": {"source": 1}}))
    assert "thermal.options.source: Input should be a valid boolean (got 1)" in msg


def test_an_option_the_model_does_not_take_names_its_key_and_models_follow_options():
    from heritage_bayes.calibration.calibrate import check_models
    from heritage_bayes.config.options import ModelOptions
    from heritage_bayes.models import build_model

    cfg = parse_config(_with(hygric={"model": "hygric_2c", "options": {"sink": "temperature"}}))
    with pytest.raises(ConfigError, match=r"^hygric\.options\.sink: model 'hygric_2c' does not"):
        check_models(cfg)
    cfg = parse_config(_with(thermal={"model": "thermal_2c", "options": {"ground": False}}))
    models, rungs = check_models(cfg)  # the run's models, built once
    assert "Tf" not in models["thermal"].input_names and rungs == {}
    sec = cfg.thermal.model_copy(update={"options": ModelOptions()})  # ground: default
    other = cfg.model_copy(update={"thermal": sec})
    assert "Tf" in build_model(other, "thermal").input_names
