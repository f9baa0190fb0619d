"""`hbayes init` on the TRH-1 attics from their raw files, with and without the radiation
columns: what a site without a pyranometer gets.

For each attic (``trh1-espoo-attic/`` as R2, ``trh1-more-attics/R3`` ... ``R7``): init on
the logger file and the FMI weather as published (measured ``Rglob``, ``Rdif``), and on a
copy of the weather without those two columns (written to a temporary folder; init then
writes ``data.irradiance: estimated``); the thermal and hygric MAP validation FIT [%]
(100 generations, 2 starts: lighter than the configs' optimiser), and for the weather
without radiation also with ``data.irradiance: clear_sky`` (what init wrote before the
estimate). Sites at the towns' positions (the houses' are not published). Nothing here
is tuned: the attics are held out.

Usage (from the repository root)::

    python benchmarks/init_without_radiation.py [R2 R3 R4 R5 R6 R7] [--data ../shared/data]
"""

from __future__ import annotations

import argparse
import sys
import tempfile
from pathlib import Path

import pandas as pd

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT / "benchmarks"))

from _common import config_map  # noqa: E402
from heritage_bayes.config import load_config  # noqa: E402
from heritage_bayes.inference.results import fit_metrics  # noqa: E402
from heritage_bayes.init_config import init_config  # noqa: E402

#: name -> (folder under the data root, latitude, longitude) [°]
SITES = {
    "R2": ("trh1-espoo-attic", 60.21, 24.66),
    "R3": ("trh1-more-attics/R3", 60.21, 24.66),
    "R4": ("trh1-more-attics/R4", 61.50, 23.76),
    "R5": ("trh1-more-attics/R5", 61.50, 23.76),
    "R6": ("trh1-more-attics/R6", 61.26, 24.03),
    "R7": ("trh1-more-attics/R7", 60.29, 25.04),
}


def map_fits(cfg) -> dict[str, float]:
    """Validation FIT [%] of each section's MAP simulation (as tests/test_init.py)."""
    opt = cfg.optimizer.model_copy(update={"maxiter": 100, "starts": 2})
    cfg = cfg.model_copy(update={"optimizer": opt})
    out = {}
    for sec in ("thermal", "hygric"):
        prep, model, lp, mp = config_map(cfg, sec)
        u = prep.model_inputs(sec, model)
        y = lp.simulate_frame(mp.theta[None], u, prep.calibration.start)[0][0]
        v, obs = prep.validation, prep.observed(sec, model)
        out[sec] = fit_metrics(obs[v.start : v.stop, 0], y[v.start : v.stop, 0])["FIT"]
    return out


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("sites", nargs="*", help=f"default: all of {list(SITES)}")
    ap.add_argument("--data", type=Path, default=ROOT.parent / "shared" / "data")
    args = ap.parse_args(argv)
    args.sites = args.sites or list(SITES)
    if set(args.sites) - set(SITES):
        ap.error(
            f"unknown site(s) {sorted(set(args.sites) - set(SITES))}; choose from {list(SITES)}"
        )
    print("validation FIT [%] of the MAP, Ti / Pi, by solar input")
    with tempfile.TemporaryDirectory() as tmp:
        for name in args.sites:
            folder, lat, lon = SITES[name]
            d = args.data / folder
            work = Path(tmp) / name
            (work / "data").mkdir(parents=True)
            bare = work / "data" / "fmi.csv"
            pd.read_csv(d / "fmi.csv").drop(columns=["Rglob", "Rdif"]).to_csv(bare, index=False)
            row = [f"{name:<4}"]
            for label, weather in (("measured", d / "fmi.csv"), ("none", bare)):
                out = work / label / "config.yaml"
                out.parent.mkdir()
                init_config(
                    d / "roofmiddle_airmiddle.csv", weather, output=out, latitude=lat, longitude=lon
                )
                cfg = load_config(out)
                modes = [cfg.data.irradiance] + (["clear_sky"] if label == "none" else [])
                for irr in modes:
                    data = cfg.data.model_copy(update={"irradiance": irr})
                    f = map_fits(cfg.model_copy(update={"data": data}))
                    row.append(f"{irr} {f['thermal']:.1f} / {f['hygric']:.1f}")
            row.append(f"({cfg.thermal.model}, {cfg.hygric.model})")
            print(" | ".join(row), flush=True)
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
