"""The parts of a run summary beyond the estimates: each model's chain and MAP
findings, the periods, the data's alignment and the report's verdict.

Typed from ``summary.json`` by :class:`heritage_bayes.rundir.summary.RunSummary` (every
key a version lacks reads as absent); see that module for the whole.
"""

from __future__ import annotations

import math
from dataclasses import asdict, dataclass, field
from types import MappingProxyType
from typing import Any

from heritage_bayes.format import fmt_int

__all__ = [
    "STATUSES",
    "Alignment",
    "Continuation",
    "DecoupledWall",
    "FrozenNode",
    "Gap",
    "Identifiability",
    "ModelInfo",
    "NullDirection",
    "Period",
    "PredictiveNoise",
    "Saturation",
    "SourceNote",
    "Verdict",
    "finite_float",
]


def finite_float(v) -> float | None:
    """A finite float, or None (absent, null, NaN, not a number)."""
    if isinstance(v, bool) or v is None:
        return None
    try:
        f = float(v)
    except (TypeError, ValueError):
        return None
    return f if math.isfinite(f) else None


def duration_words(seconds: float) -> str:
    """``6 min 12 s``, ``45 s``, ``1 h 5 min``: a duration [s] in words, to the second
    (to the minute from an hour)."""
    n = max(0, round(seconds))
    if n < 60:
        return f"{n} s"
    if n < 3600:
        m, sec = divmod(n, 60)
        return f"{m} min" + (f" {sec} s" if sec else "")
    h, m = divmod(round(n / 60), 60)
    return f"{h} h" + (f" {m} min" if m else "")


@dataclass(frozen=True)
class Continuation:
    """A chain the time budget stopped, continued after every section had sampled with
    the time the later sections left (``models.<section>.chain.continued`` of
    ``summary.json``, see :mod:`heritage_bayes.calibration.chains`): the steps it had
    (``from_steps``), the seconds it was given (``seconds_given`` [s]) and the sections
    that left them (``left_by``)."""

    from_steps: int
    seconds_given: float
    left_by: tuple[str, ...] = ()

    @classmethod
    def from_dict(cls, d) -> Continuation | None:
        """The continuation of a chain record's ``continued`` (None: not continued)."""
        if not isinstance(d, dict) or not isinstance(d.get("from_steps"), int):
            return None
        return cls(
            from_steps=int(d["from_steps"]),
            seconds_given=finite_float(d.get("seconds_given")) or 0.0,
            left_by=tuple(str(n) for n in d.get("left_by") or ()),
        )

    @property
    def words(self) -> str:
        """``continued from 15 000 steps with the 6 min 12 s the hygric section left``."""
        steps = fmt_int(self.from_steps)
        by = " and ".join(self.left_by)
        by = f"the {by} section{'s' if len(self.left_by) > 1 else ''} left" if by else "left"
        return f"continued from {steps} steps with the {duration_words(self.seconds_given)} {by}"


@dataclass(frozen=True)
class NullDirection:
    """A combination of parameters the data cannot determine: its ``label``, its
    ``description`` in words, the parameters whose prior or value pins it
    (``pinned_by``) and whether it is the overall scale (``is_scale``)."""

    label: str = ""
    description: str = ""
    pinned_by: tuple[str, ...] = ()
    is_scale: bool = False


