"""Orchestration of a calibration run and loading it back.

``run_calibration(cfg, out_dir)`` does what ``hbayes calibrate`` does: prepare the data
(:mod:`heritage_bayes.prepare`), then for each configured model (thermal, hygric,
calibrated independently as in the paper): parameters and priors, the vectorised
log-posterior, the MAP warm start, the structural identifiability check at the MAP, and
emcee until converged; then the run directory (see :mod:`heritage_bayes.inference.results`).

``load_run(DIR)`` returns a :class:`Run`: the models, the resolved config, the
InferenceData and a method to simulate posterior draws on new inputs (the entry point
for climate-change projections).
"""

from __future__ import annotations

import time
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from heritage_bayes._memory import release_memory
from heritage_bayes._progress import Progress as _Progress
from heritage_bayes._version import __version__
from heritage_bayes.calibration.chains import (
    common_draws,
    continue_chains,
    run_chain,
    sampler_args,
    say_share_spent,
)
from heritage_bayes.calibration.convergence import unconverged_reasons
from heritage_bayes.calibration.findings import LADDERS, say_findings
from heritage_bayes.calibration.ladder import (  # structural_at_map: re-exported
    ladder_row,
    rung_log_posterior,
    section_log_posterior,
    structural_at_map,
)
from heritage_bayes.calibration.wall import config_with_fixed_walls, fix_section_wall
from heritage_bayes.config import MAX_SEED, CalibrationConfig, config_hash
from heritage_bayes.convert import format_timedelta
from heritage_bayes.errors import InputError
from heritage_bayes.inference.posterior import LogPosterior
from heritage_bayes.inference.results import (
    atomic_write,
    atomic_write_text,
    dump_json,
    ensure_free_space,
    write_inference_data,
)
from heritage_bayes.models import (
    AUTO,
    SECTIONS,
    build_model,
    catalog_build,
    catalog_options,
    initial_state_of,
    models_of,
)
from heritage_bayes.rc.model import RCModel
from heritage_bayes.run import (  # Run, load_run: re-exported
    Run,
    RunWriter,
    config_yaml,
    load_run,
    section_parameters,
    stamp_provenance,
)
from heritage_bayes.rundir import check_name
from heritage_bayes.rundir.marker import read_marker, write_marker
from heritage_bayes.rundir.summary import RunSummary
from heritage_bayes.sources import input_paths

__all__ = [
    "LADDERS",
    "SECTIONS",
    "Run",
    "build_model",
    "load_run",
    "model_ladder",
    "run_calibration",
    "structural_at_map",
]


def check_models(cfg: CalibrationConfig) -> tuple[dict[str, RCModel], dict[str, list]]:
    """Build every configured model and its priors without reading any data, so that a
    wrong model name, option or prior fails at once (:class:`ConfigError` naming the key).

    Returns
    -------
    models, rungs : dict
        The run's models, built once and handed down
        (:func:`heritage_bayes.models.models_of`).
    """
    models, rungs = models_of(cfg)
    for section, model in models.items():
        section_parameters(cfg, section, model, getattr(cfg, section).priors)
        initial_state_of(cfg, section, model)
    return models, rungs


def _say_segments(say, prep) -> None:
    """Console note on input gaps too long to bridge: the calibration's segments and
    those dropped as too short."""
    if prep.breaks is None:
        return
    from heritage_bayes.inference.segments import MIN_SEGMENT_HOURS, calibration_segments

    kept, dropped = calibration_segments(prep)
    idx, h = prep.frame.index[prep.calibration], prep.dt / 3600.0
    say.say(
        f"data: {int(prep.breaks.sum())} step(s) inside input gaps longer than data.max_gap "
        f"are not simulated; the calibration is fitted over {len(kept)} segment(s) of "
        + ", ".join(f"{(b - a) * h / 24:.1f} d" for a, b in kept)
        + " (each with its own initial state)"
    )
    for a, b in dropped:
        say.say(
            f"data: calibration segment {idx[a]:%Y-%m-%d %H:%M} to {idx[b - 1]:%Y-%m-%d %H:%M} "
            f"UTC dropped: shorter than the warm-up plus {MIN_SEGMENT_HOURS:g} h between gaps"
        )


