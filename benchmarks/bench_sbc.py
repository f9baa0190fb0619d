"""Simulation-based calibration: do the 50 % and 90 % intervals cover the truth?

Rooms shaped like real logs, generated *outside* the package's simulator: each replicate
draws true parameters (a slow time constant of 2-3 weeks, thick masonry), simulates the
room with scipy's matrix exponential (exact ZOH of the continuous state space, an
implementation independent of the package's modal recursion) from a start far from the
package's assumptions (the steady state of the first day, then a random spin-up of 1-8
weeks before the calibration starts), driven by real De Bilt weather (KNMI hourly,
``../shared/data/knmi-debilt``), and observes it like a logger: AR(1) model error (phi
0.90-0.95, sd 0.15-0.30 K or 15-30 Pa) + white sensor noise + rounding to 0.1 + a
one-week gap; 3 months hourly of calibration. Each replicate is then calibrated through
the package's inference path with the defaults ``hbayes calibrate`` uses (priors from a
room volume and air change rate, MAP warm start, emcee until converged or
``--max-steps``, whichever comes first: the table counts the converged fits) and the
coverage of central intervals and the rank of the truth among the posterior draws are
recorded for the slow time constant tau_1, the static gains and (hygric_2c_fixed) the
fixed node's vapour pressure Pf.

The rank statistic: the truth's rank among L posterior draws, uniform on 0..L if the
posterior is calibrated; reported as a chi-square test on 10 bins (p-value).

    python benchmarks/bench_sbc.py --reps 50 --jobs 2
    python benchmarks/bench_sbc.py --reps 10 --models thermal_2c --noise ar1:steady
    python benchmarks/bench_sbc.py --room 64 --reps 24 --models thermal_2c \
        --noise ar1_white:estimate --without rounding,gap --jobs 2
    python benchmarks/bench_sbc.py --reps 50 --models thermal_2c \
        --noise ar1_white:estimate --solar facade --log facade.jsonl

``--solar facade`` feeds the thermal rooms the south-facade irradiance ``hbayes
calibrate`` computes from the hourly station record (Erbs + Perez, :func:`facade_south`)
as I_S instead of the global horizontal irradiance; the rooms are otherwise the same
(truths, weather stretch, start, noise, gap), and the generator and the fit share the
input either way.

``--noise NAME:INIT`` pairs a noise model with an initial state (``estimate`` or
``steady``; ``steady`` adds the old 14-day warm-up). Default: the new default
(``ar1_white:estimate``) and the old one (``ar1:steady``), compared in one run.
"""

from __future__ import annotations

import argparse
import json
import os
import time
from concurrent.futures import ProcessPoolExecutor
from pathlib import Path

os.environ.setdefault("OPENBLAS_NUM_THREADS", "1")
os.environ.setdefault("OMP_NUM_THREADS", "1")

import numpy as np
from scipy import stats
from scipy.linalg import expm

SHARED = Path(__file__).resolve().parents[2] / "shared" / "data"
KNMI = SHARED / "knmi-debilt" / "uurgeg_260_2011-2020.txt.gz"
VOLUME, ACH = 400.0, 0.5  # [m³], [1/h]: the prior knowledge given to every replicate
FLOOR = 80.0  # [m²]: the floor of a 400 m³ hall 5 m high (the demo's room)
ENVELOPE = 259.0  # [m²]: its walls (8.9 m square, 5 m high) and roof
CAL_DAYS, MAX_SPIN_DAYS = 90, 56
DT = 3600.0


#: ``--solar`` choices: the solar input I_S of the thermal rooms
SOLAR = ("ghi", "facade")
#: De Bilt, KNMI station 260 [°N, °E, m] (as bench_sbc_independent.SITE)
SITE = {"latitude": 52.10, "longitude": 5.18, "altitude": 1.9}


def weather(seed: int, solar: str = "ghi", cal_days: int = CAL_DAYS) -> dict[str, np.ndarray]:
    """A random stretch of De Bilt hourly weather: Te [°C], Pe [Pa], south irradiance
    [W/m²], long enough for the spin-up and ``cal_days`` of calibration. ``solar``: ``"ghi"`` (the
    global horizontal irradiance as a proxy, as recorded: the mean of the hour ending at
    the row's time) or ``"facade"`` (:func:`facade_south` of the same stretch: the mean
    over the row's hour, as ``hbayes calibrate`` aligns it)."""
    from heritage_bayes.climate.psychro import vapour_pressure

    w = _knmi_cache()
    n = (cal_days + MAX_SPIN_DAYS + 1) * 24
    rng = np.random.default_rng(seed)
    start = int(rng.integers(0, len(w) - n))
    part = w.iloc[start : start + n]
    te = part["Te"].interpolate(limit_direction="both").to_numpy(float)
    rh = part["RHe"].interpolate(limit_direction="both").to_numpy(float)
    ghi = part["ghi"].interpolate(limit_direction="both").to_numpy(float)
    if solar == "facade":  # one more hour: the mean over the last row's hour
        ghi = facade_south(w.iloc[start : start + n + 1][["Te", "ghi"]])[:n]
    elif solar != "ghi":
        raise ValueError(f"solar must be one of {SOLAR} (got {solar!r})")
    return {"Te": te, "Pe": vapour_pressure(te, rh), "I_S": ghi}


def facade_south(hourly) -> np.ndarray:
    """The south facade's irradiance [W/m²] that ``hbayes calibrate`` builds from an
    hourly station record (``ghi`` hour-ending means; gaps interpolated): transposed by
    :func:`heritage_bayes.inputs.solar_inputs` (Erbs + Perez at mid-hour) and aligned
    by :func:`heritage_bayes.io.align` on 1 h, as ``bench_sbc_independent.fit_inputs``
    does. Row k is the mean over the hour from ``hourly``'s k-th time: one row fewer."""
    from heritage_bayes.inputs import solar_inputs
    from heritage_bayes.io.align import align

    h = hourly.interpolate(limit_direction="both")
    g = h[["ghi"]].copy()
    g.attrs.update(averaged=("ghi",), interval="1h", source="station")
    irr = solar_inputs(g, SITE, {"S": (90.0, 180.0)}, "measured")[0]
    met = h[["Te"]].copy()
    met.attrs.update(averaged=(), interval="1h", source="station")
    frame = align([met, irr], step="1h", max_gap="0h").frame
    assert frame.index[0] == h.index[0] and len(frame) == len(h) - 1
    return frame["I_S"].to_numpy(float)


_W = None


def _knmi_cache():
    global _W
    if _W is None:
        from heritage_bayes.io.readers.knmi import read_knmi_hourly

        _W = read_knmi_hourly(KNMI, invalid="nan")
    return _W