@dataclass(frozen=True)
class Identifiability:
    """A model's structural identifiability at the MAP (what ``summary.json`` records):
    the rank of the output sensitivities, the non-identifiable combinations
    (``null_directions``, each with its ``label``, ``description``, ``pinned_by`` and
    ``is_scale``), and per parameter whether the data identify it
    (``identifiable``) or only once the scale is pinned (``identifiable_given_scale``)."""

    n_null: int = 0
    n_params: int | None = None
    rank: int | None = None
    has_scale_direction: bool | None = None
    condition_number_identifiable: float | None = None
    identifiable: frozenset = frozenset()
    identifiable_given_scale: frozenset = frozenset()
    parameters: tuple[str, ...] = ()  # the parameters the analysis covered
    null_directions: tuple[NullDirection, ...] = ()
    control: MappingProxyType = field(default_factory=lambda: MappingProxyType({}))
    summary: str = ""
    #: whether the run recorded the analysis (runs before it did not)
    recorded: bool = False

    @classmethod
    def from_dict(cls, d: dict | None) -> Identifiability:
        recorded = bool(d)
        d = d or {}
        pars = d.get("parameters") or {}
        has_scale = d.get("has_scale_direction")
        return cls(
            n_null=int(d.get("n_null") or 0),
            n_params=d.get("n_params"),
            rank=d.get("rank"),
            has_scale_direction=None if has_scale is None else bool(has_scale),
            condition_number_identifiable=finite_float(d.get("condition_number_identifiable")),
            identifiable=frozenset(n for n, v in pars.items() if v.get("identifiable")),
            identifiable_given_scale=frozenset(
                n for n, v in pars.items() if v.get("identifiable_given_scale")
            ),
            parameters=tuple(pars),
            null_directions=tuple(
                NullDirection(
                    label=str(n.get("label", "")),
                    description=str(n.get("description", "")),
                    pinned_by=tuple(str(p) for p in n.get("pinned_by") or ()),
                    is_scale=bool(n.get("is_scale")),
                )
                for n in d.get("null_directions") or []
            ),
            control=MappingProxyType(dict(d.get("control") or {})),
            summary=str(d.get("summary") or ""),
            recorded=recorded,
        )

    def on_scale(self, name: str) -> bool:
        """Identifiable only once the scale is pinned (the priors pin it)."""
        return name not in self.identifiable and name in self.identifiable_given_scale


@dataclass(frozen=True)
class DecoupledWall:
    """A buffer link ``hbayes calibrate`` fixed at the MAP
    (:func:`heritage_bayes.calibration.wall.decoupled_wall`): ``parameter`` (the link, e.g. ``Gw``)
    fixed at ``floor`` [its unit], its MAP value ``map_value``, the buffer's exchange
    time through it at the MAP ``exchange_h`` [h] and in calibration ``records`` [-],
    and ``delta_log_posterior`` [nats], the log-posterior at the floor minus the
    MAP's."""

    parameter: str
    capacity: str
    floor: float
    map_value: float
    exchange_h: float
    records: float
    delta_log_posterior: float

    def to_dict(self) -> dict:
        """``summary.json``'s ``models.<section>.decoupled_wall``."""
        return asdict(self)

    @classmethod
    def from_dict(cls, d: dict | None) -> DecoupledWall | None:
        """The finding from :meth:`to_dict`'s mapping (None: none)."""
        if not d:
            return None
        return cls(**{f: d[f] for f in cls.__dataclass_fields__})

    def text(self, section: str) -> str:
        """The run's note (the command line, the report)."""
        p = self.parameter
        return (
            f"[{section}] {p} fixed at its prior's floor {self.floor:.3g} for the sampler: "
            f"at the MAP ({p} {self.map_value:.3g}) the buffer's exchange time through it, "
            f"{self.capacity}/{p}, is {self.records:.3g} calibration records "
            f"({self.exchange_h:.3g} h), and the log-posterior with {p} at the floor is "
            f"{self.delta_log_posterior:+.2g} nats from the MAP's: the buffer does not "
            "exchange with the outdoors in these data, a flat direction the noise model's "
            f"filter would leave the chain to wander along. Set {section}.priors.{p} to "
            "keep it free"
        )


@dataclass(frozen=True)
class FrozenNode:
    """A node that barely moves over the record at the MAP: its slowest time constant
    ``tau_h`` [h], ``records`` times the calibration record; ``start_free``: its start
    is estimated freely (a free offset)."""

    tau_h: float
    records: float
    start_free: bool = False


