"""A sorbing buffer whose moisture capacity follows its humidity: the GAB isotherm's slope.

The coupled hygric models (:mod:`heritage_bayes.rc.sorption`) give the buffer one
capacity :math:`C_w` [kg/Pa at :math:`T_{ref}`]: a linearised isotherm. Hygroscopic
materials follow a curved isotherm whose slope :math:`du/d\\varphi` grows towards
saturation (multilayer sorption, then capillary condensation): over the buffer's
relative humidities of a cellar wall the slope changes severalfold. With
the option ``isotherm: gab`` the buffer's capacity is that of the
Guggenheim-Anderson-de Boer (GAB) isotherm [1]_ [2]_,

.. math::

    u(\\varphi) = \\frac{u_m C K \\varphi}{(1 - K\\varphi)(1 - K\\varphi + C K\\varphi)},
    \\qquad
    C_w(\\varphi) = C_w\\,\\frac{g(K\\varphi)}{g(K\\varphi_{ref})},
    \\quad g(x) = \\frac{(1 - x)(1 + (C-1)x) - x\\,((C-2) - 2(C-1)x)}
                        {(1 - x)^2 (1 + (C-1)x)^2},

(:math:`g(K\\varphi) = du/d\\varphi / (u_m C K)`) with the capacity parameter
:math:`C_w` (or ``Cm``) its value at the reference humidity :math:`\\varphi_{ref}` =
:data:`PHI_REF`, the multilayer factor :math:`K` [-] (``K_gab``) the one shape parameter,
and the energy constant :math:`C` fixed at :data:`GAB_C` (above 40 % RH the slope's
shape is set by K; C moves its low-humidity knee). :math:`K = 0` is the linear model exactly
(:math:`g(0) = 1`). The buffer's humidity is its state expressed at the reference
temperature, :math:`\\varphi = P_w / p_{sat}(T_{ref})`: the surface RH of a sorbing
buffer (``hygric_2c_sorption``); for a vapour-pressure buffer (``hygric_2c_fixed``), at
a temperature :math:`T_w` the model does not know, it is the RH scaled by
:math:`p_{sat}(T_w)/p_{sat}(T_{ref})`, so that the fitted ``K_gab`` is the material's K
times :math:`p_{sat}(T_{ref})/p_{sat}(T_w)` (× 1.0-2.0 for a wall at 5-15 °C). The
literature's K of wood, lime plaster and brick lies at 0.6-0.9 ([2]_, [3]_); the
prior (:mod:`heritage_bayes.inference.priors`, kind ``isotherm_shape``) is uniform on
0-:data:`K_MAX`. ``K φ`` is capped at :data:`X_MAX` (the GAB slope is infinite at
``K φ = 1``).

Per-step recursion
------------------
The buffer's balance :math:`C_w(\\varphi)\\,\\dot P_w = J` is nonlinear in its state.
Each step is the exact time-varying step of :mod:`heritage_bayes.rc.sorption` with the
buffer's capacity held at :math:`C_w(\\varphi_{k+1/2})`, the humidity at the step's middle
extrapolated from the last step, :math:`\\varphi_{k+1/2} = (3 P_{w,k} - P_{w,k-1}) /
(2 p_{sat}(T_{ref}))` (:math:`P_{w,-1} = P_{w,0}`). **Error bound**: with
:math:`\\Delta\\varphi_k` the step's change of humidity, the held capacity differs from
the mean the exact solution sees over the step by the extrapolation's error, of order
:math:`|\\Delta\\varphi_k - \\Delta\\varphi_{k-1}|`, times :math:`\\lambda_1 =
\\max|d\\ln C_w/d\\varphi|`, plus the capacity's curvature over the step,
:math:`\\lambda_2 \\Delta\\varphi_k^2` with :math:`\\lambda_2 = \\max|C_w''|/C_w` (its
first order cancels about the middle); the local error of the humidity is therefore
:math:`|\\delta\\varphi_k| \\lesssim |\\Delta\\varphi_k|\\,(\\lambda_1 |\\Delta\\varphi_k -
\\Delta\\varphi_{k-1}| + \\lambda_2 \\Delta\\varphi_k^2)`, of second order in the
step's change (measured against a fine integration of the ODE in
docs/science/models.md, "A capacity that follows the humidity"). The transitions now
depend on the state: they are computed inside the recursion, and the initial state's
free responses (with which the likelihood integrates it out) are propagated by the
transitions of the trajectory from the prior mean, then once more by those of the
trajectory from the conditional mean start that gives (a linearisation about the
path the data put the buffer on; :class:`heritage_bayes.inference.posterior.LogPosterior`).

Tabulated transitions
---------------------
The capacity and the temperature enter the step's decay matrix of :math:`(P_w, P_i)`,
:math:`L = [[a\\rho, -b/f], [-c\\,r, d]]` (:math:`f = C_w(\\varphi)/C_w`,
:math:`\\rho = r/f`), only through :math:`\\rho` on the diagonal and the factors
:math:`1/f` and :math:`r` off it. Each matrix function of the step (the pole
:math:`e^{-L\\Delta t}`, the zero-order-hold gain and the first-order-hold slope gain)
is, for a 2×2 matrix, :math:`F(L) = F_m I + F_1 (L - mI)` with :math:`m` the mean of
the eigenvalues and the scalars :math:`F_m, F_1` symmetric functions of them: smooth
functions of :math:`\\rho` alone. Nine of them (the diagonal :math:`F_m \\pm F_1\\delta`
and :math:`F_1` of each) are tabulated per parameter set over cells of 1/16 octave of
:math:`\\rho` (a cell read from the bits of :math:`\\rho`), each cell a Chebyshev
interpolant of degree 5 of the exact closed form (:func:`_matrix_functions`), built
when the recursion first reaches it. The step itself is then one division (the GAB
slope), the table's polynomials and a few products, with no exponential or square root
on the chain of dependent operations from one state to the next. **Accuracy**: a
cell's half-width is :math:`w \\le \\rho/32`, and the interpolation error at most
:math:`w^6 \\max|d^6F/d\\rho^6| / (2^5\\, 6!)` (Chebyshev nodes), that is below
:math:`5\\cdot 10^{-14}` times the functions' sixth derivatives in
:math:`\\ln\\rho`, which are of order one to ten for these exponentials; the
simulated series equal those of the exact step (:func:`gab_step`) far below the
recursion's own error
(docs/science/benchmarks.md, "The coupled hygric model against the linear one").

References
----------
.. [1] R.B. Anderson, "Modifications of the Brunauer, Emmett and Teller equation",
   J. Am. Chem. Soc. 68 (1946) 686-691.
.. [2] Ł. Bratasz, A. Kozłowska, R. Kozłowski, "Analysis of water adsorption by wood
   using the Guggenheim-Anderson-de Boer equation", Eur. J. Wood Wood Prod. 70 (2012)
   445-451.
.. [3] C. Hall, W.D. Hoff, *Water Transport in Brick, Stone and Concrete*, 2nd ed.,
   Spon, 2012 (sorption isotherms of masonry and plaster).
"""

