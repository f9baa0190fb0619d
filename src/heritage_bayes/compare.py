"""Accuracy versus identifiability of candidate models, from full posteriors.

The paper's central trade-off: a richer RC model fits the indoor climate better, but
its parameters lose their physical meaning (Kramer, van Schijndel & Schellen). Given a
config, :func:`run_compare` calibrates each candidate model of one section (each in its
own run directory, with the calibration engine's defaults) and :func:`compare_runs`
sets them side by side:

**Accuracy**

- the paper's fit criteria on the validation period (FIT [%], MSE, MAE of the
  posterior-median simulation);
- the expected log predictive density of the validation hours, ``elpd_val`` =
  :math:`\\sum_t \\log \\frac{1}{S}\\sum_s p(y_t \\mid \\theta_s, y_{t-1})`: with AR(1)
  noise each term is the one-step-ahead predictive density of the hour given the
  previous residual, from the simulation continued past the calibration period (the
  ``log_likelihood_validation`` group of ``posterior.nc``);
- **blocked PSIS-LOO** on the calibration period: the pointwise log-likelihood summed
  over blocks of ``block_hours`` consecutive hours (default one day), then Pareto-smoothed
  importance-sampling LOO over the blocks (``az.loo``) and ``az.compare`` across models.

Why blocked LOO and not leave-future-out: hourly observations are not exchangeable
(the diurnal cycle, and residuals correlated over hours), so hour-wise LOO rewards a
model for interpolating a left-out hour from its neighbours. Leaving out whole days
removes the diurnal dependence; the AR(1) terms already condition each hour on the
previous residual. Exact leave-future-out needs one refit per forecast origin (minutes
each), and its importance-sampling approximation (PSIS-LFO, Bürkner et al. 2020) must
still refit whenever the Pareto k exceeds 0.7, which happens often when a season is
added; the validation period is the leave-future-out check that needs no refit: one
block, the future, scored by ``elpd_val``. Standard errors of ELPD differences are
computed from daily block sums for the same reason (hourly terms are correlated).

**Identifiability**

- per parameter and derived quantity (time constants, static gains): posterior
  contraction relative to the prior, :math:`1 - \\mathrm{Var}_{post}/\\mathrm{Var}_{prior}`
  (on the log scale for positive quantities; the prior of a derived quantity is the
  push-forward of the parameter priors), and the 90 % interval as a factor
  :math:`q_{95}/q_{05}`; a quantity is *identified* when that factor is at most
  ``identified_factor`` (default 2);
- the structural rank (the Jacobian of the frequency response at the MAP,
  :mod:`heritage_bayes.rc.identify`) and the **practical rank**: the number of
  directions of the free physical parameters (log scale) along which the posterior
  variance is below ``practical_ratio`` (default 1 %) of the prior variance
  (eigenvalues of the prior-whitened posterior covariance);
- the widest 90 % interval of a physical parameter, in decades.

**Recommendation** (computed from the numbers): the models whose accuracy score
(validation ELPD, or blocked LOO without a validation period) is within 2 standard
errors of the best, or within 4 nats (a negligible difference [4]_), are equivalent in
accuracy; among them, the simplest one whose time
constants are all identified is recommended; if none is, the best-identified one is,
with a warning.

References
----------
.. [1] A. Vehtari, A. Gelman, J. Gabry, "Practical Bayesian model evaluation using
   leave-one-out cross-validation and WAIC", Statistics and Computing 27 (2017)
   1413–1432, doi:10.1007/s11222-016-9696-4.
.. [2] P.-C. Bürkner, J. Gabry, A. Vehtari, "Approximate leave-future-out
   cross-validation for Bayesian time series models", J. Stat. Comput. Simul. 90 (2020)
   2499–2523, doi:10.1080/00949655.2020.1783262.
.. [3] R. Kramer, J. van Schijndel, H. Schellen, "Inverse modeling of simplified
   hygrothermal building models to predict and characterize indoor climates", Building
   and Environment 68 (2013) 87–99, doi:10.1016/j.buildenv.2013.06.019.
.. [4] T. Sivula, M. Magnusson, A. Vehtari, "Uncertainty in Bayesian leave-one-out
   cross-validation based model comparison", arXiv:2008.10296 (2020).
"""

from __future__ import annotations

import html
import math
import warnings
from collections.abc import Mapping, Sequence
from pathlib import Path

import numpy as np
import xarray as xr

