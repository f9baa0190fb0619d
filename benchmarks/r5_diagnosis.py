"""Why the TRH-1 R5 attic validates poorly from its raw files: the data against R4's.

R4 and R5 are one-storey houses in Tampere with the same FMI weather file (checked
here: identical Te), so R4 is R5's control. Printed: each file's span; the weather
files' largest difference; the hourly correlation of the two attics' air temperature by
month (a swapped or misplaced logger would decorrelate); the hour of the mean daily
peak (a clock error would shift it); R5 minus R4 attic temperature [K], daily mean and
00-04 h mean, before and after mid-May 2011; the weekly daily range [K] of both attics
around the snow melt. With ``--split`` also init on R4's files cut to R5's span
(2010-11-15 to 2011-07-26: init then calibrates on Nov-May and validates on May-Jul, as
for R5) and the MAP validation FIT [%] (benchmarks/real_rooms.py's budget), against R4
as published. R5 itself is not fitted here (held out).

Usage (from the repository root)::

    python benchmarks/r5_diagnosis.py [--split] [--data ../shared/data]
"""

from __future__ import annotations

import argparse
import sys
import tempfile
from pathlib import Path

import numpy as np
import pandas as pd

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT / "benchmarks"))


def _read(path: Path) -> pd.DataFrame:
    d = pd.read_csv(path)
    d.index = pd.to_datetime(d.iloc[:, 0])
    return d.iloc[:, 1:]


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--data", type=Path, default=ROOT.parent / "shared" / "data")
    ap.add_argument("--split", action="store_true", help="also init + MAP on R4 cut to R5's span")
    args = ap.parse_args(argv)
    d = args.data / "trh1-more-attics"
    a4, a5 = (_read(d / r / "roofmiddle_airmiddle.csv") for r in ("R4", "R5"))
    w4, w5 = (_read(d / r / "fmi.csv") for r in ("R4", "R5"))
    for r, a in (("R4", a4), ("R5", a5)):
        print(f"{r} attic: {a.index[0]} to {a.index[-1]}, {len(a)} rows")
    common = w4.index.intersection(w5.index)
    print(f"weather R5 - R4: max |ΔTe| {np.nanmax(np.abs(w5.Te[common] - w4.Te[common])):.2f} K")
    j = pd.concat({"T4": a4["T"], "T5": a5["T"], "Te": w5["Te"]}, axis=1).dropna()
    print("month  corr(T4,T5)  peak hour T4 T5 Te")
    for m, g in j.groupby(j.index.to_period("M")):
        c = g.groupby(g.index.hour).mean()
        print(
            f"{m}  {np.corrcoef(g.T4, g.T5)[0, 1]:.3f}        "
            f"{c.T4.idxmax():>2} {c.T5.idxmax():>2} {c.Te.idxmax():>2}"
        )
    diff = (j.T5 - j.T4).rename("d")
    night = diff[diff.index.hour < 4]
    for label, sl in (("before 2011-05-15", slice(None, "2011-05-14")),
                      ("from 2011-05-20", slice("2011-05-20", None))):  # fmt: skip
        print(
            f"R5 - R4 attic {label}: daily mean {diff[sl].mean():+.2f} K, "
            f"00-04 h {night[sl].mean():+.2f} K"
        )
    day = j.resample("1D").agg(["max", "min"])
    rng = (
        pd.DataFrame(
            {
                r: day[(c, "max")] - day[(c, "min")]
                for r, c in (("R4", "T4"), ("R5", "T5"), ("Te", "Te"))
            }
        )
        .resample("W")
        .mean()
    )
    print("weekly mean daily range [K], March-May 2011")
    print(rng.loc["2011-03-01":"2011-05-31"].round(2).to_string())
    if args.split:
        from heritage_bayes.config import load_config
        from heritage_bayes.init_config import init_config
        from real_rooms import map_fits

        with tempfile.TemporaryDirectory() as tmp:
            cut = Path(tmp) / "data"
            cut.mkdir()
            for f in ("roofmiddle_airmiddle.csv", "fmi.csv"):
                t = pd.read_csv(d / "R4" / f)
                t[pd.to_datetime(t.iloc[:, 0]) < "2011-07-26"].to_csv(cut / f, index=False)
            for label, folder in (("R4 as published", d / "R4"), ("R4 cut to R5's span", cut)):
                out = Path(tmp) / label.replace(" ", "_") / "config.yaml"
                init_config(folder / "roofmiddle_airmiddle.csv", folder / "fmi.csv",
                            output=out, latitude=61.50, longitude=23.76)  # fmt: skip
                cfg = load_config(out)
                f = map_fits(cfg, 100, 2)
                print(
                    f"{label}: calibration {cfg.periods.calibration.start} to "
                    f"{cfg.periods.calibration.end}, validation to {cfg.periods.validation.end}: "
                    f"FIT Ti {f['Ti']:.1f} %, Pi {f['Pi']:.1f} %",
                    flush=True,
                )
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