from __future__ import annotations

import math

import numba
import numpy as np

from heritage_bayes.climate import _vecmath
from heritage_bayes.climate._vecmath import _as_double, _as_int
from heritage_bayes.rc import sorption
from heritage_bayes.rc.network import Network, ParameterInfo
from heritage_bayes.rc.sorption import (
    BLOCK,
    N_SERIES,
    P_REF,
    CoupledHygricModel,
    _gains,
    coupled_block,
    fill_series,
    step_coefficients,
    walker_constants,
)

__all__ = [
    "GAB_C",
    "ISOTHERMS",
    "K_MAX",
    "PHI_REF",
    "X_MAX",
    "IsothermHygricModel",
    "capacity_factor",
    "gab_capacity_factor",
    "gab_constants",
    "gab_step",
]

#: The buffer's isotherms: ``linear`` (one capacity) or ``gab`` (module docstring).
ISOTHERMS = ("linear", "gab")
#: GAB energy constant C [-], fixed (a value typical of wood, [2]).
GAB_C = 8.0
#: Reference relative humidity [-] at which the capacity parameter is the buffer's.
PHI_REF = 0.65
#: Highest admissible multilayer factor ``K_gab`` [-].
K_MAX = 2.0
#: Cap on ``K φ`` (the GAB slope diverges at 1).
X_MAX = 0.97
_IREF = 1.0 / P_REF
#: Walkers per call of the compiled simulation (their tables are reserved together).
_CHUNK = 64


