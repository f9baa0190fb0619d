"""What the attics' summer-noon residual is: cheap checks against the data.

Three diagnostics on the tuning attics R2, R4, R6 (the held-out ones are refused),
each printed as a table (``docs/science/real_rooms.md``, "The attics' daily shapes
checked against the data"):

- ``--clock``: the FMI radiation's time stamp. On clear days (the day's global
  radiation at least 0.85 of a cloudless sky's, its hourly ratio to it steady), the
  measured ``Rglob`` against the cloudless sky (pvlib Ineichen-Perez) read four ways:
  the value at the stamp, the mean of the hour ending, centred on, or starting at the
  stamp; for each the RMS difference after the best scale [W/m²], and the shift of the
  stamps [min] that fits best (per day, and over all clear days).
- ``--seasons``: the thermal_1c MAP (as ``attic_physics.py``: init's config, measured
  radiation, 100 generations, 2 starts) against the measured attic by month: the gain
  of the measured within-day anomaly on the simulated one (1: the model's daily swing
  right; below 1: too large), and the phase of the daily first harmonic, measured
  minus simulated [h] (negative: the attic peaks before the model).
- ``--sun``: the same MAP's May-August days in quartiles of the roof planes' daily mean
  irradiance: the noon residual (11-15 h, UTC+2) and the daily range measured and
  simulated [K].
- ``--slopes``: the calibration residual fitted on one more input through the MAP's
  time constant (each 45° slope's sun, N, E, S, W, the horizontal's, the roof's
  squared): the June-August noon residual left.
- ``--variant``: the MAP of one of ``attic_physics.py``'s variants (default ``wind``,
  init's config) for the three above and the one below.
- ``--model``, ``--estimated``: another of ``attic_physics.py``'s candidate models
  (``--seasons``, ``--sun``; e.g. ``air_feed``), the weather without its radiation.
- ``--validation``: the validation residual by month and hour, its worst days, and the
  validation FIT a correction by one more input would reach (a ceiling: fitted on the
  validation itself).

Usage (from the repository root)::

    python benchmarks/attic_diagnostics.py [ROOM ...] [--clock] [--seasons] [--sun]
        [--slopes] [--validation] [--variant snow0]
"""

from __future__ import annotations

import argparse
import functools
import sys
import tempfile
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT / "benchmarks"))

import numpy as np  # noqa: E402
import pandas as pd  # noqa: E402

from real_rooms import ROOMS  # noqa: E402

TUNING = ["R2", "R4", "R6"]
#: the conventions of an hourly irradiance: (start, end) of its mean relative to the
#: stamp [min], or None for the value at the stamp
CONVENTIONS = {
    "value at the stamp": None,
    "mean of the hour ending": (-60, 0),
    "mean of the hour centred": (-30, 30),
    "mean of the hour starting": (0, 60),
}


def clear_sky_minutes(index: pd.DatetimeIndex, site: tuple) -> pd.Series:
    """A cloudless sky's global irradiance [W/m²] every minute over ``index`` ± 2 h."""
    import pvlib

    lat, lon = site
    fine = pd.date_range(index[0] - pd.Timedelta("2h"), index[-1] + pd.Timedelta("2h"),
                         freq="1min", tz="UTC")  # fmt: skip
    return pvlib.location.Location(lat, lon).get_clearsky(fine, model="ineichen")["ghi"]


def sky_as_read(cs: pd.Series, index, convention, shift_min: int = 0) -> np.ndarray:
    """The cloudless sky at ``index`` read under a convention (:data:`CONVENTIONS`),
    the stamps moved by ``shift_min`` [min]."""
    if convention is None:
        return cs.reindex(index + pd.Timedelta(minutes=shift_min)).to_numpy()
    start, end = convention
    mean = cs.rolling(end - start).mean()  # the mean of the minutes ending at each one
    return mean.reindex(index + pd.Timedelta(minutes=end + shift_min)).to_numpy()


def best_shift(measured, sky_at, shifts=range(-90, 91, 5)) -> tuple[int, float, float]:
    """The stamp shift [min] whose scaled cloudless sky fits ``measured`` best: (shift,
    RMS [W/m²], scale); ``sky_at(shift)`` gives the sky for a shift."""
    best = None
    for s in shifts:
        y = sky_at(s)
        scale = float(measured @ y / (y @ y))
        rms = float(np.sqrt(np.mean((measured - scale * y) ** 2)))
        if best is None or rms < best[1]:
            best = (s, rms, scale)
    return best


