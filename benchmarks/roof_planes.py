"""The sun on an attic's roof: solar apertures on the two roof slopes (``data.roof``)
against one horizontal aperture and the four vertical facades, on the TRH-1 attics.

For each attic (``trh1-espoo-attic/`` as R2, ``trh1-more-attics/R3`` ... ``R7``):
``hbayes init`` on the logger file and the FMI weather as published (measured ``Rglob``,
``Rdif``) and on a copy without those two columns (``data.irradiance: estimated``); then
the thermal section's MAP validation FIT of Ti [%] (100 generations, 2 starts, as
``benchmarks/init_without_radiation.py``) with init's model and each set of solar
surfaces:

* ``H``: one aperture on the horizontal (what init wrote before ``data.roof``);
* ``facades``: the four vertical facades N, E, S, W;
* ``roof 45 E-W``: ``roof: {pitch: 45, ridge_azimuth: 90}``, init's default for an attic
  (slopes facing north and south);
* ``roof 45 N-S``: ``roof: {pitch: 45, ridge_azimuth: 0}`` (slopes east and west);
* ``roof 30 notes``: the ridge read from the data set's notes (the long sides, where
  the eave vents are), pitch 30° (a Finnish tile roof, 1:2 to 1:1.5); R3's mono-pitch
  roof, high side south, as one slope facing north, 10°.

R3, R5 and R7 are held out: no choice (init's default, the priors) was made on them.
Sites at the towns' positions (the houses' are not published).

Usage (from the repository root)::

    python benchmarks/roof_planes.py [R2 R3 R4 R5 R6 R7] [--data ../shared/data]
        [--cases H facades "roof 45 E-W" ...]
"""

from __future__ import annotations

import sys
import tempfile
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT / "benchmarks"))

from heritage_bayes.config.data import DEFAULT_SURFACES  # noqa: E402
from init_without_radiation import (  # noqa: E402
    checked_sites,
    init_both,
    map_fit,
    site_parser,
)

#: the ridge's direction [°] from the data set's notes (*_YP*_tiedot.txt): the long sides
#: with the eave vents. R2: eave vents on the west side; R4, R5: north and south long
#: sides; R6: north-west and south-east; R7: east and west. R3: a mono-pitch roof.
NOTES_RIDGE = {"R2": 0.0, "R4": 90.0, "R5": 90.0, "R6": 45.0, "R7": 0.0}

CASES = (
    "H",
    "facades",
    "roof 45 E-W",
    "roof 45 N-S",
    "roof 30 notes",
    "roof 45 E-W on Tw",
    "roof 45 E-W shared",
)


def sun_on_the_roof(cfg, node: str = "Tw", shared: bool = False):
    """``cfg`` with init's two thermal nodes (thermal_2c's links, the ground's too) and the
    slopes' sun on ``node``: ``Tw``, the envelope node (the roof; as
    ``benchmarks/configs/trh1_attic_2c_roof.yaml``), or ``Ti``, the air; ``shared``: one
    aperture ``fI_roof`` for both slopes (same area, same covering)."""
    planes = list(cfg.data.surfaces)
    spec = {
        "name": "thermal_2c_sun_on_roof",
        "domain": "thermal",
        "nodes": {"Tw": "Cw", "Ti": "Ci"},
        "links": [
            ["Tw", "Te", "Gw"],
            ["Tw", "Ti", "Gi"],
            ["Ti", "Te", "Gfast"],
            ["Ti", "Tf", "Gf"],
        ],
        "inputs": ["Te", *[f"I_{s}" for s in planes], "Tf"],
        "outputs": ["Ti"],
        "sources": [
            {"input": f"I_{s}", "node": node, "gain": "fI_roof" if shared else f"fI_{s}"}
            for s in planes
        ],
    }
    sec = type(cfg.thermal).model_validate(
        {**cfg.thermal.model_dump(exclude_unset=True, exclude={"model", "options"}), "model": spec}
    )
    return cfg.model_copy(update={"thermal": sec})


def solar(cfg, site: str, case: str, area: float | None = None):
    """``cfg`` with the solar surfaces of ``case`` (validated as a config would be);
    ``area`` [m²]: the roof's, for the prior on its apertures (``data.roof.area``)."""
    raw = cfg.data.model_dump(exclude={"surfaces", "roof"}, exclude_unset=True)
    if case == "H":
        raw["surfaces"] = {"H": (0.0, 0.0)}
    elif case == "facades":
        raw["surfaces"] = dict(DEFAULT_SURFACES)
    elif case == "roof 30 notes" and site == "R3":
        raw["surfaces"] = {"roof_N": (10.0, 0.0)}
    else:
        pitch, ridge = {
            "roof 45 E-W": (45.0, 90.0),
            "roof 45 E-W on Tw": (45.0, 90.0),
            "roof 45 E-W shared": (45.0, 90.0),
            "roof 45 N-S": (45.0, 0.0),
            "roof 30 notes": (30.0, NOTES_RIDGE.get(site)),
        }[case]
        raw["roof"] = {"pitch": pitch, "ridge_azimuth": ridge}
        if area is not None:
            raw["roof"]["area"] = area
    data = type(cfg.data).model_validate(raw)
    cfg = cfg.model_copy(update={"data": data})
    if case.endswith("on Tw"):
        return sun_on_the_roof(cfg)
    return sun_on_the_roof(cfg, "Ti", shared=True) if case.endswith("shared") else cfg


def main(argv=None) -> int:
    ap = site_parser(__doc__)
    ap.add_argument("--cases", nargs="+", default=list(CASES), choices=CASES)
    ap.add_argument("--area", type=float, help="data.roof.area [m²] of the roof cases")
    args = checked_sites(ap, argv)
    print("validation FIT of Ti [%] of the thermal MAP, by solar surfaces and irradiance")
    with tempfile.TemporaryDirectory() as tmp:
        for name in args.sites:
            cfgs = init_both(name, args.data, Path(tmp))
            for label, cfg in (("measured", cfgs["measured"]), ("estimated", cfgs["none"])):
                row = []
                for case in args.cases:
                    ti, p = map_fit(solar(cfg, name, case, args.area), "thermal")
                    apertures = " ".join(
                        f"{k[3:]} {v:.3g}" for k, v in p.items() if k.startswith("fI_")
                    )
                    row.append(f"{case}: {ti:.1f}")
                    print(
                        f"{name} {label:<9} ({cfg.thermal.model}) {case:<14} FIT Ti {ti:5.1f} %"
                        f"   apertures [m²] {apertures}",
                        flush=True,
                    )
                print(f"{name} {label}: " + " | ".join(row), flush=True)
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
