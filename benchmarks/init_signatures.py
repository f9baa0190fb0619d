"""The signatures ``hbayes init`` measures on the shared real data, and the model it
proposes from them (docs/science/models.md, "The model init proposes").

    PYTHONPATH=src python benchmarks/init_signatures.py [R3 R4 R5 R6 R7]

Runs :func:`heritage_bayes.init_config.init_config` on each logger with its weather file
(Ørholm and Annisse with the DMI file on the logger's fixed UTC+1 clock, the TRH-1 rooms
with their FMI files; the configs go to a temporary folder) and prints the proposed
``thermal`` and ``hygric`` sections with the evidence lines.
"""

from __future__ import annotations

import sys
import tempfile
from pathlib import Path

import yaml

from heritage_bayes.init_config import init_config

DATA = Path(__file__).resolve().parents[1] / ".." / "shared" / "data"
DMI = "orholm/DMI_outdoor-climate-data_2009-2021.csv"
#: The more attics' towns (Espoo, Tampere, Tampere, Valkeakoski, Vantaa) [° N, ° E].
SITES = {
    "R3": (60.21, 24.66),
    "R4": (61.50, 23.76),
    "R5": (61.50, 23.76),
    "R6": (61.27, 24.03),
    "R7": (60.29, 25.04),
}


def cases(more: list[str]) -> dict:
    out = {
        "orholm": ("orholm/oerholm-indoor-climate-data_2009-2021.csv", DMI, 55.79, 12.50, "UTC+1"),
        "annisse": ("orholm/annisse-indoor-climate-data_2014-2018.csv", DMI, 55.95, 12.22, "UTC+1"),
        "R2 attic": (
            "trh1-espoo-attic/roofmiddle_airmiddle.csv",
            "trh1-espoo-attic/fmi.csv",
            60.21,
            24.66,
            None,
        ),
        "R2 house": (
            "trh1-espoo-attic/indoor1.csv",
            "trh1-espoo-attic/fmi.csv",
            60.21,
            24.66,
            None,
        ),
    }
    for r in more:
        d = f"trh1-more-attics/{r}"
        out[f"{r} attic"] = (f"{d}/roofmiddle_airmiddle.csv", f"{d}/fmi.csv", *SITES[r], None)
    return out


def main(argv: list[str]) -> None:
    with tempfile.TemporaryDirectory() as tmp:
        for name, (logger, weather, lat, lon, zone) in cases(argv).items():
            res = init_config(
                DATA / logger,
                DATA / weather,
                output=Path(tmp) / f"{name.replace(' ', '_')}.yaml",
                latitude=lat,
                longitude=lon,
                timezone=zone,
            )
            raw = yaml.safe_load(res.text)
            print(f"## {name}: {raw['thermal']} {raw.get('hygric')} questions={len(res.questions)}")
            for f in res.findings:
                if f.startswith("model: "):
                    print("   ", f[len("model: ") :])


if __name__ == "__main__":
    main(sys.argv[1:])
