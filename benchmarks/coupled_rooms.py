"""Rooms with sorbing buffers and vapour sinks, generated without the package.

The generator of ``benchmarks/sbc_coupled.py``. It imports numpy and nothing of
``heritage_bayes`` (``tests/test_sbc_coupled.py`` checks this): its own saturation
pressure, weather, sun, isotherm and integrator, so that a calibration that covers its
truths is not covering its own code.

Physics (SI units; vapour pressures [Pa], moisture [kg], temperatures [°C]):

- **weather**, on a 150 s grid: the annual cycle of the outdoor temperature, a synoptic
  AR(1) (correlation time 3 days, sd 3 K), a daily cycle whose amplitude follows an
  AR(1) cloudiness, and a within-hour AR(1) (30 min, 0.3 K); the dew point follows the
  day-smoothed temperature less an AR(1) depression, with a within-hour fluctuation of
  the vapour pressure (30 min, 10 Pa); the sun's elevation from the declination and
  the hour angle (latitude 52° N, solar time).
- **attic** (fitted by ``hygric_2c_sorption``): the indoor air temperature is the
  outdoor one plus a solar excess through a first-order roof response (3-8 h); a wood
  buffer of dry mass ``M`` [kg] whose moisture content ``u`` follows the GAB isotherm
  ``u(φ) = u_m C K φ / ((1 - Kφ)(1 - Kφ + C K φ))`` (Anderson, 1946; parameters of
  softwood, u_m 0.05-0.07, C 5-10, K 0.72-0.82) at the air's temperature:
  ``dm/dt = G_i (p_i - φ_w p_sat(T_i))``, ``C_i dp_i/dt = G_fast (p_e - p_i) +
  G_i (φ_w p_sat(T_i) - p_i) + s(t)``, with ``s`` an unmodelled moisture source
  (AR(1), correlation time 2 h, zero mean).
- **cellar** (fitted by ``hygric_2c_fixed`` with ``sink: temperature``): a wall buffer
  with the same isotherm at the wall's constant temperature (2 K above the air's mean),
  linked to outdoors (``G_w``) and to the air (``G_i``); a ground sink at
  ``φ_f p_sat(T_f)`` through ``G_f``, ``T_f`` the ground at about 1.5 m (the annual
  cycle damped to 0.2-0.4 and lagged 30-60 days, Kusuda & Achenbach 1965); the air
  temperature between the ground's and the slowly filtered outdoor one.
- **integration**: classical Runge-Kutta of order 4 with 5-minute steps (the weather
  at the steps' ends and middles), the isotherm inverted in closed form each stage.
- **logger**: the indoor temperature and relative humidity read at every full hour
  with white sensor noise (0.1 K; 0.5-1.0 %RH), rounded to 0.1 °C and 0.1 %RH, with
  a 2-7 day outage and 1 % of single readings lost; the station's outdoor temperature
  and relative humidity at the full hour, rounded to 0.1 °C and 1 %RH; the ground
  temperature (cellar) hourly, rounded to 0.1 °C.

The truths are the physical parameters, with the buffer's capacity taken where the
nonlinear isotherm puts it. The buffer's RH obeys ``dφ_w/dt = J(t) / (M u'(φ_w))``
(``J`` the vapour flux into it [kg/s]): its rate is the inverse of the local capacity
``M u'(φ_w)``. A model with one constant capacity follows it, to first order in the
slope's variation (the averaging of a slowly varying rate), when ``1/C_m`` is the time
mean of ``1 / (M u'(φ_w(t)))`` over the calibration period: the truth is that
**harmonic mean** of the slope along the buffer's trajectory, per unit surface RH [kg]
(the cellar's ``C_w = C_m / p_sat(T_wall)`` [kg/Pa]); the arithmetic mean, larger by
Jensen's inequality where the buffer's RH moves, is kept for the record
(``capacity_means``). References: R.B. Anderson, J. Am. Chem. Soc. 68 (1946) 686
(GAB); T. Kusuda, P.R. Achenbach, ASHRAE Trans. 71 (1965) 61; O.A. Alduchov, R.E.
Eskridge, J. Appl. Meteor. 35 (1996) 601 (Magnus form of p_sat).
"""

from __future__ import annotations

import math

import numpy as np

