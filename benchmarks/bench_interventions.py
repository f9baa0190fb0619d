"""Interventions benchmark (issue 29): posterior draws × 30 years hourly × 4 scenarios
(+ the baseline) × 3 measures (conservation heating, a dehumidifier, half the
ventilation) on thermal_2c + hygric_2c, noise draws and every risk indicator included.

Target (issue 29): 1000 draws × 30 y × 4 scenarios × 3 measures <= 4 min on two cores.

Measured in one run, per measure, :func:`heritage_bayes.projection.engine.simulate_cases`
with ``measure=`` (the same draws, noise and weather as doing nothing): wall, CPU
(user + sys of the process, all threads), the controllers' share (``simulate``) and
peak RSS; linear in draws, so extrapolated to 1000 draws. The cases, draws and noise are
those of ``bench_projection.py`` (the demo's TMY3 year repeated; +1…+4 K at constant
outdoor RH).

Run from the repository root: ``python benchmarks/bench_interventions.py [--draws N]
[--years Y] [--chunk C]``. The machine is shared: the load average is printed; compare
CPU seconds when it is high.
"""

from __future__ import annotations

import argparse
import os
import resource
import time
from types import SimpleNamespace

import numba
import numpy as np

import heritage_bayes as hb
from bench_projection import SCENARIOS, _draws, _inputs_years, _scenario
from heritage_bayes.projection.engine import simulate_cases
from heritage_bayes.projection.interventions import Measure

TARGET_DRAWS, TARGET_S = 1000, 240.0
MEASURES = (
    Measure("conservation heating", heating=(0.65, -273.15, 22.0, 5000.0)),
    Measure("dehumidifier", dehumidifier=(0.60, 1.0 / 3600, 0.7)),
    Measure("half the ventilation", ventilation=0.5),
)


def main() -> int:
    ap = argparse.ArgumentParser()
    ap.add_argument("--draws", type=int, default=20)
    ap.add_argument("--years", type=int, default=30)
    ap.add_argument("--chunk", type=int, default=20)
    args = ap.parse_args()
    models = {"thermal": hb.model("thermal_2c"), "hygric": hb.model("hygric_2c")}
    run = SimpleNamespace(models=models, summary={"dt": 3600.0, "init_steps": 720}, path="bench")
    base = _inputs_years(args.years)
    cases = [base, *[_scenario(base, d) for d in SCENARIOS]]
    K, N = args.draws, len(base)
    draws = _draws(models, K)
    print(
        f"interventions: {K} draws × {N} h ({args.years} years) × {len(cases)} cases "
        f"(baseline + 4 scenarios) × {len(MEASURES)} measures; {numba.get_num_threads()} "
        f"threads; load average {os.getloadavg()[0]:.1f} (shared 2-core machine)"
    )
    for m in MEASURES:  # compile / load the compiled code outside the timing
        simulate_cases(run, _draws(models, 2), [base.iloc[:8760]], seed=1, chunk=2, measure=m)
    total_wall = total_cpu = 0.0
    for m in MEASURES:
        t0, c0 = time.perf_counter(), time.process_time()
        res = simulate_cases(run, draws, cases, seed=1, chunk=args.chunk, measure=m)
        wall, cpu = time.perf_counter() - t0, time.process_time() - c0
        total_wall += wall
        total_cpu += cpu
        ctrl = sum(r.seconds["simulate"] for r in res)
        costs = {c: float(np.median(res[1].costs[c])) for c in res[1].costs.columns}
        print(
            f"  {m.name:22s}: wall {wall:6.1f} s, CPU {cpu:6.1f} s (controllers/modal "
            f"{ctrl:.1f} s); {wall / (K * N * len(cases)) * 1e9:.0f} ns wall per "
            f"draw-hour-case; median costs (+1 K) "
            + ", ".join(f"{c} {v:.4g}" for c, v in costs.items())
        )
    peak = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024**2
    scale = TARGET_DRAWS / K
    full = total_wall * scale
    print(
        f"  all measures: wall {total_wall:.1f} s, CPU {total_cpu:.1f} s, peak RSS "
        f"{peak:.2f} GB; linear in draws at {TARGET_DRAWS}: wall {full:.0f} s, CPU "
        f"{total_cpu * scale:.0f} s -> target <= {TARGET_S:.0f} s "
        f"{'met' if full <= TARGET_S else 'NOT met'} (the do-nothing cases not included: "
        f"bench_projection.py); load average now {os.getloadavg()[0]:.1f}"
    )
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
