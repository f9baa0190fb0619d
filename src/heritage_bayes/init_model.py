"""The model ``hbayes init`` proposes (:mod:`heritage_bayes.init_config`), from
signatures measured in the files.

Each signature is a number measured on the hourly series over the periods init chose
(UTC), compared with a threshold; the proposal is the config's keys, and the evidence is
written as comments above them:

* **a controlled RH band** (humidistat, dehumidifier): indoor RH between its 5th and 95th
  percentiles spans at most :data:`BAND_MAX_PCT` points and under :data:`BAND_RATIO` of
  the outdoor span → ``hygric.options: {humidistat: band}``;
* **a heating floor** (thermostat, :func:`heritage_bayes.init_checks.heating_floor`) →
  ``thermal.options: {thermostat: true}``; with it, an indoor air warmer than outdoors by
  :data:`GAIN_K` or more in the warmest month (when no heating runs) → ``source: true``,
  a constant heat gain (the sun's mean gain too, where no irradiance is measured);
* **the sun on the room**: the median daily indoor temperature range against the
  outdoor one: at least as large, the room gains heat from the sun (a roof, windows):
  the solar apertures (``data.surfaces``) are kept, and the ratio is noted; under
  :data:`SUNLESS_RATIO` and no irradiance measured, no daily sun shows in the room and
  the irradiance estimated from the daily outdoor range (a proxy whose daily cycle is the
  outdoor air's) is left out: ``irradiance: none`` (:attr:`ModelProposal.daily_sun`);
* **a vapour sink**: indoor vapour pressure below the outdoor one on average, by at
  least :data:`SINK_PA`, in most months (without an RH band, which explains it) →
  ``hygric_2c_fixed`` with ``sink: temperature`` (a sink at ``phi_f·psat(Tf)``, the ground);
* **a moisture source**: indoor vapour pressure above the outdoor one on average, by at
  least :data:`SOURCE_PA`, in most months (ground moisture, visitors, use; without an
  RH band) → ``hygric.options: {source: true}``, a constant source ``Ms`` [kg/s];
* **sorption**: the hourly departures of indoor vapour pressure from its daily mean
  follow those of ``psat(Ti)`` once the outdoor vapour pressure's are accounted for
  (partial correlation at least :data:`SORPTION_R`), under a daily indoor swing of
  :data:`SORPTION_SWING_K` or more: a sorbing buffer at the room's temperature →
  ``hygric_2c_sorption`` (with ``sink: temperature`` when a sink shows too).

The starting order: a calibration period of :data:`LONG_DAYS` days or more of hourly
data pins two thermal nodes or more, and which of ``thermal_2c`` and Kramer et al.'s
``thermal_4a`` the room calls for is not a signature init can measure: it writes
``model: auto`` (:mod:`heritage_bayes.calibration.selection`: the ladder screened by MAP and
validation FIT, the winner sampled), and so for the hygric model where no signature
names one; shorter records keep the one-node models.

References
----------
Kramer, R., van Schijndel, J., Schellen, H. (2017). Dynamic setpoint control for museum
indoor climate conditioning integrating collection and comfort requirements: development
and energy impact for Europe. *Building and Environment* 118, 14-31.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np
import pandas as pd

from heritage_bayes.climate.psychro import saturation_vapour_pressure, vapour_pressure

__all__ = ["ModelProposal", "propose_model"]

#: Widest indoor RH band [% points, 5th to 95th percentile] taken as controlled.
BAND_MAX_PCT = 15.0
#: ... and at most this fraction of the outdoor band.
BAND_RATIO = 0.4
#: Indoor minus outdoor mean temperature [K] in the warmest month of a heated room that
#: says a constant heat gain: a massive room without one sits at the outdoor mean or
#: under it in its warmest month (it lags the season).
GAIN_K = 1.5
#: Standard deviation [K] of the set-point's prior around the measured heating floor: a
#: thermostat holds its sensor, not the logger, at ``Tset``, and its dead band and the
#: logger's place put the floor a kelvin or so from the set-point.
TSET_SD_K = 1.0
#: Median daily indoor over outdoor temperature range under which no daily sun shows.
SUNLESS_RATIO = 0.3
#: Mean indoor minus outdoor vapour pressure [Pa] at or below ``-SINK_PA``: a sink.
SINK_PA = 30.0
#: Mean indoor minus outdoor vapour pressure [Pa] at or above this: a moisture source.
SOURCE_PA = 100.0
#: Correlation of the hourly vapour-pressure departures with psat(Ti)'s: sorption.
SORPTION_R = 0.5
#: ... under a median daily indoor temperature range [K] of at least this: with less,
#: psat(Ti) hardly moves, and a common daily cycle of heat and moisture (use, occupants)
#: correlates as well.
SORPTION_SWING_K = 2.0
#: Calibration days of hourly data from which the two-node thermal model starts.
LONG_DAYS = 60


@dataclass
class ModelProposal:
    """The models and options init writes, and the evidence (comment lines) behind them."""

    thermal_model: str = "thermal_1c"
    thermal_options: dict = field(default_factory=dict)
    hygric_model: str = "hygric_1c"
    hygric_options: dict = field(default_factory=dict)
    #: Priors init measured (``thermal.priors``), e.g. the set-point at the heating floor.
    thermal_priors: dict = field(default_factory=dict)
    thermal_evidence: list[str] = field(default_factory=list)
    hygric_evidence: list[str] = field(default_factory=list)
    #: The room's daily swing against the outdoor one: a daily sun (True), none (False)
    #: or not measured (None).
    daily_sun: bool | None = None


def _hourly(s: pd.Series | None, start, end) -> pd.Series | None:
    if s is None:
        return None
    s = s[(s.index >= start) & (s.index < end)].dropna()
    return s.resample("1h").mean() if len(s) else None


def _span(s: pd.Series) -> tuple[float, float]:
    return float(np.nanpercentile(s, 5)), float(np.nanpercentile(s, 95))


def _daily_range(s: pd.Series) -> float:
    g = s.resample("1D")
    r = (g.max() - g.min())[g.count() >= 20]
    return float(r.median()) if len(r) else float("nan")


def _corr(a: np.ndarray, b: np.ndarray) -> float:
    """Pearson's correlation; 0 when either series is constant (no cycle to follow)."""
    if np.std(a) == 0 or np.std(b) == 0:
        return 0.0
    return float(np.corrcoef(a, b)[0, 1])