def _solve_capacity(A_of_cw, target_tau_h: float) -> float:
    """Envelope capacity Cw [J/K or kg/Pa] giving a slowest time constant ``target``."""
    lo, hi = 1e-12, 1e15
    for _ in range(200):
        mid = np.sqrt(lo * hi)
        lam = -np.linalg.eigvals(A_of_cw(mid)).real
        tau = 1.0 / lam.min() / 3600.0
        lo, hi = (mid, hi) if tau < target_tau_h else (lo, mid)
        if hi / lo < 1 + 1e-9:
            break
    return float(np.sqrt(lo * hi))


#: The hygric truths' log-uniform ranges [kg/(s·Pa)] (:func:`truth`; ``Gf`` without a
#: floor area only): :func:`truth_priors` gives the fit these very distributions. The
#: fixed node's ``Pf`` and (with a floor area) ``Gf`` are drawn from the fit's default
#: priors (:func:`~heritage_bayes.inference.survey.fixed_vapour_pressure_prior`,
#: :func:`~heritage_bayes.inference.survey.vapour_ground_prior`).
HYGRIC_TRUTH = {"Gw": (5e-9, 5e-8), "Gi": (3e-7, 3e-6), "Gf": (2e-8, 2e-7)}
#: log-uniform ranges of the thermal truths [W/K], [W/K], [W/K] (Gf: without a floor
#: area), [m²]
THERMAL_TRUTH = {"Gw": (80.0, 400.0), "Gi": (300.0, 2000.0), "Gf": (5.0, 40.0), "fI_S": (1.0, 6.0)}
#: sd of log(Ci) and log(Gfast) of the truths around the volume's priors' medians
TRUTH_SIGMA = 0.5
#: ``--flat-fixed-node``: the study before the node's physical priors: truths of Pf
#: uniform on this range [Pa] (Gf log-uniform on ``HYGRIC_TRUTH``), fitted with the
#: former default priors of the node, :data:`FLAT_NODE_PRIORS`
PF_FLAT = (900.0, 1400.0)
FLAT_NODE_PRIORS = {
    "Pf": {"dist": "uniform", "lower": 0.0, "upper": 5000.0},
    "Gf": {"dist": "loguniform", "lower": 1e-12, "upper": 1e-3},
}


def ground_temperature() -> float:
    """De Bilt's mean outdoor temperature over the KNMI record [°C] (10.9 °C over
    2011-2020): the temperature behind the hygric fixed node of every room, in its
    truth's ``Pf`` and in the fit's prior, as ``data.ground_temperature: annual_mean``
    gives ``hbayes calibrate`` (a running annual mean, within the years' ± 0.6 K)."""
    return float(np.nanmean(_knmi_cache()["Te"].to_numpy(float)))


def truth_priors(
    model, floor_area: float | None = None, flat_node: bool = False, cw_range=None
) -> dict[str, dict]:
    """Prior specs equal to the distributions :func:`truth` draws a model's parameters
    from (``Cw`` excepted unless ``cw_range`` (lo, hi) [J/K or kg/Pa] draws it too: it is
    otherwise solved for a slow time constant of 2-3 weeks, and keeps the fit's default
    prior). SBC is exact only when the truths are drawn from the prior the fit uses:
    ``--truth-priors`` measures what is left of a bias once the prior and the truth
    distribution agree."""
    from heritage_bayes.inference.survey import (
        air_capacity_prior,
        ground_prior,
        ventilation_prior,
    )

    dom = model.domain
    ranges = HYGRIC_TRUTH if dom == "hygric" else THERMAL_TRUTH
    drawn = ("Gw", "Gi", "fI_S") if floor_area and not flat_node else ("Gw", "Gi", "Gf", "fI_S")
    out = {
        k: {"dist": "loguniform", "lower": lo, "upper": hi}
        for k, (lo, hi) in ranges.items()
        if k in model.parameter_names and k in drawn
    }
    if dom == "thermal" and floor_area and "Gf" in model.parameter_names:
        out["Gf"] = {"dist": "lognormal", "median": ground_prior(floor_area).mu, "sigma": 0.5}
    for name, prior in (
        ("Ci", air_capacity_prior(dom, VOLUME)),
        ("Gfast", ventilation_prior(dom, VOLUME, ACH)),
    ):
        out[name] = {"dist": "lognormal", "median": prior.mu, "sigma": TRUTH_SIGMA}
    if flat_node and "Pf" in model.parameter_names:
        out["Pf"] = {"dist": "uniform", "lower": PF_FLAT[0], "upper": PF_FLAT[1]}
    if cw_range is not None:
        out["Cw"] = {"dist": "loguniform", "lower": cw_range[0], "upper": cw_range[1]}
    return out


def truth(
    model, rng, floor_area: float | None = None, flat_node: bool = False, cw_range=None
) -> dict[str, float]:
    """True parameters: air capacity and ventilation near the prior knowledge, the rest
    log-uniform, and the envelope capacity set for a slow tau of 2-3 weeks. With
    ``floor_area`` [m²] the ground coupling Gf too is drawn near the prior knowledge
    (its median times exp(N(0, 0.5)), like Ci and Gfast); without, log-uniform on
    5-40 W/K (the study before the floor-area prior). A hygric fixed node's Pf and Gf
    from the fit's physical priors (Gf's with ``floor_area``), or with ``flat_node``
    from the ranges of the study before them (:data:`PF_FLAT`, ``HYGRIC_TRUTH``)."""
    from heritage_bayes.inference.survey import (
        air_capacity_prior,
        fixed_vapour_pressure_prior,
        ground_prior,
        vapour_ground_prior,
        ventilation_prior,
    )

    dom = model.domain
    ci, gf = air_capacity_prior(dom, VOLUME), ventilation_prior(dom, VOLUME, ACH)
    p = {
        "Ci": ci.mu * np.exp(rng.normal(0, TRUTH_SIGMA)),
        "Gfast": gf.mu * np.exp(rng.normal(0, TRUTH_SIGMA)),
    }
    if dom == "thermal":
        p.update(
            **{k: float(np.exp(rng.uniform(*np.log(THERMAL_TRUTH[k])))) for k in THERMAL_TRUTH}
        )
    else:
        for k in ("Gw", "Gi"):
            p[k] = float(np.exp(rng.uniform(*np.log(HYGRIC_TRUTH[k]))))
        if "Pf" in model.parameter_names:  # the fit's default priors, drawn from
            gf = vapour_ground_prior(floor_area) if floor_area and not flat_node else None
            p["Gf"] = float(
                gf.mu * np.exp(gf.sigma * rng.normal())
                if gf
                else np.exp(rng.uniform(*np.log(HYGRIC_TRUTH["Gf"])))
            )
            pf = fixed_vapour_pressure_prior(ground_temperature())
            p["Pf"] = float(
                rng.uniform(*PF_FLAT) if flat_node else pf.mu * np.exp(pf.sigma * rng.normal())
            )
    if floor_area and dom == "thermal":
        p["Gf"] = ground_prior(floor_area).mu * float(np.exp(rng.normal(0, 0.5)))
    target = rng.uniform(336, 504)

    def A_of(cw):
        q = {**p, "Cw": cw}
        return model.state_space({k: q[k] for k in model.parameter_names})[0]

    if cw_range is None:
        p["Cw"] = _solve_capacity(A_of, target)
    else:  # drawn like the others (the same stream: the rest of the room is unchanged)
        p["Cw"] = float(np.exp(rng.uniform(*np.log(cw_range))))
    return {k: float(p[k]) for k in model.parameter_names}


