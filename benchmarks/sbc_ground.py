"""Simulation-based calibration of the ground at an estimated depth (``ground: seasonal``).

Rooms from :mod:`ground_rooms` (a generator that shares no code with the package: its
own weather, a soil of its own diffusivity whose temperature at depth is the damped,
lagged annual harmonic plus the surface's departures conducted down a finite-difference
column, 5-minute exact steps of the room, an unmodelled heat gain, a logger's noise,
rounding and gaps), each calibrated the way ``hbayes calibrate`` would from its hourly
records with ``data.ground_temperature: {mode: seasonal}`` and no depth (what init
writes for a room on the ground): ``thermal_1c`` with ``ground: seasonal``, its
equivalent depth ``zf`` estimated.

The fit's inputs are built as ``hbayes calibrate`` builds them: the station's and the
logger's hourly readings through :func:`heritage_bayes.io.align` on 1 h (instantaneous
readings, the first-order hold of ``Te``: ``data.input_hold: exact``), the ground ``Tf``
at 1 m (:func:`heritage_bayes.inputs.ground_input`, mode ``seasonal``) and the cycle's
columns ``Tf_cos``, ``Tf_sin`` (:func:`heritage_bayes.inputs.ground_cycle_inputs`), both
from the station's whole year of Te, at the steps' middles; the survey's 400 m³, 0.5 /h
and 80 m² floor; priors, MAP and emcee of ``benchmarks/bench_sbc.fit_and_rank``
(``hbayes calibrate``'s defaults; ``ar1_white``, the start state estimated, the
likelihood tempered by 2 as ``hbayes calibrate`` tempers a thermal model of one or two
nodes).

    python benchmarks/sbc_ground.py --reps 24 --jobs 2 --log ground.jsonl
    python benchmarks/sbc_ground.py --table ground.jsonl [--markdown]
    python benchmarks/sbc_ground.py --misfit --reps 8        # the ground's error, no fit
    python benchmarks/sbc_ground.py --pseudo --only 1,6 --without gain   # least squares, no noise

Each replicate is a function of ``(seed, replicate)``; one JSON line per replicate is
appended to ``--log`` as soon as it is done, ``--first-rep``/``--only`` extend a study
and ``--table`` merges logs. ``--without`` leaves parts of the generator out
(:func:`ground_rooms.generate`).
"""

from __future__ import annotations

import argparse
import os
import sys
import time
from pathlib import Path

os.environ.setdefault("OPENBLAS_NUM_THREADS", "1")
os.environ.setdefault("OMP_NUM_THREADS", "1")

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parent))

import ground_rooms as rooms  # the generator (no heritage_bayes inside)

MODEL = ("thermal_1c", {"surfaces": (), "ground": "seasonal"})
#: the quantities the hourly data determine: the time constant and the static gain
#: (scale-free), and the depth (through the ground's share of the balance, the gain
#: from Tf = 1 - gain_Ti_Te, it moves the ground's level and phase over the record)
IDENTIFIABLE = ("tau_1_h", "gain_Ti_Te", "zf")
#: ranked for the record: the ground's mean offset ``dTf`` [K] (its truth: the offset of
#: the package's ground closest to the generator's soil, :func:`ground_truth`; and
#: ``dTf_climate``, the same draws against the study's earlier truth,
#: :func:`climate_offset`), the depth against that ground's depth (``zf_lsq``; ``zf``
#: above is ranked against the generator's), and absolute sizes pinned by the survey's
#: priors only
OTHERS = ("dTf", "dTf_climate", "zf_lsq", "Gf", "Ci")
VARIANT = "ar1_white:estimate:T=2"
SEED = 2061
CAL_DAYS = 120
PARTS = ("anomaly", "gain", "noise", "outage", "synoptic", "within_hour", "subhourly", "rounding")


def fit_model():
    """The fitted model as ``hbayes calibrate`` builds it for a seasonal ground without
    a depth (``heritage_bayes.models.catalog_options``; the exact input hold)."""
    from heritage_bayes.rc.catalog import model

    name, opts = MODEL
    m = model(name, None, **opts)
    return m.with_slopes(m.network.inputs)


