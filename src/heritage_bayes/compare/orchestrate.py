"""Calibrating the candidates of a config, each in its own run directory.

Part of :mod:`heritage_bayes.compare` (see its documentation).
"""

from __future__ import annotations

from collections.abc import Sequence
from pathlib import Path

from heritage_bayes._memory import release_memory
from heritage_bayes.calibration.selection_rule import choose, rule_text
from heritage_bayes.compare.core import DEFAULT_MODELS, compare_runs
from heritage_bayes.compare.page import write_comparison
from heritage_bayes.compare.screen import screen_candidates, to_sample
from heritage_bayes.errors import ConfigError


def _section_of(cfg, models: Sequence[str] | None) -> tuple[str, list[str]]:
    """The section and candidate names; ConfigError naming ``--models`` when bad."""
    from heritage_bayes.rc.catalog import CATALOG

    if not models:
        section = "thermal" if cfg.thermal is not None else "hygric"
        return section, list(DEFAULT_MODELS[section])
    names = [m.strip() for m in models if m.strip()]
    unknown = [m for m in names if m not in CATALOG]
    if unknown:
        raise ConfigError(
            f"--models: unknown model(s) {unknown}; available: {sorted(CATALOG)} "
            "(`hbayes models NAME` describes one)"
        )
    dup = sorted({m for m in names if names.count(m) > 1})
    if dup:
        raise ConfigError(f"--models: {dup} given more than once")
    if len(names) < 2:
        raise ConfigError(f"--models: give at least two models to compare (got {names})")
    domains = {m: CATALOG[m].domain for m in names}
    section = domains[names[0]]
    wrong = [m for m in names if domains[m] != section]
    if wrong:
        raise ConfigError(
            f"--models: {wrong} are not {section} models like {names[0]!r}; the candidates "
            "of one comparison describe the same output (thermal: Ti, hygric: Pi)"
        )
    if getattr(cfg, section) is None:
        raise ConfigError(
            f"--models: {section} models, but the config has no {section!r} section "
            "(it gives the noise model, priors and options of the candidates)"
        )
    return section, names


def _candidate_config(cfg, section: str, name: str):
    """The config calibrating only ``name`` in ``section`` (same data, noise, knowledge)
    and its model, built once: (config, model)."""
    from heritage_bayes.models import SECTIONS

    sec = getattr(cfg, section)
    # the configured priors whose parameters exist in this model (as the ladder does)
    from heritage_bayes.config.options import ModelOptions
    from heritage_bayes.inference.likelihoods import get_noise_model
    from heritage_bayes.inference.parameters import owned_priors
    from heritage_bayes.models import catalog_build, catalog_options, with_input_hold
    from heritage_bayes.rc.catalog import takes_option
    from heritage_bayes.run import section_parameters

    if sec.options.sink is not None and not takes_option(name, "sink"):  # a rung's own, as in auto
        given = {k: v for k, v in sec.options.given().items() if k != "sink"}
        sec = sec.model_copy(update={"options": ModelOptions.model_validate(given)})
        cfg = cfg.model_copy(update={section: sec})
    try:
        model = catalog_build(cfg, section, name, catalog_options(cfg, section, name))
    except ValueError as exc:
        raise ConfigError(f"--models: {name}: {exc}") from None
    priors = owned_priors(sec.priors, model, get_noise_model(sec.noise))
    new_sec = sec.model_copy(update={"model": name, "priors": priors})
    cand = cfg.model_copy(
        update={
            section: new_sec,
            **{s: None for s in SECTIONS if s != section},
            "ladder": False,
            "name": f"{cfg.name or 'run'}-{name}",
        }
    )
    section_parameters(cand, section, model, priors)  # a prior that does not fit fails now
    return cand, with_input_hold(cand, model)


def _calibrate_candidate(cand, run_dir: str, kwargs: dict) -> tuple[str, float, float]:
    """One candidate's calibration: (run directory, wall [s], CPU [s] of the process)."""
    import time

    from heritage_bayes.calibration.calibrate import run_calibration

    t0, c0 = time.perf_counter(), time.process_time()
    out = run_calibration(cand, run_dir, **kwargs)
    return str(out), time.perf_counter() - t0, time.process_time() - c0


