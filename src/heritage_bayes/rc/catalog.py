"""The paper's models and the ladder of model orders around them.

Thermal models (domain ``thermal``: [°C], [J/K], [W/K], apertures [m²], irradiance
[W/m²]); inputs ``Te`` (outdoor air temperature [°C]), one irradiance per solar surface
``I_<surface>`` (default the four vertical facades N, E, S, W, the paper's order) and
``Tf`` (fixed/ground temperature [°C]).

- ``thermal_4a``: the paper's Figure 1, nodes ``Tw`` (envelope, ``Cw``), ``Ti`` (indoor
  air, ``Ci``), ``Tint`` (interior mass, ``Cint``); conductances ``Gw`` (wall to outdoor),
  ``Gi`` (wall to indoor air), ``Gint`` (air to interior mass), ``Gfast`` (ventilation
  and other fast paths to outdoor air), ``Gf`` (air to the fixed/ground temperature).
  **Solar parameterization**: one effective aperture per surface ``fI_<surface>`` [m²]
  (window area × transmittance × shading, the paper's vector fI) and one split fraction
  ``fsol`` [-]: the share of the solar gain absorbed by the interior mass ``Cint``; the
  rest, ``1 - fsol``, heats the air node ``Ci`` (the paper's text: "connected to Cint
  and Ci"). With ``fsol = 0`` the B matrix is exactly the paper's printed matrix.
- ``thermal_4a_nosolar``: the same network without solar input (the paper's
  "no solar input" row).
- ``thermal_2c``: ``thermal_4a`` without the interior-mass node.
- ``thermal_1c``: one air node with total conductance ``Ge`` to outdoor air, ``Gf`` to
  ``Tf`` and solar apertures.

Hygric models (domain ``hygric``: [Pa], [kg/Pa], [kg/(s·Pa)]), input ``Pe`` (outdoor
vapour pressure [Pa]), output ``Pi``:

- ``hygric_2c``: the paper's "model 3", nodes ``Pw`` (``Cw``, buffering surfaces) and
  ``Pi`` (``Ci``, indoor air), conductances ``Gw``, ``Gi``, ``Gfast``.
- ``hygric_2c_fixed``: adds ``Gf`` to a fixed vapour-pressure node whose pressure ``Pf``
  [Pa] is an estimable constant (the paper's "additional fixed vapour pressure node",
  e.g. a wall in contact with a canal). Option ``sink: temperature``: the node is a
  vapour sink at a temperature, pressure ``phi_f · psat(Tf)`` with ``Tf`` [°C] the
  ground/neighbour temperature input (as the thermal models' ground) and ``phi_f`` [-]
  estimated (near saturation): a cellar's soil, a crawlspace, a canal wall; ``sink:
  constant`` (the default) is the paper's constant node.
- ``hygric_1c``: one air node ``Pi`` with ``Gfast`` to ``Pe`` (ladder bottom).
- ``hygric_2c_sorption``: thermo-hygric coupling (:mod:`heritage_bayes.rc.sorption`):
  the air ``Pi`` (``Ci``, ``Gfast`` to ``Pe``) and a sorbing buffer of moisture capacity
  ``Cm`` [kg] per unit surface RH, exchanging vapour with the air through ``Gi`` at its
  surface vapour pressure ``φ_w · psat(Ti)``; option ``sink`` (``none``, ``constant``,
  ``temperature``) adds the fixed node of ``hygric_2c_fixed``. Linear time-varying given
  the temperature, simulated by an exact per-step recursion.

Option ``isotherm`` of ``hygric_2c_fixed`` and ``hygric_2c_sorption``: ``linear`` (the
default, one capacity) or ``gab``, a buffer whose capacity follows its humidity along
the GAB isotherm's slope, with the multilayer factor ``K_gab`` [-] estimated
(:mod:`heritage_bayes.rc.isotherm`; ``K_gab = 0`` is the linear buffer).

Each model is one :class:`CatalogModel` entry of :data:`CATALOG` (its network factory,
description, domain, solar surfaces, place on the model-order ladder, rungs of ``model:
auto`` and parameter roles), from which the command line, the settings, the ladders and
the priors read; :func:`register` adds one.

Options (keywords of :func:`model`): ``surfaces`` (sequence of surface names for the
thermal models with solar), ``ground`` (default True: ``Gf`` to the input column ``Tf``;
False: no fixed node; ``"estimate"``: ``Tf`` [°C] is a constant to estimate, like the
fixed vapour pressure ``Pf`` of hygric model 3: a ground or neighbouring space of
unknown but steady temperature, or the net effect of minimal heating; ``"seasonal"``:
``Tf`` is the soil temperature at 1 m under the annual cycle of the surface, and its
equivalent depth ``zf`` [m] is estimated: a :class:`~heritage_bayes.rc.network.GroundCycle`
with the inputs ``Tf_cos``, ``Tf_sin`` [K], the surface's annual anomaly and its
quadrature, so that the ground follows the Kusuda-Achenbach temperature at depth
``zf``, damped by :math:`e^{-z_f/d}` and delayed by :math:`z_f/(d\\omega)`),
``heating`` (bool, default False: an input ``Ph`` [W] of known gain 1 into the air node,
e.g. measured heating power in a test cell; it makes the absolute scale of C and G
identifiable).

Control of the air node (a heated, humidity-controlled or occupied room; see
:mod:`heritage_bayes.rc.control`): a typed :class:`~heritage_bayes.rc.control_spec.Control`
(thermostat, humidistat, constant source), which any catalogue model takes, e.g.
``model("thermal_2c", Control(thermostat=True, power_limit=True))``; the settings build
it from a section's ``options`` (:mod:`heritage_bayes.config.options`), and
:func:`heritage_bayes.model` takes the options as the YAML writes them.
"""

