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
:math:`S = C^{-1/2}\\mathbf G C^{-1/2}` is diagonalised in closed form (a plane
rotation, :math:`S = V\\Lambda V^T`; the smaller eigenvalue as the determinant over the
larger, so that a stiff pair loses no digits), and

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
linear models. Compiled (numba), batched over parameter sets: ``p_sat`` of the
temperatures is evaluated once per reading (once per data set in the likelihood), the
transitions of a block of steps in one vectorised loop (two divisions, a square root
and two exponentials per step), then the recursion.

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
    "fill_series",
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
    #: The buffer's isotherm (:data:`heritage_bayes.rc.isotherm.ISOTHERMS`): one capacity.
    isotherm = "linear"

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

    def input_columns(self) -> np.ndarray:
        """Column indices of ``Pe``, ``Pe_slope``, ``Ti`` and ``Tf`` in the inputs (-1:
        absent), as :func:`fill_series` reads them."""
        names = self.input_names
        cols = ("Pe", "Pe" + SLOPE_SUFFIX, "Ti", "Tf")
        return np.array([names.index(c) if c in names else -1 for c in cols], dtype=np.int64)

    def series(self, U: np.ndarray) -> tuple:
        """Per-step series of the compiled step from the input columns ``U`` (N, m):
        ``(sb, slope)``, ``sb`` (7, N) the rows of :func:`fill_series` (``Pe``, its
        change over the step, the step mean of ``r = p_sat(Ti)/p_sat(T_ref)`` [-], its
        square root and the inverse of that, r's change over the step, the sink's
        ``p_sat(Tf)`` [Pa] or 1), ``slope``: whether there is a ``Pe_slope`` column.
        Computed once per data set (the temperatures are data)."""
        U = np.ascontiguousarray(U, dtype=float)
        cols = self.input_columns()
        sb = np.empty((N_SERIES, U.shape[0]))
        fill_series(U, cols, 0, U.shape[0], sb)
        return sb, bool(cols[1] >= 0)

    def steady_state(self, P: np.ndarray, u0: np.ndarray) -> np.ndarray:
        """(K, 2) steady state (Pw, Pi) [Pa] of constant inputs ``u0`` (m,) (the
        temperatures included): the solution of G y = β in the variables
        (v = r Pw, Pi), then Pw = v / r."""
        kp = self.kernel_parameters(P)
        sb, _ = self.series(np.atleast_2d(u0))
        pe, r, ps = sb[0, 0], sb[2, 0], sb[6, 0]  # ps: p_sat(Tf) or 1
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
        self._recursion(P, kp, U, float(dt), x, out[:, :, 0])
        valid &= np.isfinite(out[:, -1, 0]) if U.shape[0] else valid
        return out, valid

    def _recursion(self, P, kp, U, dt, x, out) -> None:
        """Run the compiled recursion of :meth:`forward`: ``out`` (K, N) ``Pi`` [Pa]."""
        cols = self.input_columns()
        _simulate(kp, U, cols, bool(cols[1] >= 0), dt, x, out)


#: Kernel parameters of an invalid walker (a harmless stable network).
_PLACEHOLDER = np.array([1e-3, 1e-3, 0.0, 1e-8, 1e-8, 0.0, 0.0])
#: Rows of the step series (:func:`fill_series`).
N_SERIES = 7
_IREF = 1.0 / P_REF


@numba.njit(cache=True, nogil=True, error_model="numpy", fastmath={"contract"})
def fill_series(U, cols, k0, B, sb):  # pragma: no cover - compiled
    """Step series of rows ``k0 .. k0 + B - 1`` of the inputs ``U`` (N, m) into
    ``sb[:, :B]`` (7, >= B): ``Pe`` [Pa]; its change over the step (the ``Pe_slope``
    column, 0 without one); from the readings ``T`` = ``Ti`` [°C] at the step
    boundaries, ``ρ = p_sat(T)/p_sat(T_ref)`` linear between them: its step mean
    ``r = (ρ[k] + ρ[k+1])/2`` [-], ``sqrt(r)``, ``1/sqrt(r)`` and the change
    ``ρ[k+1] - ρ[k]`` (zero on the last row, whose next reading is unknown; 1, 1, 1, 0
    without ``Ti``); the sink's ``p_sat(Tf)`` [Pa] (1 without ``Tf``). ``cols``: the
    columns of ``Pe``, ``Pe_slope``, ``Ti``, ``Tf`` (-1: absent). The columns are
    copied first, so that each loop vectorises; ``p_sat`` is evaluated once per
    reading."""
    N = U.shape[0]
    ipe, idpe, iti, itf = cols[0], cols[1], cols[2], cols[3]
    for b in range(B):
        sb[0, b] = U[k0 + b, ipe]
    if idpe >= 0:
        for b in range(B):
            sb[1, b] = U[k0 + b, idpe]
    else:
        sb[1, :B] = 0.0
    if itf >= 0:
        for b in range(B):
            sb[6, b] = U[k0 + b, itf]
        for b in range(B):
            sb[6, b] = psat_water(sb[6, b])
    else:
        sb[6, :B] = 1.0
    if iti < 0:
        sb[2:5, :B] = 1.0
        sb[5, :B] = 0.0
        return
    rho = np.empty(B + 1)
    for b in range(B + 1):
        rho[b] = U[min(k0 + b, N - 1), iti]
    for b in range(B + 1):
        rho[b] = psat_water(rho[b]) * _IREF
    for b in range(B):
        v = 0.5 * (rho[b] + rho[b + 1])
        q = math.sqrt(v)
        sb[2, b] = v
        sb[3, b] = q
        sb[4, b] = 1.0 / q
        sb[5, b] = rho[b + 1] - rho[b]


