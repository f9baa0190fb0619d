"""From a config section to its RC model: catalogue name (and options) or custom network.

Layer: config → **model**. Used by data preparation (a model states which inputs it
needs), by the orchestrator and by the run directory's loader; imports neither.
"""

from __future__ import annotations

import re
from collections.abc import Mapping

import pandas as pd

from heritage_bayes.config import CalibrationConfig
from heritage_bayes.config.options import NETWORK_OPTIONS, parse_options
from heritage_bayes.errors import ConfigError
from heritage_bayes.names import DEFAULT_NOISE
from heritage_bayes.rc.catalog import CATALOG, DomainView, auto_ladder, takes_option
from heritage_bayes.rc.catalog import model as catalog_model
from heritage_bayes.rc.control_spec import COMPONENTS
from heritage_bayes.rc.model import RCModel
from heritage_bayes.rc.network import Network

__all__ = [
    "AUTO",
    "AUTO_LADDERS",
    "SECTIONS",
    "auto_rungs",
    "build_model",
    "catalog_build",
    "catalog_options",
    "describe_model",
    "input_hold_of",
    "model",
    "models_of",
    "with_input_hold",
]

SECTIONS = ("thermal", "hygric")

#: ``model:`` value that screens the section's :data:`AUTO_LADDERS` (MAP and validation
#: score, :mod:`heritage_bayes.calibration.selection`) and samples the model chosen.
AUTO = "auto"
#: The rungs ``model: auto`` screens, simplest first: (catalogue name, the rung's own
#: options, the nested simpler rung whose MAP seeds this one's search), read from the
#: catalogue entries' ``rungs`` (:func:`heritage_bayes.rc.catalog.auto_ladder`). The
#: configured ``options`` (control, sources, surfaces) apply to every rung; ``sink`` is
#: the rung's. The last rung's inputs cover every rung's: the data are prepared for it.
AUTO_LADDERS: Mapping[str, tuple[tuple[str, dict, str | None], ...]] = DomainView(auto_ladder)


def rung_label(name: str, own: Mapping) -> str:
    """A rung as the console, summary and report name it: ``hygric_2c_fixed``, or with
    its own options ``hygric_2c_fixed (sink: temperature)``; the constant sink, the
    default, is not named."""
    extra = {k: v for k, v in own.items() if not (k == "sink" and v in ("constant", "none"))}
    return name + (" (" + ", ".join(f"{k}: {v}" for k, v in extra.items()) + ")" if extra else "")


def rung_options(cfg: CalibrationConfig, section: str, name: str, own: Mapping) -> dict:
    """Network options of a rung: the configured ones without ``sink``, the rung's own,
    and the solar surfaces (:func:`catalog_options`)."""
    opts = {k: v for k, v in catalog_options(cfg, section, name).items() if k != "sink"}
    return {**opts, **own}


#: Names that become variable names in posterior.nc (NetCDF) and input columns.
_NAME = re.compile(r"^[A-Za-z][A-Za-z0-9_]*$")


def _check_names(m: RCModel, where: str) -> None:
    """Parameter, node and input names of a custom network: letters, digits and '_'."""
    for kind, names in (
        ("parameter", m.parameter_names),
        ("node", m.state_names),
        ("input", m.input_names),
    ):
        bad = [n for n in names if not _NAME.match(n)]
        if bad:
            raise ConfigError(
                f"{where}: {kind} name {bad[0]!r} is not allowed: use letters, digits and "
                "'_', starting with a letter (names become variables in posterior.nc)"
            )


def build_model(cfg: CalibrationConfig, section: str) -> RCModel:
    """The RC model of config section ``thermal`` or ``hygric``.

    Catalogue models get their solar surfaces from ``data.surfaces`` (none when
    ``data.irradiance: none``); a mapping under ``model:`` is a custom network
    (:meth:`heritage_bayes.rc.Network.from_dict`); ``model: auto`` gives the richest
    rung of :func:`auto_rungs`. Each call builds a new model: a run builds its models
    once (:func:`models_of`) and hands them down.

    Raises
    ------
    ConfigError
        An unknown model, an option the model does not take (naming
        ``<section>.options.<key>``), or a model of the other domain.
    """
    sec = getattr(cfg, section)
    where = f"{section}.model"
    if isinstance(sec.model, Mapping):
        try:
            net = Network.from_dict(sec.model, where=where)
        except ValueError as exc:  # its messages name their key path
            raise ConfigError(str(exc)) from None
        try:
            m = RCModel(net)
        except ValueError as exc:
            raise ConfigError(f"{where}: {exc}") from None
        _check_names(m, where)
    elif sec.model == AUTO:  # the richest rung: its inputs cover every rung's
        return auto_rungs(cfg, section)[-1][1]
    elif sec.model not in CATALOG:
        raise ConfigError(f"{where}: unknown model {sec.model!r}; available: {sorted(CATALOG)}")
    else:
        m = catalog_build(cfg, section, sec.model, catalog_options(cfg, section, sec.model))
    if m.domain != section:
        raise ConfigError(f"{where}: a {m.domain} model cannot be used in the {section!r} section")
    return with_input_hold(cfg, m)


