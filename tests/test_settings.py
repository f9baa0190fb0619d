"""The settings layer (issue 30): a config that cannot be misread, parsed once.

Durations need a unit, unknown keys are answered with the nearest known key, every key
is documented in the schema, the YAML reader refuses tags and alias floods, and the
typed settings below the boundary are timedeltas and tz objects.
"""

from __future__ import annotations

import datetime as dt
import zoneinfo
from pathlib import Path

import pandas as pd
import pytest
import yaml
from pydantic import BaseModel

from heritage_bayes.config import (
    CalibrationConfig,
    config_hash,
    config_keys,
    describe_key,
    load_config,
    parse_config,
    parse_duration,
    read_yaml,
)
from heritage_bayes.config.loader import MAX_ALIASES
from heritage_bayes.errors import ConfigError
from test_config import CONFIGS, _error, _with

# -- durations need a unit -----------------------------------------------------------------


@pytest.mark.parametrize("value", [10, 10.0, "10", " 10 ", "1.5e3"])
def test_a_bare_number_is_refused_with_the_units_suggested(value):
    msg = _error(_with(sampler={"max_time": value}))
    shown = str(value).strip() if isinstance(value, str) else f"{value:g}"
    assert f"sampler.max_time: a duration needs a unit: write e.g. '{shown}min'" in msg
    assert f"'{shown}s'" in msg and "a bare number" in msg


@pytest.mark.parametrize(
    "key, section",
    [
        ("step", "data"),
        ("max_gap", "data"),
        ("warmup", "periods"),
        ("init_window", "periods"),
    ],
)
def test_every_duration_key_needs_a_unit(key, section):
    sec = {"demo": {}, key: 6} if section == "data" else {key: 6}
    msg = _error(_with(**{section: sec}))
    assert f"{section}.{key}: a duration needs a unit" in msg


def test_model_section_durations_need_a_unit_and_take_none():
    msg = _error(_with(thermal={"model": "thermal_2c", "time_constant_cap": 365}))
    assert "thermal.time_constant_cap: a duration needs a unit" in msg
    cfg = parse_config(
        _with(thermal={"model": "thermal_2c", "time_constant_cap": "none"}, hygric=None)
    )
    assert cfg.thermal.cap_seconds("thermal") == float("inf")
    cfg = parse_config(_with(thermal={"model": "thermal_2c", "initial_state_horizon": "90d"}))
    assert cfg.thermal.horizon_seconds == 90 * 86400.0


def test_durations_become_timedeltas_and_are_written_back_as_text():
    cfg = parse_config(_with(sampler={"max_time": "10min"}, data={"demo": {}, "step": "30min"}))
    assert cfg.sampler.max_time == pd.Timedelta(minutes=10)
    assert cfg.sampler.max_seconds == 600.0
    assert cfg.data.step == pd.Timedelta(minutes=30)
    resolved = cfg.resolved()
    assert (resolved["sampler"]["max_time"], resolved["data"]["step"]) == ("10min", "30min")
    again = parse_config(resolved)  # the run's config.yaml reads back to the same values
    assert again.sampler.max_time == cfg.sampler.max_time and again.data.step == cfg.data.step
    assert config_hash(again) == config_hash(cfg)
    none = parse_config(_with(sampler={"max_time": "none"}))
    assert none.sampler.max_time is None and none.resolved()["sampler"]["max_time"] == "none"


def test_parse_duration_units():
    assert parse_duration("14d") == pd.Timedelta(days=14)
    assert parse_duration("36H") == pd.Timedelta(hours=36)
    assert parse_duration("1d12h") == pd.Timedelta(hours=36)
    assert parse_duration(dt.timedelta(minutes=5)) == pd.Timedelta(minutes=5)
    for bad in (10, "10", True, None, "two weeks"):
        with pytest.raises(ValueError):
            parse_duration(bad)


# -- clocks are tz objects -----------------------------------------------------------------


def test_a_clock_is_a_tz_object_and_a_bad_one_names_its_key():
    cfg = load_config(CONFIGS / "trh1_attic.yaml")
    tz = cfg.data.measurements[0].timezone
    assert isinstance(tz, dt.tzinfo) and tz.utcoffset(None) == dt.timedelta(hours=2)
    assert cfg.resolved()["data"]["measurements"][0]["timezone"] == "UTC+02:00"
    raw = {
        "data": {
            "weather": {"format": "csv", "path": "w.csv", "time_column": "t", "timezone": "EET"},
            "measurements": {
                "format": "csv",
                "path": "m.csv",
                "time_column": "t",
                "timezone": "Europe/Helsinky",
            },
            "irradiance": "none",
        },
        "thermal": {"model": "thermal_1c"},
    }
    msg = _error(raw)
    assert "data.measurements.timezone: unknown timezone 'Europe/Helsinky'" in msg
    raw["data"]["measurements"]["timezone"] = "Europe/Helsinki"
    cfg = parse_config(raw)
    assert cfg.data.measurements[0].timezone == zoneinfo.ZoneInfo("Europe/Helsinki")


