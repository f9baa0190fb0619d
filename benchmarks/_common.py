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


def config_map(cfg, section: str):
    """Prepared data, model, log-posterior and MAP of one section of a config, with the
    config's optimiser settings and seed (what ``hbayes calibrate`` does before sampling).
    """
    from threadpoolctl import threadpool_limits

    from heritage_bayes.calibration.ladder import section_log_posterior as _log_posterior
    from heritage_bayes.inference.optimize import find_map
    from heritage_bayes.models import models_of
    from heritage_bayes.prepare import prepare

    opt = cfg.optimizer
    with threadpool_limits(limits=1, user_api="blas"):
        models = models_of(cfg)[0]
        prep = prepare(cfg, models)
        m = models[section]
        lp = _log_posterior(cfg, prep, section, m, getattr(cfg, section).priors)
        mp = find_map(
            lp,
            seed=cfg.seed,
            method=opt.method,
            popsize=opt.popsize,
            maxiter=opt.maxiter,
            starts=opt.starts,
        )
    return prep, m, lp, mp
