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
    items = run_dirs.items() if isinstance(run_dirs, Mapping) else ((None, p) for p in run_dirs)
    out = {}
    for label, p in items:
        p = Path(p)
        nc = p / "posterior.nc"
        if not nc.is_file():
            raise InputError(f"{p}: not a run directory (posterior.nc is missing)")
        out[label or p.name] = az.from_netcdf(str(nc), engine="h5netcdf")
    return out


def pointwise_terms(idata, var_name: str | None = None) -> xr.Dataset:
    """The group holding the per-output calibration terms ``var_name`` (``thermal.Ti``).

    A run with one output keeps them in ``log_likelihood``; a run with several keeps
    their combination there (the default of ``az.loo``), from which the per-output terms
    are rebuilt (:func:`heritage_bayes.inference.interop.split_outputs`); runs written
    before issue 28 also hold them in ``log_likelihood_outputs``.
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
