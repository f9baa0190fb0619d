"""Rooms on the ground whose soil follows the season, generated without the package.

The generator of ``benchmarks/sbc_ground.py``. It imports numpy and nothing of
``heritage_bayes`` (``tests/test_sbc_ground.py`` checks this): its own weather, soil,
room and logger, so that a calibration that covers its truths is not covering its own
code.

Physics (SI units; temperatures [°C], capacities [J/K], conductances [W/K]):

- **weather**, on a 5-minute grid over the logger's year and a spin-up before it: the
  annual cycle ``T_m - A cos(2π (t - t_min)/Y)`` (Y = 365 d; T_m 8-12 °C, A 6-10 K,
  coldest day 5-35 of the year), a synoptic AR(1) (correlation time 4 days, sd 3 K), a
  daily cycle of 2-5 K and a within-hour AR(1) (30 min, 0.3 K).
- **soil**: a semi-infinite soil of its own thermal diffusivity α (log-uniform on
  0.3e-6-1.0e-6 m²/s: dry sand to wet clay) under a surface that follows the air. The
  annual harmonic reaches the depth ``z`` in closed form, damped by ``exp(-z/D)`` and
  late by ``z/(D ω)``, ``D = sqrt(2α/ω)`` (Carslaw & Jaeger 1959, §2.6); the surface's
  departures from that harmonic (the daily mean air temperature minus it, from the
  spin-up's start) are conducted down by an implicit finite-difference column (0.1 m
  cells to 30 m, daily steps, zero flux at the bottom) and added. The ground under the
  floor is the soil at the depth ``z``.
- **room**: one air-and-contents node ``C_i dT_i/dt = G_e (T_e - T_i) + G_f (T_f -
  T_i) + Q(t)``, ``Q`` an unmodelled heat gain (AR(1), correlation time 6 h, sd
  0.2-0.5 K × (G_e + G_f)): stepped exactly over each 5-minute step with the step's
  inputs held.
- **logger**: Ti at every full hour with white sensor noise (sd 0.05-0.15 K), rounded
  to 0.1 °C, 1 % of single readings lost and one outage of 3-10 days; the station's Te
  at the full hour rounded to 0.1 °C. Both are readings at an instant: the room's state
  at the hour, and the weather at the hour, which the 5-minute grid holds over the
  steps either side of it (the mean of the two). Taking the value of the step that
  starts at the hour instead (``reading="step_start"``) would read a weather that the
  room sees on average half a step (2.5 min) later than the reading says, a delay a fit
  takes up in its time constant.

The truths: the fit's parameters, the depth expressed as the **equivalent depth in the
fit's clay/silt soil** (α_ref 0.5e-6 m²/s, ISO 13370): ``z_f = z sqrt(α_ref/α)``, the
depth at which a soil of diffusivity α_ref damps and delays the annual cycle as this
soil does at ``z`` (only ``z/D`` enters the harmonic). ``z_f`` is drawn from the
fit's prior (log-normal, median 2 m, sd of log 0.5, within 0.5-6 m), ``C_i`` and
``G_f`` from the survey's log-normal priors (within two sd), ``G_e`` log-uniform on
30-300 W/K (its prior is the wide default). References: T. Kusuda, P.R. Achenbach,
ASHRAE Trans. 71 (1965) 61; H.S. Carslaw, J.C. Jaeger, Conduction of heat in solids
(1959) §2.6.
"""

from __future__ import annotations

import math

import numpy as np

DT = 300.0  # [s]: generator step
PER_HOUR = int(3600 / DT)
PER_DAY = 24 * PER_HOUR
YEAR = 365.0  # [d]: the generator's annual period
OMEGA = 2.0 * math.pi / (YEAR * 86400.0)  # [1/s]
#: diffusivity [m²/s] in which the fit expresses its depth (clay/silt, ISO 13370)
ALPHA_REF = 0.5e-6
#: the survey a user would give: a store of 80 m² on the ground, 5 m high (400 m³), 0.5
#: air changes per hour (``bench_sbc``'s hall)
VOLUME, ACH, FLOOR = 400.0, 0.5, 80.0
RHO_C_AIR = 1206.0  # [J/(m³ K)]
U_FLOOR = 0.4  # [W/(m² K)]: the median of the survey's ground prior
RECORD_DAYS = 365  # the logger's and the station's record
ZF_MEDIAN, ZF_SIGMA, ZF_BOUNDS = 2.0, 0.5, (0.5, 6.0)


def _ar1(rng, n: int, sd: float, tau_s: float, dt: float = DT) -> np.ndarray:
    """Stationary AR(1) of marginal sd ``sd`` and correlation time ``tau_s`` [s]."""
    a = math.exp(-dt / tau_s)
    z = rng.normal(0.0, sd * math.sqrt(1.0 - a * a), n)
    out = np.empty(n)
    acc = rng.normal(0.0, sd)
    for i in range(n):
        acc = a * acc + z[i] if i else acc
        out[i] = acc
    return out