def simulate_reference(model, params, U: np.ndarray, dt: float = DT, x0=None) -> np.ndarray:
    """Exact ZOH simulation with scipy.linalg.expm (block-matrix form), steps of ``dt``
    [s], from ``x0`` or else the steady state of the first 24 rows' mean inputs: all
    node potentials at the start of every step (N, n)."""
    A, B, _, _ = model.state_space(params)
    e = model.offset(params)
    n, m = B.shape
    Mx = np.zeros((n + m + 1, n + m + 1))
    Mx[:n, :n], Mx[:n, n : n + m], Mx[:n, -1] = A, B, e
    E = expm(Mx * dt)
    Ad, Bd, ed = E[:n, :n], E[:n, n : n + m], E[:n, -1]
    x = np.linalg.solve(-A, B @ U[:24].mean(axis=0) + e) if x0 is None else x0
    W = U @ Bd.T + ed
    X = np.empty((U.shape[0], n))
    for k in range(U.shape[0]):
        X[k] = x
        x = Ad @ x + W[k]
    return X


def replicate(args) -> dict:
    """One room: generate, calibrate, and rank the truth of each quantity."""
    room = room_data(args)
    model, rows, y, result = room["model"], room["rows"], room["y"], room["result"]
    variants, max_steps = args[2], args[4]
    priors = args[6] if len(args) > 6 else {}
    floor = args[7] if len(args) > 7 else None
    envelope = args[9] if len(args) > 9 else None
    tau_factor = args[12] if len(args) > 12 else 50.0
    result["variants"] = fit_and_rank(
        model,
        room["U"][rows],
        y,
        result["truth"],
        variants,
        args[1],
        max_steps,
        priors,
        floor,
        envelope,
        tau_factor=tau_factor,
    )
    return result


def room_data(args) -> dict:
    """One replicate's room as :func:`replicate` generates it (``args``: its task):
    ``model``, the inputs ``U`` (all rows, spin-up included), the calibration ``rows``,
    the observations ``y`` (N,) of those rows (NaN: the gap) and the log line's
    ``result`` so far (truths, noise truths)."""
    import heritage_bayes as hb
    from heritage_bayes.rc.derived import derived_quantities

    name, rep, variants, seed, max_steps = args[:5]
    cal_days = args[5] if len(args) > 5 else CAL_DAYS
    floor = args[7] if len(args) > 7 else None
    # (noise draw, components left out): the same room, weather and start with fresh
    # observation noise (see repeat_room); None: the study's own draw, every component
    redraw, without = args[8] if len(args) > 8 else (None, ())
    flat_node = args[10] if len(args) > 10 else False
    solar = args[11] if len(args) > 11 else "ghi"
    rng = np.random.default_rng([seed, rep])
    opts = {"surfaces": ("S",)} if name in ("thermal_2c", "thermal_4a") else {}
    model = hb.model(name, **opts)
    p = truth(model, rng, floor, flat_node, args[13] if len(args) > 13 else None)
    w = weather(int(rng.integers(2**31)), solar if "I_S" in model.input_names else "ghi", cal_days)
    U = np.column_stack(
        [w[c] if c in w else np.full(len(w["Te"]), 10.0) for c in model.input_names]
    )
    if "Tf" in model.input_names:  # ground: the mean outdoor temperature, constant
        U[:, model.input_names.index("Tf")] = w["Te"].mean()
    X = simulate_reference(model, p, U)
    out = model.output_names[0]
    y_true = X[:, model.state_names.index(out)]
    spin = int(rng.integers(7, MAX_SPIN_DAYS + 1)) * 24
    rows = slice(spin, spin + cal_days * 24)
    thermal = model.domain == "thermal"
    phi = rng.uniform(0.90, 0.95)
    sd = rng.uniform(0.15, 0.30) * (1.0 if thermal else 100.0)
    nr = rng if redraw is None else np.random.default_rng([seed, rep, 1 + redraw])
    e = np.empty(y_true.size)
    e[0] = nr.normal(0, sd)
    z = nr.normal(0, sd * np.sqrt(1 - phi**2), y_true.size)
    for k in range(1, e.size):
        e[k] = phi * e[k - 1] + z[k]
    if "model_error" in without:
        e[:] = 0.0
    sensor = 0.1 if thermal else 12.0  # [K]; [Pa] ~ 1 %RH at 10 °C
    y = y_true + e + nr.normal(0, sensor, e.size)
    y = (y if "rounding" in without else np.round(y, 1))[rows]
    g0 = int(nr.integers(7 * 24, cal_days * 24 - 14 * 24))
    if "gap" not in without:
        y[g0 : g0 + 7 * 24] = np.nan
    dq_true = {k: float(np.ravel(v)[0]) for k, v in derived_quantities(model, p).items()}
    result = {"model": name, "rep": rep, "truth": dq_true, "truth_parameters": p}
    # the observation model's truths: AR(1) model error (marginal sd), sensor's sd
    result["noise_truth"] = {"phi": float(phi), "sd": float(sd), "sensor": sensor}
    if "I_S" in model.input_names:
        result["solar"] = solar
    return {"model": model, "U": U, "rows": rows, "y": y, "result": result}


