"""Structural identifiability of RC networks at a point (typically the MAP).

:func:`structural_identifiability`: the rank of the Jacobian of the model's input–output
behaviour with respect to the (log-)parameters, the directions in parameter space that
leave the output unchanged, and a plain-words description of each. "Structural" means a
property of the model and of which inputs/outputs exist, not of the data: an input that
happens to be zero in a data set does not make its gain structurally non-identifiable.

The quantities that *are* identifiable (time constants, static gains, constant-boundary
contributions) are computed in :mod:`heritage_bayes.rc.derived`; the result container and
the plain-words descriptions of the null directions in
:mod:`heritage_bayes.rc.identify_result`. Both are re-exported here.

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

from collections.abc import Iterable
from dataclasses import replace

import numpy as np

from heritage_bayes.rc.derived import (
    _param_matrix,
    constant_contributions,
    derived_quantities,
    derived_units,
    static_gains,
    time_constants,
)
from heritage_bayes.rc.discretize import _check_dt, modal_form
from heritage_bayes.rc.identify_result import (
    _CONSTANT_KINDS,
    _LOG_KINDS,
    _TRANSFORM,
    IdentifiabilityResult,
    NullDirection,
    _describe,
    _scale_reference,
)
from heritage_bayes.rc.model import RCModel

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

# relative-magnitude floor of the frequency-response normalisation (see module Notes)
_H_FLOOR = 1e-12


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
    if model.control is not None:
        opts = dict(n_freq=n_freq, longest_period=longest_period, rtol=rtol, threshold=threshold)
        return _controlled_identifiability(model, P, dt, opts, fixed)
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
    vecs = _null_vectors(Q, live, scale, names.index(ref) if scale_null else None)

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


def _controlled_identifiability(model, P: np.ndarray, dt: float, opts: dict, fixed):
    """The network's check of a controlled room, and the control's parameters described."""
    from heritage_bayes.rc.control import control_identifiability

    net = RCModel(model.network)
    n_net = len(net.parameter_names)
    fixed = tuple(fixed)
    res = structural_identifiability(
        net, P[0, :n_net], dt, **opts, fixed=[f for f in fixed if f in net.parameter_names]
    )
    point = dict(res.point) | dict(zip(model.parameter_names, P[0].tolist(), strict=True))
    notes = control_identifiability(model, res.has_scale_direction, fixed)
    return replace(res, model_name=model.name, point=point, control=notes)


def _null_vectors(Q: np.ndarray, live: np.ndarray, scale: np.ndarray, r: int | None) -> list:
    """Unnormalised null directions: the scale first when ``r`` (its reference) is given.

    The others span what remains free once the scale is pinned through the reference
    parameter ``r`` (zero loading on it); parameters without any influence (not ``live``)
    come last, one direction each.
    """
    vecs: list[np.ndarray] = []
    dead = [np.eye(len(live))[j] for j in np.flatnonzero(~live)]
    Q_live = Q[:, : Q.shape[1] - len(dead)]
    if r is not None:
        vecs.append(scale / np.linalg.norm(scale))
        if Q_live.shape[1] > 1:
            W = Q_live - np.outer(scale, Q_live[r] / scale[r])
            U = np.linalg.svd(W, full_matrices=False)[0]
            vecs.extend(U[:, : Q_live.shape[1] - 1].T)
    else:
        vecs.extend(Q_live.T)
    vecs.extend(dead)
    return vecs


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
    consts = [j for j, k in enumerate(kinds) if k in _CONSTANT_KINDS]
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
        consts = [j for j, k in enumerate(kinds) if k in _CONSTANT_KINDS]
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