def fit_inputs(room: dict, model, true_mean: bool = False):
    """The hourly inputs ``U`` (N, m) in ``model.input_names`` order and the observed
    ``Ti`` (N,) (NaN where lost), built as ``hbayes calibrate`` builds them (module
    docstring), and the station's Te. ``true_mean`` (diagnosis, ``--true-mean``): the
    ground's mean is the generator's climate mean instead of the mean of the cycle the
    package fits to the station's year (``Tf`` shifted by their difference)."""
    import pandas as pd

    from heritage_bayes.inputs import add_slope_columns, ground_cycle_inputs, ground_input
    from heritage_bayes.io.align import align

    h = room["hourly"]
    n = h["Te"].size
    t0 = pd.Timestamp("2021-01-01", tz="UTC") + pd.Timedelta(days=room["start_doy"] - 1.0)
    index = pd.date_range(t0.floor("h"), periods=n, freq="1h")
    met = pd.DataFrame({"Te": h["Te"]}, index=index)
    met.attrs.update(averaged=(), interval="1h", source="station")
    logger = pd.DataFrame({"Ti": h["Ti"]}, index=index)
    logger.attrs.update(averaged=(), interval="1h", source="logger")
    aligned = align([met], logger, step="1h", max_gap="0h")
    frame = aligned.frame.copy()
    frame.attrs = dict(aligned.frame.attrs)
    mids = frame.index + pd.Timedelta(minutes=30)
    te = met["Te"]
    frame["Tf"], _ = ground_input("seasonal", te, mids, None)
    cols, _ = ground_cycle_inputs(te, mids)
    for c, v in cols.items():
        frame[c] = v
    if true_mean:
        from heritage_bayes.climate.ground import fit_annual_cycle

        frame["Tf"] += room["climate"]["T_m"] - fit_annual_cycle(te)["mean"]
    add_slope_columns(frame, [model], aligned.slopes)
    assert len(frame) == n - 1 and frame.index[0] == index[0]
    U = np.column_stack([frame[c].to_numpy(float) for c in model.input_names])
    return U, frame["Ti"].to_numpy(float), te


def package_ground(U, model, zf, dtf=0.0) -> np.ndarray:
    """The package's ground ``Tf(t; zf, dTf)`` [°C] over the fit's steps: the input
    ``Tf`` (the fitted cycle at 1 m) carried to the equivalent depth ``zf`` [m] through
    ``Tf_cos``, ``Tf_sin`` and raised by the offset ``dtf`` [K], as the fit's
    ``GroundCycle`` does (``heritage_bayes.rc.network.GroundCycle``)."""
    from heritage_bayes.climate.ground import depth_factors

    a, b = depth_factors(zf)
    a1, b1 = depth_factors(1.0)
    names = model.input_names
    tf = U[:, names.index("Tf")] + (a - a1) * U[:, names.index("Tf_cos")]
    return tf + (b - b1) * U[:, names.index("Tf_sin")] + dtf


def ground_truth(room: dict, model, U) -> dict:
    """The ground the fit can express closest to the generator's soil: ``zf`` [m] and
    ``dTf`` [K] of :func:`package_ground` by least squares against the soil's
    temperature at the room's depth over the calibration hours with a reading (within
    the fit's prior bounds, 0.5-6 m and ±5 K).

    ``dTf``'s truth: the soil's departures from its annual harmonic (the synoptic
    weather conducted down) and the fitted cycle's errors do not average out over the
    calibration window, and the package's ground, a cycle plus a constant, takes them
    up in its offset and its depth together; the offset's truth is the one that goes
    with that depth. The generator's climate mean minus the fitted cycle's
    (:func:`climate_offset`) is the offset of a ground that followed the harmonic only.
    Returns ``{"zf": ..., "dTf": ...}``."""
    from scipy.optimize import least_squares

    n = U.shape[0]
    seen = np.zeros(n, bool)
    seen[room["rows"]] = True
    seen &= np.isfinite(room["hourly"]["Ti"][:n])
    soil = room["hourly"]["Tf_true"][:n][seen]

    def resid(x):
        return package_ground(U, model, np.exp(x[0]), x[1])[seen] - soil

    zf0 = room["truth"]["zf"]
    x0 = [np.log(zf0), float(np.mean(soil - package_ground(U, model, zf0)[seen]))]
    lo, hi = [np.log(rooms.ZF_BOUNDS[0]), -5.0], [np.log(rooms.ZF_BOUNDS[1]), 5.0]
    x = least_squares(resid, np.clip(x0, lo, hi), bounds=(lo, hi)).x
    return {"zf": float(np.exp(x[0])), "dTf": float(x[1])}