from __future__ import annotations

import inspect
from collections.abc import Callable, Iterable, Iterator, Mapping, Sequence
from typing import NamedTuple

from heritage_bayes.climate.ground import GROUND_DEPTH
from heritage_bayes.rc.control import controlled
from heritage_bayes.rc.control_spec import Control
from heritage_bayes.rc.isotherm import ISOTHERMS, IsothermHygricModel
from heritage_bayes.rc.model import RCModel
from heritage_bayes.rc.network import GroundCycle, Link, Network, Node, Source
from heritage_bayes.rc.sorption import CoupledHygricModel, coupled_network

__all__ = [
    "APERTURE_PREFIX",
    "CATALOG",
    "DOMAINS",
    "GROUND_CYCLE_INPUTS",
    "GROUND_REFERENCE",
    "ROLES",
    "CatalogModel",
    "DomainView",
    "auto_ladder",
    "available_models",
    "model",
    "model_ladder",
    "register",
    "roles_of",
    "solar_apertures",
    "takes_option",
]

DEFAULT_SURFACES = ("N", "E", "S", "W")

_DESCRIPTIONS = {
    "Cw": "capacity of the envelope (walls)",
    "Ci": "capacity of the indoor air node (incl. fast-responding contents)",
    "Cint": "capacity of the interior constructions and contents",
    "Gw": "conductance envelope - outdoor",
    "Gi": "conductance envelope - indoor air",
    "Gint": "conductance indoor air - interior mass",
    "Gfast": "fast conductance indoor air - outdoor (ventilation, glazing)",
    "Gf": "conductance indoor air - fixed node (ground / fixed potential)",
    "Ge": "total conductance indoor air - outdoor",
    "fsol": "share of solar gain absorbed by the interior mass (rest heats the air)",
    "Pf": "vapour pressure of the fixed node",
    "Te": "outdoor air temperature",
    "Tf": "fixed (ground) temperature",
    "Pe": "outdoor vapour pressure",
    "Ph": "heating power into the air node (known gain 1)",
    "zf": "equivalent depth of the ground temperature in clay/silt soil",
    "dTf": "the ground's annual mean minus the outdoor air's (of its fitted cycle)",
    "Tf_cos": "annual anomaly of the ground surface (fitted to the outdoor air)",
    "Tf_sin": "quadrature of the ground surface's annual anomaly",
}

#: Input columns of the surface's annual cycle, :func:`heritage_bayes.climate.ground.
#: annual_components` (anomaly, quadrature) [K], of option ``ground: seasonal``.
GROUND_CYCLE_INPUTS = ("Tf_cos", "Tf_sin")
#: Depth [m] at which the input ``Tf`` is given under option ``ground: seasonal``
#: (:data:`heritage_bayes.climate.ground.GROUND_DEPTH`).
GROUND_REFERENCE = GROUND_DEPTH


