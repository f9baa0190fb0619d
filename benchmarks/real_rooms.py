"""Real rooms from their raw files: `hbayes init` with only its questions answered, then
the MAP (and optionally a short `hbayes calibrate`), validation FIT per room.

For each room the script runs :func:`heritage_bayes.init_config.init_config` on the raw
logger and weather files as published (``../shared/data``); when init leaves questions
open, the answers recorded in :data:`ROOMS` (what a user who read the question would
give, e.g. the logger's clock) are passed as init's options and init runs again, as its
own advice says ("after answering, `hbayes init` again"). Nothing else is edited. Then,
per section, the MAP with the config's optimiser at a modest budget (``--maxiter``,
``--starts``) and its validation FIT [%] of Ti (thermal) and Pi (hygric); RH [%] from
the two (the hygric model's Pi over psat of the thermal model's Ti). With
``--calibrate`` also the whole `hbayes calibrate` (MAP, emcee capped at
``--max-steps``, no ladder, no report) and its posterior-predictive validation FIT.

The TRH-1 attics run twice: with the FMI file as published (measured ``Rglob``,
``Rdif``) and with those columns removed (a copy in the work folder: init then writes
``irradiance: estimated``). Annisse also runs the hand-written ``configs/annisse.yaml``
with the same budget, for the comparison its done-when asks.

Held out (never run while init's proposals were tuned; run once with the final code):
R3, R5, R7 and Annisse. Tuned on: R2, R4, R6 and Ørholm.

Usage (from the repository root)::

    python benchmarks/real_rooms.py [ROOM ...] [--out DIR] [--maxiter 100] [--starts 2]
        [--calibrate --max-steps 1500] [--whole-record] [--json FILE]

ROOM: R2 R3 R4 R5 R6 R7 orholm annisse (default: the tuning rooms; ``--held-out`` adds
the held-out ones). ``--span START END`` cuts a TRH-1 room's logger and weather files to
the rows stamped in ``[START, END)`` (the files' own clock; copies in the work folder,
same layout): a user who holds a shorter record. ``--whole-record`` also runs each
config with ``periods.calibration`` widened to the whole usable stretch init names (the
validation unchanged, inside it). Beside the validation FIT, the calibration FIT over
the fitted rows (each config's own calibration, without a validation inside it).
"""

from __future__ import annotations

import argparse
import json
import os
import resource
import sys
import tempfile
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT / "benchmarks"))
os.environ.setdefault("OPENBLAS_NUM_THREADS", "1")

import numpy as np  # noqa: E402
import pandas as pd  # noqa: E402

from _common import config_map  # noqa: E402

DMI = "orholm/DMI_outdoor-climate-data_2009-2021.csv"

#: room -> logger, weather (under the data root), site [° N, ° E], held out, and the
#: answers to init's questions in turn (init_config keyword arguments; each used only
#: while init still asks). The TRH-1 houses'
#: positions are not published: the towns'.
ROOMS = {
    "R2": ("trh1-espoo-attic/roofmiddle_airmiddle.csv", "trh1-espoo-attic/fmi.csv",
           (60.21, 24.66), False, []),
    "R3": ("trh1-more-attics/R3/roofmiddle_airmiddle.csv", "trh1-more-attics/R3/fmi.csv",
           (60.21, 24.66), True, []),
    "R4": ("trh1-more-attics/R4/roofmiddle_airmiddle.csv", "trh1-more-attics/R4/fmi.csv",
           (61.50, 23.76), False, []),
    "R5": ("trh1-more-attics/R5/roofmiddle_airmiddle.csv", "trh1-more-attics/R5/fmi.csv",
           (61.50, 23.76), True, []),
    "R6": ("trh1-more-attics/R6/roofmiddle_airmiddle.csv", "trh1-more-attics/R6/fmi.csv",
           (61.26, 24.03), False, []),
    "R7": ("trh1-more-attics/R7/roofmiddle_airmiddle.csv", "trh1-more-attics/R7/fmi.csv",
           (60.29, 25.04), True, []),
    # the clock question, when init asks it: init names the stamps' fixed clock and the
    # zone's standard time UTC+1 (the data set's description says nothing of the clock)
    "orholm": ("orholm/oerholm-indoor-climate-data_2009-2021.csv", DMI, (55.79, 12.50), False,
               [{"timezone": "UTC+1"}]),
    "annisse": ("orholm/annisse-indoor-climate-data_2014-2018.csv", DMI, (56.03, 12.17), True,
                [{"timezone": "UTC+1"}]),
}  # fmt: skip
TUNING = ["R2", "R4", "R6", "orholm"]
HELD_OUT = ["R3", "R5", "R7", "annisse"]