from heritage_bayes._arviz import az
from heritage_bayes.errors import ConfigError, InputError

__all__ = [
    "blocked_loo_data",
    "compare_runs",
    "elpd_validation",
    "load_inference",
    "run_compare",
    "write_comparison",
]

#: ELPD differences smaller than this are negligible whatever their SE (two nearly
#: identical models have a tiny SE of their difference) [nats]; Sivula et al. (2020).
NEGLIGIBLE_ELPD = 4.0

#: Candidates when ``--models`` is not given: the model orders of each section.
DEFAULT_MODELS = {
    "thermal": ("thermal_1c", "thermal_2c", "thermal_4a"),
    "hygric": ("hygric_1c", "hygric_2c", "hygric_2c_fixed"),
}


# ------------------------------------------------------------------ arviz on runs
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
    ll = idata.log_likelihood
    v = _one_var(ll, var_name, "log_likelihood")
    blocks = _block_sum(ll[v], block_hours)
    return az.InferenceData(
        posterior=idata.posterior, log_likelihood=xr.Dataset({v: blocks}, attrs=ll.attrs)
    )


def _logmeanexp(a: np.ndarray) -> np.ndarray:
    """log mean exp over the first two axes (chain, draw)."""
    flat = np.asarray(a, dtype=float).reshape(-1, *a.shape[2:])
    m = np.max(flat, axis=0)
    return m + np.log(np.mean(np.exp(flat - m), axis=0))


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
    if "log_likelihood_validation" not in idata.groups():
        return None
    ds = idata["log_likelihood_validation"]
    v = _one_var(ds, var_name, "log_likelihood_validation")
    da = ds[v]
    pw = _logmeanexp(da.values)
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


# ------------------------------------------------------------------ identifiability
def _posterior_flat(idata, names: Sequence[str]) -> np.ndarray:
    post = idata.posterior
    return np.column_stack([post[n].values.reshape(-1) for n in names])


def _prior_pushforward(run, section: str, n: int, seed: int):
    """Prior draws of the model parameters (K, P) and their derived quantities."""
    from heritage_bayes.calibrate import _parameters
    from heritage_bayes.rc.identify import derived_quantities

    cfg = run.config
    model = run.models[section]
    _, params = _parameters(cfg, section, model, getattr(cfg, section).priors)
    rng = np.random.default_rng(seed)
    cols = []
    for p in params.parameters[: len(model.parameter_names)]:
        cols.append(np.full(n, p.fixed) if p.fixed is not None else p.prior.sample(rng, n))
    P = np.column_stack(cols)
    with np.errstate(all="ignore"):
        dq = derived_quantities(model, P)
    return P, {k: np.broadcast_to(np.asarray(v, dtype=float), (n,)) for k, v in dq.items()}


def _contraction(post: np.ndarray, prior: np.ndarray) -> float | None:
    """1 - Var(post)/Var(prior), on the log scale when both are positive."""
    post = post[np.isfinite(post)]
    prior = prior[np.isfinite(prior)]
    if post.size < 2 or prior.size < 2:
        return None
    if np.all(post > 0) and np.all(prior > 0):
        post, prior = np.log(post), np.log(prior)
    vp = float(np.var(prior))
    if not vp > 0:
        return None
    return float(1.0 - np.var(post) / vp)


def _interval(x: np.ndarray) -> dict:
    x = x[np.isfinite(x)]
    q05, q50, q95 = np.quantile(x, [0.05, 0.5, 0.95])
    factor = float(q95 / q05) if q05 > 0 and q95 > 0 else None
    return {"median": float(q50), "q05": float(q05), "q95": float(q95), "factor90": factor}


def _practical_rank(post: np.ndarray, prior_var: np.ndarray, ratio: float) -> tuple[int, list]:
    """Directions with posterior variance below ``ratio`` x the prior's (whitened)."""
    if post.shape[1] == 0:
        return 0, []
    z = post / np.sqrt(prior_var)
    cov = np.atleast_2d(np.cov(z, rowvar=False))
    ev = np.sort(np.linalg.eigvalsh(cov))
    return int(np.sum(ev < ratio)), [float(e) for e in ev]


