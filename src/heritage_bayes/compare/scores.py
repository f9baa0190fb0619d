"""Accuracy scores from run directories: blocked PSIS-LOO data and the validation ELPD.

Part of :mod:`heritage_bayes.compare` (see its documentation).
"""

from __future__ import annotations

import math
from collections.abc import Mapping, Sequence
from pathlib import Path

import numpy as np
import xarray as xr

from heritage_bayes._arviz import az
from heritage_bayes.errors import InputError
from heritage_bayes.inference.interop import VALIDATION_LPD, log_mean_exp, split_outputs


def load_inference(run_dirs: Sequence[str | Path] | Mapping[str, str | Path]) -> dict:
    """InferenceData of run directories, ready for ``az.loo`` and ``az.compare``.

    Parameters
    ----------
    run_dirs : sequence of paths, or mapping label -> path
        Run directories written by ``hbayes calibrate``; labels default to the folder
        names.

    Returns
    -------
    dict label -> arviz.InferenceData
        ``az.compare(load_inference([...]), var_name="thermal.Ti")`` compares the runs
        by hour-wise PSIS-LOO (see :func:`blocked_loo_data` for the blocked version).

    Raises
    ------
    InputError
        A folder is not a complete run directory.
    """
    from heritage_bayes.rundir.reader import check_run_files, read_posterior

    items = run_dirs.items() if isinstance(run_dirs, Mapping) else ((None, p) for p in run_dirs)
    out = {}
    for label, p in items:
        p = check_run_files(p, ("posterior.nc",))
        out[label or p.name] = read_posterior(p)
    return out


def pointwise_terms(idata, var_name: str | None = None) -> xr.Dataset:
    """The group holding the per-output calibration terms ``var_name`` (``thermal.Ti``).

    A run with one output keeps them in ``log_likelihood``; a run with several keeps
    their combination there (the default of ``az.loo``), from which the per-output terms
    are rebuilt (:func:`heritage_bayes.inference.interop.split_outputs`); older runs
    (without ``log_predictive_density_validation``) also hold them in ``log_likelihood_outputs``.
    """
    if var_name is not None and var_name in idata.log_likelihood:
        return idata.log_likelihood
    if "log_likelihood_outputs" in idata.groups():
        return idata["log_likelihood_outputs"]
    return split_outputs(idata.log_likelihood)


def _one_var(ds: xr.Dataset, var_name: str | None, where: str) -> str:
    names = list(ds.data_vars)
    if var_name is None:
        if len(names) != 1:
            raise InputError(f"{where}: several outputs {names}; give var_name")
        return names[0]
    if var_name not in ds:
        raise InputError(f"{where}: no variable {var_name!r}; it has {names}")
    return var_name


def _block_codes(times: np.ndarray, hours: float) -> np.ndarray:
    """Block index of each time: consecutive blocks of ``hours`` from the first time."""
    t = (times - times[0]) / np.timedelta64(1, "s")
    return np.floor(t / (hours * 3600.0) + 1e-9).astype(int)


def _block_sum(da: xr.DataArray, hours: float) -> xr.DataArray:
    dim = da.dims[-1]
    codes = _block_codes(da[dim].values, hours)
    vals = np.asarray(da.values, dtype=float)
    uniq, inv = np.unique(codes, return_inverse=True)
    out = np.zeros((*vals.shape[:-1], uniq.size))
    for i in range(uniq.size):  # few hundred blocks: a loop over blocks is fine
        out[..., i] = vals[..., inv == i].sum(axis=-1)
    start = da[dim].values[np.searchsorted(inv, np.arange(uniq.size))]
    return xr.DataArray(
        out, dims=(*da.dims[:-1], "block"), coords={"block": start}, attrs={"block_hours": hours}
    )


def blocked_loo_data(idata, var_name: str | None = None, block_hours: float = 24.0):
    """InferenceData whose ``log_likelihood`` holds block sums, for blocked PSIS-LOO.

    The pointwise calibration terms of ``var_name`` are summed over consecutive blocks of
    ``block_hours`` (default a day; the block of an hour counts from the first observed
    hour); ``az.loo`` on the result leaves out one block at a time, ``az.compare`` ranks
    runs by it. The posterior group is kept for the relative efficiency.
    """
    ll = pointwise_terms(idata, var_name)
    v = _one_var(ll, var_name, "log_likelihood")
    blocks = _block_sum(ll[v], block_hours)
    return az.InferenceData(
        posterior=idata.posterior, log_likelihood=xr.Dataset({v: blocks}, attrs=ll.attrs)
    )


