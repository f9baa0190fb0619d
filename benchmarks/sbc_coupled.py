"""Simulation-based calibration of the thermo-hygric coupled models.

Rooms from :mod:`coupled_rooms` (a generator that shares no code with the package:
5-minute Runge-Kutta of a buffer with a GAB sorption isotherm, synthetic weather, an
unmodelled moisture source, a logger's noise, rounding and gaps), each calibrated the way
``hbayes calibrate`` would from its hourly records, and the truths ranked among the
posterior draws:

- **attic** rooms, fitted by ``hygric_2c_sorption`` (the buffer's surface vapour
  pressure at φ_w p_sat(Ti), Ti the logged indoor temperature);
- **cellar** rooms, fitted by ``hygric_2c_fixed`` with ``sink: temperature`` (a vapour
  sink at φ_f p_sat(Tf), Tf the logged ground temperature).

The fit's inputs are built as ``hbayes calibrate`` builds them from the records:
:func:`heritage_bayes.io.align` on 1 h (the station's readings as instantaneous, the
first-order hold of ``Pe`` through its slope column, ``data.input_hold: exact``), the
indoor vapour pressure from the logged Ti and RHi, missing where RHi reads 99 % or more
(:func:`heritage_bayes.io.derive.add_vapour_pressure`), the logged Ti as the coupled
model's temperature input with its gaps interpolated linearly, the survey's room volume
(400 m³), air change rate (0.5 /h) and, for the cellar, floor (80 m²) and envelope
(259 m²) areas; the priors, the MAP and emcee are ``benchmarks/bench_sbc.fit_and_rank``'s
(``hbayes calibrate``'s defaults, ``noise: ar1_white``, the start state estimated).

    python benchmarks/sbc_coupled.py --reps 40 --jobs 2 --log coupled.jsonl
    python benchmarks/sbc_coupled.py --table coupled.jsonl [--markdown]
    python benchmarks/sbc_coupled.py --reps 10 --rooms attic --without outage --log no.jsonl
    python benchmarks/sbc_coupled.py --paired coupled.jsonl no.jsonl
    python benchmarks/sbc_coupled.py --source-seeds own,1,2,3 --only 0,2 --rooms cellar
    python benchmarks/sbc_coupled.py --rooms cellar --variant kalman:estimate --log kalman.jsonl

Each replicate is a function of ``(seed, room, replicate)``; one JSON line per replicate
is appended to ``--log`` as soon as it is done, ``--first-rep`` extends a study, and
``--table`` merges logs. ``--without`` leaves parts of the generator out (diagnosis:
``isotherm``, ``source``, ``noise``, ``outage``; :func:`coupled_rooms.generate`);
``--source-seeds`` finds the MAP of cellars under other realisations of their moisture
source (no chain; :func:`coupled_path.source_lines`).
"""

from __future__ import annotations

import argparse
import json
import math
import os
import sys
import time
from pathlib import Path

os.environ.setdefault("OPENBLAS_NUM_THREADS", "1")
os.environ.setdefault("OMP_NUM_THREADS", "1")

import numpy as np
from scipy import stats

sys.path.insert(0, str(Path(__file__).resolve().parent))

import coupled_rooms as rooms  # the generator (no heritage_bayes inside)
from heritage_bayes.rc.isotherm import gab_capacity_factor
from heritage_bayes.rc.sorption import P_REF

#: the fitted model of each room type: (catalogue name, options)
MODELS = {
    "attic": ("hygric_2c_sorption", {}),
    "cellar": ("hygric_2c_fixed", {"sink": "temperature"}),
}
#: quantities whose truths the data determine (scale-free: every quantity here is
#: unchanged when all capacities and conductances are multiplied by one factor, the
#: direction hourly data cannot see; :func:`coupled_rooms.network_quantities`)
IDENTIFIABLE = {
    "attic": ("tau1_h", "tau2_h", "buffer_share", "buffer_hours"),
    "cellar": ("tau1_h", "gain_Pe", "sink_pull_Pa", "buffer_hours", "phi_f"),
}
#: ranked too, for the record: absolute sizes pinned by the survey's priors only, or
#: quantities the data hardly inform (the cellar's fast mode)
OTHERS = {"attic": ("Cm",), "cellar": ("tau2_h",)}
#: ranked for a fit with ``--isotherm gab`` only: the multilayer factor, whose truth is
#: the generator's K (its C differs from the fit's fixed one)
GAB_ONLY = ("K_gab",)
#: ranked after the fit from the saved draws (``--path``, :mod:`coupled_path`): the
#: cellar's slow quantities at the capacity along the record's own path of the wall
PATH = ("tau1_path_h", "buffer_hours_path")
#: the fitted buffer's isotherms (``--isotherm``): the model's option ``isotherm``
ISOTHERMS = ("linear", "gab")
VARIANT = "ar1_white:estimate"
SEED = 2049
CAL_DAYS = 60


