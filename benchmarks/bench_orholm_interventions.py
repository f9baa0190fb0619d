"""Ørholm validation of the interventions (issue 29): a thermostat re-simulated as a
measure on a free-running version of the room, against what the logger recorded.

Ørholm storage building P (../shared/data/orholm, Boesgaard et al. 2022) is heated to a
floor of about 11 °C every winter and its RH is held near 50 % all year (README there;
``configs/orholm.yaml``). The data set holds indoor T and RH and DMI outdoor T and RH
only: **no heating power or energy was logged**, so the energy of the measure has no
measured counterpart, and the room's absolute conductances [W/K] are not identified
(no known heat input): the energy interval comes from the priors.

Steps (one run, seeded):

1. calibrate a **free-running** version of the room (``configs/orholm.yaml`` without the
   thermostat and the humidistat: thermal_1c with its ground node and constant gain,
   hygric_1c) on May-October 2015 (:data:`CAL`), when the heating floor does not act
   (the script checks: no logged hour within 1 K of the floor), with a clear-sky
   irradiance proxy on a horizontal roof (DMI has no radiation; ``--no-sun``: none, as
   the shipped config; calibrated on June-September without it, the constant gain and
   the ground node took the summer's 5-6 K excess and the free-running winter came out
   at 15-16 °C, warmer than the heated room was: no heating at all);
2. the measure: a thermostat at the floor seen in the calibration year's winter
   (:data:`FLOOR_FROM`, 1st percentile of the logged hourly Ti), unlimited power;
3. every posterior draw simulated over the year :data:`VAL` (the winter 2015/16 inside,
   after the calibration period), doing nothing and with the measure, paired, with the
   noise draws (:func:`heritage_bayes.projection.engine.simulate_measures`);
4. monthly means of Ti and RH (5-50-95 % over the draws) against the logged ones,
   hours below the floor, and the heating energy interval [kWh/a]; the figure
   ``docs/assets/orholm_interventions.png``.

The hygric model: the RH of the calibration summer lies within 49-54 % (the humidistat
acts all year, 2009-2018), so no free-running moisture behaviour is in the data; the
"free-running" hygric model is the humidity-controlled room, and the RH comparison
checks what the heating does to the RH at that moisture.

Run from the repository root: ``python benchmarks/bench_orholm_interventions.py
[--out DIR] [--draws N] [--reuse]`` (``--reuse``: the run directory of an earlier run).
"""

from __future__ import annotations

import argparse
import copy
import json
import os
import resource
import time
from pathlib import Path

import numpy as np
import pandas as pd

ROOT = Path(__file__).resolve().parents[1]
CONFIG = ROOT / "configs" / "orholm.yaml"
CAL = ("2015-05-01", "2015-11-01")  # [UTC] May-October: the heating floor does not act
FLOOR_FROM = ("2015-01-01", "2015-04-01")  # the floor's level: winter of the calibration year
VAL = ("2015-11-01", "2016-11-01")  # the year simulated: after the calibration period
FIGURE = ROOT / "docs" / "assets" / "orholm_interventions.png"


def free_config(clear_sky: bool = True):
    """``configs/orholm.yaml`` without its controllers, calibrated on :data:`CAL`; with
    ``clear_sky`` a clear-sky irradiance proxy on a horizontal roof as solar input."""
    from heritage_bayes.config import parse_config, read_yaml

    raw, _ = read_yaml(CONFIG)
    raw = copy.deepcopy(raw)
    raw["name"] = "orholm_free_summer"
    raw["thermal"]["options"] = {"ground": True, "source": True}  # no thermostat
    raw["hygric"]["options"] = {}  # no humidistat
    raw["periods"] = {"calibration": {"start": CAL[0], "end": CAL[1]}, "warmup": "14d"}
    if clear_sky:  # DMI has no radiation: a clear-sky proxy on a horizontal roof
        raw["data"]["irradiance"] = "clear_sky"
        raw["data"]["surfaces"] = {"roof": [0, 0]}
    raw["sampler"] = {"max_time": "15min"}
    raw["report"] = False
    return parse_config(raw, source=f"{CONFIG} (free-running)", base_dir=str(CONFIG.parent))


def logged(run) -> pd.DataFrame:
    """The logged indoor Ti [°C], RHi [%] on the UTC hours (the run's own reader)."""
    from heritage_bayes.sources import read_sources

    m = read_sources(run.config).measurements[0]
    return m[["Ti", "RHi"]].astype(float)


