"""Structural identifiability of RC networks and the quantities that *are* identifiable.

Two things live here.

**Derived identifiable quantities**, batched over parameter sets (they go into the
posterior for every draw): the time constants of the network (``1/λ`` of the modal form,
see :mod:`heritage_bayes.rc.discretize`), the static gain from each input to each output
(:math:`-C A^{-1} B`) and the steady-state contribution of each constant boundary (the
fixed vapour-pressure node of hygric model 3). All are properties of the input–output
behaviour, hence invariant under every transformation of the parameters that leaves the
output unchanged, e.g. scaling all capacities, conductances and solar apertures together.

**Structural identifiability at a point** (typically the MAP),
:func:`structural_identifiability`: the rank of the Jacobian of the model's input–output
behaviour with respect to the (log-)parameters, the directions in parameter space that
leave the output unchanged, and a plain-words description of each. "Structural" means a
property of the model and of which inputs/outputs exist, not of the data: an input that
happens to be zero in a data set does not make its gain structurally non-identifiable.

Notes
-----
*Observables.* The input–output behaviour of :math:`\\dot x = Ax + Bu + e`,
:math:`y = Cx` is the frequency response

.. math::

    H(i\\omega) = C (i\\omega I - A)^{-1} B = C\\,(i\\omega\\,C_{cap} + \\mathbf G)^{-1} G_u

(the second form follows from :math:`A = -C_{cap}^{-1}\\mathbf G`,
:math:`B = C_{cap}^{-1} G_u`), plus, for constant boundaries, their steady-state
contribution :math:`y_c = C\\,\\mathbf G^{-1} q_c` (a constant potential is seen only at
zero frequency). The frequency grid holds :math:`\\omega = 0` (the static gains) and
``n_freq`` log-spaced angular frequencies from :math:`2\\pi/T_{long}` (``longest_period``,
default 10 years) to the Nyquist frequency :math:`\\pi/\\Delta t` of the sampling step.

*Coordinates* :math:`\\theta`. Capacities, conductances and gains (positive):
:math:`\\theta = \\ln p`. Fractions: :math:`\\theta = f` (natural scale; a unit step is
the whole range [0, 1], comparable to a unit step in a log-parameter, and defined at the
bounds 0 and 1 where a logit is not). Constants (e.g. ``Pf`` [Pa]):
:math:`\\theta = c / s_c` with :math:`s_c = \\max(|c_0|, 1)` in the parameter's unit, a
relative scale that stays defined at :math:`c_0 = 0`.

*Jacobian.* Analytic: :math:`\\partial H = -C M^{-1} (\\partial M) M^{-1} G_u +
C M^{-1} \\partial G_u` with :math:`M = i\\omega C_{cap} + \\mathbf G`, and likewise for
:math:`y_c`. The derivatives of the network matrices (:math:`C_{cap}, \\mathbf G, G_u,
q`) are central differences with step ``0.5 × scale`` of the parameter; every network
matrix is affine in each single parameter (products appear only between different
parameters, e.g. aperture × fraction), so these differences are exact up to rounding
(~1e-16 relative). Each frequency-response entry is normalised by its own magnitude,
:math:`\\partial H/|H|` (the relative, i.e. log-magnitude and phase, sensitivity; real and
imaginary parts stacked), floored at ``1e-12`` of the block's largest magnitude, so that
every input–output block and every frequency weighs comparably; the constant-boundary
rows are normalised by :math:`|\\partial y_c/\\partial c|\\,s_c` and weighted by
:math:`\\sqrt{2 n_{freq} + 1}` so that each constant weighs like one input block.

*Rank.* The columns are scaled to unit norm (zero columns stay zero), the SVD gives the
singular values :math:`s_1 \\ge \\dots \\ge s_P`, and the numerical rank counts
:math:`s_k > r_{tol}\\,s_1`, default :math:`r_{tol} = 10^{-8}`. The Jacobian is exact to
rounding, so structurally zero singular values come out near machine precision
(:math:`\\lesssim 10^{-13}\\,s_1` for the catalogue models at plausible values), while
structurally identifiable but weakly informed directions stay far above :math:`10^{-8}`
(the result reports the gap around the cut).

*Directions.* The null space is returned in :math:`\\theta` coordinates, each direction
of unit length with its largest loading positive. The generic *overall scale* direction
(1 on every capacity, conductance and gain, 0 on fractions and constants) is recognised
and named when it lies in the null space (:math:`\\|J s\\| \\le r_{tol} s_1 \\|s\\|`
in the column-scaled metric); the remaining directions then span what stays free once
the scale is pinned through the capacity of the observed node (``Ci``), i.e. they have
zero loading on it. Parameters without any influence get one direction each. A
parameter is flagged as not identifiable when the length of its axis's projection on the
null space exceeds ``threshold`` (default 0.05): loadings below it are structurally
non-zero at most weakly (the parameter moves by less than 5 % of the direction's step).

References
----------
.. [1] E. Walter, L. Pronzato, *Identification of Parametric Models from Experimental
   Data*, Springer, 1997, ch. 2 (structural identifiability).
.. [2] R. Bellman, K.J. Åström, "On structural identifiability", *Mathematical
   Biosciences* 7 (1970) 329–339. https://doi.org/10.1016/0025-5564(70)90132-X
"""