def fit_inputs(room: dict, fit_model):
    """The hourly inputs ``U`` (N, m) in ``fit_model.input_names`` order and the observed
    ``Pi`` (N,) [Pa] (NaN where lost), built from the room's records as ``hbayes
    calibrate`` builds them (module docstring)."""
    import pandas as pd

    from heritage_bayes.climate.psychro import vapour_pressure
    from heritage_bayes.inputs import add_slope_columns
    from heritage_bayes.io.align import align
    from heritage_bayes.io.derive import add_vapour_pressure

    h = room["hourly"]
    n = h["Te"].size
    index = pd.date_range("2021-01-01", periods=n, freq="1h", tz="UTC")
    met = pd.DataFrame({"Te": h["Te"], "Pe": vapour_pressure(h["Te"], h["RHe"])}, index=index)
    met.attrs.update(averaged=(), interval="1h", source="station")
    weather = [met]
    if "Tf" in h:
        ground = pd.DataFrame({"Tf": h["Tf"]}, index=index)
        ground.attrs.update(averaged=(), interval="1h", source="ground logger")
        weather.append(ground)
    logger = pd.DataFrame({"Ti": h["Ti"], "RHi": h["RHi"]}, index=index)
    logger.attrs.update(averaged=(), interval="1h", source="logger")
    logger = add_vapour_pressure(logger)  # Pi per reading, censored at saturation
    aligned = align(weather, logger, step="1h", max_gap="0h")
    frame = aligned.frame.copy()
    frame.attrs = dict(aligned.frame.attrs)
    add_slope_columns(frame, [fit_model], aligned.slopes)
    y = frame["Pi"].to_numpy(float)
    cols = []
    for c in fit_model.input_names:
        v = frame[c].to_numpy(float)
        if c == "Ti":  # a measured indoor quantity as an input: gaps linear in time
            ok = np.isfinite(v)
            v = np.interp(np.arange(v.size), np.flatnonzero(ok), v[ok])
        cols.append(v)
    assert len(frame) == n - 1 and frame.index[0] == index[0]
    return np.column_stack(cols), y


def replicate(args) -> dict:
    """One room: generate, calibrate its calibration period, rank the truths.

    ``args``: (room type, replicate, seed, max_steps, calibration days, parts of the
    generator left out[, {quantity: factor}: truths multiplied by a factor before they
    are ranked, a deliberately wrong truth for the test that the ranking can fail[,
    the fit's variant, ``NOISE:INIT[:T=X]`` of ``bench_sbc.fit_and_rank``, default
    :data:`VARIANT`]])."""
    import heritage_bayes as hb
    from bench_sbc import ACH, VOLUME, fit_and_rank

    room_type, rep, seed, max_steps, cal_days, without = args[:6]
    # a deliberately wrong truth (quantity -> factor), to show that the ranking can miss
    shift = args[6] if len(args) > 6 else {}
    variant = args[7] if len(args) > 7 else VARIANT
    isotherm = args[8] if len(args) > 8 else "linear"
    draws_dir = args[9] if len(args) > 9 else None
    assert (VOLUME, ACH) == (rooms.VOLUME, rooms.ACH), "the survey differs from the rooms'"
    room = rooms.generate(room_type, [seed, rooms.ROOMS.index(room_type), rep], cal_days,
                          without=without)  # fmt: skip
    name, opts = MODELS[room_type]
    if isotherm != "linear":
        opts = {**opts, "isotherm": isotherm}
        room["truth"] = gab_truth(room)
    fit_model = hb.model(name, **opts).with_slopes(("Pe",))
    U, y = fit_inputs(room, fit_model)
    rows = room["rows"]
    # a GAB buffer's capacity where it lives: at the record's mean indoor vapour pressure
    phi_m = float(np.nanmean(y[rows])) / P_REF if isotherm != "linear" else None
    tf_fit = None
    if "Tf" in fit_model.input_names:
        tf_fit = float(np.mean(U[rows, fit_model.input_names.index("Tf")]))
    at = gab_truth(room, phi_m) if phi_m is not None else room["truth"]
    truth = rooms.network_quantities(room_type, at, room.get("Tf_mean"))
    if "K_gab" in room["truth"]:
        truth["K_gab"] = room["truth"]["K_gab"]
    truth = {k: float(v) * shift.get(k, 1.0) for k, v in truth.items()}
    names = fit_model.parameter_names

    def extra(dq, theta, _names=names, _tf=tf_fit, _phi=phi_m):
        if draws_dir:  # the posterior draws, for quantities derived after the fit
            tag = "-".join([room_type, str(rep), *sorted(without), variant, isotherm])
            np.save(Path(draws_dir) / f"{tag.replace(':', '_')}.npy", theta)
        p = {n: theta[:, j] for j, n in enumerate(_names)}
        if _phi is not None:  # the capacity at the record's mean humidity
            cap = "Cw" if "Cw" in p else "Cm"
            p[cap] = p[cap] * gab_capacity_factor(_phi, p["K_gab"])
        q = rooms.network_quantities(room_type, p, _tf)
        return q | ({"K_gab": p["K_gab"]} if "K_gab" in p else {})

    cellar = room_type == "cellar"
    result = {
        "room": room_type,
        "model": name,
        "rep": rep,
        "seed": seed,
        "without": sorted(without),
        "truth_shift": shift,
        "variant": variant,
        "isotherm": isotherm,
        "capacity_means": room["capacity_means"],
        "truth": truth,
        "truth_parameters": room["truth"],
        "generator": room["generator"],
        "phi_w_range": room["phi_w_range"],
        "noise_truth": {**room["noise_truth"], "source_Pa": room["source_sd"]},
        "misfit_Pa": misfit(fit_model, room, U),
    }
    result["variants"] = fit_and_rank(
        fit_model,
        U[rows],
        y[rows],
        truth,
        [variant],
        rep,
        max_steps,
        {},
        rooms.FLOOR if cellar else None,
        rooms.ENVELOPE if cellar else None,
        extra,
    )
    return result


