"""Simulation-based calibration on rooms the package did not generate.

``bench_sbc.py`` simulates its rooms with the very discretisation the fit uses (hourly
zero-order hold of the same hourly inputs): the easy case. Here the generator shares no
discretisation and no solar model with the fit:

- **10-minute sub-steps**, each an exact step (``scipy.linalg.expm``) of the continuous
  state space with its own 10-minute inputs;
- **weather that varies within the hour**: outdoor temperature and vapour pressure are
  the KNMI hourly readings (De Bilt, instantaneous at the hour) interpolated linearly,
  plus a within-hour fluctuation (AR(1), correlation time 30 min, sd 0.3 K and 10 Pa);
  the fit sees only the hourly readings *of that fluctuating series* (as a station
  logs it);
- **a different sky model**: the generator spreads each hour's global irradiance over
  its six 10-minute intervals in proportion to the cosine of the sun's zenith, splits it
  with Orgill-Hollands and transposes it to the south facade with the isotropic sky,
  while the fit gets what ``hbayes calibrate`` computes from the hourly file (Erbs and
  Perez at mid-hour, :func:`heritage_bayes.climate.surface_irradiance`);
- the fit's hourly inputs come from :func:`heritage_bayes.io.align` (the package's own
  sampling semantics: readings as instantaneous, irradiance as hour-ending means);
- **observation**: the indoor node at the full hour, plus AR(1) model error (phi
  0.90-0.95, marginal sd 0.15-0.30 K or 15-30 Pa), white sensor noise (0.1 K or 12 Pa),
  rounding to 0.1 and a one-week gap, as in ``bench_sbc.py``.

Truths are those of the continuous-time room (time constants, static gains, the fixed
node's gain and offset), independent of any discretisation; the parameters are drawn
as in ``bench_sbc.truth`` (the hygric fixed node's Pf and Gf from the fit's physical
default priors, at De Bilt's mean temperature and the hall's 80 m² floor). The
**mean solar warming** ``solar_warming_K`` [K] is the static solar gain times the mean
facade irradiance over the calibration period, each in its own irradiance model (the
generator's for the truth, the fit's input for the draws): the physical effect, which
does not depend on which sky model scaled the aperture.

    python benchmarks/bench_sbc_independent.py --reps 50 --jobs 2 --log sbc_ind.jsonl
    python benchmarks/bench_sbc_independent.py --table sbc_ind.jsonl [more.jsonl ...]
    python benchmarks/bench_sbc_independent.py --table sbc_ind.jsonl --markdown
    python benchmarks/bench_sbc_independent.py --reps 4 --models thermal_2c
    python benchmarks/bench_sbc_independent.py --reps 38 --models thermal_2c \
        --noise ar1_white:estimate --without within_hour,sky,substeps --solar ghi

``--solar ghi`` (with ``sky`` left out): the generator and the fit both take the global
horizontal irradiance (aligned as an hour-ending mean) as I_S instead of the south
facade, the rooms otherwise the same: ``bench_sbc.py``'s input on these rooms.

Each replicate's room, weather stretch and noise come from ``(seed, replicate)``; one
JSON line per replicate is appended to ``--log`` as soon as it is done (a study cut
short can be tabulated), and ``--first-rep`` extends a study.
"""

from __future__ import annotations

import argparse
import json
import os
import sys
import time
from pathlib import Path

os.environ.setdefault("OPENBLAS_NUM_THREADS", "1")
os.environ.setdefault("OMP_NUM_THREADS", "1")

import numpy as np
import pandas as pd
from scipy import stats

sys.path.insert(0, str(Path(__file__).resolve().parent))

from bench_sbc import (  # the benchmark directory is not a package
    CAL_DAYS,
    ENVELOPE,
    FLOOR,
    KNMI,
    MAX_SPIN_DAYS,
    _knmi_cache,
    fit_and_rank,
    print_study,
    room_zscores,
    run_tasks,
    simulate_reference,
    table,
    truth,
)

#: De Bilt, KNMI station 260 [°N, °E, m]
SITE = {"latitude": 52.10, "longitude": 5.18, "altitude": 1.9}
SUB = 6  # 10-minute sub-steps per hour
DT_SUB = 600.0  # [s]
QUANTITIES = {
    "thermal_2c": ("tau_1_h", "gain_Ti_Te", "gain_Ti_I_S", "gain_Ti_Tf", "solar_warming_K"),
    "hygric_2c_fixed": ("tau_1_h", "gain_Pi_Pe", "offset_Pi_Pf"),
}


def _fluctuation(rng, n: int, sd: float, tau_steps: float) -> np.ndarray:
    """Stationary AR(1) of marginal sd ``sd`` and correlation time ``tau_steps``."""
    phi = np.exp(-1.0 / tau_steps)
    z = rng.normal(0.0, sd * np.sqrt(1 - phi**2), n)
    e = np.empty(n)
    e[0] = rng.normal(0.0, sd)
    for k in range(1, n):
        e[k] = phi * e[k - 1] + z[k]
    return e


