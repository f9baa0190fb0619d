"""Climate-change projections of a calibrated room: ``hbayes project``.

After ``hbayes calibrate``, the posterior draws of the room's thermal and hygric models
are run on future weather — the KNMI'14 scenarios for Dutch sites, monthly morphing for
any site, or user-supplied future files (:mod:`heritage_bayes.climate.morph`) — and the
indoor climate is turned into conservation risk (:mod:`heritage_bayes.climate.risk`).

>>> import heritage_bayes as hb                                    # doctest: +SKIP
>>> p = hb.project("reports/demo", "configs/projection_demo.yaml")  # doctest: +SKIP
>>> p.probability_table()                                            # doctest: +SKIP

What it assumes (written into every output): the building and its use stay as
calibrated (stationary parameters: no renovation, no change of ventilation, heating or
visitors); the calibrated noise model describes the model error in the future as it did
in the calibration period; the future weather is a transformation of the baseline
(same weather sequence, shifted/stretched statistics), so year-to-year variability is
that of the baseline.

Outputs (``--out``, default ``RUN_DIR/projection``): ``projection.nc`` (xarray: per
case — the baseline and each scenario × horizon — and draw, every risk indicator, and
the monthly means of ``Ti`` and ``RHi`` by calendar month; the hourly draws are not
stored; the per-year indicators per complete year), ``projection.json`` (quantiles,
change relative to the baseline, probability statements, the uncertainty
decomposition, the indicator registry, the weather transformations, timings),
``projection.csv`` (one row per indicator and case, with name, unit, period and source)
and ``projection.html`` (self-contained decision page). The four are written into a
staging folder beside ``--out`` and swapped in together
(:class:`~heritage_bayes.rundir.writer.StagedFolder`): an interrupted or failed
re-projection leaves the previous projection whole.

Measures (``interventions:``, :mod:`heritage_bayes.projection.interventions`):
conservation heating, a dehumidifier, less ventilation — each simulated draw by draw
with the same parameters, noise and weather as doing nothing, in every case. Their
indicators (``<indicator>_measure``) and running costs (``cost_<name>``) per measure,
case and draw are in ``projection.nc``; the paired comparison (change with interval,
P(better), probability statements with and without, costs with intervals) in
``projection.json`` (``interventions``) and on the page.
"""

from __future__ import annotations

import time
from dataclasses import dataclass, field
from pathlib import Path

from heritage_bayes.calibration.convergence import EXIT_UNCONVERGED
from heritage_bayes.projection.config import (
    ProjectionConfig,
    load_projection_config,
    parse_projection_config,
)

__all__ = [
    "Projection",
    "ProjectionConfig",
    "load_projection_config",
    "parse_projection_config",
    "project",
]

ASSUMPTIONS = (
    "The building and its use stay as calibrated (stationary parameters: no renovation, "
    "no change of ventilation, heating, moisture sources or visitors).",
    "The calibrated noise model describes the model error in the future as in the "
    "calibration period; each draw adds one realisation of it (predictive bands).",
    "Future weather is a transformation of the baseline weather (same sequence of days, "
    "changed statistics), so year-to-year variability is that of the baseline.",
    "The indoor RH is formed from the simulated Ti and Pi and capped at saturation "
    "(100 %): vapour above saturation condenses.",
)


#: Exit status of ``hbayes project`` on a run whose sampler did not converge: the code of
#: ``hbayes calibrate`` for an unconverged run (one definition, in
#: :mod:`heritage_bayes.calibration.convergence`); the projection is written, with a
#: banner on its page.
EXIT_UNCONVERGED_RUN = EXIT_UNCONVERGED
UNCONVERGED_TEXT = (
    "the calibration did not converge: the posterior draws may not represent the room, "
    "and the projected intervals and probabilities can be wrong"
)


def _check_thresholds(pcfg, n_hours: int, risk_opts: dict) -> None:
    """Refuse a probability statement on an indicator the projection does not compute
    (the message lists those it does)."""
    from heritage_bayes.climate.risk.fused import projection_plan
    from heritage_bayes.climate.risk.registry import check_indicator_names

    plan, numpy = projection_plan(n_hours, **risk_opts)
    cols = [c for c in (*plan.columns, *numpy.columns) if c != "ashrae_best_class"]
    if "en15757_upper_offset" in cols:
        cols.insert(cols.index("en15757_upper_offset") + 1, "en15757_outside_baseline")
    check_indicator_names([t.indicator for t in pcfg.thresholds], cols, "thresholds")
    rank_by = pcfg.interventions_rank_by
    if rank_by is not None:
        from heritage_bayes.climate.risk.registry import indicator_info
        from heritage_bayes.errors import ConfigError

        if rank_by not in cols:
            raise ConfigError(
                f"interventions_rank_by: unknown indicator {rank_by!r}; this projection "
                f"computes: {', '.join(cols)}"
            )
        if not indicator_info(rank_by).worse:
            raise ConfigError(
                f"interventions_rank_by: {rank_by!r} has no direction (neither higher nor "
                "lower is worse for the collection): give a risk indicator such as "
                "hours_above_LIM0, vtt_mould_index_max or twpi"
            )


