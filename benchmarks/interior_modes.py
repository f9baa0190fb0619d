"""The demo's thermal_4a with the survey's interior area: two optima (issue 28).

``configs/demo.yaml`` (``interior_area: 80``, so a log-normal prior on ``Gint``) with
``thermal.model: thermal_4a``; its data come from a room without an interior mass
(``thermal_2c``, :mod:`heritage_bayes.demo`).

    python benchmarks/interior_modes.py maps [--seeds 1,2,...] [--restarts N]
            [--problem demo_4a|orholm_4a]
        the MAP of each seed of the search (one differential evolution and its polish,
        as hbayes calibrate with optimizer.restarts: 1; or N searches): its
        log-posterior and where it puts the interior mass (orholm_4a:
        configs/orholm.yaml with thermal_4a, benchmarks/configs/orholm_4a.yaml)
    python benchmarks/interior_modes.py mass [--seeds 1,3] [--steps N]
        the chain hbayes calibrate runs from each seed's MAP (at most N steps, default
        40 000), then the posterior mass near it: log Z = log ∫ p(x, y) dx over the
        region a multivariate t (5 degrees of freedom) fitted to the chain's second
        half covers, by importance sampling (20 000 draws, seed 0), for proposals of
        the fitted and of 1.5 × the fitted scale; with the importance sampling's
        effective sample size (how far the estimate can be trusted)
    python benchmarks/interior_modes.py jump [--seeds 1,3] [--jump 0.1] [--steps N]
        the walkers split between the MAPs of two seeds, with emcee's DE move at
        γ = 1 (a mode-hopping step, ter Braak 2006) at the given share: how often a
        walker changes mode, τ per parameter

References: C. J. F. ter Braak, "A Markov chain Monte Carlo version of the genetic
algorithm differential evolution", Stat. Comput. 16 (2006) 239-249.
"""

from __future__ import annotations

import os

os.environ.setdefault("OPENBLAS_NUM_THREADS", "1")

import argparse
import functools
import sys
import time
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parent))

from _common import config_map
from bench_coordinates import PROBLEMS, _config


def _problem(seed: int | None = None, problem: str = "demo_4a"):
    cfg = _config(*PROBLEMS[problem])
    return cfg if seed is None else cfg.model_copy(update={"seed": seed})


def _maps(args) -> None:
    from heritage_bayes.inference.optimize import find_map

    for seed in args.seeds:
        cfg = _problem(seed, args.problem)
        t0 = time.perf_counter()
        _, _, lp, mp = config_map(cfg, "thermal")
        if args.restarts > 1:
            mp = find_map(lp, seed=seed, starts=cfg.optimizer.starts, restarts=args.restarts)
        th = dict(zip(lp.params.names, mp.theta, strict=True))
        th.setdefault("fsol", float("nan"))  # a 4a without solar input has none
        modes = f"; modes {[round(m['log_posterior'], 2) for m in mp.modes]}" if mp.modes else ""
        print(
            f"seed {seed}: log-posterior {mp.log_post:7.2f}  Cw {th['Cw']:.3g} J/K  Cint "
            f"{th['Cint']:.3g} J/K  Gint {th['Gint']:.3g} W/K  fsol {th['fsol']:.3g}  "
            f"({time.perf_counter() - t0:.1f} s){modes}",
            flush=True,
        )


def _chain(found, args, moves=None, seed=1):
    """The chain ``hbayes calibrate --seed SEED`` runs from the first MAP of ``found``
    (its seed, walkers, coordinates, block move and weight), at most ``args.steps``
    steps."""
    import bench_sampling
    from heritage_bayes.calibration.calibrate import identifiability_at_map
    from heritage_bayes.inference.coordinates import sampling_coordinates
    from heritage_bayes.inference.moves import unidentified_block

    prep, model, lp, mp = found[0]
    _, lap = identifiability_at_map(model, lp, mp, prep.dt)
    cfg = _problem(seed)
    res, _, _ = bench_sampling._run(
        "chain",
        lp,
        mp.x,
        lambda x: x,
        lp.params.bounds,
        cfg,
        3600.0,
        moves=moves or cfg.sampler.moves,
        block=unidentified_block(lp, lap),
        block_weight=cfg.sampler.block_weight_for(model.n_states),
        max_steps=args.steps,
        max_draws=cfg.sampler.max_draws,
        coordinates=sampling_coordinates(lp, cfg.sampler.coordinates),
    )
    return lp, res