def log_posterior(model, noise, U, y, priors, floor, envelope, init: str):
    """The parameter set and log-posterior a replicate is fitted with: ``hbayes
    calibrate``'s defaults (survey priors from the room's volume, air change rate, floor
    and envelope areas; the soft cap on time constants) with ``priors`` (those of the
    model's and the noise's parameters) over them, ``init`` the initial state
    (``estimate`` or ``steady``, the latter with a 14-day warm-up)."""
    from heritage_bayes.config import ModelSection, prior_specs
    from heritage_bayes.inference.parameters import parameters_for
    from heritage_bayes.inference.posterior import LogPosterior

    # the model's parameters and (bench_sbc_independent --noise-free) the noise's
    names = set(model.parameter_names) | {
        n for n, *_ in noise.parameter_specs(model.output_names, model.state_names)
    }
    ps = parameters_for(
        model,
        noise,
        prior_specs({k: v for k, v in priors.items() if k in names}),
        room_volume=VOLUME,
        air_change_rate=ACH,
        floor_area=floor,
        envelope_area=envelope,
        fixed_node_temperature=ground_temperature() if "Pf" in model.parameter_names else None,
    )
    lp = LogPosterior(
        model,
        ps,
        noise,
        U,
        y[:, None],
        warmup=336 if init == "steady" else 0,
        init_window=720,
        initial_state=init,
        time_constant_cap=ModelSection(model=model.name).cap_seconds(model.domain),
    )
    return ps, lp


def slow_time_constant_prior(lp, median_s: float, sigma: float) -> None:
    """Add to ``lp`` a log-normal prior on the slowest time constant τ1 [s] (median
    ``median_s``, sd of log ``sigma``), on top of its soft cap (``--variant
    NOISE:INIT:tau1=MEDIAN_H/SIGMA``, issue 31's study of a prior a building physicist
    can state on the slow direction)."""
    base = lp.time_constant_log_prior

    def with_slow(theta_model, _base=base, _lp=lp):
        out = _base(theta_model)
        with np.errstate(all="ignore"):
            z = (np.log(1.0 / _lp.decay_rates(theta_model)[:, 0]) - np.log(median_s)) / sigma
        return np.where(np.isfinite(z), out - 0.5 * z * z, -np.inf)

    lp.time_constant_log_prior = with_slow


def default_section(model):
    """The config section ``hbayes calibrate`` reads for a catalogue ``model`` with its
    network options and nothing else set (``--variant default:INIT``: the package's
    default noise model and likelihood temperature for it)."""
    from heritage_bayes.config import ModelSection

    options = {"sink": getattr(model, "sink", "none"), "isotherm": model.isotherm}
    options = {k: v for k, v in options.items() if v not in (None, "none")}
    return ModelSection(model=model.name, options=options)


def default_noise(model) -> tuple[str, list[float]]:
    """``hbayes calibrate``'s noise model and likelihood temperature (as ``[T]``) for
    ``model`` (:func:`default_section`)."""
    from heritage_bayes.calibration.ladder import section_temperature

    section = default_section(model)
    return section.noise, [section_temperature(section, model)]


def idle_link_fixed(lp, mp, priors, fit):
    """``hbayes calibrate``'s rule at the MAP ``mp`` (``calibration.wall``): ``(lp, mp,
    finding)``, the log-posterior and MAP with an idle buffer link fixed at its floor
    where the rule fires (finding None, ``lp`` and ``mp`` as given, where not). ``fit``:
    ``(model, noise, U, y, floor, envelope, init)`` of :func:`log_posterior`."""
    from heritage_bayes.calibration.wall import decoupled_wall, fix_decoupled_wall
    from heritage_bayes.config import prior_specs

    if (wall := decoupled_wall(lp, mp.theta, priors)) is None:
        return lp, mp, None
    model, noise, U, y, floor, envelope, init = fit

    def rebuild(pr, _t=lp.temperature):
        lpw = log_posterior(model, noise, U, y, pr, floor, envelope, init)[1]
        lpw.temperature = _t
        return lpw

    lp, mp, _ = fix_decoupled_wall(wall, rebuild, prior_specs(priors), mp)
    return lp, mp, wall


def truth_ranks(dq: dict, dq_true: dict) -> dict:
    """Each true quantity against its posterior draws ``dq[name]``: inside the central
    50 % and 90 % intervals, its rank (the share of draws below it), the draws' median
    and sd. Quantities without draws, with a non-finite draw or with no spread are left
    out."""
    ranks = {}
    for k, t in dq_true.items():
        if k not in dq:
            continue
        d = np.asarray(dq[k], dtype=float).reshape(-1)
        if not np.all(np.isfinite(d)) or np.ptp(d) == 0:
            continue
        lo90, lo50, hi50, hi90 = np.quantile(d, [0.05, 0.25, 0.75, 0.95])
        ranks[k] = {
            "in50": bool(lo50 <= t <= hi50),
            "in90": bool(lo90 <= t <= hi90),
            "rank": float(np.mean(d < t)),
            "median": float(np.median(d)),
            "sd": float(np.std(d)),
        }
    return ranks


def posterior_summary(names, theta: np.ndarray, dq: dict) -> dict:
    """Every parameter's posterior median and sd (the noise's too) from the draws
    ``theta`` (draws, parameters), as ``posterior``, and the posterior correlation of the
    solar gain ``gain_Ti_I_S`` with each parameter, ``tau_1_h`` and ``gain_Ti_Te``
    (where the model has a solar gain), as ``corr_gain_Ti_I_S``."""
    post = {
        n: {"median": float(np.median(theta[:, j])), "sd": float(np.std(theta[:, j]))}
        for j, n in enumerate(names)
    }
    corr = {}
    if "gain_Ti_I_S" in dq:
        gs = np.asarray(dq["gain_Ti_I_S"], float).reshape(-1)
        others = {n: theta[:, j] for j, n in enumerate(names)}
        others.update({k: np.asarray(dq[k], float).reshape(-1) for k in ("tau_1_h", "gain_Ti_Te")})
        corr = {
            n: float(np.corrcoef(gs, x)[0, 1])
            for n, x in others.items()
            if np.ptp(x) > 0 and np.ptp(gs) > 0
        }
    return {"posterior": post, "corr_gain_Ti_I_S": corr}