@numba.njit(inline="always", cache=True, nogil=True, error_model="numpy")
def _gains(lam, il, dt, idt, slope):  # pragma: no cover - compiled
    """Pole ``a = exp(-lam dt)``, ZOH gain ``(1 - a)/lam`` [s] and with ``slope`` the
    FOH slope gain ``(w+ - w-)/2`` [s] (:func:`heritage_bayes.rc.discretize.foh_weights`,
    else 0) of a mode with decay rate ``lam`` [1/s] and its inverse ``il`` [s]; series
    below ``lam dt = 1e-2`` (no cancellation: relative error below 1e-12). Branch-free
    and without a division (the other side of a selection may be inf or NaN, unused),
    so that a loop over steps vectorises."""
    x = lam * dt
    a = vexp(-x)
    small = x < 1e-2
    p = dt * (1.0 + x * (-0.5 + x * (1 / 6 + x * (-1 / 24 + x * (1 / 120 - x * (1 / 720))))))
    p = p if small else (1.0 - a) * il
    g = 0.0
    if slope:
        ws = 0.5 + x * (-1 / 3 + x * (1 / 8 + x * (-1 / 30 + x * (1 / 144 - x * (1 / 840)))))
        ix = il * idt
        wl = (1.0 - a * (1.0 + x)) * ix * ix
        g = 0.5 * p - dt * (ws if small else wl)
    return a, p, g


@numba.njit(inline="always", cache=True, nogil=True, error_model="numpy")
def walker_constants(kp):  # pragma: no cover - compiled
    """The per-parameter-set constants of :func:`step_coefficients` (a tuple) from one
    row ``kp`` of :meth:`CoupledHygricModel.kernel_parameters`: with the capacities'
    scalings ``iw = Cw^-1/2``, ``s2 = Ci^-1/2``, the symmetric
    ``S = [[A11 r, -A12 sqrt(r)], [-A12 sqrt(r), S22]]`` and its determinant ``r D``
    (``D`` from the conductances, without cancellation)."""
    cw, ci, gw, gi, gfast, gf, sink = kp[0], kp[1], kp[2], kp[3], kp[4], kp[5], kp[6]
    iw = 1.0 / math.sqrt(cw)
    s2 = 1.0 / math.sqrt(ci)
    S22 = (gi + gfast + gf) * s2 * s2
    A11 = (gw + gi) * iw * iw
    A12 = gi * iw * s2
    D = (gw * (gi + gfast + gf) + gi * (gfast + gf)) * (iw * iw) * (s2 * s2)
    iD = 1.0 / D if D > 0.0 else math.inf
    return (iw, s2, S22, A11, A12, D, iD, iw / s2, s2 / iw, gw, gi, gfast, gf * sink)


@numba.njit(inline="always", cache=True, nogil=True, error_model="numpy")
def step_modes(c, r, sr, isr):  # pragma: no cover - compiled
    """The modes of one step (:func:`step_coefficients`): ``(cc, ss, cs, l1, l2, il1,
    il2)``, the rotation ``V = [[c, s], [-s, c]]`` of ``S = V diag(l1, l2) V^T`` by
    ``c²``, ``s²`` and ``cs``, the decay rates [1/s] and their inverses [s]. ``c``:
    :func:`walker_constants`; ``r``, ``sr``, ``isr``: the step mean of
    ``r = p_sat(Tw)/p_sat(T_ref)``, its square root and the inverse of that."""
    S22, A11, A12, D, iD = c[2], c[3], c[4], c[5], c[6]
    S11 = A11 * r
    b = A12 * sr
    dl = 0.5 * (S11 - S22)
    h = math.sqrt(dl * dl + b * b)
    ih = 1.0 / max(h, 1e-300)  # h = 0: S a multiple of I, any rotation (cs = 0)
    q = abs(dl) * ih
    cc = 0.5 + 0.5 * q
    ss = 0.5 - 0.5 * q
    cs = 0.5 * b * ih
    cs = cs if dl >= 0.0 else -cs
    lb = 0.5 * (S11 + S22) + h
    ilb = 1.0 / lb
    ir = isr * isr
    ls = r * D * ilb
    ils = lb * ir * iD
    up = dl >= 0.0
    l1 = lb if up else ls
    l2 = ls if up else lb
    il1 = ilb if up else ils
    il2 = ils if up else ilb
    return cc, ss, cs, l1, l2, il1, il2


