"""Compile the package's numba kernels into their on-disk cache before the tests.

Every kernel is ``cache=True``: the first process to compile one writes it beside the
sources and later processes load it. On a fresh clone the cache is empty, and each
pytest worker, and every ``hbayes`` subprocess a test starts before a kernel is written,
compiles the same kernels again. This script runs two tiny workloads (a calibration
with a coupled sorption model, and projections with measures and risk indicators), one
per process, so that the test run starts with the cache filled. It only fills the
cache: what the tests check is unchanged.

Usage: ``python .ci/warm_kernels.py`` (from the checkout, with the package installed).
"""

from __future__ import annotations

import sys
import tempfile
import time
from concurrent.futures import ProcessPoolExecutor
from pathlib import Path

TESTS = Path(__file__).resolve().parents[1] / "tests"


def _calibrate(raw: dict, out: Path) -> Path:
    from heritage_bayes.calibration.calibrate import run_calibration
    from heritage_bayes.config import parse_config

    run_calibration(parse_config(raw), out_dir=out, report=False, quiet=True)
    return out


def _job(which: str) -> float:
    sys.path.insert(0, str(TESTS))
    from heritage_bayes.projection import project
    from test_pages_agree import PROJ as MEASURES
    from test_projection import PROJ
    from test_report import TINY

    t0 = time.perf_counter()
    with tempfile.TemporaryDirectory() as tmp:
        tmp = Path(tmp)
        budget = {"sampler": {"max_steps": 100, "check_every": 100}, "ladder": False}
        if which == "project":
            run = _calibrate({**TINY, **budget}, tmp / "run")
            project(run, {**PROJ, "draws": 4}, write=False)
            project(run, {**MEASURES, "draws": 4}, write=False)
        else:
            raw = {**TINY, **budget, "thermal": {"model": "thermal_2c"}}
            raw["hygric"] = {"model": "hygric_2c_sorption"}
            run = _calibrate(raw, tmp / "run")
            vent = {"name": "vent", "ventilation": {"factor": 0.5}}
            heat = {"name": "heat", "heating": {"t_set": 12}}
            project(run, {**PROJ, "draws": 4, "interventions": [vent, heat]}, write=False)
    return time.perf_counter() - t0


def main() -> None:
    jobs = ("project", "coupled")
    with ProcessPoolExecutor(2) as pool:
        for name, s in zip(jobs, pool.map(_job, jobs), strict=True):
            print(f"warm_kernels: {name} {s:.0f} s")


if __name__ == "__main__":
    main()