@dataclass(frozen=True)
class PredictiveNoise:
    """The free-run error the predictive bands use when the noise model's own does not
    describe a free run: AR(1) of sd ``sigma`` with hourly coefficient ``phi`` [-] plus
    white noise of sd ``sigma_meas`` [unit of the output]."""

    sigma: float
    phi: float
    sigma_meas: float


@dataclass(frozen=True)
class Saturation:
    """How often predicted vapour pressure was limited to saturation at the predicted
    indoor temperature (``temperature``: which one): shares [-] of the predictive
    samples and of the hours of the noise-free median."""

    temperature: str
    share_predictive_samples: float
    share_hours_median_saturated: float


@dataclass(frozen=True)
class ModelInfo:
    """One section (``thermal``/``hygric``) of a run: its model, chain and MAP findings."""

    section: str
    model: str
    noise: str = ""
    domain: str = ""
    steps: int | None = None
    walkers: int | None = None
    tau_max: float | None = None
    converged_tau: bool = False
    likelihood_temperature: float = 1.0
    burn: int | None = None
    thin: int | None = None
    draws_per_walker: int | None = None
    acceptance_mean: float | None = None
    resumed_from: int | None = None
    stopped_by: str = ""
    #: the chain continued with the time later sections left (None: not continued)
    continued: Continuation | None = None
    tau_history: tuple[tuple[float, ...], ...] = ()
    output_names: tuple[str, ...] = ()
    input_names: tuple[str, ...] | None = None  # None: not recorded (older runs)
    state_names: tuple[str, ...] = ()
    #: the sampled parameters, in the order of the chain and the correlation matrix
    free_names: tuple[str, ...] = ()
    #: the posterior correlations of the sampled parameters (in the sampler's coordinates)
    correlation: tuple[tuple[float, ...], ...] = ()
    #: output -> the free-run error of its predictive bands (where the noise model's is not)
    predictive_noise: MappingProxyType = field(default_factory=lambda: MappingProxyType({}))
    saturation: Saturation | None = None
    map_at_bound: tuple[tuple[str, str], ...] = ()
    #: the MAP search: log-posterior at the MAP, starts that agreed of those made, method
    map_log_posterior: float | None = None
    map_agreed: Any = "?"
    map_starts: Any = "?"
    map_method: Any = "?"
    map_modes: tuple[MappingProxyType, ...] = ()
    map_restarts: int | None = None
    #: [h] the cap on the time constants (None: none)
    time_constant_cap_h: float | None = None
    frozen_node: FrozenNode | None = None
    frozen_share: float | None = None
    #: a buffer link fixed at its prior's floor for the sampler (None: none)
    decoupled_wall: DecoupledWall | None = None
    #: parameters the data leave almost as uncertain as their priors (Laplace at the MAP)
    unidentified: tuple[str, ...] = ()
    identifiability: Identifiability = field(default_factory=Identifiability)

    @classmethod
    def from_dict(cls, sec: str, info: dict, correlations: dict | None = None) -> ModelInfo:
        """``models.<sec>`` of ``summary.json``, with ``correlations.<sec>`` (the
        sampled parameters' names and correlation matrix)."""
        corr = correlations or {}
        ch = info.get("chain") or {}
        fz = info.get("frozen_node")
        found = info.get("map") or {}
        pred = info.get("predictive_noise") or {}
        sat = info.get("saturation")
        names = info.get("input_names")
        return cls(
            section=sec,
            model=str(info.get("model") or sec),
            noise=str(info.get("noise") or ""),
            domain=str(info.get("domain") or sec),
            steps=ch.get("steps"),
            walkers=ch.get("walkers"),
            tau_max=finite_float(ch.get("tau_max")),
            converged_tau=bool(ch.get("converged_tau", False)),
            likelihood_temperature=finite_float(info.get("likelihood_temperature")) or 1.0,
            burn=ch.get("burn"),
            thin=ch.get("thin"),
            draws_per_walker=ch.get("draws_per_walker"),
            acceptance_mean=finite_float(ch.get("acceptance_mean")),
            resumed_from=ch.get("resumed_from"),
            stopped_by=str(ch.get("stopped_by") or ""),
            continued=Continuation.from_dict(ch.get("continued")),
            tau_history=tuple(
                tuple(math.nan if v is None else float(v) for v in r)
                for r in ch.get("tau_history") or []
            ),
            output_names=tuple(info.get("output_names") or ()),
            input_names=None if names is None else tuple(names),
            state_names=tuple(info.get("state_names") or ()),
            free_names=tuple(corr.get("names") or ()),
            correlation=tuple(
                tuple(math.nan if v is None else float(v) for v in row)
                for row in corr.get("matrix") or ()
            ),
            predictive_noise=MappingProxyType(
                {
                    o: PredictiveNoise(float(v["sigma"]), float(v["phi"]), float(v["sigma_meas"]))
                    for o, v in pred.items()
                    if v
                }
            ),
            saturation=None
            if not sat
            else Saturation(
                temperature=str(sat["temperature"]),
                share_predictive_samples=float(sat["share_predictive_samples"]),
                share_hours_median_saturated=float(sat["share_hours_median_saturated"]),
            ),
            map_at_bound=tuple((str(n), str(side)) for n, side in info.get("map_at_bound") or []),
            map_log_posterior=finite_float(found.get("log_posterior")),
            map_agreed=found.get("agreed", "?"),
            map_starts=found.get("starts", "?"),
            map_method=found.get("method", "?"),
            time_constant_cap_h=finite_float(info.get("time_constant_cap_h")),
            map_modes=tuple(MappingProxyType(dict(m)) for m in found.get("modes") or []),
            map_restarts=found.get("restarts"),
            frozen_node=None
            if not fz
            else FrozenNode(
                tau_h=float(fz["tau_h"]),
                records=float(fz["records"]),
                start_free=bool(fz.get("start_free")),
            ),
            frozen_share=finite_float(info.get("frozen_share")),
            decoupled_wall=DecoupledWall.from_dict(info.get("decoupled_wall")),
            unidentified=tuple(
                (info.get("practical_identifiability") or {}).get("unidentified") or ()
            ),
            identifiability=Identifiability.from_dict(info.get("identifiability")),
        )