def clear_days(g: pd.Series, sky: np.ndarray, longitude: float) -> np.ndarray:
    """A mask of the hours of clear days: the day's sum at least 0.85 of the cloudless
    sky's, the hourly ratio steady (sd below 0.12 over 6 or more sunlit hours)."""
    day = (g.index + pd.Timedelta(hours=longitude / 15.0)).floor("D")
    df = pd.DataFrame({"g": g.to_numpy(), "c": sky}, index=g.index)
    sums = df.groupby(day).sum()
    ratio = (df.g / df.c.where(df.c > 50)).groupby(day).agg(["std", "count"])
    ok = (sums.g / sums.c > 0.85) & (sums.c > 1000) & (ratio["std"] < 0.12) & (ratio["count"] >= 6)
    return np.isin(day, sums.index[ok])


def clock_check(room: str, data: Path) -> None:
    """Print the clear-day fit of each convention and the best shift (``--clock``)."""
    _, wfile, site, *_ = ROOMS[room]
    w = pd.read_csv(data / wfile, parse_dates=[0], index_col=0)
    g = w["Rglob"].astype(float)
    g.index = g.index.tz_localize("UTC+02:00").tz_convert("UTC")
    cs = clear_sky_minutes(g.index, site)
    mask = clear_days(g, sky_as_read(cs, g.index, None), site[1])
    meas = g.to_numpy()[mask]
    n = len(np.unique((g.index[mask] + pd.Timedelta(hours=site[1] / 15)).floor("D")))
    print(f"{room}: {n} clear days")
    for name, conv in CONVENTIONS.items():
        s, rms, scale = best_shift(meas, lambda k, c=conv: sky_as_read(cs, g.index, c, k)[mask])
        rms0 = best_shift(meas, lambda k, c=conv: sky_as_read(cs, g.index, c, k)[mask], [0])[1]
        print(f"| {room} | {name} | {rms0:.1f} | {s:+d} | {rms:.1f} | {scale:.2f} |")
    day = (g.index + pd.Timedelta(hours=site[1] / 15)).floor("D")
    shifts = []
    for d in np.unique(day[mask]):
        m = np.asarray(day == d)
        sky_on_day = functools.partial(_sky_on, cs, g.index, m)
        shifts.append(best_shift(g.to_numpy()[m], sky_on_day)[0])
    q = np.percentile(shifts, [25, 50, 75])
    at = sky_as_read(cs, g.index, None)
    solar = (g.index.hour + g.index.minute / 60 + site[1] / 15) % 24  # solar time [h], roughly
    am, pm = mask & (solar < 12), mask & (solar > 12)
    meas_am, meas_pm = g.to_numpy()[am].sum() / at[am].sum(), g.to_numpy()[pm].sum() / at[pm].sum()
    print(
        f"{room}: per-day best shift (value at the stamp) median {q[1]:+.0f} min, IQR "
        f"{q[0]:+.0f} to {q[2]:+.0f}; measured / cloudless before solar noon {meas_am:.3f}, "
        f"after {meas_pm:.3f}"
    )


def _sky_on(cs, index, mask, shift_min):
    return sky_as_read(cs, index, None, shift_min)[mask]


def _map_frame(
    room: str,
    data: Path,
    work: Path,
    variant: str = "wind",
    model: str = "thermal_1c",
    bare: bool = False,
) -> tuple:
    """The MAP simulation of ``model`` (an ``attic_physics.py`` candidate; thermal_1c by
    default) beside the measured attic, the roof's irradiance and the boundary
    temperatures, calibration and validation (``val``), on the file clock (UTC+2); and
    the MAP's parameters. ``bare``: the weather without its radiation (estimated sun)."""
    import attic_physics as ap
    from _common import config_map

    w = work / room / model / ("bare" if bare else "meas")
    (w / "wx").mkdir(parents=True, exist_ok=True)
    ap._register()
    cfg = ap._config(room, variant, model, bare, data, w)
    undo = ap.patched(ap._roof_answers(variant)[1], ap._fmi(room, data))
    try:
        prep, m, lp, mp = config_map(cfg, "thermal")
    finally:
        undo()
    y = lp.simulate_frame(mp.theta[None], prep.model_inputs("thermal", m),
                          prep.calibration.start)[0][0][:, 0]  # fmt: skip
    sl = slice(prep.calibration.start, prep.validation.stop)
    fr = prep.frame
    roof = [c for c in fr.columns if c.startswith("I_") and not c.endswith("_slope")]
    f = pd.DataFrame(
        {"obs": prep.observed("thermal", m)[sl, 0], "sim": y[sl],
         "I": fr[roof].sum(axis=1).to_numpy()[sl], "Te": fr["Te"].to_numpy()[sl],
         "Tf": fr["Tf"].to_numpy()[sl]},
        index=fr.index[sl].tz_convert("UTC+02:00").tz_localize(None),
    )  # fmt: skip
    f["val"] = np.arange(sl.start, sl.stop) >= prep.validation.start
    return f, dict(zip(lp.params.names, mp.theta, strict=True))


