"""arviz interoperability of a run's ``posterior.nc``.

- :func:`loglik_groups`: the ``log_likelihood`` group that ``az.loo(idata)`` and
  ``az.waic(idata)`` read without ``var_name`` (one combined variable when a run has
  several outputs), and the per-output terms beside it;
- :func:`convergence_stats`: R-hat and bulk/tail ESS with the estimators of
  ``az.summary`` on the draws the file stores, so that the report's figures are
  reproduced by ``az.summary(az.from_netcdf("posterior.nc"))``.
"""

from __future__ import annotations

import numpy as np
import xarray as xr

from heritage_bayes._arviz import az

__all__ = ["JOINT_LOGLIK", "convergence_stats", "loglik_groups"]

#: Name of the combined pointwise log-likelihood of a run with several outputs.
JOINT_LOGLIK = "all_outputs"


def loglik_groups(loglik: dict[str, xr.DataArray], coords: dict, attrs: dict) -> dict:
    """The ``log_likelihood`` group arviz reads by default, and the per-output terms.

    ``az.loo(idata)`` and ``az.waic(idata)`` take the group's only variable when no
    ``var_name`` is given. With one output that is the output's own variable
    (``thermal.Ti``). With several (thermal and hygric), ``log_likelihood`` holds one
    variable :data:`JOINT_LOGLIK`: every output's terms on one ``observation`` axis
    (each an hour of one output; the noise of different outputs is independent, so the
    terms still sum to the log-likelihood the sampler used), with the coordinates
    ``observation_variable`` and ``observation_time`` saying which hour of which output
    each is; the per-output variables go to ``log_likelihood_outputs`` (not an arviz
    group: ``az.loo(idata, var_name=...)`` does not see it; read it with
    :func:`heritage_bayes.compare.scores.pointwise_terms`).
    """
    if len(loglik) <= 1:
        return {"log_likelihood": xr.Dataset(loglik, coords=coords, attrs=attrs)}
    names = list(loglik)
    vals = np.concatenate([loglik[v].values for v in names], axis=-1)
    var = np.concatenate([np.full(loglik[v].shape[-1], v, dtype=object) for v in names])
    when = np.concatenate([loglik[v][loglik[v].dims[-1]].values for v in names])
    joint = xr.DataArray(
        vals,
        dims=("chain", "draw", "observation"),
        coords={
            "observation": np.arange(vals.shape[-1]),
            "observation_variable": ("observation", var.astype(str)),
            "observation_time": ("observation", when),
        },
        attrs={"description": f"pointwise terms of {', '.join(names)} on one axis"},
    )
    return {
        "log_likelihood": xr.Dataset({JOINT_LOGLIK: joint}, coords=coords, attrs=attrs),
        "log_likelihood_outputs": xr.Dataset(loglik, coords=coords, attrs=attrs),
    }


def convergence_stats(post: dict[str, xr.DataArray], names: list[str]):
    """Rank-normalised split R-hat, bulk and tail ESS of the saved draws ``names``.

    The estimators of ``az.summary`` (Vehtari et al. 2021 [1]_) on the very arrays
    ``posterior.nc`` stores (walkers as chains), so that the report's figures are
    reproduced by ``az.summary(az.from_netcdf("posterior.nc"))``. The sampler's stopping
    rule checks all its retained draws (:func:`heritage_bayes.inference.sampler.run_sampler`);
    the saved draws are an evenly thinned subset, nearly independent, so their bulk
    ESS is close to their number when the chain has converged.

    Returns
    -------
    (r_hat, ess_bulk, ess_tail) : three ``xarray.Dataset``
        Indexed by the names.

    References
    ----------
    .. [1] A. Vehtari, A. Gelman, D. Simpson, B. Carpenter, P.-C. Bürkner, "Rank-
       normalization, folding, and localization: an improved R-hat for assessing
       convergence of MCMC", *Bayesian Analysis* 16 (2021) 667-718.
       doi:10.1214/20-BA1221
    """
    ds = xr.Dataset({v: post[v] for v in names})
    return az.rhat(ds), az.ess(ds, method="bulk"), az.ess(ds, method="tail")