def _thermal(
    name: str, *, nodes: str, surfaces: Sequence[str] | None, ground: bool | str, heating: bool
) -> Network:
    surfaces = tuple(surfaces) if surfaces else ()
    desc = dict(_DESCRIPTIONS)
    node_list = {
        "1c": [Node("Ti", "Ci")],
        "2c": [Node("Tw", "Cw"), Node("Ti", "Ci")],
        "3c": [Node("Tw", "Cw"), Node("Ti", "Ci"), Node("Tint", "Cint")],
    }[nodes]
    if nodes == "1c":
        links = [Link("Ti", "Te", "Ge")]
    else:
        links = [Link("Tw", "Te", "Gw"), Link("Tw", "Ti", "Gi")]
        if nodes == "3c":
            links.append(Link("Ti", "Tint", "Gint"))
        links.append(Link("Ti", "Te", "Gfast"))
    if ground not in (True, False, "estimate", "seasonal"):
        raise ValueError(
            f"model {name!r}: option ground must be true, false, 'estimate' or 'seasonal' "
            f"(got {ground!r})"
        )
    if ground:
        links.append(Link("Ti", "Tf", "Gf"))
    # ground="estimate": Tf is a constant potential to estimate [°C] (the thermal
    # counterpart of hygric model 3's fixed vapour-pressure node), not an input column
    constants = ("Tf",) if ground == "estimate" else ()
    inputs = (
        ["Te"] + [f"I_{s}" for s in surfaces] + (["Tf"] if ground in (True, "seasonal") else [])
    )
    cycles, units = (), {}
    if ground == "seasonal":  # Tf given at GROUND_REFERENCE, its depth zf estimated
        inputs += list(GROUND_CYCLE_INPUTS)
        cycles = (GroundCycle("Ti", "Gf", "zf", GROUND_CYCLE_INPUTS, GROUND_REFERENCE, "dTf"),)
        units = dict.fromkeys(GROUND_CYCLE_INPUTS, "K")
    sources = []
    for s in surfaces:
        desc[f"fI_{s}"] = f"effective solar aperture of surface {s}"
        desc[f"I_{s}"] = f"solar irradiance on surface {s}"
        if nodes == "3c":
            sources.append(Source(f"I_{s}", "Ti", f"fI_{s}", "1-fsol"))
            sources.append(Source(f"I_{s}", "Tint", f"fI_{s}", "fsol"))
        else:
            sources.append(Source(f"I_{s}", "Ti", f"fI_{s}"))
    if heating:
        inputs.append("Ph")
        sources.append(Source("Ph", "Ti", 1.0))
        units["Ph"] = "W"
    return Network(
        name=name,
        domain="thermal",
        nodes=tuple(node_list),
        links=tuple(links),
        inputs=tuple(inputs),
        outputs=("Ti",),
        sources=tuple(sources),
        constants=constants,
        cycles=cycles,
        descriptions=desc,
        input_units=units,
    )


def _hygric(name: str, *, nodes: str, fixed: bool) -> Network:
    if nodes == "1c":
        node_list = [Node("Pi", "Ci")]
        links = [Link("Pi", "Pe", "Gfast")]
    else:
        node_list = [Node("Pw", "Cw"), Node("Pi", "Ci")]
        links = [Link("Pw", "Pe", "Gw"), Link("Pw", "Pi", "Gi"), Link("Pi", "Pe", "Gfast")]
    constants = ()
    if fixed:
        links.append(Link("Pi", "Pf", "Gf"))
        constants = ("Pf",)
    desc = dict(_DESCRIPTIONS)
    desc.update(
        Cw="hygric capacity of buffering surfaces (walls, contents)",
        Ci="hygric capacity of the indoor air node",
        Gw="vapour conductance buffer - outdoor",
        Gi="vapour conductance buffer - indoor air",
        Gfast="vapour conductance indoor air - outdoor (ventilation)",
        Gf="vapour conductance indoor air - fixed vapour-pressure node",
    )
    return Network(
        name=name,
        domain="hygric",
        nodes=tuple(node_list),
        links=tuple(links),
        inputs=("Pe",),
        outputs=("Pi",),
        constants=constants,
        descriptions=desc,
    )


