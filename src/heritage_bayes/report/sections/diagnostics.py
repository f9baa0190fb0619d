"""Section 7, sampler diagnostics: chains, τ history, trace and rank plots, residual checks.

Rank plots (Vehtari et al. 2021, doi:10.1214/20-BA1221) are drawn for the slowest time
constant, the static gains and the scale coordinate (the coordinates of
:mod:`heritage_bayes.report.identifiable`: a raw C or G would only show the scale ridge
again). They use the draws of ``posterior.nc``'s ``posterior`` group, the thinned
post-burn-in draws the tables' quantiles and MCSE come from, rather than the chain
file: no second read of a large file. Its ``chain`` dimension
holds the emcee walkers, each with about 30 draws, too few for a histogram of its own:
the walkers are grouped into 4 blocks (:func:`~heritage_bayes.report.identifiable.rank_groups`).
"""

from __future__ import annotations

import json
import math

import numpy as np

from heritage_bayes.errors import InputError
from heritage_bayes.format import OUT_UNITS, fmt_int, fmt_pct
from heritage_bayes.inference.likelihoods import NoiseModel, find_noise_model
from heritage_bayes.report.page import Section
from heritage_bayes.report.rundata import RunData, parameter_set
from heritage_bayes.report.sections._fragment import render_fragment
from heritage_bayes.rundir.summary import ModelInfo, RunSummary

ID, TITLE = "diagnostics", "7. Sampler diagnostics"

_TRACE_POINTS = 400  # thinned steps per walker in trace plots


def _traces(rd: RunData, m: str, info: ModelInfo):
    import h5py

    from heritage_bayes.report.figures import fig_traces

    path = rd.path / f"chain_{m}.h5"
    if not path.is_file():
        return None
    try:
        with h5py.File(path, "r") as f:
            # a converged chain's checkpoint keeps every trace_stride-th step, a long
            # unconverged one every stride-th (sampler.max_stored_steps; issue 28)
            kept = int(f.attrs.get("trace_stride", 1))
            if "commit" in f.attrs:
                kept = int(json.loads(f.attrs["commit"]).get("stride", 1))
            n = f["chain"].shape[0]
            stride = max(1, math.ceil(n / _TRACE_POINTS))
            X = f["chain"][::stride]
            lp = f["log_prob"][::stride]
    except (OSError, KeyError) as exc:
        raise InputError(f"{path}: cannot be read ({exc})") from None
    steps = kept * np.arange(0, n, stride)[: X.shape[0]]
    stride *= kept
    names = list(info.free_names)
    ps = parameter_set(rd, m)
    S, W, d = X.shape
    if ps is not None and d == ps.ndim:
        theta = ps.values(X.reshape(-1, d))
        idx = [ps.names.index(nm) for nm in ps.free_names]
        V = theta[:, idx].reshape(S, W, d)
        labels = []
        for j, nm in enumerate(ps.free_names):
            p = ps[nm]
            unit = p.unit if p.unit and p.unit != "-" else ""
            if p.prior.log_scale:
                V[:, :, j] = np.log10(V[:, :, j])
                labels.append(f"log10 {nm}" + (f" [{unit}]" if unit else ""))
            else:
                labels.append(nm + (f" [{unit}]" if unit else " [-]"))
        coords = "parameter values (log10 where the prior is log-scale)"
    else:
        V = X
        labels = (
            [f"{nm} (sampler coordinate)" for nm in names]
            if len(names) == d
            else [f"x{j}" for j in range(d)]
        )
        coords = "the sampler's unconstrained coordinates"
    fig = fig_traces(
        steps,
        V,
        labels,
        lp,
        int(info.burn or 0),
        title=f"{m} ({info.model}): {W} walkers, every {stride}th step shown",
    )
    return {"figure": fig, "coords": coords}