@dataclass
class Projection:
    """The result of :func:`project`."""

    config: ProjectionConfig
    labels: list[str]
    horizons: list
    results: list
    summary: dict
    dataset: object = None
    paths: dict = field(default_factory=dict)
    #: measure name -> per-case results with the measure (paired with ``results``)
    interventions: dict = field(default_factory=dict)

    def probability_table(self):
        """pandas.DataFrame: probability statements (rows) × cases (columns)."""
        from heritage_bayes.projection.summary import probability_table

        return probability_table(self.summary, self.labels)


def _as_config(config) -> ProjectionConfig:
    if isinstance(config, ProjectionConfig):
        return config
    if isinstance(config, dict):
        return parse_projection_config(config, source="projection")
    return load_projection_config(config)


def project(
    run,
    config,
    *,
    out=None,
    draws: int | None = None,
    seed: int | None = None,
    write: bool = True,
    progress=None,
) -> Projection:
    """Project a calibrated room's climate and risk onto future weather.

    Parameters
    ----------
    run : str, Path or heritage_bayes.run.Run
        A run directory written by ``hbayes calibrate`` (or the loaded run).
    config : str, Path, dict or ProjectionConfig
        The projection file (see :mod:`heritage_bayes.projection.config`).
    out : path, optional
        Output folder; default ``<run>/projection``.
    draws, seed : int, optional
        Override the file's ``draws`` and ``seed``.
    write : bool
        Write ``projection.nc``, ``projection.json`` and ``projection.html``.
    progress : callable, optional
        Called with one line of text per chunk of draws (all cases).

    Returns
    -------
    Projection

    Raises
    ------
    heritage_bayes.errors.InputError
        (and its subclasses ConfigError, DataError) for bad input: nothing is written;
        among it a threshold on an unknown indicator, or baseline/future weather from
        another site (see ``allow_other_site``).

    Notes
    -----
    A run whose sampler did not converge is projected, with ``summary["converged"]``
    False, a banner on the page and a warning through ``progress``; ``hbayes project``
    then exits with :data:`EXIT_UNCONVERGED_RUN`.
    """
    from heritage_bayes.climate.risk.registry import indicator_info
    from heritage_bayes.projection.decision import decision_table
    from heritage_bayes.projection.engine import select_draws, simulate_measures
    from heritage_bayes.projection.interventions import compare_measures, measures_from_config
    from heritage_bayes.projection.summary import summarize
    from heritage_bayes.projection.weather import Case, baseline_weather, futures, model_inputs
    from heritage_bayes.run import Run, load_run

    t_start = time.perf_counter()
    pcfg = _as_config(config)
    pcfg = _with_overrides(pcfg, draws, seed)
    dest = None
    if write:  # the output path checked before anything is read
        from heritage_bayes.projection.output import OUTPUT_FILES
        from heritage_bayes.rundir.writer import StagedFolder

        run_dir = Path(run.path if isinstance(run, Run) else run)
        dest = StagedFolder(
            Path(out) if out is not None else run_dir / "projection",
            kind="projection",
            names=OUTPUT_FILES,
            protect=[*_input_files(pcfg), run_dir / "posterior.nc"],
            noun="projection folder",
        )
        dest.check()
    r = run if isinstance(run, Run) else load_run(run)
    sel = select_draws(r, pcfg.draws, pcfg.seed)
    base, site, base_note = baseline_weather(r, pcfg)
    cases = [Case(pcfg.baseline_label, None, base, base_note)]
    cases += futures(r, pcfg, base, site)
    for c in cases:  # every input checked before the long part
        where = "baseline" if c.horizon is None else f"scenario {c.label}"
        c.inputs = model_inputs(r, pcfg, c.weather, site, where)
    risk_opts = {"indicators": pcfg.risk.indicators} if pcfg.risk.indicators else {}
    _check_thresholds(pcfg, len(cases[0].inputs), risk_opts)
    conv = r.run_summary.convergence
    converged = conv.converged
    if not converged and progress is not None:
        progress(f"WARNING: {UNCONVERGED_TEXT} ({r.path})")
    measures = measures_from_config(pcfg)
    for m in measures:  # refused before the long part
        m.check(r)

    # doing nothing and every measure in one pass: the same draws, noise and weather
    results, per_measure = simulate_measures(
        r,
        sel,
        [c.inputs for c in cases],
        measures,
        seed=pcfg.seed,
        noise=pcfg.noise,
        chunk=pcfg.risk.chunk_draws,
        risk_options=risk_opts,
        progress=progress,
    )
    labels = [c.label for c in cases]
    horizons = [c.horizon for c in cases]
    units = dict(results[0].predictive.attrs.get("units", {}))
    summary = summarize(labels, horizons, results, labels[0], pcfg.thresholds, units)
    summary["interventions"] = compare_measures(
        labels, results, per_measure, pcfg.thresholds, units, {m.name: m.notes(r) for m in measures}
    )
    summary["cases"] = _cases_summary(cases)
    summary["decision"] = decision_table(
        labels, results, per_measure, summary, pcfg.interventions_rank_by, pcfg.tariffs
    )
    summary["assumptions"] = list(ASSUMPTIONS)
    summary["converged"] = converged
    summary["unconverged_reasons"] = list(conv.reasons)
    summary["indicator_registry"] = {
        n: indicator_info(n).as_dict() | {"key": n} for n in summary["indicators"]
    }
    summary["humidity"] = pcfg.humidity
    summary["run"] = str(r.path)
    summary["seed"] = pcfg.seed
    summary["noise"] = {s: nm.name for s, nm in sel.noise_models.items()} if pcfg.noise else None
    summary["seconds"] = _seconds(time.perf_counter() - t_start, results, per_measure)
    proj = Projection(pcfg, labels, horizons, results, summary, interventions=per_measure)
    from heritage_bayes.projection.output import to_dataset, write_outputs

    proj.dataset = to_dataset(proj, r)
    if dest is not None:  # staged, then swapped in whole: never a mix of two projections
        with dest:
            try:
                staged = write_outputs(proj, r, dest.staging)
                dest.commit()
            except BaseException as exc:
                exc.add_note(dest.left_behind())
                raise
        proj.paths = {k: dest.out / p.name for k, p in staged.items()}
    return proj


