"""τ per parameter: the log coordinates vs node time-constant coordinates (issue 28).

For each problem the MAP is found once (as ``hbayes calibrate`` does), then emcee runs
from the same start with the same seed, the package's moves (DE 80 % / snooker 20 %)
and its convergence rule (≥ 50 τ, τ stable, R-hat ≤ 1.01, bulk ESS ≥ 400), capped by
``--max-steps`` and ``--max-time``, twice in the same run:

- ``log``: the reference, emcee in the sampler's log θ / θ / logit coordinates;
- ``node_tau``: emcee in :class:`heritage_bayes.inference.coordinates.NodeTimeConstants`
  (log C_i replaced by the log of the node time constant C_i / Σ G_ik, and where a solar
  gain is split by a fraction, thermal_4a's ``fsol``, log fI_s by the log of the
  aperture to the air fI_s (1 - fsol) with ``--solar``: measured, not the default).

Both chains are measured in the same coordinates (log θ), so the integrated
autocorrelation time τ [steps] of each parameter is comparable; printed per parameter,
with steps, whether converged, CPU and wall time of sampling [s] and min bulk ESS per
CPU second, and the ratio node_tau / log. BLAS single-threaded; on a shared machine
CPU time is the figure to compare. A τ from a chain shorter than 50 τ is a lower
bound (emcee's estimate): the converged column says which.

The block move of ``hbayes calibrate`` (``sampler.block_weight``: DE within the
parameters the Laplace check flags, taken as calibrate takes them) runs with the
config's weight (0.2 for networks of three or more nodes); ``--block-weights 0,0.2``
runs each weight from the same start and seed, ``--block NAMES`` replaces the flagged
parameters. Each run also prints τ per parameter on the chain's second half.

    python benchmarks/bench_coordinates.py demo_2c demo_4a demo_hygric trh1_2c orholm_4a \\
        [--max-steps N] [--max-time SECONDS] [--only log|node_tau] [--solar] \\
        [--block-weights W,...] [--start ball|laplace] [--save-chain PREFIX]
"""

from __future__ import annotations

import os

os.environ.setdefault("OPENBLAS_NUM_THREADS", "1")
os.environ.setdefault("OMP_NUM_THREADS", "1")
os.environ.setdefault("MKL_NUM_THREADS", "1")

import argparse
import sys
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parent))

import bench_sampling
from _common import config_map
from heritage_bayes.calibration.calibrate import identifiability_at_map
from heritage_bayes.config import load_config
from heritage_bayes.inference.coordinates import node_time_constants
from heritage_bayes.inference.moves import unidentified_block
from heritage_bayes.inference.optimize import laplace
from heritage_bayes.inference.sampler import _tau

ROOT = Path(__file__).resolve().parents[1]
DEMO_ENV = ROOT / "benchmarks" / "configs" / "demo_envelope.yaml"
#: name -> (config, section, model (None: the config's own))
PROBLEMS = {
    "demo_2c": (ROOT / "configs" / "demo.yaml", "thermal", None),
    "demo_4a": (ROOT / "configs" / "demo.yaml", "thermal", "thermal_4a"),
    "demo_2c_env": (ROOT / "benchmarks" / "configs" / "demo_envelope.yaml", "thermal", None),
    "demo_4a_env": (
        ROOT / "benchmarks" / "configs" / "demo_envelope.yaml",
        "thermal",
        "thermal_4a",
    ),
    "demo_hygric": (ROOT / "configs" / "demo.yaml", "hygric", None),
    "trh1_2c": (ROOT / "configs" / "trh1_attic.yaml", "thermal", "thermal_2c"),
    "orholm_4a": (ROOT / "configs" / "orholm.yaml", "thermal", "thermal_4a"),
}


def _config(path: Path, section: str, model_name: str | None):
    cfg = load_config(path)
    if model_name is not None:
        sec = getattr(cfg, section).model_copy(update={"model": model_name})
        cfg = cfg.model_copy(update={section: sec})
    return cfg


