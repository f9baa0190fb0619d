"""The predictive side of a calibration: initial states, noise, physical limits, bands.

What :mod:`heritage_bayes.calibration.outputs` adds to each posterior draw before the bands
are drawn: how the initial state was obtained (in words), the noise model of the bands
(the free-run error when the likelihood's noise model sits at its cap, and always for
``kalman``) and the limit of predicted vapour pressure at saturation; then what of the
predictive is stored: the bands over every saved draw and a bounded subset of the draws.
"""

from __future__ import annotations

import math

import numpy as np
import xarray as xr

from heritage_bayes.climate.psychro import saturation_vapour_pressure

__all__ = [
    "BAND_LEVELS",
    "PREDICTIVE_DRAWS",
    "bounded_predictive",
    "condensation_cap",
    "initial_state_text",
    "predictive_bands",
    "predictive_noise",
]

#: At least this many posterior-predictive draws are stored per variable (the
#: ``posterior_predictive`` group; with 32 walkers 2 per walker), for users who want
#: draws; the report's bands are computed over all saved draws first
#: (``predictive_bands``); their size: docs/science/benchmarks.md, "Figures behind the
#: code's choices".
PREDICTIVE_DRAWS = 64
#: Quantile levels of ``predictive_bands`` [-] (the report's 50 % and 90 % bands and
#: the median).
BAND_LEVELS = (0.05, 0.25, 0.5, 0.75, 0.95)


def _saved_index(n_chain: int, n_draw: int, n_total: int) -> np.ndarray:
    """Draws per chain kept in ``posterior.nc``: evenly spaced, about ``n_total`` in all."""
    m = max(1, min(n_draw, math.ceil(n_total / n_chain)))
    return np.unique(np.linspace(0, n_draw - 1, m).round().astype(int))


def predictive_bands(pp: dict[str, xr.DataArray]) -> dict[str, xr.DataArray]:
    """Quantiles :data:`BAND_LEVELS` over (chain, draw) of each predictive variable:
    (quantile, time) arrays in the variable's unit, exact over every draw given."""
    out = {}
    for k, da in pp.items():
        v = np.asarray(da.values, dtype=float).reshape(-1, da.shape[-1])
        q = np.quantile(v, BAND_LEVELS, axis=0)
        out[k] = xr.DataArray(
            q.astype(np.float32),
            dims=("quantile", "time"),
            coords={"quantile": np.asarray(BAND_LEVELS), "time": da["time"].values},
            attrs=dict(da.attrs),
        )
    return out


def bounded_predictive(
    pp: dict[str, xr.DataArray], n_draws: int = PREDICTIVE_DRAWS
) -> dict[str, xr.DataArray]:
    """The predictive variables on about ``n_draws`` of their draws: the same evenly
    spaced draws of every chain (so the pairing of thermal and hygric draws, and with
    the posterior's ``draw`` labels, is kept)."""
    if not pp:
        return pp
    da = next(iter(pp.values()))
    keep = _saved_index(da.sizes["chain"], da.sizes["draw"], n_draws)
    return {k: v.isel(draw=keep) for k, v in pp.items()}