@dataclass
class _Section:
    name: str
    model: RCModel
    logpost: LogPosterior
    map: object = None
    identifiability: object = None
    chain: object = None
    X: np.ndarray | None = None  # (walkers, draws, d) unconstrained
    theta: np.ndarray | None = None  # (walkers, draws, P), common across models
    theta_kept: np.ndarray | None = None  # (walkers, draws, P), all retained draws
    X_kept: np.ndarray | None = None  # the same in sampler coordinates
    laplace: object = None  # LaplaceResult at the MAP (practical identifiability)
    block_move: dict = field(default_factory=dict)  # the block move's parameters, weight
    map_at_bound: list = field(default_factory=list)  # (name, "lower"/"upper")
    frozen_node: dict | None = None  # the MAP's slowest mode, when many records long
    decoupled_wall: object = None  # calibration.wall.DecoupledWall (fixed_priors: its)
    fixed_priors: dict | None = None
    lp: np.ndarray | None = None
    timings: dict = field(default_factory=dict)
    deadline: float | None = None  # time.perf_counter() end of the run's time budget
    sampler_args: dict = field(default_factory=dict)  # calibration.chains.sampler_args
    continued: dict | None = None  # the chain continued (calibration.chains)


def identifiability_at_map(model: RCModel, logpost: LogPosterior, map_result, dt: float):
    """(structural identifiability, Laplace check) at a MAP, as ``hbayes calibrate``
    takes them before sampling: the Laplace standard deviations are conditional on the
    capacity that pins the overall scale of C and G (the structural check's
    ``scale_reference``), so that the scale ridge alone flags nothing. The Laplace
    check's ``unidentified`` parameters are the block of the sampler's block move."""
    from heritage_bayes.inference.optimize import laplace

    ident = structural_at_map(model, logpost, map_result, dt)
    ref = ident.scale_reference
    return ident, laplace(logpost, map_result.x, given=(ref,) if ref else ())


def run_calibration(
    cfg: CalibrationConfig,
    out_dir: str | Path | None = None,
    *,
    seed: int | None = None,
    resume: bool = False,
    quiet: bool = False,
    report: bool | None = None,
    force: bool = False,
    start_maps: dict | None = None,
) -> Path:
    """Calibrate the configured models and write the run directory; return its path.

    Parameters
    ----------
    cfg : CalibrationConfig
    out_dir : path, optional
        Default ``reports/<config name>/`` (a plain name) in the current folder.
    seed : int, optional
        Overrides ``cfg.seed``. The same seed gives the same posterior.
    resume : bool
        Continue the chains saved in ``out_dir`` (``chain_<model>.h5``).
    quiet : bool
        No progress output.
    report : bool, optional
        Write ``report.html`` (default ``cfg.report``).
    force : bool
        Write the run beside the files of a folder hbayes did not make, replacing none
        (:class:`~heritage_bayes.rundir.writer.RunWriter`: output-path policy, marker).
    start_maps : dict, optional
        Section -> MAP (:class:`~heritage_bayes.inference.optimize.MAPResult`) of its
        model on these data, found beforehand: the chain starts there, no new search.

    Notes
    -----
    A section with ``model: auto`` is chosen first by the screen of its model ladder
    (:mod:`heritage_bayes.calibration.selection`), inside the time budget; the run records the
    screen (``summary.json``: ``selection``; its rows are the section's ladder) and its
    ``config.yaml`` names the model chosen.

    BLAS is limited to one thread for the duration: the hot loops multiply many small
    matrices, where OpenBLAS worker threads spin-wait on a busy machine (measured:
    docs/science/benchmarks.md, "Figures behind the code's choices").
    """
    from threadpoolctl import threadpool_limits

    with threadpool_limits(limits=1, user_api="blas"):
        return _run_calibration(
            cfg,
            out_dir,
            seed=seed,
            resume=resume,
            quiet=quiet,
            report=report,
            force=force,
            start_maps=start_maps,
        )


def _run_calibration(
    cfg: CalibrationConfig,
    out_dir: str | Path | None = None,
    *,
    seed: int | None = None,
    resume: bool = False,
    quiet: bool = False,
    report: bool | None = None,
    force: bool = False,
    start_maps: dict | None = None,
) -> Path:
    """Implementation of :func:`run_calibration` (same parameters)."""
    if seed is not None:
        if not 0 <= int(seed) <= MAX_SEED:
            raise InputError(f"--seed: must be within 0..{MAX_SEED} (got {seed})")
        cfg = cfg.model_copy(update={"seed": int(seed)})
    name = check_name(cfg.name or "run")  # a plain name, even where --out is given
    out_dir = Path("reports") / name if out_dir is None else out_dir
    writer = RunWriter(out_dir, force=force, resume=resume, protect=input_paths(cfg))
    writer.check()  # before reading any data: a bad --out fails at once
    out = writer.out
    models, rungs = check_models(cfg)
    with writer:
        try:
            _calibrate_into(
                writer.staging,
                cfg,
                out,
                models,
                rungs,
                resume=resume,
                quiet=quiet,
                report=report,
                start_maps=start_maps,
            )
            writer.commit()
        except BaseException as exc:
            exc.add_note(writer.left_behind())
            raise
    return out


