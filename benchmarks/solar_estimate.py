"""Global radiation without a pyranometer: the estimate from the temperature range vs the
cloudless sky, against measured global horizontal irradiance.

For each site: the measured ``ghi`` [W/m²], the cloudless sky
(:func:`heritage_bayes.climate.clear_sky_weather`) and the Hargreaves-Samani estimate from
the outdoor air temperature alone
(:func:`heritage_bayes.climate.solar.temperature_range_weather`, kRs 0.16, FAO-56's
interior default), compared by solar day (daily totals [MJ/m²]) and by hour (daylight
hours: cloudless sky above 0) as bias (estimate - measured), RMSE and R² = 1 - SSE/SST
(SST about the measured mean; below 0 when worse than the mean).

KNMI De Bilt is the only site any figure may be tuned on: the row ``kRs (De Bilt)``
applies the kRs fitted there (least squares of the daily Rs on sqrt(ΔT)·Ra, 2011-2020)
to every site. The six TRH-1 sites (FMI weather beside each house; site positions are
the towns', the houses' are not published) are held out.

``--bristow-campbell``: also the daily R² and bias of Bristow and Campbell's
Rs = A·(1 - exp(-B·ΔT^C))·Ra (Agric. For. Meteorol. 31 (1984) 159-166,
doi:10.1016/0168-1923(84)90017-0; ΔT = Tmax - mean of today's and tomorrow's Tmin),
A, B, C fitted on De Bilt 2011-2020, beside Hargreaves-Samani's with kRs 0.16.

``--monthly``: instead, per site and calendar month, the estimate's and the cloudless
sky's irradiance summed over the hours with a measurement, divided by the measured sum.

``--fit CONFIG [...]``: instead, the validation FIT [%] of the MAP simulation of each
config's thermal section with its solar input as measured, estimated and cloudless
(``data.irradiance`` set to each; the measured columns are then ignored), with a lighter
optimiser (100 generations, 2 starts) than the configs'.

Usage (from the repository root)::

    python benchmarks/solar_estimate.py [--data ../shared/data] [--sites debilt R2 R3 ...]
    python benchmarks/solar_estimate.py --fit configs/trh1_attic.yaml
"""

from __future__ import annotations

import argparse
from pathlib import Path

import numpy as np
import pandas as pd

from heritage_bayes.climate.solar import (
    KRS_INTERIOR,
    clear_sky_weather,
    extraterrestrial_radiation_daily,
    temperature_range_weather,
)
from heritage_bayes.io import read_csv, read_knmi_hourly

ROOT = Path(__file__).resolve().parents[1]

#: name -> (folder under the data root, site); TRH-1 positions are the towns'.
SITES = {
    "debilt": ("knmi-debilt", {"latitude": 52.10, "longitude": 5.18, "altitude": 2.0}),
    "R2": ("trh1-espoo-attic", {"latitude": 60.21, "longitude": 24.66, "altitude": 30.0}),
    "R3": ("trh1-more-attics/R3", {"latitude": 60.21, "longitude": 24.66, "altitude": 30.0}),
    "R4": ("trh1-more-attics/R4", {"latitude": 61.50, "longitude": 23.76, "altitude": 110.0}),
    "R5": ("trh1-more-attics/R5", {"latitude": 61.50, "longitude": 23.76, "altitude": 110.0}),
    "R6": ("trh1-more-attics/R6", {"latitude": 61.26, "longitude": 24.03, "altitude": 90.0}),
    "R7": ("trh1-more-attics/R7", {"latitude": 60.29, "longitude": 25.04, "altitude": 50.0}),
}


def read_site(data: Path, name: str) -> pd.DataFrame:
    """``Te`` [°C] and ``ghi`` [W/m²] with stamps at the end of the hour they describe."""
    folder = data / SITES[name][0]
    if name == "debilt":  # Q: hourly sum ending at the stamp
        w = pd.concat([read_knmi_hourly(p) for p in sorted(folder.glob("uurgeg_260_*.txt.gz"))])
        return w[["Te", "ghi"]]
    w = read_csv(
        folder / "fmi.csv",
        time_column="t_UTC+2",
        timezone="UTC+2",
        columns={"Te": "Te", "ghi": "Rglob"},
        averaged=[],
    )
    # FMI radiation is a reading at the stamp (the sun says so, configs/trh1_attic.yaml):
    # restamp it as the hour centred on the reading, the convention of the estimates
    out = w[["Te", "ghi"]].copy()
    out.index = out.index + pd.Timedelta("30min")
    out["ghi"] = out["ghi"].clip(lower=0.0)
    return out