def _worker_candidate(name: str, cand, run_dir: str, kwargs: dict, results) -> None:
    """:func:`_calibrate_candidate` in a worker process, its outcome put on ``results``
    as ``(name, "done", (run_dir, wall, cpu))`` or ``(name, "failed", message)``.
    SIGTERM (sent by the parent when it is interrupted or a candidate failed) and
    SIGINT (Ctrl-C reaches the whole process group) end the calibration at once, as
    Ctrl-C does: the staging folder removed, the chains saved for ``--resume``, the
    lock released."""
    import signal

    def stop(signum, frame):
        raise KeyboardInterrupt

    signal.signal(signal.SIGTERM, stop)
    signal.signal(signal.SIGINT, stop)
    try:
        results.put((name, "done", _calibrate_candidate(cand, run_dir, kwargs)))
    except KeyboardInterrupt:
        results.put((name, "stopped", None))
    except Exception as exc:  # told to the parent, which stops the others and raises
        results.put((name, "failed", f"{type(exc).__name__}: {exc}"))


def _start_worker(ctx, name: str, cand, run_dir: str, kwargs: dict, results):
    """A started worker process calibrating candidate ``name``."""
    proc = ctx.Process(
        target=_worker_candidate,
        args=(name, cand, run_dir, kwargs, results),
        name=f"hbayes-compare-{name}",
    )
    proc.start()
    return proc


def _stop_workers(procs: dict, grace: float = 60.0) -> None:
    """SIGTERM to every running worker, then wait (at most ``grace`` seconds in all)
    for them to save their chains, remove their staging folders and end; a worker still
    running then is killed."""
    import time

    for proc in procs.values():
        if proc.is_alive():
            proc.terminate()
    end = time.monotonic() + grace
    for proc in procs.values():
        proc.join(max(0.0, end - time.monotonic()))
        if proc.is_alive():
            proc.kill()
            proc.join()


def _sample_parallel(
    cands: dict, models: dict, out: Path, kwargs_of: dict, n_workers: int, tell
) -> dict:
    """Calibrate the candidates (``models``: name -> the model of each, which sizes it)
    in ``n_workers`` worker processes (largest first, a new
    one started as soon as one ends; ``kwargs_of``: name -> keywords of
    :func:`~heritage_bayes.calibration.calibrate.run_calibration`), with a progress line per start
    and end and every :data:`HEARTBEAT` seconds; return name -> run directory. Interrupted (Ctrl-C,
    SIGTERM) or a candidate failing: every worker stopped at once, none started."""
    import multiprocessing
    import queue
    import time

    from heritage_bayes.errors import InputError

    ctx = multiprocessing.get_context("spawn")  # no forked numba/BLAS threads
    results = ctx.Queue()
    todo = sorted(cands, key=lambda n: -_n_free(cands[n], _section_name(cands[n]), models[n]))
    running: dict = {}
    started: dict[str, float] = {}
    dirs: dict[str, Path] = {}
    last = time.monotonic()
    try:
        while todo or running:
            while todo and len(running) < n_workers:
                n = todo.pop(0)
                kw = {**kwargs_of[n], "quiet": True}
                running[n] = _start_worker(ctx, n, cands[n], str(out / n), kw, results)
                started[n] = time.monotonic()
                tell(f"sampling {n} (worker {running[n].pid})")
            try:
                name, status, value = results.get(timeout=1.0)
            except queue.Empty:
                for n, proc in list(running.items()):
                    if not proc.is_alive() and proc.exitcode not in (0, None):
                        raise InputError(
                            f"{n}: its worker ended with code {proc.exitcode}"
                        ) from None
                if time.monotonic() - last >= HEARTBEAT:
                    last = time.monotonic()
                    tell(
                        "still sampling: "
                        + ", ".join(f"{n} ({last - started[n]:.0f} s)" for n in running)
                        + (f"; waiting: {', '.join(todo)}" if todo else "")
                    )
                continue
            running.pop(name).join()
            if status == "done":
                run_dir, wall, cpu = value
                dirs[name] = Path(run_dir)
                tell(f"{name} done ({wall:.0f} s wall, {cpu:.0f} s CPU)")
            elif status == "stopped":
                raise KeyboardInterrupt
            else:
                raise InputError(f"{name}: {value}")
    except BaseException:  # Ctrl-C, SIGTERM, a failed candidate: stop them all
        _stop_workers(running)
        raise
    return dirs


