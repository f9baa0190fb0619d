"""`hbayes init` then MAP fits on a year of the TRH-1 attic (R2) with gaps in its files.

The attic's published files are gap-free. Copies of 2011-01-01 to 2012-02-01 are written
to a temporary folder with a 35-hour outage of the FMI weather from 2011-04-12 09:00 (the
files' UTC+2 clock), and with ``monthly`` also the logger read out on the 15th of every
month (8 hours without data, 09:00-17:00). init writes the config (no answer needed);
its periods, then the thermal and hygric MAP (100 generations, 2 starts: lighter than
the config's optimiser) and the FIT [%] of the MAP simulation over the calibration and
validation periods, and the segments the calibration was split into. ``--max-gap 36h``
bridges the outage by interpolation instead (the same periods, one segment): the
splitting's own effect. Run on two commits for a before/after.

Usage (from the repository root)::

    python benchmarks/init_gaps.py [monthly] [--max-gap 36h] [--data ../shared/data]
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

OUTAGE = pd.Timestamp("2011-04-12 09:00"), pd.Timedelta(hours=35)


def _files(src: Path, folder: Path, monthly: bool) -> tuple[Path, Path]:
    w = pd.read_csv(src / "fmi.csv")
    lg = pd.read_csv(src / "roofmiddle_airmiddle.csv")
    tw, tl = pd.to_datetime(w.iloc[:, 0]), pd.to_datetime(lg.iloc[:, 0])
    a = OUTAGE[0]
    keep = (tw >= "2011-01-01") & (tw < "2012-02-01") & ~((tw >= a) & (tw < a + OUTAGE[1]))
    lkeep = (tl >= "2011-01-01") & (tl < "2012-02-01")
    if monthly:
        lkeep &= ~((tl.dt.day == 15) & (tl.dt.hour >= 9) & (tl.dt.hour < 17))
    weather, logger = folder / "fmi.csv", folder / "attic.csv"
    w[keep].to_csv(weather, index=False)
    lg[lkeep].to_csv(logger, index=False)
    return logger, weather


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("monthly", nargs="?", choices=["monthly"], help="monthly logger gaps")
    ap.add_argument("--max-gap", default=None, help="data.max_gap instead of init's (6h)")
    ap.add_argument("--data", default=str(ROOT.parent / "shared" / "data"))
    args = ap.parse_args()
    src = Path(args.data) / "trh1-espoo-attic"
    with tempfile.TemporaryDirectory() as tmp:
        data = Path(tmp) / "data"
        data.mkdir()
        logger, weather = _files(src, data, args.monthly is not None)
        out = Path(tmp) / "attic.yaml"
        res = init_config(logger, weather, output=out, latitude=60.21, longitude=24.66)
        cfg = load_config(out)
        print(f"questions: {res.questions}")
        print(f"calibration {cfg.periods.calibration}; validation {cfg.periods.validation}")
        opt = cfg.optimizer.model_copy(update={"maxiter": 100, "starts": 2})
        update = {"optimizer": opt}
        if args.max_gap:
            update["data"] = cfg.data.model_copy(update={"max_gap": pd.Timedelta(args.max_gap)})
        cfg = cfg.model_copy(update=update)
        for sec in ("thermal", "hygric"):
            if getattr(cfg, sec) is None:
                continue
            prep, model, lp, mp = config_map(cfg, sec)
            y = lp.simulate_frame(
                mp.theta[None], prep.model_inputs(sec, model), prep.calibration.start
            )
            obs = prep.observed(sec, model)[:, 0]
            fit = {
                p: fit_metrics(obs[getattr(prep, p)], y[0][0, getattr(prep, p), 0])["FIT"]
                for p in ("calibration", "validation")
            }
            print(
                f"{sec} {model.name}: FIT calibration {fit['calibration']:.1f} %, validation "
                f"{fit['validation']:.1f} %; segments {getattr(lp, 'segments', 'one record')}"
            )


if __name__ == "__main__":
    main()