def models_of(cfg: CalibrationConfig) -> tuple[dict[str, RCModel], dict[str, list]]:
    """The models of a run, each built once: (section -> its model, section -> the
    rungs of a ``model: auto`` section, :func:`auto_rungs`). An automatic section's
    model is its richest rung (:func:`build_model`), whose inputs cover every rung's,
    until the screen chooses one."""
    models, rungs = {}, {}
    for section in SECTIONS:
        sec = getattr(cfg, section)
        if sec is None:
            continue
        if isinstance(sec.model, str) and sec.model == AUTO:
            rungs[section] = auto_rungs(cfg, section)
            models[section] = rungs[section][-1][1]
        else:
            models[section] = build_model(cfg, section)
    return models, rungs


def with_input_hold(cfg: CalibrationConfig, m: RCModel) -> RCModel:
    """``m`` as the data feed it: with ``data.input_hold: exact`` every network input
    gets its slope column (the data layer fills it with the change over the step for
    instantaneous readings, zeros for interval means)."""
    return m.with_slopes(m.network.inputs) if input_hold_of(cfg) == "exact" else m


def catalog_build(cfg: CalibrationConfig, section: str, name: str, options: dict) -> RCModel:
    """Catalogue model ``name`` with the network ``options`` and the section's control.

    Raises
    ------
    ConfigError
        An option ``name`` does not take (``<section>.options.<key>``, listing those it
        takes), or a combination it refuses (``<section>.options``, the model's reason).
    """
    _check_takes(name, options, f"{section}.options.")
    try:
        return catalog_model(name, getattr(cfg, section).options.control(), **options)
    except ValueError as exc:
        raise ConfigError(f"{section}.options: {exc}") from None


def auto_rungs(cfg: CalibrationConfig, section: str) -> list[tuple[str, RCModel, str | None]]:
    """The rungs of :data:`AUTO_LADDERS` that the configured options allow, built:
    (label, model, label of the nested simpler rung or None). A rung whose catalogue
    model refuses the options (e.g. a control it does not take) is left out; none
    left: :class:`ConfigError` naming ``<section>.options``."""
    rungs, refused = [], []
    labels = {}
    for name, own, parent in AUTO_LADDERS[section]:
        label = rung_label(name, own)
        labels.setdefault(name, label)  # a parent is named by its first rung
        try:
            m = catalog_build(cfg, section, name, rung_options(cfg, section, name, own))
        except ConfigError as exc:
            refused.append(f"{label}: {exc}")
            continue
        m = with_input_hold(cfg, m)
        rungs.append((label, m, labels.get(parent) if parent else None))
    if not rungs:
        raise ConfigError(
            f"{section}.model: auto: no model of the ladder takes the configured "
            f"{section}.options ({'; '.join(refused)})"
        )
    return rungs


def input_hold_of(cfg: CalibrationConfig) -> str:
    """``data.input_hold`` as configured, else ``"exact"`` for files and
    ``"interval_mean"`` for the demo (whose generator holds each input's interval mean)."""
    hold = cfg.data.input_hold
    if hold is None:
        hold = "interval_mean" if cfg.data.demo is not None else "exact"
    return hold


def initial_state_of(cfg: CalibrationConfig, section: str, model: RCModel):
    """The initial state of a section with ``model``: ``initial_state`` as
    configured, else ``"estimate"`` for a linear model and ``"steady"`` for a controlled
    room (its simulator is not linear in the state). :class:`ConfigError` for an
    estimated state on a controlled room."""
    sec = getattr(cfg, section)
    mode = sec.initial_state
    if mode is None:
        return "steady" if model.control is not None else "estimate"
    if mode != "steady" and model.control is not None:
        raise ConfigError(
            f"{section}.initial_state: {mode!r} needs a model that is linear in its state; "
            f"this {model.name} room is controlled (thermostat/humidistat): use 'steady' (with "
            "periods.warmup) or leave initial_state out"
        )
    if isinstance(mode, Mapping):
        unknown = [k for k in mode if k not in model.state_names]
        if unknown:
            raise ConfigError(
                f"{section}.initial_state: unknown node(s) {unknown}; the nodes of "
                f"{model.name} are {list(model.state_names)}"
            )
    return mode