#: seconds per generator weather sample and per Runge-Kutta step
DT_W = 150.0
DT_RK = 300.0
PER_HOUR = int(3600 / DT_RK)  # RK steps per hour
#: latitude of the synthetic site [°N]
LATITUDE = 52.0
#: gas constant of water vapour [J/(kg·K)] (the air node's capacity per m³)
R_V = 461.5
#: the survey a user would give (400 m³ hall at 0.5 air changes per hour)
VOLUME, ACH = 400.0, 0.5
FLOOR, ENVELOPE = 80.0, 259.0  # [m²]: the cellar's floor on soil, its walls and roof
ROOMS = ("attic", "cellar")


def psat(t):
    """Saturation vapour pressure over water [Pa] at ``t`` [°C] (Magnus form,
    Alduchov & Eskridge 1996: 610.94 exp(17.625 t / (t + 243.04)))."""
    t = np.asarray(t, dtype=float)
    return 610.94 * np.exp(17.625 * t / (t + 243.04))


# --------------------------------------------------------------------------- isotherm
def gab(phi, um, c, k):
    """GAB moisture content [kg/kg] at relative humidity ``phi`` [-]."""
    x = k * phi
    return um * c * x / ((1.0 - x) * (1.0 - x + c * x))


def gab_slope(phi, um, c, k):
    """du/dφ of :func:`gab` [kg/kg per unit RH]."""
    x = k * phi
    d = (1.0 - x) * (1.0 + (c - 1.0) * x)
    dd = (c - 2.0) - 2.0 * (c - 1.0) * x  # d(d)/dx
    return um * c * k * (d - x * dd) / (d * d)


def gab_inverse(u, um, c, k):
    """Relative humidity [-] of moisture content ``u`` [kg/kg] (the positive root of
    u (C-1) x² + (u_m C - u (C-2)) x - u = 0, x = Kφ)."""
    a = u * (c - 1.0)
    b = um * c - u * (c - 2.0)
    return (-b + math.sqrt(b * b + 4.0 * a * u)) / (2.0 * a) / k


# --------------------------------------------------------------------------- weather
def _ar1(rng, n: int, sd: float, tau_s: float, dt: float = DT_W) -> np.ndarray:
    """Stationary AR(1) of marginal sd ``sd`` and correlation time ``tau_s`` [s]."""
    a = math.exp(-dt / tau_s)
    z = rng.normal(0.0, sd * math.sqrt(1.0 - a * a), n)
    z[0] = rng.normal(0.0, sd)
    out = np.empty(n)
    acc = 0.0
    for i in range(n):
        acc = a * acc + z[i] if i else z[0]
        out[i] = acc
    return out


def _smooth(x: np.ndarray, tau_s: float, dt: float = DT_W) -> np.ndarray:
    """First-order low-pass of ``x`` (time constant ``tau_s`` [s]), from ``x[0]``."""
    a = math.exp(-dt / tau_s)
    out = np.empty_like(x)
    acc = x[0]
    for i in range(x.size):
        acc = a * acc + (1.0 - a) * x[i]
        out[i] = acc
    return out


def sun_elevation_sine(t_s: np.ndarray, doy0: float) -> np.ndarray:
    """sin of the sun's elevation (clipped at 0) at ``t_s`` [s] after local solar
    midnight of day-of-year ``doy0`` (declination: Cooper 1969)."""
    doy = doy0 + t_s / 86400.0
    dec = np.radians(23.44) * np.sin(2 * np.pi * (284.0 + doy) / 365.0)
    omega = 2 * np.pi * ((t_s / 3600.0) % 24.0 - 12.0) / 24.0
    lat = math.radians(LATITUDE)
    s = np.sin(lat) * np.sin(dec) + np.cos(lat) * np.cos(dec) * np.cos(omega)
    return np.clip(s, 0.0, None)