def tempered_loo(data, var_name: str, temperature: float = 1.0):
    """PSIS-LOO of draws from a tempered posterior (``likelihood_temperature`` T).

    ``az.loo`` weights draw s for left-out point i by 1 / p(y_i | θ_s): right for draws
    of the posterior ∝ prior × Π p(y_j | θ). Draws of the tempered posterior ∝ prior ×
    Π p(y_j | θ)^(1/T) count each point with weight 1/T, so leaving it out divides by
    p(y_i | θ_s)^(1/T): the raw log weights are −log p / T (Pareto-smoothed,
    Vehtari et al. 2024), and the predictive density they average is the untempered
    p(y_i | θ_s). T = 1 is ``az.loo`` itself. (How far ``az.loo``'s weights are off on
    the demo: the manual's *Benchmarks*, "LOO of a tempered posterior".)

    Parameters
    ----------
    data : arviz.InferenceData
        With ``posterior`` and the (blocked) ``log_likelihood`` of ``var_name``.
    var_name : str
        The log-likelihood variable.
    temperature : float
        The run's likelihood temperature (``summary.json``:
        ``models.<section>.likelihood_temperature``).

    Returns
    -------
    arviz.ELPDData
        As ``az.loo(..., pointwise=True)``: ``elpd_loo``, ``se``, ``p_loo``, ``loo_i``,
        ``pareto_k``; ``az.compare`` takes it.
    """
    from arviz.stats.stats_utils import ELPDData
    from scipy.special import logsumexp

    if temperature == 1.0:
        return az.loo(data, var_name=var_name, pointwise=True)
    ll = data.log_likelihood[var_name].stack(__sample__=("chain", "draw"))
    n_samples = ll.shape[-1]
    n_points = int(np.prod(ll.shape[:-1]))
    ess_p = az.ess(data.posterior, method="mean")  # as az.loo: the draws' relative efficiency
    reff = np.hstack([ess_p[v].values.ravel() for v in ess_p.data_vars]).mean() / n_samples
    lw, pareto_k = az.psislw(-ll / temperature, reff)
    loo_i = logsumexp((lw + ll).values, axis=-1)
    elpd = float(loo_i.sum())
    lppd = float(np.sum(logsumexp(ll.values, axis=-1) - math.log(n_samples)))
    good_k = min(1 - 1 / np.log10(n_samples), 0.7)
    dims = [d for d in ll.dims if d != "__sample__"]
    loo_i = xr.DataArray(loo_i, dims=dims, coords={d: ll[d] for d in dims}, name="loo_i")
    return ELPDData(
        data=[
            elpd,
            float((n_points * np.var(loo_i.values)) ** 0.5),
            lppd - elpd,
            n_samples,
            n_points,
            bool(np.any(pareto_k.values > good_k)),
            loo_i,
            pareto_k,
            "log",
            good_k,
        ],
        index=[
            "elpd_loo",
            "se",
            "p_loo",
            "n_samples",
            "n_data_points",
            "warning",
            "loo_i",
            "pareto_k",
            "scale",
            "good_k",
        ],
    )


def elpd_validation(idata, var_name: str | None = None, block_hours: float = 24.0) -> dict:
    """Expected log predictive density of the validation hours.

    Returns
    -------
    dict
        ``elpd`` (sum over hours of the log posterior-mean predictive density), ``se``
        (from block sums, see the module docstring), ``n`` hours, ``pointwise`` (n,)
        array and ``times`` (n,) of the hours; None when the run has no validation
        period.
    """
    if VALIDATION_LPD in idata.groups():  # stored per hour (issue 28)
        ds = idata[VALIDATION_LPD]
        v = _one_var(ds, var_name, VALIDATION_LPD)
        pw = np.asarray(ds[v].values, dtype=float)
    elif "log_likelihood_validation" in idata.groups():  # runs written before
        ds = idata["log_likelihood_validation"]
        v = _one_var(ds, var_name, "log_likelihood_validation")
        pw = log_mean_exp(ds[v].values)
    else:
        return None
    da = ds[v]
    times = da[da.dims[-1]].values
    return {
        "elpd": float(pw.sum()),
        "se": _block_se(pw, times, block_hours),
        "n": int(pw.size),
        "pointwise": pw,
        "times": times,
    }


def _block_se(pw: np.ndarray, times: np.ndarray, hours: float) -> float:
    """Standard error of a sum of autocorrelated terms from its block sums."""
    codes = _block_codes(times, hours)
    sums = np.bincount(codes - codes.min(), weights=pw)
    sums = sums[np.bincount(codes - codes.min()) > 0]
    if sums.size < 2:
        return float("nan")
    return float(math.sqrt(sums.size * np.var(sums, ddof=1)))