def fit_and_rank(
    model,
    U,
    y,
    dq_true,
    variants,
    rep,
    max_steps,
    priors,
    floor,
    envelope,
    extra=None,
    tau_factor: float = 50.0,
) -> dict:
    """Calibrate one replicate with ``hbayes calibrate``'s defaults and rank the truths.

    The likelihood is untempered unless a variant says ``T=X`` (``hbayes calibrate``
    tempers thermal sections by 2 since commit ca9b55f: ``ar1_white:estimate:T=2`` is
    its default there), so the commands in the docs reproduce the tables they head.

    ``U`` (N, m) inputs and ``y`` (N,) observations (NaN = missing) of the calibration
    period; ``dq_true`` the true derived quantities; ``extra`` an optional function
    ``(dq, theta) -> {name: draws}`` of further quantities (their truths in
    ``dq_true``); ``tau_factor`` the convergence rule's chain length in τ (the
    package's 50; larger: a longer chain than the rule asks for, ``--tau-factor``).
    Returns ``{variant: {ranks, converged, map, steps, cpu}}``.
    """
    from heritage_bayes.inference.likelihoods import get_noise_model
    from heritage_bayes.inference.optimize import find_map
    from heritage_bayes.inference.sampler import run_sampler
    from heritage_bayes.rc.derived import derived_quantities

    out = {}
    for variant in variants:
        # NOISE:INIT[:OPTION...] (NOISE default: hbayes calibrate's, default_section),
        # temper=L (the likelihood tempered by the long-run
        # variance ratio of the MAP's innovations, Bartlett window of L hours), T=X (by a
        # fixed temperature X), tau1=MEDIAN_H/SIGMA (slow_time_constant_prior)
        noise_name, init, *opts = variant.split(":")
        temper = [o for o in opts if o.startswith("temper=")]
        slow = [o for o in opts if o.startswith("tau1=")]
        fixed_t = [float(o.removeprefix("T=")) for o in opts if o.startswith("T=")]
        t0 = time.process_time()
        calibrate = noise_name == "default"  # hbayes calibrate's noise, T and Gw rule
        if calibrate:
            noise_name, fixed_t = default_noise(model)
        noise = get_noise_model(noise_name)
        ps, lp = log_posterior(model, noise, U, y, priors, floor, envelope, init)
        if calibrate:  # the MAP of the tempered posterior, as in calibrate
            lp.temperature = fixed_t[0]
        if slow:  # NOISE:INIT:tau1=MEDIAN_H/SIGMA: a log-normal prior on the slowest τ
            median_h, sigma = map(float, slow[0].removeprefix("tau1=").split("/"))
            slow_time_constant_prior(lp, median_h * 3600.0, sigma)
        mp = find_map(lp, seed=rep, method="differential_evolution", popsize=15, maxiter=200)
        wall = None
        if calibrate:
            fit = (model, noise, U, y, floor, envelope, init)
            lp, mp, wall = idle_link_fixed(lp, mp, priors, fit)
            ps = lp.params
        kappas = {}
        if fixed_t:  # NOISE:INIT:T=2: log L divided by a fixed temperature
            lp.temperature = fixed_t[0]
        if temper:
            from heritage_bayes.inference.tempering import (
                innovations_at,
                likelihood_temperature,
                long_run_variance_ratio,
            )

            bandwidth = int(temper[0].removeprefix("temper="))
            w = innovations_at(lp, mp.theta)[:, 0]
            kappas = {str(b): long_run_variance_ratio(w, b) for b in (24, 72, 168, 336)}
            lp.temperature = likelihood_temperature(lp, mp.theta, bandwidth)
        chain = run_sampler(
            lp,
            mp.x,
            seed=rep,
            nwalkers=max(32, 2 * lp.ndim + 2),
            bounds=ps.bounds,
            max_steps=max_steps,
            tau_factor=tau_factor,
        )
        Xd, _ = chain.draws(4000)
        theta = ps.values(Xd.reshape(-1, Xd.shape[-1]))
        dq = derived_quantities(model, theta[:, : lp.n_model])
        if extra is not None:
            dq = {**dq, **extra(dq, theta)}
        out[variant] = {
            "ranks": truth_ranks(dq, dq_true),
            **posterior_summary(ps.names, theta, dq),
            "converged": bool(chain.converged),
            "map": dict(zip(ps.names, map(float, mp.theta), strict=True)),
            "steps": int(chain.steps),
            # integrated autocorrelation time [steps] per free parameter (sampler's coords)
            "tau": dict(
                zip([q.name for q in ps.parameters if q.free], map(float, chain.tau), strict=True)
            ),
            "cpu": time.process_time() - t0,
            "noise": noise.name,
            "temperature": float(lp.temperature),
            "decoupled_wall": wall and wall.to_dict(),
        }
        if temper:
            out[variant].update(temperature=lp.temperature, kappa_by_bandwidth=kappas)
    return out


def likelihood_at_truth(room: dict, variant: dict, floor, envelope, priors=None) -> dict:
    """The likelihood ratio of the truth against the maximum, for one fitted room.

    ``room`` from :func:`room_data`, ``variant`` its log line's entry for
    ``ar1_white:estimate`` (its MAP starts the search). Returns ``{"lr": 2Δ, "df": k}``:
    2Δ = 2 (max log L − max over the noise parameters of log L at the true model
    parameters), log L the likelihood the fit samples (start state integrated out).
    If that likelihood is the data's, 2Δ follows χ² with k = the number of model
    parameters less the one scale direction hourly data leave to the priors (Wilks);
    and a quantity's marginal z (median − truth)/sd then rarely exceeds √(2Δ)
    (never, for a Gaussian posterior without a prior).
    """
    from scipy.optimize import minimize
    from scipy.special import expit, logit

    from heritage_bayes.inference.likelihoods import get_noise_model

    model = room["model"]
    noise = get_noise_model("ar1_white")
    U, y = room["U"][room["rows"]], room["y"]
    ps, lp = log_posterior(model, noise, U, y, priors or {}, floor, envelope, "estimate")
    names, nm = ps.names, lp.n_model
    is_phi = np.array([n.startswith("phi_") for n in names])

    def to_theta(v, phi=is_phi):  # log scale, phi on the logit scale
        return np.where(phi, expit(v), np.exp(v))

    def nll(theta):
        return -float(lp.log_likelihood(theta[None])[0])

    opts = {"maxiter": 20_000, "xatol": 1e-7, "fatol": 1e-5}
    start = np.array([variant["map"][n] for n in names])
    v_start = np.where(is_phi, logit(start), np.log(start))
    v0 = v_start
    for _ in range(3):  # two restarts: Nelder-Mead stalls in 10 dimensions
        best = minimize(lambda v: nll(to_theta(v)), v0, method="Nelder-Mead", options=opts)
        v0 = best.x
    tm = np.array([room["result"]["truth_parameters"][n] for n in names[:nm]])
    at_truth = minimize(
        lambda v: nll(np.concatenate([tm, to_theta(v, is_phi[nm:])])),
        v_start[nm:],
        method="Nelder-Mead",
        options=opts,
    )
    return {"lr": float(2.0 * (at_truth.fun - best.fun)), "df": nm - 1}


