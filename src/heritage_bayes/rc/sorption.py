"""Thermo-hygric coupling: a sorbing buffer at a temperature, and a vapour sink at one.

The linear hygric models (:mod:`heritage_bayes.rc.catalog`) let a buffer hold moisture
in proportion to a vapour pressure. A hygroscopic material holds moisture in proportion
to its surface *relative humidity* :math:`\\varphi_w` (a linearised sorption isotherm,
moisture capacity :math:`C_m = dm/d\\varphi` [kg]), and the vapour pressure at its surface
is :math:`\\varphi_w\\,p_{sat}(T_w)`: a warm afternoon drives moisture out of timber
without any change in its moisture content. With the indoor vapour pressure
:math:`P_i` [Pa] and the buffer's state written as
:math:`P_w = \\varphi_w\\,p_{sat}(T_{ref})` [Pa] (its surface RH expressed at the fixed
reference temperature :math:`T_{ref}` = 15 °C, so that every hygric state is in [Pa] and
:math:`C_w = C_m / p_{sat}(T_{ref})` [kg/Pa]):

.. math::

    C_w \\dot P_w &= G_i\\,(P_i - r\\,P_w) + G_w\\,(P_e - r\\,P_w),\\\\
    C_i \\dot P_i &= G_{fast}(P_e - P_i) + G_i\\,(r\\,P_w - P_i) + G_f\\,(P_f - P_i),

with :math:`r(t) = p_{sat}(T_w(t))/p_{sat}(T_{ref})`. :math:`T_w` is an input series (by
default the measured indoor temperature ``Ti``). The fixed node's vapour pressure
:math:`P_f` [Pa] is either a constant to estimate (the paper's fixed node) or a *vapour
sink at a temperature*, :math:`P_f = \\varphi_f\\,p_{sat}(T_f)`, with the
ground/neighbour temperature ``Tf`` [°C] an input series and :math:`\\varphi_f` [-]
estimated (a cold wall, a crawlspace's soil, a canal wall near saturation).

Per-step recursion
------------------
Given :math:`T_w` the model is linear time-varying in :math:`(P_w, P_i)`. ``Ti`` is a
measurement: its row ``k`` is the reading at :math:`t_k`, and :math:`r` is taken
linear between the readings at :math:`t_k` and :math:`t_{k+1}` (the data layer's
convention for instantaneous readings). With :math:`r` held at the step's mean
:math:`\\bar r_k` the step is an exact LTI solution: in the variables
:math:`(v, P_i)`, :math:`v = \\bar r_k P_w` the surface vapour pressure, it is the linear
two-node network with capacities :math:`(C_w/\\bar r_k, C_i)` and the symmetric
conductance matrix :math:`\\mathbf G`, whose zero-order hold is the modal solution of
:mod:`heritage_bayes.rc.discretize`. Per step, the 2×2 symmetric
:math:`S = C^{-1/2}\\mathbf G C^{-1/2}` is diagonalised in closed form (one Jacobi
rotation, :math:`S = V\\Lambda V^T`), and

.. math::

    y_{k+1} = C^{-1/2} V\\,e^{-\\Lambda\\Delta t}\\,V^T C^{1/2}\\,y_k
              + C^{-1/2} V\\,\\Phi\\,V^T C^{-1/2}\\,\\beta_k
              + C^{-1/2} V\\,\\Gamma\\,V^T C^{-1/2}\\,\\delta_k,

:math:`\\Phi = \\mathrm{diag}((1 - e^{-\\lambda_j\\Delta t})/\\lambda_j)`,
:math:`\\beta_k` the boundary flows of the row's interval means,
:math:`\\Gamma` the first-order-hold slope gains
(:func:`heritage_bayes.rc.discretize.foh_weights`) and :math:`\\delta_k` the flows that
change linearly over the step with zero mean: that of the vapour pressure's change (its
``Pe_slope`` column) and the coupling's own, :math:`G_i\\,\\Delta r_k\\,P_{w,k}` from the
buffer to the air, :math:`\\Delta r_k = r(t_{k+1}) - r(t_k)` (first order in
:math:`\\Delta r_k`, with :math:`P_w` at the step's start; still linear in the state);
then :math:`P_{w,k+1} = v_{k+1}/\\bar r_k`. Moisture is conserved across steps (the state
is the moisture content, not the vapour pressure). **Exactness**: exact when ``Ti`` is
constant over the step; otherwise the error is of second order in the step's change of
:math:`r` (measured: docs/science/models.md, "Sorption at the temperature of the
materials"). ``Tf`` (a sink's temperature, slow) is held over the step at its row's
value. The output is linear in the initial state given the temperatures (the
transitions do not depend on it), so the initial state is integrated out as for the
linear models. Compiled (numba), batched over parameter sets.

With :math:`r \\equiv 1` (``Tw`` constant at :math:`T_{ref}`) the model is exactly the
linear two-node network (hygric model 3 of Kramer et al. [1]_ without its buffer's link
to outdoors when :math:`G_w = 0`).

References
----------
.. [1] R.P. Kramer, A.W.M. van Schijndel, H.L. Schellen, "Inverse modeling of climate
   responses of monumental buildings", hygric model 3.
.. [2] H.M. Künzel, *Simultaneous heat and moisture transport in building components*,
   Fraunhofer IRB, 1995 (moisture storage function; vapour flux driven by the vapour
   pressure :math:`\\varphi\\,p_{sat}(T)` at the surface).
"""

