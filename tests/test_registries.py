"""One registry per name list: a model or a noise model registered in one place shows up
everywhere a user meets the list (the CLI, the config, ``hbayes models``, the ladders)."""

from __future__ import annotations

import sys

import pytest
import yaml

from heritage_bayes import names
from heritage_bayes.calibration.calibrate import check_models
from heritage_bayes.calibration.findings import LADDERS
from heritage_bayes.cli import main
from heritage_bayes.compare import DEFAULT_MODELS
from heritage_bayes.config import parse_config
from heritage_bayes.errors import ConfigError
from heritage_bayes.inference import likelihoods, monitor
from heritage_bayes.models import AUTO_LADDERS, auto_rungs, build_model
from heritage_bayes.rc import catalog
from heritage_bayes.rc.network import Link, Network, Node, Source

DEMO = "configs/demo.yaml"


@pytest.fixture
def restore_registries():
    """Whatever a test registers is gone after it."""
    catalogue = dict(catalog.CATALOG)
    before = [(r, dict(r)) for r in (names.NOISE_MODELS, names.MOVES)]
    yield
    catalog.CATALOG.clear()
    catalog.CATALOG.update(catalogue)
    for registry, entries in before:
        for name in set(registry) - set(entries):
            registry.unregister(name)
        assert dict(registry) == entries


def _toy_network(surfaces=None, ground: bool = True) -> Network:
    """One air node [°C] with a conductance Ge [W/K] to outdoors and solar apertures."""
    surfaces = tuple(surfaces) if surfaces is not None else ("S",)
    return Network(
        name="thermal_toy",
        domain="thermal",
        nodes=(Node("Ti", "Ci"),),
        links=(Link("Ti", "Te", "Ge"),),
        inputs=("Te", *(f"I_{s}" for s in surfaces)),
        outputs=("Ti",),
        sources=tuple(Source(f"I_{s}", "Ti", f"fI_{s}") for s in surfaces),
    )


class _ToyNoise(likelihoods.IIDNoise):
    name = "iid_toy"
    description = "a toy: independent errors"


def _register_toys() -> None:
    catalog.register(
        "thermal_toy",
        catalog.CatalogModel(
            _toy_network,
            "a toy: one air node",
            "thermal",
            solar=True,
            ladder=True,
            rungs=(({}, "thermal_4a"),),
        ),
    )
    likelihoods.register_noise(_ToyNoise)  # the one place its name is listed


def _config(**section):
    raw = yaml.safe_load(open(DEMO, encoding="utf-8"))
    raw["thermal"].update(section)
    return parse_config(raw, source="test")


def test_a_registered_model_and_noise_model_show_up_everywhere(restore_registries, capsys):
    _register_toys()
    with pytest.raises(ValueError, match="registered once"):
        likelihoods.register_noise(_ToyNoise)
    # the ladders: the model-order ladder (run ladder, compare, findings) and auto's rungs
    assert LADDERS["thermal"][-1] == DEFAULT_MODELS["thermal"][-1] == "thermal_toy"
    assert AUTO_LADDERS["thermal"][-1] == ("thermal_toy", {}, "thermal_4a")
    cfg = _config(model="auto", noise="iid_toy")
    labels = [(label, parent) for label, _, parent in auto_rungs(cfg, "thermal")]
    assert labels[-1] == ("thermal_toy", "thermal_4a")
    # the config takes both names; the solar surfaces come from data.surfaces
    cfg = _config(model="thermal_toy", noise="iid_toy")
    check_models(cfg)
    m = build_model(cfg, "thermal")
    assert [f"fI_{s}" for s in cfg.data.surfaces] == [
        n for n in m.parameter_names if n.startswith("fI_")
    ]
    # the CLI: the --noise choices and `hbayes models`
    assert main(["models", "--help"]) == 0
    assert "noise model: ar1_white, ar1, iid, kalman, iid_toy (default" in " ".join(
        capsys.readouterr().out.split()
    )
    from heritage_bayes.reference import config_reference

    assert "iid_toy (a toy: independent errors)" in config_reference()
    assert main(["models"]) == 0
    assert "thermal_toy" in capsys.readouterr().out
    assert main(["models", "thermal_toy", "--noise", "iid_toy"]) == 0
    out = capsys.readouterr().out
    assert "thermal_toy: a toy: one air node" in out and "Ge " in out