def _identifiability(run, section: str, *, seed: int, identified_factor: float, ratio: float):
    summ = run.summary
    model = run.models[section]
    idata = run.idata
    P_prior, dq_prior = _prior_pushforward(run, section, 20000, seed)
    params = {}
    free, prior_var, post_cols = [], [], []
    for j, name in enumerate(model.parameter_names):
        key = f"{section}.{name}"
        info = summ["parameters"].get(key, {})
        x = idata.posterior[key].values.reshape(-1)
        fixed = info.get("fixed") is not None
        entry = {"unit": info.get("unit", ""), "kind": info.get("kind", ""), "fixed": fixed}
        if not fixed:
            entry.update(_interval(x))
            entry["contraction"] = _contraction(x, P_prior[:, j])
            f = entry["factor90"]
            entry["identified"] = bool(f is not None and f <= identified_factor)
            pos = np.all(P_prior[:, j] > 0) and np.all(x > 0)
            free.append(name)
            pr = np.log(P_prior[:, j]) if pos else P_prior[:, j]
            prior_var.append(float(np.var(pr)))
            post_cols.append(np.log(x) if pos else x)
        params[name] = entry
    derived = {}
    for k, prior in dq_prior.items():
        key = f"{section}.{k}"
        if key not in idata.posterior:
            continue
        x = idata.posterior[key].values.reshape(-1)
        if not np.all(np.isfinite(x)):
            continue
        entry = {"unit": idata.posterior[key].attrs.get("unit", ""), **_interval(x)}
        entry["contraction"] = _contraction(x, prior)
        f = entry["factor90"]
        entry["identified"] = bool(f is not None and f <= identified_factor)
        derived[k] = entry
    post = np.column_stack(post_cols) if post_cols else np.zeros((1, 0))
    prank, eig = _practical_rank(post, np.asarray(prior_var), ratio)
    ev = np.asarray(eig)
    # how the practical rank depends on its threshold: ratio / 10 to ratio x 10
    prank_band = [int(np.sum(ev < ratio / 10)), int(np.sum(ev < ratio * 10))]
    ident = summ["models"][section].get("identifiability") or {}
    widest = None
    for name in free:
        e = params[name]
        if e.get("factor90"):
            dec = math.log10(e["factor90"])
            if widest is None or dec > widest["decades"]:
                widest = {"parameter": name, "decades": dec, "q05": e["q05"], "q95": e["q95"]}
    # time constants shorter than the time step act within one step: hourly data see
    # only their static effect, so they neither can nor need to be identified
    dt_h = float(summ.get("dt", 3600.0)) / 3600.0
    taus = {k: v for k, v in derived.items() if k.startswith("tau_") and v["median"] >= dt_h}
    fast = sorted(k for k in derived if k.startswith("tau_") and k not in taus)
    contr = [params[n]["contraction"] for n in free if params[n]["contraction"] is not None]
    return {
        "parameters": params,
        "derived": derived,
        "n_free_physical": len(free),
        "structural_rank": ident.get("rank"),
        "structural_n_params": ident.get("n_params"),
        "practical_rank": prank,
        "practical_eigenvalues": eig,
        "practical_rank_band": prank_band,
        "widest_interval": widest,
        "time_constants_identified": all(v["identified"] for v in taus.values()),
        "time_constants_not_identified": sorted(k for k, v in taus.items() if not v["identified"]),
        "time_constants_below_step": fast,
        "parameters_not_identified": sorted(n for n in free if not params[n]["identified"]),
        "contraction_median": float(np.median(contr)) if contr else None,
        "contraction_min": float(np.min(contr)) if contr else None,
        "contraction_max": float(np.max(contr)) if contr else None,
    }


