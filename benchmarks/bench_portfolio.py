"""Portfolio benchmark: N demo-sized rooms on a 2-worker LocalCluster vs serial (issue 16).

Target: speed-up >= 1.7x on 2 cores. Each room is ``configs/demo.yaml`` with its own
logger seed (the work of one room: data generation, MAP search, emcee to convergence,
run directory; the report and the model-order ladder are switched off here since they
are per-room extras). Both arms run the same task function
(:func:`heritage_bayes.portfolio._room_task`), in the same run:

1. serial: the rooms one after the other in this process (the reference);
2. Dask: ``heritage_bayes.portfolio.run`` on a ``LocalCluster`` of 2 single-threaded
   worker processes.

Prints wall and CPU seconds of both, the speed-up, and the peak resident memory of each
worker. Run from the repository root::

    python benchmarks/bench_portfolio.py [--rooms 8] [--workers 2]
"""

from __future__ import annotations

import argparse
import os
import resource
import tempfile
import time
from pathlib import Path

import yaml

ROOT = Path(__file__).resolve().parents[1]


def _cpu() -> float:
    self_ = resource.getrusage(resource.RUSAGE_SELF)
    return self_.ru_utime + self_.ru_stime


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--rooms", type=int, default=8)
    ap.add_argument("--workers", type=int, default=2)
    args = ap.parse_args(argv)

    from threadpoolctl import threadpool_limits

    from heritage_bayes.portfolio import _room_task, load_portfolio, run

    with tempfile.TemporaryDirectory() as tmp:
        tmp = Path(tmp)
        rooms = [
            {
                "name": f"room{i}",
                "config": str(ROOT / "configs" / "demo.yaml"),
                "overrides": {"data": {"demo": {"seed": 100 + i}}},
            }
            for i in range(args.rooms)
        ]
        pf_path = tmp / "bench.yaml"
        pf_path.write_text(
            yaml.safe_dump(
                {"name": "bench", "defaults": {"ladder": False, "report": False}, "rooms": rooms}
            )
        )
        pf = load_portfolio(pf_path)

        load0 = os.getloadavg()
        t0, c0 = time.perf_counter(), _cpu()
        with threadpool_limits(limits=1, user_api="blas"):
            serial = [_room_task(spec, str(tmp / "serial"), False) for spec in pf.rooms]
        t_serial, c_serial = time.perf_counter() - t0, _cpu() - c0
        bad = [r for r in serial if r["status"] != "done"]
        if bad:
            print("serial arm failed:", bad[0]["message"])
            return 1

        t0 = time.perf_counter()
        df = run(pf, tmp / "dask", workers=args.workers, quiet=True)
        t_dask = time.perf_counter() - t0
        load1 = os.getloadavg()
        if not (df["status"] == "done").all():
            print("dask arm failed:", df.loc[df["status"] != "done", "message"].iloc[0])
            return 1

    print(f"{args.rooms} demo-sized rooms (configs/demo.yaml, ladder and report off)")
    print(f"  serial, this process           : {t_serial:8.1f} s wall, {c_serial:8.1f} s CPU")
    print(
        f"  LocalCluster, {args.workers} workers x 1 thread: {t_dask:8.1f} s wall, "
        f"{df['task_cpu_seconds'].sum():8.1f} s CPU in the tasks "
        f"(sum of task wall times {df['task_seconds'].sum():.1f} s)"
    )
    print(f"  speed-up: {t_serial / t_dask:.2f}x  (target >= 1.7x on 2 cores)")
    print(
        f"  machine load average (1 min) before/after: {load0[0]:.2f} / {load1[0]:.2f} "
        f"on {os.cpu_count()} cores: a task CPU time close to the serial one with a longer "
        "wall time means other processes shared the cores"
    )
    print(
        f"  peak resident memory per worker: {df['worker_peak_rss_mb'].max():.0f} MB "
        f"(median over rooms {df['worker_peak_rss_mb'].median():.0f} MB)"
    )
    print(
        f"  converged rooms: serial {sum(r['converged'] for r in serial)}/{args.rooms}, "
        f"dask {int(df['converged'].sum())}/{args.rooms}"
    )
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
