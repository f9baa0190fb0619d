"""arviz interoperability of a run's ``posterior.nc``.

- :func:`loglik_groups`: the ``log_likelihood`` group that ``az.loo(idata)`` and
  ``az.waic(idata)`` read without ``var_name`` (one combined variable when a run has
  several outputs); :func:`split_outputs` gives the per-output terms back;
- :func:`log_mean_exp`: the log of the posterior-mean density of each hour (the
  ``log_predictive_density_validation`` group, expected log predictive density);
- :func:`convergence_stats`: R-hat and bulk/tail ESS by ``az.summary`` itself on the
  draws as the file stores them (:func:`as_saved`), so that the report's figures are
  reproduced bit for bit by ``az.summary`` of the group they were computed on;
- :func:`retained_dataset`, :func:`convergence_record`: a model's retained draws (group
  ``posterior_retained_<model>``, :func:`retained_group`) and the run's convergence
  figures on them, beside those of the thinned draws of the ``posterior`` group.
"""

from __future__ import annotations

import numpy as np
import xarray as xr

from heritage_bayes._arviz import az

__all__ = [
    "JOINT_LOGLIK",
    "VALIDATION_LPD",
    "as_saved",
    "convergence_record",
    "convergence_stats",
    "log_mean_exp",
    "loglik_groups",
    "retained_dataset",
    "retained_group",
    "split_outputs",
]

#: Name of the combined pointwise log-likelihood of a run with several outputs.
JOINT_LOGLIK = "all_outputs"
#: Group of ``posterior.nc`` holding the log predictive density of each validation hour.
VALIDATION_LPD = "log_predictive_density_validation"


def retained_group(section: str) -> str:
    """The group of ``posterior.nc`` holding model ``section``'s retained draws."""
    return f"posterior_retained_{section}"


def retained_dataset(
    variables: dict[str, xr.DataArray], saved: np.ndarray, attrs: dict | None = None
) -> xr.Dataset:
    """One model's retained draws as ``posterior.nc`` stores them (a group
    :func:`retained_group`): every draw its sampler retained (walkers × draws after
    burn-in and thinning by τ, at most ``sampler.max_draws``) of the free parameters and
    of the varying derived quantities, the draws its stopping rule checked and the run's
    R-hat and ESS are computed on. The coordinate ``in_posterior`` marks, in order, the
    draws the ``posterior`` group keeps (``saved``: their positions along ``draw``).
    """
    first = next(iter(variables.values()))
    n_chain, n_draw = first.shape[:2]
    mask = np.zeros(n_draw, dtype=bool)
    mask[np.asarray(saved)] = True
    coords = {
        "chain": np.arange(n_chain),
        "draw": np.arange(n_draw),
        "in_posterior": ("draw", mask),
    }
    return xr.Dataset(variables, coords=coords, attrs=attrs or {})


