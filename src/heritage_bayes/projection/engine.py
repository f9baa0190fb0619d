"""Predictive simulation of posterior draws on each weather, streamed, with risk.

For each chunk of posterior draws the thermal and hygric models are simulated over the
whole weather of one case, a draw of each section's noise model is added (so bands are
predictive, not only parametric), the indoor RH is formed from the coupled ``Ti`` and
``Pi`` and capped at saturation, and the chunk is reduced at once to what is kept:
the risk indicators of every draw (of the predictive series and of the noise-free one,
for the uncertainty split) and monthly means of ``Ti`` and ``RHi``. Peak memory is a
few arrays of ``chunk × hours`` doubles, whatever the number of draws.

The same parameter draws and the same noise realisations (seeded per chunk) are used
for every case: differences between scenarios are then paired, not blurred by noise.
Models are simulated with ``model.forward``: a controlled room (thermostat, humidistat)
keeps its calibrated control.
"""

from __future__ import annotations

import time
from dataclasses import dataclass

import numpy as np
import pandas as pd

from heritage_bayes.climate.psychro import saturation_vapour_pressure
from heritage_bayes.errors import ConfigError, InputError


@dataclass
class Draws:
    """Posterior draws used by the projection: model and noise parameters per section."""

    index: np.ndarray  # (K,) positions in the flattened (chain, draw) posterior
    model: dict  # section -> (K, p) model parameter array [SI]
    noise: dict  # section -> (K, q) noise parameters in the noise model's order
    noise_models: dict  # section -> NoiseModel


@dataclass
class CaseResult:
    """What is kept of one case."""

    predictive: pd.DataFrame  # draws × indicators (with the noise draw)
    parametric: pd.DataFrame  # draws × indicators (noise-free: parameter uncertainty only)
    months: pd.DatetimeIndex
    Ti_month: np.ndarray  # (K, n_months) [°C]
    RHi_month: np.ndarray  # (K, n_months) [%]
    seconds: dict


def select_draws(run, n: int | None, seed: int) -> Draws:
    """``n`` posterior draws (random without replacement, seeded; all if None).

    Raises
    ------
    InputError
        ``n`` larger than the posterior holds.
    """
    from heritage_bayes.inference.likelihoods import get_noise_model

    post = run.idata.posterior
    total = int(post.sizes["chain"] * post.sizes["draw"])
    if n is not None and n > total:
        raise InputError(
            f"draws: {n} requested, but the posterior of {run.path} holds {total} draws "
            f"(chains × draws); ask for at most {total}"
        )
    idx = np.arange(total)
    if n is not None and n < total:
        idx = np.sort(np.random.default_rng(seed).choice(total, size=n, replace=False))
    model, noise, nms = {}, {}, {}
    for section, m in run.models.items():
        params = run.draws(section)  # all draws, in the flattened posterior order
        P, _ = m.param_array({k: v[idx] for k, v in params.items()})
        model[section] = P
        nm = get_noise_model(getattr(run.config, section).noise)
        names = [name for name, _, _ in nm.parameter_specs(m.output_names)]
        cols = [post[f"{section}.{name}"].values.reshape(-1)[idx] for name in names]
        noise[section] = np.column_stack(cols) if cols else np.zeros((len(idx), 0))
        # the calibration's predictive error model, where it replaced the posterior's
        pred = ((run.summary.get("models") or {}).get(section) or {}).get("predictive_noise")
        for out, fit in (pred or {}).items():
            for kind in ("sigma", "phi", "sigma_meas"):
                name = f"{kind}_{out}"
                if name in names:
                    noise[section][:, names.index(name)] = fit[kind]
        nms[section] = nm
    return Draws(index=idx, model=model, noise=noise, noise_models=nms)


def _relative_humidity(T: np.ndarray, P: np.ndarray) -> np.ndarray:
    """RH [%] from T [°C] and vapour pressure [Pa], capped to 0–100 % (saturation)."""
    return np.clip(100.0 * P / saturation_vapour_pressure(T), 0.0, 100.0)


def _month_starts(index: pd.DatetimeIndex) -> tuple[np.ndarray, pd.DatetimeIndex]:
    per = index.tz_convert("UTC").tz_localize(None).to_period("M")
    codes = per.asi8
    starts = np.flatnonzero(np.r_[True, codes[1:] != codes[:-1]])
    return starts, per[starts].to_timestamp().tz_localize("UTC")


