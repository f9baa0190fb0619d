"""Interventions benchmark (issue 29): posterior draws × 30 years hourly × 4 scenarios
(+ the baseline, which every measure needs for its EN 15757 band) × 3 measures
(conservation heating, a dehumidifier, half the ventilation) on thermal_2c + hygric_2c,
noise draws and every risk indicator included.

Target (issue 29): 1000 draws × 30 y × 4 scenarios × 3 measures <= 4 min on two cores.

Two parts, one run:

1. **ratio** at a small size (``--ref-draws``, all cases and measures): the previous
   implementation (doing nothing, then each measure by its own
   :func:`~heritage_bayes.projection.engine.simulate_cases` call with
   ``compiled=False``: ``ControlledModel.forward`` per chunk, noise drawn again per
   measure) against the current one (:func:`~heritage_bayes.projection.engine.simulate_measures`:
   one pass, noise and weather shared, both models stepped together with their
   controllers in the compiled pass, draws over the threads, the measures' noise-free
   indicators skipped). Wall and CPU of each, their ratio.
2. **full size** (``--draws``): the current implementation, doing nothing and the three
   measures in one pass; wall, CPU (user + sys of the process, all threads), the
   measures' share (the seconds the engine books to them), peak RSS.

Run from the repository root: ``python benchmarks/bench_interventions.py [--draws N]
[--ref-draws R] [--years Y] [--chunk C]``. The machine is shared: the load average is
printed; compare CPU seconds when it is high.
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
from heritage_bayes.projection.engine import simulate_cases, simulate_measures
from heritage_bayes.projection.interventions import Measure

TARGET_DRAWS, TARGET_S = 1000, 240.0
MEASURES = (
    Measure("conservation heating", heating=(0.65, -273.15, 22.0, 5000.0)),
    Measure("dehumidifier", dehumidifier=(0.60, 1.0 / 3600, 0.7)),
    Measure("half the ventilation", ventilation=0.5),
)


def _timed(f):
    t0, c0 = time.perf_counter(), time.process_time()
    out = f()
    return out, time.perf_counter() - t0, time.process_time() - c0


def _previous(run, draws, cases, chunk):
    nothing = simulate_cases(run, draws, cases, seed=1, chunk=chunk)
    per = {m.name: simulate_cases(run, draws, cases, seed=1, chunk=chunk, measure=m,
                                  compiled=False) for m in MEASURES}  # fmt: skip
    return nothing, per


def _current(run, draws, cases, chunk):
    return simulate_measures(run, draws, cases, list(MEASURES), seed=1, chunk=chunk)


def main() -> int:
    ap = argparse.ArgumentParser()
    ap.add_argument("--draws", type=int, default=1000)
    ap.add_argument("--ref-draws", type=int, default=8)
    ap.add_argument("--years", type=int, default=30)
    ap.add_argument("--chunk", type=int, default=50)
    args = ap.parse_args()
    models = {"thermal": hb.model("thermal_2c"), "hygric": hb.model("hygric_2c")}
    run = SimpleNamespace(models=models, summary={"dt": 3600.0, "init_steps": 720}, path="bench")
    base = _inputs_years(args.years)
    cases = [base, *[_scenario(base, d) for d in SCENARIOS]]
    N = len(base)
    print(
        f"interventions: {N} h ({args.years} years) × {len(cases)} cases (baseline + 4 "
        f"scenarios) × {len(MEASURES)} measures + doing nothing; "
        f"{numba.get_num_threads()} threads; load average {os.getloadavg()[0]:.1f} "
        "(shared 2-core machine)",
        flush=True,
    )
    small = [base.iloc[:8760]]
    _previous(run, _draws(models, 2), small, 2)  # compile / load outside the timing
    _current(run, _draws(models, 2), small, 2)

    R = args.ref_draws
    (n0, p0), w0, c0 = _timed(lambda: _previous(run, _draws(models, R), cases, args.chunk))
    (n1, p1), w1, c1 = _timed(lambda: _current(run, _draws(models, R), cases, args.chunk))
    dev = max(
        float(np.nanmax(np.abs(a.predictive["twpi"] - b.predictive["twpi"])
                        / b.predictive["twpi"]))
        for m in MEASURES for a, b in zip(p1[m.name], p0[m.name], strict=True)
    )  # fmt: skip
    print(
        f"ratio at {R} draws: previous wall {w0:.1f} s, CPU {c0:.1f} s; current wall "
        f"{w1:.1f} s, CPU {c1:.1f} s -> {w0 / w1:.1f}x wall, {c0 / c1:.1f}x CPU "
        f"(largest relative difference of a measure's TWPI between the two: {dev:.1e}); "
        f"load average {os.getloadavg()[0]:.1f}",
        flush=True,
    )

    K = args.draws
    draws = _draws(models, K)
    (nothing, per), wall, cpu = _timed(lambda: _current(run, draws, cases, args.chunk))
    booked = {
        name: sum(r.seconds["simulate"] + r.seconds["risk"] for r in rs)
        for name, rs in [("doing nothing", nothing), *per.items()]
    }
    total_booked = sum(booked.values())
    for name, sec in booked.items():
        rs = nothing if name == "doing nothing" else per[name]
        costs = rs[1].costs
        med = ", ".join(f"{c} {float(np.median(costs[c])):.4g}" for c in costs.columns)
        print(
            f"  {name:22s}: {sec:6.1f} s booked ({100 * sec / total_booked:.0f} %)"
            + (f"; median costs (+1 K): {med}" if med else ""),
            flush=True,
        )
    share = 1.0 - booked["doing nothing"] / total_booked
    peak = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024**2
    scale = TARGET_DRAWS / K
    full = wall * share * scale
    print(
        f"full: {K} draws, one pass (doing nothing + {len(MEASURES)} measures): wall "
        f"{wall:.1f} s, CPU {cpu:.1f} s, peak RSS {peak:.2f} GB; the measures' share "
        f"{100 * share:.0f} %: wall {wall * share:.0f} s, CPU {cpu * share:.0f} s"
        + (f" (x{scale:.2f} to {TARGET_DRAWS} draws: wall {full:.0f} s)" if K != TARGET_DRAWS
           else "")
        + f" -> target <= {TARGET_S:.0f} s {'met' if full <= TARGET_S else 'NOT met'} in "
        f"this wall time; CPU {cpu * share * scale:.0f} s against the {2 * TARGET_S:.0f} "
        f"CPU-seconds of two cores: {'met' if cpu * share * scale <= 2 * TARGET_S else 'NOT met'}; "
        f"doing nothing included: wall {wall * scale:.0f} s; load average now "
        f"{os.getloadavg()[0]:.1f}",
        flush=True,
    )  # fmt: skip
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
