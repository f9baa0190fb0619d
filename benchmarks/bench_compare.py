"""Issue 28's end-to-end figures: ``hbayes compare``, a run directory, a portfolio.

Runs the command as a user would, in a fresh output folder, and prints its wall time,
the CPU time of the whole process tree (user + system, workers included), the peak of
the summed resident memory of the process tree (sampled every 0.2 s with psutil), both
as RSS (each process's resident pages, so the shared libraries that every process of
the tree maps are counted once per process: an upper bound) and as PSS (each shared
page divided among the processes that map it: what the machine had to hold at once),
and the bytes it wrote (``du -b`` per file and in
all). Targets of issue 28: compare ≤ 5 min wall on two cores, ≤ 1 GB peak, ≤ 100 MB
on disk; a demo run directory ≤ 15 MB; the portfolio demo ≤ 60 MB.

    python benchmarks/bench_compare.py compare [--config configs/demo.yaml] [--out DIR]
    python benchmarks/bench_compare.py calibrate [--config configs/demo.yaml]
    python benchmarks/bench_compare.py batch [--config configs/portfolio_demo.yaml]

Extra arguments after ``--`` go to the command (e.g. ``-- --workers 1``). On a machine
shared with other jobs wall time is inflated; CPU time is the figure to compare.
"""

from __future__ import annotations

import argparse
import os
import resource
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import psutil

ROOT = Path(__file__).resolve().parents[1]
DEFAULT_CONFIG = {
    "compare": "configs/demo.yaml",
    "calibrate": "configs/demo.yaml",
    "batch": "configs/portfolio_demo.yaml",
}


def _tree(proc: psutil.Process) -> list[psutil.Process]:
    try:
        return [proc, *proc.children(recursive=True)]
    except psutil.NoSuchProcess:
        return []


def run_measured(cmd: list[str], poll: float = 0.2) -> dict:
    """Run ``cmd``; wall [s], CPU [s] of the tree, peak summed RSS and PSS [bytes], exit
    code (PSS where the system reports it: Linux; else equal to RSS)."""
    t0 = time.perf_counter()
    child = subprocess.Popen(cmd, cwd=ROOT)
    proc = psutil.Process(child.pid)
    peak = peak_pss = 0
    while child.poll() is None:
        rss = pss = 0
        for p in _tree(proc):
            try:
                mem = p.memory_full_info()
            except psutil.NoSuchProcess:
                continue
            rss += mem.rss
            pss += getattr(mem, "pss", mem.rss)
        peak, peak_pss = max(peak, rss), max(peak_pss, pss)
        time.sleep(poll)
    wall = time.perf_counter() - t0
    # every descendant was waited for by its parent: RUSAGE_CHILDREN holds them all
    ru = resource.getrusage(resource.RUSAGE_CHILDREN)
    return {
        "wall": wall,
        "cpu": ru.ru_utime + ru.ru_stime,
        "peak_rss": peak,
        "peak_pss": peak_pss,
        "returncode": child.returncode,
    }


def disk_usage(folder: Path) -> tuple[int, list[tuple[int, str]]]:
    """Bytes in all files under ``folder`` and (bytes, relative path) per file."""
    files = sorted(
        ((p.stat().st_size, str(p.relative_to(folder))) for p in folder.rglob("*") if p.is_file()),
        reverse=True,
    )
    return sum(b for b, _ in files), files


def main(argv: list[str] | None = None) -> int:
    argv = sys.argv[1:] if argv is None else argv
    extra = argv[argv.index("--") + 1 :] if "--" in argv else []
    argv = argv[: argv.index("--")] if "--" in argv else argv
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("command", choices=tuple(DEFAULT_CONFIG))
    ap.add_argument("--config", default=None)
    ap.add_argument("--out", default=None, help="output folder (default: a new temporary one)")
    ap.add_argument("--files", type=int, default=15, help="largest files listed")
    args = ap.parse_args(argv)
    config = args.config or DEFAULT_CONFIG[args.command]
    out = Path(args.out or tempfile.mkdtemp(prefix=f"bench-{args.command}-")) / "out"
    hbayes = [sys.executable, "-m", "heritage_bayes.cli"]
    cmd = [*hbayes, args.command, config, "--out", str(out), "--quiet", *extra]
    env_threads = {k: os.environ.get(k) for k in ("OPENBLAS_NUM_THREADS", "OMP_NUM_THREADS")}
    print(f"$ {' '.join(cmd)}   (BLAS threads: {env_threads}, {os.cpu_count()} CPUs)", flush=True)
    m = run_measured(cmd)
    total, files = disk_usage(out) if out.exists() else (0, [])
    print(
        f"{args.command} {config}: exit {m['returncode']}, wall {m['wall']:.1f} s, CPU "
        f"{m['cpu']:.1f} s, peak memory of the process tree {m['peak_pss'] / 1e9:.2f} GB PSS "
        f"({m['peak_rss'] / 1e9:.2f} GB RSS), "
        f"on disk {total / 1e6:.1f} MB in {len(files)} files ({out})",
        flush=True,
    )
    for b, name in files[: args.files]:
        print(f"  {b / 1e6:9.2f} MB  {name}")
    return 0 if m["returncode"] in (0, 3) else 1


if __name__ == "__main__":
    raise SystemExit(main())