def lr_study(log: str, task) -> None:
    """``--lr LOG``: :func:`likelihood_at_truth` for every converged room of an earlier
    study's log (regenerated from ``task(model, rep)``, which must be that study's
    settings: the truths are checked) and each quantity's z against √(2Δ)."""
    from scipy import stats

    results = [json.loads(line) for line in open(log)]
    rows = []
    for r in results:
        v = r["variants"].get("ar1_white:estimate")
        if v is None or not v["converged"]:
            continue
        args = task(r["model"], r["rep"])
        room = room_data(args)
        if room["result"]["truth_parameters"] != r["truth_parameters"]:
            raise SystemExit(f"--lr: room {r['rep']} differs from the log's: other settings?")
        out = likelihood_at_truth(room, v, args[7], args[9], args[6])
        z = {k: (g["median"] - r["truth"][k]) / g["sd"] for k, g in v["ranks"].items()}
        rows.append((r["rep"], out["lr"], out["df"], z))
        zs = "  ".join(f"{k} {x:+.2f}" for k, x in z.items())
        print(
            f"  room {r['rep']:3d}: 2Δ {out['lr']:6.1f} (χ²_{out['df']} p "
            f"{stats.chi2.sf(out['lr'], out['df']):.3f})  z: {zs}",
            flush=True,
        )
    lr = np.array([x[1] for x in rows])
    df = rows[0][2]
    print(
        f"{len(rows)} rooms: 2Δ at the truth, median {np.median(lr):.1f} (χ²_{df}: "
        f"{stats.chi2.median(df):.1f}), mean {lr.mean():.1f} ({df}); above χ²_{df}'s 90 % "
        f"quantile {np.mean(lr > stats.chi2.ppf(0.9, df)):.2f} (0.10); KS p "
        f"{stats.kstest(lr, stats.chi2(df).cdf).pvalue:.3f}"
    )
    for k in rows[0][3]:
        zk = np.array([x[3].get(k, np.nan) for x in rows])
        print(
            f"  {k:16s} rooms with z² > 2Δ: {int(np.sum(zk**2 > lr))} of {len(rows)}; "
            f"|z| > 2: {int(np.sum(np.abs(zk) > 2))}"
        )


QUANTITIES = {
    "thermal_2c": ("tau_1_h", "gain_Ti_Te", "gain_Ti_I_S", "gain_Ti_Tf"),
    "hygric_2c": ("tau_1_h", "tau_2_h"),
    "hygric_2c_fixed": ("tau_1_h", "gain_Pi_Pe", "offset_Pi_Pf"),
}


def table(results: list[dict], variant: str, quantities: dict | None = None) -> list[str]:
    """Coverage and rank-uniformity lines of ``variant`` for each model's quantities
    (``quantities``: model -> names; default :data:`QUANTITIES`)."""
    quantities = QUANTITIES if quantities is None else quantities
    lines = []
    for name in sorted({r["model"] for r in results}):
        rs = [r for r in results if r["model"] == name and variant in r["variants"]]
        conv = sum(r["variants"][variant]["converged"] for r in rs)
        cpu = np.mean([r["variants"][variant]["cpu"] for r in rs])
        lines.append(
            f"  {name} [{variant}]: {len(rs)} replicates, {conv} converged, {cpu:.0f} s CPU each"
        )
        keys = [
            k
            for k in quantities.get(name, ())
            if any(k in r["variants"][variant]["ranks"] for r in rs)
        ]
        for k in keys:
            v = [
                (r["variants"][variant]["ranks"][k], r["variants"][variant]["converged"])
                for r in rs
                if k in r["variants"][variant]["ranks"]
            ]
            n = len(v)
            c50 = np.mean([x["in50"] for x, _ in v])
            c90 = np.mean([x["in90"] for x, _ in v])
            counts = np.histogram([x["rank"] for x, _ in v], bins=10, range=(0, 1))[0]
            p = stats.chisquare(counts).pvalue if n >= 20 else float("nan")
            # the fits a user would be told to trust (a run that did not converge is
            # flagged red in its report): their coverage separately
            ok = [x for x, c in v if c]
            conv_cov = (
                f"; converged ({len(ok)}) {np.mean([x['in50'] for x in ok]):4.2f} / "
                f"{np.mean([x['in90'] for x in ok]):4.2f}"
                if ok and len(ok) < n
                else ""
            )
            lines.append(
                f"    {k:16s} n {n:3d}   50 %: {c50:5.2f}   90 %: {c90:5.2f}   "
                f"rank chi² p {p:5.3f}{conv_cov}"
            )
    return lines


def room_zscores(
    results: list[dict], variant: str, name: str, quantities: dict | None = None
) -> tuple[list[dict], dict]:
    """The rooms of ``name`` fitted with ``variant`` and, per quantity of
    ``quantities`` (default :data:`QUANTITIES`), z = (posterior median - truth) /
    posterior sd of each room (NaN where not ranked)."""
    rs = [r for r in results if r["model"] == name and variant in r["variants"]]
    z = {}
    for k in (QUANTITIES if quantities is None else quantities).get(name, ()):
        vals = []
        for r in rs:
            x = r["variants"][variant]["ranks"].get(k)
            ok = x is not None and x["sd"] > 0
            vals.append((x["median"] - r["truth"][k]) / x["sd"] if ok else np.nan)
        z[k] = np.array(vals)
    return rs, z


def zscore_table(results: list[dict], variant: str) -> list[str]:
    """Per model and quantity of ``variant``: mean and sd of z = (posterior median -
    truth) / posterior sd over the replicates (calibrated: mean 0 ± 1/sqrt(n), sd 1)
    and the replicates above the truth."""
    lines = []
    for name in sorted({r["model"] for r in results}):
        parts = []
        for k, z in room_zscores(results, variant, name)[1].items():
            z = z[np.isfinite(z)]
            if z.size > 1:
                parts.append(
                    f"{k} {z.mean():+.2f} / {z.std(ddof=1):.2f} ({int(np.sum(z > 0))}/{z.size})"
                )
        if parts:
            lines.append(f"  {name} [{variant}] mean z / sd z (above truth): " + ", ".join(parts))
    return lines


def error_lines(results: list[dict], variant: str) -> list[str]:
    """Which parameter's error goes with a gain's miss: over the rooms of each model
    (log lines with ``posterior``), the Spearman correlation of a quantity's z with each
    model parameter's (posterior median - truth) / posterior sd."""
    from scipy import stats

    lines = []
    for name in sorted({r["model"] for r in results}):
        rs, z = room_zscores(results, variant, name)
        posts = [r["variants"][variant].get("posterior") for r in rs]
        if len(rs) < 5 or None in posts:
            continue
        err = {
            n: np.array(
                [
                    (q[n]["median"] - r["truth_parameters"][n]) / q[n]["sd"]
                    for r, q in zip(rs, posts, strict=True)
                ]
            )
            for n in rs[0]["truth_parameters"]
        }
        for k in ("gain_Ti_I_S", "gain_Ti_Te", "gain_Pi_Pe"):
            ok = np.isfinite(z[k]) if k in z else np.zeros(0, bool)
            if ok.sum() < 3:
                continue
            parts = [
                f"{n} {stats.spearmanr(z[k][ok], e[ok]).statistic:+.2f}"
                for n, e in err.items()
                if np.ptp(e[ok]) > 0
            ]
            lines.append(
                f"  {name} [{variant}] Spearman of {k}'s z with each parameter's error "
                f"z over {int(ok.sum())} rooms: " + ", ".join(parts)
            )
    return lines