def default_warmup(cfg: CalibrationConfig, models: Mapping[str, RCModel]) -> pd.Timedelta:
    """``periods.warmup`` when not configured: none when every model (section ->
    model) estimates its initial state, 14 days when one starts from the steady state."""
    steady = any(initial_state_of(cfg, s, m) == "steady" for s, m in models.items())
    return pd.Timedelta(days=14) if steady else pd.Timedelta(0)


def catalog_options(cfg: CalibrationConfig, section: str, name: str) -> dict:
    """Network options of catalogue model ``name`` in a section: the configured ones,
    plus the solar surfaces from ``data.surfaces`` (none when ``data.irradiance:
    none``) and, for a thermal model coupled to the ground (``ground`` true, the
    default) whose ground temperature is ``data.ground_temperature: {mode: seasonal}``
    without a ``depth``, the estimated depth (``ground: seasonal``,
    :data:`heritage_bayes.rc.catalog.GROUND_CYCLE_INPUTS`)."""
    options = getattr(cfg, section).options.network_options()
    if CATALOG[name].solar and "surfaces" not in options:
        options["surfaces"] = tuple(cfg.data.surfaces) if cfg.data.irradiance != "none" else ()
    if takes_option(name, "ground") and options.get("ground", True) is True:
        if ground_depth_estimated(cfg):
            options["ground"] = "seasonal"
    return options


def ground_depth_estimated(cfg: CalibrationConfig) -> bool:
    """Whether the thermal ground follows the season at an estimated depth: ``data.
    ground_temperature`` in mode ``seasonal`` (the default for files) without a
    ``depth``."""
    gt = cfg.data.ground_temperature
    return gt.mode == "seasonal" and gt.depth is None


def model(name: str, **options) -> RCModel:
    """A catalogue model by name, with its options as a config section writes them.

    Parameters
    ----------
    name : str
        One of :func:`heritage_bayes.available_models`.
    **options
        The keys of ``<section>.options``
        (:class:`heritage_bayes.config.options.ModelOptions`): ``surfaces``, ``ground``,
        ``heating``, ``sink``, ``thermostat`` (true or a mapping), ``humidistat`` (true,
        a mode or a mapping), ``source``.

    Raises
    ------
    ValueError
        Unknown name, an option of the wrong type or one the model does not take
        (:class:`~heritage_bayes.errors.ConfigError`, naming the option).

    Examples
    --------
    >>> model("thermal_2c", ground=False, thermostat={"power_limit": True}).parameter_names[-2:]
    ('Tset', 'Pmax')
    """
    if name not in CATALOG:
        raise ValueError(f"unknown model {name!r}; available: {sorted(CATALOG)}")
    domain = CATALOG[name].domain
    opts = parse_options(options, f"model {name!r}")
    bad = opts.misplaced_control(domain)
    if bad:
        raise ConfigError(f"model {name!r}: option {bad} needs a {COMPONENTS[bad]} model")
    net = opts.network_options()
    _check_takes(name, net, "")
    return catalog_model(name, opts.control(), **net)


def _check_takes(name: str, options: Mapping, prefix: str) -> None:
    """:class:`ConfigError` naming ``<prefix><key>`` for a network option that catalogue
    model ``name``'s factory does not take (listing those it takes)."""
    refused = [k for k in options if not takes_option(name, k)]
    if refused:
        allowed = [k for k in NETWORK_OPTIONS if takes_option(name, k)]
        raise ConfigError(
            f"{prefix}{refused[0]}: model {name!r} does not take this option; its "
            f"network options: {allowed or 'none'} (and the control: thermostat or "
            "humidistat, source)"
        )