def generator_weather(seed: int, without: tuple = (), solar: str = "facade") -> dict:
    """A random De Bilt stretch on the 10-minute grid and as a station logs it hourly.

    Returns ``fine`` (10-minute Te [°C], Pe [Pa], I_S [W/m²], each the value over the
    sub-step starting at its time), ``hourly`` (a DataFrame of the readings Te, RHe at
    the hour and the hour-ending ghi, UTC, as :func:`read_knmi_hourly` returns them) and
    ``t0`` the first hour. ``without``: parts of the generator left out, to find which
    one costs coverage: ``"within_hour"`` (no fluctuation within the hour: the
    readings describe the hour exactly), ``"sky"`` (the generator's facade irradiance
    is the fit's own, held over each hour); :func:`replicate` also knows
    ``"substeps"`` (the room simulated in hourly steps of the fit's own inputs).
    ``solar``: with ``"sky"`` left out, the fit's I_S the generator holds
    (:func:`fit_inputs`: ``"facade"`` or ``"ghi"``).
    """
    import pvlib

    from heritage_bayes.climate.psychro import vapour_pressure

    w = _knmi_cache()
    n = (CAL_DAYS + MAX_SPIN_DAYS + 2) * 24
    rng = np.random.default_rng(seed)
    start = int(rng.integers(0, len(w) - n - 1))
    part = w.iloc[start : start + n + 1][["Te", "RHe", "ghi"]]
    part = part.interpolate(limit_direction="both")
    hours = part.index
    th = hours.asi8 / 1e9
    fine_t = th[0] + DT_SUB * np.arange((len(hours) - 1) * SUB)
    mid = fine_t + DT_SUB / 2
    nf = fine_t.size
    # within-hour weather: linear between the hours + a fluctuation the hourly readings
    # sample only at the full hour
    wiggle = 0.0 if "within_hour" in without else 1.0
    te_f = np.interp(fine_t, th, part["Te"].to_numpy()) + wiggle * _fluctuation(rng, nf, 0.3, 3.0)
    rh_f = np.clip(np.interp(fine_t, th, part["RHe"].to_numpy()), 1.0, 100.0)
    pe_f = vapour_pressure(te_f, rh_f) + wiggle * _fluctuation(rng, nf, 10.0, 3.0)
    # the station's hourly record of those series
    on_hour = slice(0, nf, SUB)
    hourly = pd.DataFrame(
        {
            "Te": np.append(te_f[on_hour], te_f[-1]),
            "Pe": np.append(pe_f[on_hour], pe_f[-1]),
            "ghi": part["ghi"].to_numpy(),
        },
        index=hours,
    )
    hourly.attrs.update(averaged=("ghi",), interval="1h", source="generator")
    # 10-minute irradiance: hour-ending means spread by cos(zenith) at each mid-sub-step
    times = pd.DatetimeIndex(pd.to_datetime(mid, unit="s", utc=True))
    sp = pvlib.solarposition.get_solarposition(
        times, SITE["latitude"], SITE["longitude"], SITE["altitude"]
    )
    cz = np.clip(np.cos(np.radians(sp["apparent_zenith"].to_numpy())), 0.0, None)
    cz_h = cz.reshape(-1, SUB)
    mean_cz = cz_h.mean(axis=1, keepdims=True)
    share = np.where(mean_cz > 1e-3, cz_h / np.where(mean_cz > 1e-3, mean_cz, 1.0), 1.0)
    ghi_f = (part["ghi"].to_numpy()[1:, None] * share).reshape(-1)  # hour ending at +1h
    split = pvlib.irradiance.orgill_hollands(ghi_f, sp["zenith"].to_numpy(), times)
    poa = pvlib.irradiance.get_total_irradiance(
        90.0,
        180.0,
        sp["apparent_zenith"].to_numpy(),
        sp["azimuth"].to_numpy(),
        np.nan_to_num(np.asarray(split["dni"], float)),
        ghi_f,
        np.nan_to_num(np.asarray(split["dhi"], float)),
        albedo=0.2,
        model="isotropic",
    )
    i_s = np.clip(np.nan_to_num(np.asarray(poa["poa_global"], float)), 0.0, None)
    i_s[ghi_f <= 0] = 0.0
    if "sky" in without:  # the fit's facade irradiance, held over its hour
        i_s = np.repeat(fit_inputs(hourly, solar=solar)["I_S"].to_numpy(), SUB)
    elif solar != "facade":
        raise ValueError("solar 'ghi' needs the generator's sky model left out ('sky')")
    return {"fine": {"Te": te_f, "Pe": pe_f, "I_S": i_s}, "hourly": hourly, "t0": hours[0]}


