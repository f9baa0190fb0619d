"""Interventions: measures on the calibrated room, compared draw by draw with doing nothing.

A measure is a change to the room the calibration described, applied to every posterior
draw (:class:`Measure`):

- **conservation heating** (Staniforth 2006 [1]_): a thermostat on the thermal model
  whose set-point is the temperature at which the draw's simulated indoor vapour
  pressure has RH ``rh_max`` (at least ``t_min``, at most ``t_max``), up to
  ``power_max`` [W];
- **dehumidification**: a humidistat on the hygric model that keeps the RH at the
  draw's simulated indoor temperature at or below ``rh_max``, removing at most
  ``capacity`` [kg/h];
- a **humidistat band**: a dehumidifier above ``rh_max`` and a humidifier below
  ``rh_min``, on/off with a switching differential (hysteresis, as a wall humidistat
  works: on at the limit, off once the RH is back by the differential);
- **heating** to a set-point ``t_set`` and, in the hours of use of a weekly calendar,
  ``t_use`` (intermittent heating of a church for services), up to ``power_max``;
- **ventilation** scaled by a factor: ``Gfast`` of both models (the thermal one lumps
  ventilation and glazing) multiplied, every other parameter as calibrated;
- a **combination**: a thermostat (heating or conservation heating) with a humidistat
  (dehumidification or a band), ventilation with any.

The controllers are stepped in the compiled projection pass
(:func:`heritage_bayes.rc.control_kernels.coupled_draw`, the step of
:class:`~heritage_bayes.rc.control.ControlledModel`): per draw both models advance
together, each controller reading the air at the start of the step (conservation
heating the controlled ``Pi``, the humidistat the saturation pressure at the
controlled ``Ti``), so conservation heating and a dehumidifier act on one room.
:meth:`Measure.simulate` is the previous, independent implementation
(``ControlledModel.forward`` against the other model's free-running series), kept as
the reference the tests compare single controllers with.

Pairing is by construction: a measure is simulated with the same parameter draw, the
same noise realisation (the noise is model error, added to the controlled outputs as to
the free-running ones) and the same weather as doing nothing, in every case (baseline,
scenario × horizon); a measure that changes nothing (``factor: 1``, a dehumidifier of
zero capacity) gives the do-nothing indicators in every draw (to rounding, by test).

Each controlled draw starts from the do-nothing initial state (the steady state of the
first weeks' weather) plus the change of state a year of control makes (periodic
spin-up over the first weather year): a dehumidified room of slow response would
otherwise begin far from its controlled regime, and a controller that never acts
starts exactly where doing nothing does.

The controllers act on the model's state (noise-free): a sensor reading the room. The
hygric model ("model 3" of Kramer et al. [2]_) is in vapour pressure with the outdoor
vapour pressure as its input, so heating changes the RH through the temperature only.

Running cost (:data:`COSTS`), from the control flow of each draw: heating energy
[kWh/a] and peak power [kW]; water removed or added [kg/a], peaks [kg/h] and, with
``energy_per_kg``, the units' electric energy [kWh/a] (``total_energy``: their sum per
draw). A free-running room calibrated on temperatures and RH only identifies time
constants and gains, not the absolute conductances [W/K] (the architecture notes): the
scale of these figures, and so their interval, comes from the priors that pin it (room
volume, air change rate) and the page says so; only measured heating power as an input
of the calibration would fix it from data (an example, the Ørholm store, heated but
logging no power: docs/science/interventions.md, "Ørholm: a thermostat re-simulated
against the log").

References
----------
.. [1] S. Staniforth, "Conservation heating to slow conservation tasks", 2006.
.. [2] R. Kramer, J. van Schijndel, H. Schellen, "Inverse modeling of simplified hygrothermal
   building models to predict and characterize indoor climates", Building and
   Environment 68 (2013) 87-99, doi:10.1016/j.buildenv.2013.06.019.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from heritage_bayes.errors import ConfigError

__all__ = ["COSTS", "Measure", "measures_from_config"]

#: Running-cost columns: name -> (unit, description).
COSTS = {
    "heating_energy": ("kWh/a", "heating energy per year"),
    "heating_peak": ("kW", "peak heating power"),
    "water_removed": ("kg/a", "water removed by the dehumidifier per year"),
    "dehumidifier_peak": ("kg/h", "peak water removal"),
    "dehumidifier_energy": ("kWh/a", "electric energy of the dehumidifier per year"),
    "water_added": ("kg/a", "water added by the humidifier per year"),
    "humidifier_peak": ("kg/h", "peak water addition"),
    "humidifier_energy": ("kWh/a", "electric energy of the humidifier per year"),
    "total_energy": ("kWh/a", "energy per year of all the measure's units (per draw sum)"),
}
#: Energy columns of :data:`COSTS` [kWh/a] (their per-draw sum is ``total_energy``).
ENERGY = ("heating_energy", "dehumidifier_energy", "humidifier_energy")
#: Hours per year of the indicators' complete years.
_HOURS_YEAR = 8760
_NO_FLOOR = -273.15  # [°C] no heating floor


@dataclass(frozen=True)
class Measure:
    """One intervention (see the module docstring), built from
    :class:`heritage_bayes.projection.config.Intervention`.

    Attributes
    ----------
    name : str
    heating : tuple or None
        ``(rh_max [-], t_min [°C], t_max [°C], power_max [W] or inf)``.
    dehumidifier : tuple or None
        ``(rh_max [-], capacity [kg/s], energy_per_kg [kWh/kg] or None)``.
    ventilation : float
        Factor on ``Gfast`` of both models [-].
    thermostat : tuple or None
        ``(t_set [°C], t_use [°C] or None, WeeklyCalendar or None, power_max [W] or
        inf)``: heating to a set-point, ``t_use`` in the calendar's hours of use.
    humidistat : tuple or None
        ``(rh_min [-], rh_max [-], dehumidifier capacity [kg/s], humidifier capacity
        [kg/s], differential [-], dehumidifier energy_per_kg [kWh/kg] or None,
        humidifier energy_per_kg [kWh/kg] or None)``: a humidistat band.
    """

    name: str
    heating: tuple | None = None
    dehumidifier: tuple | None = None
    ventilation: float = 1.0
    thermostat: tuple | None = None
    humidistat: tuple | None = None

    @property
    def controlled(self) -> bool:
        """Simulated with controllers (both models stepped together), not the modal pass."""
        return any(
            x is not None
            for x in (self.heating, self.dehumidifier, self.thermostat, self.humidistat)
        )

    def stepped_together(self, run) -> bool:
        """Both models stepped together with the controllers in the compiled pass; False
        for a hygric model coupled to the temperature (time-varying): a thermostat's
        room is then simulated first and the hygric model on its ``Ti``
        (:meth:`simulate`)."""
        return not getattr(run.models.get("hygric"), "time_varying", False)

    def controller_arrays(self, k: int, modal: dict, run, P: dict) -> tuple:
        """The compiled pass's controllers for ``k`` draws: ``(cp (k, N_CP), bdT (k, nT),
        bdP (k, nP), spin, sources)`` (:func:`heritage_bayes.rc.control_kernels.coupled_draw`;
        ``modal``: section -> modal form of the draws' networks, ``P``: section -> their
        parameters, after :meth:`params`). ``sources``: section -> (constant forcing
        (k, n), steady-state shift (k, n)) of a calibrated constant source ``Qs`` [W] or
        ``Ms`` [kg/s] (``options.source``), added to the modal arrays."""
        from heritage_bayes.rc import control_kernels as rc
        from heritage_bayes.rc.control import ControlledModel

        cp = np.zeros(rc.N_CP)
        cp[rc.CP_P_MAX] = np.inf
        cp[rc.CP_T_MAX] = np.inf
        if self.heating is not None:
            rh, t_min, t_max, pmax = self.heating
            cp[[rc.CP_T_MODE, rc.CP_T_SET, rc.CP_RH_CH, rc.CP_T_MAX, rc.CP_P_MAX]] = (
                3, t_min, rh, t_max, pmax
            )  # fmt: skip
        if self.thermostat is not None:
            t_set, t_use, _, pmax = self.thermostat
            cp[[rc.CP_T_MODE, rc.CP_T_SET, rc.CP_P_MAX]] = 1, t_set, pmax
            cp[rc.CP_T_USE] = 0.0 if t_use is None else t_use - t_set
        if self.dehumidifier is not None:
            rh, cap, _ = self.dehumidifier
            cp[[rc.CP_H_ON, rc.CP_RH_LO, rc.CP_RH_HI, rc.CP_M_DEHUM]] = 1, 0.0, rh, cap
        if self.humidistat is not None:
            lo, hi, cap_d, cap_h, diff = self.humidistat[:5]
            cp[[rc.CP_H_ON, rc.CP_RH_LO, rc.CP_RH_HI, rc.CP_M_DEHUM, rc.CP_M_HUM]] = (
                1, lo, hi, cap_d, cap_h
            )  # fmt: skip
            cp[rc.CP_DIFF] = diff
        bd, sources = {}, {}
        for s, mf in modal.items():
            m = run.models[s]
            air = int(m._ix["out"][0])
            bz = mf.s[:, air, None] * mf.V[:, air, :]
            bd[s] = np.ascontiguousarray(mf.phi * bz)
            if isinstance(m, ControlledModel) and m.control.source:
                names = m.parameter_names
                q = P[s][:, names.index("Qs" if "Qs" in names else "Ms")][:, None]
                lam = np.where(mf.lam > 0, mf.lam, np.inf)
                sources[s] = (q * bd[s], q * bz / lam)
        cps = np.ascontiguousarray(np.broadcast_to(cp, (k, rc.N_CP)))
        return cps, bd["thermal"], bd["hygric"], _HOURS_YEAR, sources

    def hours_of_use(self, index, N: int) -> np.ndarray:
        """Hours of use (N,) of the heating schedule [-] (zeros without one)."""
        cal = self.thermostat[2] if self.thermostat is not None else None
        if cal is None:
            return np.zeros(N)
        if index is None:
            raise ConfigError(
                f"interventions: {self.name!r}: a weekly schedule needs the time of each step"
            )
        return np.ascontiguousarray(cal.fraction(index[:N], 3600.0), dtype=float)

    def costs(self, sums: np.ndarray, dt: float, years: float) -> dict:
        """Running costs (:data:`COSTS` name -> (K,) values) from the compiled pass's
        sums (:data:`heritage_bayes.rc.control_kernels.N_COST` columns) over ``years``."""
        out: dict = {}
        if self.heating is not None or self.thermostat is not None:
            out["heating_energy"] = sums[:, 0] * dt / 3.6e6 / years
            out["heating_peak"] = sums[:, 1] / 1e3
        e_d = e_h = None
        dehum = self.dehumidifier is not None
        hum = False
        if self.dehumidifier is not None:
            e_d = self.dehumidifier[2]
        if self.humidistat is not None:
            dehum, hum = self.humidistat[2] > 0, self.humidistat[3] > 0
            e_d, e_h = self.humidistat[5], self.humidistat[6]
        if dehum:
            out["water_removed"] = sums[:, 2] * dt / years
            out["dehumidifier_peak"] = sums[:, 3] * 3600.0
            if e_d is not None:
                out["dehumidifier_energy"] = out["water_removed"] * e_d
        if hum:
            out["water_added"] = sums[:, 4] * dt / years
            out["humidifier_peak"] = sums[:, 5] * 3600.0
            if e_h is not None:
                out["humidifier_energy"] = out["water_added"] * e_h
        energy = [out[c] for c in ENERGY if c in out]
        if len(energy) > 1:  # quantiles of a sum need the sum of each draw
            out["total_energy"] = np.sum(energy, axis=0)
        return out

    def check(self, run) -> None:
        """Refuse a measure the run's models cannot take (names the measure)."""
        from heritage_bayes.rc.control import ControlledModel

        if self.ventilation != 1.0 and not any(
            "Gfast" in m.parameter_names for m in run.models.values()
        ):
            names = {s: m.name for s, m in run.models.items()}
            raise ConfigError(
                f"interventions: {self.name!r}: ventilation scales the conductance Gfast "
                f"(air exchange), which none of the run's models {names} has"
            )
        heat = self.heating or self.thermostat
        hyg = run.models.get("hygric")
        if not self.stepped_together(run) and (
            self.heating or self.dehumidifier or self.humidistat
        ):
            raise ConfigError(
                f"interventions: {self.name!r}: conservation heating and (de)humidifiers "
                "read the other model's air and are stepped together with it on a "
                f"constant modal form, which the hygric model {hyg.name!r} (coupled to "
                "the temperature) does not have; project this measure with a run "
                "calibrated with hygric_2c, or keep to heating to a set-point and "
                "ventilation measures"
            )
        for s, on in (("thermal", heat), ("hygric", self.dehumidifier or self.humidistat)):
            m = run.models[s]
            if (
                on is not None and isinstance(m, ControlledModel) and set(m.components) - {"source"}
            ):  # a constant source is part of the free-running room
                raise ConfigError(
                    f"interventions: {self.name!r}: the calibrated {s} model is already "
                    f"controlled ({list(m.components)}); a measure adds a controller to a "
                    "free-running model"
                )

    def notes(self, run) -> list[str]:
        """What the measure leaves as calibrated, in words (for the page)."""
        if self.ventilation == 1.0:
            return []
        return [
            f"the {s} model {m.name!r} has no separate air-exchange conductance (Gfast): "
            "its parameters stay as calibrated, so the ventilation change acts on the "
            f"{'vapour pressure' if s == 'hygric' else 'temperature'} of the other model only"
            for s, m in run.models.items()
            if "Gfast" not in m.parameter_names
        ]

    def params(self, run, model: dict) -> dict:
        """Each section's (K, p) parameter array with the measure's change."""
        out = {}
        for s, P in model.items():
            P = np.array(P, dtype=float)
            if self.ventilation != 1.0 and "Gfast" in run.models[s].parameter_names:
                P[:, list(run.models[s].parameter_names).index("Gfast")] *= self.ventilation
            out[s] = P
        return out

    def cost_sums(self, costs: dict, dt: float, years: float) -> np.ndarray:
        """The inverse of :meth:`costs`: (K, N_COST) sums from running costs."""
        from heritage_bayes.rc.control_kernels import N_COST

        k = len(next(iter(costs.values()))) if costs else 0
        out = np.zeros((k, N_COST))
        for col, name, f in (
            (0, "heating_energy", years * 3.6e6 / dt), (1, "heating_peak", 1e3),
            (2, "water_removed", years / dt), (3, "dehumidifier_peak", 1 / 3600.0),
        ):  # fmt: skip
            if name in costs:
                out[:, col] = np.asarray(costs[name]) * f
        return out

    def simulate(self, run, model: dict, U: dict, u0: dict, dt: float, index=None):
        """Noise-free outputs of a chunk of draws with the controllers, through
        ``ControlledModel.forward`` (the reference implementation: each controller
        against the other model's free-running series, no humidistat band). A hygric
        model coupled to the temperature is simulated last, each draw on its own
        controlled ``Ti`` (from the steady state of the run's initial window).

        Parameters
        ----------
        run : heritage_bayes.run.Run
        model : dict
            Section -> (k, p) parameter arrays (after :meth:`params`).
        U : dict
            Section -> (N, m) inputs of the run's models.
        u0 : dict
            Section -> inputs of the initial steady state.
        dt : float
            Step [s].
        index : pandas.DatetimeIndex, optional
            Time of each step (for a thermostat's weekly hours of use).

        Returns
        -------
        Y : dict
            Section -> (k, N) ``Ti`` [°C] and ``Pi`` [Pa].
        costs : dict
            :data:`COSTS` name -> (k,) values of the measure's controllers.
        """
        from heritage_bayes.projection._modal import hygric_on
        from heritage_bayes.projection.weather import coupled_columns
        from heritage_bayes.rc.control import Control, ControlledModel

        if self.humidistat is not None or any(
            isinstance(m, ControlledModel) for m in run.models.values()
        ):
            raise ValueError(
                f"interventions: {self.name!r}: the reference path has no humidistat band "
                "(hysteresis) and takes free-running networks only; it is simulated by "
                "the compiled pass"
            )
        sim = coupled_columns(run, "hygric")  # a hygric model on the simulated Ti: last
        Y = {
            s: np.ascontiguousarray(m.forward(model[s], U[s], dt, u_init=u0[s])[0][..., 0])
            for s, m in run.models.items()
            if not (s == "hygric" and sim)
        }
        k, N = Y["thermal"].shape
        years = N / _HOURS_YEAR
        spin = min(N, _HOURS_YEAR)  # periodic spin-up over the first year
        costs: dict = {}
        if self.heating is not None:
            rh, t_min, t_max, pmax = self.heating
            m = run.models["thermal"]
            limited = bool(np.isfinite(pmax))  # unlimited: the ideal controller (no Pmax)
            ctl = ControlledModel(
                m.network,
                Control(thermostat=True, conservation=True, power_limit=limited, t_max=t_max),
            )
            extra = {"Tset": t_min, "Pmax": pmax, "RH_ch": rh}
            Y["thermal"], Q = self._coupled(ctl, model["thermal"], U["thermal"], Y["hygric"],
                                             u0["thermal"], extra, dt, spin)  # fmt: skip
            costs.update(_heating_costs(Q, dt, years))
        if self.thermostat is not None:
            Y["thermal"], Q = self._thermostat(run, model["thermal"], U["thermal"],
                                               u0["thermal"], dt, spin, index)  # fmt: skip
            costs.update(_heating_costs(Q, dt, years))
        if sim:
            from heritage_bayes.projection.cases import init_window

            w = init_window(run)
            Y["hygric"] = hygric_on(run, model["hygric"], U["hygric"], Y["thermal"], dt, w)
        if self.dehumidifier is not None:
            rh, cap, e_kg = self.dehumidifier
            m = run.models["hygric"]
            ctl = ControlledModel(m.network, Control(humidistat="dehumidifier", capacity=True))
            extra = {"RH_hi": rh, "M_dehum": cap}
            Y["hygric"], Q = self._coupled(ctl, model["hygric"], U["hygric"], Y["thermal"],
                                            u0["hygric"], extra, dt, spin)  # fmt: skip
            w = np.clip(-Q, 0.0, None)  # [kg/s]
            costs["water_removed"] = w.sum(axis=1) * dt / years
            costs["dehumidifier_peak"] = w.max(axis=1) * 3600.0
            if e_kg is not None:
                costs["dehumidifier_energy"] = costs["water_removed"] * e_kg
        return Y, costs

    def _thermostat(self, run, P, U, u0, dt, spin, index) -> tuple:
        """Thermostat outputs and heating flows (k, N), all draws at once (the
        controller needs no other model's series)."""
        from heritage_bayes.rc.control import HOURS_OF_USE, Control, ControlledModel

        t_set, t_use, cal, pmax = self.thermostat
        limited = bool(np.isfinite(pmax))
        ctl = ControlledModel(
            run.models["thermal"].network,
            Control(thermostat=True, power_limit=limited,
                    schedule=HOURS_OF_USE if cal is not None else None, calendar=cal),
        )  # fmt: skip
        extra = {"Tset": t_set, "Tset_use": t_use, "Pmax": pmax}
        Pc = _extended(ctl, P, extra)
        if cal is not None:
            if index is None:
                raise ConfigError(
                    f"interventions: {self.name!r}: a weekly schedule needs the time of each step"
                )
            use = cal.fraction(index, dt)
            U, u0 = np.column_stack([U, use]), np.r_[u0, use[:1]]
        y, ok, Q = ctl.forward(Pc, U, dt, u_init=u0, effort=True, spin_up=spin)
        _check_valid(ok, self.name, Pc)
        return np.ascontiguousarray(y[..., 0]), Q

    def _coupled(self, ctl, P, U, other, u0, extra, dt, spin) -> tuple:
        """Controlled outputs (k, N) and control flows (k, N) of ``ctl``, all draws at
        once: each draw's control input (``Pi`` for conservation heating, ``Ti`` for
        the humidistat) is its own simulated series ``other[p]``."""
        Pc = _extended(ctl, P, extra)
        u = np.r_[u0, np.mean(other[:, :1])]  # only the network's part is used
        y, ok, Q = ctl.forward(
            Pc, U, dt, u_init=u, effort=True, spin_up=spin, control_inputs=other[:, :, None]
        )
        _check_valid(ok, self.name, Pc)
        Y = np.ascontiguousarray(y[..., 0])
        return Y, Q