def _thermal(p: ModelProposal, ti, te, heated: tuple[float, int, int], cal_days: float) -> None:
    floor, held, ndays = heated
    if held >= max(20, 0.05 * ndays):
        p.thermal_options["thermostat"] = True
        p.thermal_priors["Tset"] = {
            "dist": "normal",
            "mean": round(floor, 1),
            "sigma": TSET_SD_K,
        }
        p.thermal_evidence.append(
            f"a heating floor: the indoor daily minimum sat at {floor:.1f} °C (within 0.5 K) "
            f"on {held} of {ndays} days while the outdoor air averaged 5 K colder: a "
            "thermostat (thermostat: true, its set-point Tset estimated around the floor: "
            f"thermal.priors.Tset, a normal prior {floor:.1f} ± {TSET_SD_K:g} K, so that the "
            "fit cannot switch the heating off by a set-point below every measured hour)"
        )
        both = pd.concat([ti.rename("ti"), te.rename("te")], axis=1).dropna()
        monthly = both.resample("MS").mean()[both.resample("MS").count()["ti"] >= 24 * 20]
        if len(monthly):
            warm = monthly["te"].idxmax()
            excess = float(monthly.loc[warm, "ti"] - monthly.loc[warm, "te"])
            gain = excess >= GAIN_K
            p.thermal_evidence.append(
                f"in the warmest month ({warm:%Y-%m}, outdoors {monthly.loc[warm, 'te']:.1f} "
                f"°C, no heating) the air was {excess:+.1f} K from outdoors"
                + (
                    ": a heat gain beyond the sun's (source: true, a constant Qs [W])"
                    if gain
                    else f" (under {GAIN_K:g} K: no constant gain proposed)"
                )
            )
            if gain:
                p.thermal_options["source"] = True
    ri, re_ = _daily_range(ti), _daily_range(te)
    if np.isfinite(ri) and np.isfinite(re_) and re_ > 0:
        ratio = ri / re_
        p.daily_sun = ratio >= SUNLESS_RATIO
        p.thermal_evidence.append(
            f"daily swing: median indoor range {ri:.2f} K against outdoors {re_:.2f} K "
            f"(ratio {ratio:.2f}): "
            + (
                "larger indoors: the sun heats the room (roof or windows): keep the solar "
                "apertures (data.surfaces; name roof planes or facades when known)"
                if ratio >= 1
                else "smaller indoors: damped by the envelope"
                + (
                    f"; under {SUNLESS_RATIO:g}, no daily sun shows in the room: without "
                    "measured irradiance, none is estimated (irradiance: none)"
                    if ratio < SUNLESS_RATIO
                    else ""
                )
            )
        )
    if cal_days >= LONG_DAYS:
        p.thermal_model = "auto"
        p.thermal_evidence.append(
            f"{cal_days:.0f} days of calibration data (>= {LONG_DAYS}) pin two nodes or "
            "more: thermal_2c (envelope, air) or thermal_4a (Kramer et al., the paper's "
            "model, with an interior mass): model: auto screens thermal_1c, thermal_2c and "
            "thermal_4a (MAP, validation FIT) and samples the one the data call for"
        )
    else:
        p.thermal_evidence.append(
            f"{cal_days:.0f} days of calibration data (< {LONG_DAYS}): the one-node model"
        )


