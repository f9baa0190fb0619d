"""Does the calibrated model reproduce the room? Accuracy rules and the residuals' shape.

Pure functions on the run's ``summary.json`` and on residual series; the verdict
(:mod:`heritage_bayes.report.verdict`) turns them into its level and words.

- :func:`accuracy_failures`: the measured outputs whose fit fails the accuracy rule
  (FIT below :data:`MIN_FIT` on the validation period, or on the calibration period when
  there is none; a 90 % predictive band covering less than :data:`MIN_COVERAGE90` of the
  validation hours). A series that varies within a few sensor resolutions
  (:func:`nearly_constant`) is exempt from the FIT rule: FIT divides the error by the
  series' spread, which is then mostly sensor quantisation.
- :func:`residual_shape`: the mean daily cycle and the slow part (day means) of a
  residual series, measured against the measured series' own daily cycle and spread.
- :func:`missing_physics`: the most likely missing physics, in words, from those shapes
  and the model-order ladder (a rung that fits clearly better).

The signatures follow the usual reading of residuals of grey-box building models
(Bacher & Madsen 2011): a residual cycle locked to the day is an input the model lacks
or scales wrongly (for temperatures, the sun), a slow excursion of the day means is a
missing state (a slower node), a control (thermostat, humidistat) or a fixed sink.

References
----------
.. [1] P. Bacher and H. Madsen, "Identifying suitable models for the heat dynamics of
   buildings", Energy and Buildings 43 (2011) 1511-1522.
   doi:10.1016/j.enbuild.2011.02.005
"""

from __future__ import annotations

import math

import numpy as np

from heritage_bayes.rundir.summary import FitMetrics, RunSummary, typed_summary

__all__ = [
    "DAILY_CYCLE_RATIO",
    "DRIFT_RATIO",
    "LADDER_MARGIN",
    "MIN_COVERAGE90",
    "MIN_FIT",
    "NEARLY_CONSTANT_RESOLUTIONS",
    "SENSOR_RESOLUTION",
    "accuracy_failures",
    "missing_physics",
    "nearly_constant",
    "residual_shape",
    "resolutions",
]

#: [%] FIT (validation, else calibration) below which the model does not reproduce the room.
MIN_FIT = 50.0
#: [-] share of the validation hours the 90 % predictive band must cover at least.
MIN_COVERAGE90 = 0.75
#: A series whose standard deviation is at most this many sensor resolutions is
#: "nearly constant": FIT says nothing about accuracy there.
NEARLY_CONSTANT_RESOLUTIONS = 5.0
#: Typical resolution of the loggers the package reads: [°C] for Ti, [%RH] for RHi.
#: The vapour pressure's is derived: 1 %RH of the saturation pressure (:func:`resolutions`).
SENSOR_RESOLUTION = {"Ti": 0.1, "RHi": 1.0}
#: [Pa] 1 %RH of the saturation vapour pressure at 15 °C: Pi's resolution without RH data.
_PI_RESOLUTION_DEFAULT = 17.0
#: [-] a "strong" residual daily cycle: its amplitude at least this share of the
#: measured series' daily cycle (and at least one sensor resolution).
DAILY_CYCLE_RATIO = 0.2
#: [-] a "slow drift": the RMS of the residuals' day means at least this share of the
#: measured series' standard deviation.
DRIFT_RATIO = 0.5
#: [percentage points] a ladder rung fits "clearly better" by at least this much FIT.
LADDER_MARGIN = 10.0
#: Unit of a difference of each output, for the words.
_DIFF_UNITS = {"Ti": " K", "Pi": " Pa", "RHi": " %RH"}
#: Hours of daylight in local solar time in which a sun-driven residual peaks.
_SUN_HOURS = (9, 20)


def resolutions(observed: dict) -> dict[str, float]:
    """Sensor resolution per output [unit of the output].

    ``observed``: output name -> measured array. Ti and RHi take
    :data:`SENSOR_RESOLUTION`; Pi's is 1 %RH of the saturation pressure, taken from
    the measured pair as the median of Pi / RHi [Pa per %RH] (17 Pa without RH).
    """
    out = dict(SENSOR_RESOLUTION)
    pi, rh = observed.get("Pi"), observed.get("RHi")
    res = _PI_RESOLUTION_DEFAULT
    if pi is not None and rh is not None:
        pi, rh = np.asarray(pi, dtype=float), np.asarray(rh, dtype=float)
        ok = np.isfinite(pi) & np.isfinite(rh) & (rh > 1.0)
        if ok.sum() >= 24:
            res = float(np.median(pi[ok] / rh[ok]))
    out["Pi"] = res
    return out


def nearly_constant(sd, resolution) -> bool:
    """True when a series' standard deviation ``sd`` is within
    :data:`NEARLY_CONSTANT_RESOLUTIONS` sensor resolutions."""
    try:
        sd, resolution = float(sd), float(resolution)
    except (TypeError, ValueError):
        return False
    if not (math.isfinite(sd) and math.isfinite(resolution)) or resolution <= 0:
        return False
    return sd <= NEARLY_CONSTANT_RESOLUTIONS * resolution


