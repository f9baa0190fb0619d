"""The predictive side of a calibration: initial states, noise and physical limits.

What :mod:`heritage_bayes.inference.idata` adds to each posterior draw before the bands
are drawn: how the initial state was obtained (in words), the noise model of the bands
(the free-run error when the likelihood's noise model sits at its cap) and the limit
of predicted vapour pressure at saturation.
"""

from __future__ import annotations

import numpy as np

from heritage_bayes.climate.psychro import saturation_vapour_pressure

__all__ = ["condensation_cap", "initial_state_text", "predictive_noise"]


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
    """Noise parameters of the predictive bands, and what was changed (or None).

    When the posterior of an ``ar1_white`` correlation sits at its cap, the noise model
    of the likelihood describes only the misfit's fast part: bands drawn from it would
    leave out the slow misfit (configs/orholm.yaml: a 90 % band covering 49 % of the
    hours). The error of *prediction* is then the free-run error: AR(1) + white noise
    fitted by maximum likelihood (phi up to 0.999) to the calibration residuals of the
    posterior-median simulation (:func:`fit_free_run_error`), used for every draw's
    predictive noise. The posterior (and the likelihood) are unchanged.
    """
    from heritage_bayes.inference.likelihoods import fit_free_run_error

    nm = s.logpost.noise
    if "phi" not in nm.kinds or "sigma_meas" not in nm.kinds:
        return tn, None
    q = len(nm.kinds)
    ps = s.logpost.params.parameters[s.logpost.n_model :]
    obs = np.asarray(prep.observed(s.name, s.model), dtype=float)
    cal = prep.calibration
    rows = slice(cal.start + prep.warmup_steps, cal.stop)
    out, info = tn, {}
    for o, name in enumerate(s.model.output_names):
        i_phi = q * o + nm.kinds.index("phi")
        cap = ps[i_phi].prior.upper
        if not np.median(tn[:, i_phi]) > cap - 0.05 * (1.0 - cap):
            continue
        r = obs[rows, o] - np.median(Ysim[:, rows, o], axis=0)
        fit = fit_free_run_error(r)
        out = out.copy() if out is tn else out
        for kind in ("sigma", "phi", "sigma_meas"):
            out[:, q * o + nm.kinds.index(kind)] = fit[kind]
        info[name] = {
            **fit,
            "reason": f"phi_{name} at its cap {cap:g}: bands use the free-run error "
            "(AR(1) + white fitted to the calibration residuals of the posterior-median "
            "simulation)",
        }
    return out, (info or None)


def initial_state_text(lp) -> str:
    """How the initial state of a log-posterior was obtained, in words."""
    mode = lp.initial_state
    if mode == "steady":
        return "steady state of the mean inputs, not estimated"
    fixed = ", ".join(f"{lp.model.state_names[i]} = {v:g}" for i, v in lp.x0_fixed.items())
    return "estimated, integrated out exactly" + (f"; fixed: {fixed}" if fixed else "")
