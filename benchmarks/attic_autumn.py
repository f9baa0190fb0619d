"""Where the attics' autumn validation misses: the residual by weather regime.

The validation residual (measured - simulated Ti) of ``thermal_1c``'s MAP (or of
``attic_physics.py``'s candidate ``--model``) on init's config (``attic_physics.py``'s
``wind``: the package; or one of its ``--variant``s), tuning attics R2, R4, R6 only
(the held-out ones are refused), against the weather of each local day (UTC+2, FMI's
file):

- the day's clearness index ``K`` (measured global radiation over a cloudless sky's,
  pvlib Ineichen-Perez, :func:`heritage_bayes.climate.solar.clear_sky_weather`; days
  whose cloudless sky sums under 300 W/m² over the day's hours are left out), and the
  night's: the mean of the two days that bracket it (the night ending on the morning
  of a day: the day before and the day itself); *clear* both at least 0.5, *overcast*
  both at most 0.25;
- the long-wave deficit of the sky the night saw, :math:`(1 - N)\\,\\sigma(1 -
  \\varepsilon_{clear})T_e^4` [W/m²] with the clear sky's emissivity from the dew point
  (Berdahl and Martin 1984) and the cloud fraction :math:`N = 1 - K` (Crawford and
  Duchon 1999);
- the day's precipitation [mm], mean wind speed [m/s], relative humidity [%], dew
  point [°C], the night's minimum air temperature (frost: below 0 °C), the month.

Printed: the share of the squared error in the daily means, the correlation of the
daily mean residual (and of the night's, 00-06 h) with each, and the mean residual by
regime with the number of days; ``--figures DIR`` writes one figure per attic.

Usage (from the repository root)::

    python benchmarks/attic_autumn.py [ROOM ...] [--estimated] [--variant sky]
        [--model sky] [--figures docs/assets]
"""

from __future__ import annotations

import argparse
import sys
import tempfile
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT / "benchmarks"))

import numpy as np  # noqa: E402
import pandas as pd  # noqa: E402

import attic_physics as ap  # noqa: E402

TUNING = ["R2", "R4", "R6"]
LOCAL = pd.Timedelta(hours=2)  # FMI's and the loggers' clock, UTC+2
CLEAR, OVERCAST = 0.5, 0.25  # the night's bracketing days' clearness [-]
SIGMA = 5.670374419e-8  # [W/(m² K⁴)]


def days(room: str, variant: str, bare: bool, data: Path, work: Path, model="thermal_1c"):
    """Hourly residual [K] of the validation (local time) and a table of its days."""
    from heritage_bayes.climate.psychro import dew_point
    from heritage_bayes.climate.solar import clear_sky_weather

    cfg, prep, _, _, _, obs, y = ap.simulated(room, variant, bare, data, work, model)
    v = prep.validation
    e = pd.Series(obs[v] - y[v], index=prep.frame.index[v] + LOCAL)
    o = pd.Series(obs[v], index=e.index)
    raw = ap._fmi(room, data)  # UTC
    site = cfg.site.model_dump()
    cs = clear_sky_weather(raw.index, site)["ghi"]
    wx = raw.assign(cs=cs.to_numpy(), Td=dew_point(raw["Te"].to_numpy(), raw["RHe"].to_numpy()))
    wx.index = wx.index + LOCAL
    g = wx.groupby(wx.index.floor("D"))
    d = pd.DataFrame(
        {
            "K": (g["Rglob"].sum() / g["cs"].sum()).where(g["cs"].sum() > 300.0).clip(0, 1),
            "precip": g["precip"].sum(),
            "wind": g["ws"].mean(),
            "RH": g["RHe"].mean(),
            "Td": g["Td"].mean(),
            "Te": g["Te"].mean(),
        }
    )
    night = wx[wx.index.hour < 7]
    d["Te_min"] = night["Te"].groupby(night.index.floor("D")).min()
    d["K_night"] = (d["K"].shift(1) + d["K"]) / 2
    both = pd.concat([d["K"].shift(1), d["K"]], axis=1)
    d["night"] = np.select(
        [both.min(axis=1) >= CLEAR, both.max(axis=1) <= OVERCAST], ["clear", "overcast"], "between"
    )
    d.loc[both.isna().any(axis=1), "night"] = "unknown"
    tdp = d["Td"] / 100.0
    eps = 0.711 + 0.56 * tdp + 0.73 * tdp**2
    d["LW"] = (
        d["K_night"]
        * SIGMA
        * (1 - eps)
        * (night["Te"].groupby(night.index.floor("D")).mean() + 273.15) ** 4
    )
    eday = e.dropna().groupby(e.dropna().index.floor("D"))
    d["e"] = eday.mean()
    d["n_h"] = eday.size()
    en = e[e.index.hour < 7].dropna()
    d["e_night"] = en.groupby(en.index.floor("D")).mean()
    d = d[d["n_h"] >= 20]
    d["month"] = d.index.month
    return e, o, d