def describe_model(name: str, noise: str = DEFAULT_NOISE) -> str:
    """A catalogue model in words: balance equations, parameters with units and default
    priors (the names ``priors:`` accepts), inputs and outputs (``hbayes models NAME``).

    Raises
    ------
    ValueError
        Unknown model or noise name (the message lists the available ones).
    """
    from heritage_bayes.config.models import (
        FILTERED_SINK_LIKELIHOOD_TEMPERATURE,
        FILTERED_SINK_MODELS,
        FILTERED_SINK_NOISE,
    )
    from heritage_bayes.inference.likelihoods import get_noise_model
    from heritage_bayes.inference.parameters import parameters_for

    if name not in CATALOG:
        raise ValueError(f"unknown model {name!r}; available: {sorted(CATALOG)}")
    m = catalog_model(name)
    net = m.network
    pot = "T" if net.domain == "thermal" else "P"
    lines = [
        f"{name}: {CATALOG[name].description}",
        "",
        "Equations (one balance per capacity node):",
    ]
    for node in () if hasattr(m, "equations") else net.nodes:
        terms = []
        for lk in net.links:
            if lk.a == node.name:
                terms.append(f"{lk.G}·({lk.b} − {node.name})")
            elif lk.b == node.name:
                terms.append(f"{lk.G}·({lk.a} − {node.name})")
        for src in net.sources:
            if src.node != node.name:
                continue
            frac = f"{src.fraction}·" if src.fraction else ""
            frac = f"({src.fraction})·" if src.fraction and "-" in src.fraction else frac
            gain = f"{src.gain}·" if isinstance(src.gain, str) else ""
            terms.append(f"{frac}{gain}{src.input}")
        lines.append(f"  {node.C}·d{node.name}/dt = " + " + ".join(terms))
    lines += [f"  {eq}" for eq in (m.equations() if hasattr(m, "equations") else ())]
    kind = "heat flows [W]" if pot == "T" else "vapour flows [kg/s]"
    lines.append(
        f"  (each term is one of the {kind} into the node; outputs: "
        f"{', '.join(net.outputs)}, measured with noise)"
    )
    if net.constants:
        lines.append(f"  constant potentials to estimate: {', '.join(net.constants)}")
    nm = get_noise_model(noise)
    ps = parameters_for(m, nm)
    lines += ["", f"Parameters (default priors; noise model {noise!r}):"]
    if name in FILTERED_SINK_MODELS and noise == DEFAULT_NOISE:
        lines.append(
            f"  (with sink: temperature and a linear isotherm the default is "
            f"{FILTERED_SINK_NOISE!r} at likelihood temperature "
            f"{FILTERED_SINK_LIKELIHOOD_TEMPERATURE:g}: hbayes models {name} --noise "
            f"{FILTERED_SINK_NOISE})"
        )
    for p in ps.parameters:
        lines.append(
            f"  {p.name:<9s} {'[' + p.unit + ']':<13s} {p.kind:<11s} "
            f"{p.prior.describe():<28s} {p.description}"
        )
    lines += ["", "Inputs (columns of the prepared data):"]
    unit_of = getattr(m, "input_unit", net.input_unit)
    for i in m.input_names:
        lines.append(f"  {i:<9s} {'[' + unit_of(i) + ']':<13s} {net.descriptions.get(i, '')}")
    lines += ["", "Outputs:"]
    unit = "°C" if pot == "T" else "Pa"
    what = "temperature" if pot == "T" else "vapour pressure"
    for o in m.output_names:
        lines.append(f"  {o:<9s} {'[' + unit + ']':<13s} measured indoor {what}")
    lines += [
        "",
        "Set a prior in the config, e.g.",
        f"  {net.domain}:",
        f"    model: {name}",
        "    priors:",
        f"      {ps.parameters[0].name}: {{dist: lognormal, median: <value>, sigma: 1}}",
        "room_volume [m³] and air_change_rate [1/h] set log-normal priors on Ci and Gfast.",
        *(
            [
                "glazing_area {surface: m²} sets log-normal priors on the apertures fI "
                "(median 0.4 × the glazed area); data.roof.area [m²] on a roof's two "
                "slopes' (median 0.07 × each slope's area).",
                "Options (under options:): ground (true | false | estimate), heating; the "
                "solar surfaces come from data.surfaces (and data.roof: an attic's slopes).",
            ]
            if net.domain == "thermal"
            else [
                "Options (under options:): sink (hygric_2c_fixed: constant | temperature; "
                "hygric_2c_sorption: none | constant | temperature); a sink at a temperature "
                "reads Tf, the thermal section's ground temperature (data.ground_temperature); "
                "isotherm (linear | gab: the buffer's capacity follows its humidity along "
                "the GAB isotherm, K_gab estimated)."
            ]
            if takes_option(name, "sink")
            else []
        ),
    ]
    return "\n".join(lines)
