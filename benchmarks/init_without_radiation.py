"""`hbayes init` on the TRH-1 attics from their raw files, with and without the radiation
columns: what a site without a pyranometer gets.

For each attic (``trh1-espoo-attic/`` as R2, ``trh1-more-attics/R3`` ... ``R7``): init on
the logger file and the FMI weather as published (measured ``Rglob``, ``Rdif``), and on a
copy of the weather without those two columns (written to a temporary folder; init then
writes ``data.irradiance: estimated``); the thermal and hygric MAP validation FIT [%]
(100 generations, 2 starts: lighter than the configs' optimiser), and for the weather
without radiation also with ``data.irradiance: clear_sky`` (what init wrote before the
estimate); for the weather as published also with ``data.ground_temperature: {mode:
annual_mean}`` (the former default of ``Tf``). Of the thermal MAP, the static solar gain
ΣfI/(Ge + Gf) [K per W/m²] (the sum of the apertures: fI_H, or the two roof slopes' since
init writes ``data.roof`` for an attic; the scale of Ci, Ge, Gf and fI is not
identifiable, the ratio is) and the ground's share Gf/(Ge + Gf) [-]. The hygric section depends on
neither setting: fitted once per site. Sites at the towns' positions (the houses' are not
published). Nothing here is tuned: the attics are held out.

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


def map_fit(cfg, sec: str) -> tuple[float, dict]:
    """Validation FIT [%] of a section's MAP simulation (as tests/test_init.py) and the
    MAP parameters."""
    opt = cfg.optimizer.model_copy(update={"maxiter": 100, "starts": 2})
    prep, model, lp, mp = config_map(cfg.model_copy(update={"optimizer": opt}), sec)
    u = prep.model_inputs(sec, model)
    y = lp.simulate_frame(mp.theta[None], u, prep.calibration.start)[0][0]
    v, obs = prep.validation, prep.observed(sec, model)
    fit = fit_metrics(obs[v.start : v.stop, 0], y[v.start : v.stop, 0])["FIT"]
    return fit, dict(zip(lp.params.names, mp.theta, strict=True))


def _variant(cfg, **data):
    return cfg.model_copy(update={"data": cfg.data.model_copy(update=data)})


def site_parser(doc: str) -> argparse.ArgumentParser:
    """The sites and ``--data`` of the attic benchmarks' command lines (a caller may add
    options before :func:`checked_sites`)."""
    ap = argparse.ArgumentParser(description=doc.split("\n\n")[0])
    ap.add_argument("sites", nargs="*", help=f"default: all of {list(SITES)}")
    ap.add_argument("--data", type=Path, default=ROOT.parent / "shared" / "data")
    return ap


def checked_sites(ap: argparse.ArgumentParser, argv) -> argparse.Namespace:
    args = ap.parse_args(argv)
    args.sites = args.sites or list(SITES)
    if set(args.sites) - set(SITES):
        ap.error(
            f"unknown site(s) {sorted(set(args.sites) - set(SITES))}; choose from {list(SITES)}"
        )
    return args


def init_both(name: str, data: Path, tmp: Path) -> dict:
    """init's configs of an attic on its FMI weather as published (``"measured"``) and
    on a copy without ``Rglob``, ``Rdif`` (``"none"``), written under ``tmp``."""
    folder, lat, lon = SITES[name]
    d = data / folder
    work = Path(tmp) / name
    (work / "data").mkdir(parents=True)
    bare = work / "data" / "fmi.csv"
    pd.read_csv(d / "fmi.csv").drop(columns=["Rglob", "Rdif"]).to_csv(bare, index=False)
    cfgs = {}
    for label, weather in (("measured", d / "fmi.csv"), ("none", bare)):
        out = work / label / "config.yaml"
        out.parent.mkdir()
        init_config(
            d / "roofmiddle_airmiddle.csv", weather, output=out, latitude=lat, longitude=lon
        )
        cfgs[label] = load_config(out)
    return cfgs


def main(argv=None) -> int:
    args = checked_sites(site_parser(__doc__), argv)
    print("validation FIT [%] of the MAP and the thermal MAP's aperture, by input")
    with tempfile.TemporaryDirectory() as tmp:
        for name in args.sites:
            cfgs = init_both(name, args.data, Path(tmp))
            m, n = cfgs["measured"], cfgs["none"]
            annual = m.data.ground_temperature.model_copy(update={"mode": "annual_mean"})
            cases = {
                f"{m.data.irradiance}": m,
                "measured, Tf annual mean": _variant(m, ground_temperature=annual),
                f"no radiation: {n.data.irradiance}": n,
                "no radiation: clear_sky": _variant(n, irradiance="clear_sky"),
            }
            pi, _ = map_fit(m, "hygric")
            print(f"{name} ({m.thermal.model}, {m.hygric.model}): FIT Pi {pi:.1f} %", flush=True)
            for label, cfg in cases.items():
                ti, p = map_fit(cfg, "thermal")
                g = p["Ge"] + p.get("Gf", 0.0)  # [W/K] to the fixed temperatures
                print(
                    f"  {label:<28} FIT Ti {ti:5.1f} %   solar gain ΣfI/G "
                    f"{sum(v for k, v in p.items() if k.startswith('fI_')) / g:.4f} K/(W/m²)"
                    f"   ground share Gf/G {p.get('Gf', 0) / g:.2f}",
                    flush=True,
                )
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
