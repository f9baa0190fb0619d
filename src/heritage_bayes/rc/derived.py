"""Identifiable derived quantities of RC networks, batched over parameter sets.

They go into the posterior for every draw: the time constants of the network (``1/λ`` of
the modal form, see :mod:`heritage_bayes.rc.discretize`), the static gain from each input
to each output (:math:`-C A^{-1} B`) and the steady-state contribution of each constant
boundary (the fixed vapour-pressure node of hygric model 3). All are properties of the
input–output behaviour, hence invariant under every transformation of the parameters that
leaves the output unchanged, e.g. scaling all capacities, conductances and solar apertures
together (see :mod:`heritage_bayes.rc.identify` for which transformations these are).

All names are also importable from :mod:`heritage_bayes.rc.identify` and
:mod:`heritage_bayes.rc`.
"""

from __future__ import annotations

from collections.abc import Mapping

import numpy as np

from heritage_bayes.rc.discretize import modal_form
from heritage_bayes.rc.network import DOMAINS

__all__ = [
    "constant_contributions",
    "derived_quantities",
    "derived_units",
    "static_gains",
    "time_constants",
]


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
    return [j for j, info in enumerate(model.parameters) if info.kind in ("constant", "offset")]


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


#: A mode slower than this many records barely moves over the record. [-]
FROZEN_RECORDS = 10.0


def frozen_time_constant(model, params, record_s: float, records: float = FROZEN_RECORDS):
    """The slowest time constant [s] when it exceeds ``records`` × the record, else None.

    Such a node keeps its start value over the whole record [s]: a constant temperature
    or vapour pressure that can stand in for a missing fixed node or input. When the
    start is estimated (``initial_state: estimate``) it becomes a free offset (an
    example: docs/science/noise.md, "Figures behind the code's choices").

    Parameters
    ----------
    model : RCModel
    params : (P,) array or mapping
        One parameter set [SI].
    record_s : float
        Length of the calibration record [s].
    records : float
        Threshold in records [-].
    """
    tau = time_constants(model, params)
    tau = float(np.asarray(tau).reshape(-1)[0])
    return tau if np.isfinite(tau) and tau > records * record_s else None


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
        # the network's inputs: their slope columns (first-order hold) vanish in steady state
        Bz = mf.Bz[:, :, : len(model.network.inputs)]
        g = np.einsum("kon,knm->kom", mf.Cz, Bz / mf.lam[:, :, None])
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
        for u in net.inputs:  # the linear network's inputs (a control's own are not gains)
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
        # the columns of B: the linear network's inputs; a controlled model's extra
        # inputs (Ti of a humidistat, a schedule) enter the control, not the gains
        for i, uname in enumerate(model.network.inputs):
            out[f"gain_{oname}_{uname}"] = gains[:, o, i].copy()
    if offs is not None:
        consts = [model.parameter_names[j] for j in _constant_indices(model)]
        for o, oname in enumerate(model.output_names):
            for c, cname in enumerate(consts):
                out[f"offset_{oname}_{cname}"] = offs[:, o, c].copy()
    if not batch:
        return {k: float(v[0]) for k, v in out.items()}
    return out
