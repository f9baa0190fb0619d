"""The parts of a run summary that say how its models were chosen and what produced it:
the model-order ladder, the screen of ``model: auto`` and the config's provenance.

Typed from ``summary.json`` by :class:`heritage_bayes.rundir.summary.RunSummary` (every
key a version lacks reads as absent, ``summary.json`` itself is written as it was):

- ``ladder``: section -> the rungs of the model-order ladder, each a :class:`LadderRow`
  (the MAP fit of one model: FIT, MSE, MAE per output and period, information criteria,
  structural identifiability at the MAP);
- ``selection``: section -> :class:`Selection`, the screen of ``model: auto`` (its
  rows, the scores compared, the model chosen and why, the rule, the tie);
- ``provenance``: :class:`Provenance`, the config snapshot that produced the posterior
  and its SHA-256.

The fit criteria are those of the paper: FIT [%], MSE, MAE of the simulation from the
MAP (Kramer, van Schijndel & Schellen 2013, Building and Environment 68, 87-99).
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass, field
from numbers import Integral
from types import MappingProxyType
from typing import Any

from heritage_bayes.rundir.summary_parts import finite_float

__all__ = [
    "LadderRow",
    "MapGuard",
    "Provenance",
    "RungFit",
    "Selection",
    "ladder_of",
    "selection_of",
]

#: The fit criteria a ladder row's period holds when it is not keyed by output (the
#: rows of hbayes before the ladder named its outputs).
_CRITERIA = ("FIT", "MSE", "MAE")


def _int(v) -> int | None:
    """An integer count, or None (absent, null, not an integer)."""
    return int(v) if isinstance(v, Integral) and not isinstance(v, bool) else None


def _text(v) -> str | None:
    return None if v is None else str(v)


@dataclass(frozen=True)
class RungFit:
    """Fit of a rung's MAP simulation to one output over one period: ``FIT`` [%]
    (100 (1 - |y - ŷ| / |y - ȳ|)), ``MSE`` [unit²], ``MAE`` [unit], ``SD`` [unit] of
    the measurements, over ``n`` hours."""

    FIT: float | None = None
    MSE: float | None = None
    MAE: float | None = None
    SD: float | None = None
    n: int | None = None

    @classmethod
    def from_dict(cls, d: Mapping) -> RungFit:
        return cls(
            FIT=finite_float(d.get("FIT")),
            MSE=finite_float(d.get("MSE")),
            MAE=finite_float(d.get("MAE")),
            SD=finite_float(d.get("SD")),
            n=_int(d.get("n")),
        )


@dataclass(frozen=True)
class MapGuard:
    """The restart guard of a rung's MAP search, where it ran: the ``spread`` of the
    first search's polished starts [log-posterior units], the ``log_posteriors`` of the
    searches (the first first), whether the MAP kept is another search's (``moved``),
    and ``said``, a sentence."""

    spread: float | None = None
    log_posteriors: tuple[float, ...] = ()
    moved: bool = False
    said: str = ""

    @classmethod
    def from_dict(cls, d) -> MapGuard | None:
        if not isinstance(d, Mapping):
            return None
        return cls(
            spread=finite_float(d.get("spread")),
            log_posteriors=tuple(float(v) for v in d.get("log_posteriors") or ()),
            moved=bool(d.get("moved")),
            said=str(d.get("said") or ""),
        )


@dataclass(frozen=True)
class LadderRow:
    """One rung of the model-order ladder: its model (``model``, a label such as
    ``hygric_2c_fixed (sink: temperature)``), ``n_params`` free parameters of which
    ``n_model_params`` the model's (the rest the noise model's), ``fit``: period ->
    output -> :class:`RungFit` (output ``""``: a row that did not name its output),
    log-likelihood, AIC and BIC at the MAP, the structural rank, the non-identifiable
    directions and the condition number of the identifiable part at the MAP, and the
    MAP search's agreement (``"3/4"``: starts that agreed of those made).

    ``sampled``: the run sampled this model; ``error``: why a rung was not fitted (the
    time budget, an option it does not take). The screen of ``model: auto`` adds its
    ``parent`` (the nested simpler rung), ``seeded_from`` (its MAP started the search),
    ``map_seconds``, ``score`` (the FIT compared), ``chosen`` and the ``map_guard``.
    """

    model: str = "?"
    n_params: int | None = None
    n_model_params: int | None = None
    fit: MappingProxyType = field(default_factory=lambda: MappingProxyType({}))
    log_likelihood: float | None = None
    aic: float | None = None
    bic: float | None = None
    rank: int | None = None
    n_null: int | None = None
    null_directions: tuple[str, ...] = ()
    condition_number_identifiable: float | None = None
    map_agreed: str | None = None
    sampled: bool = False
    error: str | None = None
    parent: str | None = None
    seeded_from: str | None = None
    map_seconds: float | None = None
    score: float | None = None
    chosen: bool = False
    map_guard: MapGuard | None = None

    def fits(self, period: str) -> MappingProxyType:
        """output -> :class:`RungFit` over ``period`` (empty: not fitted there)."""
        return self.fit.get(period) or MappingProxyType({})

    @classmethod
    def from_dict(cls, r: Mapping) -> LadderRow:
        fit = {}
        for period, per in (r.get("fit") or {}).items():
            if not isinstance(per, Mapping):
                continue
            if any(k in per for k in _CRITERIA):  # one output, not named
                per = {"": per}
            fit[str(period)] = MappingProxyType(
                {str(o): RungFit.from_dict(v) for o, v in per.items() if isinstance(v, Mapping)}
            )
        return cls(
            model=str(r.get("model", "?")),
            n_params=_int(r.get("n_params")),
            n_model_params=_int(r.get("n_model_params")),
            fit=MappingProxyType(fit),
            log_likelihood=finite_float(r.get("log_likelihood")),
            aic=finite_float(r.get("aic")),
            bic=finite_float(r.get("bic")),
            rank=_int(r.get("rank")),
            n_null=_int(r.get("n_null")),
            null_directions=tuple(str(d) for d in r.get("null_directions") or ()),
            condition_number_identifiable=finite_float(r.get("condition_number_identifiable")),
            map_agreed=_text(r.get("map_agreed")),
            sampled=bool(r.get("sampled")),
            error=str(r["error"]) if r.get("error") else None,
            parent=_text(r.get("parent")),
            seeded_from=_text(r.get("seeded_from")),
            map_seconds=finite_float(r.get("map_seconds")),
            score=finite_float(r.get("score")),
            chosen=bool(r.get("chosen")),
            map_guard=MapGuard.from_dict(r.get("map_guard")),
        )


def ladder_of(d) -> MappingProxyType:
    """section -> tuple of :class:`LadderRow` of ``summary.json``'s ``ladder`` (empty:
    no ladder)."""
    if not isinstance(d, Mapping):
        return MappingProxyType({})
    return MappingProxyType(
        {
            str(sec): tuple(LadderRow.from_dict(r) for r in rows or () if isinstance(r, Mapping))
            for sec, rows in d.items()
        }
    )


@dataclass(frozen=True)
class Selection:
    """The screen of ``model: auto`` in one section: each rung's MAP scored on the
    validation period (``rows``; ``scores``: label -> the ``score`` compared [%],
    ``n_params``: label -> free parameters), and the rule's decision: the ``choice``
    (the simplest rung within ``margin`` FIT points of the ``best``), the ``reason`` in
    words, the rungs that ``tied`` with it (``runner_up`` the first), the ``tie`` in
    words, the ``rule`` in words, the model recommended (``model``) and what decided
    (``decided_by``: ``"screen"``; the ELPD stage, ``posterior``, is ``hbayes
    compare``'s)."""

    choice: str
    reason: str = ""
    rule: str = ""
    score: str = ""
    best: str | None = None
    runner_up: str | None = None
    tied: tuple[str, ...] = ()
    scores: MappingProxyType = field(default_factory=lambda: MappingProxyType({}))
    n_params: MappingProxyType = field(default_factory=lambda: MappingProxyType({}))
    margin: float | None = None
    model: str | None = None
    decided_by: str = "screen"
    tie: str | None = None
    posterior: MappingProxyType | None = None
    rows: tuple[LadderRow, ...] = ()
    #: [s] the screen's wall time (None: not recorded)
    screen_seconds: float | None = None

    @classmethod
    def from_dict(cls, d) -> Selection | None:
        if not isinstance(d, Mapping) or d.get("choice") is None:
            return None
        post = d.get("posterior")
        return cls(
            choice=str(d["choice"]),
            reason=str(d.get("reason") or ""),
            rule=str(d.get("rule") or ""),
            score=str(d.get("score") or ""),
            best=_text(d.get("best")),
            runner_up=_text(d.get("runner_up")),
            tied=tuple(str(m) for m in d.get("tied") or ()),
            scores=MappingProxyType(
                {str(m): finite_float(v) for m, v in (d.get("scores") or {}).items()}
            ),
            n_params=MappingProxyType(
                {str(m): _int(v) for m, v in (d.get("n_params") or {}).items()}
            ),
            margin=finite_float(d.get("margin")),
            model=_text(d.get("model")),
            decided_by=str(d.get("decided_by") or "screen"),
            tie=str(d["tie"]) if d.get("tie") else None,
            posterior=MappingProxyType(dict(post)) if isinstance(post, Mapping) else None,
            rows=tuple(
                LadderRow.from_dict(r) for r in d.get("rows") or () if isinstance(r, Mapping)
            ),
            screen_seconds=finite_float(d.get("screen_seconds")),
        )


def selection_of(d) -> MappingProxyType:
    """section -> :class:`Selection` of ``summary.json``'s ``selection`` (empty: no
    section chose its model by the screen)."""
    if not isinstance(d, Mapping):
        return MappingProxyType({})
    out = {str(sec): Selection.from_dict(s) for sec, s in d.items()}
    return MappingProxyType({k: v for k, v in out.items() if v is not None})


@dataclass(frozen=True)
class Provenance:
    """The config that produced the posterior: its snapshot (``config``, what
    ``config.yaml`` holds, as data; None: a run written before it was recorded) and
    the snapshot's SHA-256 (``config_sha256``), also stamped on every group of
    ``posterior.nc``."""

    config: MappingProxyType | None = None
    config_sha256: str | None = None

    @property
    def recorded(self) -> bool:
        """Whether the run recorded its config snapshot."""
        return self.config is not None

    @property
    def demo_seed(self) -> int | None:
        """The seed of the synthetic data the config asked for (None: not synthetic)."""
        data = (self.config or {}).get("data")
        demo = data.get("demo") if isinstance(data, Mapping) else None
        seed = demo.get("seed") if isinstance(demo, Mapping) else None
        return seed if isinstance(seed, int) else None

    def snapshot(self) -> dict[str, Any]:
        """The config snapshot as a plain (mutable) dict (empty: not recorded)."""
        import copy

        return copy.deepcopy(dict(self.config or {}))

    @classmethod
    def from_dict(cls, d) -> Provenance:
        if not isinstance(d, Mapping):
            return cls()
        config = d.get("config")
        sha = d.get("config_sha256")
        return cls(
            config=MappingProxyType(dict(config)) if isinstance(config, Mapping) else None,
            config_sha256=None if sha is None else str(sha),
        )