from __future__ import annotations

from collections.abc import Iterable, Mapping
from dataclasses import dataclass, field

import numpy as np

from heritage_bayes.rc.discretize import _check_dt, modal_form
from heritage_bayes.rc.network import DOMAINS

__all__ = [
    "DEFAULT_LONGEST_PERIOD",
    "DEFAULT_N_FREQ",
    "DEFAULT_RTOL",
    "DEFAULT_THRESHOLD",
    "IdentifiabilityResult",
    "NullDirection",
    "constant_contributions",
    "derived_quantities",
    "derived_units",
    "static_gains",
    "structural_identifiability",
    "time_constants",
]

#: Longest period of the frequency grid [s]: 10 years.
DEFAULT_LONGEST_PERIOD = 10 * 365.25 * 86400.0
#: Log-spaced frequencies between 2π/longest_period and the Nyquist frequency π/dt.
DEFAULT_N_FREQ = 100
#: Relative singular-value tolerance of the numerical rank.
DEFAULT_RTOL = 1e-8
#: A parameter loading on the null space above this (unit-length directions) is flagged.
DEFAULT_THRESHOLD = 0.05

_LOG_KINDS = ("capacity", "conductance", "gain")
_TRANSFORM = {
    "capacity": "log",
    "conductance": "log",
    "gain": "log",
    "fraction": "natural",
    "constant": "relative",
}
_SCALE_LABEL = "overall scale"
# relative-magnitude floor of the frequency-response normalisation (see module Notes)
_H_FLOOR = 1e-12


# ---------------------------------------------------------------------------- helpers
def _param_matrix(model, params) -> tuple[np.ndarray, bool]:
    """Mapping or array -> ((K, P) array, batch?)."""
    if isinstance(params, Mapping):
        return model.param_array(params)
    P = np.asarray(params, dtype=float)
    n = len(model.parameter_names)
    if P.ndim == 1 and P.shape[0] == n:
        return P[None, :], False
    if P.ndim == 2 and P.shape[1] == n:
        return P, True
    raise ValueError(
        f"parameters for model {model.name!r}: expected a mapping name -> value, a ({n},) "
        f"array or a (K, {n}) array in the order {list(model.parameter_names)} "
        f"(got an array of shape {P.shape})"
    )


def _constant_indices(model) -> list[int]:
    return [j for j, info in enumerate(model.parameters) if info.kind == "constant"]


def _diff_unit(model) -> str:
    """Unit of a potential difference: K for thermal, Pa for hygric."""
    return "K" if model.domain == "thermal" else DOMAINS[model.domain]["potential"]


def _per(unit: str, den: str) -> str:
    if unit == den or (unit == "K" and den == "°C"):
        return "-"
    den = f"({den})" if any(c in den for c in "/·*") else den
    return f"{unit}/{den}"