@numba.njit(inline="always", cache=True, nogil=True, error_model="numpy")
def _shape(x):  # pragma: no cover - compiled
    """``g(x)`` of the module docstring, ``x = K φ`` clipped to [0, X_MAX]."""
    x = min(max(x, 0.0), X_MAX)
    c1 = GAB_C - 1.0
    d = (1.0 - x) * (1.0 + c1 * x)
    return (d - x * ((GAB_C - 2.0) - 2.0 * c1 * x)) / (d * d)


@numba.njit(inline="always", cache=True, nogil=True, error_model="numpy")
def capacity_factor(phi, k):  # pragma: no cover - compiled
    """``C_w(φ)/C_w`` [-] at humidity ``phi`` [-] for the multilayer factor ``k`` [-]
    (exactly 1 at ``k = 0``)."""
    return _shape(k * phi) / _shape(k * PHI_REF)


def gab_capacity_factor(phi, k) -> np.ndarray:
    """``C_w(φ)/C_w`` [-] of humidities ``phi`` and factors ``k`` (broadcast; numpy)."""
    phi, k = np.broadcast_arrays(np.asarray(phi, float), np.asarray(k, float))
    x = np.clip(k * phi, 0.0, X_MAX)
    x0 = np.clip(k * PHI_REF, 0.0, X_MAX)

    def g(x):
        d = (1.0 - x) * (1.0 + (GAB_C - 1.0) * x)
        return (d - x * ((GAB_C - 2.0) - 2.0 * (GAB_C - 1.0) * x)) / (d * d)

    return g(x) / g(x0)


@numba.njit(inline="always", cache=True, nogil=True, error_model="numpy")
def gab_constants(kp, k):  # pragma: no cover - compiled
    """The per-parameter-set constants of :func:`gab_step`: those of
    :func:`~heritage_bayes.rc.sorption.walker_constants` at the capacity ``kp[0]``
    [kg/Pa], the multilayer factor ``k`` [-] and ``1 / g(k φ_ref)``."""
    return walker_constants(kp), k, 1.0 / _shape(k * PHI_REF)


@numba.njit(inline="always", cache=True, nogil=True, error_model="numpy")
def gab_step(gc, xw, xw_prev, sb, j, dt, idt, slope):  # pragma: no cover - compiled
    """:func:`~heritage_bayes.rc.sorption.step_coefficients` of step ``j`` with the
    buffer's capacity scaled by :func:`capacity_factor` ``f`` at the humidity
    extrapolated to the step's middle from the states ``xw`` (now) and ``xw_prev`` (a
    step earlier) [Pa]; ``gc`` from :func:`gab_constants`. The constants that depend on
    the capacity scale with ``f^-1/2`` (``Cw^-1/2`` and the buffer's rows of ``S``):
    one square root and two divisions per step."""
    c, k, ig0 = gc
    iw, s2, S22, A11, A12, D, iD, w_s, s_w, gw, gi, gfast, gfs = c
    f = _shape(k * (1.5 * xw - 0.5 * xw_prev) * _IREF) * ig0
    isf = 1.0 / math.sqrt(f)
    if1 = isf * isf
    cf = (iw * isf, s2, S22, A11 * if1, A12 * isf, D * if1, iD * f, w_s * isf, s_w * f * isf,
          gw, gi, gfast, gfs)  # fmt: skip
    return step_coefficients(
        cf, sb[2, j], sb[3, j], sb[4, j], sb[5, j], sb[0, j], sb[1, j], sb[6, j], dt, idt, slope
    )