def weather(rng, days: int, doy0: float) -> dict:
    """Outdoor weather on the :data:`DT_W` grid over ``days`` from day-of-year ``doy0``:
    ``Te`` [°C], ``Pe`` [Pa], ``sun`` (clear-sky elevation sine × (1 - 0.75
    cloudiness)) [-], the site's annual mean ``T_mean`` and amplitude ``A_year`` [°C]."""
    n = int(days * 86400 / DT_W) + 1
    t = np.arange(n) * DT_W
    doy = doy0 + t / 86400.0
    t_mean, a_year = rng.uniform(8.0, 13.0), rng.uniform(7.0, 10.0)
    season = t_mean - a_year * np.cos(2 * np.pi * (doy - 15.0) / 365.0)
    cloud = 1.0 / (1.0 + np.exp(-_ar1(rng, n, 1.5, 2 * 86400.0)))
    sun = sun_elevation_sine(t, doy0) * (1.0 - 0.75 * cloud)
    daily = (2.0 + 5.0 * (1.0 - cloud)) * np.sin(2 * np.pi * ((t / 3600.0) % 24.0 - 9.0) / 24.0)
    te_slow = season + _ar1(rng, n, 3.0, 3 * 86400.0)
    te = te_slow + daily + _ar1(rng, n, 0.3, 1800.0)
    depression = 1.0 + np.abs(2.0 + _ar1(rng, n, 1.5, 2 * 86400.0))
    td = np.minimum(_smooth(te_slow, 86400.0) - depression, te - 0.5)
    pe = psat(td) + _ar1(rng, n, 10.0, 1800.0)
    return {"Te": te, "Pe": pe, "sun": sun, "T_mean": t_mean, "A_year": a_year, "doy": doy}


# --------------------------------------------------------------------------- rooms
def draw_truth(room: str, rng) -> dict:
    """The physical parameters of a room (module docstring): air capacity and
    ventilation near the survey's (log-normal, sd 0.5 of log around 10 × the air's
    capacity of :data:`VOLUME` and its :data:`ACH`), buffer conductances log-uniform,
    the isotherm, the buffer's dry mass (log-uniform in ``M du/dφ`` at 65 % RH), the
    sink's RH uniform on 0.7-1.0 and its conductance log-normal around a floor of
    :data:`FLOOR` with s_d 0.5 m (sd 1 of log)."""
    air = VOLUME / (R_V * 288.15)  # [kg/Pa]
    p = {
        "Ci": 10.0 * air * math.exp(rng.normal(0.0, 0.5)),
        "Gfast": air * ACH / 3600.0 * math.exp(rng.normal(0.0, 0.5)),
        "Gi": math.exp(rng.uniform(math.log(3e-7), math.log(3e-6))),
        "um": rng.uniform(0.05, 0.07),
        "C": rng.uniform(5.0, 10.0),
        "K": rng.uniform(0.72, 0.82),
    }
    # buffer capacity at 65 % RH [kg per unit RH]: a wooden roof (attic) or a wall's
    # surface layer (cellar)
    lo, hi = (20.0, 300.0) if room == "attic" else (100.0, 1000.0)
    cm65 = math.exp(rng.uniform(math.log(lo), math.log(hi)))
    p["M"] = cm65 / gab_slope(0.65, p["um"], p["C"], p["K"])
    if room == "cellar":
        p["Gw"] = math.exp(rng.uniform(math.log(5e-9), math.log(5e-8)))
        p["Gf"] = 2e-10 / 0.5 * FLOOR * math.exp(rng.normal(0.0, 1.0))
        p["phi_f"] = rng.uniform(0.7, 1.0)
    elif room != "attic":
        raise ValueError(f"room must be one of {ROOMS} (got {room!r})")
    return p


def indoor_temperature(room: str, rng, w: dict) -> tuple[np.ndarray, np.ndarray | None]:
    """True indoor air temperature [°C] on the weather grid, and the ground's (cellar)."""
    if room == "attic":
        excess = rng.uniform(8.0, 15.0) * w["sun"]  # roof's solar excess [K]
        return _smooth(w["Te"] + excess, rng.uniform(3.0, 8.0) * 3600.0), None
    damp, lag = rng.uniform(0.2, 0.4), rng.uniform(30.0, 60.0)
    tf = w["T_mean"] - damp * w["A_year"] * np.cos(2 * np.pi * (w["doy"] - 15.0 - lag) / 365.0)
    ti = 0.6 * tf + 0.4 * _smooth(w["Te"], 2 * 86400.0)
    return ti, tf


def wall_temperature(ti: np.ndarray) -> float:
    """The cellar wall's constant temperature [°C]: 2 K above the air's mean over the
    record (the wall lags the ground, which lies below the air in summer)."""
    return float(np.mean(ti)) + 2.0