# ---------------------------------------------------------------- derived quantities
def time_constants(model, params) -> np.ndarray:
    """Time constants of an RC network, batched.

    Parameters
    ----------
    model : RCModel
    params : mapping name -> value (scalars or (K,) arrays), or a (P,) / (K, P) array in
        ``model.parameter_names`` order. SI units.

    Returns
    -------
    (n,) or (K, n) array
        Time constants :math:`\\tau_j = 1/\\lambda_j` [s], sorted descending (slowest
        first), with :math:`-\\lambda_j` the eigenvalues of ``A``. Users see them in hours
        or days (:func:`derived_quantities` gives hours). Rows that are not admissible
        (non-physical values, a node cut off from every boundary) are NaN, never raised,
        so that a posterior batch with rejected proposals passes through.

    Notes
    -----
    Sorting labels the modes by speed; when two time constants cross between draws the
    labels switch, as for any eigenvalue summary.
    """
    P, batch = _param_matrix(model, params)
    mf = modal_form(model, P, 1.0)
    with np.errstate(divide="ignore"):
        tau = 1.0 / mf.lam  # eigh sorts λ ascending: τ descending
    tau[~mf.valid] = np.nan
    return tau if batch else tau[0]


def static_gains(model, params) -> np.ndarray:
    """Steady-state gain from each input to each output, batched: :math:`-C A^{-1} B`.

    Parameters
    ----------
    model : RCModel
    params : mapping or array, see :func:`time_constants`.

    Returns
    -------
    (n_out, n_in) or (K, n_out, n_in) array
        Output change per unit input change at steady state, in output unit per input
        unit: [-] from a potential boundary of the same domain (``Te`` → ``Ti``,
        ``Pe`` → ``Pi``), [K/(W/m²)] from irradiance, [K/W] from a heat input. NaN rows for
        inadmissible parameter sets. Constant boundaries are not inputs: see
        :func:`constant_contributions`.

    Notes
    -----
    In modal coordinates :math:`-C A^{-1} B = C_z\\,\\Lambda^{-1} B_z` (batched, no solve).
    """
    P, batch = _param_matrix(model, params)
    mf = modal_form(model, P, 1.0)
    with np.errstate(divide="ignore", invalid="ignore"):
        g = np.einsum("kon,knm->kom", mf.Cz, mf.Bz / mf.lam[:, :, None])
    g[~mf.valid] = np.nan
    return g if batch else g[0]


def constant_contributions(model, params) -> np.ndarray:
    """Steady-state contribution of each constant boundary to each output, batched.

    For ``hygric_2c_fixed``: the part of the indoor vapour pressure [Pa] sustained by the
    fixed node (``Gf``, ``Pf``), so that at steady state ``y = static_gains @ u + sum of
    contributions``.

    Parameters
    ----------
    model : RCModel
    params : mapping or array, see :func:`time_constants`.

    Returns
    -------
    (n_out, n_const) or (K, n_out, n_const) array
        :math:`C\\,\\mathbf G^{-1} q_c` per constant ``c`` (in the order the constants
        appear in ``model.parameter_names``), in the output's unit; empty last axis for
        networks without constant boundaries. NaN rows for inadmissible parameter sets.
    """
    P, batch = _param_matrix(model, params)
    out = _constant_part(model, P, modal_form(model, P, 1.0))
    return out if batch else out[0]


def _constant_part(model, P: np.ndarray, mf) -> np.ndarray:
    """(K, n_out, n_const) steady-state contributions from a computed modal form."""
    consts = _constant_indices(model)
    out = np.empty((P.shape[0], model.n_outputs, len(consts)))
    for i, c in enumerate(consts):
        Pc = P.copy()
        Pc[:, [j for j in consts if j != c]] = 0.0  # this constant alone
        cap, _, _, q = model.network_matrices(Pc)
        with np.errstate(divide="ignore", invalid="ignore"):
            ez = np.einsum("kij,kj->ki", mf.Tinv, q / cap)  # V^T C^-1/2 q
            out[:, :, i] = np.einsum("kon,kn->ko", mf.Cz, ez / mf.lam)
    out[~mf.valid] = np.nan
    return out