@dataclass(frozen=True)
class Period:
    """A period of the run: ``calibration``, ``validation``; ``steps`` of ``dt``."""

    name: str
    start: str | None
    end: str | None
    steps: int = 0

    def to_dict(self) -> dict[str, Any]:
        """The period as ``summary.json``'s ``periods`` holds it."""
        return {"start": self.start, "end": self.end, "steps": self.steps}


#: A room's status as its verdict gives it, most urgent first.
STATUSES = ("not converged", "checks failed", "converged")


@dataclass(frozen=True)
class Verdict:
    """The report's verdict on the run, recorded when the report is written (the page
    and ``summary.json`` hold the one verdict computed then).

    ``level``: ``green``, ``amber`` or ``red``; ``status``: one of :data:`STATUSES`
    (*converged*: green; *checks failed*: the sampler converged but the residual,
    coverage, truth or accuracy checks fail; else *not converged*); ``title`` the
    headline, ``text`` its explanation, ``reasons`` one line per model and failed check,
    ``advice`` what to do.
    """

    level: str
    status: str
    title: str
    text: str = ""
    reasons: tuple[str, ...] = ()
    advice: str = ""

    def to_dict(self) -> dict[str, Any]:
        return {
            "level": self.level,
            "status": self.status,
            "title": self.title,
            "text": self.text,
            "reasons": list(self.reasons),
            "advice": self.advice,
        }

    @classmethod
    def from_dict(cls, d) -> Verdict | None:
        if not isinstance(d, dict) or d.get("status") not in STATUSES:
            return None
        return cls(
            level=str(d.get("level") or ""),
            status=str(d["status"]),
            title=str(d.get("title") or ""),
            text=str(d.get("text") or ""),
            reasons=tuple(str(r) for r in d.get("reasons") or ()),
            advice=str(d.get("advice") or ""),
        )