def _heating_costs(Q: np.ndarray, dt: float, years: float) -> dict:
    """Heating energy [kWh/a] and peak power [kW] from heating flows (k, N) [W]."""
    e = np.clip(Q, 0.0, None)
    return {"heating_energy": e.sum(axis=1) * dt / 3.6e6 / years,
            "heating_peak": e.max(axis=1) / 1e3}  # fmt: skip


def _check_valid(ok: np.ndarray, name: str, P: np.ndarray) -> None:
    if not bool(np.all(ok)):
        raise ConfigError(
            f"interventions: {name!r}: the controlled model is not valid for a posterior "
            f"draw (parameters {P[0].tolist()}); check the measure's values"
        )


def _extended(ctl, P: np.ndarray, extra: dict) -> np.ndarray:
    """The network's parameters followed by the control's, in ``ctl``'s order."""
    n = P.shape[1]
    names = ctl.parameter_names[n:]
    return np.column_stack([P, *[np.full((P.shape[0], 1), extra[x]) for x in names]])


def measures_from_config(pcfg) -> list[Measure]:
    """The :class:`Measure` of every ``interventions`` entry (units to SI: RH [%] to
    [-], capacity [kg/h] to [kg/s])."""
    out = []
    for it in pcfg.interventions:
        h = it.conservation_heating
        d = it.dehumidification
        out.append(
            Measure(
                name=it.name,
                heating=None
                if h is None
                else (
                    h.rh_max / 100.0,
                    _NO_FLOOR if h.t_min is None else h.t_min,
                    h.t_max,
                    np.inf if h.power_max is None else h.power_max,
                ),
                dehumidifier=None
                if d is None
                else (d.rh_max / 100.0, d.capacity / 3600.0, d.energy_per_kg),
                ventilation=1.0 if it.ventilation is None else it.ventilation.factor,
                thermostat=None if it.heating is None else _thermostat_spec(it.heating),
                humidistat=None if it.humidistat_band is None else _band_spec(it.humidistat_band),
            )
        )
    return out


