"""`hbayes init` on the raw TRH-1 attic files, then the full `hbayes calibrate` (issue 30).

The done-when of issue 30: init on the logger and FMI weather files of the TRH-1 attic
(``../shared/data/trh1-espoo-attic/``; not the shipped config) writes a config that
calibrates to a converged result whose validation FIT is within 2 points of
``configs/trh1_attic.yaml``'s, with no hand edit. This script runs both calibrations in
full (MAP, emcee to convergence, ladder, report) and prints, per run and model: converged,
emcee steps, τmax, sampling CPU [s], validation FIT [%]; and the whole run's wall and CPU
time. The CI version is ``tests/test_init.py::test_init_trh1_fit_matches_the_shipped_config``
(MAP fits only).

Usage::

    python benchmarks/bench_init.py [--out DIR] [--no-shipped]
"""

from __future__ import annotations

import argparse
import json
import os
import resource
import sys
import tempfile
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
DATA = ROOT.parent / "shared" / "data" / "trh1-espoo-attic"
SITE = {"latitude": 60.21, "longitude": 24.66}


def _cpu() -> float:
    own = resource.getrusage(resource.RUSAGE_SELF)
    kids = resource.getrusage(resource.RUSAGE_CHILDREN)
    return own.ru_utime + own.ru_stime + kids.ru_utime + kids.ru_stime


def _calibrate(config: Path, out: Path) -> dict:
    from heritage_bayes.calibration.calibrate import run_calibration
    from heritage_bayes.config import load_config

    t0, c0 = time.perf_counter(), _cpu()
    run_calibration(load_config(config), out, quiet=True, force=True)
    wall, cpu = time.perf_counter() - t0, _cpu() - c0
    s = json.loads((out / "summary.json").read_text(encoding="utf-8"))
    rows = {}
    for sec, m in s["models"].items():
        out_name = "Ti" if sec == "thermal" else "Pi"
        ch = m["chain"]
        rows[sec] = {
            "model": m["model"],
            "converged": ch["converged_tau"],
            "steps": ch["steps"],
            "tau_max": ch["tau_max"],
            "sampling_cpu_s": ch["cpu_seconds"],
            "fit_val": s["metrics"][sec][out_name]["validation"]["FIT"],
        }
    return {"converged": s["converged"], "wall_s": wall, "cpu_s": cpu, "models": rows}


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--out", type=Path, help="work folder (default: a temporary one)")
    ap.add_argument("--no-shipped", action="store_true", help="skip configs/trh1_attic.yaml")
    args = ap.parse_args(argv)
    os.environ.setdefault("OPENBLAS_NUM_THREADS", "1")
    from heritage_bayes.init_config import init_config

    work = args.out or Path(tempfile.mkdtemp(prefix="bench_init_"))
    config = work / "attic" / "config.yaml"
    t0 = time.perf_counter()
    res = init_config(
        DATA / "roofmiddle_airmiddle.csv", DATA / "fmi.csv", output=config, force=True, **SITE
    )
    print(f"init: {time.perf_counter() - t0:.1f} s, {len(res.questions)} open question(s)")
    if res.questions:
        print("\n".join(res.questions))
        return 1
    runs = {"init": _calibrate(config, work / "run_init")}
    if not args.no_shipped:
        runs["shipped"] = _calibrate(ROOT / "configs" / "trh1_attic.yaml", work / "run_shipped")
    print(
        f"{'run':<8} {'model':<11} {'conv':<5} {'steps':>6} {'τmax':>6} {'CPU s':>6} {'FIT val':>7}"
    )
    for name, r in runs.items():
        for m in r["models"].values():
            print(
                f"{name:<8} {m['model']:<11} {m['converged']!s:<5} {m['steps']:>6} "
                f"{m['tau_max']:>6.0f} {m['sampling_cpu_s']:>6.0f} {m['fit_val']:>7.1f}"
            )
        print(
            f"{name:<8} whole run: converged={r['converged']}, {r['wall_s']:.0f} s wall, "
            f"{r['cpu_s']:.0f} s CPU"
        )
    ok = runs["init"]["converged"]
    if "shipped" in runs:
        for sec, m in runs["init"]["models"].items():
            ref = runs["shipped"]["models"][sec]["fit_val"]
            d = m["fit_val"] - ref
            ok &= d > -2.0
            print(f"{sec}: validation FIT init - shipped = {d:+.1f} points (within 2: {d > -2})")
    print("done-when met" if ok else "done-when NOT met")
    return 0 if ok else 1


if __name__ == "__main__":
    sys.exit(main())