def _cpu() -> float:
    own = resource.getrusage(resource.RUSAGE_SELF)
    kids = resource.getrusage(resource.RUSAGE_CHILDREN)
    return own.ru_utime + own.ru_stime + kids.ru_utime + kids.ru_stime


def run_init(
    room: str, data: Path, work: Path, weather: Path | None = None, logger: Path | None = None
) -> tuple:
    """init on a room's raw files (``logger``, ``weather``: other copies of them); while
    it asks, init again with the next recorded answer. Returns (config path, questions
    left, answers given)."""
    from heritage_bayes.init_config import init_config

    lfile, wfile, (lat, lon), _, answers = ROOMS[room]
    logger, weather = logger or data / lfile, weather or data / wfile
    out = work / "config.yaml"
    kw = {"latitude": lat, "longitude": lon, "output": out, "force": True}
    res = init_config(logger, weather, **kw)
    given: dict = {}
    for answer in answers:
        if not res.questions:
            break
        given = answer
        res = init_config(logger, weather, **kw, **given)
    return out, res.questions, given


def cut_files(room: str, data: Path, work: Path, span: list[str]) -> tuple[Path, Path]:
    """Copies of a TRH-1 room's logger and weather files in ``work`` with the rows
    stamped in ``[span[0], span[1])`` only (the files' own clock, same layout)."""
    out = []
    for rel in ROOMS[room][:2]:
        if not rel.startswith("trh1"):
            raise SystemExit(f"--span: only the TRH-1 rooms' files can be cut ({room}: {rel})")
        t = pd.read_csv(data / rel)
        stamp = pd.to_datetime(t.iloc[:, 0])
        keep = (stamp >= pd.Timestamp(span[0])) & (stamp < pd.Timestamp(span[1]))
        if not keep.any():
            raise SystemExit(f"--span: no row of {rel} in {span[0]} to {span[1]}")
        path = work / room / "cut" / Path(rel).name
        path.parent.mkdir(parents=True, exist_ok=True)
        t[keep].to_csv(path, index=False)
        out.append(path)
    return out[0], out[1]


def room_below(config: Path, logger: Path) -> Path:
    """init's config with its written advice for a room without a floor on the ground
    followed: the neighbouring space's measured temperature as ``Tf`` (the TRH-1 attics:
    ``indoor1.csv``, the heated room below, beside the attic's logger file)."""
    import yaml

    raw = yaml.safe_load(config.read_text(encoding="utf-8"))
    house = logger.parent / "indoor1.csv"
    rel = Path(os.path.relpath(house.resolve(), config.parent.resolve())).as_posix()
    raw["data"]["ground_temperature"] = {
        "mode": "column",
        "column": "T",
        "source": {"format": "csv", "path": rel, "time_column": "t_UTC+2", "timezone": "UTC+2"},
    }
    out = config.with_name("config_room_below.yaml")
    out.write_text(yaml.safe_dump(raw, sort_keys=False, allow_unicode=True), encoding="utf-8")
    return out


def whole_record(config: Path) -> Path:
    """init's config with ``periods.calibration`` widened to the whole usable stretch
    init names in its comment (``overlap: ... START to END UTC``), the validation
    unchanged (now inside the calibration, held out of the fit)."""
    import re

    import yaml

    text = config.read_text(encoding="utf-8")
    notes = " ".join(ln.lstrip("#").strip() for ln in text.splitlines() if ln.startswith("#"))
    day = r"(\d{4}-\d\d-\d\d)\s+\d\d:\d\d"
    m = re.search(rf"- overlap: .*?{day}\s+to\s+{day}\s+UTC", notes)
    if m is None:
        raise SystemExit(f"--whole-record: no overlap found in the comment of {config}")
    raw = yaml.safe_load(text)
    raw["periods"]["calibration"] = {"start": m[1], "end": m[2]}
    out = config.with_name("config_whole_record.yaml")
    out.write_text(yaml.safe_dump(raw, sort_keys=False, allow_unicode=True), encoding="utf-8")
    return out