def fit_inputs(hourly: pd.DataFrame, models=(), full: bool = False, solar: str = "facade"):
    """The hourly inputs ``hbayes calibrate`` builds from the station record: the south
    facade by :func:`heritage_bayes.inputs.solar_inputs` (an hour-ending mean, held over
    its hour) and :func:`align` on 1 h.

    ``models`` (RC models with slope inputs, :meth:`RCModel.with_slopes`) get their
    ``<input>_slope`` columns from :func:`heritage_bayes.inputs.add_slope_columns`, as
    ``hbayes calibrate`` adds them with ``data.input_hold: exact``: the change of each
    instantaneous reading over the step (the first-order hold), zeros for the
    hour-ending irradiance means. ``full``: the :class:`~heritage_bayes.io.Aligned`
    too, as ``(frame, aligned)``. ``solar="ghi"``: the global horizontal irradiance
    itself as I_S (an hour-ending mean, held over its hour), not the facade."""
    from heritage_bayes.inputs import add_slope_columns, solar_inputs
    from heritage_bayes.io.align import align

    # the facade as prepare builds it (its transposition, albedo and labels: the
    # irradiance stays an hour-ending mean, held over its hour)
    if solar == "ghi":
        irr = hourly[["ghi"]].rename(columns={"ghi": "I_S"})
        irr.attrs.update(averaged=("I_S",), interval="1h", source="station")
    else:
        cols = [c for c in ("ghi", "dni", "dhi") if c in hourly]
        irr = solar_inputs(hourly[cols], SITE, {"S": (90.0, 180.0)}, "measured")[0]
    met = hourly[["Te", "Pe"]].copy()
    met.attrs.update(averaged=(), interval="1h", source="station")
    aligned = align([met, irr], step="1h", max_gap="0h")
    frame = aligned.frame.copy()
    frame.attrs = dict(aligned.frame.attrs)
    if models:
        add_slope_columns(frame, models, aligned.slopes)
    return (frame, aligned) if full else frame


def replicate(args) -> dict:
    """One room: generate on the 10-minute grid, fit on the hourly record, rank truths."""
    import heritage_bayes as hb
    from heritage_bayes.rc.derived import derived_quantities

    name, rep, variants, seed, max_steps = args[:5]
    cal_days = args[5] if len(args) > 5 else CAL_DAYS
    floor = args[6] if len(args) > 6 else FLOOR
    envelope = args[7] if len(args) > 7 else ENVELOPE
    without = args[8] if len(args) > 8 else ()
    hold = args[9] if len(args) > 9 else "exact"
    noise_free = args[10] if len(args) > 10 else False
    solar = args[11] if len(args) > 11 else "facade"
    rng = np.random.default_rng([seed, rep])
    opts = {"surfaces": ("S",)} if name.startswith("thermal") else {}
    model = hb.model(name, **opts)
    p = truth(model, rng, floor)
    gw = generator_weather(int(rng.integers(2**31)), without, solar)
    fine = gw["fine"]
    nf = fine["Te"].size
    Uf = np.column_stack([fine[c] if c in fine else np.full(nf, 10.0) for c in model.input_names])
    if "Tf" in model.input_names:  # ground: the mean outdoor temperature, constant
        Uf[:, model.input_names.index("Tf")] = fine["Te"].mean()
    A, B, _, _ = model.state_space(p)
    x0 = np.linalg.solve(-A, B @ Uf[: 24 * SUB].mean(axis=0) + model.offset(p))
    X = simulate_reference(model, p, Uf, DT_SUB, x0)  # exact 10-minute steps
    out = model.output_names[0]
    y_hour = X[::SUB, model.state_names.index(out)]  # the node at every full hour
    # the fit's model and inputs, as hbayes calibrate builds them for this input hold
    fit_model = model.with_slopes(model.network.inputs if hold == "exact" else ())
    frame = fit_inputs(gw["hourly"], [fit_model], solar=solar)
    U = np.column_stack(
        [
            frame[c].to_numpy(float) if c in frame else np.full(len(frame), 10.0)
            for c in fit_model.input_names
        ]
    )
    if "Tf" in model.input_names:  # constant: its slope column (if any) stays zero
        U[:, model.input_names.index("Tf")] = fine["Te"].mean()
    if "substeps" in without:  # the fit's own discretisation: hourly ZOH of its inputs
        m_net = len(model.network.inputs)
        y_hour = simulate_reference(model, p, U[:, :m_net], 3600.0, x0)
        y_hour = y_hour[:, model.state_names.index(out)]
    n = min(len(U), y_hour.size)
    spin = int(rng.integers(7, MAX_SPIN_DAYS + 1)) * 24
    rows = slice(spin, spin + cal_days * 24)
    assert rows.stop <= n, "weather stretch too short for the spin-up and calibration"
    thermal = model.domain == "thermal"
    phi = rng.uniform(0.90, 0.95)
    sd = rng.uniform(0.15, 0.30) * (1.0 if thermal else 100.0)
    e = _fluctuation(rng, n, sd, -1.0 / np.log(phi))
    sensor = 0.1 if thermal else 12.0  # [K]; [Pa] ~ 1 %RH at 10 °C
    y = np.round(y_hour[:n] + e + rng.normal(0, sensor, n), 1)[rows]
    g0 = int(rng.integers(7 * 24, cal_days * 24 - 14 * 24))
    fixed = {}
    if noise_free:
        # the room's own noise-free record (same gap), fitted with the noise parameters
        # fixed at the truths of the observation model (the sensor's sd with rounding's):
        # the posterior's width is the study's, its centre the generator's systematic
        # error plus the prior's pull, so z = (median - truth)/sd is the deterministic
        # part of the study's z in its own sd
        y = y_hour[:n][rows].copy()
        o = model.output_names[0]
        fixed = {
            f"sigma_{o}": {"fixed": sd},
            f"phi_{o}": {"fixed": phi},
            f"sigma_meas_{o}": {"fixed": float(np.hypot(sensor, 0.1 / np.sqrt(12)))},
        }
    y[g0 : g0 + 7 * 24] = np.nan
    dq_true = {k: float(np.ravel(v)[0]) for k, v in derived_quantities(model, p).items()}
    extra = None
    if "I_S" in model.input_names:
        j = model.input_names.index("I_S")
        cal_fine = slice(rows.start * SUB, rows.stop * SUB)
        mean_true = float(fine["I_S"][cal_fine].mean())
        mean_fit = float(U[rows, j].mean())
        dq_true["solar_warming_K"] = dq_true["gain_Ti_I_S"] * mean_true

        def extra(dq, theta, _m=mean_fit):
            return {"solar_warming_K": np.asarray(dq["gain_Ti_I_S"], float) * _m}

    result = {
        "model": name,
        "rep": rep,
        "truth": dq_true,
        "truth_parameters": p,
        "generator": "independent",
        "input_hold": hold,
        # parts of the generator left out (--without)
        "without": sorted(without),
        "noise_free": bool(noise_free),
        # the solar input I_S of generator and fit (--solar)
        "solar": solar,
        # the fit's upper bounds on the hygric buffer from the envelope area
        "hygric_envelope": bool(envelope) and not name.startswith("thermal"),
        # the fixed node's Pf and Gf drawn from, and fitted with, the physical priors
        # (fixed_vapour_pressure_prior, vapour_ground_prior)
        "fixed_node_prior": "physical" if "Pf" in model.parameter_names else None,
    }
    if extra is not None:
        result["irradiance_mean"] = {"generator": mean_true, "fit": mean_fit}
    result["variants"] = fit_and_rank(
        fit_model, U[rows], y, dq_true, variants, rep, max_steps, fixed, floor, envelope, extra
    )
    return result