from __future__ import annotations

import math

import numba
import numpy as np

from heritage_bayes.climate import _vecmath
from heritage_bayes.climate._vecmath import psat_water, stamp_cache, vexp
from heritage_bayes.climate.psychro import saturation_vapour_pressure
from heritage_bayes.rc.model import SLOPE_SUFFIX, RCModel
from heritage_bayes.rc.network import Link, Network, Node, ParameterInfo

__all__ = [
    "P_REF",
    "SINKS",
    "T_REF",
    "CoupledHygricModel",
    "coupled_block",
    "coupled_network",
]

#: Reference temperature [°C] at which the buffer's state is expressed in [Pa].
T_REF = 15.0
#: Saturation vapour pressure at :data:`T_REF` [Pa].
P_REF = float(saturation_vapour_pressure(T_REF))
#: Fixed-node kinds: a constant vapour pressure ``Pf`` [Pa] or a sink at the temperature
#: ``Tf`` with relative humidity ``phi_f`` [-].
SINKS = ("none", "constant", "temperature")


def coupled_network(name: str, *, sorption: bool, outdoor: bool, sink: str) -> Network:
    """The network of a coupled hygric model at the reference temperature (``r = 1``).

    Its linear form is what the time constants, derived quantities and the initial
    state's prior use; the simulation and likelihood use the exact time-varying
    recursion of :class:`CoupledHygricModel`. ``sorption``: the buffer's capacity is
    ``Cm`` [kg] per unit surface RH (else ``Cw`` [kg/Pa], a vapour-pressure buffer);
    ``outdoor``: the buffer also exchanges with outdoors (``Gw``); ``sink``: one of
    :data:`SINKS`.
    """
    if sink not in SINKS:
        raise ValueError(f"model {name!r}: option sink must be one of {list(SINKS)} (got {sink!r})")
    cap = "Cm" if sorption else "Cw"
    links = [Link("Pw", "Pi", "Gi"), Link("Pi", "Pe", "Gfast")]
    if outdoor:
        links.insert(0, Link("Pw", "Pe", "Gw"))
    constants: tuple[str, ...] = ()
    if sink != "none":
        pot = "Pf" if sink == "constant" else "phi_f"
        links.append(Link("Pi", pot, "Gf"))
        constants = (pot,)
    desc = {
        "Cm": "moisture capacity of the sorbing buffer per unit surface RH (linearised "
        "sorption isotherm dm/dφ)",
        "Cw": "hygric capacity of buffering surfaces (walls, contents)",
        "Ci": "hygric capacity of the indoor air node",
        "Gw": "vapour conductance buffer - outdoor",
        "Gi": "vapour conductance buffer surface - indoor air",
        "Gfast": "vapour conductance indoor air - outdoor (ventilation)",
        "Gf": "vapour conductance indoor air - fixed vapour-pressure node",
        "Pf": "vapour pressure of the fixed node",
        "phi_f": "relative humidity of the vapour sink at the temperature Tf",
        "Pe": "outdoor vapour pressure",
        "Ti": "temperature of the buffer's surface (the measured indoor temperature)",
        "Tf": "temperature of the vapour sink (ground / neighbouring space)",
    }
    return Network(
        name=name,
        domain="hygric",
        nodes=(Node("Pw", cap), Node("Pi", "Ci")),
        links=tuple(links),
        inputs=("Pe",),
        outputs=("Pi",),
        constants=constants,
        descriptions=desc,
    )