def through(x, tau_h: float) -> np.ndarray:
    """``x`` through a first-order lag of time constant ``tau_h`` [h] (hourly steps)."""
    a, out, acc = np.exp(-1.0 / tau_h), np.empty(len(x)), float(x[0])
    for k, v in enumerate(np.asarray(x, dtype=float)):
        acc = a * acc + (1.0 - a) * v
        out[k] = acc
    return out


def fit_percent(obs, sim) -> float:
    """FIT [%] = 100 (1 - |obs - sim| / |obs - mean(obs)|)."""
    return 100.0 * (1.0 - np.linalg.norm(obs - sim) / np.linalg.norm(obs - obs.mean()))


def slope_table(room: str, data: Path, f: pd.DataFrame, theta: dict) -> pd.DataFrame:
    """The calibration residual fitted (least squares, with a constant) on one more
    input through the MAP's time constant: each 45° slope's irradiance (wind-weighted,
    20° skyline), the horizontal's, and the roof's squared; the June-August noon
    residual left [K] (``--slopes``)."""
    from heritage_bayes.climate.solair import roof_wind_weight
    from heritage_bayes.climate.solar_surfaces import surface_irradiance

    _, wfile, (lat, lon), *_ = ROOMS[room]
    w = pd.read_csv(data / wfile, parse_dates=[0], index_col=0)
    w.index = w.index.tz_localize("UTC+02:00")
    wx = w.rename(columns={"Rglob": "ghi", "Rdif": "dhi"})[["ghi", "dhi"]]
    site = {"latitude": lat, "longitude": lon, "altitude": 0}
    planes = {k: (45, az) for k, az in zip("NESW", (0, 90, 180, 270), strict=True)}
    irr = surface_irradiance(wx, site, planes, averaged=False, horizon=20)
    irr = irr.mul(roof_wind_weight(w["ws"].interpolate(limit_direction="both").to_numpy()), axis=0)
    irr["H"] = surface_irradiance(wx, site, {"H": (0, 0)}, averaged=False)["H"]
    irr.index = irr.index.tz_localize(None)
    x = irr.reindex(f.index).interpolate(limit_direction="both").fillna(0.0)
    x["roof squared"] = f["I"] ** 2 / 1000.0
    tau = theta["Ci"] / theta["Ge"] / 3600.0
    e, cal = (f.obs - f.sim).to_numpy(), ~f.val.to_numpy()
    noon = np.asarray(f.index.month.isin([6, 7, 8]) & (f.index.hour >= 11) & (f.index.hour <= 15))
    rows = {"(none)": e[noon].mean()}
    for name in x.columns:
        z = np.column_stack([np.ones(len(e)), through(x[name].to_numpy(), tau)])
        b = np.linalg.lstsq(z[cal], e[cal], rcond=None)[0]
        rows[name] = (e - z @ b)[noon].mean()
    return pd.Series(rows, name="JJA noon residual left [K]").round(2).to_frame().T


def validation_table(f: pd.DataFrame, theta: dict) -> None:
    """The validation residual: by month and hour, its worst days, and the FIT a
    least-squares correction by one more input (through the MAP's time constant,
    fitted on the validation itself) would reach (``--validation``)."""
    v = f[f.val]
    e = v.obs - v.sim
    print(e.groupby([e.index.month, e.index.hour]).mean().unstack(0).iloc[4:21:2].round(1).T)
    day = pd.DataFrame({"residual": e, "Te": v.Te}).resample("D").mean().dropna()
    print(day.reindex(day.residual.abs().nlargest(5).index).round(1).T)
    tau = theta["Ci"] / theta["Ge"] / 3600.0
    inputs = {"heat from 20 °C": 20.0 - f.Te, "roof sun": f.I, "Te": f.Te}
    ceil = {"(none)": fit_percent(v.obs.to_numpy(), v.sim.to_numpy())}
    for name, x in {**{k: through(x.to_numpy(), tau) for k, x in inputs.items()},
                    "Tf": f.Tf.to_numpy()}.items():  # fmt: skip
        z = np.column_stack([np.ones(len(v)), x[f.val.to_numpy()]])
        b = np.linalg.lstsq(z, e.to_numpy(), rcond=None)[0]
        ceil[name] = fit_percent(v.obs.to_numpy(), v.sim.to_numpy() + z @ b)
    rms = {k: float(np.sqrt(np.mean((g.obs - g.sim) ** 2))) for k, g in f.groupby("val")}
    print(f"RMS residual calibration {rms[False]:.2f} K, validation {rms[True]:.2f} K; "
          "validation FIT with one input more: "
          + ", ".join(f"{k} {c:.1f}" for k, c in ceil.items()))  # fmt: skip


