"""Timing helpers shared by the benchmark scripts."""

from __future__ import annotations

import time


def best_of(fn, repeat: int = 5, number: int = 1) -> float:
    """Best wall time [s] of ``number`` calls of ``fn``, over ``repeat`` runs."""
    best = float("inf")
    for _ in range(repeat):
        t0 = time.perf_counter()
        for _ in range(number):
            fn()
        best = min(best, (time.perf_counter() - t0) / number)
    return best


def report(label: str, seconds: float, target: float | None = None) -> None:
    verdict = "" if target is None else ("  [ok]" if seconds <= target else "  [SLOW]")
    tgt = "" if target is None else f"  (target <= {target * 1e3:.0f} ms)"
    print(f"{label:<58s} {seconds * 1e3:9.2f} ms{tgt}{verdict}")
