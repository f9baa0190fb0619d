"""A compiled RC network: names, units and batched state-space assembly.

Import direction: :mod:`heritage_bayes.rc.network` is the declarative description and
imports nothing of the package; this module compiles it (``RCModel(network)``) and
imports the network, the discretisation and the simulator at module level.
"""

from __future__ import annotations

import copy
from collections.abc import Mapping

import numpy as np

from heritage_bayes.climate.ground import depth_factors
from heritage_bayes.rc.discretize import modal_form
from heritage_bayes.rc.network import Network, ParameterInfo
from heritage_bayes.rc.simulate import modal_simulate

__all__ = ["SLOPE_SUFFIX", "RCModel"]

#: Suffix of the input column holding an input's change over the step (first-order hold).
SLOPE_SUFFIX = "_slope"


class RCModel:
    """Continuous-time state space of an RC network.

    :math:`\\dot x = A x + B u + e`, :math:`y = C x + D u`, with
    :math:`A = -C_{cap}^{-1}\\mathbf{G}` (see :mod:`heritage_bayes.rc.network`). The
    affine term :math:`e` is non-zero only for networks with constant boundaries (the
    fixed vapour-pressure node of hygric model 3); :meth:`offset` returns it.

    Use :func:`heritage_bayes.model` to get catalogue models by name.
    """

    #: Control of the air node (:class:`heritage_bayes.rc.control.Control`); None for a
    #: free-running room.
    control = None

    #: Linear in the state but time-varying (a hygric model coupled to a temperature,
    #: :mod:`heritage_bayes.rc.sorption`): no constant modal form, simulated by its own
    #: recursion (:meth:`forward`).
    time_varying = False

    #: Network inputs discretised with the first-order hold (instantaneous readings,
    #: linear between samples); each adds the input column ``<name>_slope`` (see
    #: :meth:`with_slopes`).
    slope_inputs: tuple[str, ...] = ()

    def __init__(self, network: Network):
        self.network = network
        self._ix = as_index_arrays(network)

    # ------------------------------------------------------------------ names
    @property
    def name(self) -> str:
        return self.network.name

    @property
    def domain(self) -> str:
        return self.network.domain

    @property
    def parameter_names(self) -> tuple[str, ...]:
        return self.network.parameter_names

    @property
    def input_names(self) -> tuple[str, ...]:
        return self.network.inputs + self.slope_columns

    @property
    def slope_columns(self) -> tuple[str, ...]:
        """Input columns ``<name>_slope`` of :attr:`slope_inputs`, after the network's."""
        return tuple(f"{u}{SLOPE_SUFFIX}" for u in self.slope_inputs)

    @property
    def slope_mask(self) -> np.ndarray | None:
        """(m_net,) bool: the slope columns among the network's input columns (None:
        none), for :func:`heritage_bayes.rc.discretize.modal_form`."""
        if not self.slope_inputs:
            return None
        n = len(self.network.inputs)
        return np.arange(n + len(self.slope_inputs)) >= n

    @property
    def slope_sources(self) -> tuple[int, ...]:
        """Index in ``network.inputs`` of the input behind each slope column."""
        return tuple(self.network.inputs.index(u) for u in self.slope_inputs)

    def with_slopes(self, inputs) -> RCModel:
        r"""This model with the first-order hold (FOH) for the network inputs ``inputs``.

        Each input ``u`` in ``inputs`` gains a column ``u_slope``
        :math:`= u(t_{k+1}) - u(t_k)` [unit of ``u`` per step] beside its column of
        interval means :math:`\bar u_k`; the step's forcing is then
        :math:`\phi\tilde B\bar u_k + c\,\tilde B(u(t_{k+1}) - u(t_k))`, exact for an
        input linear between its samples (:func:`heritage_bayes.rc.discretize.foh_weights`).
        A slope column of zeros gives the zero-order hold of the interval mean, exact
        for an interval mean. Parameters, states and outputs are unchanged.

        Parameters
        ----------
        inputs : iterable of str
            Network inputs (e.g. ``("Te", "Tf")``); ``()`` gives the model without slopes.
        """
        inputs = tuple(dict.fromkeys(inputs))
        unknown = [u for u in inputs if u not in self.network.inputs]
        if unknown:
            raise ValueError(
                f"with_slopes: {unknown} are not inputs of the network of model "
                f"{self.name!r}; its inputs are {list(self.network.inputs)}"
            )
        new = copy.copy(self)
        new.slope_inputs = tuple(u for u in self.network.inputs if u in inputs)
        return new

    @property
    def state_names(self) -> tuple[str, ...]:
        return self.network.state_names

    @property
    def output_names(self) -> tuple[str, ...]:
        return self.network.outputs

    @property
    def parameters(self) -> tuple[ParameterInfo, ...]:
        return self.network.parameters

    @property
    def n_states(self) -> int:
        return len(self.network.nodes)

    @property
    def n_inputs(self) -> int:
        return len(self.network.inputs) + len(self.slope_inputs)

    @property
    def n_outputs(self) -> int:
        return len(self.network.outputs)

    def __repr__(self) -> str:
        return (
            f"RCModel({self.name!r}, states={self.state_names}, "
            f"inputs={self.input_names}, outputs={self.output_names})"
        )

    # ------------------------------------------------------------------ params
    def param_array(self, params: Mapping[str, object]) -> tuple[np.ndarray, bool]:
        """Parameter mapping -> (K, P) array in :attr:`parameter_names` order.

        Values may be scalars or 1-D arrays of a common length K (a batch); scalars are
        broadcast. Returns the array and whether the input was a batch.

        Raises
        ------
        ValueError
            Missing or unknown names, arrays of different lengths, non-finite values.
        """
        if not isinstance(params, Mapping):
            raise ValueError(
                f"params must be a mapping name -> value for model "
                f"{self.name!r} (got {type(params).__name__})"
            )
        names = self.parameter_names
        missing = [p for p in names if p not in params]
        unknown = [p for p in params if p not in names]
        if missing or unknown:
            parts = []
            if missing:
                parts.append(f"missing {missing}")
            if unknown:
                parts.append(f"unknown {unknown}")
            raise ValueError(
                f"parameters for model {self.name!r}: {'; '.join(parts)}; "
                f"expected exactly {list(names)}"
            )
        vals = [np.asarray(params[p], dtype=float) for p in names]
        batch = any(v.ndim > 0 for v in vals)
        sizes = {v.shape for v in vals if v.ndim > 0}
        if any(v.ndim > 1 for v in vals) or len(sizes) > 1:
            shapes = {p: v.shape for p, v in zip(names, vals, strict=True) if v.ndim}
            raise ValueError(
                f"batched parameters must be 1-D arrays of one common length (got shapes {shapes})"
            )
        K = next(iter(sizes))[0] if sizes else 1
        P = np.empty((K, len(names)))
        for j, v in enumerate(vals):
            P[:, j] = v
        bad = ~np.isfinite(P)
        if bad.any():
            j = int(np.argwhere(bad)[0, 1])
            raise ValueError(
                f"parameter {names[j]} must be finite (got {P[bad.any(axis=1)][0, j]})"
            )
        return P, batch

    def check_values(self, P: np.ndarray) -> None:
        """Raise ValueError naming the first physically invalid parameter value."""
        for j, info in enumerate(self.parameters):
            col = P[:, j]
            if info.kind == "capacity" and np.any(col <= 0):
                bad = col[col <= 0][0]
                raise ValueError(f"capacity {info.name} must be > 0 [{info.unit}] (got {bad:g})")
            if info.kind == "conductance" and np.any(col < 0):
                bad = col[col < 0][0]
                raise ValueError(
                    f"conductance {info.name} must be >= 0 [{info.unit}] (got {bad:g})"
                )
            if info.kind == "fraction" and np.any((col < 0) | (col > 1)):
                bad = col[(col < 0) | (col > 1)][0]
                raise ValueError(f"fraction {info.name} must be within [0, 1] (got {bad:g})")
            if info.kind == "depth" and np.any(col < 0):
                bad = col[col < 0][0]
                raise ValueError(f"depth {info.name} must be >= 0 [m] (got {bad:g})")

    def valid_mask(self, P: np.ndarray) -> np.ndarray:
        """(K,) bool: parameter sets that are physically admissible."""
        ok = np.all(np.isfinite(P), axis=1)
        for j, info in enumerate(self.parameters):
            if info.kind == "capacity":
                ok &= P[:, j] > 0
            elif info.kind == "conductance":
                ok &= P[:, j] >= 0
            elif info.kind == "fraction":
                ok &= (P[:, j] >= 0) & (P[:, j] <= 1)
            elif info.kind == "depth":
                ok &= P[:, j] >= 0
        return ok

    # ------------------------------------------------------------------ matrices
    def network_matrices(self, P: np.ndarray):
        """Capacities, conductance matrix, boundary coupling and constant forcing.

        Parameters
        ----------
        P : (K, n_params) array

        Returns
        -------
        cap : (K, n) array
            Node capacities [J/K] or [kg/Pa].
        G : (K, n, n) array
            Symmetric conductance matrix [W/K] or [kg/(s·Pa)]: node-node links as
            Laplacian, node-boundary links on the diagonal.
        Gu : (K, n, m) array
            Flow into each node per unit of each input.
        q : (K, n) array
            Constant flow from constant boundaries (``G * P_const``).
        """
        ix = self._ix
        K = P.shape[0]
        n, m = self.n_states, len(self.network.inputs)
        cap = P[:, ix["cap"]]
        G = np.zeros((K, n, n))
        Gu = np.zeros((K, n, m))
        q = np.zeros((K, n))
        for a, b, g in ix["nn"]:
            G[:, a, a] += P[:, g]
            G[:, b, b] += P[:, g]
            G[:, a, b] -= P[:, g]
            G[:, b, a] -= P[:, g]
        for a, u, g in ix["nu"]:
            G[:, a, a] += P[:, g]
            Gu[:, a, u] += P[:, g]
        for a, c, g in ix["nc"]:
            G[:, a, a] += P[:, g]
            q[:, a] += P[:, g] * P[:, c]
        for node, u, gi, gv, fi, comp in ix["src"]:
            gain = P[:, gi] if gi >= 0 else gv
            if fi >= 0:
                gain = gain * ((1.0 - P[:, fi]) if comp else P[:, fi])
            Gu[:, node, u] += gain
        for node, g, zi, uc, us, ref, oi in ix["cycle"]:
            a, b = depth_factors(P[:, zi])
            Gu[:, node, uc] += P[:, g] * (a - ref[0])
            Gu[:, node, us] += P[:, g] * (b - ref[1])
            if oi >= 0:  # the boundary's mean offset: a constant flow G ΔT
                q[:, node] += P[:, g] * P[:, oi]
        return cap, G, Gu, q

    def output_matrix(self) -> np.ndarray:
        """C: (n_out, n) selection of the observed nodes."""
        Cm = np.zeros((self.n_outputs, self.n_states))
        Cm[np.arange(self.n_outputs), self._ix["out"]] = 1.0
        return Cm

    def state_space(self, params: Mapping[str, object]):
        """Continuous (A, B, C, D) for one parameter set or a batch.

        Parameters
        ----------
        params : mapping name -> float (or (K,) arrays for a batch), SI units.

        Returns
        -------
        A : (n, n) [1/s];  B : (n, m);  C : (n_out, n);  D : (n_out, m)
            With a batch, A and B gain a leading axis K.
        """
        P, batch = self.param_array(params)
        self.check_values(P)
        cap, G, Gu, _ = self.network_matrices(P)
        A = -G / cap[:, :, None]
        B = Gu / cap[:, :, None]
        Cm = self.output_matrix()
        D = np.zeros((self.n_outputs, B.shape[-1]))
        if not batch:
            A, B = A[0], B[0]
        return A, B, Cm, D

    def with_control(self, enabled=True) -> RCModel:
        """This model with control components switched (a free-running model has none:
        returns itself; see :meth:`heritage_bayes.rc.control.ControlledModel.with_control`)."""
        return self

    def forward(self, P, U, dt, *, u_init=None, x0=None):
        """Simulate a batch of parameter sets: outputs (K, N, n_out) and validity (K,).

        The one entry point for simulating a (possibly controlled) model from a
        parameter array.

        Parameters
        ----------
        P : (K, n_params) array, SI units
        U : (N, m) array of :attr:`input_names` columns
        dt : float
            Time step [s].
        u_init : (m,) array, optional
            Inputs whose steady state is the initial state (default ``U[0]``).
        x0 : (n,) or (K, n) array, optional
            Initial state [°C] or [Pa] instead.
        """
        P = np.atleast_2d(np.asarray(P, dtype=float))
        mf = modal_form(self, P, dt)
        with np.errstate(divide="ignore", invalid="ignore"):
            if x0 is not None:
                z0 = mf.to_modal(np.asarray(x0, dtype=float))
            else:
                z0 = mf.steady_state_modal(U[0] if u_init is None else u_init)
        z0 = np.where(np.isfinite(z0), z0, 0.0)
        z0 = np.ascontiguousarray(np.broadcast_to(z0, mf.lam.shape))
        return modal_simulate(mf, U, z0), mf.valid

    def offset(self, params: Mapping[str, object]) -> np.ndarray:
        """Affine term e [potential/s] of :math:`\\dot x = Ax + Bu + e` (zero unless
        the network has constant boundaries)."""
        P, batch = self.param_array(params)
        self.check_values(P)
        cap, _, _, q = self.network_matrices(P)
        e = q / cap
        return e if batch else e[0]


