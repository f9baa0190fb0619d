"""Controlled rooms: thermostats, humidistats and constant sources on an RC network.

Most logged monuments are not free-running: churches are heated for services, stores
have a heating floor and a dehumidifier. A :class:`ControlledModel` is an
:class:`~heritage_bayes.rc.model.RCModel` whose controlled node (the first output: the
indoor air ``Ti`` or ``Pi``) also receives a flow :math:`Q_k` [W] or [kg/s] chosen each
step by an ideal or capacity-limited controller:

.. math::

    x_{k+1} = A_d x_k + B_d u_k + b\\,Q_k,\\qquad
    Q_k = \\operatorname{clip}\\left(\\frac{r_k - c^T(A_d x_k + B_d u_k)}{c^T b},
    -Q^{rem}, Q^{add}\\right)\\ \\text{if the free-running } c^Tx_{k+1}
    \\text{ leaves } [lo_k, hi_k],

with :math:`b` the exact zero-order-hold response of the state to a unit flow into the
air node held over one step (a column of :math:`B_d`), :math:`c` the air node's row of
the output matrix and :math:`r_k` the violated bound. This is the exact solution of the
piecewise-linear system when the flow is constant within a step: the air node ends the
step at the bound (``max(free-running, set-point)``) unless the capacity is reached.
The recursion runs in modal coordinates, batched over parameter sets, compiled (numba).

Components (options of :func:`heritage_bayes.model`):

- ``thermostat`` (thermal): heating to a set-point ``Tset`` [°C]; ``power_limit: true``
  adds the maximum heating power ``Pmax`` [W] (otherwise ideal); ``schedule: COLUMN``
  adds a calendar input (1 in the hours of use, 0 otherwise, fractions allowed) and the
  service set-point ``Tset_use`` [°C] that applies while it is 1 (intermittent heating of
  a church); ``schedule: {weekly: ["Sun 08-12"], timezone: UTC+1}`` generates that input
  (column ``hours_of_use``) from a weekly calendar of the hours of use
  (:mod:`heritage_bayes.rc.calendar`); ``conservation: true`` adds conservation
  heating: the set-point is raised to the temperature at which the RH of the measured
  vapour pressure (input ``Pi``) is ``RH_ch`` [-].
- ``humidistat`` (hygric): the air's RH at the indoor temperature (input ``Ti``, the
  measured one in calibration, a predicted one in projections) held within
  ``[RH_lo, RH_hi]`` [-] (``mode: band``), below ``RH_hi`` (``mode: dehumidifier``),
  above ``RH_lo`` (``mode: humidifier``) or at ``RH_set`` (``mode: setpoint``);
  ``capacity: true`` adds the dehumidifier's and humidifier's capacities ``M_dehum``,
  ``M_hum`` [kg/s] (otherwise ideal).
- ``source`` (both domains): a constant flow into the air node, ``Qs`` [W] (people,
  lighting, a neighbouring heated space) or ``Ms`` [kg/s] (people, a wet floor, a wall
  in contact with a canal), estimated with its own prior.

Switching control off (projections: "what if the dehumidifier fails?"):
:meth:`ControlledModel.with_control` returns the same model (same parameters, so
posterior draws still apply) with chosen components disabled.

References
----------
.. [1] G.F. Franklin, J.D. Powell, M.L. Workman, *Digital Control of Dynamic Systems*,
   3rd ed., Addison-Wesley, 1998, ch. 4 (zero-order-hold equivalent).
.. [2] M. Kramer, J. van Schijndel, H. Schellen, "Inverse modeling of climate responses
   of monumental buildings", 2013 (the free-running models this extends).
.. [3] J. Staniforth, "Conservation heating to slow conservation tasks", 2006
   (heating to keep RH below a limit).
"""

from __future__ import annotations

from dataclasses import replace

import numpy as np

from heritage_bayes.rc.calendar import WeeklyCalendar
from heritage_bayes.rc.control_kernels import control_run, kernel_rows
from heritage_bayes.rc.control_spec import COMPONENTS, HOURS_OF_USE, Control
from heritage_bayes.rc.model import RCModel
from heritage_bayes.rc.network import Network, ParameterInfo

__all__ = ["COMPONENTS", "HOURS_OF_USE", "Control", "ControlledModel", "controlled"]