def fit_krs(w: pd.DataFrame, site: dict) -> float:
    """kRs [°C^-1/2] by least squares of daily measured Rs on sqrt(Tmax - Tmin)·Ra."""
    g = _days(w, site)
    x = np.sqrt(g["tmax"] - g["tmin"]) * g["ra"]
    return float((x * g["rs"]).sum() / (x * x).sum())


def scores(est: np.ndarray, meas: np.ndarray) -> tuple[float, float, float]:
    ok = np.isfinite(est) & np.isfinite(meas)
    e, m = est[ok], meas[ok]
    sse = float(np.sum((e - m) ** 2))
    return (
        float(np.mean(e - m)),
        float(np.sqrt(sse / len(e))),
        1 - sse / float(np.sum((m - m.mean()) ** 2)),
    )


def evaluate(w: pd.DataFrame, site: dict, krs_debilt: float) -> list[tuple]:
    te = w["Te"]
    te.attrs = {"interval": "1h"}
    cases = {
        "cloudless sky": clear_sky_weather(w.index, site, interval="1h")["ghi"],
        f"kRs {KRS_INTERIOR:g} (FAO-56)": temperature_range_weather(te, site)["ghi"],
        f"kRs {krs_debilt:.3f} (De Bilt)": temperature_range_weather(te, site, krs=krs_debilt)[
            "ghi"
        ],
    }
    meas = w["ghi"]
    day = (w.index - pd.Timedelta("30min") + pd.Timedelta(hours=site["longitude"] / 15)).floor("D")
    full = meas.groupby(day).count() == 24
    daily_m = meas.groupby(day).sum()[full] * 3600 / 1e6
    daylight = cases["cloudless sky"].to_numpy() > 0
    rows = []
    for label, est in cases.items():
        daily_e = est.groupby(day).sum()[full] * 3600 / 1e6
        d = scores(daily_e.to_numpy(), daily_m.to_numpy())
        h = scores(est.to_numpy()[daylight], meas.to_numpy()[daylight])
        rows.append(
            (label, int(full.sum()), *d, int(np.isfinite(meas.to_numpy()[daylight]).sum()), *h)
        )
    return rows


def _days(w: pd.DataFrame, site: dict) -> pd.DataFrame:
    """Complete solar days: Tmax, Tmin, next day's Tmin [°C], Rs and Ra [MJ/m²]."""
    day = (w.index - pd.Timedelta("30min") + pd.Timedelta(hours=site["longitude"] / 15)).floor("D")
    g = w.groupby(day).agg(
        tmax=("Te", "max"), tmin=("Te", "min"), rs=("ghi", "sum"), n=("ghi", "count")
    )
    g["tmin_next"] = g["tmin"].shift(-1)
    g = g[g["n"] == 24].dropna()
    g["rs"] *= 3600 / 1e6
    g["ra"] = extraterrestrial_radiation_daily(g.index.day_of_year, site["latitude"])
    return g


def _bristow_campbell(g: pd.DataFrame, a: float, b: float, c: float) -> pd.Series:
    dt = (g["tmax"] - (g["tmin"] + g["tmin_next"]) / 2).clip(lower=0.0)
    return a * (1 - np.exp(-b * dt**c)) * g["ra"]


def bristow_campbell_check(data: Path, debilt: pd.DataFrame, names) -> None:
    from scipy.optimize import least_squares

    g = _days(debilt.loc["2011":"2020"], SITES["debilt"][1])
    fit = least_squares(
        lambda p: _bristow_campbell(g, *p) - g["rs"],
        [0.7, 0.01, 2.0],
        bounds=([0.3, 1e-5, 0.5], [1.0, 1.0, 3.0]),
    )
    a, b, c = fit.x
    print(f"\nBristow-Campbell fitted on De Bilt 2011-2020: A {a:.3f}, B {b:.4f}, C {c:.3f}")
    print(f"{'site':<7}{'HS 0.16 R²':>11}{'bias':>7}{'BC R²':>8}{'bias':>7}  (daily, MJ/m²)")
    for name in names:
        g = _days(debilt if name == "debilt" else read_site(data, name), SITES[name][1])
        hs = KRS_INTERIOR * np.sqrt(g["tmax"] - g["tmin"]) * g["ra"]
        bc = _bristow_campbell(g, a, b, c)
        bh, _, rh = scores(hs.to_numpy(), g["rs"].to_numpy())
        bb, _, rb = scores(bc.to_numpy(), g["rs"].to_numpy())
        print(f"{name:<7}{rh:>11.3f}{bh:>7.2f}{rb:>8.3f}{bb:>7.2f}")