def summary(room: str, e: pd.Series, o: pd.Series, d: pd.DataFrame) -> None:
    """Print the split of the squared error, the correlations and the regimes."""
    ok = e.dropna()
    daily = ok.groupby(ok.index.floor("D")).transform("mean")
    oo = o.dropna()
    den = ((oo - oo.mean()) ** 2).sum()
    fit = 100 * (1 - np.sqrt((ok**2).sum() / den))
    share = (daily**2).sum() / (ok**2).sum()
    print(f"\n{room}: validation FIT {fit:.1f} %, {len(d)} days, daily means "
          f"{100 * share:.0f} % of the squared error (FIT with them perfect "
          f"{100 * (1 - np.sqrt(((ok - daily) ** 2).sum() / den)):.1f}, with the within-day "
          f"rest perfect {100 * (1 - np.sqrt((daily**2).sum() / den)):.1f}); mean residual "
          f"{ok.mean():+.2f} K")  # fmt: skip
    cols = ["K", "K_night", "LW", "precip", "wind", "RH", "Td", "Te_min", "Te"]
    print("| correlation with | " + " | ".join(cols) + " |")
    for target in ("e", "e_night"):
        r = [d[[target, c]].dropna().corr().iloc[0, 1] for c in cols]
        n = [len(d[[target, c]].dropna()) for c in cols]
        print(
            f"| {target} | "
            + " | ".join(f"{x:+.2f} ({k})" for x, k in zip(r, n, strict=True))
            + " |"
        )
    regimes = {
        "night clear": d["night"] == "clear",
        "night overcast": d["night"] == "overcast",
        "night between": d["night"] == "between",
        "wet (>= 1 mm)": d["precip"] >= 1.0,
        "dry (0 mm)": d["precip"] == 0.0,
        "frost night": d["Te_min"] < 0.0,
        "no frost": d["Te_min"] >= 0.0,
        "calm (< 2.5 m/s)": d["wind"] < 2.5,
        "windy (>= 4 m/s)": d["wind"] >= 4.0,
        "humid (RH >= 90 %)": d["RH"] >= 90.0,
        "dry air (RH < 80 %)": d["RH"] < 80.0,
    }
    regimes |= {f"month {m}": d["month"] == m for m in sorted(d["month"].unique())}
    print("| regime | days | daily mean residual [K] | 00-06 h [K] | share of the daily error |")
    tot = (d["e"] ** 2).sum()
    for label, sel in regimes.items():
        s = d[sel]
        print(f"| {label} | {len(s)} | {s['e'].mean():+.2f} | {s['e_night'].mean():+.2f} | "
              f"{100 * (s['e'] ** 2).sum() / tot:.0f} % |")  # fmt: skip


def figure(room: str, d: pd.DataFrame, out: Path, label: str) -> None:
    """The daily mean residual against each weather quantity, one panel each."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    panels = [("K_night", "night's clearness [-]"), ("LW", "sky's long-wave deficit [W/m²]"),
              ("precip", "precipitation [mm/d]"), ("wind", "wind [m/s]"),
              ("Td", "dew point [°C]"), ("Te_min", "night's minimum Te [°C]")]  # fmt: skip
    fig, axes = plt.subplots(2, 4, figsize=(13, 5.6), layout="constrained")
    for ax, (col, xl) in zip(axes.flat, panels, strict=False):
        ax.scatter(d[col], d["e"], s=9, c=d["month"], cmap="viridis")
        ax.axhline(0, color="0.6", lw=0.8)
        ax.set_xlabel(xl)
        ax.set_ylabel("daily mean residual [K]")
    ax = axes.flat[6]
    ax.boxplot([d.loc[d["month"] == m, "e"].dropna() for m in sorted(d["month"].unique())],
               tick_labels=[str(m) for m in sorted(d["month"].unique())])  # fmt: skip
    ax.axhline(0, color="0.6", lw=0.8)
    ax.set_xlabel("month")
    ax.set_ylabel("daily mean residual [K]")
    ax = axes.flat[7]
    ax.plot(d.index, d["e"], lw=0.9, label="daily mean")
    ax.plot(d.index, d["e_night"], lw=0.6, label="00-06 h")
    ax.axhline(0, color="0.6", lw=0.8)
    ax.legend(fontsize=7)
    ax.tick_params(axis="x", labelrotation=45, labelsize=7)
    fig.suptitle(f"{room}: validation residual (measured − simulated Ti), MAP, {label}")
    fig.savefig(out / f"attic_autumn_{room}.png", dpi=80)
    plt.close(fig)


def main(argv=None) -> int:
    p = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    p.add_argument("rooms", nargs="*", default=TUNING)
    p.add_argument("--data", type=Path, default=ROOT.parent / "shared" / "data")
    p.add_argument("--variant", default="wind", help="attic_physics.py's (default: the package)")
    p.add_argument("--estimated", action="store_true", help="without the radiation columns")
    p.add_argument("--model", default="thermal_1c", choices=list(ap.MODELS),
                   help="attic_physics.py's candidate (default: thermal_1c)")  # fmt: skip
    p.add_argument("--figures", type=Path, default=None, help="folder for the figures")
    args = p.parse_args(argv)
    if set(args.rooms) - set(TUNING):
        p.error(f"tuning attics only: {TUNING} (the others are held out)")
    work = Path(tempfile.mkdtemp(prefix="attic_autumn_"))
    ap._register()
    for room in args.rooms:
        e, o, d = days(room, args.variant, args.estimated, args.data, work, args.model)
        summary(room, e, o, d)
        if args.figures:
            label = ("estimated" if args.estimated else "measured") + f" radiation, {args.variant}"
            label += f", {args.model}"
            figure(room, d, args.figures, label)
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