def _calibrate_into(
    out: Path,
    cfg: CalibrationConfig,
    final: Path,
    models: dict[str, RCModel],
    rungs: dict[str, list],
    *,
    resume: bool,
    quiet: bool,
    report: bool | None,
    start_maps: dict | None = None,
) -> None:
    """Calibrate and write every output into ``out`` (the staging folder of ``final``)
    with the run's ``models`` and the ``rungs`` of its ``model: auto`` sections
    (:func:`check_models`); ``start_maps``: section -> a MAP found beforehand (``hbayes
    compare``'s screen) that starts the chain instead of a new search."""
    t_start = time.perf_counter()
    say = _Progress(quiet)
    start_maps = start_maps or {}
    # the heavy imports (arviz, scipy.optimize, emcee) only once the config is valid
    from heritage_bayes.calibration.outputs import build_run_outputs
    from heritage_bayes.prepare import prepare

    say.say(f"hbayes {__version__}: calibrating {cfg.name!r} -> {final}")
    t0 = time.perf_counter()
    prep = prepare(cfg, models)
    t_prep = time.perf_counter() - t0
    if (fixed := prep.sources.get("fixed_node_temperature")) is not None:
        # the Pf prior's centre, resolved from the data: recorded in config.yaml, so
        # that every reader of the run rebuilds the very prior the chain sampled
        cfg = cfg.model_copy(update={"fixed_node_temperature": fixed["value"]})
    for w in prep.sources.get("clock", {}).get("warnings", []):  # see sources.check_clocks
        say.warn(w)
    say.say(
        f"data: {prep.n_rows} steps of {prep.dt / 3600:g} h from "
        f"{prep.frame.index[0]} to {prep.frame.index[-1]} "
        f"(irradiance: {prep.irradiance_source})"
    )
    _say_segments(say, prep)
    end = None if cfg.sampler.max_seconds is None else t_start + cfg.sampler.max_seconds
    # model: auto: the ladder's MAP screen chooses the model sampled (calibration.selection)
    cfg, screens = _select_models(cfg, prep, say, end, rungs)
    models = {**models, **{k: v.models[v.choice["choice"]] for k, v in screens.items()}}
    maps = dict(start_maps or {})
    maps.update({k: v.maps[v.choice["choice"]] for k, v in screens.items()})
    atomic_write_text(out / "config.yaml", config_yaml(cfg))
    if cfg.source_text is not None:  # the user's own file, comments and all
        atomic_write_text(out / "config.original.yaml", cfg.source_text)
    sections: list[_Section] = []
    for name in SECTIONS:
        sec_cfg = getattr(cfg, name)
        if sec_cfg is None:
            continue
        lp = section_log_posterior(cfg, prep, name, models[name], sec_cfg.priors)
        sections.append(_Section(name, models[name], lp))
    ndims = [s.logpost.ndim for s in sections]
    nwalkers = cfg.sampler.walkers or max(32, 2 * max(ndims) + 2)
    for i, s in enumerate(sections):  # one budget: MAP search and sampling, all sections
        _sample_section(
            cfg,
            prep,
            s,
            i,
            len(sections),
            maps.get(s.name),
            say,
            end,
            nwalkers,
            out=out,
            resume=resume,
        )
    continue_chains(cfg, sections, end, say)  # a chain out of time: what later ones left
    if (fixed := config_with_fixed_walls(cfg, sections)) is not None:  # readers rebuild
        atomic_write_text(out / "config.yaml", config_yaml(cfg := fixed))  # chain's priors
    common_draws(cfg, sections)
    ladder = {k: v.rows for k, v in screens.items()}  # model: auto: the screen is the ladder
    if cfg.ladder:
        for i, s in enumerate(sections):
            if s.name in ladder:
                continue
            t0 = time.perf_counter()
            say.say(f"[{s.name}] model-order ladder (MAP fits)")
            s.deadline = end  # the ladder stops where the budget does
            ladder[s.name] = model_ladder(cfg, prep, s, seed=cfg.seed + 101 * i)
            s.timings["ladder_seconds"] = time.perf_counter() - t0
    t0 = time.perf_counter()
    idata, summary = build_run_outputs(cfg, prep, sections, chash=config_hash(cfg), seed=cfg.seed)
    summary["unconverged_reasons"] = unconverged_reasons(summary)  # [] when converged
    t_out = time.perf_counter() - t0
    summary["ladder"] = ladder or None
    summary["selection"] = {k: v.record() for k, v in screens.items()} or None
    summary["timings"] = {
        "prepare_seconds": t_prep,
        **{f"{s.name}_{k}": v for s in sections for k, v in s.timings.items()},
        "outputs_seconds": t_out,
    }
    summary["wall_seconds"] = time.perf_counter() - t_start
    stamp_provenance(cfg, idata, summary)
    ensure_free_space(out / "posterior.nc", sum(int(idata[g].nbytes) for g in idata.groups()))
    atomic_write(out / "posterior.nc", lambda p: write_inference_data(idata, p))
    # written through the typed summary every consumer reads (schema version stamped)
    summary = RunSummary.from_dict(summary, source=out / "summary.json").to_dict()
    dump_json(out / "summary.json", summary)
    # the staging marker lists it now (not only at the commit): the report records the
    # verdict it shows in it, and writes only into files the marker lists
    marker = read_marker(out)
    if marker is not None:
        write_marker(out, marker.with_files("summary.json"))
    say.say(
        f"summary: converged={summary['converged']}, max R-hat "
        f"{summary['max_rhat']:.3f}, min bulk ESS {summary['min_ess_bulk']:.0f}, "
        f"{summary['wall_seconds']:.0f} s"
    )
    if cfg.report if report is None else report:
        from heritage_bayes.report import write_report

        # the report reads the run back from its files: the chains, draws and outputs
        # held here go first, and the heap they leave goes back to the system
        del idata
        for s in sections:
            s.chain = s.X = s.theta = s.theta_kept = s.X_kept = s.lp = None
        release_memory()
        write_report(out)
        say.say(f"report: {final / 'report.html'}")