class CoupledHygricModel(RCModel):
    """A two-node hygric model, linear time-varying given temperatures (module docstring).

    Parameters are the network's (:func:`coupled_network`); inputs ``Pe`` [Pa] (and its
    slope column with the first-order hold), then ``Ti`` [°C] (the buffer's temperature,
    when ``sorption``) and ``Tf`` [°C] (the sink's, when ``sink == "temperature"``).
    :meth:`network_matrices` and everything built on the modal form (time constants,
    identifiability, the initial state's prior covariance) describe the model at the
    reference temperature; :meth:`forward` and the likelihood are the exact recursion.
    """

    #: The simulator is linear in the state but time-varying: no constant modal form.
    time_varying = True

    def __init__(self, network: Network, *, sorption: bool, sink: str):
        super().__init__(network)
        self.sorption = bool(sorption)
        self.sink = sink
        extra = (["Ti"] if self.sorption else []) + (["Tf"] if sink == "temperature" else [])
        self._time_inputs = tuple(extra)

    # ------------------------------------------------------------------ names
    @property
    def input_names(self) -> tuple[str, ...]:
        return self.network.inputs + self.slope_columns + self._time_inputs

    @property
    def n_inputs(self) -> int:
        return len(self.input_names)

    @property
    def parameters(self) -> tuple[ParameterInfo, ...]:
        out = []
        for p in self.network.parameters:
            if p.name == "Cm":
                p = ParameterInfo("Cm", "sorption_capacity", "kg", p.description)
            elif p.name == "phi_f":
                p = ParameterInfo("phi_f", "saturation", "-", p.description)
            out.append(p)
        return tuple(out)

    def input_unit(self, name: str) -> str:
        """Unit of input column ``name``."""
        return "°C" if name in ("Ti", "Tf") else "Pa"

    def __repr__(self) -> str:
        return f"{super().__repr__()[:-1]}, sorption={self.sorption}, sink={self.sink!r})"

    def equations(self) -> tuple[str, ...]:
        """The balance equations in words (for ``hbayes models``)."""
        cap = "(Cm/psat(T_ref))" if self.sorption else "Cw"
        r = "r" if self.sorption else ""
        rw = "r·Pw" if self.sorption else "Pw"  # the buffer's surface vapour pressure
        out = "Gw·(Pe − Pw) + " if "Gw" in self.parameter_names else ""
        sink = {
            "none": "",
            "constant": " + Gf·(Pf − Pi)",
            "temperature": " + Gf·(phi_f·psat(Tf) − Pi)",
        }[self.sink]
        lines = [
            f"{cap}·dPw/dt = {out.replace('Pw', rw)}Gi·(Pi − {rw})",
            f"Ci·dPi/dt = Gfast·(Pe − Pi) + Gi·({r + '·' if r else ''}Pw − Pi){sink}",
        ]
        if self.sorption:
            lines += [
                f"  r = psat(Ti)/psat(T_ref): Pw = φ_w·psat(T_ref) is the buffer's surface RH "
                f"φ_w expressed at T_ref = {T_REF:g} °C; its surface vapour pressure is "
                "φ_w·psat(Ti)",
                "  exact per step with Ti (and Tf) held over the step (heritage_bayes.rc.sorption)",
            ]
        return tuple(lines)

    # ------------------------------------------------------------------ values
    def _col(self, P: np.ndarray, name: str, default: float = 0.0) -> np.ndarray:
        names = self.parameter_names
        if name in names:
            return np.ascontiguousarray(P[:, names.index(name)], dtype=float)
        return np.full(P.shape[0], default)

    def _extra_ok(self, P: np.ndarray) -> np.ndarray:
        ok = np.ones(P.shape[0], dtype=bool)
        if self.sorption:
            ok &= self._col(P, "Cm") > 0
        if self.sink == "temperature":
            f = self._col(P, "phi_f")
            ok &= (f >= 0) & (f <= 1.5)
        return ok

    def check_values(self, P: np.ndarray) -> None:
        super().check_values(P)
        ok = self._extra_ok(P)
        if not ok.all():
            k = int(np.argmin(ok))
            vals = ", ".join(
                f"{n}={P[k, j]:g}"
                for j, n in enumerate(self.parameter_names)
                if n in ("Cm", "phi_f")
            )
            raise ValueError(
                f"model {self.name!r}: {vals} out of range (Cm > 0 kg, phi_f within [0, 1.5])"
            )

    def valid_mask(self, P: np.ndarray) -> np.ndarray:
        return super().valid_mask(P) & self._extra_ok(P)

    def network_matrices(self, P: np.ndarray):
        """The matrices of :meth:`RCModel.network_matrices` at the reference temperature:
        ``Cm`` [kg] becomes ``Cm / p_sat(T_ref)`` [kg/Pa] and the sink's ``phi_f``
        becomes the vapour pressure ``phi_f p_sat(T_ref)`` [Pa]."""
        cap, G, Gu, q = super().network_matrices(P)
        if self.sorption:
            cap = cap.copy()
            cap[:, 0] = cap[:, 0] / P_REF
        if self.sink == "temperature":
            q = q * P_REF
        return cap, G, Gu, q

    def state_space(self, params):
        """Continuous (A, B, C, D) at the reference temperature (:meth:`RCModel.state_space`),
        with zero columns of B and D for the temperature inputs ``Ti``, ``Tf``: they act
        through the coupling, not as linear inputs."""
        A, B, C, D = super().state_space(params)
        extra = len(self._time_inputs)
        pad = [(0, 0)] * (B.ndim - 1) + [(0, extra)]
        return A, np.pad(B, pad), C, np.pad(D, [(0, 0), (0, extra)])

    def kernel_parameters(self, P: np.ndarray) -> np.ndarray:
        """(K, 7) per-walker arrays of the compiled step: Cw [kg/Pa at T_ref], Ci
        [kg/Pa], Gw, Gi, Gfast, Gf [kg/(s·Pa)], and the sink's factor (``Pf`` [Pa] for
        a constant node, ``phi_f`` [-] for a sink at ``Tf``, 0 without a node)."""
        P = np.atleast_2d(np.asarray(P, dtype=float))
        cw = self._col(P, "Cm") / P_REF if self.sorption else self._col(P, "Cw")
        sink = self._col(P, "Pf") if self.sink == "constant" else self._col(P, "phi_f")
        cols = [cw, self._col(P, "Ci"), self._col(P, "Gw"), self._col(P, "Gi")]
        cols += [self._col(P, "Gfast"), self._col(P, "Gf"), sink]
        out = np.ascontiguousarray(np.column_stack(cols))
        out[~self.valid_mask(P)] = _PLACEHOLDER
        return out

    def series(self, U: np.ndarray) -> tuple:
        """Per-step series of the compiled step from the input columns ``U`` (N, m).

        ``pe`` [Pa]; ``dpe`` its change over the step [Pa] (the ``Pe_slope`` column;
        without one, ``pe``, unused); ``rs`` (4, N): the step mean of
        ``r = p_sat(Ti)/p_sat(T_ref)`` [-] (linear between the readings), its square
        root, the inverse of that and r's change over the step (ones and zero without
        sorption, :func:`temperature_ratio`); ``ps``: the
        sink's ``p_sat(Tf)`` [Pa] (``[1.0]`` without a sink at a temperature);
        ``slope``: whether there is a ``Pe_slope`` column."""
        U = np.asarray(U, dtype=float)
        names = self.input_names
        N = U.shape[0]
        pe = np.ascontiguousarray(U[:, 0])
        slope = "Pe" + SLOPE_SUFFIX in names
        dpe = np.ascontiguousarray(U[:, names.index("Pe" + SLOPE_SUFFIX)]) if slope else pe
        if self.sorption:
            ratio = np.empty((4, N))
            temperature_ratio(np.ascontiguousarray(U[:, names.index("Ti")]), ratio)
        else:
            ratio = np.ones((4, N))
            ratio[3] = 0.0
        if self.sink == "temperature":
            ps = np.empty(N)
            saturation_series(np.ascontiguousarray(U[:, names.index("Tf")]), ps)
        else:
            ps = np.ones(1)
        return pe, dpe, ratio, ps, slope

    def steady_state(self, P: np.ndarray, u0: np.ndarray) -> np.ndarray:
        """(K, 2) steady state (Pw, Pi) [Pa] of constant inputs ``u0`` (m,) (the
        temperatures included): the solution of G y = β in the variables
        (v = r Pw, Pi), then Pw = v / r."""
        kp = self.kernel_parameters(P)
        pe, _, rs, ps, _ = self.series(np.atleast_2d(u0))
        pe, r, ps = pe[0], rs[0, 0], ps[0]  # ps: p_sat(Tf) or 1
        _, _, gw, gi, gfast, gf, sink = kp.T
        b1, b2 = gw * pe, gfast * pe + gf * sink * ps
        a11, a22 = gw + gi, gi + gfast + gf
        det = a11 * a22 - gi * gi
        with np.errstate(divide="ignore", invalid="ignore"):
            v = (a22 * b1 + gi * b2) / det
            pi = (gi * b1 + a11 * b2) / det
            # a buffer linked to nothing but the air (Gw = 0) sits at the air's pressure
            v = np.where(np.isfinite(v), v, pi)
        return np.column_stack([v / r, pi])

    # ------------------------------------------------------------------ simulation
    def forward(self, P, U, dt, *, u_init=None, x0=None):
        """Simulate a batch: outputs (K, N, 1) ``Pi`` [Pa] and validity (K,), by the
        exact per-step recursion (module docstring) from ``x0`` (n,) or (K, n) [Pa], or
        the steady state of ``u_init`` (default ``U[0]``)."""
        P = np.atleast_2d(np.asarray(P, dtype=float))
        U = np.ascontiguousarray(U, dtype=float)
        K = P.shape[0]
        valid = self.valid_mask(P)
        kp = self.kernel_parameters(P)
        if x0 is None:
            x = self.steady_state(P, U[0] if u_init is None else np.asarray(u_init, float))
        else:
            x = np.broadcast_to(np.asarray(x0, dtype=float), (K, 2))
        x = np.ascontiguousarray(np.where(np.isfinite(x), x, 0.0))
        out = np.empty((K, U.shape[0], 1))
        _simulate(kp, *self.series(U), float(dt), x, out[:, :, 0])
        valid &= np.isfinite(out[:, -1, 0]) if U.shape[0] else valid
        return out, valid


