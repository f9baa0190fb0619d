"""HTML report benchmark: ``hbayes report RUN_DIR`` on a calibration run (issue 5).

Target: <= 20 s for the demo run (``hbayes calibrate configs/demo.yaml``: thermal_4a +
hygric_2c, 15 + 7 free parameters, 4.5 months hourly) on a 2-core machine.

1. Cold: ``hbayes report`` in a fresh Python process (imports included), as a user runs it.
2. Warm: ``write_report`` again in this process (imports done), best of ``--repeat``.

The run directory is not written to: its files are symlinked into a temporary folder
and the report is written there. Run from the repository root::

    python benchmarks/bench_report.py [RUN_DIR]     # default: reports/demo
"""

from __future__ import annotations

import argparse
import subprocess
import sys
import tempfile
import time
from pathlib import Path

from _common import report

TARGET = 20.0  # [s], the limit for the demo run


def _shadow(run_dir: Path, dest: Path) -> Path:
    """A folder with symlinks to the run's files (report.html excluded)."""
    dest.mkdir()
    for p in run_dir.iterdir():
        if p.is_file() and p.name != "report.html":
            (dest / p.name).symlink_to(p.resolve())
    return dest


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("run_dir", nargs="?", default="reports/demo")
    ap.add_argument("--repeat", type=int, default=2)
    args = ap.parse_args(argv)
    run_dir = Path(args.run_dir)
    if not (run_dir / "posterior.nc").is_file():
        print(f"{run_dir}: not a run directory; run `hbayes calibrate configs/demo.yaml` first")
        return 2
    with tempfile.TemporaryDirectory(prefix="hb-bench-report-") as tmp:
        cold_dir = _shadow(run_dir, Path(tmp) / "cold")
        t0 = time.perf_counter()
        subprocess.run(
            [
                sys.executable,
                "-c",
                "import sys; from heritage_bayes.cli import main; "
                "sys.exit(main(['report', sys.argv[1], '--quiet']))",
                str(cold_dir),
            ],
            check=True,
        )
        cold = time.perf_counter() - t0
        size = (cold_dir / "report.html").stat().st_size
        report(f"hbayes report, fresh process ({run_dir.name})", cold, TARGET)

        from heritage_bayes.report import write_report

        best = float("inf")
        for i in range(max(1, args.repeat)):
            warm_dir = _shadow(run_dir, Path(tmp) / f"warm{i}")
            t0 = time.perf_counter()
            write_report(warm_dir)
            best = min(best, time.perf_counter() - t0)
        report("write_report, imports done (best)", best, TARGET)
    print(f"{'report.html size':<58s} {size / 1e6:9.2f} MB")
    return 0 if cold <= TARGET else 1


if __name__ == "__main__":
    raise SystemExit(main())
