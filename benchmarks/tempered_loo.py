"""How far ``az.loo``'s importance weights are off on a tempered run.

The draws of a run whose likelihood is tempered (``likelihood_temperature`` T, 2 for
thermal sections by default) come from prior × likelihood^(1/T). ``az.loo(idata)``
weights them by 1 / p(y_i | θ), right for T = 1; ``hbayes compare`` uses
:func:`heritage_bayes.compare.scores.tempered_loo` (weights p^(-1/T)). For each section
of a run directory this prints the blocked PSIS-LOO (daily blocks, as ``hbayes
compare``) both ways, their difference, the largest Pareto k and the wall time of each
(the reference, ``az.loo``, measured in the same run):

    hbayes calibrate configs/demo.yaml --out /tmp/demo
    python benchmarks/tempered_loo.py /tmp/demo
"""

from __future__ import annotations

import argparse
import json
import sys
import time
import warnings
from pathlib import Path


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("run_dir", type=Path)
    ap.add_argument("--block-hours", type=float, default=24.0)
    a = ap.parse_args(argv)
    from heritage_bayes._arviz import az
    from heritage_bayes.compare.scores import blocked_loo_data, tempered_loo

    summary = json.loads((a.run_dir / "summary.json").read_text(encoding="utf-8"))
    idata = az.from_netcdf(a.run_dir / "posterior.nc")
    warnings.simplefilter("ignore")
    for section, info in summary["models"].items():
        T = float(info.get("likelihood_temperature") or 1.0)
        for out in info["output_names"]:
            var = f"{section}.{out}"
            data = blocked_loo_data(idata, var, a.block_hours)
            t0 = time.perf_counter()
            ref = az.loo(data, var_name=var, pointwise=True)
            t1 = time.perf_counter()
            new = tempered_loo(data, var, T)
            t2 = time.perf_counter()
            print(
                f"{var} (T {T:g}, {int(new.n_data_points)} blocks of {a.block_hours:g} h): "
                f"ELPD tempered weights {float(new.elpd_loo):.1f} ± {float(new.se):.1f} "
                f"(max k {float(new.pareto_k.max()):.2f}), az.loo {float(ref.elpd_loo):.1f} "
                f"± {float(ref.se):.1f} (max k {float(ref.pareto_k.max()):.2f}), difference "
                f"{float(new.elpd_loo) - float(ref.elpd_loo):+.1f}; time {t2 - t1:.2f} s vs "
                f"{t1 - t0:.2f} s (ratio {(t2 - t1) / max(t1 - t0, 1e-9):.2f})"
            )
    return 0


if __name__ == "__main__":
    sys.exit(main())