def climate_offset(room: dict, te) -> float:
    """The generator's climate mean minus the mean of the cycle the package fits to the
    station's Te [K] (the study's truth of ``dTf`` before :func:`ground_truth`)."""
    from heritage_bayes.climate.ground import fit_annual_cycle

    return float(room["climate"]["T_m"] - fit_annual_cycle(te)["mean"])


def ground_error(room: dict, te, model, U) -> dict:
    """The package's ground at the true equivalent depth against the generator's soil
    over the calibration hours (mean, sd [K]), and the package's fitted surface cycle
    against the generator's harmonic (mean [°C], amplitude [K], coldest day [d])."""
    from heritage_bayes.climate.ground import fit_annual_cycle

    rows = room["rows"]
    tf = package_ground(U, model, room["truth"]["zf"])
    d = (room["hourly"]["Tf_true"][: tf.size] - tf)[rows]
    c = fit_annual_cycle(te)
    cl = room["climate"]
    return {
        "tf_mean": float(d.mean()),
        "tf_sd": float(d.std()),
        "cycle_mean": c["mean"] - cl["T_m"],
        "cycle_amplitude": c["amplitude"] - cl["A"],
        "cycle_coldest": float((c["coldest_day"] - cl["t_min"] + 182.5) % 365.0 - 182.5),
    }


def replicate(args) -> dict:
    """One room: generate, calibrate its calibration period, rank the truths.
    ``args``: (replicate, seed, max_steps, calibration days, parts left out[,
    variant[, {quantity: factor}: truths multiplied by a factor, to show the ranking
    can fail]])."""
    from bench_sbc import ACH, FLOOR, VOLUME, fit_and_rank

    rep, seed, max_steps, cal_days, without = args[:5]
    variant = args[5] if len(args) > 5 else VARIANT
    shift = args[6] if len(args) > 6 else {}
    true_mean = bool(args[7]) if len(args) > 7 else False
    reading = args[8] if len(args) > 8 else "instant"
    assert (VOLUME, ACH, FLOOR) == (rooms.VOLUME, rooms.ACH, rooms.FLOOR), "survey differs"
    room = rooms.generate([seed, rep], cal_days, without=without, reading=reading)
    model = fit_model()
    U, y, te = fit_inputs(room, model, true_mean)
    rows = room["rows"]
    truth = rooms.quantities(room["truth"])
    lsq = ground_truth(room, model, U)  # against the input the fit was given
    climate = 0.0 if true_mean else climate_offset(room, te)
    truth.update(dTf=lsq["dTf"], dTf_climate=climate, zf_lsq=lsq["zf"])
    truth = {k: float(v) * shift.get(k, 1.0) for k, v in truth.items()}
    names = model.parameter_names

    def extra(dq, theta, _names=names):
        p = {n: theta[:, j] for j, n in enumerate(_names)}
        q = rooms.quantities(p)
        out = {k: q[k] for k in ("zf", "Gf", "Ci")}
        return out | {"zf_lsq": q["zf"], "dTf": p["dTf"], "dTf_climate": p["dTf"]}

    return {
        "room": "ground",
        "model": MODEL[0],
        "rep": rep,
        "seed": seed,
        "without": sorted(without) + (["ground_mean"] if true_mean else []),
        "reading": reading,
        "variant": variant,
        "truth": truth,
        "truth_parameters": room["truth"],
        "soil": room["soil"],
        "ground_error": ground_error(room, te, model, U),
        "variants": fit_and_rank(
            model,
            U[rows],
            y[rows],
            truth,
            [variant],
            rep,
            max_steps,
            {},
            rooms.FLOOR,
            None,
            extra,
        ),
    }