# ------------------------------------------------------------------ comparison
def compare_runs(
    run_dirs: Mapping[str, str | Path],
    section: str,
    *,
    block_hours: float = 24.0,
    identified_factor: float = 2.0,
    practical_ratio: float = 0.01,
    seed: int = 0,
) -> dict:
    """Compare calibrated runs of one section on accuracy and identifiability.

    Parameters
    ----------
    run_dirs : mapping label -> run directory
        Runs of the same data, each with a model of ``section``.
    section : {"thermal", "hygric"}
    block_hours : float
        Block length of the blocked LOO and of the standard errors [h].
    identified_factor : float
        A quantity is identified when its 90 % interval spans at most this factor.
    practical_ratio : float
        Posterior/prior variance ratio below which a direction counts in the practical
        rank.
    seed : int
        Seed of the prior draws of the derived quantities.

    Returns
    -------
    dict
        ``models`` (per label: accuracy, identifiability, convergence), ``loo_compare``
        (``az.compare`` on the blocked LOO), ``recommendation`` and the settings.
    """
    from heritage_bayes.run import load_run

    runs = {k: load_run(p) for k, p in run_dirs.items()}
    out_models: dict[str, dict] = {}
    val_pw: dict[str, tuple[np.ndarray, np.ndarray]] = {}
    loo_data = {}
    for label, run in runs.items():
        if section not in run.models:
            raise InputError(f"{run.path}: the run has no {section!r} model")
        model = run.models[section]
        var = f"{section}.{model.output_names[0]}"
        acc: dict = {}
        met = (run.summary.get("metrics") or {}).get(section, {}).get(model.output_names[0], {})
        for period in ("calibration", "validation"):
            if period in met:
                acc[period] = {k: met[period].get(k) for k in ("FIT", "MSE", "MAE", "coverage90")}
        ev = elpd_validation(run.idata, var, block_hours)
        if ev is not None:
            acc["elpd_validation"] = {k: ev[k] for k in ("elpd", "se", "n")}
            val_pw[label] = (ev["pointwise"], ev["times"])
        loo_data[label] = blocked_loo_data(run.idata, var, block_hours)
        with warnings.catch_warnings():  # high Pareto k: recorded below, not printed
            warnings.simplefilter("ignore", UserWarning)
            loo = az.loo(loo_data[label], var_name=var)
        k = np.asarray(loo.pareto_k)
        acc["loo_blocked"] = {
            "elpd": float(loo.elpd_loo),
            "se": float(loo.se),
            "p_loo": float(loo.p_loo),
            "n_blocks": int(k.size),
            "max_pareto_k": float(np.max(k)),
            "share_k_above_0.7": float(np.mean(k > 0.7)),
        }
        ident = _identifiability(
            run, section, seed=seed, identified_factor=identified_factor, ratio=practical_ratio
        )
        out_models[label] = {
            "model": model.name,
            "run_dir": str(run.path),
            "noise": run.summary["models"][section].get("noise"),
            "periods": run.summary.get("periods"),
            "converged": bool(run.summary.get("converged")),
            "max_rhat": run.summary.get("max_rhat"),
            "min_ess_bulk": run.summary.get("min_ess_bulk"),
            "n_draws": int(run.idata.posterior.sizes["chain"] * run.idata.posterior.sizes["draw"]),
            "accuracy": acc,
            "identifiability": ident,
        }
    # differences in validation ELPD against the best, SE from daily block sums
    if len(val_pw) == len(runs) and val_pw:
        best = max(val_pw, key=lambda m: out_models[m]["accuracy"]["elpd_validation"]["elpd"])
        pb, tb = val_pw[best]
        for label, (pw, t) in val_pw.items():
            common, ia, ib = np.intersect1d(t, tb, return_indices=True)
            d = pw[ia] - pb[ib]
            ev = out_models[label]["accuracy"]["elpd_validation"]
            ev["diff_to_best"] = float(d.sum())
            ev["dse_to_best"] = 0.0 if label == best else _block_se(d, common, block_hours)
        score = "elpd_validation"
    else:
        score = "loo_blocked"
    with warnings.catch_warnings():  # Pareto k (recorded) and arviz's pandas notices
        warnings.simplefilter("ignore")
        cmp = az.compare(loo_data, ic="loo")
    loo_table = {
        str(m): {
            c: _num(cmp.loc[m, c])
            for c in ("rank", "elpd_loo", "p_loo", "elpd_diff", "se", "dse", "weight")
        }
        for m in cmp.index
    }
    for m, row in loo_table.items():
        out_models[m]["accuracy"]["loo_blocked"]["diff_to_best"] = -row["elpd_diff"]
        out_models[m]["accuracy"]["loo_blocked"]["dse_to_best"] = row["dse"]
    rec = _recommend(out_models, score)
    return {
        "section": section,
        "models": out_models,
        "loo_compare": loo_table,
        "accuracy_score": score,
        "recommendation": rec,
        "settings": {
            "block_hours": block_hours,
            "identified_factor": identified_factor,
            "practical_ratio": practical_ratio,
            "seed": seed,
            "method": {
                "calibration": f"blocked PSIS-LOO, blocks of {block_hours:g} h (az.loo over "
                "block sums of the pointwise log-likelihood)",
                "validation": "sum over validation hours of the log posterior-mean one-step "
                "predictive density (elpd_val); SE from block sums",
                "identified": f"90 % interval within a factor {identified_factor:g}",
                "practical_rank": f"directions with posterior/prior variance < {practical_ratio:g}",
            },
        },
    }