def derived_units(model) -> dict[str, str]:
    """Unit of every :func:`derived_quantities` name, in the same order.

    Names: ``tau_<k>_h`` (k = 1 slowest) [h]; ``gain_<output>_<input>`` (output unit per
    input unit, see :func:`static_gains`); ``offset_<output>_<constant>`` (steady-state
    contribution of a constant boundary, [K] or [Pa]).
    """
    units: dict[str, str] = {}
    for k in range(model.n_states):
        units[f"tau_{k + 1}_h"] = "h"
    du = _diff_unit(model)
    net = model.network
    for o in model.output_names:
        for u in model.input_names:
            units[f"gain_{o}_{u}"] = _per(du, net.input_unit(u))
    for o in model.output_names:
        for j in _constant_indices(model):
            units[f"offset_{o}_{model.parameter_names[j]}"] = du
    return units


def derived_quantities(model, params) -> dict[str, np.ndarray]:
    """Identifiable derived quantities with stable, readable names, batched.

    Parameters
    ----------
    model : RCModel
    params : mapping or array, see :func:`time_constants`.

    Returns
    -------
    dict name -> (K,) array (floats for a single parameter set)
        In the order of :func:`derived_units`: time constants ``tau_1_h`` ... [h]
        (slowest first), static gains ``gain_<output>_<input>``, and constant-boundary
        contributions ``offset_<output>_<constant>``. All are invariant under parameter
        changes that leave the output unchanged (e.g. the overall scale of C, G and
        apertures). NaN for inadmissible parameter sets.

    Examples
    --------
    >>> import heritage_bayes as hb
    >>> from heritage_bayes.rc.identify import derived_quantities
    >>> m = hb.model("hygric_2c")
    >>> d = derived_quantities(m, dict(Cw=5e-3, Ci=1e-4, Gw=1e-8, Gi=5e-8, Gfast=2e-8))
    >>> list(d)
    ['tau_1_h', 'tau_2_h', 'gain_Pi_Pe']
    >>> round(d["gain_Pi_Pe"], 12)
    1.0
    """
    P, batch = _param_matrix(model, params)
    mf = modal_form(model, P, 1.0)
    bad = ~mf.valid
    with np.errstate(divide="ignore", invalid="ignore"):
        tau_h = 1.0 / mf.lam / 3600.0
        gains = np.einsum("kon,knm->kom", mf.Cz, mf.Bz / mf.lam[:, :, None])
    tau_h[bad] = np.nan
    gains[bad] = np.nan
    offs = _constant_part(model, P, mf) if _constant_indices(model) else None
    out: dict[str, np.ndarray] = {}
    for k in range(model.n_states):
        out[f"tau_{k + 1}_h"] = tau_h[:, k].copy()
    for o, oname in enumerate(model.output_names):
        for i, uname in enumerate(model.input_names):
            out[f"gain_{oname}_{uname}"] = gains[:, o, i].copy()
    if offs is not None:
        consts = [model.parameter_names[j] for j in _constant_indices(model)]
        for o, oname in enumerate(model.output_names):
            for c, cname in enumerate(consts):
                out[f"offset_{oname}_{cname}"] = offs[:, o, c].copy()
    if not batch:
        return {k: float(v[0]) for k, v in out.items()}
    return out


# ------------------------------------------------------------ structural identifiability
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