def daily_phase(values: pd.Series) -> pd.Series:
    """The phase [h of the day] of each day's first harmonic of ``values`` (hourly)."""
    theta = 2 * np.pi * values.index.hour.to_numpy() / 24.0
    anom = values - values.groupby(values.index.floor("D")).transform("mean")
    parts = (
        pd.DataFrame(
            {"c": anom.to_numpy() * np.cos(theta), "s": anom.to_numpy() * np.sin(theta)},
            index=values.index,
        )
        .groupby(values.index.floor("D"))
        .sum()
    )
    return np.arctan2(parts.s, parts.c) * 24.0 / (2 * np.pi)


def season_table(f: pd.DataFrame) -> pd.DataFrame:
    """By month: the gain of the measured within-day anomaly on the simulated one and
    the median daily phase difference measured - simulated [h] (``--seasons``)."""
    day = f.index.floor("D")
    anom = f[["obs", "sim"]] - f[["obs", "sim"]].groupby(day).transform("mean")
    gain = anom.groupby(anom.index.month).apply(lambda a: (a.obs @ a.sim) / (a.sim @ a.sim))
    dp = (daily_phase(f.obs) - daily_phase(f.sim) + 12.0) % 24.0 - 12.0
    phase = dp.groupby(dp.index.month).median()
    return pd.DataFrame({"gain": gain, "phase_h": phase}).round(2)


def sun_table(f: pd.DataFrame) -> pd.DataFrame:
    """May-August days in quartiles of the roof's daily mean irradiance: the noon
    residual and the daily range measured and simulated [K] (``--sun``)."""
    s = f[f.index.month.isin([5, 6, 7, 8])]
    day = s.resample("D")
    noon = s[(s.index.hour >= 11) & (s.index.hour <= 15)]
    t = pd.DataFrame({
        "I": day.I.mean(),
        "noon_residual": (noon.obs - noon.sim).resample("D").mean(),
        "range_measured": day.obs.max() - day.obs.min(),
        "range_simulated": day.sim.max() - day.sim.min(),
    }).dropna()  # fmt: skip
    t["quartile"] = pd.qcut(t.I, 4, labels=["dullest", "2nd", "3rd", "sunniest"])
    return t.groupby("quartile", observed=True).mean().round(2)


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("rooms", nargs="*", default=TUNING)
    ap.add_argument("--data", type=Path, default=ROOT.parent / "shared" / "data")
    ap.add_argument("--clock", action="store_true", help="the radiation's time stamp")
    ap.add_argument("--seasons", action="store_true", help="daily swing and phase by month")
    ap.add_argument("--sun", action="store_true", help="summer noon residual by sunniness")
    ap.add_argument("--variant", default="wind", help="an attic_physics.py variant")
    ap.add_argument("--slopes", action="store_true", help="the residual on each slope's sun")
    ap.add_argument("--validation", action="store_true", help="the validation residual")
    ap.add_argument("--model", default="thermal_1c", help="an attic_physics.py candidate "
                    "(--seasons, --sun only)")  # fmt: skip
    ap.add_argument("--estimated", action="store_true", help="the weather without radiation")
    args = ap.parse_args(argv)
    if args.model != "thermal_1c" and (args.slopes or args.validation):
        ap.error("--slopes and --validation read thermal_1c's parameters")
    if set(args.rooms) - set(TUNING):
        ap.error(f"tuning attics only: {TUNING} (the others are held out)")
    if args.clock:
        print("| room | read as | RMS [W/m²] | best shift [min] | its RMS | scale |")
        for room in args.rooms:
            clock_check(room, args.data)
    if args.seasons or args.sun or args.slopes or args.validation:
        work = Path(tempfile.mkdtemp(prefix="attic_diagnostics_"))
        for room in args.rooms:
            f, theta = _map_frame(room, args.data, work, args.variant, args.model,
                                  args.estimated)  # fmt: skip
            print(f"{room}: MAP " + " ".join(f"{k}={x:.3g}" for k, x in theta.items()))
            if args.seasons:
                print(f"{room}: by month\n{season_table(f).T.to_string()}")
            if args.sun:
                print(f"{room}: May-August by sunniness\n{sun_table(f).to_string()}")
            if args.slopes:
                print(f"{room}: {slope_table(room, args.data, f, theta).to_string()}")
            if args.validation:
                print(f"{room}: the validation residual")
                validation_table(f, theta)
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
