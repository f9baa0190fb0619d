"""One rung of the model-order ladder: its log-posterior on a prepared dataset and its
MAP row (fit criteria over the calibration and validation periods, information criteria,
structural identifiability at the MAP).

Used by the calibration run's ladder (:func:`heritage_bayes.calibration.calibrate.model_ladder`),
the automatic selection (:mod:`heritage_bayes.calibration.selection`) and ``hbayes compare``'s
screen. The fit criteria are those of the paper: FIT [%], MSE, MAE of the simulation
from the MAP (Kramer, van Schijndel & Schellen 2013, Building and Environment 68, 87-99).
"""

from __future__ import annotations

from collections.abc import Mapping

import numpy as np

from heritage_bayes.errors import InputError
from heritage_bayes.inference.likelihoods import get_noise_model
from heritage_bayes.inference.parameters import owned_priors
from heritage_bayes.inference.posterior import LogPosterior
from heritage_bayes.models import initial_state_of
from heritage_bayes.rc.model import RCModel
from heritage_bayes.run import section_parameters

__all__ = [
    "ladder_row",
    "rung_log_posterior",
    "section_log_posterior",
    "section_temperature",
    "structural_at_map",
]


def section_log_posterior(
    cfg, prep, section: str, model: RCModel, priors: Mapping, initial_state=None
) -> LogPosterior:
    """The log-posterior of ``model`` on the calibration period of a config section
    (initial state as configured unless ``initial_state`` is given)."""
    noise, params = section_parameters(cfg, section, model, priors)
    if initial_state is None:
        initial_state = initial_state_of(cfg, section, model)
    cal = prep.calibration
    kind, extra = LogPosterior, {}
    if getattr(prep, "breaks", None) is not None:  # gaps too long to bridge: one start each
        from heritage_bayes.inference.segments import SegmentedLogPosterior, calibration_segments

        kind = SegmentedLogPosterior
        extra = {
            "segments": tuple(calibration_segments(prep)[0]),
            "frame_breaks": prep.breaks,
            "held_out": prep.held_out,
        }
    try:
        return kind(
            model,
            params,
            noise,
            prep.model_inputs(section, model)[cal],
            prep.calibration_observed(section, model),
            dt=prep.dt,
            warmup=prep.warmup_steps,
            init_window=prep.init_steps,
            initial_state=initial_state,
            initial_state_sd=getattr(cfg, section).initial_state_sd,
            initial_state_horizon=getattr(cfg, section).horizon_seconds,
            time_constant_cap=getattr(cfg, section).cap_seconds(model.domain),
            temperature=section_temperature(getattr(cfg, section), model),
            **extra,
        )
    except ValueError as exc:
        raise InputError(f"{section}: {exc}") from None


def section_temperature(sec_cfg, model: RCModel) -> float:
    """The likelihood temperature of a config section (a
    :class:`~heritage_bayes.config.models.ModelSection`) for ``model``: its own or the
    default for the model's domain, nodes, sorption, sink and the section's noise
    model (:meth:`~heritage_bayes.config.models.ModelSection.temperature`)."""
    return sec_cfg.temperature(
        model.domain,
        model.n_states,
        getattr(model, "sorption", False),
        getattr(model, "sink", "none"),
    )


def rung_log_posterior(cfg, prep, section: str, model: RCModel, initial_state) -> LogPosterior:
    """The log-posterior of a ladder rung: the section's data and noise model, and those
    configured priors whose parameters exist in the rung. ``initial_state``: the
    configured model's mode; fixed nodes belong to the configured model, so a rung with
    a mapping estimates its own start, and a controlled rung starts steady."""
    sec_cfg = getattr(cfg, section)
    priors = owned_priors(sec_cfg.priors, model, get_noise_model(sec_cfg.noise))
    mode = initial_state
    if isinstance(mode, Mapping) or model.control is not None:
        mode = "steady" if model.control is not None else "estimate"
    return section_log_posterior(cfg, prep, section, model, priors, initial_state=mode)


def structural_at_map(model: RCModel, logpost: LogPosterior, map_result, dt: float):
    """Structural identifiability of ``model`` at a MAP (its fixed parameters held):
    :func:`heritage_bayes.rc.identify.structural_identifiability`."""
    from heritage_bayes.rc.identify import structural_identifiability

    n = logpost.n_model
    fixed = tuple(p.name for p in logpost.params.parameters[:n] if not p.free)
    point = dict(zip(model.parameter_names, map_result.theta[:n], strict=True))
    return structural_identifiability(model, point, dt=dt, fixed=fixed)


def ladder_row(prep, section: str, model: RCModel, lp: LogPosterior, mp, *, label=None) -> dict:
    """The ladder's row of a rung at its MAP ``mp``: FIT, MSE, MAE per output over the
    calibration (after the warm-up) and validation periods of the simulation from the
    MAP; log-likelihood, AIC, BIC; structural rank and null directions at the MAP."""
    from heritage_bayes.inference.results import fit_metrics

    out = model.output_names
    ident = structural_at_map(model, lp, mp, prep.dt)
    U = prep.model_inputs(section, model)
    ysim = lp.simulate_frame(mp.theta[None], U, prep.calibration.start)[0][0]
    obs = prep.observed(section, model)
    fit = {}
    rows = {"calibration": prep.fitted_rows(), "validation": prep.validation}
    for period, sl in rows.items():
        if sl is None:
            continue
        fit[period] = {o: fit_metrics(obs[sl, k], ysim[sl, k]) for k, o in enumerate(out)}
    ll = float(lp.log_likelihood(mp.theta[None])[0])
    n_obs = int(np.isfinite(lp.observed).sum())
    k = lp.ndim
    return {
        "model": label or model.name,
        "n_params": int(k),
        "n_model_params": len(model.parameter_names),
        "fit": fit,
        "log_likelihood": ll,
        "aic": 2 * k - 2 * ll,
        "bic": k * float(np.log(max(n_obs, 1))) - 2 * ll,
        "rank": int(ident.rank),
        "n_null": len(ident.directions),
        "null_directions": [d.label for d in ident.directions],
        "condition_number_identifiable": float(ident.condition_number_identifiable),
        "map_agreed": f"{mp.n_agreed}/{mp.n_starts}",
        "sampled": False,
    }
