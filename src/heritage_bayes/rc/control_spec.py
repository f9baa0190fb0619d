"""What controls the air node of a room: the typed options of a thermostat, a
humidistat and a constant source (:class:`Control`), as the settings layer builds them
and :class:`heritage_bayes.rc.control.ControlledModel` compiles them.

A description only (no numerics), so that the settings can build it without loading
the compiled kernels.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

from heritage_bayes.names import CONTROLS, HUMIDISTAT_MODES
from heritage_bayes.rc.calendar import WeeklyCalendar

__all__ = ["COMPONENTS", "HOURS_OF_USE", "HUMIDISTAT_MODES", "Control"]

#: Input column generated from a weekly calendar (``thermostat.schedule.weekly``) [-].
HOURS_OF_USE = "hours_of_use"

#: Control components, the domain they belong to.
COMPONENTS = CONTROLS


@dataclass(frozen=True)
class Control:
    """What controls the air node of a :class:`ControlledModel` (see module docstring).

    Attributes
    ----------
    thermostat : bool
    power_limit : bool
        Estimated maximum heating power ``Pmax`` [W]; otherwise ideal.
    schedule : str or None
        Input column of the hours of use (1 in use, 0 not) for ``Tset_use``.
    calendar : WeeklyCalendar or None
        The weekly calendar that generates the schedule column :data:`HOURS_OF_USE`.
    conservation : bool
        Conservation heating: the set-point also keeps RH <= ``RH_ch`` (input ``Pi``).
    t_max : float
        Upper limit [°C] of the conservation-heating set-point (default none).
    humidistat : str or None
        One of ``band``, ``dehumidifier``, ``humidifier``, ``setpoint``.
    capacity : bool
        Estimated humidistat capacities ``M_dehum``, ``M_hum`` [kg/s]; otherwise ideal.
    source : bool
        Constant flow into the air node (``Qs`` [W] or ``Ms`` [kg/s]).
    enabled : frozenset of str
        Components that act in simulations (all configured ones by default).
    """

    thermostat: bool = False
    power_limit: bool = False
    schedule: str | None = None
    calendar: WeeklyCalendar | None = None
    conservation: bool = False
    humidistat: str | None = None
    capacity: bool = False
    source: bool = False
    enabled: frozenset = frozenset(COMPONENTS)
    #: Conservation heating never raises the air above this temperature [°C] (the
    #: upper limit of an intervention: a conservation-heating set-point is capped at
    #: it, the RH limit then yields); not a parameter, so calibrated draws still apply.
    t_max: float = math.inf

    def __post_init__(self):
        if self.humidistat is not None and self.humidistat not in HUMIDISTAT_MODES:
            raise ValueError(
                f"Control.humidistat: expected one of {list(HUMIDISTAT_MODES)} or None "
                f"(got {self.humidistat!r})"
            )
        if self.calendar is not None and self.schedule is None:
            raise ValueError("Control.calendar: a weekly calendar needs its schedule column")

    @property
    def active(self) -> bool:
        return self.thermostat or self.humidistat is not None or self.source

    @property
    def components(self) -> tuple[str, ...]:
        """Configured components (``thermostat``, ``humidistat``, ``source``)."""
        on = {"thermostat": self.thermostat, "humidistat": self.humidistat is not None}
        return tuple(k for k in COMPONENTS if on.get(k, self.source))
