"""How much of a controlled room's signal can a calendar explain? FIT of period means.

For a config section, the paper's FIT of the measured output against its own means over
calendar periods (month, ISO week, day; UTC), per calibration and validation period
(after the warm-up, as in the calibration's figures): the FIT a model would reach if it
knew the exact level of every period and nothing within it. A model driven by weather
and a calendar (set-points per season or month, a weekly schedule of the hours of use)
cannot know the level of a day when someone changed the set-point by hand, so the daily
figure bounds what such models can reach on a room heated that way. ``month-of-year``
applies the calibration period's monthly means to the validation period (a set-point per
calendar month, estimated in one year and used in the next).

    python benchmarks/oracle_fit.py configs/annisse.yaml thermal
"""

from __future__ import annotations

import argparse

import numpy as np
import pandas as pd

from heritage_bayes.config import load_config
from heritage_bayes.inference.results import fit_metrics
from heritage_bayes.models import models_of
from heritage_bayes.prepare import prepare


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("config")
    ap.add_argument("section", choices=["thermal", "hygric"])
    args = ap.parse_args()
    cfg = load_config(args.config)
    models = models_of(cfg)[0]
    prep = prepare(cfg, models)
    m = models[args.section]
    out = m.output_names[0]
    y = pd.Series(prep.observed(args.section, m)[:, 0], prep.frame.index)
    cal = prep.calibration
    rows = {
        "calibration": slice(cal.start + prep.warmup_steps, cal.stop),
        "validation": prep.validation,
    }
    ycal = y.iloc[rows["calibration"]]
    moy = ycal.groupby(ycal.index.month).mean()
    print(f"{args.config} [{out}]: FIT [%] of the measured {out} against its own period means")
    for name, sl in rows.items():
        if sl is None:
            continue
        yp = y.iloc[sl]
        line = []
        for label, freq in (("month", "MS"), ("week", "W-SUN"), ("day", "D")):
            mean = yp.groupby(pd.Grouper(freq=freq)).transform("mean")
            line.append(f"{label} {fit_metrics(yp.to_numpy(), mean.to_numpy())['FIT']:5.1f}")
        guess = moy.reindex(yp.index.month).to_numpy()
        moy_fit = fit_metrics(yp.to_numpy(), guess)["FIT"]
        line.append(f"month-of-year (calibration means) {moy_fit:5.1f}")
        daily = yp.resample("D").mean()
        line.append(f"std {np.nanstd(yp):.2f}, of daily means {np.nanstd(daily):.2f}")
        print(f"  {name}: " + "; ".join(line))


if __name__ == "__main__":
    main()