def _section_name(cand) -> str:
    from heritage_bayes.models import SECTIONS

    return next(s for s in SECTIONS if getattr(cand, s) is not None)


def _n_free(cand, section: str, model) -> int:
    """Free parameters of a candidate's section with its ``model`` (the order in which
    to start them)."""
    from heritage_bayes.run import section_parameters

    return section_parameters(cand, section, model)[1].ndim


#: [s] between the progress lines of candidates still sampling.
HEARTBEAT = 60.0


def run_compare(
    cfg,
    models: Sequence[str] | None = None,
    out_dir: str | Path | None = None,
    *,
    seed: int | None = None,
    quiet: bool = False,
    report: bool | None = None,
    resume: bool = False,
    force: bool = False,
    workers: int | None = None,
) -> Path:
    """Screen the candidate models by their MAP, sample those within reach of the best,
    and write the comparison; return its folder.

    First every candidate's MAP and its validation FIT
    (:mod:`heritage_bayes.compare.screen`: seconds each) and the choice of ``model:
    auto``'s rule (:func:`heritage_bayes.calibration.selection_rule.choose`); then the
    choice and its best tied rival (without a tie, the best other candidate:
    :func:`~heritage_bayes.compare.screen.to_sample`) are calibrated, each chain started
    at its screened MAP, compared by their posteriors (blocked LOO, validation ELPD),
    and one is recommended by the same rule, the ELPD breaking the screen's tie where it
    is reliable (:func:`heritage_bayes.calibration.selection_rule.decide`; ``comparison.json``:
    ``selection``). The others are in ``comparison.json`` (``screened_out``,
    ``screen``) and the page with their MAP score and the reason. Ctrl-C or SIGTERM
    stops every worker at once (exit 130): no run written, the chains so far kept in
    the staging folders for ``--resume``, no candidate started after.

    Parameters
    ----------
    cfg : CalibrationConfig
        Data, periods, noise model, priors and knowledge of the room; the model of the
        compared section is replaced by each candidate in turn (the other section is left
        out), with the calibration engine's defaults.
    models : sequence of str, optional
        Catalogue names, all of one section (default: 1c, 2c and the paper's model of
        the config's thermal section, or of its hygric section without one).
    out_dir : path, optional
        Default ``reports/<config name>-compare/``; each candidate's run directory is
        ``<out_dir>/<model>/``; the comparison is ``comparison.json`` and
        ``comparison.html``.
    seed, quiet, report, resume, force
        As for :func:`heritage_bayes.calibration.calibrate.run_calibration` (applied to every
        candidate; with ``force`` a candidate's run and the comparison are written
        beside the files of folders hbayes did not make, replacing none of them: see
        :class:`~heritage_bayes.rundir.folder.OutputFolder`).
    workers : int, optional
        Candidates calibrated at the same time (default: one per core, at most one per
        candidate sampled; 1: one after the other in this process). Each runs in a
        worker process of its own, the largest first, the next started as soon as one
        ends; this process prints a line as each starts and ends and every minute
        meanwhile. The comparison then reads the runs one at a time. Every candidate
        has its own seed-determined chain from its screened MAP, so the results do not
        depend on ``workers``.

    Raises
    ------
    ConfigError
        Unknown model, models of different sections, or a section the config lacks.
    InputError
        ``workers`` below 1.
    """
    import os
    import sys

    from heritage_bayes.calibration.calibrate import run_calibration
    from heritage_bayes.errors import InputError
    from heritage_bayes.rundir import check_name
    from heritage_bayes.rundir.folder import OutputFolder
    from heritage_bayes.rundir.writer import RunWriter, is_run_directory
    from heritage_bayes.sources import input_paths

    section, names = _section_of(cfg, models)
    built = {n: _candidate_config(cfg, section, n) for n in names}
    cands = {n: c for n, (c, _) in built.items()}
    cand_models = {n: m for n, (_, m) in built.items()}  # each candidate's, built once
    if out_dir is None:
        out_dir = Path("reports") / check_name(f"{cfg.name or 'run'}-compare", what="name")
    if workers is not None and (isinstance(workers, bool) or int(workers) < 1):
        raise InputError(f"--workers: expected a whole number >= 1 (got {workers})")
    kwargs = dict(quiet=quiet, report=report, resume=resume, force=force)

    def tell(msg: str) -> None:
        if not quiet:
            print(f"hbayes compare: {msg}", file=sys.stderr, flush=True)

    if seed is not None:  # the screen's MAPs and the chains: the same seed
        from heritage_bayes.config import MAX_SEED

        if not 0 <= int(seed) <= MAX_SEED:
            raise InputError(f"--seed: must be within 0..{MAX_SEED} (got {seed})")
        cands = {n: c.model_copy(update={"seed": int(seed)}) for n, c in cands.items()}
    folder = OutputFolder(out_dir, kind="comparison", protect=input_paths(cfg), force=force)
    with folder:
        out = folder.path
        # a candidate's folder: new, its own run, or (--force) one the run writes beside
        folder.claim(*names, folders_from=lambda q: force or is_run_directory(q))
        folder.claim("comparison.json", "comparison.html")
        for n in names:  # refuse a bad folder before any candidate starts
            RunWriter(out / n, force=force, resume=resume).check()
        tell(f"screening {', '.join(names)} by their MAP (validation FIT)")
        rows, maps, scores = screen_candidates(cands, cand_models, section, tell=tell)
        sel = choose([r for r in rows.values() if "error" not in r])  # as model: auto
        tell(f"the screen chose {sel['choice']}: {sel['reason']}")
        sampled = to_sample(sel)
        verdicts = {
            n: sampled[n] if n in sampled else f"screened out: {rows[n].get('error', 'no score')}"
            for n in names
        }
        keep = [n for n in names if verdicts[n] is None]
        for n in names:
            if verdicts[n] is not None:
                tell(f"{n}: {verdicts[n]}")
        n_workers = min(len(keep), int(workers) if workers else (os.cpu_count() or 1))
        dirs = {}
        if n_workers <= 1:
            for n in keep:
                tell(f"sampling {n}")
                dirs[n] = run_calibration(
                    cands[n], out / n, **kwargs, start_maps={section: maps[n]}
                )
        else:
            tell(f"sampling {', '.join(keep)}, {n_workers} at a time")
            per = {n: {**kwargs, "start_maps": {section: maps[n]}} for n in keep}
            keep_cands = {n: cands[n] for n in keep}
            dirs = _sample_parallel(keep_cands, cand_models, out, per, n_workers, tell)
        dirs = {n: dirs[n] for n in keep}
        release_memory()
        tell("comparing the posteriors (blocked LOO, validation ELPD)")
        result = compare_runs(
            dirs,
            section,
            seed=cfg.seed if seed is None else int(seed),
            screen_rows=[r for r in rows.values() if "error" not in r],
        )
        result["screen"] = {
            "rule": rule_text(sel["score"], sel["margin"]),
            "rows": [rows[n] for n in names],
            "sampled": keep,
        }
        result["screened_out"] = {
            n: {"model": n, "map_validation_fit": _finite(scores[n]), "reason": verdicts[n]}
            for n in names
            if verdicts[n] is not None
        }
        result["config"] = {"name": cfg.name, "building": cfg.building, "room": cfg.room}
        write_comparison(result, out)
    return out


def _finite(x: float) -> float | None:
    return float(x) if x == x else None