#: The transitions' table in ``ρ = r/f`` (:func:`gab_table`): 2**_CELL_BITS cells per
#: octave, a polynomial of degree _DEG in each, octaves 2**-_OCT .. 2**_OCT.
_CELL_BITS = 4
_SHIFT = 52 - _CELL_BITS
_DEG = 5
_OCT = 40
_J0 = (1023 - _OCT) << _CELL_BITS  # the first cell: the bits of 2**-_OCT, shifted
N_CELLS = (2 * _OCT) << _CELL_BITS
#: Functions of ρ per cell (:func:`_matrix_functions`) and the table's row length.
_NF = 9
ROW = _NF * (_DEG + 1)
_LOW = (1 << _SHIFT) - 1
_USCALE = 2.0 ** (1 - _SHIFT)
_NODES = np.cos(np.pi * (2 * np.arange(_DEG + 1) + 1) / (2 * (_DEG + 1)))
#: Values at the Chebyshev nodes -> monomial coefficients in the cell's u in [-1, 1].
_FIT = np.linalg.inv(np.vander(_NODES, _DEG + 1, increasing=True))


@numba.njit(inline="always", cache=True, nogil=True, error_model="numpy")
def table_constants(kp, k):  # pragma: no cover - compiled
    """Per-parameter-set constants of :func:`gab_table_step` from one row ``kp`` of
    :meth:`~heritage_bayes.rc.sorption.CoupledHygricModel.kernel_parameters` and the
    multilayer factor ``k`` [-]: with ``L`` the decay matrix of ``(Pw, Pi)`` at
    ``ρ = r/f``, ``L = [[a ρ, -b/f], [-c r, d]]`` [1/s], its determinant ``ρ D``."""
    cw, ci, gw, gi, gfast, gf, sink = kp[0], kp[1], kp[2], kp[3], kp[4], kp[5], kp[6]
    gsum = gi + gfast + gf
    D = (gw * gsum + gi * (gfast + gf)) / (cw * ci)
    return (k, _shape(k * PHI_REF), (gw + gi) / cw, gi / cw, gi / ci, gsum / ci, D,
            gw / cw, gfast / ci, gf * sink / ci, 1.5 * k * _IREF, 0.5 * k * _IREF)  # fmt: skip


@numba.njit(inline="always", cache=True, nogil=True, error_model="numpy")
def _matrix_functions(tc, rho, dt, idt):  # pragma: no cover - compiled
    """The step's matrix functions of ``L`` at ``ρ`` (:func:`table_constants`), each
    ``F(L) = F_m I + F_1 (L - m I)`` (``m`` the mean of the eigenvalues ``l1 <= l2``,
    ``F_1 = (F(l2) - F(l1))/(l2 - l1)``, ``δ = (a ρ - d)/2``): the diagonal
    ``F_m ± F_1 δ`` and ``F_1`` of the pole ``e^{-l dt}``, the zero-order-hold gain and
    the first-order-hold slope gain of :func:`~heritage_bayes.rc.sorption._gains`;
    smooth in ρ (symmetric in the eigenvalues). The smaller eigenvalue is the
    determinant over the larger (no cancellation)."""
    a, b, c, d, D = tc[2], tc[3], tc[4], tc[5], tc[6]
    ar = a * rho
    dl = 0.5 * (ar - d)
    h = math.sqrt(dl * dl + b * c * rho)
    l2 = 0.5 * (ar + d) + h
    l1 = rho * D / l2
    a1, p1, g1 = _gains(l1, 1.0 / l1, dt, idt, True)
    a2, p2, g2 = _gains(l2, 1.0 / l2, dt, idt, True)
    ih = 0.5 / max(h, 1e-300)
    e1, q1, s1 = (a2 - a1) * ih, (p2 - p1) * ih, (g2 - g1) * ih
    em, qm, sm = 0.5 * (a1 + a2), 0.5 * (p1 + p2), 0.5 * (g1 + g2)
    return (em + e1 * dl, em - e1 * dl, e1, qm + q1 * dl, qm - q1 * dl, q1, sm + s1 * dl,
            sm - s1 * dl, s1)  # fmt: skip