def table_lines(results: list[dict], markdown: bool = False) -> list[str]:
    """The coverage table (:func:`sbc_coupled.summary`, identifiable quantities first)."""
    from sbc_coupled import summary, verdict

    head = (
        "| model (rooms, converged) | quantity | 90 % coverage (95 % CI) | verdict | 50 % "
        "| mean z / sd z | rank χ² p | width |"
    )
    lines = [head, "|---|---|---|---|---|---|---|---|"] if markdown else []
    conv = sum(r["variants"][r["variant"]]["converged"] for r in results)
    cpu = np.mean([r["variants"][r["variant"]]["cpu"] for r in results])
    label = f"{MODEL[0]}, ground: seasonal ({len(results)}, {conv})"
    if not markdown:
        lines.append(f"{label}: {cpu:.0f} s CPU per fit")
    for q in IDENTIFIABLE + OTHERS:
        s = summary(results, "ground", q)
        if s is None:
            continue
        tag = " (not identifiable)" if q in ("Gf", "Ci") else ""
        ci = f"{s['c90']:.2f} ({s['c90_ci'][0]:.2f}-{s['c90_ci'][1]:.2f})"
        p = "—" if not np.isfinite(s["rank_p"]) else f"{s['rank_p']:.3f}"
        zz = f"{s['z_mean']:+.2f} / {s['z_sd']:.2f}"
        if markdown:
            lines.append(
                f"| {label} | {q}{tag} | {ci} | {verdict(s)} | {s['c50']:.2f} | {zz} | {p} "
                f"| {s['width']:.2f} |"
            )
            label = ""
        else:
            lines.append(
                f"  {q + tag:26s} n {s['n']:3d}  90 %: {ci}  {verdict(s):18s} 50 %: "
                f"{s['c50']:.2f}  z {zz}  rank p {p}  width {s['width']:.2f}"
            )
    return lines


def room_lines(results: list[dict]) -> list[str]:
    """Per room: z of each identifiable quantity and of ``dTf`` (``*`` outside the 90 %
    interval), the truths' depth and ground share, and the ground's error
    (:func:`ground_error`)."""
    lines = [
        "rep: z tau, gain, zf, dTf | zf true, gain from Tf | ground - package's at true zf: "
        "mean, sd [K] | cycle: mean, amplitude error [K], coldest day [d]"
    ]
    for r in sorted(results, key=lambda r: r["rep"]):
        ranks = r["variants"][r["variant"]]["ranks"]
        zs = []
        for q in (*IDENTIFIABLE, "dTf"):
            x = ranks.get(q)
            if x is None:
                zs.append("   —  ")
                continue
            z = (x["median"] - r["truth"][q]) / x["sd"]
            zs.append(f"{z:+6.2f}{'*' if not x['in90'] else ' '}")
        g = r["ground_error"]
        lines.append(
            f"{r['rep']:3d}: {' '.join(zs)} | {r['truth']['zf']:.2f} m, "
            f"{1 - r['truth']['gain_Ti_Te']:.2f} | {g['tf_mean']:+.2f}, {g['tf_sd']:.2f} | "
            f"{g['cycle_mean']:+.2f}, {g['cycle_amplitude']:+.2f}, {g['cycle_coldest']:+.0f}"
        )
    return lines


def paired_lines(a: list[dict], b: list[dict]) -> list[str]:
    """Two logs of the same rooms (e.g. the default and ``--true-mean``): per quantity
    over the replicates in both, mean z in each, mean and sd of z_a - z_b and the
    rooms inside the 90 % interval in each."""

    def zs(r):
        ranks = r["variants"][r["variant"]]["ranks"]
        return {q: ((x["median"] - r["truth"][q]) / x["sd"], x["in90"]) for q, x in ranks.items()}

    ra, rb = ({r["rep"]: zs(r) for r in log} for log in (a, b))
    reps = sorted(set(ra) & set(rb))
    lines = [f"{len(reps)} rooms in both (replicates {reps})"]
    for q in IDENTIFIABLE + OTHERS:
        pairs = [(ra[r][q], rb[r][q]) for r in reps if q in ra[r] and q in rb[r]]
        if not pairs:
            continue
        za, zb = (np.array([p[i][0] for p in pairs]) for i in (0, 1))
        d = za - zb
        sd = f"{d.std(ddof=1):.2f}" if d.size > 1 else "—"
        lines.append(
            f"  {q:10s} mean z {za.mean():+.2f} / {zb.mean():+.2f}; z_a - z_b mean "
            f"{d.mean():+.2f}, sd {sd}; in 90 %: {sum(p[0][1] for p in pairs)} / "
            f"{sum(p[1][1] for p in pairs)} of {d.size}"
        )
    return lines