def _num(x):
    try:
        x = float(x)
    except (TypeError, ValueError):
        return None
    return x if math.isfinite(x) else None


def _recommend(models: dict, score: str) -> dict:
    """The simplest accuracy-equivalent model whose time constants are identified."""
    what = "validation ELPD" if score == "elpd_validation" else "blocked LOO ELPD"
    rows = {}
    for m, info in models.items():
        a = info["accuracy"][score]
        diff, dse = a.get("diff_to_best", 0.0), a.get("dse_to_best", 0.0)
        equivalent = diff >= -max(2.0 * (dse or 0.0), NEGLIGIBLE_ELPD)
        rows[m] = (diff, dse or 0.0, equivalent, info["identifiability"])
    best = max(rows, key=lambda m: rows[m][0])
    equiv = [m for m in rows if rows[m][2]]
    ok = [m for m in equiv if rows[m][3]["time_constants_identified"]]
    by_size = sorted(ok or equiv, key=lambda m: (rows[m][3]["n_free_physical"], -rows[m][0]))
    if ok:
        choice = by_size[0]
    else:
        choice = max(
            equiv,
            key=lambda m: (
                -len(rows[m][3]["time_constants_not_identified"]),
                rows[m][3]["practical_rank"],
            ),
        )
    diff, dse, _, ident = rows[choice]
    parts = []
    if choice == best:
        parts.append(f"the best {what} of the candidates")
    else:
        parts.append(
            f"{what} within 2 SE or {NEGLIGIBLE_ELPD:g} of {best} "
            f"(difference {diff:.1f} ± {dse:.1f})"
        )
    if ident["time_constants_identified"]:
        fast = ident["time_constants_below_step"]
        parts.append(
            "all its time constants identified"
            + (f" ({', '.join(fast)} shorter than the time step)" if fast else "")
        )
    else:
        parts.append(
            "but not all its time constants are identified ("
            + ", ".join(ident["time_constants_not_identified"])
            + "; no candidate of equal accuracy has all of them)"
        )
    others = []
    for m, (d, se, eq, idf) in rows.items():
        if m == choice:
            continue
        if not eq:
            others.append(f"{m} is less accurate ({what} {d:.1f} ± {se:.1f} below the best)")
            continue
        bad = idf["time_constants_not_identified"]
        if bad:
            others.append(f"{m} is as accurate but not identified: {', '.join(bad)}")
        else:
            others.append(
                f"{m} is as accurate and identified but has more parameters "
                f"({idf['n_free_physical']} against {ident['n_free_physical']})"
            )
    text = f"{choice}: " + ", ".join(parts) + "."
    if others:
        text += " " + "; ".join(others) + "."
    unconverged = [m for m, info in models.items() if info.get("converged") is False]
    if unconverged:
        text += f" Not converged (R-hat/ESS/τ criteria), so provisional: {', '.join(unconverged)}."
    return {
        "model": choice,
        "reason": text,
        "best_accuracy": best,
        "equivalent": equiv,
        "not_converged": unconverged,
    }


# ------------------------------------------------------------------ orchestration
def _section_of(cfg, models: Sequence[str] | None) -> tuple[str, list[str]]:
    """The section and candidate names; ConfigError naming ``--models`` when bad."""
    from heritage_bayes.rc.catalog import CATALOG

    if not models:
        section = "thermal" if cfg.thermal is not None else "hygric"
        return section, list(DEFAULT_MODELS[section])
    names = [m.strip() for m in models if m.strip()]
    unknown = [m for m in names if m not in CATALOG]
    if unknown:
        raise ConfigError(
            f"--models: unknown model(s) {unknown}; available: {sorted(CATALOG)} "
            "(`hbayes models NAME` describes one)"
        )
    dup = sorted({m for m in names if names.count(m) > 1})
    if dup:
        raise ConfigError(f"--models: {dup} given more than once")
    if len(names) < 2:
        raise ConfigError(f"--models: give at least two models to compare (got {names})")
    domains = {m: m.split("_")[0] for m in names}
    section = domains[names[0]]
    wrong = [m for m in names if domains[m] != section]
    if wrong:
        raise ConfigError(
            f"--models: {wrong} are not {section} models like {names[0]!r}; the candidates "
            "of one comparison describe the same output (thermal: Ti, hygric: Pi)"
        )
    if getattr(cfg, section) is None:
        raise ConfigError(
            f"--models: {section} models, but the config has no {section!r} section "
            "(it gives the noise model, priors and options of the candidates)"
        )
    return section, names