def _hygric(p: ModelProposal, ti, te, rhi, rhe, cal_days: float) -> None:
    lo, hi = _span(rhi)
    band = hi - lo
    controlled = False
    if rhe is not None and len(rhe.dropna()):
        elo, ehi = _span(rhe)
        controlled = band <= BAND_MAX_PCT and band <= BAND_RATIO * (ehi - elo) and ehi > elo
        p.hygric_evidence.append(
            f"RH band: indoors {lo:.0f}-{hi:.0f} % ({band:.1f} points, 5-95 %) against "
            f"outdoors {elo:.0f}-{ehi:.0f} % ({ehi - elo:.1f} points): "
            + (
                "held in a narrow band: a humidistat or dehumidifier (humidistat: band, its "
                "limits RH_lo, RH_hi estimated)"
                if controlled
                else "not controlled"
            )
        )
    if controlled:
        p.hygric_options["humidistat"] = "band"
        return
    both = pd.concat(
        {"ti": ti, "rhi": rhi, "te": te, "rhe": rhe if rhe is not None else te * np.nan},
        axis=1,
    ).dropna()
    if len(both) < 48:
        return
    pi = pd.Series(vapour_pressure(both["ti"], both["rhi"]), index=both.index)
    pe = pd.Series(vapour_pressure(both["te"], both["rhe"]), index=both.index)
    ps = pd.Series(saturation_vapour_pressure(both["ti"]), index=both.index)
    long = cal_days >= LONG_DAYS
    d = pi - pe
    months = d.resample("MS").mean().dropna()
    below = int((months < 0).sum())
    sink = float(d.mean()) <= -SINK_PA and below >= 2 * len(months) / 3
    wet = float(d.mean()) >= SOURCE_PA and len(months) - below >= 2 * len(months) / 3
    p.hygric_evidence.append(
        f"vapour pressure: indoors {float(d.mean()):+.0f} Pa from outdoors on average, "
        f"below in {below} of {len(months)} months: "
        + (
            "a vapour sink"
            if sink
            else "a moisture source (source: true, a constant Ms [kg/s])"
            if wet
            else "no sink"
        )
    )
    if wet:
        p.hygric_options["source"] = True

    def dep(s):  # departures from the daily mean
        return s - s.groupby(s.index.floor("D")).transform("mean")

    x, y, z = dep(pi).to_numpy(), dep(ps).to_numpy(), dep(pe).to_numpy()
    r_t, r_e, r_ty = _corr(x, y), _corr(x, z), _corr(y, z)
    partial = (r_t - r_e * r_ty) / np.sqrt(max((1 - r_e**2) * (1 - r_ty**2), 1e-12))
    swing = _daily_range(ti)
    sorption = partial >= SORPTION_R and swing >= SORPTION_SWING_K
    p.hygric_evidence.append(
        f"daily cycle of indoor vapour pressure (departures from the daily mean): "
        f"correlation {r_t:.2f} with psat(Ti), {r_e:.2f} with the outdoor vapour pressure, "
        f"{partial:.2f} with psat(Ti) once the outdoor one is accounted for (partial), "
        f"under a daily indoor swing of {swing:.1f} K: "
        + (
            "it follows the room's temperature: sorption in a buffer at Ti"
            if sorption
            else "no sorption signature"
            + (
                f" (a swing under {SORPTION_SWING_K:g} K: a common daily cycle of heat and "
                "moisture, such as use, is as likely)"
                if partial >= SORPTION_R
                else ""
            )
        )
    )
    if not long:
        if sink or sorption:
            p.hygric_evidence.append(
                f"{cal_days:.0f} days of calibration data (< {LONG_DAYS}): the one-node "
                "model first; try the two-node model the signature names with `hbayes compare`"
            )
        return
    if not (sorption or sink):
        p.hygric_model = "auto"
        p.hygric_evidence.append(
            f"{cal_days:.0f} days of calibration data (>= {LONG_DAYS}) and no signature "
            "that names a model: model: auto screens the hygric ladder (1c, 2c, the fixed "
            "node, sorption; MAP, validation FIT) and samples the one the data call for"
        )
    if sorption:
        p.hygric_model = "hygric_2c_sorption"
        if sink:
            p.hygric_options["sink"] = "temperature"
        if p.hygric_options.pop("source", None):  # the sorbing buffer has no source term
            p.hygric_evidence.append(
                "the sorbing buffer has no moisture source term: the source is left out; "
                "`hbayes compare` weighs it (hygric_2c with source: true) against sorption"
            )
    elif sink:
        p.hygric_model = "hygric_2c_fixed"
        p.hygric_options["sink"] = "temperature"
    if sink:
        p.hygric_evidence.append(
            "the sink: a vapour node at phi_f·psat(Tf), Tf the ground temperature "
            "(sink: temperature; the fixed-node model hygric_2c_fixed with sink: constant "
            "is the alternative)"
        )