def controlled(net: Network, control: Control) -> RCModel:
    """Compile ``net`` with ``control`` (a plain :class:`RCModel` when nothing is set)."""
    return ControlledModel(net, control) if control.active else RCModel(net)


class ControlledModel(RCModel):
    """An RC model whose air node is controlled (see the module docstring).

    Parameters are the network's followed by the control's; inputs the network's
    followed by the control's (``Ti`` for a humidistat, ``Pi`` for conservation
    heating, the schedule column). The linear part (``modal_form``, time constants,
    identifiability of the network) is the free-running network.
    """

    def __init__(self, network: Network, control: Control):
        super().__init__(network)
        self.control = control
        dom = network.domain
        c = control
        wrong = [k for k in c.components if COMPONENTS[k] not in (None, dom)]
        if wrong:
            raise ValueError(
                f"model {network.name!r}: a {wrong[0]} needs a {COMPONENTS[wrong[0]]} model "
                f"(this one is {dom})"
            )
        specs: list[ParameterInfo] = []
        extra_in: list[str] = []
        if c.thermostat:
            specs.append(ParameterInfo("Tset", "setpoint", "°C", "heating set-point"))
            if c.schedule:
                specs.append(
                    ParameterInfo(
                        "Tset_use",
                        "setpoint",
                        "°C",
                        f"set-point in the hours of use ({c.schedule})",
                    )
                )
                extra_in.append(c.schedule)
            if c.power_limit:
                specs.append(ParameterInfo("Pmax", "power", "W", "maximum heating power"))
            if c.conservation:
                specs.append(ParameterInfo("RH_ch", "rh", "-", "RH limit of conservation heating"))
                extra_in.append("Pi")
        if c.humidistat:
            mode = c.humidistat
            if mode == "setpoint":
                specs.append(ParameterInfo("RH_set", "rh", "-", "RH held by the humidistat"))
            if mode in ("band", "humidifier"):
                specs.append(ParameterInfo("RH_lo", "rh", "-", "lower RH of the humidistat"))
            if mode in ("band", "dehumidifier"):
                specs.append(ParameterInfo("RH_hi", "rh", "-", "upper RH of the humidistat"))
            if c.capacity:
                if mode != "humidifier":
                    specs.append(
                        ParameterInfo(
                            "M_dehum", "moisture_capacity", "kg/s", "dehumidifier capacity"
                        )
                    )
                if mode != "dehumidifier":
                    specs.append(
                        ParameterInfo("M_hum", "moisture_capacity", "kg/s", "humidifier capacity")
                    )
            extra_in.append("Ti")
        if c.source:
            if dom == "thermal":
                specs.append(ParameterInfo("Qs", "source", "W", "constant heat gain of the air"))
            else:
                specs.append(
                    ParameterInfo("Ms", "source", "kg/s", "constant moisture source of the air")
                )
        clash = [s.name for s in specs if s.name in network.parameter_names]
        clash += [u for u in extra_in if u in network.inputs]
        if clash:
            raise ValueError(
                f"model {network.name!r}: control names {clash} clash with the network"
            )
        self._control_params = tuple(specs)
        self._control_inputs = tuple(dict.fromkeys(extra_in))
        self._n_net = len(network.parameter_names)

    # ------------------------------------------------------------------ names
    @property
    def name(self) -> str:
        return self.network.name

    @property
    def parameter_names(self) -> tuple[str, ...]:
        return self.network.parameter_names + tuple(p.name for p in self._control_params)

    @property
    def parameters(self) -> tuple[ParameterInfo, ...]:
        return self.network.parameters + self._control_params

    @property
    def input_names(self) -> tuple[str, ...]:
        return self.network.inputs + self.slope_columns + self._control_inputs

    @property
    def _m_net(self) -> int:
        """Input columns of the linear network (its inputs and their slope columns)."""
        return len(self.network.inputs) + len(self.slope_inputs)

    @property
    def n_inputs(self) -> int:
        return len(self.input_names)

    @property
    def calendar_inputs(self) -> dict[str, WeeklyCalendar]:
        """Input columns generated from a calendar (name -> :class:`WeeklyCalendar`);
        the data layer computes them from the time grid."""
        c = self.control
        return {c.schedule: c.calendar} if c.calendar is not None else {}

    def input_unit(self, name: str) -> str:
        """Unit of input column ``name``."""
        if name in self.network.inputs:
            return self.network.input_unit(name)
        if name in self.slope_columns:  # an input's change over the step
            return self.network.input_unit(self.slope_inputs[self.slope_columns.index(name)])
        return {"Ti": "°C", "Pi": "Pa"}.get(name, "-")

    def __repr__(self) -> str:
        on = sorted(self.control.enabled & set(self.components))
        return f"{super().__repr__()[:-1]}, control={on})"

    @property
    def components(self) -> tuple[str, ...]:
        """Configured control components (``thermostat``, ``humidistat``, ``source``)."""
        return self.control.components

    def with_control(self, enabled: bool | dict = True) -> ControlledModel:
        """The same model (same parameters and inputs) with control components switched.

        Parameters
        ----------
        enabled : bool or mapping component -> bool
            ``False``: free-running (every component off); ``True``: all on; a mapping
            such as ``{"humidistat": False}`` switches the named components only.
        """
        if isinstance(enabled, bool):
            on = set(COMPONENTS) if enabled else set()
        else:
            unknown = sorted(set(enabled) - set(COMPONENTS))
            if unknown:
                raise ValueError(
                    f"with_control: unknown component(s) {unknown}; model {self.name!r} "
                    f"has {list(self.components)}"
                )
            on = set(self.control.enabled)
            on |= {k for k, v in enabled.items() if v}
            on -= {k for k, v in enabled.items() if not v}
        new = ControlledModel(self.network, replace(self.control, enabled=frozenset(on)))
        return new.with_slopes(self.slope_inputs)

    # ------------------------------------------------------------------ values
    def _cp(self, P: np.ndarray, name: str, default: float = 0.0) -> np.ndarray:
        names = self.parameter_names
        if name in names:
            return np.ascontiguousarray(P[:, names.index(name)])
        return np.full(P.shape[0], default)

    def check_values(self, P: np.ndarray) -> None:
        super().check_values(P)
        ok = self._control_ok(P)
        if not ok.all():
            k = int(np.argmin(ok))
            vals = {p.name: P[k, self._n_net + j] for j, p in enumerate(self._control_params)}
            raise ValueError(
                f"model {self.name!r}: control parameters out of range {vals} (RH in "
                "[0, 1] with RH_lo <= RH_hi, capacities and powers >= 0)"
            )

    def valid_mask(self, P: np.ndarray) -> np.ndarray:
        return super().valid_mask(P) & self._control_ok(P)

    def _control_ok(self, P: np.ndarray) -> np.ndarray:
        ok = np.ones(P.shape[0], dtype=bool)
        for j, p in enumerate(self._control_params):
            col = P[:, self._n_net + j]
            if p.kind == "rh":
                ok &= (col > 0) & (col <= 1)
            elif p.kind in ("power", "moisture_capacity"):
                ok &= col >= 0
        if "RH_lo" in self.parameter_names and "RH_hi" in self.parameter_names:
            ok &= self._cp(P, "RH_lo") <= self._cp(P, "RH_hi")
        return ok

    # ------------------------------------------------------------------ simulation
    def forward(
        self,
        P,
        U,
        dt,
        *,
        u_init=None,
        x0=None,
        effort: bool = False,
        max_block: int = 2**22,
        spin_up: int = 0,
        control_inputs=None,
    ):
        """Controlled simulation of a batch: outputs (K, N, n_out) and validity (K,).

        Parameters
        ----------
        P : (K, n_params) array
        U : (N, m) array of :attr:`input_names` columns
        dt : float [s]
        u_init : (m,) array, optional
            Inputs of the initial steady state (default ``U[0]``); the initial state is
            the steady state of ``u_init`` plus the mean control flow over steps 360 to
            720 (one pass of the controller from the free-running steady state).
        x0 : (n,) or (K, n) array, optional
            Initial state instead (physical units).
        effort : bool
            Also return the control flow (K, N) [W] or [kg/s] (heating > 0,
            dehumidification < 0; the constant source not included).
        max_block : int
            Forcing values held in memory at once (doubles).
        spin_up : int
            Instead of the mean-flow correction of ``u_init``'s steady state, run the
            controller over the first ``spin_up`` steps from the free-running steady
            state and add the state difference it made (controlled minus free-running
            at the end) to that steady state (periodic spin-up: with a year of hourly
            weather, its end is the start of the next; a controller that never acts
            starts exactly where the free-running model does). For
            capacity-limited controllers that have not reached their bound within the
            720 steps of the mean-flow correction (slow rooms, small capacities).
        control_inputs : (K, N, c) array, optional
            The control inputs (``Ti``, ``Pi``, the schedule: the last ``c`` of
            :attr:`input_names`) of each parameter set, instead of ``U``'s columns
            (a projection's simulated ``Ti`` per draw); ``U`` may then hold the
            network's inputs only.
        """
        from heritage_bayes.rc.discretize import modal_form

        P = np.atleast_2d(np.asarray(P, dtype=float))
        U = np.ascontiguousarray(U, dtype=float)
        K = P.shape[0]
        N = U.shape[0]
        mf = modal_form(self, P, dt)
        valid = mf.valid & self._control_ok(P)
        # contiguous: the forcing product below is 10x slower on a strided view
        Un = np.ascontiguousarray(U[:, : self._m_net])
        if control_inputs is None:
            Uc = U[None, :, self._m_net :]  # one control signal for every walker
        else:
            Uc = np.asarray(control_inputs, dtype=float)
            if Uc.shape != (K, N, len(self._control_inputs)):
                raise ValueError(
                    f"control_inputs: expected shape {(K, N, len(self._control_inputs))} "
                    f"({list(self._control_inputs)} per parameter set), got {Uc.shape}"
                )
        air = int(self._ix["out"][0])
        # modal response to a unit flow into the air node: continuous and one-step ZOH
        bz = mf.s[:, air, None] * mf.V[:, air, :]  # (K, n)
        bd = mf.phi * bz
        c = self._controller_arrays(P, Uc)
        src = c.pop("src")
        W_extra = src[:, None] * bd  # constant source per step (K, n)
        with np.errstate(divide="ignore", invalid="ignore"):
            if x0 is not None:
                z0 = mf.to_modal(np.asarray(x0, dtype=float))
            else:
                u0 = Un[0] if u_init is None else np.asarray(u_init, dtype=float)[: self._m_net]
                z0 = mf.steady_state_modal(u0) + src[:, None] * bz / mf.lam
        z0 = np.where(np.isfinite(z0), z0, 0.0)
        z0 = np.ascontiguousarray(np.broadcast_to(z0, mf.lam.shape))
        Bcat = mf.Bdz.reshape(K * mf.lam.shape[1], -1).T  # (m_net, K*n)
        ecat = (mf.edz + W_extra).reshape(-1)
        Cz = np.ascontiguousarray(mf.Cz)
        ad = np.ascontiguousarray(mf.ad)
        rows = max(256, max_block // max(ecat.size, 1))

        def run(Uin, z, Y, Q, control=True):
            kw = kernel_rows(c) if control else {**kernel_rows(c), "mode": 0}
            for k0 in range(0, Uin.shape[0], rows):
                W = Uin[k0 : k0 + rows] @ Bcat + ecat
                control_run(ad, W, bd, Cz, z, Y, Q, k0, **kw)

        if x0 is None and c["on"] and spin_up > 0:
            # the state the control has moved the room by, added to the steady state
            n0 = min(N, int(spin_up))
            zc, zf = z0.copy(), z0.copy()
            yb, q = np.empty((K, n0, Cz.shape[1])), np.zeros((K, n0))
            run(Un[:n0], zc, yb, q)
            run(Un[:n0], zf, yb, q, control=False)
            z0 = np.ascontiguousarray(z0 + (zc - zf))
        elif x0 is None and c["on"]:
            # one controller pass over the start to put the mean control flow in the
            # initial steady state (the heating floor reaches the slow envelope modes)
            n0 = min(N, 720)
            q = np.zeros((K, n0))
            yb = np.empty((K, n0, Cz.shape[1]))
            run(Un[:n0], z0.copy(), yb, q)
            # the mean flow of the second half (after the fast modes' transient)
            qbar = q[:, n0 // 2 :].mean(axis=1)
            z0 = z0 + qbar[:, None] * bz / np.where(mf.lam > 0, mf.lam, 1.0)
            z0 = np.ascontiguousarray(np.where(np.isfinite(z0), z0, 0.0))
        Y = np.empty((K, N, Cz.shape[1]))
        Q = np.zeros((K, N))
        run(Un, z0.copy(), Y, Q)
        valid = valid & np.all(np.isfinite(Y[:, :1, 0]), axis=1)
        return (Y, valid, Q) if effort else (Y, valid)

    def _controller_arrays(self, P: np.ndarray, Uc: np.ndarray) -> dict:
        """Per-walker controller parameters and per-step signals for the kernel
        (``Uc``: (1 or K, N, c); the signals (1 or K, N))."""
        from heritage_bayes.climate.psychro import saturation_vapour_pressure

        c, on = self.control, self.control.enabled
        K, N = P.shape[0], Uc.shape[1]
        cols = {u: Uc[:, :, i] for i, u in enumerate(self._control_inputs)}
        inf = np.full(K, np.inf)
        zero = np.zeros(K)
        out = {
            "mode": 0,
            "t_max": float(c.t_max),
            "lo0": zero,
            "lo1": zero,
            "hi1": zero,
            "qadd": zero,
            "qrem": zero,
            "rh_ch": zero,
            "s": np.zeros((1, N)),
            "pv": np.zeros((1, N)),
            "on": False,
            "src": self._cp(P, "Qs") if "Qs" in self.parameter_names else self._cp(P, "Ms"),
        }
        if not (c.source and "source" in on):
            out["src"] = zero
        if c.thermostat and "thermostat" in on:
            t0 = self._cp(P, "Tset")
            out.update(mode=1, on=True, lo0=t0, qadd=self._cp(P, "Pmax", np.inf))
            if c.schedule:
                out["lo1"] = self._cp(P, "Tset_use") - t0
                out["s"] = np.ascontiguousarray(cols[c.schedule])
            if c.conservation:
                out["mode"] = 3
                out["rh_ch"] = self._cp(P, "RH_ch")
                out["pv"] = np.ascontiguousarray(cols["Pi"])
        elif c.humidistat and "humidistat" in on:
            mode = c.humidistat
            lo = self._cp(P, "RH_set") if mode == "setpoint" else self._cp(P, "RH_lo")
            hi = self._cp(P, "RH_set") if mode == "setpoint" else self._cp(P, "RH_hi")
            cap_d = self._cp(P, "M_dehum", np.inf) if c.capacity else inf
            cap_h = self._cp(P, "M_hum", np.inf) if c.capacity else inf
            out.update(
                mode=2,
                on=True,
                lo1=lo if mode != "dehumidifier" else zero,
                hi1=hi if mode != "humidifier" else inf,
                qadd=cap_h if mode != "dehumidifier" else zero,
                qrem=cap_d if mode != "humidifier" else zero,
                s=np.ascontiguousarray(saturation_vapour_pressure(cols["Ti"])),
            )
        return out


def control_identifiability(model: ControlledModel, scale_free: bool, fixed=()) -> dict[str, str]:
    """What pins each control parameter of ``model`` (plain words, for the report).

    Parameters
    ----------
    model : ControlledModel
    scale_free : bool
        Whether the free-running network's overall scale (all C, G and gains together)
        is a null direction (:func:`heritage_bayes.rc.identify.structural_identifiability`).
    fixed : iterable of str
        Parameters held at known values.

    Notes
    -----
    Set-points and RH limits are levels of the observed air node itself: identifiable
    from the hours in which the control acts (the heating season, the humid months).
    Capacities, powers and constant sources are flows [W] or [kg/s] into the air node:
    scaling every C, G and gain together with them leaves the output unchanged, so
    without a known scale (``room_volume``, ``air_change_rate``, a known heat input)
    only their ratio to the conductances is identifiable (e.g. ``Pmax`` over the total
    conductance to outdoors: the temperature lift the heating can sustain [K]).
    """
    out = {}
    for p in model.parameters[model._n_net :]:
        acts = "; only from hours in which it is reached" if p.kind != "source" else ""
        if p.name in fixed:
            out[p.name] = "fixed (known)"
        elif p.kind in ("setpoint", "rh"):
            out[p.name] = (
                "identifiable from the hours in which the control acts (a level the "
                "air is held at); not informed by data without such hours"
            )
        elif scale_free:
            out[p.name] = (
                f"a flow [{p.unit}]: on the overall-scale direction of the network, "
                "identifiable only in ratio to the conductances unless the scale is "
                f"pinned (room_volume, air_change_rate, a known heat input){acts}"
            )
        else:
            out[p.name] = f"a flow [{p.unit}]: identifiable (the network's scale is pinned){acts}"
    return out
