"""Is a demo truth outside its interval bad luck or bias? MAP over several data seeds.

Regenerates the demo room (``configs/demo.yaml``) with other logger-noise seeds
(``data.demo.seed``) and prints the thermal MAP's slowest and fastest time constants and
the static gain from the outdoor temperature against their true values. A bias shows as
estimates on one side of the truth for every seed; bad luck as scatter around it.

    python benchmarks/demo_seeds.py 7 8 9 10 11 12
"""

from __future__ import annotations

import sys

import numpy as np

from _common import config_map
from heritage_bayes.config import load_config
from heritage_bayes.rc.derived import derived_quantities

QUANTITIES = ("tau_1_h", "gain_Ti_Te", "tau_2_h")


def main(seeds: list[int]) -> None:
    cfg0 = load_config("configs/demo.yaml")
    print("data seed  " + "  ".join(f"{q:>22s}" for q in QUANTITIES) + "   (MAP, truth)")
    for seed in seeds:
        demo = cfg0.data.demo.model_copy(update={"seed": seed})
        cfg = cfg0.model_copy(
            update={"data": cfg0.data.model_copy(update={"demo": demo}), "hygric": None}
        )
        prep, m, lp, mp = config_map(cfg, "thermal")
        truth = prep.truth["thermal"]
        est = derived_quantities(m, mp.theta[None, : lp.n_model])
        ref = derived_quantities(m, np.array([[truth[k] for k in m.parameter_names]]))
        row = [
            f"{float(np.ravel(est[q])[0]):.4g} ({float(np.ravel(ref[q])[0]):.4g})"
            for q in QUANTITIES
        ]
        print(f"{seed:9d}  " + "  ".join(f"{r:>22s}" for r in row), flush=True)


if __name__ == "__main__":
    main([int(s) for s in sys.argv[1:]] or [7, 8, 9, 10, 11, 12])