def simulate(room: str, p: dict, w: dict, ti, tf, source, linear=None) -> dict:
    """Runge-Kutta 4 of the room (module docstring) on steps of :data:`DT_RK`: the air's
    vapour pressure ``pi`` [Pa] and the buffer's RH ``phi_w`` [-] at every step's start.

    Attic: the buffer at the air temperature ``ti``; cellar: at the constant
    :func:`wall_temperature`, with the sink at ``phi_f p_sat(tf)``. ``source``
    [kg/s] on the weather grid. Starts from the buffer in equilibrium with the first
    day's mean outdoor vapour pressure and the air at the outdoor one. ``linear``
    (a0, a1): the linear isotherm u = a0 + a1 φ instead of the GAB."""
    um, c, k, mass = p["um"], p["C"], p["K"], p["M"]
    if linear is None:

        def content(phi):
            return gab(phi, um, c, k)

        def rh(u):
            return gab_inverse(u, um, c, k)

    else:

        def content(phi):
            return linear[0] + linear[1] * phi

        def rh(u):
            return (u - linear[0]) / linear[1]

    ci, gfast, gi = p["Ci"], p["Gfast"], p["Gi"]
    gw = p.get("Gw", 0.0)
    gf = p.get("Gf", 0.0)
    pe = w["Pe"]
    sub = int(DT_RK / DT_W)
    day = int(86400 / DT_W)
    if room == "attic":
        ps_w = psat(ti)
        sink = np.zeros_like(pe)
    else:
        ps_w = np.full(pe.size, float(psat(wall_temperature(ti))))
        sink = p["phi_f"] * psat(tf)
    phi0 = min(float(np.mean(pe[:day] / ps_w[:day])), 0.95)
    m = mass * content(phi0)
    pi = float(pe[0])
    n = (pe.size - 1) // sub
    out_pi = np.empty(n)
    out_phi = np.empty(n)

    def rates(m, pi, j):
        phi = rh(m / mass)
        pw = phi * ps_w[j]
        dm = gi * (pi - pw) + gw * (pe[j] - pw)
        dpi = (gfast * (pe[j] - pi) + gi * (pw - pi) + gf * (sink[j] - pi) + source[j]) / ci
        return dm, dpi, phi

    h = DT_RK
    for s in range(n):
        j = s * sub
        k1m, k1p, phi = rates(m, pi, j)
        out_pi[s], out_phi[s] = pi, phi
        k2m, k2p, _ = rates(m + 0.5 * h * k1m, pi + 0.5 * h * k1p, j + 1)
        k3m, k3p, _ = rates(m + 0.5 * h * k2m, pi + 0.5 * h * k2p, j + 1)
        k4m, k4p, _ = rates(m + h * k3m, pi + h * k3p, j + 2)
        m += h / 6.0 * (k1m + 2 * k2m + 2 * k3m + k4m)
        pi += h / 6.0 * (k1p + 2 * k2p + 2 * k3p + k4p)
    return {"pi": out_pi, "phi_w": out_phi}


