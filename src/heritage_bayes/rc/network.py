"""Declarative lumped RC networks compiled to continuous state space.

A network has capacity *nodes* (thermal capacity [J/K] or hygric capacity [kg/Pa]),
*links* (conductances [W/K] or [kg/(s·Pa)]) between two nodes or between a node and a
*boundary* (a measured input column such as ``Te``, or an estimable constant potential
such as the fixed vapour pressure ``Pf``), and *sources*: an input column times a gain
(e.g. irradiance [W/m²] times a solar aperture [m²]) injected into a node, optionally
split between nodes by a fraction parameter.

Energy (or mass) balance of node *i* with capacity :math:`C_i`:

.. math::

    C_i \\dot x_i = \\sum_j G_{ij}(x_j - x_i) + \\sum_b G_{ib}(u_b - x_i)
                  + \\sum_s g_s f_s u_s

so that :math:`\\dot x = A x + B u + e` with :math:`A = -C^{-1}\\mathbf{G}`, where
:math:`\\mathbf{G}` is the symmetric conductance (Laplacian plus boundary) matrix and
:math:`e` collects the constant boundaries. Outputs are node potentials, so ``D = 0``.

References
----------
.. [1] R.P. Kramer, A.W.M. van Schijndel, H.L. Schellen, "Inverse modeling of climate
   responses of monumental buildings", (thermal model 4a, hygric model 3).
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from dataclasses import dataclass, field

__all__ = ["DOMAINS", "GroundCycle", "Link", "Network", "Node", "ParameterInfo", "Source"]

#: Units per domain: potential, capacity, conductance, source flow.
DOMAINS: dict[str, dict[str, str]] = {
    "thermal": {"potential": "°C", "capacity": "J/K", "conductance": "W/K", "flow": "W"},
    "hygric": {"potential": "Pa", "capacity": "kg/Pa", "conductance": "kg/(s·Pa)", "flow": "kg/s"},
}


@dataclass(frozen=True)
class Node:
    """A capacity node: state ``name`` with capacity parameter ``C``."""

    name: str
    C: str
    description: str = ""


@dataclass(frozen=True)
class Link:
    """A conductance ``G`` (parameter name) between node ``a`` and node-or-boundary ``b``."""

    a: str
    b: str
    G: str


@dataclass(frozen=True)
class Source:
    """Flow ``gain * fraction * input`` into ``node``.

    ``gain`` is a parameter name (e.g. a solar aperture ``fI_S`` [m²]) or a known
    constant (e.g. 1.0 for a measured heating power [W]); ``fraction`` is ``None``, a
    parameter name ``"f"`` or its complement ``"1-f"``.
    """

    input: str
    node: str
    gain: str | float = 1.0
    fraction: str | None = None

    @property
    def fraction_param(self) -> tuple[str, bool] | None:
        """(parameter name, complement?) of the split fraction, or None."""
        if self.fraction is None:
            return None
        f = self.fraction.replace(" ", "")
        if f.startswith("1-"):
            return f[2:], True
        return f, False


@dataclass(frozen=True)
class GroundCycle:
    """The annual cycle of a boundary at an estimable depth in the soil.

    The boundary ``link`` (a :class:`Link` from ``node`` to an input column, e.g. the
    ground temperature ``Tf`` given at ``reference`` depth [m]) is corrected to the
    depth parameter ``depth`` [m] by the flow

    .. math::
        G\\,[a(z) - a(z_r)]\\,c(t) + G\\,[b(z) - b(z_r)]\\,s(t) + G\\,\\Delta T

    into ``node``, where :math:`c, s` are the input columns ``inputs`` (the surface's
    annual anomaly and its quadrature [potential]) and :math:`a, b` the depth weights
    of :func:`heritage_bayes.climate.ground.depth_factors` (Kusuda-Achenbach): the
    boundary then follows the cycle at depth :math:`z`; at :math:`z = z_r` nothing changes.
    ``offset`` (optional) names the parameter :math:`\\Delta T` (kind ``offset``, a
    potential difference) by which the boundary's annual mean exceeds the input's (the
    soil's mean is not the mean of one year's outdoor air).
    """

    node: str
    G: str
    depth: str
    inputs: tuple[str, str]
    reference: float
    offset: str | None = None


@dataclass(frozen=True)
class ParameterInfo:
    """Name, kind, unit and meaning of a network parameter."""

    name: str
    kind: str  # "capacity" | "conductance" | "gain" | "fraction" | "constant"
    unit: str
    description: str = ""


@dataclass(frozen=True)
class Network:
    """A lumped RC network (see module docstring).

    Parameters
    ----------
    name : str
        Model name.
    domain : {"thermal", "hygric"}
        Sets the units: thermal potentials [°C], capacities [J/K], conductances [W/K];
        hygric potentials [Pa], capacities [kg/Pa], conductances [kg/(s·Pa)].
    nodes : sequence of Node
        Capacity nodes, in state order.
    links : sequence of Link
        Conductances between nodes or from a node to a boundary.
    inputs : sequence of str
        Input columns, in order (boundary potentials and source inputs).
    outputs : sequence of str
        Node names that are observed (e.g. ``("Ti",)``).
    sources : sequence of Source
        Injected flows.
    constants : sequence of str
        Boundaries whose potential is an estimable parameter (e.g. ``"Pf"`` [Pa]).
    cycles : sequence of GroundCycle
        Boundaries that follow an annual cycle at an estimable depth (parameter kind
        ``depth`` [m]).
    descriptions : mapping
        Optional description per parameter or input name.
    input_units : mapping
        Unit per source input (default: [W/m²] for thermal sources with a parameter
        gain, else the domain's flow unit).
    """

    name: str
    domain: str
    nodes: tuple[Node, ...]
    links: tuple[Link, ...]
    inputs: tuple[str, ...]
    outputs: tuple[str, ...]
    sources: tuple[Source, ...] = ()
    constants: tuple[str, ...] = ()
    cycles: tuple[GroundCycle, ...] = ()
    descriptions: Mapping[str, str] = field(default_factory=dict)
    input_units: Mapping[str, str] = field(default_factory=dict)

    def __post_init__(self):
        for attr in ("nodes", "links", "inputs", "outputs", "sources", "constants", "cycles"):
            object.__setattr__(self, attr, tuple(getattr(self, attr)))
        self._validate()

    # ------------------------------------------------------------------ checks
    def _validate(self) -> None:
        where = f"network {self.name!r}"
        if self.domain not in DOMAINS:
            raise ValueError(
                f"{where}: domain must be one of {sorted(DOMAINS)} (got {self.domain!r})"
            )
        if not self.nodes:
            raise ValueError(f"{where}: needs at least one capacity node")
        names = [n.name for n in self.nodes]
        _no_duplicates(names, f"{where}: node names")
        _no_duplicates(list(self.inputs), f"{where}: input names")
        clash = set(names) & (set(self.inputs) | set(self.constants))
        if clash:
            raise ValueError(f"{where}: {sorted(clash)} used both as node and as input")
        boundaries = set(self.inputs) | set(self.constants)
        for link in self.links:
            if link.a not in names:
                raise ValueError(
                    f"{where}: link {link.G} starts at unknown node {link.a!r}; nodes are {names}"
                )
            if link.b not in names and link.b not in boundaries:
                raise ValueError(
                    f"{where}: link {link.G} ends at {link.b!r}, which is "
                    f"neither a node {names} nor an input/constant "
                    f"{sorted(boundaries)}"
                )
            if link.a == link.b:
                raise ValueError(f"{where}: link {link.G} connects node {link.a!r} to itself")
        for src in self.sources:
            if src.node not in names:
                raise ValueError(
                    f"{where}: source of input {src.input!r} goes to "
                    f"unknown node {src.node!r}; nodes are {names}"
                )
            if src.input not in self.inputs:
                raise ValueError(
                    f"{where}: source input {src.input!r} is not among "
                    f"the inputs {list(self.inputs)}"
                )
        for out in self.outputs:
            if out not in names:
                raise ValueError(f"{where}: output {out!r} is not a node; nodes are {names}")
        if not self.outputs:
            raise ValueError(f"{where}: needs at least one output node")
        for cy in self.cycles:
            if not any(lk.a == cy.node and lk.G == cy.G for lk in self.links):
                raise ValueError(
                    f"{where}: ground cycle at depth {cy.depth!r} needs a link {cy.G!r} "
                    f"from node {cy.node!r}"
                )
            missing = [u for u in cy.inputs if u not in self.inputs]
            if missing:
                raise ValueError(f"{where}: ground cycle inputs {missing} are not inputs")
        used = {lk.b for lk in self.links} | {s.input for s in self.sources}
        used |= {u for cy in self.cycles for u in cy.inputs}
        unused = [u for u in self.inputs if u not in used]
        if unused:
            raise ValueError(f"{where}: inputs {unused} are not connected to any node")
        for c in self.constants:
            if c not in used:
                raise ValueError(f"{where}: constant boundary {c!r} is not linked to any node")
        # every node must reach a boundary through links, else G is singular
        adj: dict[str, set[str]] = {n: set() for n in names}
        grounded: set[str] = set()
        for link in self.links:
            if link.b in adj:
                adj[link.a].add(link.b)
                adj[link.b].add(link.a)
            else:
                grounded.add(link.a)
        reach = set(grounded)
        stack = list(grounded)
        while stack:
            for nb in adj[stack.pop()]:
                if nb not in reach:
                    reach.add(nb)
                    stack.append(nb)
        isolated = [n for n in names if n not in reach]
        if isolated:
            raise ValueError(
                f"{where}: node(s) {isolated} are not connected to any "
                "boundary (isolated); add a link to an input or a "
                "constant"
            )
        kinds: dict[str, str] = {}
        for p, kind in self._iter_params():
            if kinds.setdefault(p, kind) != kind:
                raise ValueError(
                    f"{where}: parameter {p!r} is used both as {kinds[p]} and as {kind}"
                )

    def _iter_params(self):
        for n in self.nodes:
            yield n.C, "capacity"
        for lk in self.links:
            yield lk.G, "conductance"
        for s in self.sources:
            if isinstance(s.gain, str):
                yield s.gain, "gain"
        for s in self.sources:
            fp = s.fraction_param
            if fp is not None:
                yield fp[0], "fraction"
        for c in self.constants:
            yield c, "constant"
        for cy in self.cycles:
            yield cy.depth, "depth"
        for cy in self.cycles:
            if cy.offset is not None:
                yield cy.offset, "offset"

    # ------------------------------------------------------------------ metadata
    @property
    def parameter_names(self) -> tuple[str, ...]:
        """Parameter names: capacities, conductances, gains, fractions, constants."""
        return tuple(dict.fromkeys(p for p, _ in self._iter_params()))

    @property
    def state_names(self) -> tuple[str, ...]:
        return tuple(n.name for n in self.nodes)

    @property
    def parameters(self) -> tuple[ParameterInfo, ...]:
        """Metadata (kind, unit, description) of every parameter."""
        units = DOMAINS[self.domain]
        seen: dict[str, ParameterInfo] = {}
        for p, kind in self._iter_params():
            if p in seen:
                continue
            if kind == "capacity":
                unit = units["capacity"]
            elif kind == "conductance":
                unit = units["conductance"]
            elif kind == "gain":
                src = next(s for s in self.sources if s.gain == p)
                in_unit = self.input_unit(src.input)
                unit = "m²" if in_unit == "W/m²" else f"({units['flow']})/({in_unit})"
            elif kind == "fraction":
                unit = "-"
            elif kind == "depth":
                unit = "m"
            elif kind == "offset":
                unit = "K" if self.domain == "thermal" else units["potential"]
            else:
                unit = units["potential"]
            seen[p] = ParameterInfo(p, kind, unit, self.descriptions.get(p, ""))
        return tuple(seen.values())

    def input_unit(self, name: str) -> str:
        """Unit of input column ``name``."""
        if name in self.input_units:
            return self.input_units[name]
        units = DOMAINS[self.domain]
        if any(lk.b == name for lk in self.links) or any(name in c.inputs for c in self.cycles):
            return units["potential"]
        src = next(s for s in self.sources if s.input == name)
        if self.domain == "thermal" and isinstance(src.gain, str):
            return "W/m²"
        return units["flow"]

    # ------------------------------------------------------------------ building
    @classmethod
    def from_dict(cls, spec: Mapping, *, where: str = "network") -> Network:
        """Build a network from a plain mapping (e.g. parsed YAML).

        Layout::

            name: two_rooms
            domain: thermal
            nodes: {T1: C1, T2: C2}          # state -> capacity parameter
            links: [[T1, Te, G1], [T1, T2, G12], [T2, Te, G2]]
            inputs: [Te, I_S]
            outputs: [T1, T2]
            sources: [{input: I_S, node: T1, gain: fI_S}]
            constants: []
        """
        allowed = {
            "name",
            "domain",
            "nodes",
            "links",
            "inputs",
            "outputs",
            "sources",
            "constants",
            "descriptions",
            "input_units",
        }
        unknown = sorted(set(spec) - allowed)
        if unknown:
            raise ValueError(
                f"{where}: unknown key(s) {unknown}; allowed keys are {sorted(allowed)}"
            )
        for key in ("nodes", "links", "inputs", "outputs"):
            if key not in spec:
                raise ValueError(f"{where}.{key}: required")
        nodes = spec["nodes"]
        if not isinstance(nodes, Mapping):
            raise ValueError(
                f"{where}.nodes: expected a mapping state -> capacity "
                f"parameter (got {type(nodes).__name__})"
            )
        links = []
        for i, lk in enumerate(spec["links"]):
            if isinstance(lk, Mapping):
                lk = (lk.get("a"), lk.get("b"), lk.get("G"))
            if len(lk) != 3 or not all(isinstance(v, str) for v in lk):
                raise ValueError(
                    f"{where}.links[{i}]: expected [node, node_or_input, "
                    f"conductance_parameter] (got {lk!r})"
                )
            links.append(Link(*lk))
        sources = []
        for i, s in enumerate(spec.get("sources", []) or []):
            if (
                not isinstance(s, Mapping)
                or not {"input", "node"} <= set(s)
                or set(s) - {"input", "node", "gain", "fraction"}
            ):
                raise ValueError(
                    f"{where}.sources[{i}]: expected keys input, node and "
                    f"optionally gain, fraction (got {s!r})"
                )
            sources.append(Source(**s))
        return cls(
            name=str(spec.get("name", "custom")),
            domain=str(spec.get("domain", "thermal")),
            nodes=tuple(Node(k, v) for k, v in nodes.items()),
            links=tuple(links),
            inputs=tuple(spec["inputs"]),
            outputs=tuple(spec["outputs"]),
            sources=tuple(sources),
            constants=tuple(spec.get("constants", []) or []),
            descriptions=dict(spec.get("descriptions", {}) or {}),
            input_units=dict(spec.get("input_units", {}) or {}),
        )


def _no_duplicates(items: Sequence[str], what: str) -> None:
    seen, dup = set(), []
    for it in items:
        if it in seen:
            dup.append(it)
        seen.add(it)
    if dup:
        raise ValueError(f"{what} must be unique; repeated: {dup}")