def screen_auto(cfg) -> tuple:
    """Each ``model: auto`` section replaced by the model its ladder screen chooses, as
    ``hbayes calibrate`` does (its own screen, same seeds, no time budget); returns the
    config and the screen's rows in words (``<section>_screen``)."""
    from types import SimpleNamespace

    from threadpoolctl import threadpool_limits

    from heritage_bayes.calibration.calibrate import _select_models
    from heritage_bayes.models import AUTO, SECTIONS, models_of
    from heritage_bayes.prepare import prepare

    if not any(getattr(getattr(cfg, n, None), "model", None) == AUTO for n in SECTIONS):
        return cfg, {}
    with threadpool_limits(limits=1, user_api="blas"):
        models, rungs = models_of(cfg)
        say = SimpleNamespace(say=lambda m: None)
        cfg, screens = _select_models(cfg, prepare(cfg, models), say, None, rungs)
    out = {
        f"{name}_screen": "; ".join(
            f"{r['model']} {r.get('score', float('nan')):.1f}" for r in scr.rows if "error" not in r
        )
        for name, scr in screens.items()
    }
    return cfg, out


def map_fits(cfg, maxiter: int, starts: int) -> dict:
    """Validation FIT [%] of the MAP simulations: Ti, Pi and RH (Pi over psat(Ti)), and
    the models."""
    from heritage_bayes.climate.psychro import saturation_vapour_pressure
    from heritage_bayes.inference.results import fit_metrics

    opt = cfg.optimizer.model_copy(update={"maxiter": maxiter, "starts": starts})
    cfg = cfg.model_copy(update={"optimizer": opt})
    cfg, out = screen_auto(cfg)
    sims = {}
    for sec, name in (("thermal", "Ti"), ("hygric", "Pi")):
        if getattr(cfg, sec, None) is None:
            continue
        prep, model, lp, mp = config_map(cfg, sec)
        u = prep.model_inputs(sec, model)
        y = lp.simulate_frame(mp.theta[None], u, prep.calibration.start)[0][0][:, 0]
        v = prep.validation
        obs = prep.observed(sec, model)[:, 0]
        out[name] = fit_metrics(obs[v.start : v.stop], y[v.start : v.stop])["FIT"]
        fitted = prep.fitted_rows() & np.isfinite(obs)
        out[f"fit_{name}"] = fit_metrics(obs[fitted], y[fitted])["FIT"]
        sims[name] = (y[v.start : v.stop], obs[v.start : v.stop])
        out[f"{sec}_model"] = model.name if hasattr(model, "name") else getattr(cfg, sec).model
    if len(sims) == 2:
        (ti, ti_obs), (pi, pi_obs) = sims["Ti"], sims["Pi"]
        rh = 100 * pi / saturation_vapour_pressure(ti)
        rh_obs = 100 * pi_obs / saturation_vapour_pressure(ti_obs)
        ok = np.isfinite(rh_obs)
        out["RH"] = fit_metrics(rh_obs[ok], rh[ok])["FIT"] if ok.any() else float("nan")
    return out


def monthly_residuals(cfg, maxiter: int, starts: int) -> pd.DataFrame:
    """The thermal MAP's validation residual (measured - simulated Ti) by month: bias
    and RMSE [K], and the mean daily range [K] measured and simulated."""
    opt = cfg.optimizer.model_copy(update={"maxiter": maxiter, "starts": starts})
    prep, model, lp, mp = config_map(cfg.model_copy(update={"optimizer": opt}), "thermal")
    y = lp.simulate_frame(mp.theta[None], prep.model_inputs("thermal", model),
                          prep.calibration.start)[0][0][:, 0]  # fmt: skip
    v = prep.validation
    r = pd.DataFrame(
        {"obs": prep.observed("thermal", model)[v.start : v.stop, 0], "sim": y[v.start : v.stop]},
        index=prep.period_index("validation"),
    )
    e = r.obs - r.sim
    day = r.resample("1D")
    rng = (day.max() - day.min()).resample("MS").mean()
    return pd.DataFrame(
        {
            "bias_K": e.resample("MS").mean(),
            "rmse_K": np.sqrt((e**2).resample("MS").mean()),
            "range_measured_K": rng.obs,
            "range_simulated_K": rng.sim,
        }
    ).round(2)