# -- unknown keys: the nearest known one ---------------------------------------------------


def test_a_misspelt_key_names_the_nearest_known_one():
    msg = _error(_with(sampler={"max_tme": "10min"}))
    assert "sampler.max_tme: unknown key; did you mean 'max_time'? Allowed keys: walkers" in msg
    msg = _error(_with(thermal={"model": "thermal_2c", "Noise": "iid"}))
    assert "thermal.Noise: unknown key; did you mean 'noise'?" in msg


def test_a_key_in_the_wrong_section_names_its_section():
    msg = _error(_with(max_time="10min"))
    assert "max_time: unknown key; 'max_time' belongs in sampler.max_time" in msg
    msg = _error(_with(periods={"step": "1h"}))
    assert "periods.step: unknown key; 'step' belongs in data.step" in msg


# -- the schema documents every key --------------------------------------------------------


def _models(root: type[BaseModel]) -> set[type[BaseModel]]:
    from heritage_bayes.config._messages import _model_of

    found, todo = set(), [root]
    while todo:
        cls = todo.pop()
        if cls in found:
            continue
        found.add(cls)
        todo.extend(m for f in cls.model_fields.values() if (m := _model_of(f.annotation)))
    return found


def test_every_key_has_a_description_a_unit_entry_and_a_default():
    models = _models(CalibrationConfig)
    assert len(models) == 16  # every section is reached (data.roof; priors; the model options)
    for cls in models:
        for name, field in cls.model_fields.items():
            where = f"{cls.__name__}.{name}"
            assert field.description and len(field.description) > 10, where
            extra = field.json_schema_extra
            assert isinstance(extra, dict) and "unit" in extra, where
    keys = config_keys()
    paths = [k.path for k in keys]
    assert len(paths) == len(set(paths))
    # numbers carry a unit
    for k in keys:
        if k.type in ("float", "float | None"):
            assert k.unit, k.path
    required = {k.path for k in keys if k.required}
    assert required >= {"data", "site.latitude", "data.weather.format", "thermal.model"}


def test_the_reference_gives_defaults_as_written_in_yaml():
    keys = {k.path: k for k in config_keys()}
    assert keys["sampler.max_time"].default == "30min"
    assert keys["sampler.max_time"].unit == "duration"
    assert keys["periods.init_window"].default == "30D"
    assert keys["room_volume"].unit == "m³"
    assert keys["data.measurements"].section and keys["data.measurements.timezone"].unit is None
    assert describe_key("data.step") == (
        "data.step [duration] (default 1h): the model's time step: every table is put on this grid"
    )
    with pytest.raises(KeyError):
        describe_key("data.nope")
    # the pydantic JSON schema carries the units too (the docs may walk either)
    schema = CalibrationConfig.model_json_schema()
    assert schema["properties"]["room_volume"]["unit"] == "m³"


# -- the YAML reader ------------------------------------------------------------------------


def _write(tmp_path: Path, text: str) -> Path:
    p = tmp_path / "c.yaml"
    p.write_text(text, encoding="utf-8")
    return p


@pytest.mark.parametrize(
    "text, tag",
    [
        ("notes: !!python/object:os.system ls\n", "tag:yaml.org,2002:python/object:os.system"),
        ("notes: !!binary aGVsbG8=\n", "tag:yaml.org,2002:binary"),
        ("notes: !!str 5\n", "tag:yaml.org,2002:str"),
        ("notes: !custom x\n", "!custom"),
        ("notes: !!set {a, b}\n", "tag:yaml.org,2002:set"),
    ],
)
def test_tags_are_refused_with_the_line(tmp_path, text, tag):
    with pytest.raises(ConfigError) as exc:
        read_yaml(_write(tmp_path, "seed: 1\n" + text))
    msg = str(exc.value)
    assert "not valid YAML at line 2" in msg and f"the tag {tag!r} is not allowed" in msg


