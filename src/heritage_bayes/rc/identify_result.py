"""The outcome of the structural identifiability check, in numbers and in plain words.

:class:`IdentifiabilityResult` (rank, singular values, null directions, per-parameter
loadings, a JSON summary) and :class:`NullDirection`, with the plain-words description of
each direction and of the knowledge that pins it. The computation is
:func:`heritage_bayes.rc.identify.structural_identifiability`; that module re-exports
both classes.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

__all__ = ["IdentifiabilityResult", "NullDirection"]

_LOG_KINDS = ("capacity", "conductance", "gain", "sorption_capacity")
#: Kinds of constant boundary potentials (a vapour pressure, or a sink's RH [-]).
_CONSTANT_KINDS = ("constant", "saturation", "offset")
_TRANSFORM = {
    "capacity": "log",
    "conductance": "log",
    "gain": "log",
    "fraction": "natural",
    "constant": "relative",
    "sorption_capacity": "log",
    "saturation": "relative",
    "depth": "relative",
    "offset": "relative",
}
_SCALE_LABEL = "overall scale"


# ------------------------------------------------------------------------- results
@dataclass(frozen=True)
class NullDirection:
    """A direction in parameter space that leaves the output unchanged.

    Attributes
    ----------
    label : str
        ``"overall scale"`` or ``"direction <k>"``.
    vector : dict name -> float
        Unit-length direction in the :math:`\\theta` coordinates (log for capacities,
        conductances and gains; natural for fractions; relative for constants), largest
        loading positive.
    description : str
        Plain-words meaning and which knowledge pins it.
    pinned_by : tuple of str
        Parameters loading on it above the threshold: fixing any one of them, or giving
        it an informative prior, removes this direction.
    is_scale : bool
        Whether this is the generic overall-scale direction.
    """

    label: str
    vector: dict[str, float]
    description: str
    pinned_by: tuple[str, ...]
    is_scale: bool = False

    def to_dict(self) -> dict:
        return {
            "label": self.label,
            "is_scale": self.is_scale,
            "vector": {k: float(v) for k, v in self.vector.items()},
            "pinned_by": list(self.pinned_by),
            "description": self.description,
        }


@dataclass(frozen=True)
class IdentifiabilityResult:
    """Outcome of :func:`structural_identifiability`.

    Attributes
    ----------
    model_name : str
    parameter_names : tuple of str
        The free parameters the check covers (all but ``fixed``).
    point : dict name -> float
        The parameter set the check was made at, all parameters [SI units].
    fixed : tuple of str
        Parameters held at their value (left out of the Jacobian).
    transforms : dict name -> str
        Coordinate of each parameter: ``"log"``, ``"natural"`` (fractions) or
        ``"relative"`` (constants, :math:`c/\\max(|c_0|, 1)`).
    dt : float
        Sampling step [s] that sets the Nyquist frequency of the grid.
    omega : (n_freq + 1,) array
        Angular frequencies of the grid [rad/s], 0 first.
    singular_values : (P,) array
        Of the column-scaled Jacobian, descending.
    rtol : float
        Relative tolerance of the numerical rank.
    threshold : float
        Loading above which a parameter counts as on a null direction.
    rank : int
    directions : tuple of NullDirection
        A basis of the null space (``P - rank`` directions, each of unit length). When
        the overall scale is among them it comes first, and the others span what
        remains free once the scale is pinned through ``scale_reference`` (they have
        zero loading on it); otherwise they are orthonormal.
    scale_reference : str or None
        The parameter through which the scale is thought of as pinned: the capacity of
        the (first) observed node, e.g. ``Ci``, which users can know from the room
        volume. None when the overall scale is not a null direction.
    null_loading : dict name -> float
        Length of the projection of the parameter's axis on the null space (0: fully
        identifiable; 1: no influence at all).
    loading_given_scale : dict name -> float
        The same on the null space that remains once the overall scale is pinned through
        ``scale_reference`` (equal to ``null_loading`` without a scale direction).
    jacobian : (rows, P) array
        The normalised Jacobian (before column scaling), for diagnostics.
    """

    model_name: str
    parameter_names: tuple[str, ...]
    point: dict[str, float]
    fixed: tuple[str, ...]
    transforms: dict[str, str]
    dt: float
    omega: np.ndarray
    singular_values: np.ndarray
    rtol: float
    threshold: float
    rank: int
    directions: tuple[NullDirection, ...]
    scale_reference: str | None
    null_loading: dict[str, float]
    loading_given_scale: dict[str, float]
    jacobian: np.ndarray = field(repr=False)
    #: Control parameters of a controlled room (:mod:`heritage_bayes.rc.control`), name
    #: -> what pins them (they act only while the control does, outside the linear
    #: frequency-response check, which covers the free-running network).
    control: dict[str, str] = field(default_factory=dict)

    # ------------------------------------------------------------------ summaries
    @property
    def n_params(self) -> int:
        return len(self.parameter_names)

    @property
    def n_null(self) -> int:
        return self.n_params - self.rank

    @property
    def is_identifiable(self) -> bool:
        """True when the Jacobian has full rank: every parameter is locally identifiable."""
        return self.rank == self.n_params

    @property
    def has_scale_direction(self) -> bool:
        return any(d.is_scale for d in self.directions)

    @property
    def null_space(self) -> np.ndarray:
        """(P, n_null) basis of the null space in θ coordinates (see ``directions``)."""
        if not self.directions:
            return np.zeros((self.n_params, 0))
        return np.column_stack(
            [[d.vector[p] for p in self.parameter_names] for d in self.directions]
        )

    @property
    def identifiable(self) -> dict[str, bool]:
        """Per parameter: not on any null direction (loading below the threshold)."""
        return {p: v < self.threshold for p, v in self.null_loading.items()}

    @property
    def identifiable_given_scale(self) -> dict[str, bool]:
        """Per parameter: identifiable once the overall scale is pinned through
        ``scale_reference`` (e.g. a prior on ``Ci`` from the room volume)."""
        return {p: v < self.threshold for p, v in self.loading_given_scale.items()}

    @property
    def condition_number(self) -> float:
        """Largest over smallest singular value (inf when the smallest is 0)."""
        s = self.singular_values
        return float(s[0] / s[-1]) if s[-1] > 0 else float("inf")

    @property
    def condition_number_identifiable(self) -> float:
        """Largest over the smallest singular value above the rank tolerance."""
        s = self.singular_values
        return float(s[0] / s[self.rank - 1]) if self.rank else float("inf")

    @property
    def gap(self) -> float | None:
        """Ratio of the singular values on either side of the rank cut (None at full
        rank): a large gap means a clear-cut rank decision."""
        s = self.singular_values
        if self.rank == self.n_params or self.rank == 0:
            return None
        return float(s[self.rank - 1] / s[self.rank]) if s[self.rank] > 0 else float("inf")

    def summary(self) -> str:
        """A few lines of plain text for logs and reports."""
        lines = [
            f"structural identifiability of {self.model_name!r}: rank {self.rank} of "
            f"{self.n_params} parameters"
            + (" (all identifiable)" if self.is_identifiable else f", {self.n_null} null")
        ]
        for d in self.directions:
            lines.append(f"- {d.label}: {d.description}")
        if not self.is_identifiable:
            ok = [p for p, v in self.identifiable.items() if v]
            up = [p for p, v in self.identifiable_given_scale.items() if v and p not in ok]
            lines.append(f"identifiable: {', '.join(ok) if ok else 'none'}")
            if self.has_scale_direction:
                lines.append(
                    f"identifiable once the scale is pinned through {self.scale_reference}: "
                    + (", ".join(up) if up else "no further parameter")
                )
        return "\n".join(lines)

    def __str__(self) -> str:
        return self.summary()

    def to_dict(self) -> dict:
        """JSON-serialisable summary (non-finite numbers become None)."""

        def num(x):
            x = float(x)
            return x if np.isfinite(x) else None

        return {
            "model": self.model_name,
            "rank": int(self.rank),
            "n_params": self.n_params,
            "n_null": self.n_null,
            "identifiable_model": self.is_identifiable,
            "has_scale_direction": self.has_scale_direction,
            "scale_reference": self.scale_reference,
            "point": {k: float(v) for k, v in self.point.items()},
            "fixed": list(self.fixed),
            "transforms": dict(self.transforms),
            "control": dict(self.control),
            "method": {
                "observables": "frequency response C(iωI-A)^-1 B on the grid incl. ω=0, "
                "constant-boundary contributions",
                "normalisation": "relative (dH/|H|), real and imaginary parts",
                "derivatives": "analytic (exact network-matrix derivatives)",
                "dt": float(self.dt),
                "omega_min": float(self.omega[1]),
                "omega_max": float(self.omega[-1]),
                "n_freq": len(self.omega) - 1,
                "rtol": float(self.rtol),
                "threshold": float(self.threshold),
            },
            "singular_values": [float(s) for s in self.singular_values],
            "condition_number": num(self.condition_number),
            "condition_number_identifiable": num(self.condition_number_identifiable),
            "gap": None if self.gap is None else num(self.gap),
            "null_directions": [d.to_dict() for d in self.directions],
            "parameters": {
                p: {
                    "identifiable": bool(self.identifiable[p]),
                    "identifiable_given_scale": bool(self.identifiable_given_scale[p]),
                    "null_loading": float(self.null_loading[p]),
                    "loading_given_scale": float(self.loading_given_scale[p]),
                }
                for p in self.parameter_names
            },
            "summary": self.summary(),
        }


# ---------------------------------------------------------------------- descriptions
def _fmt_list(items) -> str:
    items = list(items)
    if len(items) <= 2:
        return " and ".join(items)
    return ", ".join(items[:-1]) + " and " + items[-1]


def _scale_hint(model, ref: str) -> str:
    air = ref if any(n.C == ref for n in model.network.nodes) else None
    if model.domain == "thermal":
        hints = []
        if air:
            hints.append(
                f"a prior on {air} from the room air volume V (about 1.2 kJ/(m³·K) × V, "
                "more with fast-responding contents)"
            )
        hints.append("a known heat input (measured heating power, a known-gain input)")
        hints.append(
            "a conductance known from measurement, e.g. the ventilation conductance "
            "shared with the hygric model through the air change rate"
        )
    else:
        hints = []
        if air:
            hints.append(
                f"a prior on {air} from the room air volume V (V/(Rᵥ·T) ≈ "
                "7.4e-6 kg/(Pa·m³) × V at 20 °C)"
            )
        hints.append("a known moisture source")
        hints.append(
            "the ventilation conductance shared with the thermal model through the air change rate"
        )
    return "; ".join(hints)


def _scale_reference(model, names, kinds, scale) -> str:
    """Capacity parameter of the first observed node (``Ci`` in the catalogue), or the
    first free capacity (then log-parameter) on the scale direction."""
    node = next(n for n in model.network.nodes if n.name == model.output_names[0])
    if node.C in names and scale[names.index(node.C)] > 0:
        return node.C
    on = [j for j in range(len(names)) if scale[j] > 0]
    caps = [j for j in on if kinds[j] == "capacity"]
    return names[(caps or on)[0]]


def _describe(model, names, kinds, p0, v, threshold, is_scale, k, ref) -> NullDirection:
    vec = {n: float(x) for n, x in zip(names, v, strict=True)}
    order = np.argsort(-np.abs(v), kind="stable")
    big = [int(j) for j in order if abs(v[j]) >= threshold]
    pinned = tuple(names[j] for j in big)
    if is_scale:
        members = [n for n, x in zip(names, v, strict=True) if x != 0]
        rest = [n for n, kd in zip(names, kinds, strict=True) if kd not in _LOG_KINDS]
        text = (
            f"scaling {_fmt_list(members)} together by the same factor"
            + (f" (with {_fmt_list(rest)} unchanged)" if rest else "")
            + " leaves the output unchanged: their absolute values are not identifiable, "
            "only ratios, time constants and static gains are. Pin the scale with "
            "knowledge of any one of them: " + _scale_hint(model, ref) + "."
        )
        return NullDirection(_SCALE_LABEL, vec, text, tuple(members), True)
    label = f"direction {k}"
    if len(big) == 1:
        j = big[0]
        text = (
            f"{names[j]} is not identifiable from these inputs and outputs: at these "
            "parameter values its influence on the output is below what the data "
            "resolve (to first order). That does not mean the link does nothing in the "
            "room, only that these data cannot tell its value. Fix it, give it an "
            "informative prior, or use a model without it."
        )
        return NullDirection(label, vec, text, pinned)
    units = sorted({_TRANSFORM[kinds[j]] for j in big})
    parts = [f"{names[j]} {v[j]:+.2f}" for j in big]
    pattern = _pattern(names, kinds, p0, v, big)
    text = (
        (f"even with the overall scale pinned through {ref}, " if ref else "")
        + f"changing {_fmt_list(parts)} together (first order, in {'/'.join(units)} "
        "coordinates) leaves the output unchanged: these parameters are not separately "
        "identifiable"
        + (f"; {pattern}" if pattern else "")
        + ". Pin this direction by fixing, or giving an informative prior to, one of "
        + _fmt_list(pinned)
        + "."
    )
    return NullDirection(label, vec, text, pinned)


def _pattern(names, kinds, p0, v, big) -> str:
    """Recognise sums, products and ratios among the loaded parameters."""
    if not big or any(kinds[j] not in _LOG_KINDS for j in big):
        return ""
    small = [j for j in range(len(v)) if j not in big]
    if np.linalg.norm(v[small]) > 1e-6:
        return ""
    same_kind = len({kinds[j] for j in big}) == 1
    # Σ δp_j = Σ p_j v_j = 0: the parameters act only through their sum
    dp = p0[big] * v[big]
    if same_kind and abs(dp.sum()) <= 1e-6 * np.abs(dp).sum():
        return f"only their sum {' + '.join(names[j] for j in big)} is identifiable"
    if len(big) == 2:
        a, b = big
        if abs(v[a] + v[b]) <= 1e-6:
            return f"only the product {names[a]}·{names[b]} is identifiable"
        if abs(v[a] - v[b]) <= 1e-6:
            return f"only the ratio {names[a]}/{names[b]} is identifiable"
    return ""