def _mass(args) -> None:
    from scipy import stats

    rng = np.random.default_rng(0)
    for seed in args.seeds:
        found = [config_map(_problem(seed), "thermal")]
        lp, res = _chain(found, args, seed=seed)
        chain = res.chain
        X = chain[chain.shape[0] // 2 :].reshape(-1, chain.shape[2])
        ic = lp.params.free_names.index("Cint")
        mu, cov = X.mean(axis=0), np.cov(X.T)
        print(
            f"seed {seed}: MAP {found[0][3].log_post:.2f}; median Cint of the chain's second "
            f"half {np.exp(np.median(X[:, ic])):.3g} J/K; log-posterior of its draws: "
            f"median {np.median(np.asarray(lp(X[::50]), dtype=float)):.1f}",
            flush=True,
        )
        for scale in (1.0, 1.5):
            q = stats.multivariate_t(loc=mu, shape=cov * scale, df=5, seed=rng)
            Y = q.rvs(size=20_000)
            lw = np.asarray(lp(Y), dtype=float) - q.logpdf(Y)
            ok = np.isfinite(lw)
            top = lw[ok].max()
            w = np.exp(lw[ok] - top)
            log_z = top + np.log(w.sum() / lw.size)
            print(
                f"  t proposal, {scale} × the chain's covariance: log Z {log_z:.2f}, "
                f"importance-sampling ESS {w.sum() ** 2 / (w**2).sum():.0f} of {lw.size}",
                flush=True,
            )


def _jump(args) -> None:
    import emcee

    from heritage_bayes.inference import monitor, sampler

    found = [config_map(_problem(s), "thermal") for s in args.seeds]
    for s, (*_, m) in zip(args.seeds, found, strict=True):
        print(f"MAP of seed {s}: {m.log_post:.2f}", flush=True)
    ball = sampler.start_ensemble

    def split(logpost, x_map, nwalkers, rng, init_ball, bounds):
        parts = []
        for j, (*_, m) in enumerate(found):
            n = nwalkers // len(found) + (1 if j < nwalkers % len(found) else 0)
            parts.append(ball(logpost, m.x, n, rng, init_ball=init_ball, bounds=bounds))
        return np.vstack([p for p, _ in parts]), np.concatenate([v for _, v in parts])

    sampler.start_ensemble = split
    hop = functools.partial(emcee.moves.DEMove, gamma0=1.0)
    monitor.register_move(
        "split",
        "DE 80 % (less the jumps), snooker 20 %, DE jumps of γ₀ = 1 (--jump)",
        (emcee.moves.DEMove, 0.8 - args.jump),
        (emcee.moves.DESnookerMove, 0.2),
        *(((hop, args.jump),) if args.jump > 0 else ()),
    )
    lp, res = _chain(found, args, moves="split")
    names = lp.params.free_names
    mass = res.chain[..., names.index("Cint")] > np.log(1e6)
    n = mass.shape[0]
    for k in range(10):
        part = mass[k * n // 10 : (k + 1) * n // 10]
        switches = np.abs(np.diff(part.astype(int), axis=0)).mean()
        print(
            f"  tenth {k}: share of walkers with Cint > 1e6 J/K {part.mean():.2f}, mode "
            f"changes per walker and stored step {switches:.4f}"
        )
    taus = ", ".join(f"{a} {t:.0f}" for a, t in zip(names, res.tau, strict=True))
    print(f"  τ per parameter [steps]: {taus}")


def main() -> None:
    ap = argparse.ArgumentParser()
    sub = ap.add_subparsers(dest="what", required=True)

    def seeds(text: str) -> list[int]:
        return [int(x) for x in text.split(",")]

    m = sub.add_parser("maps")
    m.add_argument("--seeds", type=seeds, default=[1, 2, 3, 4, 5, 6, 7])
    m.add_argument("--restarts", type=int, default=1)
    m.add_argument("--problem", default="demo_4a", choices=("demo_4a", "orholm_4a"))
    s = sub.add_parser("mass")
    s.add_argument("--seeds", type=seeds, default=[1, 3])
    s.add_argument("--steps", type=int, default=40_000)
    j = sub.add_parser("jump")
    j.add_argument("--seeds", type=seeds, default=[1, 3])
    j.add_argument("--jump", type=float, default=0.1)
    j.add_argument("--steps", type=int, default=40_000)
    args = ap.parse_args()
    {"maps": _maps, "mass": _mass, "jump": _jump}[args.what](args)


if __name__ == "__main__":
    main()