def test_an_unregistered_name_is_refused_with_the_registry_s_names():
    with pytest.raises(ConfigError, match=r"thermal\.noise: Input should be 'ar1_white', 'ar1'"):
        _config(noise="iid_toy")
    with pytest.raises(ConfigError, match=r"thermal\.model: unknown model 'thermal_toy'"):
        build_model(_config(model="thermal_toy"), "thermal")

    class Undescribed(likelihoods.IIDNoise):
        name = "undescribed_toy"

    with pytest.raises(ValueError, match="a description of its own is required"):
        likelihoods.register_noise(Undescribed)
    assert "undescribed_toy" not in names.NOISE_MODELS

    class Taken(likelihoods.IIDNoise):
        description = "registered twice"

    with pytest.raises(ValueError, match="'iid': registered once"):
        likelihoods.register_noise(Taken)
    assert names.NOISE_MODELS["iid"] is likelihoods.IIDNoise
    with pytest.raises(ValueError, match="rung parent 'thermal_nope'"):
        catalog.register(
            "thermal_toy",
            catalog.CatalogModel(_toy_network, "toy", "thermal", rungs=(({}, "thermal_nope"),)),
        )
    assert "thermal_toy" not in catalog.CATALOG


def test_every_declared_name_has_its_implementation_and_no_other():
    assert likelihoods.NOISE_MODELS is names.NOISE_MODELS  # one registry
    assert list(names.NOISE_MODELS) == ["ar1_white", "ar1", "iid", "kalman"]
    assert next(iter(names.NOISE_MODELS)) == names.DEFAULT_NOISE
    assert monitor.MOVES is names.MOVES  # one registry
    assert list(names.MOVES) == [
        "de_snooker",
        "de_snooker_50",
        "de",
        "stretch",
        "de_global",
        "dime",
    ]
    assert next(iter(names.MOVES)) == names.DEFAULT_MOVE
    for name, mixture in names.MOVES.items():
        assert mixture.name == name
    for name, cls in likelihoods.NOISE_MODELS.items():
        assert cls.name == name
    for name, entry in catalog.CATALOG.items():
        assert catalog.model(name).domain == entry.domain


def test_a_registered_move_shows_in_the_settings_and_an_unknown_one_is_refused(
    restore_registries,
):
    """A move mixture registered in one place is a choice of ``sampler.moves`` (its
    description in the reference) and builds its emcee moves; a name not registered is
    refused with the registry's names."""
    import emcee

    from heritage_bayes.reference import config_reference

    raw = {**yaml.safe_load(open(DEMO, encoding="utf-8")), "sampler": {"moves": "walk"}}
    with pytest.raises(ConfigError, match=r"sampler\.moves: Input should be 'de_snooker', "):
        parse_config(raw, source="test")
    with pytest.raises(ValueError, match=r"sampler\.moves must be one of .*'dime'.*'walk'"):
        monitor.make_moves("walk")
    monitor.register_move("walk", "a toy: the stretch move", (emcee.moves.StretchMove, 1.0))
    assert parse_config(raw, source="test").sampler.moves == "walk"
    assert "walk (a toy: the stretch move)" in config_reference()
    (move, weight), block = monitor.make_moves("walk", [1], 0.25)
    assert isinstance(move, emcee.moves.StretchMove) and weight == 0.75 and block[1] == 0.25
    with pytest.raises(ValueError, match="sampler move 'walk': registered once"):
        monitor.register_move("walk", "again", (emcee.moves.StretchMove, 1.0))
    with pytest.raises(ValueError, match="shares sum to 1"):
        monitor.register_move("half", "a toy", (emcee.moves.StretchMove, 0.5))
    assert "half" not in names.MOVES