#: Kernel parameters of an invalid walker (a harmless stable network).
_PLACEHOLDER = np.array([1e-3, 1e-3, 0.0, 1e-8, 1e-8, 0.0, 0.0])


@numba.njit(inline="always", cache=True, nogil=True, error_model="numpy")
def _gains(lam, dt, slope):  # pragma: no cover - compiled
    """Pole ``a = exp(-lam dt)``, ZOH gain ``(1 - a)/lam`` [s] and with ``slope`` the
    FOH slope gain ``(w+ - w-)/2`` [s] (:func:`heritage_bayes.rc.discretize.foh_weights`,
    else 0) of a mode with decay rate ``lam`` [1/s]; series below ``lam dt = 1e-2`` (no
    cancellation: relative error below 1e-12). Branch-free in the step, so that a loop
    over steps vectorises."""
    x = lam * dt
    a = vexp(-x)
    xs = min(x, 1e-2)
    xl = max(x, 1e-2)
    ixl = 1.0 / xl
    ps = 1.0 + xs * (-0.5 + xs * (1 / 6 + xs * (-1 / 24 + xs * (1 / 120 - xs / 720))))
    p = dt * (ps if x < 1e-2 else (1.0 - a) * ixl)
    g = 0.0
    if slope:
        ws = 0.5 + xs * (-1 / 3 + xs * (1 / 8 + xs * (-1 / 30 + xs * (1 / 144 - xs / 840))))
        wl = (1.0 - a * (1.0 + xl)) * ixl * ixl
        g = 0.5 * p - dt * (ws if x < 1e-2 else wl)
    return a, p, g