def _ranks(rd: RunData, m: str, info: ModelInfo) -> dict | None:
    """Rank plot of the slowest τ, the gains and the scale of section ``m`` (or None)."""
    from heritage_bayes.report.figures import fig_rank
    from heritage_bayes.report.identifiable import (
        identifiable_coordinates,
        rank_counts,
        rank_groups,
    )

    coords = [
        c
        for c in identifiable_coordinates(rd, m)
        if c.name in ("tau_1_h", "scale") or not c.name.startswith("tau_")
    ]
    if not coords:
        return None
    n_chain, n_draw = coords[0].draws.shape
    groups = rank_groups(n_chain)
    if len(groups) < 2 or n_draw * len(groups[0]) < 20:
        return None
    panels = []
    for c in coords:
        counts, band, expected = rank_counts(c.draws, groups)
        panels.append({"label": c.label, "counts": counts, "band": band, "expected": expected})
    fig = fig_rank(
        panels,
        title=f"{m} ({info.model}): rank plots, {len(groups)} groups of {len(groups[0])} walkers",
    )
    return {
        "figure": fig,
        "groups": len(groups),
        "per_group": len(groups[0]),
        "n_draws": fmt_int(n_chain * n_draw),
    }


def _residual_check(resid: np.ndarray, view, dt_hours: float) -> dict:
    """Whiteness of what the noise model leaves: the innovations of its
    :class:`~heritage_bayes.inference.likelihoods.ResidualView` ``view``."""
    from heritage_bayes.report._diag import acf, cumulative_periodogram

    max_lag = max(1, round(72 / dt_hours))
    _, rho, n = acf(resid, max_lag)
    w = view.innovations
    _, rho_w, n_w = acf(w, max_lag)
    band = 1.96 / math.sqrt(max(n_w, 1))
    out_share = float(np.mean(np.abs(rho_w[1:]) > band)) if rho_w.size > 1 else float("nan")
    f, c, kb = cumulative_periodogram(w)
    dev = float(np.nanmax(np.abs(c - 2 * f))) if c.size else float("nan")
    adequate = out_share <= 0.10 and (not math.isfinite(dev) or dev <= kb)
    lag1 = float(rho[1]) if rho.size > 1 else float("nan")
    worst = int(np.nanargmax(np.abs(rho_w[1:]))) + 1 if rho_w.size > 1 else 0
    return {
        "lag1": lag1,
        "innovations": w,
        "lag1_innovations": float(rho_w[1]) if rho_w.size > 1 else float("nan"),
        "worst_lag_h": worst * dt_hours,
        "worst_rho": float(rho_w[worst]) if worst else float("nan"),
        "phi": view.phi,
        "out_share": out_share,
        "dev": dev,
        "band": kb,
        "adequate": adequate,
    }


def _median(s: RunSummary, key: str, absent=None):
    """The posterior median of the parameter ``key`` (``absent`` if the run has none)."""
    e = s.parameters.get(key)
    return absent if e is None else e.median


def diagnostics_context(rd: RunData, fits: list[dict]) -> dict:
    from heritage_bayes.report.figures import fig_tau_history

    s = rd.summary
    conv = s.convergence
    models = []
    missing = []
    for m, info in s.models.items():
        tr = _traces(rd, m, info)
        rk = _ranks(rd, m, info)
        if tr is None:
            missing.append(f"chain_{m}.h5")
        models.append(
            {
                "section": m,
                "model": info.model,
                "walkers": fmt_int(info.walkers),
                "steps": fmt_int(info.steps),
                "burn": fmt_int(info.burn),
                "thin": fmt_int(info.thin),
                "draws": fmt_int(info.draws_per_walker),
                "tau_max": fmt_int(info.tau_max),
                "needed": fmt_int(conv.tau_factor * info.tau_max)
                if info.tau_max is not None
                else "—",
                "converged_tau": info.converged_tau,
                "acceptance": fmt_pct(info.acceptance_mean),
                "resumed_from": fmt_int(info.resumed_from),
                "trace": tr,
                "rank": rk,
            }
        )
    hist = {m: info.tau_history for m, info in s.models.items()}
    tau_fig = fig_tau_history(hist, conv.tau_factor) if any(len(h) for h in hist.values()) else None
    residuals = [r for fit in fits if (r := _residual_entry(s, fit)) is not None]
    return {
        "models": models,
        "tau_fig": tau_fig,
        "residuals": residuals,
        "missing": missing,
        "tau_factor": f"{conv.tau_factor:g}",
        "tau_rtol": fmt_pct(conv.tau_rtol, 0),
    }


