"""The typed run summary: what a calibration states about its posterior, read once.

``hbayes calibrate`` writes ``summary.json`` through :class:`RunSummary`
(:meth:`RunSummary.to_dict`, which stamps :data:`SCHEMA_VERSION`); the report, the
comparison, the portfolio, the projection and the CLI read it through
:func:`load_summary`, so that the same posterior prints the same figures everywhere and
no consumer pokes at nested dicts:

- :class:`Estimate` — one parameter or derived quantity: median, 5 % and 95 %
  quantiles, mean, sd [its unit], its plain-words label, prior, sampler statistics;
- :class:`FitMetrics` — fit criteria and band coverage of one output over one period;
- :class:`Convergence` — the criteria the run states (max R-hat, min bulk ESS, chain
  length in τ), the figures of the draws they are judged on (every retained draw; the
  thinned draws of ``posterior.nc``'s ``posterior`` group in runs written before) and
  the stopping rule's decision;
- :class:`ModelInfo` — one section's model, noise model, chain and MAP findings
  (:class:`Identifiability`, :class:`FrozenNode`);
- :class:`Period` — the calibration and validation periods;
- :class:`Verdict` — the report's verdict (level, status, headline, reasons), written
  with the report: the portfolio reads the verdict the report shows;
- :class:`LadderRow`, :class:`Selection`, :class:`Provenance` — the model-order ladder,
  the screen of ``model: auto`` and the config snapshot that produced the posterior.

Versions: a summary without ``schema_version`` is version 1 (every hbayes before the
typed summary); its keys are read as they were written, missing ones as absent
(None). A summary of a newer schema than this hbayes knows is refused with a message
naming the file. The whole JSON object stays available as :attr:`RunSummary.raw`
(what :meth:`RunSummary.to_dict` writes back);
:mod:`heritage_bayes.rundir.summary_parts` holds the models', periods', alignment's and
verdict's types, :mod:`heritage_bayes.rundir.summary_ladder` the ladder's, the
selection's and the provenance's.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from pathlib import Path
from types import MappingProxyType
from typing import Any

from heritage_bayes.format import fmt_int, quantity_label
from heritage_bayes.rundir.reader import SCHEMA_VERSION, damaged, read_summary
from heritage_bayes.rundir.summary_ladder import (
    LadderRow,
    MapGuard,
    Provenance,
    RungFit,
    Selection,
    ladder_of,
    selection_of,
)
from heritage_bayes.rundir.summary_parts import (
    STATUSES,
    Alignment,
    FrozenNode,
    Gap,
    Identifiability,
    ModelInfo,
    NullDirection,
    Period,
    PredictiveNoise,
    Saturation,
    SourceNote,
    Verdict,
    finite_float,
)

__all__ = [
    "SCHEMA_VERSION",
    "STATUSES",
    "Alignment",
    "Convergence",
    "Estimate",
    "FitMetrics",
    "FrozenNode",
    "Gap",
    "Identifiability",
    "LadderRow",
    "MapGuard",
    "ModelInfo",
    "NullDirection",
    "Period",
    "PredictiveNoise",
    "Provenance",
    "RunSummary",
    "RungFit",
    "Saturation",
    "Selection",
    "SourceNote",
    "Verdict",
    "load_summary",
    "typed_summary",
]

#: The convergence criteria of runs that did not state them (hbayes before they did).
_DEFAULT_CRITERIA = {"max_rhat": 1.01, "min_ess_bulk": 400.0, "tau_factor": 50.0}


@dataclass(frozen=True)
class Estimate:
    """One parameter or derived quantity of a run's posterior.

    ``median``, ``q05``, ``q95`` [``unit``] are the quantiles of the draws saved in
    ``posterior.nc`` (a reader recomputing them from the file gets the same digits);
    ``r_hat``, ``ess_bulk``, ``ess_tail`` those of the draws
    :attr:`Convergence.draws` names; ``fixed`` holds the value of a parameter the
    config fixed (no posterior).
    """

    key: str  # "<section>.<name>"
    unit: str = ""
    median: float | None = None
    q05: float | None = None
    q95: float | None = None
    mean: float | None = None
    sd: float | None = None
    truth: float | None = None
    kind: str = ""
    description: str = ""
    derived: bool = False
    fixed: float | None = None
    prior: str | None = None
    map: float | None = None
    r_hat: float | None = None
    ess_bulk: float | None = None
    ess_tail: float | None = None
    tau: float | None = None
    contraction: float | None = None
    at_bound: str | None = None

    @property
    def section(self) -> str:
        return self.key.split(".", 1)[0]

    @property
    def name(self) -> str:
        return self.key.split(".", 1)[-1]

    @property
    def free(self) -> bool:
        return self.fixed is None and not self.derived

    @property
    def label(self) -> str:
        """Plain words, symbol and unit (``τ₁ [h]``, ``solar aperture, east facade [m²]``)."""
        return quantity_label(self.name, self.unit, self.description, domain=self.section)

    @property
    def truth_inside(self) -> bool | None:
        """Whether a known true value lies inside the 90 % interval (None: no truth)."""
        if self.truth is None or self.q05 is None or self.q95 is None:
            return None
        return self.q05 <= self.truth <= self.q95

    @classmethod
    def from_dict(cls, key: str, d: dict, *, derived: bool = False) -> Estimate:
        fixed = d.get("fixed")
        return cls(
            key=key,
            unit=str(d.get("unit") or ""),
            median=finite_float(d.get("median")),
            q05=finite_float(d.get("q05")),
            q95=finite_float(d.get("q95")),
            mean=finite_float(d.get("mean")),
            sd=finite_float(d.get("sd")),
            truth=finite_float(d.get("truth")),
            kind="derived" if derived else str(d.get("kind") or ""),
            description=str(d.get("description") or ""),
            derived=derived,
            fixed=finite_float(fixed) if fixed is not None else None,
            prior=d.get("prior") if isinstance(d.get("prior"), str) else None,
            map=finite_float(d.get("map")),
            r_hat=finite_float(d.get("r_hat")),
            ess_bulk=finite_float(d.get("ess_bulk")),
            ess_tail=finite_float(d.get("ess_tail")),
            tau=finite_float(d.get("tau")),
            contraction=finite_float(d.get("contraction")),
            at_bound=d.get("at_bound") if isinstance(d.get("at_bound"), str) else None,
        )


@dataclass(frozen=True)
class FitMetrics:
    """Fit of the posterior-median simulation of one output over one period.

    ``FIT`` [%] (100 (1 - |y - ŷ| / |y - ȳ|)), ``MSE`` [unit²], ``MAE`` [unit],
    ``n`` hours; ``coverage50``/``coverage90`` [-]: the share of hours inside the 50 %
    and 90 % predictive bands.
    """

    section: str
    output: str
    period: str
    FIT: float | None = None
    MSE: float | None = None
    MAE: float | None = None
    n: int | None = None
    coverage50: float | None = None
    coverage90: float | None = None
    SD: float | None = None
    coverage90_1step: float | None = None


@dataclass(frozen=True)
class Convergence:
    """The run's convergence: criteria stated, figures of the draws judged, decision.

    ``max_rhat`` and ``min_ess_bulk`` are the largest rank-normalised split R-hat and
    the smallest bulk ESS over the free parameters (walkers as chains, ``az.summary``)
    on the draws ``draws`` names: ``"retained"``, every draw each model's sampler
    retained (``walkers`` × the draws per walker of each group
    ``posterior_retained_<model>`` of ``posterior.nc``, ``groups``), the draws its
    stopping rule checked; or ``"saved"``, the thinned draws of the ``posterior`` group
    (runs written before the retained draws were stored). ``saved_max_rhat`` and
    ``saved_min_ess_bulk`` are the thinned draws' figures, recorded beside the retained
    ones and deciding nothing: on a few draws per walker R-hat is mostly noise
    (docs/science/benchmarks.md, "Which draws the convergence figures are on").
    ``converged`` is the sampler's stopping rule (chains of ``tau_factor`` τ with a
    stable τ, R-hat and ESS on the retained draws).
    """

    max_rhat: float | None
    min_ess_bulk: float | None
    target_rhat: float
    target_ess: float
    tau_factor: float
    converged: bool
    converged_tau: bool
    reasons: tuple[str, ...] = ()
    tau_rtol: float | None = None
    draws: str = "saved"
    walkers: int | None = None
    #: (group, draws per walker) of each model's retained draws
    groups: tuple[tuple[str, int], ...] = ()
    saved_draws_per_walker: int | None = None
    saved_max_rhat: float | None = None
    saved_min_ess_bulk: float | None = None

    @classmethod
    def from_dict(cls, d: dict, crit: dict) -> Convergence:
        """The convergence of a ``summary.json`` object, its criteria ``crit``."""
        cd = d.get("convergence_draws") if isinstance(d.get("convergence_draws"), dict) else {}
        on = "retained" if cd.get("on") == "retained" else "saved"
        return cls(
            max_rhat=finite_float(d.get("max_rhat")),
            min_ess_bulk=finite_float(d.get("min_ess_bulk")),
            target_rhat=float(crit["max_rhat"]),
            target_ess=float(crit["min_ess_bulk"]),
            tau_factor=float(crit["tau_factor"]),
            converged=bool(d.get("converged", False)),
            converged_tau=bool(d.get("converged_tau", d.get("converged", False))),
            reasons=tuple(str(r) for r in d.get("unconverged_reasons") or ()),
            tau_rtol=finite_float(crit.get("tau_rtol")),
            draws=on,
            walkers=_count(cd.get("walkers")),
            groups=tuple(
                (str(g), n) for g, n in (cd.get("groups") or {}).items() if _count(n) is not None
            ),
            saved_draws_per_walker=_count(cd.get("saved_draws_per_walker")),
            saved_max_rhat=finite_float(cd.get("saved_max_rhat")),
            saved_min_ess_bulk=finite_float(cd.get("saved_min_ess_bulk")),
        )

    @property
    def draws_ok(self) -> bool:
        """Whether the judged draws (:attr:`draws`) meet the stated R-hat and ESS
        criteria."""
        return (
            self.max_rhat is not None
            and self.min_ess_bulk is not None
            and self.max_rhat <= self.target_rhat
            and self.min_ess_bulk >= self.target_ess
        )

    @property
    def saved_draws_ok(self) -> bool:
        """:attr:`draws_ok` under its earlier name (scripts written before)."""
        return self.draws_ok

    @property
    def draws_name(self) -> str:
        """``"retained draws"`` or ``"saved draws"``: what the figures are on."""
        return f"{self.draws} draws"

    @property
    def draws_where(self) -> str:
        """The judged draws in words, with their number and where a reader finds them."""
        if self.draws != "retained":
            return "the draws saved in posterior.nc"
        if len(self.groups) == 1:
            (group, n), w = self.groups[0], self.walkers or 0
            return (
                f"the {fmt_int(w * n)} retained draws ({w} walkers × {n}; group "
                f"`{group}` of `posterior.nc`)"
            )
        each = ", × ".join(f"{n} in `{g}`" for g, n in self.groups)
        return f"the retained draws ({self.walkers} walkers × {each} of `posterior.nc`)"

    @property
    def draws_text(self) -> str:
        """The judged draws' R-hat and ESS against the criteria, in words."""
        r = "—" if self.max_rhat is None else f"{self.max_rhat:.3f}"
        return (
            f"{self.draws_where} give max R-hat {r} and min bulk ESS "
            f"{fmt_int(self.min_ess_bulk)} against the criteria R-hat ≤ {self.target_rhat:g} "
            f"and ESS ≥ {self.target_ess:g}"
        )

    @property
    def saved_text(self) -> str:
        """What the thinned draws of the ``posterior`` group give, when the figures are
        on the retained draws ("" otherwise): a reader's ``az.summary`` of that group."""
        if self.draws != "retained" or self.saved_max_rhat is None:
            return ""
        n = (self.walkers or 0) * (self.saved_draws_per_walker or 0)
        return (
            f"the {fmt_int(n)} thinned draws of the posterior group ({self.walkers} walkers "
            f"× {self.saved_draws_per_walker}, what the quantiles and bands use) give max "
            f"R-hat {self.saved_max_rhat:.3f} and min bulk ESS "
            f"{fmt_int(self.saved_min_ess_bulk)}; with so few draws per walker R-hat "
            "can lie above the target even for independent draws, so they decide nothing"
        )

    @property
    def criteria_text(self) -> str:
        """The stated criteria in words."""
        return (
            f"R-hat ≤ {self.target_rhat:g} and bulk ESS ≥ {self.target_ess:g} on the "
            f"{self.draws_name}, chains of at least {self.tau_factor:g} τ with a stable τ"
        )