def _sample_section(
    cfg: CalibrationConfig,
    prep,
    s: _Section,
    i: int,
    n_sections: int,
    known,
    say,
    end,
    nwalkers: int,
    *,
    out: Path,
    resume: bool,
) -> None:
    """One section's share of the run's budget: its MAP (``known``, a MAP found
    beforehand, when it fits, else a new search), the identifiability at the MAP and the
    sampler's chain (checkpointed in ``out``), all stored on ``s`` with their timings.
    Section ``i`` of ``n_sections`` gets an equal share of the time left before ``end``
    and the seed ``cfg.seed + 101 i``."""
    from heritage_bayes.inference.optimize import seconds_left, share_deadline

    t0, deadline = time.perf_counter(), share_deadline(end, n_sections - i)
    if known is not None and known.x.size == s.logpost.ndim:
        s.map = known  # the screen's MAP starts the chain
        say.say(f"[{s.name}] {s.model.name}: the screen's MAP starts the sampler")
    else:
        say.say(
            f"[{s.name}] {s.model.name}: {s.logpost.ndim} free parameters, MAP search "
            f"({cfg.optimizer.method})"
        )
        s.map = _section_map(cfg, s, i, deadline, t0, n_sections)
    s.timings["map_seconds"] = time.perf_counter() - t0
    say.say(
        f"[{s.name}] MAP log-posterior {s.map.log_post:.1f}; "
        f"{s.map.n_agreed}/{s.map.n_starts} starts agreed"
    )
    fix_section_wall(cfg, prep, s, say)  # a buffer link the MAP leaves idle under a filter
    t0 = time.perf_counter()
    s.identifiability, s.laplace = identifiability_at_map(s.model, s.logpost, s.map, prep.dt)
    s.timings["identifiability_seconds"] = time.perf_counter() - t0
    say_findings(say, s, getattr(cfg, s.name).priors)
    t0 = time.perf_counter()
    s.sampler_args = sampler_args(cfg, s, i, nwalkers, out)
    s.chain = run_chain(s, say, seconds_left(deadline), resume=resume)
    s.timings["sampling_seconds"] = time.perf_counter() - t0
    s.timings["sampling_cpu_seconds"] = s.chain.cpu_seconds
    verdict = "converged" if s.chain.converged else "NOT converged"
    if s.chain.stopped_by == "max_seconds" and i < n_sections - 1:
        say_share_spent(cfg, s, say)  # continue_chains: with the time later ones leave
    say.say(f"[{s.name}] {s.chain.steps} steps, τmax {np.nanmax(s.chain.tau):.0f}: {verdict}")