def _residual_entry(s, fit: dict) -> dict | None:
    """The residual check of one fitted output over the calibration period: its figure,
    the check's figures and the verdict in words; None for an output without a noise
    model of its own (RH, a one-step band) or with under four calibration hours."""
    from heritage_bayes.report.figures import fig_residuals

    if fit["section"] == "combined":
        return None  # RH is not a model output: its residuals have no noise model
    if fit.get("resid") is None:
        return None  # a one-step-ahead band: its residuals are the filter's innovations
    dt_hours = s.dt / 3600.0
    m, o = fit["section"], fit["output"]
    noise = s.models[m].noise if m in s.models else ""
    cal = fit["codes"] == 1
    if cal.sum() < 4:
        return None
    # first to last calibration hour; a validation inside it is a gap (NaN), not a join
    idx = np.flatnonzero(cal)
    span = slice(idx[0], idx[-1] + 1)
    resid = np.where(cal[span], fit["resid"][span], np.nan)
    nm = find_noise_model(noise) or NoiseModel()

    def median(kind, absent=None):
        return _median(s, f"{m}.{kind}_{o}", absent)

    if nm.statespace and (one := fit.get("resid_1step")) is not None:
        view = nm.residual_view(resid, median, np.where(cal[span], one[span], np.nan))
    else:
        view = nm.residual_view(resid, median)
    check = _residual_check(resid, view, dt_hours)
    fig = fig_residuals(
        fit["times"][span],
        resid,
        output=o,
        unit=OUT_UNITS.get(o, ""),
        phi=view.phi,
        dt_hours=dt_hours,
        innov=check.pop("innovations"),
        acf_scale=view.acf_scale,
    )
    return {
        "id": f"fig-resid-{m}-{o}",
        "section": m,
        "output": o,
        "model": fit["model"],
        "figure": fig,
        "words": _residual_words(check, view),
        "adequate": check["adequate"],
        "check": check,
    }


def _residual_words(check: dict, view) -> str:
    """The residual check in words: the lag-1 autocorrelation against the noise model's
    and whether what is left is white noise."""
    words = f"Lag-1 autocorrelation of the residuals {check['lag1']:.2f}; {view.expects}. "
    subject = view.subject
    share = fmt_pct(check["out_share"])
    if view.phi is not None:
        words += f"Lag-1 autocorrelation of the innovations {check['lag1_innovations']:.2f}. "
    if check["adequate"]:
        words += (
            f"The noise model looks adequate: {subject} are close to white "
            f"noise ({share} of the lags 1–72 h outside the 95 % band)."
        )
    else:
        words += (
            f"The noise model is not fully adequate: {subject} are not white "
            f"({share} of the lags 1–72 h outside the 95 % band"
            + (
                ", cumulative periodogram outside its band"
                if math.isfinite(check["dev"]) and check["dev"] > check["band"]
                else ""
            )
            + f"; the largest at a lag of {check['worst_lag_h']:g} h: "
            f"{check['worst_rho']:.2f}"
            + (", a daily cycle the model misses" if check["worst_lag_h"] in (24, 48, 72) else "")
            + "). Correlation the noise model misses makes the posterior intervals "
            "and predictive bands too narrow."
        )
    return words


def section(ctx: dict) -> Section:
    """This section of the page, from the report context (figures already data URIs)."""
    return Section(TITLE, render_fragment("diagnostics.html", ctx), id=ID)