def _count(v) -> int | None:
    """A positive count of ``summary.json`` (None: absent or not a count)."""
    return v if isinstance(v, int) and not isinstance(v, bool) and v > 0 else None


@dataclass(frozen=True)
class RunSummary:
    """``summary.json`` of a calibration run, typed (see the module docstring)."""

    schema_version: int
    name: str
    building: str
    room: str
    seed: int | None
    config_hash: str
    created_at: str
    dt: float
    parameters: MappingProxyType  # key -> Estimate
    derived: MappingProxyType  # key -> Estimate
    metrics: tuple[FitMetrics, ...]
    convergence: Convergence
    models: MappingProxyType  # section -> ModelInfo
    timings: MappingProxyType  # what -> seconds
    wall_seconds: float | None
    periods: tuple[Period, ...]
    warmup_steps: int
    init_steps: int | None
    notes: str
    heritage_bayes_version: str
    irradiance_source: str
    #: library versions the run recorded (empty: an older run)
    versions: MappingProxyType
    #: synthetic data with known true values
    has_truth: bool
    #: the site's longitude [° east] (None: not recorded)
    longitude: float | None
    #: how the ground temperature was set, in words ("" if not recorded)
    ground_temperature: str
    #: the report's verdict (None: no report written since the run, or an older run)
    verdict: Verdict | None
    alignment: Alignment
    #: section -> the model-order ladder's rows (:class:`LadderRow`; empty: no ladder)
    ladder: MappingProxyType
    #: section -> the screen of ``model: auto`` (:class:`Selection`; empty: none)
    selection: MappingProxyType
    #: the config snapshot that produced the posterior (not recorded: an older run)
    provenance: Provenance
    raw: MappingProxyType = field(repr=False)

    # ------------------------------------------------------------------ reading
    def estimate(self, key: str) -> Estimate | None:
        """The parameter or derived quantity ``<section>.<name>`` (None if absent)."""
        return self.parameters.get(key) or self.derived.get(key)

    def estimates(self, section: str | None = None) -> list[Estimate]:
        """Parameters then derived quantities (of one section)."""
        out = [*self.parameters.values(), *self.derived.values()]
        return [e for e in out if section is None or e.section == section]

    def metrics_by_output(self) -> dict[tuple[str, str], dict[str, FitMetrics]]:
        """(section, output) -> period -> its metrics, in the order the run wrote them
        (``combined``: the relative humidity of the two models)."""
        out: dict[tuple[str, str], dict[str, FitMetrics]] = {}
        for m in self.metrics:
            out.setdefault((m.section, m.output), {})[m.period] = m
        return out

    def metric(self, section: str, output: str, period: str) -> FitMetrics | None:
        for m in self.metrics:
            if (m.section, m.output, m.period) == (section, output, period):
                return m
        return None

    @property
    def seeds(self) -> dict[str, int]:
        """The seeds that make the run reproducible (calibration; synthetic data)."""
        out = {"calibration": self.seed} if self.seed is not None else {}
        if self.provenance.demo_seed is not None:
            out["synthetic data"] = self.provenance.demo_seed
        return out

    def to_dict(self) -> dict[str, Any]:
        """The JSON object ``summary.json`` holds (this hbayes's schema version)."""
        import copy

        d = copy.deepcopy(dict(self.raw))
        d["schema_version"] = SCHEMA_VERSION
        return d

    # ------------------------------------------------------------------ building
    @classmethod
    def from_dict(cls, d: dict, *, source: str | Path = "summary.json") -> RunSummary:
        """The typed summary of a ``summary.json`` object (any schema up to
        :data:`SCHEMA_VERSION`; keys a version lacks read as absent).

        Raises
        ------
        InputError
            A schema newer than this hbayes knows, named with the file.
        """
        version = d.get("schema_version", 1)
        if (
            not isinstance(version, int)
            or isinstance(version, bool)
            or not (1 <= version <= SCHEMA_VERSION)
        ):
            raise damaged(
                Path(source),
                f"summary schema {version!r}: this hbayes reads 1 to {SCHEMA_VERSION} "
                "(a newer one: upgrade heritage_bayes)",
            )
        crit = {**_DEFAULT_CRITERIA, **(d.get("criteria") or {})}
        site = (d.get("sources") or {}).get("site") or {}
        corr = d.get("correlations") or {}
        models = {
            sec: ModelInfo.from_dict(sec, info, corr.get(sec))
            for sec, info in (d.get("models") or {}).items()
        }
        metrics = []
        for sec, outs in (d.get("metrics") or {}).items():
            for out, periods in (outs or {}).items():
                for per, m in (periods or {}).items():
                    if not isinstance(m, dict):
                        continue
                    metrics.append(
                        FitMetrics(
                            section=sec,
                            output=out,
                            period=per,
                            FIT=finite_float(m.get("FIT")),
                            MSE=finite_float(m.get("MSE")),
                            MAE=finite_float(m.get("MAE")),
                            n=m.get("n"),
                            coverage50=finite_float(m.get("coverage50")),
                            coverage90=finite_float(m.get("coverage90")),
                            SD=finite_float(m.get("SD")),
                            coverage90_1step=finite_float(m.get("coverage90_1step")),
                        )
                    )
        conv = Convergence.from_dict(d, crit)
        return cls(
            schema_version=version,
            name=str(d.get("name") or ""),
            building=str(d.get("building") or ""),
            room=str(d.get("room") or ""),
            seed=d.get("seed") if isinstance(d.get("seed"), int) else None,
            config_hash=str(d.get("config_hash") or ""),
            created_at=str(d.get("created_at") or ""),
            dt=finite_float(d.get("dt")) or 3600.0,
            parameters=MappingProxyType(
                {k: Estimate.from_dict(k, v) for k, v in (d.get("parameters") or {}).items()}
            ),
            derived=MappingProxyType(
                {
                    k: Estimate.from_dict(k, v, derived=True)
                    for k, v in (d.get("derived") or {}).items()
                }
            ),
            metrics=tuple(metrics),
            convergence=conv,
            models=MappingProxyType(models),
            timings=MappingProxyType(
                {
                    k: float(v)
                    for k, v in (d.get("timings") or {}).items()
                    if finite_float(v) is not None
                }
            ),
            wall_seconds=finite_float(d.get("wall_seconds")),
            periods=tuple(
                Period(name=k, start=p.get("start"), end=p.get("end"), steps=p.get("steps", 0))
                for k, p in (d.get("periods") or {}).items()
            ),
            warmup_steps=int(d.get("warmup_steps") or 0),
            init_steps=d.get("init_steps"),
            notes=str(d.get("notes") or ""),
            heritage_bayes_version=str(d.get("heritage_bayes_version") or ""),
            irradiance_source=str(d.get("irradiance_source") or ""),
            versions=MappingProxyType(
                dict(d["versions"]) if isinstance(d.get("versions"), dict) else {}
            ),
            has_truth=bool(d.get("truth")),
            longitude=finite_float(site.get("longitude")),
            ground_temperature=str(
                ((d.get("sources") or {}).get("ground_temperature") or {}).get("method") or ""
            ),
            verdict=Verdict.from_dict(d.get("verdict")),
            alignment=Alignment.from_dict(d.get("alignment")),
            ladder=ladder_of(d.get("ladder")),
            selection=selection_of(d.get("selection")),
            provenance=Provenance.from_dict(d.get("provenance")),
            raw=MappingProxyType(d),
        )


def typed_summary(summary: RunSummary | dict) -> RunSummary:
    """``summary`` typed: a :class:`RunSummary` as it is, a ``summary.json`` object
    through :meth:`RunSummary.from_dict` (for callers that hold the JSON)."""
    return summary if isinstance(summary, RunSummary) else RunSummary.from_dict(summary)


def load_summary(run_dir: str | Path) -> RunSummary:
    """The typed ``summary.json`` of a run directory (:func:`read_summary` checks the
    file; every schema version up to :data:`SCHEMA_VERSION` loads).

    Raises
    ------
    InputError
        Missing, damaged or foreign file, or a newer schema (named).
    """
    return RunSummary.from_dict(read_summary(run_dir), source=Path(run_dir) / "summary.json")