def structural_identifiability(
    model,
    params,
    dt: float = 3600.0,
    *,
    n_freq: int = DEFAULT_N_FREQ,
    longest_period: float = DEFAULT_LONGEST_PERIOD,
    rtol: float = DEFAULT_RTOL,
    threshold: float = DEFAULT_THRESHOLD,
    fixed: Iterable[str] = (),
) -> IdentifiabilityResult:
    """Local structural identifiability of an RC model at one parameter set.

    Parameters
    ----------
    model : RCModel
    params : mapping name -> float, or (P,) array
        One parameter set (typically the MAP) [SI units]. Capacities, conductances and
        gains must be > 0 (their coordinate is the logarithm).
    dt : float
        Sampling step of the data [s]; sets the highest frequency (Nyquist, π/dt).
    n_freq : int
        Number of log-spaced frequencies (plus ω = 0).
    longest_period : float
        Period of the lowest frequency of the grid [s], default 10 years.
    rtol : float
        Singular values ≤ ``rtol × largest`` count as zero.
    threshold : float
        A parameter whose axis projects on the null space with length above this is
        flagged as not identifiable; loadings above it make up ``pinned_by``.
    fixed : iterable of str
        Parameters held at their value (known, or fixed in the calibration): their
        columns are left out, so e.g. ``fixed=("Ci",)`` shows what remains once the
        scale is pinned by a known air capacity. The result then covers the free
        parameters only.

    Returns
    -------
    IdentifiabilityResult

    Raises
    ------
    ValueError
        A batch instead of one parameter set, non-physical values, a free capacity,
        conductance or gain that is not > 0, unknown names in ``fixed``, or invalid
        options.

    Notes
    -----
    See the module docstring for the observables, coordinates, derivatives and
    tolerance. For unheated rooms observed through temperatures (or vapour pressures)
    only, the result has the *overall scale* direction: all capacities, conductances and
    gains scaled together leave the output unchanged.

    A network driven by a single potential boundary has a static gain of exactly 1 by
    construction, which carries no information. The two-node hygric models
    (``hygric_2c``, ``hygric_2c_fixed``, driven by ``Pe`` only) therefore have a second
    null direction: even with ``Ci`` known, the buffer capacity ``Cw`` and its
    conductance to outdoors ``Gw`` (and ``Gf``) trade off; their transfer function has
    three free coefficients for four scale-free parameters. The thermal models escape
    this through their second potential input ``Tf`` and the solar inputs.

    Examples
    --------
    >>> import heritage_bayes as hb
    >>> from heritage_bayes.rc.identify import structural_identifiability
    >>> m = hb.model("hygric_2c")
    >>> r = structural_identifiability(m, dict(Cw=5e-3, Ci=1e-4, Gw=1e-8, Gi=5e-8, Gfast=2e-8))
    >>> r.rank, [d.label for d in r.directions]
    (3, ['overall scale', 'direction 2'])
    >>> r.directions[1].pinned_by
    ('Gw', 'Cw')
    """
    dt = _check_dt(dt)
    n_freq = _check_int(n_freq, "n_freq", 2)
    longest_period = _check_positive(longest_period, "longest_period")
    if longest_period <= 2.0 * dt:
        raise ValueError(
            f"longest_period must exceed the Nyquist period 2*dt = {2 * dt:g} s "
            f"(got {longest_period:g} s)"
        )
    rtol = _check_fraction(rtol, "rtol")
    threshold = _check_fraction(threshold, "threshold")
    P, batch = _param_matrix(model, params)
    if batch or P.shape[0] != 1:
        raise ValueError(
            "structural_identifiability takes one parameter set (e.g. the MAP), "
            f"not a batch (got {P.shape[0]} sets)"
        )
    model.check_values(P)
    p0 = P[0]
    all_names = model.parameter_names
    all_kinds = [info.kind for info in model.parameters]
    fixed = _check_fixed(fixed, all_names)
    free = [j for j, n in enumerate(all_names) if n not in fixed]
    for name, kind, v in zip(all_names, all_kinds, p0, strict=True):
        if kind in _LOG_KINDS and not v > 0 and name not in fixed:
            raise ValueError(
                f"structural_identifiability: {kind} {name} must be > 0, its coordinate "
                f"is log({name}) (got {v:g}); build the network without that link or "
                "source to check a model where it is absent"
            )
    if not model.valid_mask(P)[0] or not modal_form(model, P, dt).valid[0]:
        raise ValueError(
            f"model {model.name!r}: the parameter set gives a singular network "
            "(a node cut off from every boundary?)"
        )

    omega = np.concatenate([[0.0], np.geomspace(2 * np.pi / longest_period, np.pi / dt, n_freq)])
    J = _jacobian(model, p0, all_kinds, omega)[:, free]
    names = tuple(all_names[j] for j in free)
    kinds = [all_kinds[j] for j in free]
    pf = p0[free]

    s_full, rank, Q, live = _svd_rank(J, rtol)
    # the overall scale: 1 on every capacity, conductance and gain that has an influence
    scale = np.array([1.0 if k in _LOG_KINDS else 0.0 for k in kinds]) * live
    tol = rtol * s_full[0]
    Jn = J / np.where(live, np.linalg.norm(J, axis=0), 1.0)
    w = scale * np.linalg.norm(J, axis=0)  # the scale vector in column-scaled coordinates
    scale_null = bool(
        scale.any() and Q.shape[1] and np.linalg.norm(Jn @ w) <= tol * np.linalg.norm(w)
    )
    ref = _scale_reference(model, names, kinds, scale) if scale_null else None
    vecs: list[np.ndarray] = []
    dead = [np.eye(len(names))[j] for j in np.flatnonzero(~live)]
    Q_live = Q[:, : Q.shape[1] - len(dead)]
    if scale_null:
        # the scale first; the others span what remains free once the scale is pinned
        # through the reference parameter (zero loading on it)
        r = names.index(ref)
        vecs.append(scale / np.linalg.norm(scale))
        if Q_live.shape[1] > 1:
            W = Q_live - np.outer(scale, Q_live[r] / scale[r])
            U = np.linalg.svd(W, full_matrices=False)[0]
            vecs.extend(U[:, : Q_live.shape[1] - 1].T)
    else:
        vecs.extend(Q_live.T)
    vecs.extend(dead)  # parameters without any influence, one direction each

    directions = []
    for k, v in enumerate(vecs):
        v = v / np.linalg.norm(v)
        if v[np.argmax(np.abs(v))] < 0:
            v = -v
        v = np.where(np.abs(v) < 1e-12, 0.0, v)
        is_scale = scale_null and k == 0
        directions.append(_describe(model, names, kinds, pf, v, threshold, is_scale, k + 1, ref))

    null_loading = np.linalg.norm(Q, axis=1)
    if scale_null:
        rest = [[d.vector[n] for n in names] for d in directions if not d.is_scale]
        given_scale = np.linalg.norm(np.array(rest), axis=0) if rest else np.zeros(len(names))
    else:
        given_scale = null_loading
    transforms = {n: _TRANSFORM[k] for n, k in zip(names, kinds, strict=True)}
    return IdentifiabilityResult(
        model_name=model.name,
        parameter_names=names,
        point={n: float(v) for n, v in zip(all_names, p0, strict=True)},
        fixed=fixed,
        transforms=transforms,
        dt=dt,
        omega=omega,
        singular_values=s_full,
        rtol=rtol,
        threshold=threshold,
        rank=rank,
        directions=tuple(directions),
        scale_reference=ref,
        null_loading={n: float(v) for n, v in zip(names, null_loading, strict=True)},
        loading_given_scale={n: float(v) for n, v in zip(names, given_scale, strict=True)},
        jacobian=J,
    )


