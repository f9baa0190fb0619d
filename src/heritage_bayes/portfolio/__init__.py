"""Portfolios: many rooms calibrated as tasks on ``dask.distributed``.

A heritage agency monitors hundreds of rooms; one calibration takes minutes. A
*portfolio* file lists rooms, each a calibration config (optionally with overrides and
a projection config); every room is one task on a Dask cluster: an embedded
``LocalCluster`` on this machine by default (nothing to start), or an existing scheduler
(``--scheduler tcp://host:8786``) where the user has a cluster of several machines.

Layer: above the run directory (:mod:`heritage_bayes.run`) and the orchestrator
(:mod:`heritage_bayes.calibration.calibrate`); nothing imports this module.

Portfolio file (YAML)::

    name: church_portfolio            # default: the file's stem
    defaults:                         # deep-merged into every room's config (optional)
      sampler: {max_steps: 40000}
    rooms:
      - name: nave                    # run directory <out>/nave/ and the run's name in its
                                      # report (letters, digits, _ . -)
        config: rooms/nave.yaml       # relative to the portfolio file
      - name: crypt
        config: rooms/crypt.yaml
        overrides: {seed: 4}          # deep-merged after `defaults`
        projection: projection.yaml   # optional: `hbayes project` after calibrating

Every config is validated before any work starts; a bad entry is reported by name with
its message (all bad entries at once). A room that fails while it runs (its data, say)
is reported with its message in the table and does not stop the others. Inside a task
the sampler stays single-threaded (BLAS too, see :func:`heritage_bayes.calibration.calibrate.
run_calibration`): the parallelism is across rooms, one Dask worker process per core
with one thread each.

Outputs in ``<out>/``: one run directory per room, ``portfolio.csv`` and
``portfolio.json`` (one row per room: status, convergence, the paper's fit criteria,
band coverage, key derived quantities, risk indicators), and ``index.html`` linking
every room's report with an overview sorted by conservation risk.
"""

from __future__ import annotations

import contextlib
import json
import logging
import os
import sys
import time
from pathlib import Path

import numpy as np
import pandas as pd

from heritage_bayes.errors import InputError
from heritage_bayes.portfolio.page import render_index
from heritage_bayes.portfolio.rooms import _attention_order, _room_task, measured_risk, room_row
from heritage_bayes.portfolio.spec import Portfolio, RoomSpec, load_portfolio
from heritage_bayes.rundir import check_name
from heritage_bayes.rundir.folder import OutputFolder
from heritage_bayes.rundir.signals import DeferSignals
from heritage_bayes.rundir.writer import is_run_directory

__all__ = [
    "Portfolio",
    "RoomSpec",
    "available_cpus",
    "check_workers",
    "load_portfolio",
    "measured_risk",
    "room_row",
    "run",
]


@contextlib.contextmanager
def _client(scheduler: str | None, workers: int | None, n_rooms: int):
    try:
        from distributed import Client, LocalCluster
    except ImportError:
        raise InputError(
            "hbayes batch needs dask.distributed: pip install 'heritage_bayes[dask]'"
        ) from None
    if scheduler:
        try:
            client = Client(scheduler, timeout="10s")
        except (OSError, TimeoutError, ValueError) as exc:
            raise InputError(
                f"--scheduler {scheduler}: could not connect to a Dask scheduler there "
                f"({type(exc).__name__}: {str(exc)[:200]}); start one with `dask scheduler` "
                "and `dask worker ADDRESS`, or leave --scheduler out for a local cluster"
            ) from None
        try:
            yield client
        finally:
            client.close()
        return
    n = workers or min(n_rooms, available_cpus())
    try:
        import bokeh  # noqa: F401  (the dashboard needs it)

        dashboard = ":0"
    except ImportError:
        dashboard = None
    cluster = LocalCluster(
        n_workers=max(1, n),
        threads_per_worker=1,
        processes=True,
        dashboard_address=dashboard,
        silence_logs=logging.ERROR,
    )
    client = Client(cluster)
    try:
        yield client
    finally:
        client.close()
        cluster.close()


def run(
    portfolio: str | Path | Portfolio,
    out_dir: str | Path | None = None,
    *,
    scheduler: str | None = None,
    workers: int | None = None,
    resume: bool = False,
    quiet: bool = False,
    workers_unbounded: bool = False,
) -> pd.DataFrame:
    """Calibrate every room of a portfolio on Dask; return the overview table.

    Parameters
    ----------
    portfolio : path or Portfolio
        The portfolio file (see the module documentation) or its loaded form.
    out_dir : path, optional
        Default ``reports/<portfolio name>/``. Each room writes ``<out_dir>/<room>/``.
    scheduler : str, optional
        Address of a running Dask scheduler (``tcp://host:8786``); default an embedded
        ``LocalCluster`` with one single-threaded worker process per core.
    workers : int, optional
        Workers of the local cluster (default: one per available CPU, at most one per
        room); at most :func:`available_cpus` unless ``workers_unbounded``.
    resume : bool
        Skip rooms whose run directory holds a finished run of the same config, and
        continue rooms with saved chains.
    quiet : bool
        No progress bar.
    workers_unbounded : bool
        Allow more workers than CPUs available.

    Returns
    -------
    pandas.DataFrame
        One row per room in attention order (see ``index.html``), also written to
        ``portfolio.csv`` and ``portfolio.json``.
    """
    pf = portfolio if isinstance(portfolio, Portfolio) else load_portfolio(portfolio)
    check_workers(workers, unbounded=workers_unbounded)
    folder = OutputFolder(
        Path(out_dir) if out_dir is not None else Path("reports") / check_name(pf.name),
        kind="portfolio",
        protect=_input_files(pf),
    )
    try:
        with folder:
            folder.claim(*(s.name for s in pf.rooms), folders_from=is_run_directory)
            folder.claim("portfolio.csv", "portfolio.json", "index.html")
            return _run(pf, folder.path, scheduler, workers, resume, quiet)
    except PermissionError as exc:
        raise InputError(f"--out {folder.path}: cannot write ({exc.strerror})") from None


