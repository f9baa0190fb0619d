"""Which roof orientation do TRH-1's attic temperatures favour? (issue 28)

The building's orientation is not in the TRH-1 data set ("Ilmansuunta = -1");
``configs/trh1_attic.yaml`` assumes planes facing east and west (from the position of
an eave-vent sensor). For each config given, this finds the MAP of its thermal section
(the config's optimiser settings and seed, what ``hbayes calibrate`` does before
sampling) with its two roof planes, tilt unchanged, turned to each pair of opposite
azimuths, and prints the MAP log-posterior and the two effective apertures [m²]. The
first plane keeps the name ``roof_E`` and the second ``roof_W`` whatever their azimuth.
``--shift`` repeats it with the indoor logger's clock read that many hours ahead
(its timezone's offset from UTC plus the shift): is a morning-facing plane a clock?

    python benchmarks/roof_orientation.py configs/trh1_attic.yaml \\
        benchmarks/configs/trh1_attic_2c_roof.yaml [--shift -1 0 1]
"""

from __future__ import annotations

import os

os.environ.setdefault("OPENBLAS_NUM_THREADS", "1")

import argparse
import sys
from datetime import timedelta, timezone
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent))

from _common import config_map
from heritage_bayes.config import load_config

#: label -> azimuths [°] (clockwise from north) of the first and the second plane
AZIMUTHS = {
    "E/W (shipped)": (90.0, 270.0),
    "S/N": (180.0, 0.0),
    "SE/NW": (135.0, 315.0),
    "SW/NE": (225.0, 45.0),
}


def main() -> None:
    ap = argparse.ArgumentParser()
    ap.add_argument("configs", nargs="+", help="configs with two surfaces roof_E, roof_W")
    ap.add_argument(
        "--shift",
        type=float,
        nargs="+",
        default=[0.0],
        help="hours added to the indoor logger's UTC offset (default 0: as configured)",
    )
    args = ap.parse_args()
    for path in args.configs:
        cfg = load_config(path)
        (first, (tilt1, _)), (second, (tilt2, _)) = cfg.data.surfaces.items()
        for shift in args.shift:
            sources = [
                m.model_copy(
                    update={
                        "timezone": timezone(m.timezone.utcoffset(None) + timedelta(hours=shift))
                    }
                )
                for m in cfg.data.measurements
            ]
            for label, (az1, az2) in AZIMUTHS.items():
                data = cfg.data.model_copy(
                    update={
                        "surfaces": {first: (tilt1, az1), second: (tilt2, az2)},
                        "measurements": sources,
                    }
                )
                _, model, lp, mp = config_map(cfg.model_copy(update={"data": data}), "thermal")
                theta = dict(zip(lp.params.names, mp.theta, strict=True))
                print(
                    f"{Path(path).name} ({model.name}), logger clock {shift:+g} h, planes at "
                    f"{az1:g}° / {az2:g}° ({label}): MAP log-posterior {mp.log_post:.1f}; "
                    f"fI_{first} {theta[f'fI_{first}']:.3g} m², fI_{second} "
                    f"{theta[f'fI_{second}']:.3g} m²",
                    flush=True,
                )


if __name__ == "__main__":
    main()