def _judged_period(per: dict[str, FitMetrics]) -> str | None:
    """The period whose FIT judges the model: validation, else calibration."""
    for p in ("validation", "calibration"):
        if p in per and per[p].FIT is not None:
            return p
    return None


def accuracy_failures(summary: RunSummary | dict, resolutions: dict | None = None) -> list[dict]:
    """The measured outputs the model does not reproduce (empty: all pass).

    Returns
    -------
    list of dict
        Per failing output: ``section``, ``output``, ``period`` (the period judged),
        ``fit`` [%] (None if not judged), ``coverage90`` [-] (None if not failing) and
        ``text`` (the failure in words).
    """
    res = resolutions or {}
    out = []
    for (sec, o), per in typed_summary(summary).metrics_by_output().items():
        reasons, fit_bad, cov_bad = [], None, None
        p = _judged_period(per)
        if p is not None:
            m = per[p]
            fit = float(m.FIT)
            if fit < MIN_FIT and not nearly_constant(m.SD, res.get(o)):
                fit_bad = fit
                reasons.append(f"FIT {fit:.1f} % on the {p} period (at least {MIN_FIT:g} %)")
        cov = per["validation"].coverage90 if "validation" in per else None
        if cov is not None and cov < MIN_COVERAGE90:
            cov_bad = float(cov)
            reasons.append(
                f"the 90 % band covers {100 * cov_bad:.1f} % of the validation hours "
                f"(at least {100 * MIN_COVERAGE90:.0f} %)"
            )
        if reasons:
            out.append(
                {
                    "section": sec,
                    "output": o,
                    "period": p,
                    "fit": fit_bad,
                    "coverage90": cov_bad,
                    "text": f"{o} ({sec}): " + " and ".join(reasons),
                }
            )
    return out


def _daily_profile(x: np.ndarray, solar_hour: np.ndarray) -> np.ndarray:
    """Mean by hour of (local solar) day of ``x`` minus its 24-hour running mean."""
    import pandas as pd

    s = pd.Series(x)
    fast = (s - s.rolling(24, center=True, min_periods=12).mean()).to_numpy()
    ok = np.isfinite(fast)
    prof = np.full(24, np.nan)
    h = np.floor(solar_hour).astype(int) % 24
    for k in range(24):
        sel = ok & (h == k)
        if sel.any():
            prof[k] = fast[sel].mean()
    return prof


def residual_shape(
    resid: np.ndarray,
    measured: np.ndarray,
    times: np.ndarray,
    *,
    longitude: float | None = None,
    resolution: float | None = None,
) -> dict | None:
    """The daily cycle and the slow drift of hourly residuals (measured − model).

    Parameters
    ----------
    resid, measured : (N,) arrays
        Residuals and the measured series [unit of the output]; NaN = missing.
    times : (N,) datetime64 array
        UTC stamps (hourly).
    longitude : float, optional
        Site longitude [°, east positive]: hours are read in local solar time
        (UTC + longitude / 15 h); UTC without it.
    resolution : float, optional
        Sensor resolution [unit]: a daily cycle below one resolution is not strong.

    Returns
    -------
    dict or None
        ``daily_amplitude`` (half the peak-to-peak of the residuals' mean daily cycle
        around their 24-h running mean), ``measured_daily_amplitude`` (the same of the
        measured series), ``peak_hour`` (solar hour of the residual cycle's maximum),
        ``drift`` (RMS of the residuals' 24-h running mean: the slow misfit),
        ``measured_sd``, and the judgements ``daily`` (``daily_amplitude`` ≥
        :data:`DAILY_CYCLE_RATIO` × the measured cycle and ≥ 1 resolution), ``sunlit``
        (the residual peaks in daylight, 9-20 h solar time) and ``slow`` (``drift`` ≥
        :data:`DRIFT_RATIO` × ``measured_sd``). None with fewer than two days of data.
    """
    import pandas as pd

    r = np.asarray(resid, dtype=float)
    y = np.asarray(measured, dtype=float)
    if np.isfinite(r).sum() < 48:
        return None
    t = np.asarray(times).astype("datetime64[ns]")
    hours = (t - t.astype("datetime64[D]")) / np.timedelta64(1, "h")
    solar = hours + (float(longitude) / 15.0 if longitude is not None else 0.0)
    pr, py = _daily_profile(r, solar), _daily_profile(y, solar)
    amp = float(np.nanmax(pr) - np.nanmin(pr)) / 2
    amp_y = float(np.nanmax(py) - np.nanmin(py)) / 2
    peak = int(np.nanargmax(pr))
    slow = pd.Series(r).rolling(24, center=True, min_periods=12).mean().to_numpy()
    drift = float(np.sqrt(np.nanmean(slow**2)))
    sd = float(np.nanstd(y))
    floor = float(resolution) if resolution else 0.0
    return {
        "daily_amplitude": amp,
        "measured_daily_amplitude": amp_y,
        "peak_hour": peak,
        "drift": drift,
        "measured_sd": sd,
        "daily": bool(amp >= DAILY_CYCLE_RATIO * amp_y and amp >= floor and amp > 0),
        "sunlit": _SUN_HOURS[0] <= peak < _SUN_HOURS[1],
        "slow": bool(sd > 0 and drift >= DRIFT_RATIO * sd),
    }