def as_index_arrays(net: Network):
    """Index arrays that let :class:`RCModel` assemble matrices for many parameter sets.

    Returns a dict of small integer arrays (internal).
    """
    pnames = net.parameter_names
    pidx = {p: i for i, p in enumerate(pnames)}
    nidx = {n.name: i for i, n in enumerate(net.nodes)}
    uidx = {u: i for i, u in enumerate(net.inputs)}
    cap = np.array([pidx[n.C] for n in net.nodes])
    nn = [(nidx[lk.a], nidx[lk.b], pidx[lk.G]) for lk in net.links if lk.b in nidx]
    nu = [(nidx[lk.a], uidx[lk.b], pidx[lk.G]) for lk in net.links if lk.b in uidx]
    nc = [(nidx[lk.a], pidx[lk.b], pidx[lk.G]) for lk in net.links if lk.b in net.constants]
    src = []
    for s in net.sources:
        gain_idx = pidx[s.gain] if isinstance(s.gain, str) else -1
        gain_val = 1.0 if isinstance(s.gain, str) else float(s.gain)
        fp = s.fraction_param
        f_idx, comp = (pidx[fp[0]], fp[1]) if fp else (-1, False)
        src.append((nidx[s.node], uidx[s.input], gain_idx, gain_val, f_idx, comp))
    cycle = [
        (
            nidx[cy.node],
            pidx[cy.G],
            pidx[cy.depth],
            uidx[cy.inputs[0]],
            uidx[cy.inputs[1]],
            tuple(float(v) for v in depth_factors(cy.reference)),
            pidx[cy.offset] if cy.offset is not None else -1,
        )
        for cy in net.cycles
    ]
    out = np.array([nidx[o] for o in net.outputs])
    return {"cap": cap, "nn": nn, "nu": nu, "nc": nc, "src": src, "cycle": cycle, "out": out}
