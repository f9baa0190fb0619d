"""Where the demo's thermal_4a posterior puts the interior mass (issue 28).

The MAP is found as ``hbayes calibrate`` finds it (the config's optimiser and seed),
then the log-posterior is evaluated with every parameter at the MAP except the
interior mass's conductance ``Gint`` [W/K], capacity ``Cint`` [J/K] and the solar share
``fsol`` [-] it absorbs (in the sampler's coordinates: the density the walkers see), on a
grid: the interior mass decoupled (small ``Gint``, any
``Cint``) or merged with the air node (small ``Cint``, large ``Gint``), with ``fsol`` at
its MAP value or at 1/2. One vectorised call; a few seconds after the MAP search.

    python benchmarks/interior_mass_slice.py [demo_4a | orholm_4a] [--seed N]
"""

from __future__ import annotations

import os

os.environ.setdefault("OPENBLAS_NUM_THREADS", "1")

import argparse
import sys
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parent))

from _common import config_map
from bench_coordinates import PROBLEMS, _config

GINT = (0.02, 0.75, 5.0, 50.0, 500.0, 5e4)  # [W/K]
CINT = (1e4, 1e6, 1e8, 1e10, 9.9e11)  # [J/K]


def main() -> None:
    ap = argparse.ArgumentParser()
    ap.add_argument("problem", nargs="?", default="demo_4a", choices=sorted(PROBLEMS))
    ap.add_argument("--seed", type=int, default=None, help="the MAP search's seed (the config's)")
    args = ap.parse_args()
    cfg = _config(*PROBLEMS[args.problem])
    if args.seed is not None:
        cfg = cfg.model_copy(update={"seed": args.seed})
    _, _, lp, mp = config_map(cfg, PROBLEMS[args.problem][1])
    names = list(lp.params.free_names)
    theta = dict(zip(lp.params.names, mp.theta, strict=True))
    print(
        f"{args.problem}: MAP log-posterior {mp.log_post:.2f} at Gint {theta['Gint']:.3g} W/K, "
        f"Cint {theta['Cint']:.3g} J/K" + (f", fsol {theta['fsol']:.3g}" if "fsol" in theta else "")
    )
    at_map = float(np.asarray(lp(mp.x[None]), dtype=float)[0])
    print(
        f"the sampler's log-density at the MAP: {at_map:.2f} (the MAP maximises the density "
        "in the parameters' own scale; the sampler's coordinates add the Jacobian of each "
        "log or logit transform)"
    )
    ig, ic = names.index("Gint"), names.index("Cint")
    jf = names.index("fsol") if "fsol" in names else None
    shares = [("fsol at the MAP", mp.x[jf]) if jf is not None else ("log-density", None)]
    if jf is not None:
        shares.append(("fsol 1/2", 0.0))  # the logit coordinate of 1/2
    rows, X = [], []
    for g in GINT:
        for c in CINT:
            for label, xf in shares:
                x = mp.x.copy()
                x[ig], x[ic] = np.log(g), np.log(c)
                if xf is not None:
                    x[jf] = xf
                rows.append((g, c, label))
                X.append(x)
    values = np.asarray(lp(np.array(X)), dtype=float)
    print(f"{'Gint [W/K]':>11s} {'Cint [J/K]':>11s}  " + "  ".join(f"{s:>16s}" for s, _ in shares))
    k = 0
    for g in GINT:
        for c in CINT:
            cells = values[k : k + len(shares)]
            k += len(shares)
            print(f"{g:11.3g} {c:11.3g}  " + "  ".join(f"{v:16.2f}" for v in cells))


if __name__ == "__main__":
    main()
