"""The seasonal ground temperature's surface cycle: fitted on whole records and on nine
months of them, to see what a 9-month logger file gives.

For each weather record: :func:`heritage_bayes.climate.ground.fit_annual_cycle` on every
complete calendar year, and on March-November of the same year (the 9-month file of a
logger campaign); the mean [°C], amplitude [K] and coldest day of the fitted cycle, and
the ground temperature's range at the default depth (1 m in clay/silt soil:
:func:`heritage_bayes.inputs.seasonal_ground_temperature`); and the plain mean of the
temperatures fitted (a flat ground temperature from the same record).

Usage (from the repository root)::

    python benchmarks/ground_cycle.py [--data ../shared/data]
"""

from __future__ import annotations

import argparse
from pathlib import Path

import pandas as pd

from heritage_bayes.climate.ground import fit_annual_cycle
from heritage_bayes.inputs import seasonal_ground_temperature
from heritage_bayes.io import read_csv, read_knmi_hourly

ROOT = Path(__file__).resolve().parents[1]


def records(data: Path) -> dict[str, pd.Series]:
    knmi = sorted((data / "knmi-debilt").glob("uurgeg_260_*.txt.gz"))
    out = {"De Bilt": pd.concat([read_knmi_hourly(p)["Te"] for p in knmi])}
    for name, folder in (("R2 Espoo", "trh1-espoo-attic"), ("R4 Tampere", "trh1-more-attics/R4")):
        w = read_csv(
            data / folder / "fmi.csv",
            time_column="t_UTC+2",
            timezone="UTC+2",
            columns={"Te": "Te"},
            averaged=[],
        )
        out[name] = w["Te"]
    return out


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--data", type=Path, default=ROOT.parent / "shared" / "data")
    args = ap.parse_args(argv)
    print(
        f"{'record':<12}{'fitted on':<20}{'mean °C':>9}{'ampl. K':>9}{'coldest':>9}"
        f"{'Tf(1 m) min..max °C':>22}"
    )
    for name, te in records(args.data).items():
        counts = te.dropna().groupby(te.dropna().index.year).count()
        years = [int(y) for y, n in counts.items() if n > 8000]
        for y in years[:3]:
            for label, part in (
                (f"{y}", te.loc[str(y)]),
                (f"{y}-03..{y}-11", te.loc[f"{y}-03" : f"{y}-11"]),
            ):
                c = fit_annual_cycle(part)
                tf, _ = seasonal_ground_temperature(part, part.index)
                print(
                    f"{name:<12}{label:<20}{c['mean']:>9.2f}{c['amplitude']:>9.2f}"
                    f"{c['coldest_day']:>9d}{tf.min():>12.1f}..{tf.max():<8.1f}{part.mean():>10.2f}"
                )
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
