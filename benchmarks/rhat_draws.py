"""R-hat on the retained draws against R-hat on the thinned draws ``posterior.nc`` saves.

Without arguments: independent standard-normal draws (a perfectly mixed chain), 32
walkers as chains, 10 parameters, ``--replicates`` times; the largest rank-normalised
split R-hat (``az.summary``) over the parameters on 31 draws per walker (the ~1 000
draws the ``posterior`` group keeps) and on 125 (the 4 000 retained draws), and the
share of replicates above 1.01. With run directories: the figures ``summary.json``
states and ``az.summary`` of each model's retained draws and of the ``posterior``
group of ``posterior.nc``:

    python benchmarks/rhat_draws.py
    hbayes calibrate configs/demo.yaml --out /tmp/demo
    python benchmarks/rhat_draws.py /tmp/demo
"""

from __future__ import annotations

import argparse
import json
import sys
import warnings
from pathlib import Path

import numpy as np


def independent(replicates: int, seed: int) -> None:
    """The largest R-hat of 10 independent parameters, 32 walkers, two draw counts."""
    import xarray as xr

    from heritage_bayes._arviz import az

    rng = np.random.default_rng(seed)
    for draws in (31, 125):
        mx = []
        for _ in range(replicates):
            x = rng.standard_normal((10, 32, draws))
            ds = xr.Dataset({f"p{i}": (("chain", "draw"), x[i]) for i in range(10)})
            mx.append(az.summary(ds, kind="diagnostics", round_to="none")["r_hat"].max())
        mx = np.array(mx)
        print(
            f"32 walkers x {draws} draws: max R-hat median {np.median(mx):.4f}, "
            f"90 % quantile {np.quantile(mx, 0.9):.4f}, share above 1.01 "
            f"{np.mean(mx > 1.01):.2f} ({replicates} replicates)"
        )


def run(path: Path) -> None:
    """A run directory's figures: summary.json and az.summary of its groups."""
    from heritage_bayes._arviz import az

    s = json.loads((path / "summary.json").read_text(encoding="utf-8"))
    idata = az.from_netcdf(path / "posterior.nc")
    free = [k for k, v in s["parameters"].items() if "r_hat" in v]
    print(f"{path}: converged {s['converged']}, verdict {(s.get('verdict') or {}).get('level')}")
    groups = [f"posterior_retained_{m}" for m in s["models"]] + ["posterior"]
    for group in groups:
        if group not in idata.groups():
            print(f"  {group}: absent (a run written before)")
            continue
        names = [k for k in free if k in idata[group]]
        d = az.summary(idata[group], var_names=names, kind="diagnostics", round_to="none")
        w, n = idata[group].sizes["chain"], idata[group].sizes["draw"]
        worst = d["r_hat"].idxmax()
        print(
            f"  {group} ({w} walkers x {n} draws): max R-hat {d['r_hat'].max():.4f} "
            f"({worst}), min bulk ESS {d['ess_bulk'].min():.0f}"
        )
    print(f"  summary.json: max_rhat {s['max_rhat']:.4f}, min_ess_bulk {s['min_ess_bulk']:.0f}")
    # a model with more retained draws than another, on only the last ones common to both
    retained = [g for g in groups[:-1] if g in idata.groups()]
    common = min((idata[g].sizes["draw"] for g in retained), default=0)
    for g in retained:
        if idata[g].sizes["draw"] > common:
            names = [k for k in free if k in idata[g]]
            last = idata[g].isel(draw=slice(-common, None))
            d = az.summary(last, var_names=names, kind="diagnostics", round_to="none")
            print(
                f"  {g}, its last {common} draws only: max R-hat {d['r_hat'].max():.4f} "
                f"({d['r_hat'].idxmax()})"
            )


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("run_dirs", type=Path, nargs="*")
    ap.add_argument("--replicates", type=int, default=200)
    ap.add_argument("--seed", type=int, default=87)
    a = ap.parse_args(argv)
    warnings.simplefilter("ignore")
    if not a.run_dirs:
        independent(a.replicates, a.seed)
    for p in a.run_dirs:
        run(p)
    return 0


if __name__ == "__main__":
    sys.exit(main())