def calibrate_fits(cfg, work: Path, max_steps: int) -> dict:
    """`hbayes calibrate` (no ladder, no report) with emcee capped at ``max_steps``:
    posterior-predictive validation FIT [%] and convergence."""
    from heritage_bayes.calibration.calibrate import run_calibration

    sampler = cfg.sampler.model_copy(update={"max_steps": max_steps})
    cfg = cfg.model_copy(update={"sampler": sampler, "ladder": False})
    try:
        run_calibration(cfg, work / "run", quiet=True, force=True, report=False)
    except TypeError:  # no report switch in this version
        run_calibration(cfg, work / "run", quiet=True, force=True)
    s = json.loads((work / "run" / "summary.json").read_text(encoding="utf-8"))
    out = {"converged": s.get("converged")}
    for sec, name in (("thermal", "Ti"), ("hygric", "Pi"), ("hygric", "RH")):
        m = s["metrics"].get(sec, {}).get(name)
        if m:
            out[f"cal_{name}"] = m["validation"]["FIT"]
    return out


def _models(cfg) -> str:
    parts = []
    for sec in ("thermal", "hygric"):
        s = getattr(cfg, sec, None)
        if s is None:
            continue
        o = s.options or {}
        o = o if isinstance(o, dict) else o.model_dump()
        opts = {k: v for k, v in o.items() if v}
        parts.append(s.model + (f" {opts}" if opts else ""))
    return "; ".join(parts)


def one(room, variant, config: Path, args, work: Path, extra: dict) -> dict:
    from heritage_bayes.config import load_config

    cfg = load_config(config)
    t0, c0 = time.perf_counter(), _cpu()
    row = {"room": room, "variant": variant, "held_out": ROOMS[room][3], **extra}
    row["irradiance"] = cfg.data.irradiance
    row["models"] = _models(cfg)
    cal, val = cfg.periods.calibration, cfg.periods.validation
    row["periods"] = f"cal {cal.start}..{cal.end}, val {val.start}..{val.end}"
    row.update(map_fits(cfg, args.maxiter, args.starts))
    secs = [sec for sec in ("thermal", "hygric") if getattr(cfg, sec, None) is not None]
    parts = row["models"].split("; ")
    for i, sec in enumerate(secs):  # model: auto: the screen's choice beside it
        if f"{sec}_screen" in row:
            parts[i] = parts[i].replace("auto", f"auto → {row[f'{sec}_model']}", 1)
    row["models"] = "; ".join(parts)
    if args.calibrate:
        row.update(calibrate_fits(cfg, work, args.max_steps))
    row["wall_s"], row["cpu_s"] = time.perf_counter() - t0, _cpu() - c0
    return row