def test_aliases_are_bounded_but_a_few_are_fine(tmp_path):
    few = "base: &b {seed: 1}\nx: *b\ny: *b\n"
    raw, _ = read_yaml(_write(tmp_path, few))
    assert raw["x"] == raw["y"] == {"seed": 1}
    many = "a: &a 1\nl: [" + ", ".join(["*a"] * (MAX_ALIASES + 1)) + "]\n"
    with pytest.raises(ConfigError, match=rf"more than {MAX_ALIASES} aliases"):
        read_yaml(_write(tmp_path, many))


def test_quoted_and_plain_values_still_load(tmp_path):
    text = yaml.safe_dump({"notes": "!not a tag", "name": "x"}) + "building: '5'\n"
    raw, _ = read_yaml(_write(tmp_path, text))
    assert raw == {"notes": "!not a tag", "name": "x", "building": "5"}


# -- every shipped config is valid under the stricter schema --------------------------------


@pytest.mark.parametrize(
    "path",
    sorted(CONFIGS.glob("*.yaml"))
    + sorted((CONFIGS.parent / "benchmarks" / "configs").glob("*.yaml")),
    ids=lambda p: p.name,
)
def test_shipped_configs_have_no_bare_durations_or_tags(path):
    raw, _ = read_yaml(path)
    if "data" in raw:  # a calibration config (others: projection, portfolio)
        load_config(path)


# -- findings before sampling: a decision taken in the config is said, not warned ---------


def _section_at_cap(noise="ar1_white"):
    from types import SimpleNamespace as Ns

    import numpy as np

    from heritage_bayes.inference.likelihoods import get_noise_model

    phi = Ns(name="phi_Ti", prior=Ns(upper=0.96))
    params = Ns(
        names=["Ci", "phi_Ti"],
        parameters=[Ns(name="Ci"), phi],
        at_bound=lambda x: [("phi_Ti", "upper")],
    )
    nm = get_noise_model(noise)
    logpost = Ns(params=params, dt=3600.0, noise=nm, n_model=1, record_seconds=1e7)
    ident = Ns(has_scale_direction=False, identifiable={"Ci": True})
    return Ns(
        name="thermal",
        model=Ns(
            name="thermal_1c",
            domain="thermal",
            parameter_names=["Ci"],
            output_names=("Ti",),
            state_names=("Ti",),
        ),
        logpost=logpost,
        map=Ns(x=np.zeros(2), theta=np.array([1e7, 0.96]), modes=[]),
        identifiability=ident,
        laplace=None,
        map_at_bound=[],
        frozen_node=None,
    )


def test_a_phi_at_its_cap_is_warned_once_and_not_when_the_config_sets_it(monkeypatch, capsys):
    import heritage_bayes.calibration.calibrate as cal
    import heritage_bayes.calibration.findings as fin

    monkeypatch.setattr(fin, "frozen_time_constant", lambda *a: None)
    fin.say_findings(cal._Progress(quiet=False), _section_at_cap())
    err = capsys.readouterr().err
    assert err.count("hbayes: warning:") == 1  # the cap, not also "MAP on a prior bound"
    assert "phi_Ti at its cap 0.96" in err and "about 24 h" in err
    priors = {"phi_Ti": {"dist": "uniform", "lower": 0, "upper": 0.96}}
    fin.say_findings(cal._Progress(quiet=False), _section_at_cap(), priors)
    err = capsys.readouterr().err
    assert "warning" not in err and "phi_Ti at its cap 0.96" in err  # said, not warned
    # with a single AR(1) the cap is not explained: the bound is flagged
    fin.say_findings(cal._Progress(quiet=False), _section_at_cap("ar1"))
    assert "the MAP lies on a prior bound for phi_Ti (upper)" in capsys.readouterr().err


def test_a_parameter_the_config_pins_is_not_flagged_as_unidentified(monkeypatch, capsys):
    """demo.yaml closes hygric_2c's Cw-Gw direction with a lognormal prior on Gw: the
    advice 'add an informative prior' is already taken, so no warning for it."""
    import heritage_bayes.calibration.calibrate as cal
    import heritage_bayes.calibration.findings as fin

    monkeypatch.setattr(fin, "frozen_time_constant", lambda *a: None)
    s = _section_at_cap("ar1")
    s.logpost.params.at_bound = lambda x: []
    s.identifiability.identifiable = {"Ci": True, "Gw": False}
    fin.say_findings(cal._Progress(quiet=True), s)
    assert "over-parameterised for these data (structurally not identifiable: Gw)" in (
        capsys.readouterr().err
    )
    fin.say_findings(cal._Progress(quiet=True), s, {"Gw": {"dist": "lognormal"}})
    assert capsys.readouterr().err == ""
