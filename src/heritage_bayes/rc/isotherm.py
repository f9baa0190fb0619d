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
from heritage_bayes.rc import sorption
from heritage_bayes.rc.network import Network, ParameterInfo
from heritage_bayes.rc.sorption import (
    BLOCK,
    N_SERIES,
    P_REF,
    CoupledHygricModel,
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


@numba.njit(cache=True, nogil=True, error_model="numpy", fastmath={"contract"})
def _simulate_gab(kp, ks, U, cols, slope, dt, x, out):  # pragma: no cover - compiled
    """Outputs ``out[p, k] = Pi[k]`` of every walker (``x`` (K, 2) start, in place)
    with the capacity of :func:`gab_step`, ``ks`` (K,) the multilayer factors."""
    K = kp.shape[0]
    N = U.shape[0]
    sb = np.empty((N_SERIES, BLOCK))
    prev = x[:, 0].copy()
    idt = 1.0 / dt
    for k0 in range(0, N, BLOCK):
        B = min(BLOCK, N - k0)
        fill_series(U, cols, k0, B, sb)
        for p in range(K):
            gc = gab_constants(kp[p], ks[p])
            xw = x[p, 0]
            xi = x[p, 1]
            xp = prev[p]
            for b in range(B):
                out[p, k0 + b] = xi
                m0, m1, m2, m3, f0, f1 = gab_step(gc, xw, xp, sb, b, dt, idt, slope)
                xp = xw
                xw, xi = m0 * xw + m1 * xi + f0, m2 * xw + m3 * xi + f1
            x[p, 0] = xw
            x[p, 1] = xi
            prev[p] = xp


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
        _simulate_gab(kp, ks, U, cols, bool(cols[1] >= 0), dt, x, out)


sorption.stamp_cache(globals(), sorption, _vecmath)