def misfit_lines(reps, seed: int, cal_days: int, without: tuple, reading: str) -> list[str]:
    """``--misfit``: the ground's error (:func:`ground_error`) of rooms ``reps``, no fit."""
    model = fit_model()
    lines = ["rep: ground - package's at true zf: mean, sd [K]; cycle errors"]
    for rep in reps:
        room = rooms.generate([seed, rep], cal_days, without=without, reading=reading)
        U, _, te = fit_inputs(room, model)
        g = ground_error(room, te, model, U)
        lines.append(f"{rep:3d}: " + ", ".join(f"{k} {v:+.2f}" for k, v in g.items()))
    return lines


def pseudo_fit(room: dict, model) -> dict:
    """The fit's pseudo-truth of one room without the posterior: ``Ge``, ``Gf``, ``zf``
    and ``dTf`` by least squares of the package's model on the room's noise-free hourly
    Ti over the calibration hours (``Ci`` at its truth, the start at the generator's).
    Returns the least-squares and true ``tau_1_h`` [h], ``zf`` [m], gain from Tf [-]
    and ``dTf`` [K] (``*_true``; ``zf_lsq`` and ``dTf_true`` of :func:`ground_truth`,
    ``dTf_climate`` of :func:`climate_offset`), and the ground's error
    (:func:`ground_error`)."""
    from scipy.optimize import least_squares

    from heritage_bayes import simulate

    U, _, te = fit_inputs(room, model)
    t, rows = room["truth"], room["rows"]
    target = room["hourly"]["Ti_true"][: U.shape[0]][rows]
    x0 = np.array([room["hourly"]["Ti_true"][0]])
    lsq = ground_truth(room, model, U)

    def resid(x):
        p = {**t, "Ge": np.exp(x[0]), "Gf": np.exp(x[1]), "zf": np.exp(x[2]), "dTf": x[3]}
        return simulate(model, p, U, 3600.0, x0)[rows, 0] - target

    start = [*np.log([t["Ge"], t["Gf"], t["zf"]]), lsq["dTf"]]
    lo, hi = [*np.log([1e-2, 1e-2, 0.5]), -5.0], [*np.log([1e5, 1e5, 6.0]), 5.0]
    x = least_squares(resid, start, bounds=(lo, hi), x_scale=1.0).x
    ge, gf, zf = np.exp(x[:3])
    return {
        "tau_1_h": t["Ci"] / (ge + gf) / 3600.0,
        "tau_1_h_true": t["Ci"] / (t["Ge"] + t["Gf"]) / 3600.0,
        "zf": zf,
        "zf_true": t["zf"],
        "zf_lsq": lsq["zf"],
        "gain_f": gf / (ge + gf),
        "gain_f_true": t["Gf"] / (t["Ge"] + t["Gf"]),
        "dTf": float(x[3]),
        "dTf_true": lsq["dTf"],
        "dTf_climate": climate_offset(room, te),
        "ground": ground_error(room, te, model, U),
    }


