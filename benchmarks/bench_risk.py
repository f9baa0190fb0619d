"""Conservation-risk benchmark: all indicators over 1000 posterior draws × 1 year hourly.

1. ``assess_batch`` on 1000 draws × 8760 h (target: a few seconds; the issue asks for it
   to be usable on posterior draws), against a per-draw loop of ``assess`` measured on a
   subset in the same run and scaled to 1000 draws.
2. The VTT mould-index recursion over 1000 draws × 8760 h (numba), against the same
   recursion in pure Python on a few draws, scaled to 1000.

Run from the repository root: ``python benchmarks/bench_risk.py``.
"""

from __future__ import annotations

import time

import numpy as np

from _common import best_of, report
from heritage_bayes.climate import risk
from heritage_bayes.climate.risk._vtt import SENSITIVITY, vtt_loop

DRAWS, HOURS = 1000, 8760
LOOP_SUBSET = 25  # draws timed with the per-draw loop
PY_SUBSET = 2  # draws timed with the pure-Python VTT loop


def make_draws(d: int = DRAWS, n: int = HOURS, seed: int = 0):
    """Posterior-draw-like indoor climates: a damp unheated monument, varied per draw."""
    rng = np.random.default_rng(seed)
    t = np.arange(n)
    amp = rng.uniform(4, 8, (d, 1))
    T = 11 + amp * np.sin(2 * np.pi * (t - 2500) / n) + 1.5 * np.sin(2 * np.pi * t / 24)
    T = T + rng.normal(0, 0.5, (d, n))
    RH = 70 + rng.uniform(5, 12, (d, 1)) * np.sin(2 * np.pi * (t + 1500) / n)
    RH = np.clip(RH + 6 * np.sin(2 * np.pi * t / 24) + rng.normal(0, 2, (d, n)), 0, 100)
    return T, RH


def main() -> int:
    T, RH = make_draws()
    print(f"conservation-risk indicators, {DRAWS} draws x {HOURS} h")
    risk.assess_batch(T[:2], RH[:2])  # compile / load the numba kernel once

    t_batch = best_of(lambda: risk.assess_batch(T, RH), repeat=3)
    report("assess_batch, 1000 draws x 8760 h", t_batch)

    def loop():
        for i in range(LOOP_SUBSET):
            risk.assess(T[i], RH[i])

    t_loop = best_of(loop, repeat=3) * DRAWS / LOOP_SUBSET
    report(f"loop of assess() (measured on {LOOP_SUBSET} draws, scaled)", t_loop)
    print(f"{'ratio loop / batch':<58s} {t_loop / t_batch:9.1f} x")

    # the VTT recursion alone
    k1l, k1h, A, B, C, RHmin, Cmat = SENSITIVITY["VS"]
    args = (k1l, k1h, A, B, C, RHmin, Cmat, 0.0, 0.0, 0.0, True, False)
    t_numba = best_of(lambda: risk.vtt_mould_index(T, RH), repeat=3)
    report("vtt_mould_index (numba), 1000 draws x 8760 h", t_numba)
    t0 = time.perf_counter()
    ref = np.empty((PY_SUBSET, HOURS))
    vtt_loop(T[:PY_SUBSET], RH[:PY_SUBSET], *args, ref)
    t_py = (time.perf_counter() - t0) * DRAWS / PY_SUBSET
    report(f"pure-Python VTT loop (measured on {PY_SUBSET} draws, scaled)", t_py)
    print(f"{'ratio Python / numba':<58s} {t_py / t_numba:9.1f} x")
    got = risk.vtt_mould_index(T[:PY_SUBSET], RH[:PY_SUBSET])
    if not np.allclose(got, ref, rtol=1e-12, atol=0.0):
        print("ERROR: numba and Python VTT recursions differ")
        return 1
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