def _print(row: dict) -> None:
    def f(k):
        v = row.get(k)
        return "  -  " if v is None else f"{v:5.1f}"

    ho = "held out" if row["held_out"] else "tuning"
    line = (
        f"| {row['room']} | {ho} | {row['variant']} | {row['irradiance']} | {row['models']} | "
        f"{f('Ti')} | {f('Pi')} | {f('RH')} | {f('fit_Ti')} | {f('fit_Pi')} |"
    )
    if "cal_Ti" in row:
        line += f" {f('cal_Ti')} | {f('cal_Pi')} | {f('cal_RH')} | {row.get('converged')} |"
    line += f" {row['wall_s']:.0f} / {row['cpu_s']:.0f} | {row['periods']} |"
    print(line, flush=True)


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("rooms", nargs="*", help=f"default: {TUNING}")
    ap.add_argument("--held-out", action="store_true", help=f"add {HELD_OUT}")
    ap.add_argument("--data", type=Path, default=ROOT.parent / "shared" / "data")
    ap.add_argument("--out", type=Path, help="work folder (default: a temporary one)")
    ap.add_argument("--maxiter", type=int, default=100, help="MAP generations (default 100)")
    ap.add_argument("--starts", type=int, default=2, help="MAP local starts (default 2)")
    ap.add_argument("--calibrate", action="store_true", help="also a short hbayes calibrate")
    ap.add_argument("--max-steps", type=int, default=1500, help="emcee cap with --calibrate")
    ap.add_argument("--no-bare", action="store_true", help="skip the attics without radiation")
    ap.add_argument(
        "--room-below",
        action="store_true",
        help="attics: also with init's advice followed (the room below's measured T as Tf)",
    )
    ap.add_argument(
        "--monthly", action="store_true", help="also the thermal MAP's residual by month"
    )
    ap.add_argument(
        "--whole-record",
        action="store_true",
        help="also with periods.calibration widened to the whole usable stretch (same validation)",
    )
    ap.add_argument("--json", type=Path, help="write the rows here")
    ap.add_argument(
        "--span",
        nargs=2,
        metavar=("START", "END"),
        help="cut the TRH-1 files to the rows stamped in [START, END) (copies in the work folder)",
    )
    args = ap.parse_args(argv)
    rooms = args.rooms or TUNING + (HELD_OUT if args.held_out else [])
    if set(rooms) - set(ROOMS):
        ap.error(f"unknown room(s) {sorted(set(rooms) - set(ROOMS))}; choose from {list(ROOMS)}")
    work = args.out or Path(tempfile.mkdtemp(prefix="real_rooms_"))
    hdr = (
        "| room | held out? | weather | irradiance | models init chose | Ti | Pi | RH |"
        " calibration Ti | calibration Pi |"
    )
    if args.calibrate:
        hdr += " cal Ti | cal Pi | cal RH | converged |"
    print(f"validation FIT [%] of the MAP (maxiter {args.maxiter}, starts {args.starts})")
    print(hdr + " wall / CPU [s] | periods |", flush=True)
    rows = []
    for room in rooms:
        logger, wfile, *_ = ROOMS[room]
        lpath, wpath = args.data / logger, args.data / wfile
        if args.span:
            lpath, wpath = cut_files(room, args.data, work, args.span)
        published = f"{args.span[0]} to {args.span[1]}" if args.span else "as published"
        variants = {published: wpath}
        if wfile.startswith("trh1") and not args.no_bare:
            bare = work / room / "bare" / "fmi.csv"
            bare.parent.mkdir(parents=True, exist_ok=True)
            pd.read_csv(wpath).drop(columns=["Rglob", "Rdif"]).to_csv(bare, index=False)
            variants["no radiation"] = bare
        for variant, weather in variants.items():
            w = work / room / ("init" if weather == wpath else "init_bare")
            w.mkdir(parents=True, exist_ok=True)
            t0, c0 = time.perf_counter(), _cpu()
            config, questions, given = run_init(room, args.data, w, weather, lpath)
            init_s = {"init_wall_s": time.perf_counter() - t0, "init_cpu_s": _cpu() - c0}
            if questions:
                print(f"| {room} | {variant}: open questions after the answers {given}: "
                      f"{questions} |", flush=True)  # fmt: skip
                continue
            row = one(room, variant, config, args, w, {"answers": given, **init_s})
            rows.append(row)
            _print(row)
            if args.monthly:
                from heritage_bayes.config import load_config

                print(monthly_residuals(load_config(config), args.maxiter, args.starts))
            if args.whole_record:
                whole = whole_record(config)
                row = one(room, variant + ", whole record", whole, args, w, {"answers": given})
                rows.append(row)
                _print(row)
            if args.room_below and logger.startswith("trh1"):
                below = room_below(config, args.data / logger)
                row = one(room, variant + ", room below", below, args, w, {"answers": given})
                rows.append(row)
                _print(row)
        if room == "annisse":
            row = one(room, "hand config", ROOT / "configs" / "annisse.yaml", args,
                      work / room / "hand", {})  # fmt: skip
            rows.append(row)
            _print(row)
    if args.json:
        args.json.write_text(json.dumps(rows, indent=1, default=str), encoding="utf-8")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