def _thermal_factory(nodes: str, solar: bool, name: str) -> Callable[..., Network]:
    def build(
        surfaces: Sequence[str] | None = None, ground: bool | str = True, heating: bool = False
    ) -> Network:
        if not solar and surfaces:
            raise ValueError(f"model {name!r} has no solar input; do not pass surfaces")
        surf = (surfaces if surfaces is not None else DEFAULT_SURFACES) if solar else ()
        return _thermal(name, nodes=nodes, surfaces=surf, ground=ground, heating=heating)

    return build


def _hygric_factory(nodes: str, fixed: bool, name: str) -> Callable[..., Network]:
    def build() -> Network:
        return _hygric(name, nodes=nodes, fixed=fixed)

    def build_fixed(sink: str = "constant", isotherm: str = "linear") -> Network | RCModel:
        _check_isotherm(name, isotherm)
        if sink == "constant" and isotherm == "linear":
            return _hygric(name, nodes=nodes, fixed=True)
        if sink not in ("constant", "temperature"):
            raise ValueError(
                f"model {name!r}: option sink must be 'constant' or 'temperature' (got {sink!r})"
            )
        net = coupled_network(name, sorption=False, outdoor=True, sink=sink)
        cls = IsothermHygricModel if isotherm == "gab" else CoupledHygricModel
        return cls(net, sorption=False, sink=sink)

    return build_fixed if fixed else build


def _sorption_factory(name: str) -> Callable[..., RCModel]:
    def build(sink: str = "none", isotherm: str = "linear") -> RCModel:
        _check_isotherm(name, isotherm)
        net = coupled_network(name, sorption=True, outdoor=False, sink=sink)
        cls = IsothermHygricModel if isotherm == "gab" else CoupledHygricModel
        return cls(net, sorption=True, sink=sink)

    return build


def _check_isotherm(name: str, isotherm: str) -> None:
    if isotherm not in ISOTHERMS:
        raise ValueError(
            f"model {name!r}: option isotherm must be one of {list(ISOTHERMS)} (got {isotherm!r})"
        )


class CatalogModel(NamedTuple):
    """One catalogue model: everything the package reads about it, in one entry.

    The CLI (``hbayes models``), the config's ``model:`` names, the solar surfaces a
    section's model receives, the model-order ladder (the run's ladder, the candidates
    of ``hbayes compare``, the smaller model a finding suggests) and the rungs that
    ``model: auto`` screens are all read from :data:`CATALOG`; :func:`register` adds one.
    """

    #: Builds the model from its options: a :class:`Network` (compiled and given its
    #: control by :func:`model`) or a compiled :class:`RCModel` (a time-varying model).
    factory: Callable[..., Network | RCModel]
    #: One line for ``hbayes models``.
    description: str
    #: ``"thermal"`` or ``"hygric"``: the config section it calibrates, and the control
    #: it takes (``thermostat`` or ``humidistat``).
    domain: str
    #: Takes solar surfaces: the option ``surfaces`` is filled from ``data.surfaces``.
    solar: bool = False
    #: On its section's model-order ladder (smallest first, in catalogue order).
    ladder: bool = False
    #: Rungs of ``model: auto``'s screen (in catalogue order): per rung, the rung's own
    #: options and the catalogue name of the nested simpler rung whose MAP seeds it.
    rungs: tuple[tuple[dict, str | None], ...] = ()
    #: Parameter name -> role, for a model that names its parameters otherwise than
    #: the catalogue (:data:`ROLES`, the default).
    roles: Mapping[str, str] | None = None


#: The roles of a network's parameters that a description of the room sets a prior on
#: (:data:`heritage_bayes.inference.survey.ROLE_PRIORS`): parameter name -> role,
#: by the catalogue's names. ``air_capacity`` (``room_volume``), ``ventilation``
#: (``air_change_rate``), ``ground`` (``floor_area``), ``interior_mass``
#: (``interior_area``), ``envelope`` (a conductance and a capacity: ``envelope_area``),
#: ``fixed_potential`` (``fixed_node_temperature``).
ROLES: Mapping[str, str] = {
    "Ci": "air_capacity",
    "Gfast": "ventilation",
    "Gf": "ground",
    "Gint": "interior_mass",
    "Gw": "envelope",
    "Cw": "envelope",
    "Pf": "fixed_potential",
}