@numba.njit(inline="always", cache=True, nogil=True, error_model="numpy")
def walker_constants(kp, each, ps0):  # pragma: no cover - compiled
    """The per-parameter-set constants of :func:`step_coefficients` (a tuple) from one
    row ``kp`` of :meth:`CoupledHygricModel.kernel_parameters`; ``each``: the sink's
    ``p_sat(Tf)`` is a series, else the constant ``ps0`` (1 for a constant node)."""
    cw, ci, gw, gi, gfast, gf, sink = kp[0], kp[1], kp[2], kp[3], kp[4], kp[5], kp[6]
    iw = 1.0 / math.sqrt(cw)
    s2 = 1.0 / math.sqrt(ci)
    S22 = (gi + gfast + gf) * s2 * s2
    A11 = (gw + gi) * iw * iw  # S11 = A11 r
    A12 = gi * iw * s2  # S12 = -A12 sqrt(r)
    iA12 = 0.5 / A12 if A12 > 0.0 else 1e300  # zeta huge or 0: t = 0 or 1, same M
    # the sink's flow gf·sink·ps[k]: a series, or a constant (a series read with weight
    # 0 in the constant case keeps the step branch-free)
    gfs = gf * sink if each else 0.0
    const = 0.0 if each else gf * sink * ps0
    return (iw, s2, S22, A11, A12, iA12, gw, gi, gfast, gfs, const)


