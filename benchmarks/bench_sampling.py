"""Sampling benchmark (issue 11): steps, τ, time to convergence and ESS per second.

For the thermal section of the demo (``configs/demo.yaml``), TRH-1 with thermal_2c
(``configs/trh1_attic.yaml``, which itself uses thermal_1c) and TRH-1 4a
(``benchmarks/configs/trh1_attic_4a.yaml``): the
MAP search as ``hbayes calibrate`` does it, then emcee (default DE/snooker moves, the
convergence rule of :func:`heritage_bayes.inference.sampler.run_sampler`: ≥ 50 τ, τ
stable, R-hat ≤ 1.01, bulk ESS ≥ 400) in two coordinate systems, in the same run:

- ``log``: the reference, the sampler's log θ / θ / logit coordinates;
- ``laplace``: whitened by the Laplace approximation at the MAP
  (:func:`heritage_bayes.inference.optimize.affine_coordinates`), x = x0 + L z.

Printed per problem and coordinate system: steps, final τmax, whether it converged,
wall and CPU time of sampling [s], min bulk ESS (in the log coordinates) per CPU second,
and the ratio laplace / log. One core: BLAS single-threaded. The machine may be shared:
CPU time is the figure to compare.

    python benchmarks/bench_sampling.py [demo trh1_2c trh1_4a] [--max-time SECONDS]
"""

from __future__ import annotations

import os

os.environ.setdefault("OPENBLAS_NUM_THREADS", "1")
os.environ.setdefault("OMP_NUM_THREADS", "1")
os.environ.setdefault("MKL_NUM_THREADS", "1")

import argparse
import time
from pathlib import Path

import numpy as np

from heritage_bayes._arviz import az
from heritage_bayes.calibration.ladder import section_log_posterior as _log_posterior
from heritage_bayes.config import load_config
from heritage_bayes.errors import InputError
from heritage_bayes.inference.optimize import affine_coordinates, find_map, laplace
from heritage_bayes.inference.sampler import run_sampler
from heritage_bayes.models import models_of
from heritage_bayes.prepare import prepare

ROOT = Path(__file__).resolve().parents[1]
PROBLEMS = {  # config, thermal model (None: the config's own)
    "demo": (ROOT / "configs" / "demo.yaml", None),
    "trh1_2c": (ROOT / "configs" / "trh1_attic.yaml", "thermal_2c"),
    "trh1_4a": (ROOT / "benchmarks" / "configs" / "trh1_attic_4a.yaml", None),
}


def _problem(path: Path, model_name: str | None = None):
    cfg = load_config(path)
    if model_name is not None:  # e.g. TRH-1 with 2c, which its config no longer uses
        cfg = cfg.model_copy(
            update={"thermal": cfg.thermal.model_copy(update={"model": model_name})}
        )
    models = models_of(cfg)[0]
    prep = prepare(cfg, models)
    model = models["thermal"]
    lp = _log_posterior(cfg, prep, "thermal", model, cfg.thermal.priors)
    m = find_map(
        lp,
        seed=cfg.seed,
        method=cfg.optimizer.method,
        popsize=cfg.optimizer.popsize,
        maxiter=cfg.optimizer.maxiter,
        starts=cfg.optimizer.starts,
    )
    return cfg, lp, m


def _run(label, target, x_start, to_x, bounds, cfg, max_time, **kw):
    """Sample once (``kw``: more arguments of ``run_sampler``) and print a line; returns
    (ChainResult, CPU seconds, min bulk ESS per CPU second)."""
    c0, t0 = time.process_time(), time.perf_counter()
    res = run_sampler(
        target,
        x_start,
        seed=cfg.seed,
        bounds=bounds,
        max_seconds=max_time,
        check_every=cfg.sampler.check_every,
        tau_factor=cfg.sampler.tau_factor,
        **kw,
    )
    cpu, wall = time.process_time() - c0, time.perf_counter() - t0
    X, _ = res.draws(cfg.sampler.max_draws)
    W, D, d = X.shape
    Xx = to_x(X.reshape(-1, d)).reshape(W, D, d)  # ESS in the same (log) coordinates
    ess = float(az.ess(az.convert_to_dataset({"x": Xx}), method="bulk")["x"].min())
    print(
        f"  {label:<8s} steps {res.steps:7d}  τmax {np.nanmax(res.tau):6.0f}  "
        f"converged {res.converged!s:5s}  wall {wall:7.1f} s  CPU {cpu:7.1f} s  "
        f"min ESS {ess:6.0f}  ESS/CPU-s {ess / cpu:7.2f}",
        flush=True,
    )
    return res, cpu, ess / cpu


def main() -> None:
    ap = argparse.ArgumentParser()
    ap.add_argument("problems", nargs="*", default=list(PROBLEMS))
    ap.add_argument("--max-time", type=float, default=1800.0, help="per chain [s]")
    args = ap.parse_args()
    for name in args.problems:
        cfg, lp, m = _problem(*PROBLEMS[name])
        print(f"{name}: {lp.model.name}, {lp.ndim} free parameters, MAP {m.log_post:.1f}")
        _, c_log, r_log = _run("log", lp, m.x, lambda x: x, lp.params.bounds, cfg, args.max_time)
        ref = lp.params.free_names.index("Ci") if "Ci" in lp.params.free_names else None
        lap = laplace(lp, m.x, given=() if ref is None else ("Ci",))
        aff = affine_coordinates(lp, lap)
        try:
            _, c_aff, r_aff = _run(
                "laplace", aff, aff.to_z(m.x)[0], aff.to_x, None, cfg, args.max_time
            )
        except InputError as exc:
            # a near-singular Laplace approximation (a parameter the data leave to its
            # prior) stretches the start ball in z far outside the prior's support
            print(f"  laplace  could not start: {exc}", flush=True)
            continue
        print(f"  laplace / log: CPU {c_aff / c_log:.2f}, ESS/CPU-s {r_aff / r_log:.2f}")


if __name__ == "__main__":
    main()