def _candidate_config(cfg, section: str, name: str):
    """The config calibrating only ``name`` in ``section`` (same data, noise, knowledge)."""
    from heritage_bayes.models import SECTIONS

    sec = getattr(cfg, section)
    # the configured priors whose parameters exist in this model (as the ladder does)
    from heritage_bayes.calibrate import _parameters
    from heritage_bayes.models import _catalog_options
    from heritage_bayes.rc.catalog import model as catalog_model

    try:
        model = catalog_model(name, **_catalog_options(cfg, section, name))
    except ValueError as exc:
        raise ConfigError(f"--models: {name}: {exc}") from None
    keep = set(model.parameter_names) | {"sigma", "phi"}
    priors = {k: v for k, v in sec.priors.items() if k in keep or k.split("_")[0] in keep}
    new_sec = sec.model_copy(update={"model": name, "priors": priors})
    cand = cfg.model_copy(
        update={
            section: new_sec,
            **{s: None for s in SECTIONS if s != section},
            "ladder": False,
            "name": f"{cfg.name or 'run'}-{name}",
        }
    )
    _parameters(cand, section, model, priors)  # a prior that does not fit fails now
    return cand


def run_compare(
    cfg,
    models: Sequence[str] | None = None,
    out_dir: str | Path | None = None,
    *,
    seed: int | None = None,
    quiet: bool = False,
    report: bool | None = None,
    resume: bool = False,
) -> Path:
    """Calibrate each candidate model and write the comparison; return its folder.

    Parameters
    ----------
    cfg : CalibrationConfig
        Data, periods, noise model, priors and knowledge of the room; the model of the
        compared section is replaced by each candidate in turn (the other section is left
        out), with the calibration engine's defaults.
    models : sequence of str, optional
        Catalogue names, all of one section (default: 1c, 2c and the paper's model of
        the config's thermal section, or of its hygric section without one).
    out_dir : path, optional
        Default ``reports/<config name>-compare/``; each candidate's run directory is
        ``<out_dir>/<model>/``; the comparison is ``comparison.json`` and
        ``comparison.html``.
    seed, quiet, report, resume
        As for :func:`heritage_bayes.calibrate.run_calibration` (applied to every
        candidate).

    Raises
    ------
    ConfigError
        Unknown model, models of different sections, or a section the config lacks.
    """
    from heritage_bayes.calibrate import run_calibration

    section, names = _section_of(cfg, models)
    cands = {n: _candidate_config(cfg, section, n) for n in names}
    out = Path(out_dir) if out_dir is not None else Path("reports") / f"{cfg.name or 'run'}-compare"
    out.mkdir(parents=True, exist_ok=True)
    dirs = {}
    for n, c in cands.items():
        if not quiet:
            import sys

            print(f"hbayes compare: calibrating {n}", file=sys.stderr, flush=True)
        dirs[n] = run_calibration(c, out / n, seed=seed, quiet=quiet, report=report, resume=resume)
    result = compare_runs(dirs, section, seed=cfg.seed if seed is None else int(seed))
    result["config"] = {"name": cfg.name, "building": cfg.building, "room": cfg.room}
    write_comparison(result, out)
    return out