def propose_model(
    ti: pd.Series,
    te: pd.Series,
    rhi: pd.Series | None,
    rhe: pd.Series | None,
    *,
    start,
    mid,
    end,
    heated: tuple[float, int, int],
) -> ModelProposal:
    """The models and options the data call for.

    Parameters
    ----------
    ti, te : pandas.Series
        Indoor and outdoor temperature [°C] on UTC stamps.
    rhi, rhe : pandas.Series or None
        Indoor and outdoor relative humidity [%] on UTC stamps (None: no hygric section).
    start, mid, end : str or pandas.Timestamp
        The calibration ``[start, mid)`` and validation ``[mid, end)`` periods [UTC]: the
        signatures are measured over both.
    heated : (float, int, int)
        :func:`heritage_bayes.init_checks.heating_floor` over the whole overlap.

    Returns
    -------
    ModelProposal
    """
    s, m, e = (
        pd.Timestamp(x, tz="UTC") if pd.Timestamp(x).tz is None else x for x in (start, mid, end)
    )
    cal_days = (m - s) / pd.Timedelta(days=1)
    ti_h, te_h = _hourly(ti, s, e), _hourly(te, s, e)
    p = ModelProposal()
    if ti_h is None or te_h is None:
        return p
    _thermal(p, ti_h, te_h, heated, cal_days)
    rhi_h = _hourly(rhi, s, e)
    if rhi_h is not None:
        _hygric(p, ti_h, te_h, rhi_h, _hourly(rhe, s, e), cal_days)
    return p
