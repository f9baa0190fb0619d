"""Build the run's InferenceData and ``summary.json`` from sampled sections.

See :mod:`heritage_bayes.inference.results` for the layout. Thermal and hygric models are
sampled independently; their retained draws share the (chain, draw) grid so that draw
*i* of one pairs with draw *i* of the other, which is how the combined indoor RH
(:math:`RH = P_i / P_{sat}(T_i)`) is predicted. R-hat and ESS are those of every draw
a model's sampler retained (its group ``posterior_retained_<model>``: the draws its
stopping rule checked); the quantiles, bands and log-likelihoods those of the thinned
draws of the ``posterior`` group
(:func:`~heritage_bayes.inference.interop.convergence_record`).
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from datetime import UTC, datetime

import numpy as np
import pandas as pd
import xarray as xr

from heritage_bayes._arviz import az
from heritage_bayes._version import __version__
from heritage_bayes.calibration.runinfo import (
    _frozen_share,
    _hours,
    _metrics_for,
    _periods,
    _truth_for,
    _versions,
)
from heritage_bayes.climate.psychro import saturation_vapour_pressure
from heritage_bayes.inference.interop import (
    VALIDATION_LPD,
    convergence_record,
    convergence_stats,
    log_mean_exp,
    loglik_groups,
    retained_dataset,
    retained_group,
)
from heritage_bayes.inference.predictive import (
    _saved_index,
    bounded_predictive,
    condensation_cap,
    initial_state_text,
    predictive_bands,
    predictive_noise,
)
from heritage_bayes.rc.discretize import modal_form
from heritage_bayes.rc.identify import derived_quantities, derived_units

__all__ = ["CONVERGENCE", "build_run_outputs"]

#: Convergence criteria (also in summary.json).
CONVERGENCE = {"max_rhat": 1.01, "min_ess_bulk": 400.0}

_OUT_UNITS = {"Ti": "°C", "Pi": "Pa", "RHi": "%"}
_CDIMS = ("chain", "draw")


def _times(prep) -> np.ndarray:
    idx = pd.DatetimeIndex(prep.frame.index)
    return idx.tz_convert("UTC").tz_localize(None).values


def _period_codes(prep) -> np.ndarray:
    code = np.full(prep.n_rows, -1, dtype=np.int8)
    cal = prep.calibration
    code[cal] = 1
    if prep.validation is not None:
        code[prep.validation] = 2
    code[cal.start : cal.start + prep.warmup_steps] = 0
    return code


def _pointwise(s, pw: np.ndarray, times: np.ndarray, shape) -> dict[str, xr.DataArray]:
    """Pointwise log-likelihood terms (K, N, n_out) -> one DataArray per output.

    Only hours with a finite term (an observation that enters the likelihood) are kept,
    on one ``time.<section>.<output>`` axis per output, so that ``az.loo`` uses them all.
    """
    out = {}
    for o, name in enumerate(s.model.output_names):
        idx = np.flatnonzero(np.isfinite(pw[0, :, o]))
        if idx.size == 0:
            continue
        dim = f"time.{s.name}.{name}"
        out[f"{s.name}.{name}"] = xr.DataArray(
            # float32: ample for log densities (1e-7 relative), half the file size
            pw[:, idx, o].reshape(*shape, idx.size).astype(np.float32),
            dims=("chain", "draw", dim),
            coords={dim: times[idx]},
        )
    return out


def _validation_lpd(terms: xr.DataArray, n_draws: int) -> xr.DataArray:
    """(time,) log pointwise predictive density of validation hours [nats] from their
    (chain, draw, time) terms: log of the mean density over the draws (float64)."""
    dim = terms.dims[-1]
    return xr.DataArray(
        log_mean_exp(terms.values),
        dims=(dim,),
        coords={dim: terms[dim].values},
        attrs={
            "unit": "nats",
            "description": "log of the posterior-mean predictive density of "
            f"each validation hour, over the {n_draws} draws of the posterior group",
        },
    )


def _validation_pointwise(s, prep, Ysim, tn, th=None) -> np.ndarray:
    """(K, N, n_out) one-step predictive log densities of the validation observations.

    ``Ysim`` is the simulation over the whole frame (from the calibration's initial
    state); the noise model conditions each term on the previous validation residual (the
    first one has the stationary variance), NaN outside the validation period. Under
    ``noise: kalman`` the filter runs over the frame from the initial-state prior with
    only the validation hours observed (``th``: the full parameter values).
    """
    obs = np.asarray(prep.observed(s.name, s.model), dtype=float)
    Yobs = np.full_like(obs, np.nan)
    if prep.validation is not None:
        Yobs[prep.validation] = obs[prep.validation]
    if prep.breaks is not None:  # no prediction inside an input gap
        Yobs[prep.breaks] = np.nan
    Yobs = np.ascontiguousarray(Yobs)
    lp = s.logpost
    if lp.noise.statespace and th is not None:
        mf = lp._form(th[:, : lp.n_model])
        U = np.ascontiguousarray(prep.model_inputs(s.name, s.model), dtype=float)
        return lp.noise.filter(s.model, mf, U, Yobs, tn, *lp._x0_prior(mf), True)[1]
    return lp.noise.pointwise(Ysim, Yobs, tn)


def _one_step_sample(s, prep, th, rng) -> np.ndarray:
    """(K, N, n_out) one-step-ahead predictive samples of a state-space noise model.

    The Kalman filter of ``noise: kalman`` runs over the whole frame with every
    measurement (calibration and validation), from the initial-state prior, as
    :func:`_validation_pointwise` does; each row's sample is the filter's prediction from
    the measurements before it plus a draw of its predictive variance (measurement noise
    included): the band a forecaster updating with the logger would quote, where the
    free-run band is what the model claims without measurements (N. R. Kristensen,
    H. Madsen, S. B. Jørgensen, "Parameter estimation in stochastic grey-box models",
    Automatica 40 (2004) 225-237).
    """
    lp = s.logpost
    obs = np.ascontiguousarray(prep.observed(s.name, s.model), dtype=float)
    mf = lp._form(th[:, : lp.n_model])
    U = np.ascontiguousarray(prep.model_inputs(s.name, s.model), dtype=float)
    tn = th[:, lp.n_model :]
    with np.errstate(all="ignore"):
        _, _, mean, var = lp.noise.filter(s.model, mf, U, obs, tn, *lp._x0_prior(mf), True)
    mean[~mf.valid], var[~mf.valid] = np.nan, np.nan
    if prep.breaks is not None:  # no prediction inside an input gap
        mean[:, prep.breaks] = np.nan
    return mean + np.sqrt(np.maximum(var, 0.0)) * rng.standard_normal(mean.shape)


def _prior_variance(prior, rng) -> float:
    y = prior.sample(rng, 20000)
    y = np.log(y) if prior.log_scale else y
    return float(np.var(y))


def _summ(x: np.ndarray) -> dict:
    q05, q50, q95 = np.quantile(x, [0.05, 0.5, 0.95])
    return {
        "median": float(q50),
        "q05": float(q05),
        "q95": float(q95),
        "mean": float(np.mean(x)),
        "sd": float(np.std(x)),
    }


@dataclass
class _Outputs:
    """What :func:`build_run_outputs` gathers section by section: the InferenceData
    groups' variables and the summary's entries."""

    W: int
    D: int
    sel: np.ndarray
    times: np.ndarray
    codes: np.ndarray
    post: dict = field(default_factory=dict)
    #: section -> every retained draw of its free parameters and varying derived
    #: quantities (:func:`retained_dataset`)
    retained: dict = field(default_factory=dict)
    stats: dict = field(default_factory=dict)
    loglik: dict = field(default_factory=dict)
    loglik_val: dict = field(default_factory=dict)
    pp: dict = field(default_factory=dict)
    params: dict = field(default_factory=dict)
    derived: dict = field(default_factory=dict)
    metrics: dict = field(default_factory=dict)
    models: dict = field(default_factory=dict)
    correlations: dict = field(default_factory=dict)
    #: output -> (K, N) predictive and simulated draws
    pp_outputs: dict = field(default_factory=dict)
    #: output -> (K, N) one-step samples (state-space noise)
    one_step: dict = field(default_factory=dict)

    def series(self, values: np.ndarray, attrs: dict) -> xr.DataArray:
        """(K, N) draws of a time series -> a float32 (chain, draw, time) DataArray."""
        n_sel = len(self.sel)
        return xr.DataArray(
            values.reshape(self.W, n_sel, -1).astype(np.float32),
            dims=("chain", "draw", "time"),
            coords={"chain": np.arange(self.W), "draw": np.arange(n_sel), "time": self.times},
            attrs=attrs,
        )


def build_run_outputs(cfg, prep, sections, *, chash: str, seed: int):
    """(InferenceData, summary dict) for sampled sections (see module docstring)."""
    rng = np.random.default_rng(seed + 7)
    W, D = sections[0].X.shape[:2]
    # every group holds the same draws (arviz convention: az.loo takes the relative
    # efficiency from the posterior and the terms from log_likelihood)
    sel = _saved_index(W, D, cfg.sampler.n_predictive)
    o = _Outputs(W, D, sel, _times(prep), _period_codes(prep))
    for s in sections:
        dq_all, dq_units = _posterior_draws(o, s)
        x0, pred_info, saturation = _predictive_draws(o, s, prep, rng, seed)
        _parameter_summaries(o, cfg, prep, s, seed, dq_units)
        o.metrics[s.name] = _metrics_for(
            prep, o.codes, s.model.output_names, o.pp_outputs, o.one_step
        )
        o.models[s.name] = _section_info(o, s, x0, pred_info, saturation, dq_all)
    _combined_rh(o, prep)
    attrs = {
        "heritage_bayes_version": __version__,
        "seed": int(seed),
        "config_hash": chash,
        "created_at": datetime.now(UTC).isoformat(timespec="seconds"),
        "run_name": cfg.name or "",
        "dt_seconds": float(prep.dt),
    }
    idata = _inference_data(o, prep, sections, attrs)
    return idata, _summary(o, cfg, prep, sections, attrs)


def _posterior_draws(o: _Outputs, s) -> tuple[dict, dict]:
    """The saved draws of a section's parameters and derived quantities, its retained
    draws and its sampler statistics; returns (derived quantity -> its (W, D) draws
    common to the sections, -> its unit)."""
    ps, W, D = s.logpost.params, o.W, o.D
    kept = s.theta_kept  # (W, n, p); s.theta is its last D draws
    retained = {}
    for j, p in enumerate(ps.parameters):
        attrs = {"unit": p.unit, "kind": p.kind, "description": p.description}
        o.post[f"{s.name}.{p.name}"] = xr.DataArray(
            np.ascontiguousarray(s.theta[:, o.sel, j], dtype=np.float64),
            dims=_CDIMS,
            attrs=attrs,
        )
        if p.free:
            retained[f"{s.name}.{p.name}"] = xr.DataArray(
                np.ascontiguousarray(kept[..., j], dtype=np.float64), dims=_CDIMS, attrs=attrs
            )
    tm = kept[..., : s.logpost.n_model]
    dq = derived_quantities(s.model, tm.reshape(-1, tm.shape[-1]))
    units = derived_units(s.model)
    dq_all = {}
    for k, v in dq.items():
        full = np.broadcast_to(np.asarray(v, dtype=float), (tm.shape[0] * tm.shape[1],))
        full = full.reshape(tm.shape[:2])
        dq_all[k] = arr = full[:, -D:]
        attrs = {"unit": units.get(k, "")}
        o.post[f"{s.name}.{k}"] = xr.DataArray(
            np.ascontiguousarray(arr[:, o.sel], dtype=np.float64), dims=_CDIMS, attrs=attrs
        )
        if np.all(np.isfinite(full)) and np.ptp(full) > 0:  # R-hat and ESS are defined
            retained[f"{s.name}.{k}"] = xr.DataArray(
                np.ascontiguousarray(full, dtype=np.float64), dims=_CDIMS, attrs=attrs
            )
    if retained:  # the posterior group's draws: the last D, thinned to o.sel
        o.retained[s.name] = retained_dataset(retained, kept.shape[1] - D + o.sel)
    o.stats[f"{s.name}.lp"] = xr.DataArray(s.lp[:, o.sel], dims=_CDIMS)
    o.stats[f"{s.name}.acceptance_rate"] = xr.DataArray(
        np.broadcast_to(s.chain.acceptance[:, None], (W, len(o.sel))).copy(), dims=_CDIMS
    )
    return dq_all, {k: units.get(k, "") for k in dq}


def _predictive_draws(o: _Outputs, s, prep, rng, seed: int):
    """The initial states, the predictive and simulated outputs over the whole frame and
    the pointwise log-likelihoods of the saved draws; returns (initial states (K, n) or
    None, the predictive noise's description, the condensation cap's)."""
    W, n_sel, n_model = o.W, len(o.sel), s.logpost.n_model
    th_sel = s.theta[:, o.sel].reshape(-1, s.theta.shape[-1])
    tn_sel = th_sel[:, n_model:]
    U = prep.model_inputs(s.name, s.model)
    # the initial state: a draw from its conditional posterior for each draw
    x0 = s.logpost.initial_states(th_sel, rng)
    if x0 is not None:
        for i, node in enumerate(s.model.state_names):
            o.post[f"{s.name}.x0_{node}"] = xr.DataArray(
                x0[:, i].reshape(W, n_sel),
                dims=_CDIMS,
                attrs={
                    "unit": "°C" if s.model.domain == "thermal" else "Pa",
                    "description": f"state of node {node} at the first calibration "
                    f"step ({initial_state_text(s.logpost)})",
                },
            )
    Ysim, _ = s.logpost.simulate_frame(th_sel, U, prep.calibration.start, x0=x0)
    band_nm, tn_pred, pred_info = predictive_noise(s, prep, Ysim, tn_sel)
    if band_nm.statespace:
        mf = modal_form(s.model, th_sel[:, :n_model], prep.dt)
        noise = band_nm.sample_statespace(rng, mf, tn_pred, U.shape[0], s.model.n_outputs)
    else:
        noise = band_nm.sample(rng, tn_pred, U.shape[0], s.model.n_outputs)
    noise += Ysim  # the predictive draws, in the noise's array (one fewer K x N copy)
    Ypp, noise = noise, None
    saturation = condensation_cap(s, prep, Ysim, Ypp, o.pp_outputs)
    Y1 = None
    if s.logpost.noise.statespace:
        # its own stream: the free-run outputs above do not depend on it
        Y1 = _one_step_sample(s, prep, th_sel, np.random.default_rng([seed, 17]))
    for k, out in enumerate(s.model.output_names):
        attrs = {"unit": _OUT_UNITS.get(out, "")}
        o.pp[f"{s.name}.{out}"] = o.series(Ypp[..., k], attrs)
        o.pp[f"{s.name}.{out}_sim"] = o.series(Ysim[..., k], attrs)
        o.pp_outputs[out] = (Ypp[..., k], Ysim[..., k])
        if Y1 is not None:
            description = "one-step-ahead predictive samples"
            o.pp[f"{s.name}.{out}_1step"] = o.series(
                Y1[..., k], {**attrs, "description": description}
            )
            o.one_step[out] = Y1[..., k]
    pw = s.logpost.pointwise_log_likelihood(th_sel)
    o.loglik.update(_pointwise(s, pw, o.times[prep.calibration], (W, n_sel)))
    pw = _validation_pointwise(s, prep, Ysim, tn_sel, th_sel)
    o.loglik_val.update(_pointwise(s, pw, o.times, (W, n_sel)))
    return x0, pred_info, saturation


def _parameter_summaries(o: _Outputs, cfg, prep, s, seed: int, dq_units: dict) -> None:
    """The summary's entries of a section's parameters and derived quantities, and the
    posterior correlations of its free parameters.

    Quantiles are those of the ``posterior`` group's draws, R-hat and ESS those of the
    section's retained draws (:func:`retained_group`), each as ``posterior.nc`` holds
    them, so that a reader of the file reproduces every digit; contraction, bounds and
    correlations are taken on all draws the sampler kept."""
    ps = s.logpost.params
    kept = s.theta_kept
    free_vars = [f"{s.name}.{n}" for n in ps.free_names]
    retained = o.retained.get(s.name, {})
    rhat, ess_b, ess_t = convergence_stats(retained, free_vars) if free_vars else ({},) * 3
    tau = dict(zip(ps.free_names, s.chain.tau, strict=True))
    truth, truth_dq = _truth_for(cfg, prep, s)
    mapv = dict(zip(ps.names, s.map.theta, strict=True))
    prng = np.random.default_rng(seed + 11)
    for j, p in enumerate(ps.parameters):
        key = f"{s.name}.{p.name}"
        x = kept[..., j].reshape(-1)
        entry = {
            "unit": p.unit,
            "kind": p.kind,
            "description": p.description,
            "fixed": p.fixed,
            "prior": None if p.fixed is not None else p.prior.describe(),
            "prior_spec": None if p.fixed is not None else p.prior.to_dict(),
            "transform": None if p.fixed is not None else ps.modes[ps.free_names.index(p.name)],
            "map": mapv[p.name],
            **_summ(o.post[key].values.reshape(-1)),
            "truth": truth.get(p.name),
        }
        if p.free:
            y = np.log(x) if p.prior.log_scale else x
            a, b = (
                (math.log(p.prior.lower), math.log(p.prior.upper))
                if p.prior.log_scale
                else (p.prior.lower, p.prior.upper)
            )
            pos = (np.quantile(y, [0.05, 0.95]) - a) / (b - a)
            entry.update(
                r_hat=float(rhat[key]),
                ess_bulk=float(ess_b[key]),
                ess_tail=float(ess_t[key]),
                tau=float(tau[p.name]),
                contraction=float(1 - np.var(y) / _prior_variance(p.prior, prng)),
                at_bound=("lower" if pos[0] < 0.01 else "upper" if pos[1] > 0.99 else None),
            )
        o.params[key] = entry
    for k, unit in dq_units.items():
        key = f"{s.name}.{k}"
        x = o.post[key].values.reshape(-1)
        o.derived[key] = {"unit": unit, **_summ(x), "truth": truth_dq.get(k)}
        if key in retained:
            r, e, _ = convergence_stats(retained, [key])
            o.derived[key]["r_hat"] = float(r[key])
            o.derived[key]["ess_bulk"] = float(e[key])
    # posterior correlations of the free parameters (log scale where the prior is)
    Y = []
    for j, p in enumerate(ps.parameters):
        if p.free:
            x = kept[..., j].reshape(-1)
            Y.append(np.log(x) if p.prior.log_scale else x)
    corr = np.corrcoef(np.array(Y)) if len(Y) > 1 else np.ones((1, 1))
    o.correlations[s.name] = {"names": list(ps.free_names), "matrix": corr.tolist()}


def _section_info(o: _Outputs, s, x0, pred_info, saturation, dq_all: dict) -> dict:
    """The summary's ``models.<section>`` entry: the model, its noise and initial state,
    the MAP, identifiability, the chain and the findings before sampling."""
    ps = s.logpost.params
    return {
        "predictive_noise": pred_info,
        "saturation": saturation,
        "model": s.model.name,
        "domain": s.model.domain,
        "state_names": list(s.model.state_names),
        "input_names": list(s.model.input_names),
        "output_names": list(s.model.output_names),
        "noise": s.logpost.noise.name,
        "initial_state": {
            "mode": s.logpost.initial_state
            if isinstance(s.logpost.initial_state, str)
            else dict(s.logpost.initial_state),
            "how": initial_state_text(s.logpost),
            "prior_sd": s.logpost.initial_state_sd,
            "horizon_h": s.logpost.initial_state_horizon / 3600.0,
            "unit": "°C" if s.model.domain == "thermal" else "Pa",
            "nodes": (
                {node: _summ(x0[:, i]) for i, node in enumerate(s.model.state_names)}
                if x0 is not None
                else None
            ),
        },
        "map": s.map.to_dict(ps.names),
        "identifiability": s.identifiability.to_dict(),
        "chain": _chain_info(o, s),
        # findings before sampling: a MAP on a prior bound, and practical
        # identifiability from the Laplace approximation at the MAP
        "map_at_bound": [list(b) for b in getattr(s, "map_at_bound", [])],
        "frozen_node": getattr(s, "frozen_node", None),
        # a buffer link fixed at its prior's floor at the MAP (calibration.wall)
        "decoupled_wall": getattr(s, "decoupled_wall", None) and s.decoupled_wall.to_dict(),
        # the share of draws whose slowest mode is frozen (a second posterior branch)
        "frozen_share": _frozen_share(dq_all.get("tau_1_h"), s.logpost),
        "time_constant_cap_h": _hours(s.logpost.time_constant_cap),
        "likelihood_temperature": float(s.logpost.temperature),
        "practical_identifiability": (
            s.laplace.to_dict(ps.free_names) if getattr(s, "laplace", None) else None
        ),
    }


def _chain_info(o: _Outputs, s) -> dict:
    """The summary's ``models.<section>.chain``: the sampler's settings and course
    (``continued``: only for a chain continued with the time later sections left,
    :mod:`heritage_bayes.calibration.chains`)."""
    info = {
        "coordinates": getattr(s.chain, "coordinates", "log"),
        # the block move: the flagged parameters and its share of the steps
        # (0: the named moves alone)
        "block_move": getattr(s, "block_move", None) or None,
        "walkers": int(o.W),
        "steps": int(s.chain.steps),
        "burn": int(s.chain.burn),
        "thin": int(s.chain.thin),
        "draws_per_walker": int(o.D),
        "converged_tau": bool(s.chain.converged),
        "tau_max": float(np.nanmax(s.chain.tau)),
        "tau_history": [list(map(float, r)) for r in s.chain.tau_history],
        "acceptance_mean": float(np.mean(s.chain.acceptance)),
        "resumed_from": int(s.chain.resumed_from),
        "stopped_by": getattr(s.chain, "stopped_by", ""),
        "cpu_seconds": float(getattr(s.chain, "cpu_seconds", 0.0)),
    }
    if getattr(s, "continued", None) is not None:
        info["continued"] = dict(s.continued)
    return info


def _combined_rh(o: _Outputs, prep) -> None:
    """The indoor RH [%] of paired thermal and hygric draws, and its fit metrics."""
    if "Ti" not in o.pp_outputs or "Pi" not in o.pp_outputs:
        return
    ti_pp, ti_sim = o.pp_outputs["Ti"]
    pi_pp, pi_sim = o.pp_outputs["Pi"]
    rh_pp = 100.0 * pi_pp / saturation_vapour_pressure(ti_pp)
    rh_sim = 100.0 * pi_sim / saturation_vapour_pressure(ti_sim)
    o.pp["RHi"] = o.series(rh_pp, {"unit": "%"})
    o.pp["RHi_sim"] = o.series(rh_sim, {"unit": "%"})
    if "RHi" in prep.frame:
        o.metrics["combined"] = _metrics_for(prep, o.codes, ("RHi",), {"RHi": (rh_pp, rh_sim)})


def _inference_data(o: _Outputs, prep, sections, attrs: dict):
    """The run's InferenceData from the gathered groups, the observations and inputs."""
    times = o.times
    observed = {
        c: xr.DataArray(
            prep.frame[c].to_numpy(dtype=float),
            dims=("time",),
            coords={"time": times},
            attrs={"unit": _OUT_UNITS.get(c, "")},
        )
        for c in ("Ti", "Pi", "RHi")
        if c in prep.frame
    }
    inputs = sorted({c for s in sections for c in s.model.input_names})
    const = {
        c: xr.DataArray(prep.frame[c].to_numpy(dtype=float), dims=("time",), coords={"time": times})
        for c in inputs
    }
    const["period"] = xr.DataArray(
        o.codes,
        dims=("time",),
        coords={"time": times},
        attrs={"codes": "-1 outside, 0 warm-up, 1 calibration, 2 validation"},
    )
    for c in inputs:
        if c in prep.flags:
            const[f"interpolated.{c}"] = xr.DataArray(
                prep.flags[c].to_numpy(dtype=np.int8), dims=("time",), coords={"time": times}
            )
    coords = {"chain": np.arange(o.W), "draw": np.arange(len(o.sel))}
    groups = {
        "posterior": xr.Dataset(o.post, coords=coords, attrs=attrs),
        # every retained draw of each model (a superset of the posterior group's): the
        # R-hat and ESS
        **{retained_group(k): ds.assign_attrs(attrs) for k, ds in o.retained.items()},
        "sample_stats": xr.Dataset(o.stats, coords=coords, attrs=attrs),
        **loglik_groups(o.loglik, coords, attrs),
        # a bounded number of draws, the bands over all of them (the predictive was 75 %
        # of a 130 MB demo run directory)
        "posterior_predictive": xr.Dataset(bounded_predictive(o.pp), attrs=attrs),
        "predictive_bands": xr.Dataset(predictive_bands(o.pp), attrs=attrs),
        "observed_data": xr.Dataset(observed, attrs=attrs),
        "constant_data": xr.Dataset(const, attrs=attrs),
    }
    if o.loglik_val:
        # not an arviz group: the validation period is not conditioned on; what the
        # expected log predictive density of new data needs (heritage_bayes.compare) is
        # each hour's log mean density over the saved draws, stored as that: the terms
        # per draw were 4.1 MB of the demo's posterior.nc
        groups[VALIDATION_LPD] = xr.Dataset(
            {k: _validation_lpd(v, len(o.sel) * o.W) for k, v in o.loglik_val.items()},
            attrs=attrs,
        )
    return az.InferenceData(**groups)