# ------------------------------------------------------------------ outputs
def fig_tradeoff(result: dict):
    """The paper's trade-off: accuracy against identifiability, one point per model.

    x: the share of well-identified directions, practical rank / number of free physical
    parameters (whiskers: the same with the variance-ratio threshold ten times stricter
    and ten times looser); y: the accuracy score relative to the best model, ±2 SE. The
    legend gives each model's practical and structural rank.
    """
    from heritage_bayes.report.figures.style import C_ALT, C_MODEL, _figure, tex_safe

    fig = _figure(7.5, 4.2)
    ax = fig.subplots()
    score = result["accuracy_score"]
    what = "validation ELPD" if score == "elpd_validation" else "blocked LOO ELPD"
    rec = result["recommendation"]["model"]
    markers = "osD^v<>p"
    others = ["0.35", C_ALT, "#2e8b57", "#8e44ad", "#b8860b"]
    for i, (m, info) in enumerate(result["models"].items()):
        idf = info["identifiability"]
        n = max(idf["n_free_physical"], 1)
        a = info["accuracy"][score]
        x = idf["practical_rank"] / n
        lo, hi = (r / n for r in idf.get("practical_rank_band", [idf["practical_rank"]] * 2))
        y, dse = a.get("diff_to_best", 0.0), a.get("dse_to_best") or 0.0
        colour = C_MODEL if m == rec else others[i % len(others)]
        label = (
            f"{tex_safe(m)}{' (recommended)' if m == rec else ''}: rank "
            f"{idf['practical_rank']} practical, {idf['structural_rank']} structural, "
            f"{idf['n_free_physical']} parameters"
        )
        ax.errorbar(
            x,
            y,
            xerr=[[x - lo], [hi - x]],
            yerr=2 * dse,
            fmt=markers[i % len(markers)],
            color=colour,
            capsize=4,
            ms=9 if m == rec else 7,
            label=label,
        )
    ax.axhline(0.0, color="0.7", lw=0.8)
    ax.set_xlim(-0.05, 1.05)
    ax.set_xlabel("well-identified directions: practical rank / parameters [-]")
    ax.set_ylabel(f"{what} − best [-] (±2 SE)")
    ax.set_title("accuracy vs identifiability (full posteriors)")
    ax.legend(loc="best", fontsize=8)
    return fig


def _f(x, fmt="{:.3g}") -> str:
    if x is None or (isinstance(x, float) and not math.isfinite(x)):
        return "–"
    if isinstance(x, bool):
        return "yes" if x else "no"
    return fmt.format(x)


def _table(head: Sequence[str], rows: Sequence[Sequence[str]]) -> str:
    h = "".join(f"<th scope='col'>{html.escape(c)}</th>" for c in head)
    body = "".join(
        "<tr>"
        + "".join(
            f"<td class='num'>{html.escape(c)}</td>" if i else f"<td>{html.escape(c)}</td>"
            for i, c in enumerate(r)
        )
        + "</tr>"
        for r in rows
    )
    return (
        f"<div class='scroll'><table><thead><tr>{h}</tr></thead><tbody>{body}</tbody></table></div>"
    )


def accuracy_rows(result: dict) -> tuple[list[str], list[list[str]]]:
    """The accuracy table (also printed by the CLI)."""
    head = [
        "model",
        "FIT val [%]",
        "MSE val",
        "MAE val",
        "ELPD val",
        "Δ ± SE",
        "LOO cal (blocked)",
        "Δ ± SE",
        "max Pareto k",
        "converged",
    ]
    rows = []
    for m, info in result["models"].items():
        a = info["accuracy"]
        v = a.get("validation", {})
        ev = a.get("elpd_validation", {})
        lo = a["loo_blocked"]
        rows.append(
            [
                m,
                _f(v.get("FIT"), "{:.1f}"),
                _f(v.get("MSE"), "{:.3g}"),
                _f(v.get("MAE"), "{:.3g}"),
                _f(ev.get("elpd"), "{:.1f}"),
                f"{_f(ev.get('diff_to_best'), '{:.1f}')} ± {_f(ev.get('dse_to_best'), '{:.1f}')}",
                f"{_f(lo['elpd'], '{:.1f}')} ± {_f(lo['se'], '{:.1f}')}",
                f"{_f(lo.get('diff_to_best'), '{:.1f}')} ± {_f(lo.get('dse_to_best'), '{:.1f}')}",
                _f(lo["max_pareto_k"], "{:.2f}"),
                _f(info["converged"]),
            ]
        )
    return head, rows


def identifiability_rows(result: dict) -> tuple[list[str], list[list[str]]]:
    """The identifiability summary table (also printed by the CLI)."""
    head = [
        "model",
        "free physical",
        "structural rank",
        "practical rank",
        "contraction (median)",
        "widest 90 % interval",
        "parameters identified",
        "time constants identified",
        "derived not identified",
    ]
    rows = []
    for m, info in result["models"].items():
        i = info["identifiability"]
        w = i["widest_interval"]
        rows.append(
            [
                m,
                str(i["n_free_physical"]),
                _f(i["structural_rank"], "{}"),
                str(i["practical_rank"]),
                _f(i["contraction_median"], "{:.2f}"),
                f"{w['parameter']}: {w['decades']:.1f} decades" if w else "–",
                f"{i['n_free_physical'] - len(i['parameters_not_identified'])} of "
                f"{i['n_free_physical']}",
                _f(i["time_constants_identified"]),
                ", ".join(
                    k + (" (< time step)" if k in i["time_constants_below_step"] else "")
                    for k, e in i["derived"].items()
                    if not e["identified"]
                )
                or "–",
            ]
        )
    return head, rows