def _band_spec(b) -> tuple:
    """A humidistat band in SI: RH [-], capacities [kg/s], differential [-]."""
    return (
        b.rh_min / 100.0, b.rh_max / 100.0, b.dehumidifier_capacity / 3600.0,
        b.humidifier_capacity / 3600.0, b.differential / 100.0,
        b.dehumidifier_energy_per_kg, b.humidifier_energy_per_kg,
    )  # fmt: skip


def _thermostat_spec(h) -> tuple:
    from heritage_bayes.rc.calendar import parse_weekly

    cal = None
    if h.weekly is not None:
        cal = parse_weekly({"weekly": h.weekly, "timezone": h.timezone}, "heating")
    pmax = np.inf if h.power_max is None else h.power_max
    return (h.t_set, h.t_use, cal, pmax)


def _q(x: np.ndarray) -> dict:
    from heritage_bayes.projection.summary import _q as q

    return q(np.asarray(x, dtype=float))


def compare_measures(labels, nothing, per_measure: dict, thresholds, units, notes=None) -> dict:
    """The JSON-ready comparison of every measure with doing nothing.

    Parameters
    ----------
    labels : list of str
        Case labels (the baseline first).
    nothing : list of CaseResult
        Doing nothing, per case.
    per_measure : dict
        Measure name -> list of CaseResult (per case, same draws, noise and weather).
    thresholds : list of Threshold
        The projection's probability statements.
    units : dict
        Indicator -> unit.
    notes : dict, optional
        Measure name -> list of sentences (:meth:`Measure.notes`).

    Returns
    -------
    dict
        Measure name -> ``{"cases": {label: {"indicators": {name: change},
        "probabilities": [...], "costs": {name: quantiles}}}}``. A change is the paired
        difference measure − nothing (quantiles 5/50/95 % and mean over the draws, the
        indicator's own quantiles with the measure in ``with_measure``) with
        ``p_better``: the share of draws in which the measure is strictly better (the
        registry's direction of ``worse``; None for an indicator without one).
        Probabilities: P(statement) with the measure and without, per threshold.
    """
    from heritage_bayes.climate.risk.registry import indicator_info
    from heritage_bayes.projection.summary import numeric_columns

    out: dict = {}
    for name, results in per_measure.items():
        cases = {}
        for lab, r0, r in zip(labels, nothing, results, strict=True):
            inds = {}
            for n in numeric_columns(r0.predictive):
                info = indicator_info(n)
                d = r.predictive[n].to_numpy(float) - r0.predictive[n].to_numpy(float)
                ok = np.isfinite(d)
                e = _q(d) | {"name": info.name, "unit": units.get(n, info.unit)}
                e["with_measure"] = _q(r.predictive[n].to_numpy(float))
                e["p_better"] = float(np.mean(info.worse * d[ok] < 0)) if info.worse else None
                inds[n] = e
            probs = []
            for t in thresholds:
                op, val = (">", t.above) if t.above is not None else ("<", t.below)

                def p(df, t=t, op=op, val=val):
                    v = df[t.indicator].to_numpy(float)
                    return float(np.mean(v > val) if op == ">" else np.mean(v < val))

                probs.append(
                    {"indicator": t.indicator, "op": op, "value": val,
                     "p_measure": p(r.predictive), "p_nothing": p(r0.predictive)}
                )  # fmt: skip
            costs = {}
            if r.costs is not None:
                for c in r.costs.columns:
                    unit, desc = COSTS[c]
                    costs[c] = _q(r.costs[c].to_numpy(float)) | {"unit": unit, "name": desc}
            cases[lab] = {"indicators": inds, "probabilities": probs, "costs": costs}
        out[name] = {"cases": cases, "notes": list((notes or {}).get(name, []))}
    return out