def loglik_groups(loglik: dict[str, xr.DataArray], coords: dict, attrs: dict) -> dict:
    """The ``log_likelihood`` group arviz reads by default, and the per-output terms.

    ``az.loo(idata)`` and ``az.waic(idata)`` take the group's only variable when no
    ``var_name`` is given. With one output that is the output's own variable
    (``thermal.Ti``). With several (thermal and hygric), ``log_likelihood`` holds one
    variable :data:`JOINT_LOGLIK`: every output's terms on one ``observation`` axis
    (each an hour of one output; the noise of different outputs is independent, so the
    terms still sum to the log-likelihood the sampler used), with the coordinates
    ``observation_variable`` and ``observation_time`` saying which hour of which output
    each is. The per-output terms are not stored a second time (they would double the
    largest part of the file; sizes: docs/science/benchmarks.md):
    :func:`split_outputs` rebuilds them from the combined variable.
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
    return {"log_likelihood": xr.Dataset({JOINT_LOGLIK: joint}, coords=coords, attrs=attrs)}


def split_outputs(ds: xr.Dataset) -> xr.Dataset:
    """The per-output terms of a ``log_likelihood`` group written by :func:`loglik_groups`.

    With several outputs the group holds :data:`JOINT_LOGLIK` on an ``observation``
    axis; this returns one variable per output (``thermal.Ti``) on its own time axis
    (``time.thermal.Ti``), the terms and hours exactly as stored. A group without the
    combined variable (one output) is returned as it is.
    """
    if JOINT_LOGLIK not in ds.data_vars or "observation_variable" not in ds.coords:
        return ds
    joint = ds[JOINT_LOGLIK]
    names = joint["observation_variable"].values.astype(str)
    when = joint["observation_time"].values
    out = {}
    for name in dict.fromkeys(names):  # in stored order
        idx = np.flatnonzero(names == name)
        dim = f"time.{name}"
        out[name] = xr.DataArray(
            joint.values[..., idx],
            dims=(*joint.dims[:-1], dim),
            coords={**{d: joint[d].values for d in joint.dims[:-1]}, dim: when[idx]},
        )
    return xr.Dataset(out, attrs=ds.attrs)


def log_mean_exp(a) -> np.ndarray:
    """log of the mean of exp(``a``) over its first two axes (chain, draw), float64.

    Of pointwise log densities ℓ_i(θ_s) [nats]: the log pointwise predictive density
    log (1/S Σ_s p(y_i | θ_s)) of each observation (Vehtari, Gelman & Gabry 2017 [1]_,
    eq. 3), computed stably (the maximum factored out).

    References
    ----------
    .. [1] A. Vehtari, A. Gelman, J. Gabry, "Practical Bayesian model evaluation using
       leave-one-out cross-validation and WAIC", *Statistics and Computing* 27 (2017)
       1413-1432. doi:10.1007/s11222-016-9696-4
    """
    flat = np.asarray(a, dtype=float).reshape(-1, *np.shape(a)[2:])
    m = np.max(flat, axis=0)
    return m + np.log(np.mean(np.exp(flat - m), axis=0))


def convergence_stats(post: dict[str, xr.DataArray], names: list[str]):
    """Rank-normalised split R-hat, bulk and tail ESS of the draws ``names`` of ``post``.

    Computed by ``az.summary(..., kind="diagnostics", round_to="none")`` itself
    (Vehtari et al. 2021 [1]_) on the very arrays ``posterior.nc`` stores (walkers as
    chains, float64, C order), so that ``az.summary`` of the group they are stored in
    reproduces every figure bit for bit. arviz has two R-hat paths that differ:
    ``az.rhat`` folds the draws about the median of the *split* chains (dropping the
    middle draw of an odd-length chain), ``az.summary`` about the median of all draws;
    the summary's is the one a reader runs, so it is the one used here.

    Returns
    -------
    (r_hat, ess_bulk, ess_tail) : three ``pandas.Series``
        Indexed by the names.

    References
    ----------
    .. [1] A. Vehtari, A. Gelman, D. Simpson, B. Carpenter, P.-C. Bürkner, "Rank-
       normalization, folding, and localization: an improved R-hat for assessing
       convergence of MCMC", *Bayesian Analysis* 16 (2021) 667-718.
       doi:10.1214/20-BA1221
    """
    ds = xr.Dataset({v: as_saved(post[v]) for v in names})
    diag = az.summary(ds, kind="diagnostics", round_to="none")
    return diag["r_hat"], diag["ess_bulk"], diag["ess_tail"]


def convergence_record(groups: dict[str, xr.Dataset], names: list[str]) -> dict:
    """The run's convergence figures for the free parameters ``names``: on every
    retained draw, and on the thinned draws the ``posterior`` group keeps.

    ``groups`` maps a group's name to a model's retained draws
    (:func:`retained_dataset`; each name in one of them). The run's criteria (R-hat and
    bulk ESS) are judged on the retained draws, the same draws the sampler's stopping
    rule checked: the rank-normalised split R-hat compares the walkers' means with the
    spread within them, and for independent draws its excess over 1 is about
    (χ²_{M-1}/(M-1) - 1)/(2N) for M half-chains of N draws (the between-chain variance
    of Gelman & Rubin [1]_), a noise that shrinks as 1/N. On the few draws per walker
    the ``posterior`` group keeps (sized by the log-likelihood group) the largest R-hat
    of a handful of well-mixed parameters lies above 1.01 in most runs, so those figures
    are recorded (``saved_*``) but decide nothing (docs/science/benchmarks.md, "Which
    draws the convergence figures are on").

    Returns
    -------
    dict
        ``r_hat``, ``ess_bulk``, ``ess_tail`` (name -> float, retained draws),
        ``max_rhat`` and ``min_ess_bulk`` over the names (retained draws), and
        ``convergence_draws``: ``on`` (``"retained"``), ``walkers``, ``groups`` (group
        -> its draws per walker), ``saved_draws_per_walker``, ``saved_max_rhat`` and
        ``saved_min_ess_bulk`` (what ``az.summary`` of the ``posterior`` group gives).

    References
    ----------
    .. [1] A. Gelman, D. B. Rubin, "Inference from iterative simulation using multiple
       sequences", *Statistical Science* 7 (1992) 457-472. doi:10.1214/ss/1177011136
    """
    out: dict = {"r_hat": {}, "ess_bulk": {}, "ess_tail": {}}
    saved_r, saved_e, sizes = [], [], {}
    walkers, n_saved = 0, 0
    for group, ds in groups.items():
        mine = [k for k in names if k in ds.data_vars]
        if not mine:
            continue
        stats = convergence_stats(ds, mine)
        for key, stat in zip(("r_hat", "ess_bulk", "ess_tail"), stats, strict=True):
            out[key].update({k: float(stat[k]) for k in mine})
        r, e, _ = convergence_stats(ds.isel(draw=ds["in_posterior"].values), mine)
        saved_r.append(float(r.max()))
        saved_e.append(float(e.min()))
        sizes[group] = int(ds.sizes["draw"])
        walkers, n_saved = int(ds.sizes["chain"]), int(ds["in_posterior"].sum())
    if not sizes:
        raise ValueError(
            f"convergence_record: none of the parameters {names} is in a retained group "
            f"({sorted(groups)})"
        )
    out["max_rhat"] = max(out["r_hat"].values())
    out["min_ess_bulk"] = min(out["ess_bulk"].values())
    out["convergence_draws"] = {
        "on": "retained",
        "walkers": walkers,
        "groups": sizes,
        "saved_draws_per_walker": n_saved,
        "saved_max_rhat": max(saved_r),
        "saved_min_ess_bulk": min(saved_e),
    }
    return out


def as_saved(da: xr.DataArray) -> xr.DataArray:
    """``da`` with its values as ``posterior.nc`` hands them back: a C-ordered float64
    copy (what ``h5netcdf`` reads). Sums over the draws (means, variances, the ESS's
    autocovariances) then run in the same order in memory and from the file."""
    return da.copy(data=np.ascontiguousarray(da.values, dtype=np.float64))