def misfit(rep: int, seed: int, without: tuple = ()) -> dict:
    """The generator's noise-free error against the fit's model, without a fit: thermal
    replicate ``rep``'s hourly indoor temperature from the generator (the parts
    ``without`` left out, as :func:`replicate` draws them) minus the fit's own model
    (exact input hold) with the true parameters on the fit's hourly inputs, from the
    same state, over the calibration period. Returns its mean, sd and the sd of its
    daily means [K] and its correlation with the fit's facade irradiance: the error
    that the AR(1) + white noise model has to take up, by part of the generator."""
    import heritage_bayes as hb

    rng = np.random.default_rng([seed, rep])
    model = hb.model("thermal_2c", surfaces=("S",))
    p = truth(model, rng, FLOOR)
    gw = generator_weather(int(rng.integers(2**31)), without)
    fine = gw["fine"]
    nf = fine["Te"].size
    Uf = np.column_stack([fine[c] if c in fine else np.full(nf, 10.0) for c in model.input_names])
    j_tf, j_s = model.input_names.index("Tf"), model.input_names.index("I_S")
    Uf[:, j_tf] = fine["Te"].mean()
    A, B, _, _ = model.state_space(p)
    x0 = np.linalg.solve(-A, B @ Uf[: 24 * SUB].mean(axis=0) + model.offset(p))
    fit_model = model.with_slopes(model.network.inputs)
    frame = fit_inputs(gw["hourly"], [fit_model])
    U = np.column_stack(
        [
            frame[c].to_numpy(float) if c in frame else np.full(len(frame), 10.0)
            for c in fit_model.input_names
        ]
    )
    U[:, j_tf] = fine["Te"].mean()
    i = model.state_names.index(model.output_names[0])
    if "substeps" in without:
        y = simulate_reference(model, p, U[:, : len(model.network.inputs)], 3600.0, x0)[:, i]
    else:
        y = simulate_reference(model, p, Uf, DT_SUB, x0)[::SUB, i]
    n = min(len(U), y.size)
    spin = int(rng.integers(7, MAX_SPIN_DAYS + 1)) * 24
    rows = slice(spin, spin + CAL_DAYS * 24)
    d = (y[:n] - hb.simulate(fit_model, p, U[:n], 3600.0, x0)[:, 0])[rows]
    daily = d[: d.size // 24 * 24].reshape(-1, 24).mean(axis=1)
    # what another aperture cannot take up: the error less its least-squares fit by the
    # room's response to the fit's facade irradiance alone (and a constant)
    Us = np.zeros_like(U[:n])
    Us[:, j_s] = U[:n, j_s]
    resp = hb.simulate(fit_model, p, Us, 3600.0, np.zeros(len(x0)))[:, 0][rows]
    X = np.column_stack([resp, np.ones_like(resp)])
    coef = np.linalg.lstsq(X, d, rcond=None)[0]
    rest = d - X @ coef
    # two apertures: the room's responses to the beam part of the fit's facade
    # irradiance (with the ground-reflected part) and to its sky-diffuse part, each with
    # its own scaling: how much of the error is the sky models' split of the light
    beam = fit_inputs(_without_sky_diffuse(gw["hourly"]))["I_S"].to_numpy(float)[:n]
    resp2 = []
    for part in (beam, U[:n, j_s] - beam):
        Us = np.zeros_like(U[:n])
        Us[:, j_s] = part
        resp2.append(hb.simulate(fit_model, p, Us, 3600.0, np.zeros(len(x0)))[:, 0][rows])
    X2 = np.column_stack([*resp2, np.ones_like(resp)])
    coef2 = np.linalg.lstsq(X2, d, rcond=None)[0]
    return {
        "mean": float(d.mean()),
        "sd": float(d.std()),
        "daily_sd": float(daily.std()),
        "corr_I_S": float(np.corrcoef(d, U[rows, j_s])[0, 1]),
        "sd_unscaled": float(rest.std()),
        "scale": float(1.0 + coef[0]),
        "sd_two_apertures": float((d - X2 @ coef2).std()),
        "scale_beam": float(1.0 + coef2[0]),
        "scale_diffuse": float(1.0 + coef2[1]),
        "diffuse_share": float((U[rows, j_s] - beam[rows]).mean() / U[rows, j_s].mean()),
    }


def _without_sky_diffuse(hourly: pd.DataFrame) -> pd.DataFrame:
    """The station record with the fit's own split of ``ghi`` (Erbs at mid-hour, as
    :func:`heritage_bayes.climate.surface_irradiance` makes it) given as ``dni`` and a
    zero ``dhi``: the facade then gets the beam and the ground-reflected part only."""
    import pvlib

    times = hourly.index - pd.Timedelta("30min")
    sp = pvlib.solarposition.get_solarposition(
        times, SITE["latitude"], SITE["longitude"], SITE["altitude"]
    )
    zen = sp["zenith"].to_numpy()
    ghi = hourly["ghi"].to_numpy(float)
    dni = np.asarray(pvlib.irradiance.erbs(ghi, zen, times.day_of_year.to_numpy())["dni"])
    dni = np.where((zen > 87.0) | ~np.isfinite(dni), 0.0, dni)
    out = hourly.copy()
    out["dni"], out["dhi"] = dni, 0.0
    out.attrs = {**hourly.attrs, "averaged": ("ghi", "dni", "dhi")}
    return out


def misfit_lines(reps, seed: int) -> list[str]:
    """:func:`misfit` over the replicates ``reps`` for the generator with every part and
    with each part left out: medians over the rooms."""
    cases = {
        "every part": (),
        "without sky": ("sky",),
        "without within_hour": ("within_hour",),
        "without within_hour,sky,substeps": ("within_hour", "sky", "substeps"),
    }
    lines = [
        f"noise-free generator - fit's model with the true parameters, thermal_2c, "
        f"{len(reps)} rooms (medians): |mean|, sd, sd of daily means [K], corr with I_S; "
        "sd [K] left after the best scaling of the solar response, that scaling"
    ]
    for label, without in cases.items():
        m = [misfit(r, seed, without) for r in reps]
        med = {k: float(np.median([abs(x[k]) if k == "mean" else x[k] for x in m])) for k in m[0]}
        lines.append(
            f"  {label:34s} {med['mean']:.3f} {med['sd']:.3f} {med['daily_sd']:.3f} "
            f"{med['corr_I_S']:+.2f} {med['sd_unscaled']:.3f} {med['scale']:.3f}; "
            f"beam and sky diffuse scaled apart: sd {med['sd_two_apertures']:.3f}, "
            f"scalings {med['scale_beam']:.3f} / {med['scale_diffuse']:.3f} "
            f"(diffuse {med['diffuse_share']:.2f} of the facade's light)"
        )
    return lines


def paired_lines(a: list[dict], b: list[dict]) -> list[str]:
    """Two studies of the same rooms (logs of one generator variant each, e.g. every
    part and ``--without sky``): per model and quantity over the replicates in both,
    the correlation of z between them and the mean, sd and rms of z_a - z_b, the shift
    the difference between the studies makes in the posterior's own sd (the rooms'
    noise is the same, so it cancels in the difference)."""
    lines = []
    for name in sorted({r["model"] for r in a} & {r["model"] for r in b}):
        ra = {r["rep"]: r for r in a if r["model"] == name}
        rb = {r["rep"]: r for r in b if r["model"] == name}
        reps = sorted(set(ra) & set(rb))
        if len(reps) < 3:
            continue
        va, vb = (sorted({v for r in x.values() for v in r["variants"]}) for x in (ra, rb))
        if len(va) != 1 or len(vb) != 1:
            raise SystemExit("--paired: one variant per log")
        _, za = _zscores([ra[r] for r in reps], va[0], name)
        _, zb = _zscores([rb[r] for r in reps], vb[0], name)
        parts = []
        for k in za:
            ok = np.isfinite(za[k]) & np.isfinite(zb[k])
            if ok.sum() < 3:
                continue
            d = za[k][ok] - zb[k][ok]
            corr = np.corrcoef(za[k][ok], zb[k][ok])[0, 1]
            parts.append(
                f"{k} corr {corr:+.2f}, diff {d.mean():+.2f} / {d.std(ddof=1):.2f} / "
                f"{np.sqrt(np.mean(d**2)):.2f}"
            )
        lines.append(
            f"  {name} ({len(reps)} rooms in both) z_a - z_b mean / sd / rms: " + "; ".join(parts)
        )
    return lines


def read_logs(paths: list[str]) -> list[dict]:
    """The replicates of one or more ``--log`` files, one record per (model, replicate)
    with the variants of every file merged; a variant found twice for the same replicate
    (a replicate repeated, e.g. a pilot extended from an overlapping ``--first-rep``)
    must agree, since each replicate is a function of ``(seed, replicate)``."""
    merged: dict[tuple[str, int], dict] = {}
    for path in paths:
        with open(path) as f:
            for line in f:
                if not line.strip():
                    continue
                r = json.loads(line)
                # logs from before the fit's first-order hold held every input at its
                # interval mean: their variants are tabulated apart ("...@interval_mean")
                hold = r.get("input_hold", "interval_mean")
                if hold != "exact":
                    r["variants"] = {f"{v}@{hold}": x for v, x in r["variants"].items()}
                # hygric fits from before the envelope's bounds on the hygric buffer
                # (Gw, Cw from --envelope-area, as for the thermal envelope)
                if r["model"].startswith("hygric") and not r.get("hygric_envelope", False):
                    r["variants"] = {f"{v}@unbounded": x for v, x in r["variants"].items()}
                # hygric_2c_fixed rooms from before the physical priors of the fixed
                # node (Pf uniform 900-1400 Pa in the truths, 0-5 000 Pa in the fit)
                if r["model"] == "hygric_2c_fixed" and r.get("fixed_node_prior") is None:
                    r["variants"] = {f"{v}@flat_pf": x for v, x in r["variants"].items()}
                if r.get("solar", "facade") != "facade":
                    r["variants"] = {f"{v}@{r['solar']}": x for v, x in r["variants"].items()}
                if r.get("noise_free"):
                    r["variants"] = {f"{v}@noise_free": x for v, x in r["variants"].items()}
                key = (r["model"], int(r["rep"]))
                if key not in merged:
                    merged[key] = {**r, "variants": dict(r["variants"])}
                    continue
                have = merged[key]["variants"]
                for v, x in r["variants"].items():
                    if v in have and have[v]["ranks"] != x["ranks"]:
                        raise SystemExit(
                            f"{path}: {r['model']} replicate {r['rep']} {v} differs from "
                            "an earlier log's (another seed or code?)"
                        )
                    have.setdefault(v, x)
    return [merged[k] for k in sorted(merged)]


def zscore_lines(results: list[dict], variant: str) -> list[str]:
    """Per model and quantity the rms of z = (posterior median - truth) / posterior sd
    over the replicates: about 1 for calibrated intervals, the factor by which they are
    too narrow otherwise (with n replicates its standard error is about 1/sqrt(2n))."""
    lines = []
    for name in sorted({r["model"] for r in results}):
        rs, zs = _zscores(results, variant, name)
        parts = [
            f"{k} {np.sqrt(np.mean(np.square(z[np.isfinite(z)]))):.2f}"
            for k, z in zs.items()
            if np.isfinite(z).any()
        ]
        lines.append(f"  {name} [{variant}] z rms ({len(rs)} rooms): " + ", ".join(parts))
    return lines


def _zscores(results: list[dict], variant: str, name: str) -> tuple[list[dict], dict]:
    """:func:`bench_sbc.room_zscores` with this study's quantities (the solar warming)."""
    return room_zscores(results, variant, name, QUANTITIES)


def bias_lines(results: list[dict], variant: str) -> list[str]:
    """Bias or width? Per model and quantity the mean and sd of z over the rooms (z =
    (median - truth)/sd; calibrated: mean 0 ± 1/sqrt(n), sd 1) and the rooms above the
    truth; then the room-to-room correlation of z between quantities and with the log
    of the generator/fit mean facade irradiance ratio (thermal rooms)."""
    lines = []
    for name in sorted({r["model"] for r in results}):
        rs, z = _zscores(results, variant, name)
        parts = []
        for k, v in z.items():
            v = v[np.isfinite(v)]
            if v.size > 1:
                parts.append(
                    f"{k} {v.mean():+.2f} / {v.std(ddof=1):.2f} ({int(np.sum(v > 0))}/{v.size})"
                )
        if not parts:
            continue
        lines.append(
            f"  {name} [{variant}] mean z / sd z (rooms above the truth): " + ", ".join(parts)
        )
        keys = ("tau_1_h", "gain_Ti_Te", "gain_Ti_I_S", "solar_warming_K")
        keys = [k for k in keys if k in z and np.isfinite(z[k]).any()]
        if len(keys) < 2:
            continue
        Z = np.column_stack([z[k] for k in keys])
        ok = np.all(np.isfinite(Z), axis=1)
        if ok.sum() < 3:
            continue
        C = np.corrcoef(Z[ok].T)
        pairs = [
            f"{keys[i]}~{keys[j]} {C[i, j]:+.2f}"
            for i in range(len(keys))
            for j in range(i + 1, len(keys))
        ]
        line = f"  {name} [{variant}] corr of z: " + ", ".join(pairs)
        if all("irradiance_mean" in r for r in rs):
            irr = np.log(
                [r["irradiance_mean"]["generator"] / r["irradiance_mean"]["fit"] for r in rs]
            )[ok]
            if np.ptp(irr) > 1e-9:  # (1 in every room without the other sky model)
                line += "; with log irradiance ratio: " + ", ".join(
                    f"{k} {np.corrcoef(Z[ok, i], irr)[0, 1]:+.2f}" for i, k in enumerate(keys)
                )
        lines.append(line)
    return lines


def solar_lines(results: list[dict], variant: str) -> list[str]:
    """Is the solar gain's bias the sky models' difference? Over the thermal rooms of
    ``variant``: the ratio of the generator's to the fit's mean facade irradiance (if
    the data fixed the solar warming, the fitted gain would be the true one times this
    ratio), the posterior median of the solar gain and of the mean solar warming over
    their truths (medians over the rooms, the rooms below 1) and the room-to-room
    correlation of the gain's ratio with the irradiance ratio (logs)."""
    rs = [
        r
        for r in results
        if "irradiance_mean" in r
        and variant in r["variants"]
        and {"gain_Ti_I_S", "solar_warming_K"} <= set(r["variants"][variant]["ranks"])
    ]
    if len(rs) < 2:
        return []
    irr = np.array([r["irradiance_mean"]["generator"] / r["irradiance_mean"]["fit"] for r in rs])
    ratio = {
        k: np.array([r["variants"][variant]["ranks"][k]["median"] / r["truth"][k] for r in rs])
        for k in ("gain_Ti_I_S", "solar_warming_K")
    }
    corr = np.corrcoef(np.log(ratio["gain_Ti_I_S"]), np.log(irr))[0, 1]
    return [
        f"  solar [{variant}] ({len(rs)} rooms): irradiance generator/fit median "
        f"{np.median(irr):.3f} ({irr.min():.3f}-{irr.max():.3f}); posterior median / truth: "
        + ", ".join(
            f"{k} {np.median(x):.3f} (below 1 in {int(np.sum(x < 1))})" for k, x in ratio.items()
        )
        + f"; corr(log gain ratio, log irradiance ratio) {corr:.2f}"
    ]


#: how the markdown table names the quantities
LABELS = {
    "tau_1_h": "τ1",
    "gain_Ti_Te": "gain from Te",
    "gain_Ti_I_S": "gain from I_S",
    "gain_Ti_Tf": "gain from Tf",
    "solar_warming_K": "mean solar warming",
    "gain_Pi_Pe": "gain from Pe",
    "offset_Pi_Pf": "offset from Pf",
}


def markdown_table(results: list[dict], variant: str) -> list[str]:
    """The coverage table of ``variant`` in markdown (docs, README): per model and
    quantity the replicates, the 90 % and 50 % coverage, the rank χ² p-value (20
    replicates or more) and the rms z-score."""
    lines = [
        "| model (replicates, converged) | quantity | n | 90 % coverage | 50 % | rank χ² p "
        "| z rms |",
        "|---|---|---|---|---|---|---|",
    ]
    for name in sorted({r["model"] for r in results}):
        rs = [r for r in results if r["model"] == name and variant in r["variants"]]
        if not rs:
            continue
        conv = sum(r["variants"][variant]["converged"] for r in rs)
        head = f"{name} ({len(rs)}, {conv})"
        for k in QUANTITIES.get(name, ()):
            v = [
                (x, r["truth"][k])
                for r in rs
                if (x := r["variants"][variant]["ranks"].get(k)) is not None
            ]
            if not v:
                continue
            n = len(v)
            counts = np.histogram([x["rank"] for x, _ in v], bins=10, range=(0, 1))[0]
            p = stats.chisquare(counts).pvalue if n >= 20 else float("nan")
            z = [(x["median"] - t) / x["sd"] for x, t in v if x["sd"] > 0]
            zr = float(np.sqrt(np.mean(np.square(z)))) if z else float("nan")
            c90 = np.mean([x["in90"] for x, _ in v])
            c50 = np.mean([x["in50"] for x, _ in v])
            p_txt = "—" if not np.isfinite(p) else f"{p:.3f}"
            lines.append(
                f"| {head} | {LABELS.get(k, k)} | {n} | {c90:.2f} | {c50:.2f} | {p_txt} "
                f"| {zr:.2f} |"
            )
            head = ""
    return lines


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--reps", type=int, default=50)
    ap.add_argument("--first-rep", type=int, default=0)
    ap.add_argument("--models", default="thermal_2c,hygric_2c_fixed")
    ap.add_argument("--noise", action="append", help="NAME:INIT (repeatable)")
    ap.add_argument("--jobs", type=int, default=1)
    ap.add_argument("--seed", type=int, default=2031)
    ap.add_argument("--max-steps", type=int, default=12000)
    ap.add_argument("--log", help="append each replicate's result as a JSON line")
    ap.add_argument(
        "--without",
        default="",
        help="comma-separated parts of the generator left out: within_hour, sky, substeps "
        "(then the room is simulated with the fit's hourly zero-order hold of its inputs)",
    )
    ap.add_argument(
        "--envelope-area",
        type=float,
        default=ENVELOPE,
        help="exterior area of walls and roof [m²] given to every fit: upper bounds on the "
        "envelope (thermal) or buffer (hygric) node's Gw and Cw; 0: none "
        f"(default {ENVELOPE:g})",
    )
    ap.add_argument(
        "--input-hold",
        choices=("exact", "interval_mean"),
        default="exact",
        help="how the fit holds its inputs over each hour (data.input_hold): exact (the "
        "default of hbayes calibrate for files: readings linear between the hours) or "
        "interval_mean (every input held at its hourly mean, as before the first-order "
        "hold; tabulated as NOISE:INIT@interval_mean)",
    )
    ap.add_argument(
        "--noise-free",
        action="store_true",
        help="fit each room's noise-free record (same gap) with the noise parameters fixed "
        "at the observation model's truths: z = (median - truth)/sd is then the "
        "deterministic part of the study's z (the generator's systematic error and the "
        "prior's pull), in the study's own sd; tabulated as NOISE:INIT@noise_free",
    )
    ap.add_argument(
        "--solar",
        choices=("facade", "ghi"),
        default="facade",
        help="the solar input I_S: the south facade (default) or, with --without sky, the "
        "global horizontal irradiance in generator and fit alike (bench_sbc.py's input); "
        "tabulated as NOISE:INIT@ghi",
    )
    ap.add_argument(
        "--table",
        nargs="+",
        metavar="LOG",
        help="only tabulate the --log file(s) of earlier studies (several: a study "
        "extended with --first-rep, or variants run apart on the same replicates)",
    )
    ap.add_argument("--markdown", action="store_true", help="with --table: the tables in markdown")
    ap.add_argument(
        "--paired",
        nargs=2,
        metavar="LOG",
        help="two logs of the same rooms (one generator variant each): the correlation "
        "of z between them and the mean, sd and rms of the difference, per quantity",
    )
    ap.add_argument(
        "--misfit",
        action="store_true",
        help="no fit: the noise-free error of the generator (every part, and each left "
        "out) against the fit's model with the true parameters, thermal rooms "
        "--first-rep .. --first-rep + --reps",
    )
    args = ap.parse_args(argv)
    variants = args.noise or ["ar1_white:estimate"]
    without = tuple(w for w in args.without.split(",") if w)
    parts = {"within_hour", "sky", "substeps"}
    if set(without) - parts:
        ap.error(f"--without: unknown {sorted(set(without) - parts)}; use {sorted(parts)}")
    if args.solar != "facade" and "sky" not in without:
        ap.error("--solar ghi: with --without sky (the generator's sky model is a facade's)")
    if args.paired:
        a, b = (read_logs([p]) for p in args.paired)
        print(f"paired z: {args.paired[0]} - {args.paired[1]}")
        for line in paired_lines(a, b):
            print(line)
        return 0
    if args.misfit:
        reps = range(args.first_rep, args.first_rep + args.reps)
        for line in misfit_lines(reps, args.seed):
            print(line)
        return 0
    if args.table:
        results = read_logs(args.table)
        print(
            f"SBC (independent generator) table of {' '.join(args.table)}: "
            f"{len(results)} replicates"
        )
        for v in sorted({v for r in results for v in r["variants"]}):
            if args.markdown:
                print(f"\nnoise model {v}:\n")
                lines = markdown_table(results, v)
            else:
                lines = table(results, v, QUANTITIES) + zscore_lines(results, v)
                lines += bias_lines(results, v) + solar_lines(results, v)
            for line in lines:
                print(line)
        return 0
    tasks = [
        (
            m,
            r,
            variants,
            args.seed,
            args.max_steps,
            CAL_DAYS,
            FLOOR,
            args.envelope_area or None,
            without,
            args.input_hold,
            args.noise_free,
            args.solar,
        )
        for r in range(args.first_rep, args.first_rep + args.reps)
        for m in args.models.split(",")
    ]
    t0 = time.perf_counter()
    results = run_tasks(replicate, tasks, args.jobs, args.log)
    print_study(
        results,
        variants,
        f"SBC (independent generator): {args.reps} replicates per model, "
        f"{time.perf_counter() - t0:.0f} s wall",
        QUANTITIES,
    )
    return 0


if __name__ == "__main__":
    if not KNMI.is_file():
        sys.exit(f"needs {KNMI}")
    sys.exit(main())