def _svd_rank(J: np.ndarray, rtol: float):
    """Singular values, numerical rank and null space of a Jacobian (θ coordinates).

    Columns are scaled to unit norm; columns that are zero (parameters without any
    influence) are set aside and contribute one zero singular value and one axis each.

    Returns
    -------
    s : (P,) singular values, descending
    rank : int
    Q : (P, P - rank) orthonormal null-space basis: the null space of the influential
        columns first, then one unit axis per zero column
    live : (P,) bool, the columns with an influence
    """
    npar = J.shape[1]
    cn = np.linalg.norm(J, axis=0)
    live = cn > 1e-14 * max(cn.max(), 1e-300)
    idx = np.flatnonzero(live)
    s = np.zeros(npar)
    if idx.size == 0:
        return s, 0, np.eye(npar), live
    _, sl, Vt = np.linalg.svd(J[:, idx] / cn[idx], full_matrices=True)
    s[: sl.size] = sl
    rank = int(np.sum(sl > rtol * sl[0]))
    Nl = Vt[rank:].T / cn[idx, None]  # back to θ coordinates
    N = np.zeros((npar, Nl.shape[1]))
    N[idx] = Nl
    if N.shape[1]:
        N = np.linalg.qr(N)[0]
    Q = np.column_stack([N, *(np.eye(npar)[:, j] for j in np.flatnonzero(~live))])
    return s, rank, Q.reshape(npar, -1), live