def main() -> int:
    ap = argparse.ArgumentParser()
    ap.add_argument("--out", default="reports/bench-orholm-free")
    ap.add_argument("--draws", type=int, default=200)
    ap.add_argument("--reuse", action="store_true")
    ap.add_argument(
        "--no-sun", action="store_true", help="no solar proxy (the shipped orholm.yaml's choice)"
    )
    args = ap.parse_args()
    from heritage_bayes.calibration.calibrate import run_calibration
    from heritage_bayes.projection import parse_projection_config
    from heritage_bayes.projection.engine import select_draws, simulate_measures
    from heritage_bayes.projection.interventions import Measure
    from heritage_bayes.projection.weather import baseline_weather, model_inputs
    from heritage_bayes.run import load_run

    t0, c0 = time.perf_counter(), time.process_time()
    out = Path(args.out)
    if not args.reuse:
        run_calibration(free_config(not args.no_sun), out_dir=out, quiet=True, report=False)
    t_cal, c_cal = time.perf_counter() - t0, time.process_time() - c0
    run = load_run(out)
    obs = logged(run)
    winter = obs.loc[FLOOR_FROM[0] : FLOOR_FROM[1]]
    t_set = float(np.percentile(winter["Ti"].dropna(), 1))
    cal = obs.loc[CAL[0] : CAL[1]]
    near = int((cal["Ti"] < t_set + 1.0).sum())
    print(
        f"free-running calibration on {CAL[0]}..{CAL[1]} ({len(cal)} logged hours, "
        f"{near} within 1 K of the floor {t_set:.2f} °C = 1st percentile of Ti "
        f"{FLOOR_FROM[0]}..{FLOOR_FROM[1]}): wall {t_cal:.0f} s, CPU {c_cal:.0f} s; "
        f"converged {run.summary.get('converged')}; load average {os.getloadavg()[0]:.1f}",
        flush=True,
    )
    pcfg = parse_projection_config({
        "draws": args.draws, "seed": 1,
        "morphing": [{"scenario": "none", "horizon": 2016, "method": "shift",
                      "deltas": {"Te": [0.0] * 12}}],
    })  # fmt: skip
    weather, site, _ = baseline_weather(run, pcfg)
    inputs = model_inputs(run, pcfg, weather, site, "Ørholm DMI weather")
    inputs = inputs.loc[pd.Timestamp(VAL[0], tz="UTC") : pd.Timestamp(VAL[1], tz="UTC")]
    draws = select_draws(run, args.draws, 1)
    measure = Measure("thermostat", thermostat=(t_set, None, None, np.inf))
    nothing, per = simulate_measures(run, draws, [inputs], [measure], seed=1, chunk=50)
    r0, r1 = nothing[0], per["thermostat"][0]
    months = r1.months
    o = obs.loc[months[0] : months[-1] + pd.offsets.MonthEnd(1)]
    from heritage_bayes.climate.psychro import saturation_vapour_pressure

    o = o.assign(Pi=o["RHi"] / 100.0 * saturation_vapour_pressure(o["Ti"]))
    om = o.groupby(o.index.tz_localize(None).to_period("M")).mean()
    om.index = om.index.to_timestamp().tz_localize("UTC")
    om = om.reindex(months)
    # the noise-free vapour pressure of the hygric model (no controller touches it)
    hy = run.models["hygric"]
    u0 = inputs[list(hy.input_names)].to_numpy(float)[:720].mean(axis=0)
    Pi = hy.forward(draws.model["hygric"], inputs[list(hy.input_names)].to_numpy(float),
                    3600.0, u_init=u0)[0][..., 0]  # fmt: skip
    per = inputs.index.tz_localize(None).to_period("M")
    Pm = np.stack([Pi[:, per == p.tz_localize(None).to_period("M")].mean(axis=1)
                   for p in months], axis=1)  # fmt: skip

    def q(x):
        return np.nanpercentile(x, [5, 50, 95], axis=0)

    rows = []
    for j, mth in enumerate(months):
        row = {"month": mth.strftime("%Y-%m"), "Ti_logged": om["Ti"].iloc[j],
               "RHi_logged": om["RHi"].iloc[j], "Pi_logged": om["Pi"].iloc[j],
               "Pi_q50": float(np.median(Pm[:, j]))}  # fmt: skip
        for lab, r in (("nothing", r0), ("thermostat", r1)):
            for v, arr in (("Ti", r.Ti_month), ("RHi", r.RHi_month)):
                a, b, c = q(arr[:, j])
                row |= {f"{v}_{lab}_q05": a, f"{v}_{lab}_q50": b, f"{v}_{lab}_q95": c}
        rows.append(row)
    tab = pd.DataFrame(rows)
    pd.set_option("display.width", 200)
    print(tab.round(2).to_string(index=False))
    e = r1.costs["heating_energy"].to_numpy()
    pk = r1.costs["heating_peak"].to_numpy()
    eq, pq = np.percentile(e, [5, 50, 95]), np.percentile(pk, [5, 50, 95])
    heated = tab["Ti_logged"] < t_set + 2.0  # the months the floor held the logged air
    inside = (tab["Ti_logged"] >= tab["Ti_thermostat_q05"]) & (
        tab["Ti_logged"] <= tab["Ti_thermostat_q95"]
    )
    inside_rh = (tab["RHi_logged"] >= tab["RHi_thermostat_q05"]) & (
        tab["RHi_logged"] <= tab["RHi_thermostat_q95"]
    )
    d_t = (tab["Ti_thermostat_q50"] - tab["Ti_logged"])[heated]
    d_rh = (tab["RHi_thermostat_q50"] - tab["RHi_logged"])[heated]
    d_rh0 = (tab["RHi_nothing_q50"] - tab["RHi_logged"])[heated]
    g = run.draws("thermal")
    scale = {k: np.percentile(v, [5, 50, 95]).tolist() for k, v in g.items() if k.startswith("G")}
    summary = {
        "t_set": t_set,
        "heated_months": tab["month"][heated].tolist(),
        "Ti_median_minus_logged_heated": [float(d_t.min()), float(d_t.max())],
        "RHi_median_minus_logged_heated": [float(d_rh.min()), float(d_rh.max())],
        "RHi_nothing_median_minus_logged_heated": [float(d_rh0.min()), float(d_rh0.max())],
        "Ti_logged_inside_90": f"{int(inside.sum())}/{len(tab)}",
        "RHi_logged_inside_90": f"{int(inside_rh.sum())}/{len(tab)}",
        "heating_energy_kWh_a": eq.tolist(),
        "heating_peak_kW": pq.tolist(),
        "energy_q95_over_q05": float(eq[2] / eq[0]) if eq[0] > 0 else None,
        "Pi_median_minus_logged_heated": [
            float((tab["Pi_q50"] - tab["Pi_logged"])[heated].min()),
            float((tab["Pi_q50"] - tab["Pi_logged"])[heated].max()),
        ],
        "months_heated_in_median_draw": tab["month"][
            tab["Ti_thermostat_q50"] > tab["Ti_nothing_q50"] + 0.05
        ].tolist(),
        "conductances_W_K": scale,
        "draws": int(args.draws),
    }
    print(json.dumps(summary, indent=1, default=float))
    _figure(tab, summary, months)
    peak = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024**2
    print(
        f"total wall {time.perf_counter() - t0:.0f} s, CPU {time.process_time() - c0:.0f} s, "
        f"peak RSS {peak:.2f} GB; figure {FIGURE.relative_to(ROOT)}; load average "
        f"{os.getloadavg()[0]:.1f}",
        flush=True,
    )
    return 0