def test_a_model_s_own_parameter_roles_take_the_room_s_priors(restore_registries):
    """The room's description sets priors by role: a model naming its air capacity
    ``Ca`` declares the role and gets ``room_volume``'s prior on it."""
    from heritage_bayes.inference.parameters import parameters_for
    from heritage_bayes.inference.survey import air_capacity_prior

    def network() -> Network:
        return Network(
            name="thermal_ca",
            domain="thermal",
            nodes=(Node("Ti", "Ca"),),
            links=(Link("Ti", "Te", "Ge"),),
            inputs=("Te",),
            outputs=("Ti",),
        )

    catalog.register(
        "thermal_ca",
        catalog.CatalogModel(network, "toy", "thermal", roles={"Ca": "air_capacity"}),
    )
    ps = parameters_for(
        catalog.model("thermal_ca"), likelihoods.get_noise_model("iid"), room_volume=80.0
    )
    assert ps.parameters[ps.names.index("Ca")].prior == air_capacity_prior("thermal", 80.0)
    default = parameters_for(
        catalog.model("thermal_1c"), likelihoods.get_noise_model("iid"), room_volume=80.0
    )
    assert default.parameters[default.names.index("Ci")].prior == air_capacity_prior(
        "thermal", 80.0
    )


def test_a_registry_s_first_read_imports_its_home(tmp_path, monkeypatch):
    """The settings sit below the noise models: a config naming one is valid whoever
    asks first, because the registry's first read imports the module that fills it."""
    assert names.NOISE_MODELS.home == "heritage_bayes.inference"
    toys = names.Registry("toy", "toy_home_for_the_registry_test")
    (tmp_path / "toy_home_for_the_registry_test.py").write_text(
        "from test_registries import TOYS\nTOYS.register('built_in', 1)\n"
    )
    monkeypatch.syspath_prepend(str(tmp_path))
    monkeypatch.setitem(sys.modules, "test_registries", sys.modules[__name__])
    monkeypatch.setattr(sys.modules[__name__], "TOYS", toys, raising=False)
    monkeypatch.delitem(sys.modules, "toy_home_for_the_registry_test", raising=False)
    assert "built_in" in toys and list(toys) == ["built_in"]
    toys.register("added", 2)
    with pytest.raises(ValueError, match="'added': registered once"):
        toys.register("added", 3)
    assert dict(toys) == {"built_in": 1, "added": 2}


def test_a_model_without_a_modal_form_is_offered_the_registered_residual_models(
    restore_registries,
):
    """A state-space noise model cannot filter a model whose transitions follow its
    state (a GAB buffer); the message offers the registered noise models of the
    residuals, a newly registered one included."""
    import heritage_bayes as hb
    from heritage_bayes.run import section_parameters

    _register_toys()
    cfg = parse_config(
        {**yaml.safe_load(open(DEMO, encoding="utf-8")), "thermal": None},
        source="test",
    )
    cfg.hygric.model, cfg.hygric.noise = "hygric_2c_sorption", "kalman"
    model = hb.model("hygric_2c_sorption", isotherm="gab")
    with pytest.raises(ConfigError, match=r"use one of ar1_white, ar1, iid, iid_toy$"):
        section_parameters(cfg, "hygric", model)


def test_the_settings_and_hbayes_version_leave_the_numerics_unimported():
    """The registries are read lazily: defining the settings (whose ``noise:`` and
    ``sampler.moves`` choose from them) and ``hbayes --version`` import no sampler."""
    import subprocess

    code = (
        "import sys\n"
        "from heritage_bayes.config import sampler, models\n"
        "from heritage_bayes.cli import main\n"
        "assert main(['--version']) == 0\n"
        "print(sorted(m for m in ('emcee', 'heritage_bayes.inference') if m in sys.modules))\n"
    )
    out = subprocess.run(
        [sys.executable, "-c", code], capture_output=True, text=True, check=True
    ).stdout
    assert out.splitlines()[-1] == "[]"