@numba.njit(inline="always", cache=True, nogil=True, error_model="numpy")
def step_coefficients(c, r, sr, isr, dr, pe, dpe, xs, dt, slope):  # pragma: no cover
    """Transition ``(M0, M1, M2, M3)`` and forcing ``(f0, f1)`` of one step:
    ``(Pw, Pi)[k+1] = [[M0, M1], [M2, M3]] (Pw, Pi)[k] + (f0, f1)`` (module docstring).
    ``c``: :func:`walker_constants`; ``r``, ``sr``, ``isr``, ``dr``: the step mean of
    ``r = p_sat(Tw)/p_sat(T_ref)``, its square root, the inverse of that and r's change
    over the step; ``pe``, ``dpe`` the vapour pressure's mean and change (the latter
    used with ``slope``); ``xs`` the sink's ``p_sat(Tf)``. Branch-free."""
    iw, s2, S22, A11, A12, iA12, gw, gi, gfast, gfs, const = c
    S11 = A11 * r
    S12 = -A12 * sr
    # one Jacobi rotation: V = [[c, s], [-s, c]], columns the eigenvectors of S (l1, l2);
    # an uncoupled buffer (S12 = 0, zeta infinite) gives t = 0
    zeta = (S11 - S22) * iA12 * isr
    t = 1.0 / (abs(zeta) + math.sqrt(1.0 + zeta * zeta))
    t = t if zeta >= 0.0 else -t
    l1 = S11 - t * S12
    l2 = S22 + t * S12
    a1, p1, g1 = _gains(l1, dt, True)
    a2, p2, g2 = _gains(l2, dt, True)
    # cos² = 1/(1 + t²), t = sin/cos: only the products of cos and sin enter
    cc = 1.0 / (1.0 + t * t)
    ss, cs = t * t * cc, t * cc
    h11 = cc * g1 + ss * g2
    h22 = ss * g1 + cc * g2
    h12 = cs * (g2 - g1)
    s1 = sr * iw
    # y = (v, Pi) with v = r Pw: y+ = C^-1/2 V diag(a) V^T C^1/2 y, then Pw+ = v+/r; r's
    # change over the step, a flow gi·dr·(s/dt - 1/2)·Pw[k] from the buffer to the air,
    # enters with the first-order-hold slope gains (h)
    gdr = gi * dr
    m12 = cs * (a2 - a1)
    M0 = cc * a1 + ss * a2 + iw * isr * (h12 * s2 - h11 * s1) * gdr
    M1 = m12 * (iw / s2) * isr
    M2 = m12 * (s2 / iw) * sr + s2 * (h22 * s2 - h12 * s1) * gdr
    M3 = ss * a1 + cc * a2
    b1 = s1 * gw * pe
    b2 = s2 * (gfast * pe + gfs * xs + const)
    k12 = cs * (p2 - p1)
    f1 = (cc * p1 + ss * p2) * b1 + k12 * b2
    f2 = k12 * b1 + (ss * p1 + cc * p2) * b2
    if slope:
        d1 = s1 * gw * dpe
        d2 = s2 * gfast * dpe
        f1 += h11 * d1 + h12 * d2
        f2 += h12 * d1 + h22 * d2
    return M0, M1, M2, M3, iw * isr * f1, s2 * f2  # f0 = s1 f1 / r