def available_cpus() -> int:
    """CPUs this process may run on (its affinity mask, e.g. a container's or
    ``taskset``'s share), else ``os.cpu_count()``."""
    try:
        return len(os.sched_getaffinity(0)) or 1
    except (AttributeError, OSError):
        return os.cpu_count() or 1


def check_workers(workers: int | None, *, unbounded: bool = False) -> None:
    """Raise InputError for ``--workers`` below 1, or above :func:`available_cpus`
    unless ``unbounded`` (each worker is a process running one calibration: more of
    them than CPUs only slows every room down and multiplies the memory)."""
    if workers is None:
        return
    if workers < 1:
        raise InputError(f"--workers: expected a whole number >= 1 (got {workers})")
    n = available_cpus()
    if workers > n and not unbounded:
        raise InputError(
            f"--workers: {workers} is more than the {n} CPU(s) available to this process; "
            f"give at most {n}, or add --workers-unbounded to start {workers} anyway"
        )


def _input_files(pf: Portfolio) -> list[Path]:
    """The portfolio file's folder, each room's config folder and data files."""
    from heritage_bayes.config import parse_config
    from heritage_bayes.sources import input_paths

    found = [pf.path.resolve().parent]
    for spec in pf.rooms:
        cfg = parse_config(spec.raw, source=str(spec.config_path), base_dir=spec.base_dir)
        found += input_paths(cfg)
        found += [spec.projection] if spec.projection is not None else []
    return found


def _run(pf: Portfolio, out: Path, scheduler, workers, resume: bool, quiet: bool):
    rows: list[dict] = []
    t0 = time.perf_counter()
    with _client(scheduler, workers, len(pf.rooms)) as client:
        from distributed import as_completed

        link = _dashboard(client)
        if not quiet:
            where = scheduler or f"a local cluster of {len(client.scheduler_info()['workers'])}"
            print(f"hbayes batch: {len(pf.rooms)} room(s) of {pf.name!r} on {where} worker(s)")
            if link:
                print(f"Dask dashboard: {link}")
        futures = [
            client.submit(_room_task, spec, str(out), resume, key=f"room-{spec.name}", pure=False)
            for spec in pf.rooms
        ]
        bar = None
        if not quiet and sys.stderr.isatty():
            from tqdm import tqdm

            bar = tqdm(
                total=len(futures), desc=pf.name, unit="room", mininterval=1.0, file=sys.stderr
            )
        try:
            for fut in as_completed(futures):
                row = fut.result()
                rows.append(row)
                if bar is not None:
                    bar.set_postfix_str(f"{row['room']}: {row['status']}", refresh=False)
                    bar.update(1)
                elif not quiet:  # a log file: one plain line per room
                    print(
                        f"[{pf.name}] {len(rows)}/{len(futures)} rooms: {row['room']} "
                        f"{row['status']} ({row['task_seconds']:.0f} s)",
                        file=sys.stderr,
                        flush=True,
                    )
                _write_outputs(pf, out, rows, time.perf_counter() - t0)
        finally:
            if bar is not None:
                bar.close()
            for f in futures:
                f.cancel()
    df = _write_outputs(pf, out, rows, time.perf_counter() - t0)
    if not quiet:
        n_ok = int(df["status"].isin(["done", "skipped"]).sum())
        print(f"{n_ok} of {len(df)} room(s) calibrated; overview: {out / 'index.html'}")
    return df


def _dashboard(client) -> str | None:
    try:
        link = client.dashboard_link
    except Exception:  # no dashboard (bokeh not installed)
        return None
    return link or None


def _table(rows: list[dict], pf: Portfolio) -> pd.DataFrame:
    order = {spec.name: i for i, spec in enumerate(pf.rooms)}
    df = pd.DataFrame(rows)
    df = df.iloc[np.argsort([order[r] for r in df["room"]], kind="stable")]
    return _attention_order(df.reset_index(drop=True))


def _write_outputs(pf: Portfolio, out: Path, rows: list[dict], seconds: float) -> pd.DataFrame:
    """``portfolio.csv``, ``portfolio.json`` and ``index.html``, rendered first and
    written as a group (SIGINT/SIGTERM wait until all three are written)."""
    from heritage_bayes.convert import to_jsonable
    from heritage_bayes.inference.results import atomic_write, atomic_write_text

    df = _table(rows, pf)
    meta = {
        "portfolio": pf.name,
        "source": str(pf.path),
        "rooms_total": len(pf.rooms),
        "rooms_finished": len(rows),
        "wall_seconds": seconds,
        "rows": df.to_dict(orient="records"),
    }
    text = json.dumps(to_jsonable(meta), indent=1)
    page = render_index(pf, df, out)
    with DeferSignals():
        atomic_write(out / "portfolio.csv", lambda p: df.to_csv(p, index=False))
        atomic_write_text(out / "portfolio.json", text)
        atomic_write_text(out / "index.html", page)
    return df