def _with_overrides(pcfg, draws: int | None, seed: int | None):
    """The projection settings with the caller's ``draws`` and ``seed``, checked."""
    if draws is None and seed is None:
        return pcfg
    upd = {k: v for k, v in (("draws", draws), ("seed", seed)) if v is not None}
    if draws is not None and draws < 1:
        from heritage_bayes.errors import ConfigError

        raise ConfigError(f"--draws: expected a positive number (got {draws})")
    if seed is not None:
        from heritage_bayes.config._base import check_in_range
        from heritage_bayes.projection.config import ProjectionConfig

        check_in_range(ProjectionConfig, "seed", seed, "--seed")
    return pcfg.model_copy(update=upd)


def _cases_summary(cases) -> list[dict]:
    """One entry per weather case: its label, scenario, horizon and weather in brief."""
    from heritage_bayes.climate.risk.registry import years_of

    return [
        {
            "label": c.label,
            "scenario": c.scenario,
            "horizon": c.horizon,
            "weather": c.note,
            "mean_Te": float(c.weather["Te"].mean()),
            "hours": len(c.inputs),
            "years": years_of(len(c.inputs)),
            "hours_dropped": int(c.inputs.attrs.get("hours_dropped", 0)),
        }
        for c in cases
    ]


def _seconds(total: float, results, per_measure) -> dict:
    """Wall time of the projection [s]: in total, per stage, and for the measures."""
    return {
        "total": total,
        **{k: float(sum(res.seconds[k] for res in results)) for k in ("simulate", "noise", "risk")},
        "interventions": float(
            sum(
                res.seconds["simulate"] + res.seconds["risk"]
                for rs in per_measure.values()
                for res in rs
            )
        ),
    }


def _input_files(pcfg) -> list[Path]:
    """The projection file's folder and every file it names (an output may not hold
    them)."""
    found = [Path(pcfg.base_dir)] if pcfg.base_dir else []

    def walk(node) -> None:
        if isinstance(node, dict):
            for k, v in node.items():
                if k == "path" and isinstance(v, str | list):
                    found.extend(pcfg.path(str(q)) for q in ([v] if isinstance(v, str) else v))
                else:
                    walk(v)
        elif isinstance(node, list):
            for v in node:
                walk(v)

    walk(pcfg.model_dump(mode="json"))
    return found