def roles_of(name: str) -> Mapping[str, str]:
    """The parameter roles of a model by name: its catalogue entry's, else :data:`ROLES`
    (a custom network named by the catalogue's conventions)."""
    entry = CATALOG.get(name)
    return entry.roles if entry is not None and entry.roles is not None else ROLES


#: The name of the effective solar aperture [m²] of a surface: the gain of its
#: irradiance input ``I_<surface>`` in the catalogue's networks.
APERTURE_PREFIX = "fI_"


def solar_apertures(parameter_names: Iterable[str]) -> dict[str, str]:
    """The solar apertures among a network's parameters: name -> surface
    (``fI_S`` -> ``S``); a custom network that names them so gets the priors a survey
    sets on them (``glazing_area``, ``data.roof``)."""
    n = len(APERTURE_PREFIX)
    return {p: p[n:] for p in parameter_names if p.startswith(APERTURE_PREFIX)}


#: Sections a catalogue model belongs to.
DOMAINS = ("thermal", "hygric")

#: Catalogue: name -> :class:`CatalogModel`, in ladder order within each domain.
CATALOG: dict[str, CatalogModel] = {}


def register(name: str, entry: CatalogModel) -> CatalogModel:
    """Add a model to :data:`CATALOG` (after the others of its domain's ladder).

    Raises
    ------
    ValueError
        A name taken or not a lowercase identifier, an unknown domain, or a rung whose
        parent is not a catalogue model of the same domain.
    """
    if name in CATALOG or not name.isidentifier() or name != name.lower():
        raise ValueError(f"model name {name!r}: taken, or not a lowercase identifier")
    if entry.domain not in DOMAINS:
        raise ValueError(f"model {name!r}: domain must be one of {DOMAINS} (got {entry.domain!r})")
    for _, parent in entry.rungs:
        if (
            parent is not None
            and parent != name
            and (parent not in CATALOG or CATALOG[parent].domain != entry.domain)
        ):
            raise ValueError(
                f"model {name!r}: rung parent {parent!r} is not a {entry.domain} model"
            )
    CATALOG[name] = entry
    return entry


def takes_option(name: str, option: str) -> bool:
    """Whether catalogue model ``name``'s factory takes ``option`` (e.g. ``sink``)."""
    return option in inspect.signature(CATALOG[name].factory).parameters


def model_ladder(domain: str) -> tuple[str, ...]:
    """The model-order ladder of a domain, smallest first: the catalogue models marked
    ``ladder``."""
    return tuple(n for n, e in CATALOG.items() if e.domain == domain and e.ladder)


def auto_ladder(domain: str) -> tuple[tuple[str, dict, str | None], ...]:
    """The rungs ``model: auto`` screens in a domain, simplest first: (catalogue name,
    the rung's own options, the nested simpler rung's name or None)."""
    return tuple(
        (n, own, parent)
        for n, e in CATALOG.items()
        if e.domain == domain
        for own, parent in e.rungs
    )


class DomainView(Mapping):
    """A read-only ``{domain: value}`` mapping computed from :data:`CATALOG` on each
    look-up, so that a model registered later shows in it."""

    def __init__(self, of: Callable[[str], tuple]):
        self._of = of

    def __getitem__(self, domain: str) -> tuple:
        if domain not in DOMAINS:
            raise KeyError(domain)
        return self._of(domain)

    def __iter__(self) -> Iterator[str]:
        return iter(DOMAINS)

    def __len__(self) -> int:
        return len(DOMAINS)

    def __repr__(self) -> str:
        return repr(dict(self))