def draw_truth(rng) -> dict:
    """The room's parameters and its soil (module docstring)."""

    def lognormal(median, sigma, lo=-2.0, hi=2.0):
        return median * math.exp(sigma * float(np.clip(rng.normal(), lo, hi)))

    zlo, zhi = (math.log(b / ZF_MEDIAN) / ZF_SIGMA for b in ZF_BOUNDS)
    zf = ZF_MEDIAN * math.exp(ZF_SIGMA * _truncated_normal(rng, zlo, zhi))
    alpha = math.exp(rng.uniform(math.log(0.3e-6), math.log(1.0e-6)))
    return {
        "Ci": lognormal(5.0 * RHO_C_AIR * VOLUME, 1.0),
        "Ge": math.exp(rng.uniform(math.log(30.0), math.log(300.0))),
        "Gf": lognormal(U_FLOOR * FLOOR, 1.0),
        "zf": zf,
        "alpha": alpha,
        "depth_m": zf * math.sqrt(alpha / ALPHA_REF),
    }


def _truncated_normal(rng, lo: float, hi: float) -> float:
    while True:
        x = float(rng.normal())
        if lo <= x <= hi:
            return x


def weather(rng, days: int, doy0: float) -> dict:
    """Outdoor air [°C] on the :data:`DT` grid over ``days`` from day-of-year ``doy0``,
    and its annual harmonic (``T_m``, ``A``, ``t_min`` [day of year])."""
    n = days * PER_DAY
    t_day = doy0 + np.arange(n) * DT / 86400.0
    t_m, amp, t_min = rng.uniform(8.0, 12.0), rng.uniform(6.0, 10.0), rng.uniform(5.0, 35.0)
    season = t_m - amp * np.cos(2 * math.pi * (t_day - t_min) / YEAR)
    daily = rng.uniform(2.0, 5.0) * np.sin(2 * math.pi * ((t_day % 1.0) * 24.0 - 9.0) / 24.0)
    within = _ar1(rng, n, 0.3, 1800.0)
    te = season + _ar1(rng, n, 3.0, 4 * 86400.0) + daily + within
    return {
        "Te": te,
        "day": t_day,
        "T_m": t_m,
        "A": amp,
        "t_min": t_min,
        "season": season,
        "within": within,
    }


def soil_temperature(w: dict, depth: float, alpha: float, anomaly: bool = True) -> np.ndarray:
    """The soil at ``depth`` [m] of diffusivity ``alpha`` [m²/s] on the weather grid
    (module docstring): the annual harmonic in closed form, plus the surface's
    departures from it conducted down a finite-difference column (``anomaly``)."""
    d = math.sqrt(2.0 * alpha / OMEGA)  # damping depth [m]
    arg = 2 * math.pi * (w["day"] - w["t_min"]) / YEAR - depth / d
    tf = w["T_m"] - w["A"] * math.exp(-depth / d) * np.cos(arg)
    if not anomaly:
        return tf
    days = w["Te"].size // PER_DAY
    surf = (w["Te"] - w["season"])[: days * PER_DAY].reshape(days, PER_DAY).mean(axis=1)
    dz, nz = 0.1, 300
    r = alpha * 86400.0 / dz**2
    # backward Euler: (1 + 2r) T_j - r (T_{j-1} + T_{j+1}) = T_j^old, T_0 = surface
    m = np.diag(np.full(nz, 1.0 + 2.0 * r)) - r * (np.eye(nz, k=1) + np.eye(nz, k=-1))
    m[-1, -2] = -2.0 * r  # zero flux at the bottom
    inv = np.linalg.inv(m)
    prof = np.zeros(nz)
    at = np.empty(days + 1)
    at[0] = 0.0
    depths = dz * np.arange(nz + 1)  # the surface, then the cells' depths
    for k in range(days):
        rhs = prof.copy()
        rhs[0] += r * surf[k]
        prof = inv @ rhs
        at[k + 1] = np.interp(depth, depths, np.concatenate(([surf[k]], prof)))
    t = np.arange(w["Te"].size) / PER_DAY
    return tf + np.interp(t, np.arange(days + 1), at)


def simulate(p: dict, te: np.ndarray, tf: np.ndarray, q: np.ndarray, ti0: float) -> np.ndarray:
    """Exact 5-minute steps of the room (inputs held over each step): Ti at each
    step's start [°C]."""
    g = p["Ge"] + p["Gf"]
    a = math.exp(-DT * g / p["Ci"])
    target = (p["Ge"] * te + p["Gf"] * tf + q) / g
    out = np.empty(te.size)
    x = ti0
    for k in range(te.size):
        out[k] = x
        x = a * x + (1.0 - a) * target[k]
    return out