def monthly_ratios(w: pd.DataFrame, site: dict) -> pd.DataFrame:
    """Estimate / measured and cloudless / measured irradiance by calendar month [-]."""
    te = w["Te"].copy()
    te.attrs = {"interval": "1h"}
    ok = w["ghi"].notna().to_numpy()
    cols = {
        "estimate": temperature_range_weather(te, site)["ghi"],
        "cloudless": clear_sky_weather(w.index, site, interval="1h")["ghi"],
        "measured": w["ghi"],
    }
    sums = pd.DataFrame({k: v[ok] for k, v in cols.items()}).groupby(w.index[ok].month).sum()
    return sums[["estimate", "cloudless"]].div(sums["measured"], axis=0).T


def map_fits(path: Path) -> dict[str, float]:
    """Validation FIT [%] of the thermal MAP per solar input (as tests/test_init.py)."""
    import sys

    sys.path.insert(0, str(ROOT / "benchmarks"))
    from _common import config_map
    from heritage_bayes.config import load_config
    from heritage_bayes.inference.results import fit_metrics

    cfg = load_config(path)
    cfg = cfg.model_copy(
        update={"optimizer": cfg.optimizer.model_copy(update={"maxiter": 100, "starts": 2})}
    )
    out = {}
    for mode in ("measured", "estimated", "clear_sky"):
        c = cfg.model_copy(update={"data": cfg.data.model_copy(update={"irradiance": mode})})
        prep, model, lp, mp = config_map(c, "thermal")
        y = lp.simulate_frame(
            mp.theta[None], prep.model_inputs("thermal", model), prep.calibration.start
        )
        v, obs = prep.validation, prep.observed("thermal", model)
        out[mode] = fit_metrics(obs[v.start : v.stop, 0], y[0][0][v.start : v.stop, 0])["FIT"]
    return out


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--data", type=Path, default=ROOT.parent / "shared" / "data")
    ap.add_argument("--sites", nargs="+", default=list(SITES), choices=list(SITES))
    ap.add_argument("--monthly", action="store_true", help="monthly ratios to measured")
    ap.add_argument("--bristow-campbell", action="store_true", help="daily BC vs HS")
    ap.add_argument("--fit", nargs="+", type=Path, help="configs: thermal MAP FIT per input")
    args = ap.parse_args(argv)
    if args.monthly:
        data = args.data
        for name in args.sites:
            w = read_site(data, name)
            print(f"{name}: irradiance / measured by month")
            print(monthly_ratios(w, SITES[name][1]).round(2).to_string())
        return 0
    if args.fit:
        for path in args.fit:
            fits = map_fits(path)
            print(
                f"{path}: validation FIT Ti (thermal MAP) "
                + ", ".join(f"{k} {v:.1f} %" for k, v in fits.items())
            )
        return 0
    debilt = read_site(args.data, "debilt")
    krs = fit_krs(debilt.loc["2011":"2020"], SITES["debilt"][1])
    print(
        f"kRs fitted on De Bilt 2011-2020: {krs:.4f} °C^-1/2 "
        f"(FAO-56 interior default {KRS_INTERIOR})"
    )
    head = (
        f"{'site':<7}{'input':<22}{'days':>6}{'bias MJ/m²':>11}{'RMSE':>7}{'R²':>7}"
        f"{'hours':>8}{'bias W/m²':>10}{'RMSE':>7}{'R²':>7}"
    )
    print(head)
    for name in args.sites:
        w = debilt if name == "debilt" else read_site(args.data, name)
        for r in evaluate(w, SITES[name][1], krs):
            print(
                f"{name:<7}{r[0]:<22}{r[1]:>6}{r[2]:>11.2f}{r[3]:>7.2f}{r[4]:>7.2f}"
                f"{r[5]:>8}{r[6]:>10.1f}{r[7]:>7.1f}{r[8]:>7.2f}"
            )
    if args.bristow_campbell:
        bristow_campbell_check(args.data, debilt, args.sites)
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