def _theta_steps(p0: np.ndarray, kinds) -> np.ndarray:
    """dp/dθ per parameter: p (log), 1 (fraction), max(|c|, 1) (constant)."""
    # (a log-parameter at <= 0 can only be a fixed one, whose column is dropped)
    return np.array(
        [
            (v if v > 0 else 1.0)
            if k in _LOG_KINDS
            else 1.0
            if k == "fraction"
            else max(abs(v), 1.0)
            for v, k in zip(p0, kinds, strict=True)
        ]
    )


def _matrix_derivatives(model, p0: np.ndarray, kinds):
    """Network matrices at p0 and their derivatives with respect to θ (exact: affine).

    Returns cap (n,), G (n,n), Gu (n,m), qc (n_const, n) [q of each constant alone,
    and per unit of that constant], and derivatives dcap (P,n), dG (P,n,n), dGu (P,n,m),
    dqc (P, n_const, n) [of the q of each constant alone, at its actual value].
    """
    npar = len(p0)
    ds = _theta_steps(p0, kinds)
    h = 0.5 * ds
    # rows: base, then +h_j, -h_j for every j
    Pp = np.repeat(p0[None], 1 + 2 * npar, axis=0)
    idx = np.arange(npar)
    Pp[1 + idx, idx] += h
    Pp[1 + npar + idx, idx] -= h
    cap, G, Gu, _ = model.network_matrices(Pp)
    scale = (ds / (2 * h))[:, None]
    dcap = (cap[1 : 1 + npar] - cap[1 + npar :]) * scale
    dG = (G[1 : 1 + npar] - G[1 + npar :]) * scale[:, :, None]
    dGu = (Gu[1 : 1 + npar] - Gu[1 + npar :]) * scale[:, :, None]
    consts = [j for j, k in enumerate(kinds) if k == "constant"]
    n = cap.shape[1]
    qc_unit = np.zeros((len(consts), n))
    dqc = np.zeros((npar, len(consts), n))
    for i, cidx in enumerate(consts):
        Pc = Pp.copy()
        Pc[:, [j for j in consts if j != cidx]] = 0.0
        q = model.network_matrices(Pc)[3]
        dqc[:, i] = (q[1 : 1 + npar] - q[1 + npar :]) * scale
        Pu = p0[None].copy()
        Pu[:, consts] = 0.0
        Pu[0, cidx] = 1.0
        qc_unit[i] = model.network_matrices(Pu)[3][0]
    return cap[0], G[0], Gu[0], qc_unit, dcap, dG, dGu, dqc


