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

Usage (from the repository root)::

    python benchmarks/attic_diagnostics.py [ROOM ...] [--clock] [--seasons] [--sun]
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


def _map_frame(room: str, data: Path, work: Path) -> pd.DataFrame:
    """thermal_1c's MAP simulation beside the measured attic and the roof's irradiance,
    calibration and validation, on the file clock (UTC+2)."""
    import attic_physics as ap
    from _common import config_map

    w = work / room
    (w / "wx").mkdir(parents=True, exist_ok=True)
    cfg = ap._config(room, "wind", "thermal_1c", False, data, w)
    prep, m, lp, mp = config_map(cfg, "thermal")
    y = lp.simulate_frame(mp.theta[None], prep.model_inputs("thermal", m),
                          prep.calibration.start)[0][0][:, 0]  # fmt: skip
    sl = slice(prep.calibration.start, prep.validation.stop)
    roof = [c for c in prep.frame.columns if c.startswith("I_") and not c.endswith("_slope")]
    return pd.DataFrame(
        {"obs": prep.observed("thermal", m)[sl, 0], "sim": y[sl],
         "I": prep.frame[roof].sum(axis=1).to_numpy()[sl]},
        index=prep.frame.index[sl].tz_convert("UTC+02:00").tz_localize(None),
    )  # fmt: skip


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
    args = ap.parse_args(argv)
    if set(args.rooms) - set(TUNING):
        ap.error(f"tuning attics only: {TUNING} (the others are held out)")
    if args.clock:
        print("| room | read as | RMS [W/m²] | best shift [min] | its RMS | scale |")
        for room in args.rooms:
            clock_check(room, args.data)
    if args.seasons or args.sun:
        work = Path(tempfile.mkdtemp(prefix="attic_diagnostics_"))
        for room in args.rooms:
            f = _map_frame(room, args.data, work)
            if args.seasons:
                print(f"{room}: by month\n{season_table(f).T.to_string()}")
            if args.sun:
                print(f"{room}: May-August by sunniness\n{sun_table(f).to_string()}")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
