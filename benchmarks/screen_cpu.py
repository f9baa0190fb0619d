"""CPU time of a config's ``model: auto`` screen, rung by rung, and of its richest
rung's MAP with the optimizer's restarts (what ``hbayes compare``'s screen ran before
it became the same loop), from the same carried start.

    python benchmarks/screen_cpu.py CONFIG [--section thermal]

Prints, per rung, the process CPU time [s] since the start of the screen and the
screen's progress line, then the richest rung's MAP with ``optimizer.restarts_for``
its nodes: CPU [s] and log-posterior against the screen's. CPU time, not wall time:
the figure carries over between loads (docs/science/benchmarks.md, the whole path).
"""

from __future__ import annotations

import argparse
import time

from threadpoolctl import threadpool_limits

from heritage_bayes.calibration.selection import carried_start, screen
from heritage_bayes.config import load_config
from heritage_bayes.inference.optimize import find_map
from heritage_bayes.models import models_of
from heritage_bayes.prepare import prepare


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("config")
    ap.add_argument("--section", default="thermal", choices=("thermal", "hygric"))
    args = ap.parse_args()
    cfg = load_config(args.config)
    models, rungs = models_of(cfg)
    prep = prepare(cfg, models)
    with threadpool_limits(limits=1, user_api="blas"):
        c0 = time.process_time()
        scr = screen(
            cfg,
            prep,
            args.section,
            rungs[args.section],
            seed=cfg.seed,
            say=lambda m: print(f"{time.process_time() - c0:7.1f} s CPU  {m}", flush=True),
        )
        rich = [r for r in scr.rows if "error" not in r][-1]
        label, parent = rich["model"], rich.get("parent")
        lp = scr.logposts[label]
        start = None
        if parent in scr.maps:
            start = carried_start(lp, scr.logposts[parent], scr.maps[parent])
        o, model = cfg.optimizer, scr.models[label]
        c1 = time.process_time()
        mp = find_map(
            lp,
            seed=cfg.seed,
            method=o.method,
            popsize=o.popsize,
            maxiter=o.maxiter,
            starts=o.starts,
            restarts=o.restarts_for(model.n_states),
            start=start,
        )
        print(
            f"{label} MAP with restarts={o.restarts_for(model.n_states)}: "
            f"{time.process_time() - c1:.1f} s CPU, log-posterior {mp.log_post:.1f} "
            f"(the screen's: {scr.maps[label].log_post:.1f})"
        )


if __name__ == "__main__":
    main()