def condensation_cap(s, prep, Ysim: np.ndarray, Ypp: np.ndarray, pp_outputs: dict):
    """Limit predicted vapour pressure to [0, saturation at the indoor temperature].

    Air cannot hold more vapour than saturation: the excess condenses (on the coldest
    surfaces first, so the cap at the air temperature is the generous one). The
    temperature is the thermal model's paired draw (predictive for the predictive
    series, noise-free for the noise-free one) when the run calibrates one, else the
    measured ``Ti`` (hours without it are left as they are). In place on ``Ysim`` and
    ``Ypp``; returns how often the cap acted (shares of draws × hours), or None for a
    thermal section.
    """
    if "Pi" not in s.model.output_names:
        return None
    o = s.model.output_names.index("Pi")
    if "Ti" in pp_outputs:
        ti_pp, ti_sim = pp_outputs["Ti"]
        source = "the thermal model's paired draws"
    elif "Ti" in prep.frame:
        ti_pp = ti_sim = prep.frame["Ti"].to_numpy(dtype=float)[None, :]
        source = "the measured indoor temperature"
    else:
        return None
    with np.errstate(invalid="ignore"):
        ps_pp = saturation_vapour_pressure(ti_pp)
        ps_sim = saturation_vapour_pressure(ti_sim)
        over_pp = Ypp[..., o] > ps_pp
        over_sim = Ysim[..., o] > ps_sim
        below = Ypp[..., o] < 0.0
        Ypp[..., o] = np.where(over_pp, ps_pp, np.maximum(Ypp[..., o], 0.0))
        Ysim[..., o] = np.where(over_sim, ps_sim, np.maximum(Ysim[..., o], 0.0))
    med_over = np.mean(over_sim, axis=0) > 0.5
    return {
        "temperature": source,
        "share_predictive_samples": float(np.mean(over_pp)),
        "share_noise_free_samples": float(np.mean(over_sim)),
        "share_hours_median_saturated": float(np.mean(med_over)),
        "share_predictive_below_zero": float(np.mean(below)),
    }


def predictive_noise(s, prep, Ysim: np.ndarray, tn: np.ndarray):
    """Noise model and parameters of the predictive bands, and what was changed.

    Returns ``(noise_model, noise, info)``: the likelihood's own model and ``tn`` when
    nothing is changed (``info`` None), else the free-run error's model
    (:meth:`~heritage_bayes.inference.likelihoods.NoiseModel.free_run_model`) and its
    parameters per draw, with ``info`` (output -> fitted parameters and the reason).

    The noise model says per output whether its bands need the free-run error
    (:meth:`~heritage_bayes.inference.likelihoods.NoiseModel.free_run_reason`):
    ``ar1_white`` whose correlation sits at its cap describes only the misfit's fast
    part; ``kalman``'s process noise is estimated for one-step-ahead prediction, and
    propagated without the data it is not the error of a free run. The coverage of such
    bands on real and generated rooms: docs/science/noise.md, "Figures behind the
    code's choices".

    The error of *prediction* is then the free-run error: AR(1) + white noise fitted by
    maximum likelihood (phi up to 0.999) to the calibration residuals of the
    posterior-median simulation (:func:`fit_free_run_error`), used for every draw's
    predictive noise. The posterior, the likelihood and ``kalman``'s one-step-ahead
    band are unchanged.
    """
    from heritage_bayes.inference.likelihoods import fit_free_run_error

    nm = s.logpost.noise
    ps = s.logpost.params.parameters[s.logpost.n_model :]
    reasons = {
        o: r
        for o, name in enumerate(s.model.output_names)
        if (r := nm.free_run_reason(o, name, tn, ps)) is not None
    }
    if not reasons:
        return nm, tn, None
    band = nm.free_run_model()
    width = len(band.kinds)
    out = tn.copy() if band is nm else np.zeros((tn.shape[0], width * s.model.n_outputs))
    obs = np.array(prep.observed(s.name, s.model), dtype=float)
    fitted = prep.fitted_rows()
    obs[~fitted] = np.nan  # a validation inside the calibration: a gap in the residuals
    rows = slice(int(np.argmax(fitted)), fitted.size - int(np.argmax(fitted[::-1])))
    info = {}
    for o, reason in reasons.items():
        r = obs[rows, o] - np.median(Ysim[:, rows, o], axis=0)
        fit = fit_free_run_error(r)
        for j, kind in enumerate(band.kinds):
            out[:, width * o + j] = fit[kind]
        info[s.model.output_names[o]] = {**fit, "reason": reason}
    return band, out, info


def initial_state_text(lp) -> str:
    """How the initial state of a log-posterior was obtained, in words."""
    mode = lp.initial_state
    if mode == "steady":
        return "steady state of the mean inputs, not estimated"
    fixed = ", ".join(f"{lp.model.state_names[i]} = {v:g}" for i, v in lp.x0_fixed.items())
    return "estimated, integrated out exactly" + (f"; fixed: {fixed}" if fixed else "")