def _run(label, lp, mp, coords, cfg, args, moves, walkers=None, hessian=None, block=(), bw=0.0):
    out = bench_sampling._run(
        label,
        lp,
        mp.x,
        lambda x: x,  # the chain is stored in the log coordinates either way
        lp.params.bounds,
        cfg,
        args.max_time,
        moves=moves,
        block=block,
        block_weight=bw,
        nwalkers=walkers,
        max_steps=args.max_steps,
        max_draws=cfg.sampler.max_draws,
        coordinates=coords,
        start_hessian=hessian,
    )
    res = out[0]
    # τ of the chain's second half: without the ensemble's spread from its start ball
    # (the package's rule estimates τ on the whole chain)
    half = _tau(res.chain[res.chain.shape[0] // 2 :])
    print(
        f"  {label}: {res.chain.shape[1]} walkers, τmax {np.nanmax(res.tau):.0f} on the "
        f"whole chain, {np.nanmax(half):.0f} on its second half; acceptance "
        f"{float(np.mean(res.acceptance)):.3f}",
        flush=True,
    )
    return out


def main() -> None:
    ap = argparse.ArgumentParser()
    ap.add_argument("problems", nargs="*", default=list(PROBLEMS))
    ap.add_argument("--max-steps", type=int, default=200_000)
    ap.add_argument("--max-time", type=float, default=1800.0, help="per chain [s]")
    ap.add_argument("--only", choices=("log", "node_tau"), default=None)
    ap.add_argument(
        "--moves",
        default=None,
        help="comma-separated sampler.moves to run in node_tau coordinates (the first is "
        "the reference of the ratios; default: the config's)",
    )
    ap.add_argument(
        "--walkers",
        default=None,
        help="comma-separated ensemble sizes, each run with every --moves in node_tau "
        "coordinates (default: the sampler's, max(32, 2 d + 2))",
    )
    ap.add_argument(
        "--start",
        default="ball",
        help="comma-separated starts of the node_tau runs: ball (the init_ball around the "
        "MAP) and/or laplace (walkers drawn from N(MAP, H^-1), "
        "heritage_bayes.inference.start)",
    )
    ap.add_argument(
        "--solar",
        action="store_true",
        help="node_tau with the split-solar coordinates (log fI_s -> log fI_s (1 - fsol))",
    )
    ap.add_argument(
        "--air-share",
        action="store_true",
        help="node_tau with split fractions (fsol) sampled as log(1 - fsol), the log of "
        "the air's share",
    )
    ap.add_argument(
        "--series",
        action="store_true",
        help="node_tau with a node between exactly two conductances (the envelope's Cw "
        "with Gw, Gi) sampled along the log series conductance and the log ratio",
    )
    ap.add_argument(
        "--block-weights",
        default=None,
        help="comma-separated sampler.block_weight values, each run with every --moves in "
        "node_tau coordinates: the share of steps of the block move on the parameters the "
        "Laplace check flags, as hbayes calibrate takes them (default: the config's)",
    )
    ap.add_argument(
        "--block",
        default=None,
        help="comma-separated parameter names of the block move in place of those the "
        "Laplace check flags (an experiment)",
    )
    ap.add_argument(
        "--p-global",
        type=float,
        default=None,
        help="probability of a global proposal per walker and step of the de_global and "
        "dime moves (heritage_bayes.inference.moves.GlobalDEMove.P_GLOBAL)",
    )
    ap.add_argument(
        "--save-chain",
        default=None,
        help="write each chain (steps, walkers, d) in the log coordinates to "
        "<SAVE_CHAIN>_<problem>_<label>.npz with the free parameters' names",
    )
    ap.add_argument(
        "--seed",
        type=int,
        default=None,
        help="the config's seed (MAP search and sampler; the demo's data keep theirs): "
        "a second chain of the same problem, for the scatter of τ estimated from one chain",
    )
    args = ap.parse_args()
    if args.p_global is not None:
        from heritage_bayes.inference.moves import GlobalDEMove

        GlobalDEMove.P_GLOBAL = args.p_global
    for name in args.problems:
        cfg = _config(*PROBLEMS[name])
        if args.seed is not None:
            cfg = cfg.model_copy(update={"seed": args.seed})
        section = PROBLEMS[name][1]
        prep, model, lp, mp = config_map(cfg, section)
        _, lap = identifiability_at_map(model, lp, mp, prep.dt)
        block = unidentified_block(lp, lap)
        if args.block:
            block = [lp.params.free_names.index(n) for n in args.block.split(",")]
        weights = (
            [float(w) for w in args.block_weights.split(",")]
            if args.block_weights
            else [cfg.sampler.block_weight_for(model.n_states)]
        )
        coords = node_time_constants(
            lp, solar=args.solar, air_share=args.air_share, series=args.series
        )
        print(
            f"{name}: {model.name}, {lp.ndim} free parameters, MAP {mp.log_post:.1f}; "
            f"{len(coords.nodes) if coords else 0} node(s) and "
            f"{sum(len(g) for *_, g in coords.splits) if coords else 0} split solar "
            "aperture(s) re-coordinated; block move on "
            f"{[lp.params.free_names[i] for i in block]}",
            flush=True,
        )
        runs = {}
        moves = args.moves.split(",") if args.moves else [cfg.sampler.moves]
        if args.only != "node_tau":
            runs["log"] = _run("log", lp, mp, None, cfg, args, moves[0], block=block, bw=weights[0])
        sizes = [int(w) for w in args.walkers.split(",")] if args.walkers else [None]
        starts = args.start.split(",")
        hessian = laplace(lp, mp.x).hessian if "laplace" in starts else None
        for start in starts if args.only != "log" else ():
            for w in sizes:
                for m, bw in ((m, bw) for m in moves for bw in weights):
                    label = "node_tau" + (f"/{m}" if len(moves) > 1 else "")
                    label += f"/{w}w" if w is not None else ""
                    label += f"/{start}" if len(starts) > 1 else ""
                    label += f"/bw{bw:g}" if len(weights) > 1 else ""
                    h = hessian if start == "laplace" else None
                    runs[label] = _run(label, lp, mp, coords, cfg, args, m, w, h, block, bw)
        names = lp.params.free_names
        for label, (res, _, _) in runs.items() if args.save_chain else ():
            out = f"{args.save_chain}_{name}_{label.replace('/', '_')}.npz"
            np.savez_compressed(out, chain=res.chain, names=np.array(names))
        print("  τ per parameter [steps]: " + "  ".join(f"{n:>8s}" for n in names))
        for label, (res, _, _) in runs.items():
            print(f"  {label:<22s}  " + "  ".join(f"{t:8.0f}" for t in res.tau))
            half = _tau(res.chain[res.chain.shape[0] // 2 :])
            print(f"  {'  second half':<22s}  " + "  ".join(f"{t:8.0f}" for t in half))
        labels = list(runs)
        for other in labels[1:]:
            (a, ca, ra), (b, cb, rb) = runs[labels[0]], runs[other]
            print(
                f"  {other} / {labels[0]}: τmax {np.nanmax(b.tau) / np.nanmax(a.tau):.2f}, "
                f"CPU {cb / ca:.2f}, ESS/CPU-s {rb / ra:.2f}",
                flush=True,
            )


if __name__ == "__main__":
    main()