def pseudo_lines(reps, seed: int, cal_days: int, without: tuple, reading: str) -> list[str]:
    """``--pseudo``: :func:`pseudo_fit` of rooms ``reps`` against their truths (the
    room's unmodelled gain stays unless ``without`` leaves it out): what the ground's
    and the weather's structural error alone do to the time constant, the depth, the
    gain and the ground's offset."""
    model = fit_model()
    lines = [
        "rep: tau true [h], least squares - true [min]; zf true (ground's LS) -> LS; gain "
        "from Tf true -> LS; dTf true (climate's) -> LS [K]"
    ]
    for rep in reps:
        room = rooms.generate([seed, rep], cal_days, without=without, reading=reading)
        f = pseudo_fit(room, model)
        lines.append(
            f"{rep:3d}: tau {f['tau_1_h_true']:.2f} h, "
            f"{60 * (f['tau_1_h'] - f['tau_1_h_true']):+.1f} min; zf {f['zf_true']:.2f} "
            f"({f['zf_lsq']:.2f}) -> {f['zf']:.2f} m; gain from Tf {f['gain_f_true']:.3f} "
            f"-> {f['gain_f']:.3f}; dTf {f['dTf_true']:+.2f} ({f['dTf_climate']:+.2f}) -> "
            f"{f['dTf']:+.2f} K"
        )
    return lines


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--reps", type=int, default=24)
    ap.add_argument("--first-rep", type=int, default=0)
    ap.add_argument("--only", help="comma-separated replicates (instead of --first-rep/--reps)")
    ap.add_argument("--jobs", type=int, default=1)
    ap.add_argument("--seed", type=int, default=SEED)
    ap.add_argument("--max-steps", type=int, default=4000)
    ap.add_argument("--cal-days", type=int, default=CAL_DAYS)
    ap.add_argument("--variant", default=VARIANT, help="NOISE:INIT[:T=X] (bench_sbc)")
    ap.add_argument("--log", help="append each replicate's result as a JSON line")
    ap.add_argument("--without", default="", help=f"parts left out: {', '.join(PARTS)}")
    ap.add_argument("--true-mean", action="store_true", help="diagnosis: the fit's ground "
                    "at the generator's climate mean (fit_inputs)")  # fmt: skip
    ap.add_argument("--reading", choices=("instant", "step_start"), default="instant",
                    help="the station's reading at the hour: the weather at that instant "
                    "(default), or the 5-minute step's that starts there (the old "
                    "generator, for paired diagnosis)")  # fmt: skip
    ap.add_argument("--table", nargs="+", metavar="LOG", help="only tabulate logs")
    ap.add_argument("--markdown", action="store_true", help="with --table: markdown")
    ap.add_argument("--paired", nargs=2, metavar="LOG", help="two logs of the same rooms")
    ap.add_argument("--misfit", action="store_true", help="no fit: the ground's error")
    ap.add_argument("--pseudo", action="store_true", help="no posterior: least-squares "
                    "depth and gain on noise-free rooms (pseudo_lines)")  # fmt: skip
    args = ap.parse_args(argv)
    without = tuple(w for w in args.without.split(",") if w)
    if set(without) - set(PARTS):
        ap.error(f"--without: unknown {sorted(set(without) - set(PARTS))}")
    reps = range(args.first_rep, args.first_rep + args.reps)
    if args.only:
        reps = [int(r) for r in args.only.split(",")]
    if args.paired:
        from sbc_coupled import read_logs

        for line in paired_lines(*(read_logs([p]) for p in args.paired)):
            print(line)
        return 0
    if args.table:
        from sbc_coupled import read_logs

        results = read_logs(args.table)
        print(f"SBC of the seasonal ground, {' '.join(args.table)}: {len(results)} rooms")
        for line in table_lines(results, args.markdown) + room_lines(results):
            print(line)
        return 0
    if args.pseudo:
        for line in pseudo_lines(reps, args.seed, args.cal_days, without, args.reading):
            print(line, flush=True)
        return 0
    if args.misfit:
        for line in misfit_lines(reps, args.seed, args.cal_days, without, args.reading):
            print(line, flush=True)
        return 0
    from bench_sbc import run_tasks

    opts = (args.variant, {}, args.true_mean, args.reading)
    tasks = [(rep, args.seed, args.max_steps, args.cal_days, without, *opts) for rep in reps]
    t0 = time.perf_counter()
    results = run_tasks(replicate, tasks, args.jobs, args.log)
    print(
        f"SBC of the seasonal ground: {len(results)} rooms, {time.perf_counter() - t0:.0f} s "
        f"wall, load average {os.getloadavg()[0]:.1f}"
    )
    for line in table_lines(results) + room_lines(results):
        print(line)
    return 0


if __name__ == "__main__":
    sys.exit(main())