def generate(seed, cal_days: int = 120, without: tuple = (), reading: str = "instant") -> dict:
    """One room: truths, the station's and the logger's hourly records.

    ``without``: parts left out (diagnosis): ``"anomaly"`` (the soil follows only the
    annual harmonic), ``"gain"`` (no unmodelled heat gain), ``"noise"`` (no sensor
    noise, rounding or lost readings; the outage stays), ``"outage"``, ``"synoptic"``
    (no synoptic weather nor daily cycle: the harmonic plus the within-hour
    fluctuation), ``"within_hour"`` (no within-hour fluctuation), ``"subhourly"`` (the
    weather linear between the full hours, what the fit's first-order hold assumes),
    ``"rounding"`` (readings not rounded). Leaving parts out keeps every random draw of
    the room. ``reading``: ``"instant"`` (the station reads the weather at the hour) or
    ``"step_start"`` (the 5-minute step's value that starts at the hour; the generator
    before the reading was corrected, for paired diagnosis).

    Returns a dict: ``truth`` (``Ci``, ``Ge``, ``Gf``, ``zf``), ``soil`` (``alpha``,
    ``depth_m``), ``climate`` (the harmonic's ``T_m``, ``A``, ``t_min``), ``hourly``
    (``Te`` station, ``Ti`` logger with NaN where lost, the noise-free ``Ti_true`` and
    ``Tf_true``, over every full hour of the record), ``rows`` (slice of the
    calibration hours), ``start_doy``.
    """
    rng = np.random.default_rng(seed)
    p = draw_truth(rng)
    spin = 120  # days of weather before the record (the soil's departures start there)
    doy0 = float(rng.uniform(0.0, 365.0))
    w = weather(rng, spin + RECORD_DAYS + 1, doy0 - spin)
    if "synoptic" in without:
        rng2 = np.random.default_rng([*np.atleast_1d(seed), 7])
        w["within"] = _ar1(rng2, w["Te"].size, 0.3, 1800.0)
        w["Te"] = w["season"] + w["within"]
    if "within_hour" in without:
        w["Te"] = w["Te"] - w["within"]
    if "subhourly" in without:  # linear between the full hours (what the fit assumes):
        k = np.arange(w["Te"].size)  # each step holds the line's mean over it
        w["Te"] = np.interp(k + 0.5, k[::PER_HOUR], w["Te"][::PER_HOUR])
    tf = soil_temperature(w, p["depth_m"], p["alpha"], "anomaly" not in without)
    g = p["Ge"] + p["Gf"]
    q = _ar1(rng, w["Te"].size, rng.uniform(0.2, 0.5) * g, 6 * 3600.0)
    if "gain" in without:
        q[:] = 0.0
    ti = simulate(p, w["Te"], tf, q, float((p["Ge"] * w["Te"][0] + p["Gf"] * tf[0]) / g))
    at = spin * PER_DAY + np.arange(RECORD_DAYS * 24 + 1) * PER_HOUR
    at = at[at < w["Te"].size]
    hours = at.size
    ti_true, te = ti[at], w["Te"][at]
    if reading == "instant":  # the weather at the hour: between the steps either side
        te = 0.5 * (w["Te"][at - 1] + w["Te"][at])
    sd = rng.uniform(0.05, 0.15)
    e = rng.normal(0.0, sd, hours)
    lost = rng.random(hours) < 0.01
    cal0 = int(rng.integers(0, RECORD_DAYS - cal_days)) * 24
    rows = slice(cal0, cal0 + cal_days * 24)
    g_len = int(rng.integers(3 * 24, 10 * 24 + 1))
    g0 = rows.start + int(rng.integers(7 * 24, cal_days * 24 - g_len - 7 * 24))
    ti_obs = ti_true.copy()
    if "noise" not in without:
        ti_obs = ti_true + e if "rounding" in without else np.round(ti_true + e, 1)
        lost[[0, -1]] = False
        ti_obs[lost] = np.nan
    if "outage" not in without:
        ti_obs[g0 : g0 + g_len] = np.nan
    truth = {k: p[k] for k in ("Ci", "Ge", "Gf", "zf")}
    return {
        "truth": truth,
        "soil": {"alpha": p["alpha"], "depth_m": p["depth_m"]},
        "climate": {"T_m": w["T_m"], "A": w["A"], "t_min": w["t_min"]},
        "hourly": {
            "Te": te if "rounding" in without else np.round(te, 1),
            "Ti": ti_obs,
            "Ti_true": ti_true,
            "Tf_true": tf[at],
        },
        "rows": rows,
        "start_doy": doy0,
        "sensor_sd": sd,
        "gap": (g0, g_len),
    }


def quantities(p: dict) -> dict:
    """The ranked quantities from parameters by the fit's names (arrays of draws or
    floats): ``tau_1_h`` [h], ``gain_Ti_Te`` [-] (the static gain from the outdoor
    air; 1 - the gain from the ground), ``zf`` [m], and for the record ``Gf`` [W/K]
    and ``Ci`` [J/K] (absolute: their scale is the survey's)."""
    ci, ge, gf = (np.asarray(p[k], dtype=float) for k in ("Ci", "Ge", "Gf"))
    return {
        "tau_1_h": ci / (ge + gf) / 3600.0,
        "gain_Ti_Te": ge / (ge + gf),
        "zf": np.asarray(p["zf"], dtype=float),
        "Gf": gf,
        "Ci": ci,
    }