def noise_lines(results: list[dict], variant: str) -> list[str]:
    """The thermal rooms' noise posteriors against the observation model's truths (log
    lines with ``posterior`` and ``noise_truth``): per noise parameter the median over
    the rooms of its posterior median / its truth (phi: minus its truth; sigma: the
    AR(1) model error's marginal sd; sigma_meas: the sensor's sd with rounding's), and
    the mean (min-max) over the rooms of the solar gain's posterior correlation with
    each parameter and with tau_1 and the gain from Te."""
    rs = [
        r
        for r in results
        if variant in r["variants"]
        and "posterior" in r["variants"][variant]
        and "noise_truth" in r
        and r["model"].startswith("thermal")
    ]
    if not rs:
        return []
    o = "Ti"
    truths = {
        f"sigma_{o}": lambda t: t["sd"],
        f"phi_{o}": lambda t: t["phi"],
        f"sigma_meas_{o}": lambda t: float(np.hypot(t["sensor"], 0.1 / np.sqrt(12))),
    }
    parts = []
    for n, f in truths.items():
        v = [
            (r["variants"][variant]["posterior"][n]["median"], f(r["noise_truth"]))
            for r in rs
            if n in r["variants"][variant]["posterior"]
        ]
        if not v:
            continue
        d = np.array([m - t if n.startswith("phi") else m / t for m, t in v])
        op = "-" if n.startswith("phi") else "/"
        parts.append(
            f"{n} median {op} truth {np.median(d):+.3f}"
            if op == "-"
            else f"{n} median {op} truth {np.median(d):.3f}"
        )
    lines = [f"  noise [{variant}] ({len(rs)} rooms), median over rooms: " + ", ".join(parts)]
    corr = [r["variants"][variant].get("corr_gain_Ti_I_S", {}) for r in rs]
    names = sorted({k for c in corr for k in c})
    if names:
        lines.append(
            f"  corr(gain_Ti_I_S, .) [{variant}] mean (min..max) over rooms: "
            + ", ".join(
                f"{k} {np.mean(x):+.2f} ({np.min(x):+.2f}..{np.max(x):+.2f})"
                for k in names
                if (x := [c[k] for c in corr if k in c])
            )
        )
    return lines


def repeat_room(results: list[dict], variant: str) -> list[str]:
    """One room observed afresh many times (``--room``): for each quantity the spread
    of the posterior medians over the observation draws against the mean posterior sd
    (1 if the intervals have the right width), and the z-score of the truth
    (median - truth) / sd: rms 1 and mean 0 (standard error 1/sqrt(n)) if calibrated
    for this room; a mean away from 0 is a bias of this room's posterior."""
    lines = []
    rs = [r["variants"][variant] for r in results if variant in r["variants"]]
    conv = sum(r["converged"] for r in rs)
    lines.append(f"  [{variant}]: {len(rs)} observation draws, {conv} converged")
    maps = [r["map"] for r in rs if "map" in r]
    if maps:
        t = results[0]["truth_parameters"]
        lines.append(
            "    MAP over the draws (min-max; truth): "
            + ", ".join(
                f"{n} {min(m[n] for m in maps):.3g}-{max(m[n] for m in maps):.3g} ({t[n]:.3g})"
                for n in t
            )
        )
    for k in QUANTITIES.get(results[0]["model"], ()):
        v = [r["ranks"][k] for r in rs if k in r["ranks"]]
        if len(v) < 2:
            continue
        t = results[0]["truth"][k]
        med = np.array([x["median"] for x in v])
        sd = np.array([x["sd"] for x in v])
        z = (med - t) / sd
        lines.append(
            f"    {k:16s} spread of medians / posterior sd {med.std(ddof=1) / sd.mean():5.2f}"
            f"   z rms {np.sqrt(np.mean(z**2)):5.2f}   mean {z.mean():+5.2f}"
            f" ± {1 / np.sqrt(len(z)):.2f}   90 %: {np.mean([x['in90'] for x in v]):4.2f}"
        )
    return lines


def print_study(results, variants, header: str, quantities: dict | None = None) -> None:
    """Print a study's header line and its coverage table for each variant."""
    print(header)
    print("coverage of central 50 % / 90 % intervals (target 0.50 / 0.90; 90 %: 0.85-0.95)")
    for v in variants:
        for line in table(results, v, quantities):
            print(line)