@numba.njit(cache=True, nogil=True, error_model="numpy")
def _build_cell(tab, built, j, tc, dt, idt, fit):  # pragma: no cover - compiled
    """Row ``j`` of the table: each function's degree-_DEG interpolant at the Chebyshev
    nodes of the cell, as monomials in the cell's ``u``, degree-major."""
    lo = _as_double(np.int64(j + _J0) << _SHIFT)
    hi = _as_double(np.int64(j + _J0 + 1) << _SHIFT)
    vals = np.empty((_DEG + 1, _NF))
    for n in range(_DEG + 1):
        v = _matrix_functions(tc, lo + 0.5 * (1.0 + _NODES[n]) * (hi - lo), dt, idt)
        for i in range(_NF):
            vals[n, i] = v[i]
    for dg in range(_DEG + 1):
        for i in range(_NF):
            acc = 0.0
            for n in range(_DEG + 1):
                acc += fit[dg, n] * vals[n, i]
            tab[j, dg * _NF + i] = acc
    built[j] = True


@numba.njit(inline="always", cache=True, nogil=True, error_model="numpy")
def gab_cell(tc, xw, xp, r, ir):  # pragma: no cover - compiled
    """The capacity of :func:`gab_step` as ``1/f`` [-] at the humidity extrapolated to
    the step's middle from the buffer's states ``xw`` (now) and ``xp`` (a step earlier)
    [Pa], ``ρ = r/f`` (``ir = 1/r``) and its cell of the table: the row ``j`` (16 per
    octave of ρ, read from its bits, uniform in ρ within an octave) and ``u`` in [-1, 1)
    across it. ``tc`` from :func:`table_constants`; one division, as
    ``g(x) = (1 + (C-1) x²) / ((1 - x)² (1 + (C-1) x)²)``."""
    x = min(max(tc[10] * xw - tc[11] * xp, 0.0), X_MAX)
    c1 = GAB_C - 1.0
    dd = (1.0 - x) * (1.0 + c1 * x)
    rho = (r * tc[1]) * (dd * dd) / (1.0 + c1 * x * x)
    bits = _as_int(rho)
    j = min(max((bits >> _SHIFT) - _J0, 0), N_CELLS - 1)
    return rho * ir, rho, j, np.float64(bits & _LOW) * _USCALE - 1.0


@numba.njit(inline="always", cache=True, nogil=True, error_model="numpy")
def _poly(t, j, i, u, u2, u4):  # pragma: no cover - compiled
    """Function ``i`` of row ``j`` of the table at ``u`` (Estrin's scheme, degree 5)."""
    lo = t[j, i] + t[j, i + _NF] * u
    mid = t[j, i + 2 * _NF] + t[j, i + 3 * _NF] * u
    return lo + u2 * mid + u4 * (t[j, i + 4 * _NF] + t[j, i + 5 * _NF] * u)


@numba.njit(inline="always", cache=True, nogil=True, error_model="numpy")
def gab_table_step(tc, tab, cell, r, dr, pe, dpe, xs, slope):  # pragma: no cover - compiled
    """:func:`gab_step` from the table ``tab`` (N_CELLS, ROW) of the step's matrix
    functions in ``ρ = r/f`` (:func:`_matrix_functions`, each cell a Chebyshev
    interpolant of degree 5): ``cell`` from :func:`gab_cell` (its row built), ``r``,
    ``dr``, ``pe``, ``dpe``, ``xs`` the rows 2, 5, 0, 1, 6 of the step series."""
    iF, rho, j, u = cell
    b, c = tc[3], tc[4]
    u2 = u * u
    u4 = u2 * u2
    T0, T1, T2 = (
        _poly(tab, j, 0, u, u2, u4),
        _poly(tab, j, 1, u, u2, u4),
        _poly(tab, j, 2, u, u2, u4),
    )
    T3, T4, T5 = (
        _poly(tab, j, 3, u, u2, u4),
        _poly(tab, j, 4, u, u2, u4),
        _poly(tab, j, 5, u, u2, u4),
    )
    T6, T7, T8 = (
        _poly(tab, j, 6, u, u2, u4),
        _poly(tab, j, 7, u, u2, u4),
        _poly(tab, j, 8, u, u2, u4),
    )
    bi = b * iF
    cr = c * r
    q0 = tc[7] * pe * iF
    q1 = tc[8] * pe + tc[9] * xs
    f0 = T3 * q0 - T5 * bi * q1
    f1 = T4 * q1 - T5 * cr * q0
    if slope:
        d0 = tc[7] * dpe * iF
        d1 = tc[8] * dpe
        f0 += T6 * d0 - T8 * bi * d1
        f1 += T7 * d1 - T8 * cr * d0
    # r's change over the step: a flow Gi·dr·(t/dt - 1/2)·Pw[k] from the buffer to the air
    m0 = T0 - bi * dr * (T6 + T8 * c)
    m2 = c * dr * (T8 * b * rho + T7) - T2 * cr
    return m0, -T2 * bi, m2, T1, f0, f1