def _monthly(x: np.ndarray, starts: np.ndarray) -> np.ndarray:
    sums = np.add.reduceat(x, starts, axis=1)
    counts = np.diff(np.r_[starts, x.shape[1]])
    return (sums / counts).astype(np.float32)


def simulate_case(
    run,
    draws: Draws,
    inputs: pd.DataFrame,
    *,
    seed: int,
    noise: bool = True,
    chunk: int = 50,
    init_steps: int | None = None,
    risk_options: dict | None = None,
) -> CaseResult:
    """Predictive simulation and risk of every draw on one weather (streamed by chunks).

    Parameters
    ----------
    run : heritage_bayes.run.Run
    draws : Draws
    inputs : pandas.DataFrame
        Model inputs on an hourly grid (:func:`heritage_bayes.projection.weather.model_inputs`).
    seed : int
        Seed of the noise draws (chunk ``i`` uses ``(seed, i)``: identical across cases).
    noise : bool
        Add a draw of each section's noise model (predictive); False: noise-free only.
    chunk : int
        Draws simulated together (bounds memory: ~8 arrays of ``chunk × hours`` doubles).
    init_steps : int, optional
        Rows averaged for the steady-state initial state (default the calibration's).
    risk_options : dict, optional
        Keywords of :func:`heritage_bayes.climate.risk.assess_batch`.

    Returns
    -------
    CaseResult
    """
    from heritage_bayes.climate.risk import assess_batch

    if set(run.models) != {"thermal", "hygric"}:
        raise ConfigError(
            f"run {run.path}: a projection of risk needs both the thermal and the hygric "
            f"model (indoor T and RH); the run has {sorted(run.models)}"
        )
    dt = float(run.summary.get("dt", 3600.0))
    if dt != 3600.0:
        raise ConfigError(
            f"run {run.path}: data.step is {dt:g} s; the risk indicators need an hourly grid"
        )
    w = int(init_steps or run.summary.get("init_steps", 720))
    U = {
        s: np.ascontiguousarray(inputs[list(m.input_names)].to_numpy(dtype=float))
        for s, m in run.models.items()
    }
    starts, months = _month_starts(inputs.index)
    K = draws.index.size
    N = len(inputs)
    pred, par, tm, rm = [], [], [], []
    sec = {"simulate": 0.0, "noise": 0.0, "risk": 0.0}
    opts = dict(risk_options or {})
    for i, s0 in enumerate(range(0, K, chunk)):
        sl = slice(s0, min(s0 + chunk, K))
        rng = np.random.default_rng([seed, i])
        out = {}
        for s, m in run.models.items():
            t0 = time.perf_counter()
            u0 = U[s][: max(1, w)].mean(axis=0)  # steady state of the first window
            y = m.forward(draws.model[s][sl], U[s], dt, u_init=u0)[0][..., 0]
            t1 = time.perf_counter()
            e = None
            if noise:
                e = draws.noise_models[s].sample(rng, draws.noise[s][sl], N, 1)[..., 0]
            sec["simulate"] += t1 - t0
            sec["noise"] += time.perf_counter() - t1
            out[s] = (y, e)
        t0 = time.perf_counter()
        Ts, Ps = out["thermal"][0], out["hygric"][0]
        RHs = _relative_humidity(Ts, Ps)
        par.append(assess_batch(Ts, RHs, **opts))
        if noise:
            T = Ts + out["thermal"][1]
            RH = _relative_humidity(T, Ps + out["hygric"][1])
            pred.append(assess_batch(T, RH, **opts))
        else:
            T, RH = Ts, RHs
            pred.append(par[-1])
        tm.append(_monthly(T, starts))
        rm.append(_monthly(RH, starts))
        sec["risk"] += time.perf_counter() - t0
    return CaseResult(
        predictive=_concat(pred),
        parametric=_concat(par),
        months=months,
        Ti_month=np.concatenate(tm),
        RHi_month=np.concatenate(rm),
        seconds=sec,
    )


def _concat(parts: list[pd.DataFrame]) -> pd.DataFrame:
    df = pd.concat(parts, ignore_index=True)
    df.index.name = "draw"
    df.attrs["units"] = dict(parts[0].attrs.get("units", {}))
    return df
