"""A validation inside the calibration against the same validation with the calibration
on one side of it only: what the second side brings.

For a config whose ``periods.validation`` lies inside ``periods.calibration`` (init's
choice for a short record, e.g. written by ``benchmarks/real_rooms.py --span ... --out
DIR`` in ``DIR/<room>/init/config.yaml``), the MAP validation FIT [%] of Ti, Pi and RH
(``real_rooms.map_fits``, the model screened as ``hbayes calibrate`` does) with the
calibration before the validation only, after it only, and on both sides. The edited
configs are written beside the given one (``sides_<which>.yaml``).

Usage (from the repository root)::

    python benchmarks/validation_sides.py CONFIG [--maxiter 100] [--starts 2]
"""

from __future__ import annotations

import argparse
import resource
import sys
from pathlib import Path

import yaml

sys.path.insert(0, str(Path(__file__).resolve().parent))

import real_rooms
from heritage_bayes.config import load_config


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("config", type=Path)
    ap.add_argument("--maxiter", type=int, default=100)
    ap.add_argument("--starts", type=int, default=2)
    args = ap.parse_args()
    raw = yaml.safe_load(args.config.read_text(encoding="utf-8"))
    per = raw["periods"]
    cs, ce = str(per["calibration"]["start"]), str(per["calibration"]["end"])
    vs, ve = str(per["validation"]["start"]), str(per["validation"]["end"])
    if not cs < vs < ve < ce:
        sys.exit(f"{args.config}: the validation does not lie inside the calibration")
    print(f"validation {vs} to {ve}; MAP (maxiter {args.maxiter}, starts {args.starts})")
    print("| calibration | models | Ti | Pi | RH | CPU [s] |\n|---|---|---:|---:|---:|---:|")
    for which, (a, b) in (("before", (cs, vs)), ("after", (ve, ce)), ("both", (cs, ce))):
        raw["periods"] = {
            "calibration": {"start": a, "end": b},
            "validation": {"start": vs, "end": ve},
        }
        path = args.config.parent / f"sides_{which}.yaml"
        path.write_text(yaml.safe_dump(raw, sort_keys=False), encoding="utf-8")
        t0 = resource.getrusage(resource.RUSAGE_SELF).ru_utime
        out = real_rooms.map_fits(load_config(path), args.maxiter, args.starts)
        cpu = resource.getrusage(resource.RUSAGE_SELF).ru_utime - t0
        models = f"{out.get('thermal_model')}; {out.get('hygric_model')}"
        figs = " | ".join(f"{out.get(k, float('nan')):.1f}" for k in ("Ti", "Pi", "RH"))
        print(f"| {a} to {b} ({which}) | {models} | {figs} | {cpu:.0f} |", flush=True)


if __name__ == "__main__":
    main()