for _name, _entry in (
    (
        "thermal_1c",
        CatalogModel(
            _thermal_factory("1c", True, "thermal_1c"),
            "thermal, 1 capacity (air + contents), solar, ground",
            "thermal",
            solar=True,
            ladder=True,
            rungs=(({}, None),),
        ),
    ),
    (
        "thermal_2c",
        CatalogModel(
            _thermal_factory("2c", True, "thermal_2c"),
            "thermal, 2 capacities (envelope, air), solar, ground",
            "thermal",
            solar=True,
            ladder=True,
            rungs=(({}, "thermal_1c"),),
        ),
    ),
    (
        "thermal_4a",
        CatalogModel(
            _thermal_factory("3c", True, "thermal_4a"),
            "thermal model 4a of Kramer et al.: envelope, air, interior mass, solar on "
            "facades, ground",
            "thermal",
            solar=True,
            ladder=True,
            rungs=(({}, "thermal_2c"),),
        ),
    ),
    (
        "thermal_4a_nosolar",
        CatalogModel(
            _thermal_factory("3c", False, "thermal_4a_nosolar"),
            "thermal model 4a without solar input",
            "thermal",
        ),
    ),
    (
        "hygric_1c",
        CatalogModel(
            _hygric_factory("1c", False, "hygric_1c"),
            "hygric, 1 capacity (air + fast buffer)",
            "hygric",
            ladder=True,
            rungs=(({}, None),),
        ),
    ),
    (
        "hygric_2c",
        CatalogModel(
            _hygric_factory("2c", False, "hygric_2c"),
            "hygric model 3 of Kramer et al.: buffer, air",
            "hygric",
            ladder=True,
            rungs=(({}, "hygric_1c"),),
        ),
    ),
    (
        "hygric_2c_fixed",
        CatalogModel(
            _hygric_factory("2c", True, "hygric_2c_fixed"),
            "hygric model 3 with a fixed vapour-pressure node (Gf, Pf; or sink: "
            "temperature, a vapour sink at phi_f·psat(Tf))",
            "hygric",
            ladder=True,
            rungs=(({"sink": "constant"}, "hygric_2c"), ({"sink": "temperature"}, "hygric_2c")),
        ),
    ),
    (
        "hygric_2c_sorption",
        CatalogModel(
            _sorption_factory("hygric_2c_sorption"),
            "hygric, air and a sorbing buffer whose surface vapour pressure is "
            "φ_w·psat(Ti) (thermo-hygric coupling)",
            "hygric",
            rungs=(({}, "hygric_1c"), ({"sink": "temperature"}, "hygric_2c_sorption")),
        ),
    ),
):
    register(_name, _entry)


def available_models() -> dict[str, str]:
    """Catalogue names and descriptions."""
    return {k: v.description for k, v in CATALOG.items()}


def model(name: str, control: Control | None = None, **options) -> RCModel:
    """A catalogue model by name, compiled.

    Parameters
    ----------
    name : str
        One of :func:`available_models` (``"thermal_4a"``, ``"hygric_2c"``, ...).
    control : Control, optional
        The control of the air node: thermostat (thermal), humidistat (hygric),
        constant source (both); see :mod:`heritage_bayes.rc.control`. Default none.
    **options
        The network's options, keywords of the model's factory: ``surfaces``,
        ``ground``, ``heating`` for thermal models, ``sink`` for the hygric ones with a
        fixed node (see the module docstring).

    Raises
    ------
    ValueError
        Unknown name (the message lists the catalogue), an option the model does not
        take (the message lists those it takes), or a control the model cannot have.

    Examples
    --------
    >>> from heritage_bayes.rc.control_spec import Control
    >>> model("thermal_2c", Control(thermostat=True, power_limit=True), ground=False).name
    'thermal_2c'
    """
    if name not in CATALOG:
        raise ValueError(f"unknown model {name!r}; available: {sorted(CATALOG)}")
    factory = CATALOG[name].factory
    allowed = list(inspect.signature(factory).parameters)
    unknown = sorted(k for k in options if k not in allowed)
    if unknown:
        raise ValueError(f"model {name!r}: unknown option(s) {unknown}; allowed: {allowed}")
    control = Control() if control is None else control
    net = factory(**options)
    if isinstance(net, RCModel):  # a time-varying model, compiled by its factory
        if control.active:
            raise ValueError(
                f"model {name!r}: the control options (humidistat, source) are not "
                "available for a thermo-hygric coupled model; use hygric_2c or "
                "hygric_2c_fixed with its constant node"
            )
        return net
    return controlled(net, control)