def generate(
    room: str,
    seed,
    cal_days: int = 90,
    max_spin_days: int = 28,
    without: tuple = (),
    source_seed=None,
) -> dict:
    """One room: truths, the station's and the logger's hourly records.

    ``seed``: anything :func:`numpy.random.default_rng` takes. ``without``: parts left
    out (diagnosis): ``"isotherm"`` (a linear isotherm through the GAB's 65 % RH point:
    the fitted model's own buffer), ``"source"`` (no moisture source), ``"noise"`` (no
    sensor noise, rounding or lost readings; the outage stays), ``"outage"`` (no
    outage). Leaving parts out keeps every random draw of the room. ``source_seed``
    (diagnosis): the moisture source redrawn from its own generator with this seed, every
    other draw of the room kept (the same room under another realisation of its source).

    Returns a dict: ``truth`` (the fit's parameters by name, the buffer's capacity
    the harmonic mean of ``M u'(φ_w)`` over the calibration period; module docstring),
    ``capacity_means`` (its ``harmonic`` and ``arithmetic`` means [kg per unit RH]),
    ``generator`` (the drawn physical parameters), ``hourly`` (dict of arrays over
    every full hour from the start: ``Te``, ``RHe`` [%] (station, rounded), ``Ti``,
    ``RHi`` [%] (logger, NaN where lost), ``Tf`` (cellar), and the noise-free
    ``Pi_true``, ``Ti_true``), ``rows`` (slice of the calibration hours),
    ``start_doy``, ``Tf_mean`` (cellar: the ground's mean over the calibration hours
    [°C]) and ``wall_psat`` (cellar: p_sat at the wall [Pa]), ``start`` (the buffer's
    RH and the air's vapour pressure at the record's start) and the buffer's RH range
    over the calibration hours.
    """
    rng = np.random.default_rng(seed)
    p = draw_truth(room, rng)
    lin = None
    if "isotherm" in without:  # linear through the 65 % point: the same capacity
        u65, s65 = gab(0.65, p["um"], p["C"], p["K"]), gab_slope(0.65, p["um"], p["C"], p["K"])
        lin = (u65 - s65 * 0.65, s65)
    spin = int(rng.integers(7, max_spin_days + 1))
    days = spin + cal_days + 1
    doy0 = float(rng.uniform(0.0, 365.0))
    w = weather(rng, days, doy0)
    ti, tf = indoor_temperature(room, rng, w)
    air = VOLUME / (R_V * 288.15)
    g_all = p["Gfast"] + p["Gi"] + p.get("Gf", 0.0)
    src_sd = rng.uniform(10.0, 25.0) * g_all  # [kg/s]: 10-25 Pa at the air node
    source = _ar1(rng, w["Pe"].size, src_sd, 7200.0)
    if source_seed is not None:  # drawn after the room's own: its later draws are kept
        source = _ar1(np.random.default_rng(source_seed), w["Pe"].size, src_sd, 7200.0)
    if "source" in without:
        source[:] = 0.0
    sim = simulate(room, p, w, ti, tf, source, lin if "isotherm" in without else None)
    hours = sim["pi"].size // PER_HOUR
    sub_h = int(3600 / DT_W)
    at = np.arange(hours) * sub_h  # weather grid index of every full hour
    pi_true = sim["pi"][::PER_HOUR][:hours]
    ti_true = ti[at]
    rows = slice(spin * 24, (spin + cal_days) * 24)
    quiet = "noise" in without
    sd_t, sd_rh = 0.1, rng.uniform(0.5, 1.0)
    rhi = 100.0 * pi_true / psat(ti_true)
    # drawn whether used or not: without the noise the room keeps its outage's draws
    e_t, e_rh = rng.normal(0.0, sd_t, hours), rng.normal(0.0, sd_rh, hours)
    lost = rng.random(hours) < 0.01
    ti_obs = ti_true + (0.0 if quiet else e_t)
    rhi_obs = rhi + (0.0 if quiet else e_rh)
    if not quiet:
        ti_obs, rhi_obs = np.round(ti_obs, 1), np.round(np.clip(rhi_obs, 0.0, 100.0), 1)
        lost[[0, -1]] = False  # the record's ends are read
        ti_obs[lost] = np.nan
        rhi_obs[lost] = np.nan
    g_len = int(rng.integers(2 * 24, 7 * 24 + 1))
    g0 = rows.start + int(rng.integers(7 * 24, cal_days * 24 - g_len - 7 * 24))
    if "outage" not in without:
        ti_obs[g0 : g0 + g_len] = np.nan
        rhi_obs[g0 : g0 + g_len] = np.nan
    te = w["Te"][at]
    hourly = {
        "Te": np.round(te, 1),
        "RHe": np.round(np.clip(100.0 * w["Pe"][at] / psat(te), 1.0, 100.0)),
        "Ti": ti_obs,
        "RHi": rhi_obs,
        "Pi_true": pi_true,
        "Ti_true": ti_true,
    }
    # the buffer's capacity where the isotherm puts it, averaged over the calibration
    steps = slice(rows.start * PER_HOUR, rows.stop * PER_HOUR)
    phi_cal = sim["phi_w"][steps]
    if "isotherm" in without:
        cm = p["M"] * lin[1]
        means = {"harmonic": cm, "arithmetic": cm}
    else:
        slope = p["M"] * gab_slope(phi_cal, p["um"], p["C"], p["K"])
        means = {"harmonic": float(1.0 / np.mean(1.0 / slope)), "arithmetic": float(slope.mean())}
        cm = means["harmonic"]
    truth = {"Ci": p["Ci"], "Gi": p["Gi"], "Gfast": p["Gfast"]}
    out = {"rows": rows, "start_doy": doy0, "spin_days": spin, "source_sd": src_sd / g_all}
    if room == "attic":
        truth["Cm"] = cm
    else:
        hourly["Tf"] = np.round(tf[at], 1)
        truth.update(
            Cw=cm / float(psat(wall_temperature(ti))), Gw=p["Gw"], Gf=p["Gf"], phi_f=p["phi_f"]
        )
        out["Tf_mean"] = float(np.mean(tf[at][rows]))
        out["wall_psat"] = float(psat(wall_temperature(ti)))
    out.update(
        truth=truth,
        generator={k: float(v) for k, v in p.items()},
        hourly=hourly,
        phi_w_range=(float(phi_cal.min()), float(phi_cal.max())),
        start={"phi_w": float(sim["phi_w"][0]), "pi": float(sim["pi"][0])},
        capacity_means=means,
        noise_truth={"sd_T": sd_t, "sd_RH": float(sd_rh)},
        gap=(g0, g_len),
        air_capacity=air,
    )
    return out