def _quantity_rows(info: dict) -> list[list[str]]:
    rows = []
    i = info["identifiability"]
    for kind, table in (("parameter", i["parameters"]), ("derived", i["derived"])):
        for name, e in table.items():
            if e.get("fixed"):
                rows.append([name, kind, e.get("unit", ""), "fixed", "", "", "", ""])
                continue
            rows.append(
                [
                    name,
                    kind,
                    e.get("unit", ""),
                    _f(e.get("median")),
                    f"{_f(e.get('q05'))} – {_f(e.get('q95'))}",
                    _f(e.get("factor90"), "{:.3g}"),
                    _f(e.get("contraction"), "{:.3f}"),
                    _f(e.get("identified")),
                ]
            )
    return rows


def render_comparison(result: dict) -> str:
    """``comparison.html``: the house page with the trade-off figure and the tables."""
    from heritage_bayes._version import __version__
    from heritage_bayes.report.figures import to_png_uri
    from heritage_bayes.report.page import Section, render_page

    rec = result["recommendation"]
    s = result["settings"]
    lead = (
        f"<div class='verdict green'><strong>Recommended: {html.escape(rec['model'])}</strong>"
        f"<p>{html.escape(rec['reason'])}</p></div>"
    )
    fig = fig_tradeoff(result)
    summary = (
        "<p>Each candidate was calibrated on the same data, noise model and prior "
        "knowledge, with full posteriors (its own run directory and report). Accuracy: "
        f"{html.escape(s['method']['validation'])}; on the calibration period "
        f"{html.escape(s['method']['calibration'])}: hourly data are not exchangeable, so "
        "whole blocks are left out (see heritage_bayes.compare). Identifiability: "
        f"a quantity counts as identified when its {html.escape(s['method']['identified'])}; "
        f"practical rank: {html.escape(s['method']['practical_rank'])}.</p>"
        f"<figure id='fig-tradeoff'><img src='{to_png_uri(fig)}' alt='accuracy against "
        "identifiability, one point per model'><figcaption>Accuracy (relative to the best "
        "model, ±2 SE) against the share of parameter directions the data identify "
        "(practical rank over the number of physical parameters; whiskers: threshold "
        "ten times stricter and looser).</figcaption>"
        "</figure>"
    )
    ha, ra = accuracy_rows(result)
    hi, ri = identifiability_rows(result)
    sections = [
        Section("Summary", summary, id="summary", lead=lead),
        Section("Accuracy", _table(ha, ra), id="accuracy"),
        Section("Identifiability", _table(hi, ri), id="identifiability"),
    ]
    for m, info in result["models"].items():
        p = info.get("periods") or {}
        per = "; ".join(
            f"{k} {v['start'][:10]} – {v['end'][:10]}" for k, v in p.items() if isinstance(v, dict)
        )
        body = (
            f"<p>Noise model {html.escape(str(info.get('noise')))}; {html.escape(per)}; "
            f"{info['n_draws']} posterior draws; max R-hat {_f(info.get('max_rhat'), '{:.3f}')}, "
            f"min bulk ESS {_f(info.get('min_ess_bulk'), '{:.0f}')}. Run directory: "
            f"<code>{html.escape(info['run_dir'])}</code>.</p>"
            + _table(
                [
                    "quantity",
                    "kind",
                    "unit",
                    "median",
                    "90 % interval",
                    "q95/q05",
                    "contraction",
                    "identified",
                ],
                _quantity_rows(info),
            )
        )
        sections.append(Section(f"Model {m}", body, id=f"model-{m}"))
    c = result.get("config") or {}
    return render_page(
        f"Model comparison — {c.get('name') or ''}",
        sections,
        subtitle=" · ".join(x for x in (c.get("building"), c.get("room")) if x),
        generator=f"heritage_bayes {__version__}",
    )


def write_comparison(result: dict, out: str | Path) -> tuple[Path, Path]:
    """Write ``comparison.json`` and ``comparison.html`` into ``out`` (atomically)."""
    from heritage_bayes.inference.results import atomic_write_text, dump_json

    out = Path(out)
    dump_json(out / "comparison.json", result)
    page = render_comparison(result)
    atomic_write_text(out / "comparison.html", page)
    return out / "comparison.json", out / "comparison.html"