def _figure(tab: pd.DataFrame, s: dict, months) -> None:
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    x = np.arange(len(tab))
    fig, axes = plt.subplots(1, 2, figsize=(11, 3.8), constrained_layout=True)
    for ax, v, unit in ((axes[0], "Ti", "°C"), (axes[1], "RHi", "%")):
        for lab, col, name in (
            ("nothing", "#999999", "free-running (doing nothing)"),
            ("thermostat", "#c0392b", f"thermostat {s['t_set']:.1f} °C"),
        ):
            ax.fill_between(
                x,
                tab[f"{v}_{lab}_q05"],
                tab[f"{v}_{lab}_q95"],
                color=col,
                alpha=0.3,
                lw=0,
                label=f"{name}, 90 % interval",
            )
            ax.plot(x, tab[f"{v}_{lab}_q50"], color=col, lw=1.5)
        ax.plot(x, tab[f"{v}_logged"], "ko", ms=4, label="logged (heated and humidistat)")
        ax.set_xticks(x, [m.strftime("%b\n%Y") if m.month in (1, 7) else m.strftime("%b")
                          for m in months], fontsize=8)  # fmt: skip
        ax.set_ylabel(f"monthly mean {v} [{unit}]")
        ax.grid(alpha=0.3)
    axes[0].legend(fontsize=8, loc="upper left")
    e = s["heating_energy_kWh_a"]
    fig.suptitle(
        f"Ørholm store P, {VAL[0][:7]} to {VAL[1][:7]} (not calibrated on): the room "
        f"calibrated free-running on {CAL[0][:7]} to {CAL[1][:7]}, with a thermostat\n"
        f"heating energy {e[1]:,.0f} kWh/a, 90 % interval [{e[0]:,.0f}, {e[2]:,.0f}]: "
        "from the priors (no heating power was logged)",
        fontsize=9,
    )
    FIGURE.parent.mkdir(parents=True, exist_ok=True)
    fig.savefig(FIGURE, dpi=110)
    plt.close(fig)


if __name__ == "__main__":
    raise SystemExit(main())