@numba.njit(cache=True, nogil=True, error_model="numpy", fastmath={"contract"})
def _gab_run(tc, tab, built, sb, b0, B, slope, x, Mf, out):  # pragma: no cover - compiled
    """Steps ``b0 ..`` of the block ``sb`` (``x`` = [Pw, Pi, Pw a step earlier], in
    place; each step's transition and forcing into ``Mf[:, b]``, ``Pi`` at its start
    into ``out[b]``) until the end of the
    block or a cell of the table not yet built: returns the step reached and that cell
    (-1: none). No call in the loop, so that the compiler keeps the state in registers."""
    xw, xi, xp = x[0], x[1], x[2]
    b = b0
    j = -1
    while b < B:
        cell = gab_cell(tc, xw, xp, sb[2, b], sb[4, b] * sb[4, b])
        if not built[cell[2]]:
            j = cell[2]
            break
        m0, m1, m2, m3, f0, f1 = gab_table_step(
            tc, tab, cell, sb[2, b], sb[5, b], sb[0, b], sb[1, b], sb[6, b], slope
        )
        Mf[0, b], Mf[1, b], Mf[2, b], Mf[3, b], Mf[4, b], Mf[5, b] = m0, m1, m2, m3, f0, f1
        out[b] = xi
        xp = xw
        xw, xi = m0 * xw + m1 * xi + f0, m2 * xw + m3 * xi + f1
        b += 1
    x[0], x[1], x[2] = xw, xi, xp
    return b, j


@numba.njit(cache=True, nogil=True, error_model="numpy")
def gab_block(tc, tab, built, sb, B, dt, slope, x, Mf, out):  # pragma: no cover - compiled
    """The transitions and forcings (into ``Mf[:, :B]``, as
    :func:`~heritage_bayes.rc.sorption.coupled_block`) of the ``B`` steps of the block
    ``sb`` (the step series) with the capacity of :func:`gab_step` at the states of the
    recursion: ``x`` = [Pw, Pi, Pw a step earlier] [Pa], advanced in place, ``out[:B]``
    the ``Pi`` at each step's start. ``tc``
    from :func:`table_constants`; the cells of the table ``tab`` (one per parameter
    set, ``built`` marking them) are built when first reached."""
    b = 0
    idt = 1.0 / dt
    while b < B:
        b, j = _gab_run(tc, tab, built, sb, b, B, slope, x, Mf, out)
        if j >= 0:
            _build_cell(tab, built, j, tc, dt, idt, _FIT)