def _summary(o: _Outputs, cfg, prep, sections, attrs: dict) -> dict:
    """The run's ``summary.json`` from the gathered entries."""
    free = [k for k, v in o.params.items() if "r_hat" in v]
    # the decision is the sampler's stopping rule: 50 τ with a stable τ, and R-hat/ESS
    # within CONVERGENCE on every retained draw; max_rhat/min_ess below are those of the
    # same retained draws in the parameters' own coordinates (the saved ones' beside)
    conv = convergence_record({retained_group(k): v for k, v in o.retained.items()}, free)
    tau_ok = all(s.chain.converged for s in sections)
    return {
        "name": cfg.name,
        "building": cfg.building,
        "room": cfg.room,
        "notes": cfg.notes,
        "heritage_bayes_version": __version__,
        "seed": attrs["seed"],
        "config_hash": attrs["config_hash"],
        "created_at": attrs["created_at"],
        "converged": bool(tau_ok),
        "converged_tau": tau_ok,
        "max_rhat": conv["max_rhat"],
        "min_ess_bulk": conv["min_ess_bulk"],
        "convergence_draws": conv["convergence_draws"],
        "criteria": {
            **CONVERGENCE,
            "tau_factor": cfg.sampler.tau_factor,
            "tau_rtol": cfg.sampler.tau_rtol,
        },
        "dt": float(prep.dt),
        "warmup_steps": int(prep.warmup_steps),
        "init_steps": int(prep.init_steps),
        "periods": _periods(prep),
        "irradiance_source": prep.irradiance_source,
        "parameters": o.params,
        "derived": o.derived,
        "metrics": o.metrics,
        "models": o.models,
        "correlations": o.correlations,
        "alignment": prep.alignment,
        "sources": prep.sources,
        "truth": prep.truth or None,
        "versions": _versions(),
    }
