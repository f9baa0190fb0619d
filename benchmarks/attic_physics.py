"""Which roof physics an unheated attic needs: candidate inputs on the tuning attics.

Each TRH-1 attic through ``hbayes init`` (as ``real_rooms.py`` does), then the MAP of
``thermal_1c`` (the model the screen keeps on these attics) and its validation FIT of
Ti [%], with the FMI weather as published and without its radiation columns, for each
variant of the roof planes' irradiance input:

- ``none``: the irradiance as transposed, without the wind weight (init's config with
  ``weather.columns.wind`` removed);
- ``wind``: the package's default for a weather with wind: each slope's irradiance
  times :func:`heritage_bayes.climate.solair.roof_wind_weight`; ``wind_u0``,
  ``wind_u12``: the same with the cover's inner conductance 0 and 12 W/(m² K);
- ``sky``, ``snow``: on top of the wind weight (does either add to it?);
- ``sky``: long-wave loss to the sky subtracted from each slope's irradiance,
  :math:`I - F_{sky} \\Delta R`, :math:`\\Delta R = \\sigma (1 - \\varepsilon_{sky})
  T_e^4` with the clear sky's emissivity from the dew point (Berdahl and Martin 1984),
  raised by the cloud fraction 1 - the day's clearness (Crawford and Duchon 1999);
  ε/α = 1 (the long-wave loss through the solar aperture);
- ``snow``: each slope's irradiance times 1 - 2/3 c, c the snow cover from a
  degree-day snowpack on FMI's precipitation (snow below +1 °C, melt 3 mm/(K d), a
  roof covered from 5 mm water equivalent; snow absorbs a third of what the roof does).

The three candidates are not in the package (only the wind weight paid, see
``docs/science/real_rooms.md``, "The wind on the roof"); they are written here as
changes of the irradiance table before alignment. ``--hours``: the MAP's residual
(measured - simulated Ti) by season and hour of day, calibration and validation, and
the correlation of its daily mean with FMI's daily mean wind speed.

Usage (from the repository root)::

    python benchmarks/attic_physics.py [ROOM ...] [--variants none wind sky snow] [--hours]

ROOM: R2 R4 R6 (the tuning attics, the default); the held-out ones are refused.
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

from _common import config_map  # noqa: E402
from real_rooms import ROOMS, run_init  # noqa: E402

TUNING = ["R2", "R4", "R6"]
SIGMA = 5.670374419e-8  # Stefan-Boltzmann [W/(m² K⁴)]


def _fmi(room: str, data: Path) -> pd.DataFrame:
    raw = pd.read_csv(data / ROOMS[room][1], parse_dates=[0], index_col=0)
    raw.index = raw.index.tz_localize("UTC+02:00").tz_convert("UTC")
    return raw


def _sky_loss(irr, weather, site, surfaces, table):
    """Each slope's irradiance less its long-wave loss to the sky [W/m²]."""
    from heritage_bayes.climate.psychro import dew_point
    from heritage_bayes.climate.solar import clear_sky_weather

    idx = irr.index
    te = weather["Te"].reindex(idx).interpolate(limit_direction="both").to_numpy(float)
    rhe = weather["RHe"].reindex(idx).interpolate(limit_direction="both").to_numpy(float)
    tdp = dew_point(te, rhe) / 100.0
    eps_clear = 0.711 + 0.56 * tdp + 0.73 * tdp**2
    cs = clear_sky_weather(idx, site, interval=irr.attrs.get("interval"))["ghi"].to_numpy()
    day = (idx + pd.Timedelta(hours=site["longitude"] / 15.0)).floor("D")
    g = pd.DataFrame({"g": table["ghi"].reindex(idx).to_numpy(float), "c": cs}, index=day)
    sums = g.groupby(level=0).sum()
    ok = sums["c"] > 150.0  # W/m² summed over the day's hours: enough sun to judge
    clear = (sums["g"] / sums["c"]).clip(0, 1).where(ok).interpolate(limit_direction="both")
    cloud = 1.0 - clear.reindex(day).to_numpy()
    eps = cloud + (1.0 - cloud) * eps_clear
    loss = SIGMA * (1.0 - eps) * (te + 273.15) ** 4
    out = irr.copy()
    for name, (tilt, _) in surfaces.items():
        out[name] = irr[name] - (1 + np.cos(np.radians(tilt))) / 2 * loss
    return out


def _snow_factor(raw: pd.DataFrame, index) -> np.ndarray:
    """1 - 2/3 of the roof's snow cover [-] from a degree-day snowpack."""
    te, p = raw["Te"].to_numpy(float), np.nan_to_num(raw["precip"].to_numpy(float))
    swe, cover = 0.0, np.empty(len(te))
    for k in range(len(te)):
        t = te[k] if np.isfinite(te[k]) else 0.0
        swe = max(0.0, swe + (p[k] if t < 1.0 else 0.0) - 3.0 / 24.0 * max(t, 0.0))
        cover[k] = min(1.0, swe / 5.0)
    c = pd.Series(cover, index=raw.index).reindex(index).ffill().fillna(0.0).to_numpy()
    return 1.0 - 2.0 / 3.0 * c


