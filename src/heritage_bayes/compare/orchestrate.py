"""Calibrating the candidates of a config, each in its own run directory.

Part of :mod:`heritage_bayes.compare` (see its documentation).
"""

from __future__ import annotations

from collections.abc import Sequence
from pathlib import Path

from heritage_bayes._memory import release_memory
from heritage_bayes.compare.core import DEFAULT_MODELS, compare_runs
from heritage_bayes.compare.page import write_comparison
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
    domains = {m: m.split("_")[0] for m in names}
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
    """The config calibrating only ``name`` in ``section`` (same data, noise, knowledge)."""
    from heritage_bayes.models import SECTIONS

    sec = getattr(cfg, section)
    # the configured priors whose parameters exist in this model (as the ladder does)
    from heritage_bayes.calibrate import _parameters
    from heritage_bayes.models import _catalog_options
    from heritage_bayes.rc.catalog import model as catalog_model

    try:
        model = catalog_model(name, **_catalog_options(cfg, section, name))
    except ValueError as exc:
        raise ConfigError(f"--models: {name}: {exc}") from None
    keep = set(model.parameter_names) | {"sigma", "phi"}
    priors = {k: v for k, v in sec.priors.items() if k in keep or k.split("_")[0] in keep}
    new_sec = sec.model_copy(update={"model": name, "priors": priors})
    cand = cfg.model_copy(
        update={
            section: new_sec,
            **{s: None for s in SECTIONS if s != section},
            "ladder": False,
            "name": f"{cfg.name or 'run'}-{name}",
        }
    )
    _parameters(cand, section, model, priors)  # a prior that does not fit fails now
    return cand


def _calibrate_candidate(cand, run_dir: str, kwargs: dict) -> tuple[str, float, float]:
    """One candidate's calibration in a worker process: (run directory, wall [s], CPU
    [s] of the worker)."""
    import time

    from heritage_bayes.calibrate import run_calibration

    t0, c0 = time.perf_counter(), time.process_time()
    out = run_calibration(cand, run_dir, **kwargs)
    return str(out), time.perf_counter() - t0, time.process_time() - c0


def _worker_candidate(cand, run_dir: str, kwargs: dict) -> tuple[str, float, float]:
    """:func:`_calibrate_candidate` in a worker process, where SIGTERM (sent by the
    parent when it is interrupted or fails) ends the calibration as Ctrl-C does: the
    chains saved for ``--resume``, the lock released."""
    import signal

    def stop(signum, frame):
        raise KeyboardInterrupt

    signal.signal(signal.SIGTERM, stop)
    return _calibrate_candidate(cand, run_dir, kwargs)


def _stop_workers(pool) -> None:
    """Cancel the candidates not started; SIGTERM to the running workers, then wait for
    them to save their chains and end (a parent that is interrupted must not wait for
    their whole calibrations)."""
    procs = list((getattr(pool, "_processes", None) or {}).values())
    pool.shutdown(wait=False, cancel_futures=True)
    for proc in procs:
        if proc.is_alive():
            proc.terminate()
    for proc in procs:
        proc.join()