def _jacobian(model, p0: np.ndarray, kinds, omega: np.ndarray) -> np.ndarray:
    """Normalised Jacobian of the input–output behaviour with respect to θ."""
    cap, G, Gu, qc_unit, dcap, dG, dGu, dqc = _matrix_derivatives(model, p0, kinds)
    Cm = model.output_matrix()
    n_out, m = Cm.shape[0], Gu.shape[1]
    iw = 1j * omega
    M = iw[:, None, None] * np.diag(cap)[None] + G[None]  # (F, n, n)
    R = np.linalg.solve(M, np.broadcast_to(Gu, (len(omega), *Gu.shape)))  # (F, n, m)
    Lt = np.linalg.solve(
        np.swapaxes(M, 1, 2), np.broadcast_to(Cm.T, (len(omega), *Cm.T.shape))
    )  # (F, n, n_out)
    L = np.swapaxes(Lt, 1, 2)  # C M^-1: (F, n_out, n)
    H = Cm[None] @ R  # (F, n_out, m)
    # dH_j = -L (iω diag(dcap_j) + dG_j) R + L dGu_j
    LR_cap = np.einsum("fon,pn,fnm->fpom", L, dcap, R) * iw[:, None, None, None]
    dH = -LR_cap - np.einsum("fon,pnk,fkm->fpom", L, dG, R) + np.einsum("fon,pnm->fpom", L, dGu)
    rows = []
    nrow_block = 2 * len(omega) - 1  # ω=0 has no imaginary part
    for o in range(n_out):
        for i in range(m):
            h = H[:, o, i]
            hmax = np.abs(h).max()
            if not hmax > 0:
                continue  # the input does not reach this output: no information
            wgt = 1.0 / np.maximum(np.abs(h), _H_FLOOR * hmax)
            d = dH[:, :, o, i] * wgt[:, None]  # (F, P)
            rows.append(d.real)
            rows.append(d.imag[1:])
    # constant boundaries: steady-state contribution y_c = C G^-1 q_c
    if qc_unit.shape[0]:
        consts = [j for j, k in enumerate(kinds) if k == "constant"]
        Ginv_C = np.linalg.solve(G.T, Cm.T).T  # C G^-1: (n_out, n)
        for i, cidx in enumerate(consts):
            g_unit = Ginv_C @ qc_unit[i]  # (n_out,) per unit of the constant
            q = qc_unit[i] * p0[cidx]
            x = np.linalg.solve(G, q)
            # dy_j = -C G^-1 dG_j G^-1 q + C G^-1 dq_j
            dy = -np.einsum("on,pnk,k->po", Ginv_C, dG, x) + np.einsum(
                "on,pn->po", Ginv_C, dqc[:, i]
            )
            s_c = max(abs(p0[cidx]), 1.0)
            for o in range(n_out):
                if not abs(g_unit[o]) > 0:
                    continue
                rows.append(dy[None, :, o] * np.sqrt(nrow_block) / (abs(g_unit[o]) * s_c))
    if not rows:
        raise ValueError(
            f"model {model.name!r}: no input or constant reaches any output; nothing to identify"
        )
    return np.concatenate(rows, axis=0)


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
                f"a prior on {air} from the room air volume V (V/(R_v·T) ≈ "
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
            f"{names[j]} has no influence on the input-output behaviour: it is not "
            "identifiable from these inputs and outputs. Fix it, give it an informative "
            "prior, or remove it from the model."
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


# ---------------------------------------------------------------------- validation
def _check_int(x, name: str, minimum: int) -> int:
    if isinstance(x, bool) or not isinstance(x, int | np.integer) or x < minimum:
        raise ValueError(f"{name} must be an integer >= {minimum} (got {x!r})")
    return int(x)


def _check_fixed(fixed, names) -> tuple[str, ...]:
    if isinstance(fixed, str):
        fixed = (fixed,)
    try:
        fixed = tuple(fixed)
    except TypeError:
        raise ValueError(f"fixed must be a sequence of parameter names (got {fixed!r})") from None
    unknown = [f for f in fixed if f not in names]
    if unknown:
        raise ValueError(f"fixed: unknown parameter(s) {unknown}; parameters are {list(names)}")
    if len(set(fixed)) == len(names):
        raise ValueError("fixed: every parameter is fixed; nothing to check")
    return tuple(n for n in names if n in fixed)


def _check_positive(x, name: str) -> float:
    try:
        x = float(x)
    except (TypeError, ValueError):
        raise ValueError(f"{name} must be a positive number (got {x!r})") from None
    if not np.isfinite(x) or x <= 0:
        raise ValueError(f"{name} must be a positive number (got {x!r})")
    return x


def _check_fraction(x, name: str) -> float:
    try:
        x = float(x)
    except (TypeError, ValueError):
        raise ValueError(f"{name} must be a number in (0, 1) (got {x!r})") from None
    if not 0 < x < 1:
        raise ValueError(f"{name} must be a number in (0, 1) (got {x!r})")
    return x