def gab_truth(room: dict, phi_ref: float | None = None) -> dict:
    """The truths of a fit with ``isotherm: gab`` (:mod:`heritage_bayes.rc.isotherm`):
    the buffer's capacity at the humidity ``phi_ref`` (default the model's ``PHI_REF``)
    expressed at 15 °C, i.e. at the true RH ``phi_ref p_sat(15 °C)/p_sat(T_w)`` (the
    cellar's wall at ``T_w``; the attic's buffer is at its true RH), and the
    multilayer factor the same scaling makes of the generator's K. The generator's C
    (5-10) is not the fit's fixed one: ``K_gab`` is the generator's K, not the fit's
    pseudo-true value (a few per cent apart)."""
    from heritage_bayes.rc.isotherm import PHI_REF

    g, t = room["generator"], dict(room["truth"])
    ps = room.get("wall_psat", P_REF)
    phi = (PHI_REF if phi_ref is None else phi_ref) * P_REF / ps
    cap = g["M"] * rooms.gab_slope(phi, g["um"], g["C"], g["K"])  # [kg per unit RH]
    if "Cw" in t:
        t["Cw"] = cap / ps
    else:
        t["Cm"] = cap
    t["K_gab"] = g["K"] * P_REF / ps
    return t


def misfit(fit_model, room: dict, U: np.ndarray) -> dict:
    """The generator's noise-free hourly ``Pi`` against the fitted model run with the
    room's true parameters (the buffer's capacity averaged over the calibration) on the
    fit's inputs, from the generator's state at the record's start: mean, sd and sd of
    the daily means [Pa] over the calibration period (the structural error the noise
    model has to take up: the isotherm's curvature, sub-hourly weather, p_sat
    formulas, and the source when it is on)."""
    import heritage_bayes as hb

    rows = room["rows"]
    pw = room["start"]["phi_w"] * room.get("wall_psat", P_REF)  # the buffer's state [Pa]
    x0 = np.array([pw, room["start"]["pi"]])
    sim = hb.simulate(fit_model, room["truth"], U, 3600.0, x0)[:, 0]
    d = (room["hourly"]["Pi_true"][: sim.size] - sim)[rows]
    days = d[: d.size // 24 * 24].reshape(-1, 24).mean(axis=1)
    return {"mean": float(d.mean()), "sd": float(d.std()), "daily_sd": float(days.std())}


def misfit_lines(room_types, reps, seed: int, cal_days: int) -> list[str]:
    """``--misfit``: the structural error (:func:`misfit`, no fit) of rooms ``reps``
    with every part of the generator and with each part left out (the same rooms and
    draws), for the fitted buffer with each of :data:`ISOTHERMS` (``gab``: the truths of
    :func:`gab_truth`): medians over the rooms of its |mean|, sd and sd of daily means
    [Pa], then the sd per room without the source."""
    import heritage_bayes as hb

    cases = {
        "every part": (),
        "without outage": ("outage",),
        "without isotherm": ("isotherm",),
        "without source": ("source",),
        "without isotherm, source, outage": ("isotherm", "source", "outage"),
    }
    lines = [
        f"noise-free generator - fitted model with the true parameters, {len(reps)} rooms "
        "each (medians): |mean|, sd, sd of daily means [Pa]"
    ]
    per_room = []
    for room_type in room_types:
        for iso in ISOTHERMS:
            name, opts = MODELS[room_type]
            opts = opts if iso == "linear" else {**opts, "isotherm": iso}
            model = hb.model(name, **opts).with_slopes(("Pe",))
            for label, without in cases.items():
                if iso != "linear" and "isotherm" in without:
                    continue  # gab_truth is the GAB generator's
                m = []
                for rep in reps:
                    room = rooms.generate(
                        room_type, [seed, rooms.ROOMS.index(room_type), rep], cal_days,
                        without=without,
                    )  # fmt: skip
                    if iso != "linear":
                        room["truth"] = gab_truth(room)
                    m.append(misfit(model, room, fit_inputs(room, model)[0]))
                    if without == ("source",):
                        lo, hi = room["phi_w_range"]
                        per_room.append(
                            f"  {room_type} {rep:3d} {iso:6s} buffer RH {lo:.2f}-{hi:.2f}: "
                            f"sd {m[-1]['sd']:5.1f}, mean {m[-1]['mean']:+5.1f} Pa"
                        )
                med = [np.median([abs(x[k]) for x in m]) for k in ("mean", "sd", "daily_sd")]
                lines.append(
                    f"  {room_type:7s} {iso:6s} {label:34s} {med[0]:6.1f} {med[1]:6.1f} "
                    f"{med[2]:6.1f}"
                )
    return [*lines, "without the source, per room:", *per_room]


def shape_lines() -> list[str]:
    """The fit's GAB slope (C fixed, :data:`heritage_bayes.rc.isotherm.GAB_C`) against
    the generator's (C 5-10, K 0.72-0.82), both normalised at the reference RH: the
    least-squares K of the log slopes over RH 0.4-1.0 and the largest relative error."""
    from scipy.optimize import minimize_scalar

    from heritage_bayes.rc.isotherm import PHI_REF, gab_capacity_factor

    phi = np.linspace(0.4, 1.0, 61)
    out = []
    for c in (5.0, 8.0, 10.0):
        for k in (0.72, 0.77, 0.82):
            t = rooms.gab_slope(phi, 1.0, c, k) / rooms.gab_slope(PHI_REF, 1.0, c, k)

            def sse(kk, _t=t):
                return float(np.sum(np.log(gab_capacity_factor(phi, kk) / _t) ** 2))

            best = minimize_scalar(sse, bounds=(0.0, 0.99), method="bounded").x
            err = np.max(np.abs(gab_capacity_factor(phi, best) / t - 1.0))
            out.append(
                f"generator C {c:4.1f} K {k:.2f}: slope {t.min():.2f}-{t.max():.2f} x; "
                f"fit's K {best:.3f}, largest error {100 * err:.1f} %"
            )
    return out


def capacity_lines(room_types, reps, seed: int, cal_days: int) -> list[str]:
    """``--capacity``: which mean of the isotherm's slope a constant capacity matches.
    Rooms ``reps`` without the moisture source, the logger's noise and the outage (the
    nonlinear isotherm is the only structural error left, with the true Ti as the
    coupling's input), the fitted model's capacity (``Cm`` or ``Cw``) by least squares
    on the noise-free hourly ``Pi`` with every other parameter at its truth and the
    generator's start state; printed: the buffer's RH range and the harmonic and
    arithmetic means of ``M du/dφ`` over the calibration (:func:`coupled_rooms.generate`)
    over that least-squares capacity, and the latter's rms misfit [Pa]."""
    from scipy.optimize import minimize_scalar

    import heritage_bayes as hb

    lines = ["room rep: buffer RH range; harmonic / LS, arithmetic / LS; rms at LS [Pa]"]
    for room_type in room_types:
        name, opts = MODELS[room_type]
        model = hb.model(name, **opts).with_slopes(("Pe",))
        for rep in reps:
            room = rooms.generate(room_type, [seed, rooms.ROOMS.index(room_type), rep],
                                  cal_days, without=("source", "noise", "outage"))  # fmt: skip
            U, _ = fit_inputs(room, model)
            if "Ti" in model.input_names:
                U[:, model.input_names.index("Ti")] = room["hourly"]["Ti_true"][: len(U)]
            rows, truth = room["rows"], room["truth"]
            cap = "Cm" if room_type == "attic" else "Cw"
            x0 = np.array([room["start"]["phi_w"] * room.get("wall_psat", P_REF),
                           room["start"]["pi"]])  # fmt: skip
            target = room["hourly"]["Pi_true"][: len(U)][rows]

            def sse(log_c, _m=model, _t=truth, _c=cap, _u=U, _x=x0, _y=target, _r=rows):
                sim = hb.simulate(_m, {**_t, _c: math.exp(log_c)}, _u, 3600.0, _x)
                return float(np.sum((sim[_r, 0] - _y) ** 2))

            c0 = math.log(truth[cap])
            best = minimize_scalar(sse, bounds=(c0 - 1.0, c0 + 1.0), method="bounded")
            ls = math.exp(best.x)
            to_ls = room["capacity_means"]
            scale = 1.0 if room_type == "attic" else room["wall_psat"]  # Cw = Cm / p_sat
            lo, hi = room["phi_w_range"]
            lines.append(
                f"{room_type} {rep}: RH {lo:.2f}-{hi:.2f}; "
                f"{to_ls['harmonic'] / scale / ls:.3f}, {to_ls['arithmetic'] / scale / ls:.3f}; "
                f"{math.sqrt(best.fun / target.size):.1f}"
            )
    return lines


# --------------------------------------------------------------------------- tables
def fit_of(r: dict) -> dict:
    """The fit of a replicate (its variant's entry; logs before ``--variant``:
    :data:`VARIANT`)."""
    return r["variants"][r.get("variant", VARIANT)]


def read_logs(paths) -> list[dict]:
    """Replicates of one or more logs; a (room, replicate, without) found twice must
    agree (a replicate is a function of its seed)."""
    merged: dict[tuple, dict] = {}
    for path in paths:
        with open(path) as f:
            for line in f:
                if not line.strip():
                    continue
                r = json.loads(line)
                key = (r["room"], r["rep"], r["seed"], tuple(r["without"]), r.get("variant"))
                if key in merged and merged[key]["truth"] != r["truth"]:
                    raise SystemExit(f"{path}: replicate {key} differs from an earlier log's")
                merged[key] = r
    return [merged[k] for k in sorted(merged)]


def coverage_interval(k: int, n: int, level: float = 0.95) -> tuple[float, float]:
    """Clopper-Pearson interval of a binomial proportion ``k / n``."""
    a = 1.0 - level
    lo = stats.beta.ppf(a / 2, k, n - k + 1) if k > 0 else 0.0
    hi = stats.beta.ppf(1 - a / 2, k + 1, n - k) if k < n else 1.0
    return float(lo), float(hi)


def summary(results: list[dict], room: str, quantity: str) -> dict | None:
    """Coverage of one quantity over the rooms: ``n``, ``in90`` (count), ``c90`` and its
    95 % Clopper-Pearson interval, ``c50``, mean and sd of z = (median - truth)/sd,
    the rank χ² p (10 bins, 20 rooms or more), and ``width``: the median posterior sd
    of log(quantity) over the sd of log(truth) across the rooms (≪ 1: the data, not
    the spread of the truths, set the interval)."""
    v = [
        (fit_of(r)["ranks"][quantity], r["truth"][quantity])
        for r in results
        if r["room"] == room and quantity in fit_of(r)["ranks"]
    ]
    if not v:
        return None
    n = len(v)
    k90 = sum(x["in90"] for x, _ in v)
    z = np.array([(x["median"] - t) / x["sd"] for x, t in v if x["sd"] > 0])
    counts = np.histogram([x["rank"] for x, _ in v], bins=10, range=(0, 1))[0]
    truths = np.array([t for _, t in v])
    spread = np.std(np.log(truths)) if np.all(truths > 0) and n > 2 else np.nan
    rel_sd = np.median([x["sd"] / abs(x["median"]) for x, _ in v])
    return {
        "n": n,
        "in90": int(k90),
        "c90": k90 / n,
        "c90_ci": coverage_interval(k90, n),
        "c50": float(np.mean([x["in50"] for x, _ in v])),
        "z_mean": float(z.mean()) if z.size else np.nan,
        "z_sd": float(z.std(ddof=1)) if z.size > 1 else np.nan,
        "rank_p": float(stats.chisquare(counts).pvalue) if n >= 20 else np.nan,
        "width": float(rel_sd / spread) if spread > 0 else np.nan,
    }


def verdict(s: dict, lo: float = 0.85, hi: float = 0.95) -> str:
    """``met`` when the 90 % coverage lies in ``[lo, hi]``; else ``low`` or ``high``,
    with ``(within noise)`` when the binomial 95 % interval still reaches the range."""
    c, (a, b) = s["c90"], s["c90_ci"]
    if lo <= c <= hi:
        return "met"
    side = "low" if c < lo else "high"
    reach = b >= lo if side == "low" else a <= hi
    return f"{side} (within noise)" if reach else side


def table_lines(results: list[dict], markdown: bool = False) -> list[str]:
    """The coverage table: per room type and quantity (identifiable first)."""
    head = (
        "| room → model (rooms, converged) | quantity | 90 % coverage (95 % CI) | verdict "
        "| 50 % | mean z / sd z | rank χ² p | width |"
    )
    lines = [head, "|---|---|---|---|---|---|---|---|"] if markdown else []
    for room in rooms.ROOMS:
        rs = [r for r in results if r["room"] == room]
        if not rs:
            continue
        conv = sum(fit_of(r)["converged"] for r in rs)
        cpu = np.mean([fit_of(r)["cpu"] for r in rs])
        label = f"{room} → {MODELS[room][0]} ({len(rs)}, {conv})"
        if not markdown:
            mis = np.median([r["misfit_Pa"]["sd"] for r in rs])
            lines.append(f"{label}: {cpu:.0f} s CPU per fit; structural misfit sd {mis:.1f} Pa")
        for q in IDENTIFIABLE[room] + PATH + OTHERS[room] + GAB_ONLY:
            s = summary(rs, room, q)
            if s is None:
                continue
            tag = "" if q in IDENTIFIABLE[room] + PATH else " (not identifiable)"
            ci = f"{s['c90']:.2f} ({s['c90_ci'][0]:.2f}-{s['c90_ci'][1]:.2f})"
            p = "—" if not np.isfinite(s["rank_p"]) else f"{s['rank_p']:.3f}"
            zz = f"{s['z_mean']:+.2f} / {s['z_sd']:.2f}"
            if markdown:
                lines.append(
                    f"| {label} | {q}{tag} | {ci} | {verdict(s)} | {s['c50']:.2f} | {zz} "
                    f"| {p} | {s['width']:.2f} |"
                )
                label = ""
            else:
                lines.append(
                    f"  {q + tag:34s} n {s['n']:3d}  90 %: {ci}  {verdict(s):18s} 50 %: "
                    f"{s['c50']:.2f}  z {zz}  rank p {p}  width {s['width']:.2f}"
                )
    return lines


def mean_lines(results: list[dict]) -> list[str]:
    """``--means``: per room type and quantity, the mean z = (posterior median -
    truth)/posterior sd with the capacity's truth the harmonic mean of the isotherm's
    slope (the logs' truth) and with it the arithmetic mean (``capacity_means``; the
    other truths unchanged): what the choice of the truth moves."""
    lines = []
    for room in rooms.ROOMS:
        rs = [r for r in results if r["room"] == room and "capacity_means" in r]
        if not rs:
            continue
        lines.append(f"{room}: {len(rs)} rooms, mean z with the harmonic / arithmetic mean")
        cap = "Cm" if room == "attic" else "Cw"
        for q in IDENTIFIABLE[room] + OTHERS[room]:
            z = []
            for r in rs:
                x = fit_of(r)["ranks"].get(q)
                if x is None:
                    continue
                m = r["capacity_means"]
                arith = dict(r["truth_parameters"])
                arith[cap] *= m["arithmetic"] / m["harmonic"]
                # the quantities of the capacity (the sink's pull, the gain, φ_f and the
                # buffer share do not involve it; the ground's mean only enters the pull)
                t_a = r["truth"][q]
                if q in ("tau1_h", "tau2_h", "buffer_hours", "Cm"):
                    t_a = float(rooms.network_quantities(room, arith, 10.0)[q])
                z.append(((x["median"] - r["truth"][q]) / x["sd"], (x["median"] - t_a) / x["sd"]))
            if z:
                za, zb = np.mean(z, axis=0)
                lines.append(f"  {q:14s} {za:+.2f} / {zb:+.2f}")
    return lines


def paired_lines(a: list[dict], b: list[dict]) -> list[str]:
    """Two logs of the same rooms (e.g. every part, and ``--without outage``): per room
    type and quantity over the replicates in both, mean z in each, the mean and sd of
    z_a - z_b (z = (posterior median - truth)/posterior sd) and the 90 % coverage in
    each: what the part left out moves, in the posterior's own sd."""
    lines = []
    for room in rooms.ROOMS:
        ra = {r["rep"]: r for r in a if r["room"] == room}
        rb = {r["rep"]: r for r in b if r["room"] == room}
        reps = sorted(set(ra) & set(rb))
        if not reps:
            continue
        lines.append(f"{room}: {len(reps)} rooms in both (replicates {reps})")
        for q in IDENTIFIABLE[room] + PATH + OTHERS[room] + GAB_ONLY:
            za, zb, ia, ib = [], [], 0, 0
            for r in reps:
                xa = fit_of(ra[r])["ranks"].get(q)
                xb = fit_of(rb[r])["ranks"].get(q)
                if xa is None or xb is None:
                    continue
                za.append((xa["median"] - ra[r]["truth"][q]) / xa["sd"])
                zb.append((xb["median"] - rb[r]["truth"][q]) / xb["sd"])
                ia, ib = ia + xa["in90"], ib + xb["in90"]
            if not za:  # ranked in neither log (e.g. the --path quantities)
                continue
            d = np.subtract(za, zb)
            sd = f"{d.std(ddof=1):.2f}" if d.size > 1 else "—"
            lines.append(
                f"  {q:14s} mean z {np.mean(za):+.2f} / {np.mean(zb):+.2f}; z_a - z_b mean "
                f"{d.mean():+.2f}, sd {sd}; in 90 %: {ia} / {ib} of {d.size}"
            )
    return lines


def path_log(log: str, draws: str, out: str) -> int:
    """``--path``: the replicates of ``log`` (cellars fitted with ``--isotherm gab
    --draws``) with the ranks of :data:`PATH` added from their saved draws, written to
    ``out`` (:mod:`coupled_path`)."""
    from coupled_path import path_ranks

    if not (draws and out):
        raise SystemExit("--path needs --draws DIR (the fit's draws) and --log OUT")
    with open(out, "a") as f:
        for r in read_logs([log]):
            tag = "-".join([r["room"], str(r["rep"]), *r["without"], r["variant"], r["isotherm"]])
            theta = np.load(Path(draws) / f"{tag.replace(':', '_')}.npy")
            ranks, truths = path_ranks(r, theta, fit_inputs, MODELS)
            fit_of(r)["ranks"].update(ranks)
            r["truth"].update(truths)
            f.write(json.dumps(r) + "\n")
            zs = ", ".join(
                f"{q} z {(x['median'] - truths[q]) / x['sd']:+.2f}" for q, x in ranks.items()
            )
            print(f"cellar {r['rep']}: {zs}", flush=True)
    return 0


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--reps", type=int, default=40)
    ap.add_argument("--first-rep", type=int, default=0)
    ap.add_argument("--only", help="comma-separated replicates (instead of --first-rep "
                    "and --reps): e.g. the rooms a change of the fit path reaches")  # fmt: skip
    ap.add_argument("--rooms", default=",".join(rooms.ROOMS))
    ap.add_argument("--jobs", type=int, default=1)
    ap.add_argument("--seed", type=int, default=SEED)
    ap.add_argument("--max-steps", type=int, default=4000)
    ap.add_argument("--cal-days", type=int, default=CAL_DAYS)
    ap.add_argument("--variant", default=VARIANT, help="the fit: NOISE:INIT[:T=X] "
                    "(bench_sbc.fit_and_rank; T=X a likelihood tempered by X; "
                    "kalman:estimate: the Kalman filter over the linear wall's "
                    "transitions, process noise at the nodes)")  # fmt: skip
    ap.add_argument("--log", help="append each replicate's result as a JSON line")
    ap.add_argument("--draws", help="a directory: save each replicate's posterior draws "
                    "(model then noise parameters, .npy) for --path")  # fmt: skip
    ap.add_argument("--shape", action="store_true", help="no fit: the fit's GAB slope "
                    "(C fixed) against the generator's (shape_lines)")  # fmt: skip
    ap.add_argument("--isotherm", default="linear", choices=ISOTHERMS, help="the fitted "
                    "buffer's isotherm (the models' option; gab: K_gab estimated)")  # fmt: skip
    ap.add_argument("--without", default="", help="parts of the generator left out: "
                    "isotherm, source, noise, outage (coupled_rooms.generate)")  # fmt: skip
    ap.add_argument("--table", nargs="+", metavar="LOG", help="only tabulate logs")
    ap.add_argument("--markdown", action="store_true", help="with --table: markdown")
    ap.add_argument("--paired", nargs=2, metavar="LOG", help="two logs of the same rooms: "
                    "what a part left out moves (paired_lines)")  # fmt: skip
    ap.add_argument("--path", metavar="LOG", help="with --draws and --log: rank the "
                    "cellar's slow quantities along each draw's wall (coupled_path)")  # fmt: skip
    ap.add_argument("--start", action="store_true", help="no fit: the GAB wall's start "
                    "and log L at the truth, linearised once and twice (coupled_path)")  # fmt: skip
    ap.add_argument("--source-seeds", metavar="S,S", help="no posterior: the MAP of "
                    "cellars --only/--first-rep.. under other realisations of their moisture "
                    "source ('own': the room's own; coupled_path.source_lines)")  # fmt: skip
    ap.add_argument("--misfit", action="store_true", help="no fit: the structural error "
                    "of rooms --first-rep.. with each part of the generator left out")  # fmt: skip
    ap.add_argument("--means", nargs="+", metavar="LOG", help="mean z with the "
                    "capacity's harmonic and arithmetic truth (mean_lines)")  # fmt: skip
    ap.add_argument("--capacity", action="store_true", help="no fit: the isotherm's "
                    "harmonic and arithmetic mean slope against the least-squares "
                    "capacity of rooms --first-rep.. (capacity_lines)")  # fmt: skip
    args = ap.parse_args(argv)
    without = tuple(w for w in args.without.split(",") if w)
    bad = set(without) - {"isotherm", "source", "noise", "outage"}
    if bad:
        ap.error(f"--without: unknown {sorted(bad)}")
    room_types = [r for r in args.rooms.split(",") if r]
    if set(room_types) - set(rooms.ROOMS):
        ap.error(f"--rooms: expected some of {list(rooms.ROOMS)}")
    if args.paired:
        for line in paired_lines(*(read_logs([p]) for p in args.paired)):
            print(line)
        return 0
    if args.table:
        results = read_logs(args.table)
        print(f"SBC of the coupled models, {' '.join(args.table)}: {len(results)} rooms")
        for line in table_lines(results, args.markdown):
            print(line)
        return 0
    if args.path:
        return path_log(args.path, args.draws, args.log)
    if args.start:
        from coupled_path import start_lines

        reps = range(args.first_rep, args.first_rep + args.reps)
        reps = [int(r) for r in args.only.split(",")] if args.only else reps
        for line in start_lines(reps, args.seed, args.cal_days, fit_inputs, MODELS, gab_truth):
            print(line, flush=True)
        return 0
    if args.source_seeds:
        from coupled_path import source_lines

        reps = range(args.first_rep, args.first_rep + args.reps)
        reps = [int(r) for r in args.only.split(",")] if args.only else reps
        seeds = [None if s == "own" else int(s) for s in args.source_seeds.split(",")]
        for line in source_lines(reps, seeds, args.seed, args.cal_days, fit_inputs, MODELS,
                                 gab_truth, without):  # fmt: skip
            print(line, flush=True)
        return 0
    if args.means:
        for line in mean_lines(read_logs(args.means)):
            print(line)
        return 0
    if args.shape:
        for line in shape_lines():
            print(line)
        return 0
    if args.capacity:
        reps = range(args.first_rep, args.first_rep + args.reps)
        for line in capacity_lines(room_types, reps, args.seed, args.cal_days):
            print(line, flush=True)
        return 0
    if args.misfit:
        reps = range(args.first_rep, args.first_rep + args.reps)
        reps = [int(r) for r in args.only.split(",")] if args.only else reps
        for line in misfit_lines(room_types, reps, args.seed, args.cal_days):
            print(line, flush=True)
        return 0
    from bench_sbc import run_tasks

    reps = range(args.first_rep, args.first_rep + args.reps)
    if args.only:
        reps = [int(r) for r in args.only.split(",")]

    tasks = [
        (
            room,
            rep,
            args.seed,
            args.max_steps,
            args.cal_days,
            without,
            {},
            args.variant,
            args.isotherm,
            args.draws,
        )
        for rep in reps
        for room in room_types
    ]
    t0 = time.perf_counter()
    results = run_tasks(replicate, tasks, args.jobs, args.log)
    print(
        f"SBC of the coupled models: {len(results)} rooms, {time.perf_counter() - t0:.0f} s "
        f"wall, load average {os.getloadavg()[0]:.1f}"
    )
    for line in table_lines(results):
        print(line)
    return 0


if __name__ == "__main__":
    sys.exit(main())