def _n_free(cand, section: str) -> int:
    """Free parameters of a candidate's section (the order in which to start them)."""
    from heritage_bayes.models import build_model
    from heritage_bayes.run import section_parameters

    model = build_model(cand, section)
    return section_parameters(cand, section, model)[1].ndim


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
    """Calibrate each candidate model and write the comparison; return its folder.

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
        As for :func:`heritage_bayes.calibrate.run_calibration` (applied to every
        candidate; with ``force`` a candidate's run and the comparison are written
        beside the files of folders hbayes did not make, replacing none of them: see
        :class:`~heritage_bayes.rundir.folder.OutputFolder`).
    workers : int, optional
        Candidates calibrated at the same time (default: one per core, at most one per
        candidate; 1: one after the other in this process). This process calibrates
        the largest model, which starts first so that the longest chain does not wait,
        and ``workers - 1`` worker processes the others, each calibrating one
        candidate and exiting: memory holds one model's calibration per process, and
        no idle parent holds a copy of the libraries. The comparison then reads the
        runs one at a time. Every candidate has its own seed-determined chain, so the
        results do not depend on ``workers``.

    Raises
    ------
    ConfigError
        Unknown model, models of different sections, or a section the config lacks.
    InputError
        ``workers`` below 1.
    """
    import os
    import sys

    from heritage_bayes.calibrate import run_calibration
    from heritage_bayes.errors import InputError
    from heritage_bayes.rundir import check_name
    from heritage_bayes.rundir.folder import OutputFolder
    from heritage_bayes.rundir.writer import is_run_directory
    from heritage_bayes.sources import input_paths

    section, names = _section_of(cfg, models)
    cands = {n: _candidate_config(cfg, section, n) for n in names}
    if out_dir is None:
        out_dir = Path("reports") / check_name(f"{cfg.name or 'run'}-compare", what="name")
    if workers is not None and (isinstance(workers, bool) or int(workers) < 1):
        raise InputError(f"--workers: expected a whole number >= 1 (got {workers})")
    n_workers = min(len(cands), int(workers) if workers else (os.cpu_count() or 1))
    kwargs = dict(seed=seed, quiet=quiet, report=report, resume=resume, force=force)

    def tell(msg: str) -> None:
        if not quiet:
            print(f"hbayes compare: {msg}", file=sys.stderr, flush=True)

    folder = OutputFolder(out_dir, kind="comparison", protect=input_paths(cfg), force=force)
    with folder:
        out = folder.path
        # a candidate's folder: new, its own run, or (--force) one the run writes beside
        folder.claim(*names, folders_from=lambda q: force or is_run_directory(q))
        folder.claim("comparison.json", "comparison.html")
        dirs = {}
        if n_workers <= 1:
            for n, c in cands.items():
                tell(f"calibrating {n}")
                dirs[n] = run_calibration(c, out / n, **kwargs)
        else:
            import multiprocessing
            from concurrent.futures import ProcessPoolExecutor, as_completed

            from heritage_bayes.run import RunWriter

            for n in names:  # refuse a bad folder before any candidate starts
                RunWriter(out / n, force=force, resume=resume).check()
            order = sorted(cands, key=lambda n: -_n_free(cands[n], section))
            # this process calibrates the largest candidate itself, and n_workers - 1
            # worker processes the others: n_workers calibrations at once, as before,
            # without a waiting parent that holds the libraries of a calibration (about
            # 0.3 GB resident) on top of those of the workers (issue 28)
            own, rest = order[0], order[1:]
            tell(f"calibrating {', '.join(order)}, {n_workers} at a time ({own} in this process)")
            ctx = multiprocessing.get_context("spawn")  # no forked numba/BLAS threads
            pool_size = min(n_workers - 1, len(rest))
            with ProcessPoolExecutor(pool_size, mp_context=ctx, max_tasks_per_child=1) as pool:
                quiet_kw = {**kwargs, "quiet": True}
                try:
                    futs = {
                        pool.submit(_worker_candidate, cands[n], str(out / n), quiet_kw): n
                        for n in rest
                    }
                    run_dir, wall, cpu = _calibrate_candidate(cands[own], str(out / own), quiet_kw)
                    dirs[own] = Path(run_dir)
                    tell(f"{own} done ({wall:.0f} s wall, {cpu:.0f} s CPU)")
                    release_memory()  # while the workers run on
                    for f in as_completed(futs):
                        run_dir, wall, cpu = f.result()
                        dirs[futs[f]] = Path(run_dir)
                        tell(f"{futs[f]} done ({wall:.0f} s wall, {cpu:.0f} s CPU)")
                except BaseException:  # Ctrl-C, SIGTERM, a failed candidate: stop them all
                    _stop_workers(pool)
                    raise
            dirs = {n: dirs[n] for n in names}
        result = compare_runs(dirs, section, seed=cfg.seed if seed is None else int(seed))
        result["config"] = {"name": cfg.name, "building": cfg.building, "room": cfg.room}
        write_comparison(result, out)
    return out