@dataclass(frozen=True)
class Gap:
    """A gap in one column of the aligned data: ``start``/``end`` (ISO times, UTC),
    ``length`` (pandas' words, ``7D``) and ``length_hours`` [h], ``n_missing`` rows;
    ``filled``: bridged by interpolation (an input gap short enough), None if not
    recorded."""

    column: str
    start: str | None
    end: str | None
    length: str = "?"
    length_hours: float = 0.0
    n_missing: int | None = None
    filled: bool | None = None

    @classmethod
    def from_dict(cls, g: dict) -> Gap:
        filled = g.get("filled")
        return cls(
            column=str(g.get("column", "?")),
            start=g.get("start"),
            end=g.get("end"),
            length=str(g.get("length", "?")),
            length_hours=float(g.get("length_hours") or 0),
            n_missing=g.get("n_missing"),
            filled=None if filled is None else bool(filled),
        )


@dataclass(frozen=True)
class SourceNote:
    """One file read for the run (``role``: weather, measurements): its columns, those
    averaged to the step, and the clock it was read in."""

    role: str
    source: str
    columns: tuple[str, ...] = ()
    averaged: tuple[str, ...] = ()
    timezone: str = ""


@dataclass(frozen=True)
class Alignment:
    """What aligning the records on the run's grid did: the grid (``step``, ``start``,
    ``end``, ``n_rows``), rows read and dropped per role, input values interpolated
    and rows flagged per column (gaps up to ``max_gap``), the input and measurement
    gaps, the measurements missing per column and the files read."""

    step: str = "?"
    start: str | None = None
    end: str | None = None
    n_rows: int | None = None
    max_gap: str = "?"
    rows_in: MappingProxyType = field(default_factory=lambda: MappingProxyType({}))
    rows_dropped: MappingProxyType = field(default_factory=lambda: MappingProxyType({}))
    interpolated: MappingProxyType = field(default_factory=lambda: MappingProxyType({}))
    flagged_rows: MappingProxyType = field(default_factory=lambda: MappingProxyType({}))
    measurement_missing: MappingProxyType = field(default_factory=lambda: MappingProxyType({}))
    input_gaps: tuple[Gap, ...] = ()
    measurement_gaps: tuple[Gap, ...] = ()
    sources: tuple[SourceNote, ...] = ()

    @classmethod
    def from_dict(cls, al: dict | None) -> Alignment:
        al = al or {}
        period = al.get("period") or {}

        def counts(key: str) -> MappingProxyType:
            return MappingProxyType(dict(al.get(key) or {}))

        return cls(
            step=str(period.get("step", "?")),
            start=period.get("start"),
            end=period.get("end"),
            n_rows=period.get("n_rows"),
            max_gap=str(al.get("max_gap", "?")),
            rows_in=counts("rows_in"),
            rows_dropped=counts("rows_dropped"),
            interpolated=counts("interpolated"),
            flagged_rows=counts("flagged_rows"),
            measurement_missing=counts("measurement_missing"),
            input_gaps=tuple(Gap.from_dict(g) for g in al.get("input_gaps") or []),
            measurement_gaps=tuple(Gap.from_dict(g) for g in al.get("measurement_gaps") or []),
            sources=tuple(
                SourceNote(
                    role=str(s.get("role", "")),
                    source=str(s.get("source", "")),
                    columns=tuple(str(c) for c in s.get("columns") or []),
                    averaged=tuple(str(c) for c in s.get("averaged") or []),
                    timezone=str(s.get("timezone", "") or ""),
                )
                for s in al.get("sources") or []
            ),
        )