@numba.njit(cache=True, nogil=True, error_model="numpy")
def coupled_block(kp, pe, dpe, rs, ps, dt, slope, k0, B, Mf):  # pragma: no cover - compiled
    """Transitions and forcings of steps ``k0 .. k0 + B - 1`` for one parameter set
    (:func:`step_coefficients`), into ``Mf[:, :B]`` (``Mf`` (6, >= B), C-contiguous).

    ``kp``: one row of :meth:`CoupledHygricModel.kernel_parameters`; ``rs`` (4, N): the
    step mean of ``r = p_sat(Tw)/p_sat(T_ref)``, its square root, the inverse of that
    and r's change over the step; ``ps`` the sink's ``p_sat(Tf)`` (N,) (or ``[1.0]``: a
    constant node); ``dpe`` the change of ``pe`` over the step, used with ``slope``. No
    dependency between steps: the loop vectorises."""
    each = ps.size > 1
    c = walker_constants(kp, each, ps[0])
    xs = ps if each else pe
    for b in range(B):
        k = k0 + b
        m0, m1, m2, m3, f0, f1 = step_coefficients(
            c, rs[0, k], rs[1, k], rs[2, k], rs[3, k], pe[k], dpe[k], xs[k], dt, slope
        )
        Mf[0, b] = m0
        Mf[1, b] = m1
        Mf[2, b] = m2
        Mf[3, b] = m3
        Mf[4, b] = f0
        Mf[5, b] = f1


@numba.njit(cache=True, nogil=True, error_model="numpy")
def temperature_ratio(T, out):  # pragma: no cover - compiled
    """From readings ``T`` [°C] at the step boundaries, ``ρ = p_sat(T)/p_sat(T_ref)``
    linear between them: ``out[0]`` its step mean ``(ρ[k] + ρ[k+1])/2`` [-], ``out[1]``
    the square root of that, ``out[2]`` the inverse of ``out[1]``, ``out[3]`` the change
    ``ρ[k+1] - ρ[k]`` (zero on the last row, whose next reading is unknown) (4, N)."""
    N = T.size
    if N == 0:
        return
    rho = np.empty(N + 1)
    for k in range(N):  # two passes: each loop vectorises
        rho[k] = psat_water(T[k]) / P_REF
    rho[N] = rho[N - 1]
    for k in range(N):
        v = 0.5 * (rho[k] + rho[k + 1])
        q = math.sqrt(v)
        out[0, k] = v
        out[1, k] = q
        out[2, k] = 1.0 / q
        out[3, k] = rho[k + 1] - rho[k]


@numba.njit(cache=True, nogil=True, error_model="numpy")
def saturation_series(T, out):  # pragma: no cover - compiled
    """``out = p_sat(T)`` [Pa] over water (N,)."""
    for k in range(T.size):
        out[k] = psat_water(T[k])


#: Steps per block of :func:`coupled_block` (its (6, BLOCK) array stays in cache).
BLOCK = 2048


@numba.njit(cache=True, nogil=True, error_model="numpy")
def _simulate(kp, pe, dpe, rs, ps, slope, dt, x, out):  # pragma: no cover - compiled
    """Outputs ``out[p, k] = Pi[k]`` of every walker (``x`` (K, 2) start, in place)."""
    K = kp.shape[0]
    N = pe.size
    Mf = np.empty((6, BLOCK))
    for p in range(K):
        xw = x[p, 0]
        xi = x[p, 1]
        for k0 in range(0, N, BLOCK):
            B = min(BLOCK, N - k0)
            coupled_block(kp[p], pe, dpe, rs, ps, dt, slope, k0, B, Mf)
            for b in range(B):
                out[p, k0 + b] = xi
                xw, xi = (
                    Mf[0, b] * xw + Mf[1, b] * xi + Mf[4, b],
                    Mf[2, b] * xw + Mf[3, b] * xi + Mf[5, b],
                )
        x[p, 0] = xw
        x[p, 1] = xi


stamp_cache(globals(), _vecmath)