@numba.njit(cache=True, nogil=True, error_model="numpy", fastmath={"contract"})
def _simulate_gab(kp, ks, U, cols, slope, dt, x, out):  # pragma: no cover - compiled
    """Outputs ``out[p, k] = Pi[k]`` of every walker (``x`` (K, 2) start, in place)
    with the capacity of :func:`gab_block`, ``ks`` (K,) the multilayer factors (a
    walker with ``K_gab = 0`` runs the linear buffer's step)."""
    K = kp.shape[0]
    N = U.shape[0]
    sb = np.empty((N_SERIES, BLOCK))
    Mf = np.empty((6, BLOCK))
    tab = np.empty((K, N_CELLS, ROW))
    built = np.zeros((K, N_CELLS), dtype=np.bool_)
    st = np.empty((K, 3))
    st[:, :2] = x
    st[:, 2] = x[:, 0]
    for k0 in range(0, N, BLOCK):
        B = min(BLOCK, N - k0)
        fill_series(U, cols, k0, B, sb)
        for p in range(K):
            if ks[p] > 0.0:
                tc = table_constants(kp[p], ks[p])
                gab_block(tc, tab[p], built[p], sb, B, dt, slope, st[p], Mf, out[p, k0:])
                continue
            coupled_block(kp[p], sb, dt, slope, 0, B, Mf)
            xw = st[p, 0]
            xi = st[p, 1]
            for b in range(B):
                out[p, k0 + b] = xi
                xw, xi = (
                    Mf[0, b] * xw + Mf[1, b] * xi + Mf[4, b],
                    Mf[2, b] * xw + Mf[3, b] * xi + Mf[5, b],
                )
            st[p, 0], st[p, 1] = xw, xi
    x[:, :] = st[:, :2]


class IsothermHygricModel(CoupledHygricModel):
    """A coupled hygric model whose buffer follows the GAB isotherm (module docstring):
    the parameters of :class:`~heritage_bayes.rc.sorption.CoupledHygricModel`, the
    buffer's capacity at :data:`PHI_REF`, and ``K_gab`` [-] last."""

    isotherm = "gab"

    def __init__(self, network: Network, *, sorption: bool, sink: str):
        super().__init__(network, sorption=sorption, sink=sink)

    @property
    def parameter_names(self) -> tuple[str, ...]:
        return (*self.network.parameter_names, "K_gab")

    @property
    def parameters(self) -> tuple[ParameterInfo, ...]:
        desc = (
            "multilayer factor K of the buffer's GAB isotherm (its humidity expressed at "
            f"T_ref; 0: the linear isotherm); the capacity is the buffer's at RH {PHI_REF:g}"
        )
        return (*super().parameters, ParameterInfo("K_gab", "isotherm_shape", "-", desc))

    def __repr__(self) -> str:
        return f"{super().__repr__()[:-1]}, isotherm='gab')"

    def equations(self) -> tuple[str, ...]:
        """The balance equations in words (for ``hbayes models``)."""
        cap = "Cm" if self.sorption else "Cw"
        return (
            *super().equations(),
            f"  {cap}(φ) = {cap}·g(K_gab·φ)/g(K_gab·{PHI_REF:g}): the GAB isotherm's slope "
            f"(C = {GAB_C:g}), φ = Pw/psat(T_ref); K_gab = 0 is the linear buffer",
            "  the capacity per step at φ extrapolated to the step's middle "
            "(heritage_bayes.rc.isotherm)",
        )

    def shape(self, P: np.ndarray) -> np.ndarray:
        """(K,) the multilayer factors ``K_gab`` [-] of parameter sets ``P``."""
        return self._col(np.atleast_2d(np.asarray(P, float)), "K_gab")

    def _extra_ok(self, P: np.ndarray) -> np.ndarray:
        k = self._col(P, "K_gab")
        return super()._extra_ok(P) & (k >= 0.0) & (k <= K_MAX)

    def check_values(self, P: np.ndarray) -> None:
        k = self._col(P, "K_gab")
        bad = (k < 0.0) | (k > K_MAX)
        if bad.any():
            raise ValueError(
                f"model {self.name!r}: K_gab={k[bad][0]:g} out of range (within [0, {K_MAX:g}])"
            )
        super().check_values(P)

    def _recursion(self, P, kp, U, dt, x, out) -> None:
        """The per-step recursion with the state's capacity (module docstring):
        ``out`` (K, N) ``Pi`` [Pa]; invalid parameter sets run as linear buffers."""
        ks = np.where(self.valid_mask(P), self.shape(P), 0.0)
        cols = self.input_columns()
        for s in range(0, P.shape[0], _CHUNK):  # each walker's table: 0.5 MB reserved
            c = slice(s, s + _CHUNK)
            _simulate_gab(kp[c], ks[c], U, cols, bool(cols[1] >= 0), dt, x[c], out[c])


sorption.stamp_cache(globals(), sorption, _vecmath)