# --------------------------------------------------------------------------- quantities
def network_quantities(room: str, p: dict, tf_mean: float | None = None) -> dict:
    """The quantities ranked by the study, from parameters by the fit's names (arrays
    of draws or floats): the buffer's capacity in [kg/Pa] at 15 °C (``Cm /
    p_sat(15 °C)`` for the attic), then the two-node network's time constants
    ``tau1_h``, ``tau2_h`` [h], and:

    attic: ``buffer_share`` = G_i/(G_i + G_fast) [-] (the share of the air's vapour
    exchange that goes to the buffer), ``buffer_hours`` = C_m / (p_sat(15 °C) G_fast)
    / 3600 [h] (the buffer's capacity in hours of ventilation), ``Cm`` [kg] (absolute:
    its scale is the survey's, through the priors of C_i and G_fast);

    cellar: ``gain_Pe`` [-] the static gain of the air from the outdoor vapour
    pressure, ``phi_f`` [-], ``sink_pull_Pa`` = (1 - gain_Pe) φ_f p_sat(T_f,mean)
    [Pa] (the sink's share of the mean indoor vapour pressure), ``buffer_hours`` =
    C_w / G_fast / 3600 [h].
    """
    ci, gi, gfast = (np.asarray(p[k], dtype=float) for k in ("Ci", "Gi", "Gfast"))
    if room == "attic":
        cw = np.asarray(p["Cm"], dtype=float) / float(psat(15.0))
        gw = gf = np.zeros_like(ci)
    else:
        cw, gw, gf = (np.asarray(p[k], dtype=float) for k in ("Cw", "Gw", "Gf"))
    # A = -C^-1 G of the network (buffer, air): its eigenvalues in closed form
    a11, a12 = (gw + gi) / cw, -gi / cw
    a21, a22 = -gi / ci, (gi + gfast + gf) / ci
    tr, det = a11 + a22, a11 * a22 - a12 * a21
    disc = np.sqrt(np.maximum(tr * tr / 4.0 - det, 0.0))
    lam_slow, lam_fast = tr / 2.0 - disc, tr / 2.0 + disc
    out = {"tau1_h": 1.0 / lam_slow / 3600.0, "tau2_h": 1.0 / lam_fast / 3600.0}
    out["buffer_hours"] = cw / gfast / 3600.0
    if room == "attic":
        out["buffer_share"] = gi / (gi + gfast)
        out["Cm"] = np.asarray(p["Cm"], dtype=float)
        return out
    # steady state: G x = (gw Pe, gfast Pe): the air's gain from Pe
    g11, g22 = gw + gi, gi + gfast + gf
    gain = (gi * gw + g11 * gfast) / (g11 * g22 - gi * gi)
    out["gain_Pe"] = gain
    out["phi_f"] = np.asarray(p["phi_f"], dtype=float)
    out["sink_pull_Pa"] = (1.0 - gain) * out["phi_f"] * float(psat(tf_mean))
    return out
