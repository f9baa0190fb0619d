"""bench_coordinates.py with the walkers started at the mode of the sampler's own
log-density instead of the MAP (issue 28; tried on the demo's thermal_4a, not kept).

The MAP maximises the posterior density in the parameters' own scale; the sampler's
coordinates (log, logit) add each transform's Jacobian, so a MAP on a bound (thermal_4a's
``fsol`` at 0 on the demo's data) lies where the sampler's density is low. This script
runs a local search (Powell, bounded) of the sampler's log-density from the MAP and
starts ``bench_coordinates.py`` from there; the arguments are bench_coordinates.py's:

    python benchmarks/mode_start.py demo_4a --only node_tau --air-share --max-steps 40000

(The Laplace check, and so the block of the block move, is then taken at the new point.)
"""

from __future__ import annotations

import dataclasses
import sys
from pathlib import Path

import numpy as np
from scipy.optimize import minimize

sys.path.insert(0, str(Path(__file__).resolve().parent))

import bench_coordinates
from _common import config_map as _config_map


def config_map(cfg, section):
    """:func:`_common.config_map` with the MAP's x moved to the local mode of the
    sampler's log-density (printed with the parameters that moved by more than 0.3)."""
    prep, model, lp, mp = _config_map(cfg, section)
    lo, hi = lp.params.bounds
    bounds = [
        (a + 1e-9 if np.isfinite(a) else None, c - 1e-9 if np.isfinite(c) else None)
        for a, c in zip(lo, hi, strict=True)
    ]
    x0 = np.clip(mp.x, lo + 1e-9, hi - 1e-9)

    def f(x):
        return -float(np.asarray(lp(x[None]))[0])

    res = minimize(f, x0, method="Powell", bounds=bounds, options={"maxiter": 20000, "xtol": 1e-6})
    moved = {
        n: (round(float(a), 2), round(float(b), 2))
        for n, a, b in zip(lp.params.free_names, x0, res.x, strict=True)
        if abs(a - b) > 0.3
    }
    print(
        f"sampler's log-density at the MAP {-f(x0):.2f}, at its local mode {-res.fun:.2f} "
        f"({res.nfev} evaluations); moved (sampler coordinates): {moved}",
        flush=True,
    )
    return prep, model, lp, dataclasses.replace(mp, x=res.x)


if __name__ == "__main__":
    bench_coordinates.config_map = config_map
    bench_coordinates.main()