def _better_rung(summary: RunSummary, failure: dict) -> str | None:
    """A ladder rung whose FIT of the failing output beats the sampled model's by
    :data:`LADDER_MARGIN` points on the judged period, in words (or None)."""
    sec, o, p = failure["section"], failure["output"], failure["period"]
    met = None if p is None else summary.metric(sec, o, p)
    own = None if met is None else met.FIT
    if own is None or p is None:
        return None
    best, best_fit = None, float(own) + LADDER_MARGIN
    for r in summary.ladder.get(sec, ()):
        fit = r.fits(p).get(o)
        m = None if fit is None else fit.FIT
        if r.sampled or m is None:
            continue
        if m >= best_fit:
            best, best_fit = r.model, m
    if best is None:
        return None
    text = (
        f"the model-order ladder's `{best}` reproduces {o} with FIT {best_fit:.1f} % on the "
        f"{p} period (its MAP), against {float(own):.1f} %"
    )
    if best_fit >= MIN_FIT:
        return text + f": calibrate `{best}`"
    return text + f", still below {MIN_FIT:g} %: it has part of what is missing"


def missing_physics(
    summary: RunSummary | dict, failures: list[dict], shapes: dict | None
) -> list[str]:
    """The most likely missing physics of each failing output, in words.

    ``shapes``: (section, output) -> :func:`residual_shape`. A strong daily cycle in
    the temperature residuals that peaks in daylight names the sun (no solar input in
    the model, or apertures on the wrong surfaces); in the vapour pressure a daily
    moisture input. A slow drift names a node, a control or a sink the model lacks.
    A ladder rung that fits clearly better is named with its FIT.
    """
    shapes = shapes or {}
    rs = typed_summary(summary)
    lines = []
    for f in failures:
        sec, o = f["section"], f["output"]
        info = rs.models.get(sec)
        have = {e.name for e in rs.parameters.values() if e.section == sec}
        found = []
        sh = shapes.get((sec, o))
        u = _DIFF_UNITS.get(o, "")
        if sh and sh["daily"]:
            share = sh["daily_amplitude"] / max(sh["measured_daily_amplitude"], 1e-12)
            size = (
                f"a daily cycle of ±{sh['daily_amplitude']:.2g}{u} in the residuals "
                f"({100 * share:.0f} % "
                f"of the measured ±{sh['measured_daily_amplitude']:.2g}{u}, largest at "
                f"{sh['peak_hour']:02d} h solar time)"
            )
            if o == "Ti" and sh["sunlit"]:
                names = () if info is None else info.input_names or ()
                solar = any(str(n).startswith("I_") for n in names)
                found.append(
                    f"{size}: the sun — "
                    + (
                        "its input through the solar apertures is too small or on the "
                        "wrong surfaces (a roof, another facade: data.surfaces)"
                        if solar
                        else "the model has no solar input (give measured or clear-sky "
                        "irradiance, data.irradiance, and a model with solar apertures)"
                    )
                )
            elif o == "Ti":
                found.append(f"{size}: a daily input the model lacks (heating or use schedule)")
            else:
                found.append(
                    f"{size}: a daily moisture input or ventilation the model lacks (use, "
                    "airing, a humidistat's cycle)"
                )
        if sh and sh["slow"]:
            lack = []
            if info is None or len(info.state_names) < 2:
                lack.append(
                    "a second, slower node (`" + ("thermal_2c" if o == "Ti" else "hygric_2c") + "`)"
                )
            if o == "Ti" and "Tset" not in have:
                lack.append("a control (thermostat, if the room is heated)")
            if o == "Pi":
                if not {"RH_lo", "RH_hi", "RH_set"} & have:
                    lack.append("a control (humidistat, dehumidifier)")
                if "Pf" not in have:
                    lack.append("a sink (the fixed vapour-pressure node of `hygric_2c_fixed`)")
            found.append(
                f"a slow drift of the residuals' day means (RMS {sh['drift']:.2g}{u}, against "
                f"a measured standard deviation of {sh['measured_sd']:.2g}{u}): "
                + (", ".join(lack) if lack else "a node, a control or a sink the model lacks")
            )
        rung = _better_rung(rs, f)
        if rung:
            found.append(rung)
        if found:
            lines.append(f"{o} ({sec}): " + "; ".join(found) + ".")
    return lines