def run_tasks(fn, tasks: list, jobs: int, log: str | None) -> list[dict]:
    """Run ``fn`` on every task (``jobs`` processes), appending each result to ``log``
    as one JSON line as soon as it is done (a study cut short can be tabulated)."""
    results = []

    def done(r):
        results.append(r)
        if log:
            with open(log, "a") as f:
                f.write(json.dumps(r) + "\n")
        conv = ", ".join(f"{v}: {x['steps']} steps" for v, x in r["variants"].items())
        print(f"  {r['model']} replicate {r['rep']} done ({conv})", flush=True)

    if jobs > 1:
        with ProcessPoolExecutor(jobs) as ex:
            for r in ex.map(fn, tasks):
                done(r)
    else:
        for t in tasks:
            done(fn(t))
    return results


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--reps", type=int, default=50)
    ap.add_argument(
        "--first-rep",
        type=int,
        default=0,
        help="number of the first replicate (each replicate's room and weather come from "
        "(seed, replicate)): --first-rep 50 --reps 50 --log same.jsonl extends a 50-replicate "
        "study to 100, tabulated with --table",
    )
    ap.add_argument("--models", default="thermal_2c,hygric_2c")
    ap.add_argument("--noise", action="append", help="NAME:INIT (repeatable)")
    ap.add_argument("--jobs", type=int, default=1)
    ap.add_argument("--seed", type=int, default=2026)
    ap.add_argument("--log", help="append each replicate's result as a JSON line")
    ap.add_argument(
        "--prior",
        action="append",
        default=[],
        metavar="NAME=MEDIAN,SIGMA",
        help="a log-normal prior given to every fit (e.g. Gf=14,0.6: knowledge of the "
        "ground coupling), to see what a weakly identified parameter's prior does",
    )
    ap.add_argument(
        "--truth-priors",
        action="store_true",
        help="give every fit priors equal to the distributions the truths are drawn "
        "from (Cw excepted): SBC as its theory has it, to separate a prior-volume bias from "
        "a likelihood or sampler one",
    )
    ap.add_argument(
        "--flat-fixed-node",
        action="store_true",
        help="hygric_2c_fixed as before the node's physical priors: truths of Pf uniform on "
        "900-1 400 Pa and Gf log-uniform on 2e-8..2e-7 kg/(s·Pa), fitted with Pf uniform "
        "on 0-5 000 Pa and Gf log-uniform on 1e-12..1e-3",
    )
    ap.add_argument(
        "--floor-area",
        type=float,
        default=FLOOR,
        help="floor area on the ground [m²] given to every fit (a log-normal prior on Gf) "
        "and used to draw the true Gf; 0: neither, Gf log-uniform on 5-40 W/K as in the "
        f"study before that prior (default {FLOOR:g})",
    )
    ap.add_argument(
        "--envelope-area",
        type=float,
        default=ENVELOPE,
        help="exterior area of walls and roof [m²] given to every fit (upper bounds on Gw "
        f"and Cw); 0: none, as in the studies before those bounds (default {ENVELOPE:g})",
    )
    ap.add_argument(
        "--solar",
        choices=SOLAR,
        default="ghi",
        help="the thermal rooms' solar input I_S, in the generator and the fit alike: ghi "
        "(global horizontal, default) or facade (the south facade hbayes calibrate "
        "computes from the hourly record: Erbs + Perez); recorded in each log line",
    )
    ap.add_argument(
        "--tau-factor",
        type=float,
        default=50.0,
        help="chain length the convergence rule asks for, in τ (default 50, the package's): "
        "a larger factor runs each fit longer than hbayes calibrate would, to see whether "
        "a posterior changes with the chain's length (the sampler) or not (the posterior)",
    )
    ap.add_argument(
        "--cw-range",
        type=lambda v: tuple(float(x) for x in v.split(",")),
        default=None,
        metavar="LO,HI",
        help="draw the envelope capacity Cw of the truths log-uniform on LO-HI [J/K or "
        "kg/Pa] instead of solving it for a slow time constant of 2-3 weeks; with "
        "--truth-priors the fit's prior on Cw is the same, so every parameter's truth "
        "comes from the fit's prior (SBC as its theory has it)",
    )
    ap.add_argument(
        "--cal-days",
        type=int,
        default=CAL_DAYS,
        help=f"days of calibration record per room (default {CAL_DAYS}): the same rooms "
        "(truths) with a longer record, to see whether intervals too narrow on a slow "
        "envelope come from a record only a few of its time constants long",
    )
    ap.add_argument("--table", help="only tabulate a --log file of an earlier study")
    ap.add_argument(
        "--lr",
        metavar="LOG",
        help="the likelihood ratio of the truth against the maximum for each converged "
        "room of an earlier study's log (give the study's own --seed, --solar, ...): "
        "χ² if the fit's likelihood is the data's; against each quantity's z",
    )
    ap.add_argument(
        "--room",
        type=int,
        help="one replicate's room (truth, weather, start) observed afresh --reps times: "
        "is this room's posterior calibrated, and which part of the observation model "
        "(see --without) matters?",
    )
    ap.add_argument(
        "--without",
        default="",
        help="with --room: comma-separated parts of the observation model left out: "
        "model_error, rounding, gap",
    )
    ap.add_argument(
        "--max-steps",
        type=int,
        default=12000,
        help="emcee steps at most per fit (stops earlier once converged); the chains of "
        "these rooms have tau ~ 250, so 12 000 steps is ~50 tau (default 12000)",
    )
    args = ap.parse_args()
    variants = args.noise or ["ar1_white:estimate", "ar1:steady"]
    if args.table:
        results = [json.loads(line) for line in open(args.table)]
        found = sorted({v for r in results for v in r["variants"]})
        print(f"SBC table of {args.table}: {len(results)} replicates")
        for v in found:
            lines = table(results, v) + zscore_table(results, v) + noise_lines(results, v)
            for line in lines + error_lines(results, v):
                print(line)
        return
    priors = {}
    for spec in args.prior:
        name, _, vals = spec.partition("=")
        median, sigma = (float(v) for v in vals.split(","))
        priors[name] = {"dist": "lognormal", "median": median, "sigma": sigma}
    if args.flat_fixed_node:
        if set(args.models.split(",")) != {"hygric_2c_fixed"}:
            ap.error("--flat-fixed-node: with --models hygric_2c_fixed only")
        priors = {**FLAT_NODE_PRIORS, **priors}
    if args.truth_priors:
        import heritage_bayes as hb

        for m in args.models.split(","):
            priors.update(
                truth_priors(
                    hb.model(m), args.floor_area or None, args.flat_fixed_node, args.cw_range
                )
            )
    floor = args.floor_area or None
    envelope = args.envelope_area or None

    def task(model: str, rep: int, observation=(None, ())) -> tuple:
        """:func:`replicate`'s arguments (``observation``: see its ``redraw``)."""
        return (
            model,
            rep,
            variants,
            args.seed,
            args.max_steps,
            args.cal_days,
            priors,
            floor,
            observation,
            envelope,
            args.flat_fixed_node,
            args.solar,
            args.tau_factor,
            args.cw_range,
        )

    if args.lr:
        lr_study(args.lr, task)
        return
    if args.room is not None:
        without = tuple(w for w in args.without.split(",") if w)
        unknown = set(without) - {"model_error", "rounding", "gap"}
        if unknown:
            ap.error(f"--without: unknown {sorted(unknown)}; use model_error, rounding, gap")
        tasks = [
            task(args.models.split(",")[0], args.room, (k, without))
            for k in range(args.first_rep, args.first_rep + args.reps)
        ]
        with ProcessPoolExecutor(max(1, args.jobs)) as ex:
            results = list(ex.map(replicate, tasks))
        if args.log:
            with open(args.log, "a") as f:
                f.writelines(json.dumps(r) + "\n" for r in results)
        print(
            f"room {args.room} of {results[0]['model']}, {len(results)} observation draws"
            f" without {list(without) or 'nothing'}"
        )
        for v in variants:
            for line in repeat_room(results, v):
                print(line)
        return
    tasks = [
        task(m, r)
        for r in range(args.first_rep, args.first_rep + args.reps)
        for m in args.models.split(",")
    ]  # models interleaved: a study cut short still covers every model
    t0 = time.perf_counter()
    results = run_tasks(replicate, tasks, args.jobs, args.log)
    print_study(
        results,
        variants,
        f"SBC: {args.reps} replicates per model, 3 months hourly De Bilt weather, "
        f"{time.perf_counter() - t0:.0f} s wall",
    )


if __name__ == "__main__":
    main()