def _section_map(cfg: CalibrationConfig, s: _Section, i: int, deadline, t0, n: int):
    """The MAP search of section ``s`` (the ``i``-th of ``n``) within its deadline."""
    from heritage_bayes.inference.optimize import find_map

    return find_map(
        s.logpost,
        seed=cfg.seed + 101 * i,
        method=cfg.optimizer.method,
        popsize=cfg.optimizer.popsize,
        maxiter=cfg.optimizer.maxiter,
        starts=cfg.optimizer.starts,
        restarts=cfg.optimizer.restarts_for(s.model.n_states),
        deadline=deadline,
        budget=f"the time budget sampler.max_time = "
        f"{format_timedelta(cfg.sampler.max_time or 0)} ({n - i} section(s) "
        f"left: {(deadline or t0) - t0:.0f} s for this one)",
    )


def _select_models(
    cfg: CalibrationConfig, prep, say, end, rungs: dict[str, list]
) -> tuple[CalibrationConfig, dict]:
    """Every ``model: auto`` section screened (its built ``rungs``,
    :func:`heritage_bayes.models.auto_rungs`) and replaced by its choice: (the config
    with the models chosen, section -> :class:`~heritage_bayes.calibration.selection.Screen`).
    Each screen may use a share of the time budget (``end``) of its own and of the
    sections still to sample."""
    from heritage_bayes.calibration.selection import chosen_section, screen
    from heritage_bayes.inference.optimize import share_deadline

    auto = [n for n in SECTIONS if getattr(cfg, n) is not None and getattr(cfg, n).model == AUTO]
    n_sections = sum(getattr(cfg, n) is not None for n in SECTIONS)
    screens = {}
    for i, name in enumerate(auto):
        say.say(f"[{name}] model: auto: screening the model ladder (MAP and validation FIT)")
        t0 = time.perf_counter()
        scr = screen(
            cfg,
            prep,
            name,
            rungs[name],
            seed=cfg.seed + 101 * SECTIONS.index(name),
            deadline=share_deadline(end, 2 * (n_sections - i)),
            say=say.say,
        )
        scr.choice["screen_seconds"] = time.perf_counter() - t0
        if scr.choice.get("tie"):
            say.say(f"[{name}] {scr.choice['tie']}")
        cfg = chosen_section(cfg, name, scr)
        screens[name] = scr
    return cfg, screens


def model_ladder(cfg: CalibrationConfig, prep, section: _Section, *, seed: int) -> list[dict]:
    """Accuracy versus identifiability over model orders (the paper's trade-off).

    MAP fit of each model of the section's ladder (thermal 1c/2c/4a, hygric 1c/2c/2c
    with fixed node; the sampled model's own MAP is reused), with the same data, noise
    model, room volume and those configured priors whose names exist in the model:
    fit criteria over calibration and validation periods (simulation from the MAP),
    log-likelihood, AIC and BIC, and the structural identifiability (rank, null
    directions, condition number of the identifiable part) at the MAP. Models the time
    budget (``section.deadline``) leaves no time for are left out.
    """
    from heritage_bayes.inference.optimize import BudgetError, find_map

    sec_cfg = getattr(cfg, section.name)
    names = list(LADDERS[section.name]) if isinstance(sec_cfg.model, str) else []
    if section.model.name not in names:
        names.append(section.model.name)
    rows = []
    out = section.model.output_names
    for name in names:
        if name == section.model.name:
            model, lp, mp = section.model, section.logpost, section.map
        else:
            try:
                opts = catalog_options(cfg, section.name, name)
                model = catalog_build(cfg, section.name, name, opts)
            except ValueError:  # a rung that does not take the configured options
                continue
            if model.output_names != out:
                continue
            lp = rung_log_posterior(cfg, prep, section.name, model, section.logpost.initial_state)
            try:
                mp = find_map(
                    lp,
                    seed=seed,
                    method=cfg.optimizer.method,
                    popsize=cfg.optimizer.popsize,
                    maxiter=max(30, cfg.optimizer.maxiter // 3),
                    starts=max(1, cfg.optimizer.starts // 2),
                    deadline=section.deadline,
                )
            except BudgetError:  # sampler.max_time is spent: the ladder ends here
                break
        row = ladder_row(prep, section.name, model, lp, mp)
        row["sampled"] = model.name == section.model.name
        rows.append(row)
    return rows