def patched(variant: str, raw: pd.DataFrame):
    """The package's ``solar_inputs`` with the variant's change of the irradiance."""
    import heritage_bayes.inputs as inputs
    from heritage_bayes.climate import solair

    orig = inputs.solar_inputs

    def solar_inputs(weather, site, surfaces, mode, *, where="data.weather", roof=()):
        if variant.startswith("wind_u"):
            u = float(variant[6:])
            w = solair.roof_wind_weight(
                weather["wind"].interpolate(limit_direction="both").to_numpy(), u
            )
            out, label, detail = orig(weather.drop(columns="wind"), site, surfaces, mode,
                                      where=where)  # fmt: skip
            for k in roof:
                out[f"I_{k}"] = out[f"I_{k}"].to_numpy() * w
            return out, label, detail
        out, label, detail = orig(weather, site, surfaces, mode, where=where, roof=roof)
        if variant == "sky":
            table = weather if "ghi" in weather else _estimated(weather, site)
            cols = {f"I_{k}": v for k, v in surfaces.items()}
            out = _sky_loss(out, weather, dict(site), cols, table)
        elif variant == "snow":
            out = out.mul(_snow_factor(raw, out.index), axis=0)
        return out, label, detail

    inputs.solar_inputs = solar_inputs
    return functools.partial(setattr, inputs, "solar_inputs", orig)


def _estimated(weather, site):
    from heritage_bayes.climate.solar import temperature_range_weather

    return temperature_range_weather(weather["Te"], dict(site))


def run(room, variant, bare, data, work, hours):
    from heritage_bayes.config import load_config
    from heritage_bayes.inference.results import fit_metrics

    w = work / room / ("bare" if bare else "meas")
    (w / "wx").mkdir(parents=True, exist_ok=True)
    weather = None
    if bare:
        weather = w / "wx" / "fmi.csv"
        bare_fmi = pd.read_csv(data / ROOMS[room][1]).drop(columns=["Rglob", "Rdif"])
        bare_fmi.to_csv(weather, index=False)
    cfg = load_config(run_init(room, data, w, weather)[0])
    if variant == "none":
        cols = {k: v for k, v in cfg.data.weather.columns.items() if k != "wind"}
        src = cfg.data.weather.model_copy(update={"columns": cols})
        cfg = cfg.model_copy(update={"data": cfg.data.model_copy(update={"weather": src})})
    opt = cfg.optimizer.model_copy(update={"maxiter": 100, "starts": 2})
    th = cfg.thermal.model_copy(update={"model": "thermal_1c"})
    cfg = cfg.model_copy(update={"optimizer": opt, "thermal": th, "hygric": None})
    undo = patched(variant, _fmi(room, data))
    try:
        prep, m, lp, mp = config_map(cfg, "thermal")
    finally:
        undo()
    u = prep.model_inputs("thermal", m)
    y = lp.simulate_frame(mp.theta[None], u, prep.calibration.start)[0][0][:, 0]
    obs = prep.observed("thermal", m)[:, 0]
    v = prep.validation
    fit = fit_metrics(obs[v], y[v])["FIT"]
    if hours:
        sl = slice(prep.calibration.start, v.stop)
        e = pd.Series(obs[sl] - y[sl], index=prep.frame.index[sl] + pd.Timedelta(hours=2))
        season = np.array(["DJF", "DJF", "MAM", "MAM", "MAM", "JJA", "JJA", "JJA", "SON",
                           "SON", "SON", "DJF"])[e.index.month - 1]  # fmt: skip
        print(e.groupby([season, e.index.hour]).mean().unstack(0).iloc[::6].round(2))
        ws = _fmi(room, data)["ws"].reindex(e.index - pd.Timedelta(hours=2))
        daily = pd.DataFrame({"e": e.to_numpy(), "ws": ws.to_numpy()}).groupby(
            np.asarray(e.index.floor("D"))
        )
        r = daily.mean().corr().loc["e", "ws"]
        print(f"correlation of the daily mean residual with the daily mean wind: {r:.2f}")
    return fit


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("rooms", nargs="*", default=TUNING)
    ap.add_argument("--variants", nargs="+", default=["none", "wind", "sky", "snow"])
    ap.add_argument("--data", type=Path, default=ROOT.parent / "shared" / "data")
    ap.add_argument("--hours", action="store_true", help="residual by season and hour")
    args = ap.parse_args(argv)
    if set(args.rooms) - set(TUNING):
        ap.error(f"tuning attics only: {TUNING} (the others are held out)")
    work = Path(tempfile.mkdtemp(prefix="attic_physics_"))
    print("validation FIT of Ti [%], thermal_1c MAP (100 generations, 2 starts)")
    print("| room | variant | measured radiation | estimated |")
    for room in args.rooms:
        for variant in args.variants:
            fits = [run(room, variant, bare, args.data, work, args.hours) for bare in (0, 1)]
            print(f"| {room} | {variant} | {fits[0]:.1f} | {fits[1]:.1f} |", flush=True)
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