@numba.njit(inline="always", cache=True, nogil=True, error_model="numpy")
def step_coefficients(c, r, sr, isr, dr, pe, dpe, xs, dt, idt, slope):  # pragma: no cover
    """Transition ``(M0, M1, M2, M3)`` and forcing ``(f0, f1)`` of one step:
    ``(Pw, Pi)[k+1] = [[M0, M1], [M2, M3]] (Pw, Pi)[k] + (f0, f1)`` (module docstring).
    ``c``: :func:`walker_constants`; ``r``, ``sr``, ``isr``, ``dr``: the step mean of
    ``r = p_sat(Tw)/p_sat(T_ref)``, its square root, the inverse of that and r's change
    over the step; ``pe``, ``dpe`` the vapour pressure's mean and change (the latter
    used with ``slope``); ``xs`` the sink's ``p_sat(Tf)`` (1 for a constant node);
    ``idt = 1/dt``. Branch-free, two divisions and one square root.

    The eigen-decomposition of the 2×2 symmetric ``S`` in closed form: with
    ``δ = (S11 - S22)/2``, ``b = -S12 >= 0``, ``h = sqrt(δ² + b²)``, the eigenvalue
    that continues ``S11`` is ``l1 = (S11 + S22)/2 + sign(δ) h``, and
    ``V = [[c, s], [-s, c]]`` with ``c² = (1 + |δ|/h)/2``, ``s² = 1 - c²``,
    ``cs = sign(δ) b/(2h)``; the smaller eigenvalue is the determinant over the larger
    (no cancellation), and ``1/l`` of each follows from ``1/det``."""
    iw, s2, S22, A11, A12, D, iD, w_s, s_w, gw, gi, gfast, gfs = c
    cc, ss, cs, l1, l2, il1, il2 = step_modes(c, r, sr, isr)
    a1, p1, g1 = _gains(l1, il1, dt, idt, True)
    a2, p2, g2 = _gains(l2, il2, dt, idt, True)
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
    M1 = m12 * w_s * isr
    M2 = m12 * s_w * sr + s2 * (h22 * s2 - h12 * s1) * gdr
    M3 = ss * a1 + cc * a2
    b1 = s1 * gw * pe
    b2 = s2 * (gfast * pe + gfs * xs)
    k12 = cs * (p2 - p1)
    f1 = (cc * p1 + ss * p2) * b1 + k12 * b2
    f2 = k12 * b1 + (ss * p1 + cc * p2) * b2
    if slope:
        d1 = s1 * gw * dpe
        d2 = s2 * gfast * dpe
        f1 += h11 * d1 + h12 * d2
        f2 += h12 * d1 + h22 * d2
    return M0, M1, M2, M3, iw * isr * f1, s2 * f2  # f0 = s1 f1 / r


@numba.njit(cache=True, nogil=True, error_model="numpy", fastmath={"contract"})
def coupled_block(kp, sb, dt, slope, k0, B, Mf):  # pragma: no cover - compiled
    """Transitions and forcings of steps ``k0 .. k0 + B - 1`` for one parameter set
    (:func:`step_coefficients`), into ``Mf[:, :B]`` (``Mf`` (6, >= B), C-contiguous).

    ``kp``: one row of :meth:`CoupledHygricModel.kernel_parameters`; ``sb`` (7, N): the
    step series of :func:`fill_series`; the change of ``Pe`` over the step is used with
    ``slope``. No dependency between steps: the loop vectorises."""
    c = walker_constants(kp)
    idt = 1.0 / dt
    for b in range(B):
        k = k0 + b
        m0, m1, m2, m3, f0, f1 = step_coefficients(
            c, sb[2, k], sb[3, k], sb[4, k], sb[5, k], sb[0, k], sb[1, k], sb[6, k], dt, idt,
            slope,
        )  # fmt: skip
        Mf[0, b] = m0
        Mf[1, b] = m1
        Mf[2, b] = m2
        Mf[3, b] = m3
        Mf[4, b] = f0
        Mf[5, b] = f1


#: Steps per block of :func:`coupled_block` (its (6, BLOCK) array stays in cache).
BLOCK = 2048


@numba.njit(cache=True, nogil=True, error_model="numpy", fastmath={"contract"})
def _simulate(kp, U, cols, slope, dt, x, out):  # pragma: no cover - compiled
    """Outputs ``out[p, k] = Pi[k]`` of every walker (``x`` (K, 2) start, in place),
    the step series of each block of inputs computed once for all walkers."""
    K = kp.shape[0]
    N = U.shape[0]
    Mf = np.empty((6, BLOCK))
    sb = np.empty((N_SERIES, BLOCK))
    for k0 in range(0, N, BLOCK):
        B = min(BLOCK, N - k0)
        fill_series(U, cols, k0, B, sb)
        for p in range(K):
            coupled_block(kp[p], sb, dt, slope, 0, B, Mf)
            xw = x[p, 0]
            xi = x[p, 1]
            for b in range(B):
                out[p, k0 + b] = xi
                xw, xi = (
                    Mf[0, b] * xw + Mf[1, b] * xi + Mf[4, b],
                    Mf[2, b] * xw + Mf[3, b] * xi + Mf[5, b],
                )
            x[p, 0] = xw
            x[p, 1] = xi


stamp_cache(globals(), _vecmath)
