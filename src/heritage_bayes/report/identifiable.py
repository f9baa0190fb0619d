"""Posterior diagnostics in identifiable coordinates: the numbers behind them.

With only indoor temperatures (or vapour pressures) measured and no known heat
(moisture) input, scaling every capacity, conductance and solar aperture together leaves
the output unchanged: in raw log-parameters the posterior is a straight ridge and every
correlation along it is ±1. The report therefore shows the posterior in coordinates the
data can fix, plus one for the direction they cannot:

- ``log10 τ_k`` [h], the time constants (``tau_<k>_h`` in ``posterior.nc``);
- the static gains ``gain_<out>_<in>`` and steady-state offsets ``offset_<out>_<const>``:
  linear for the dimensionless gains from a boundary potential (fractions between 0 and 1
  that sum to one over the boundaries) and for offsets [Pa]; log10 for gains with a unit
  (from irradiance [K/(W/m²)], from a heat input [K/W]: positive, scale-like quantities
  whose priors span decades);
- the *scale*: ``log10 ΣC`` of the section's free capacities [J/K or kg/Pa], the one
  coordinate that moves along the ridge; only prior knowledge (room volume, a measured
  air change rate) or a known heat input pins it.

This module computes these coordinates from ``posterior.nc`` and ``summary.json``, their
push-forward priors (:meth:`heritage_bayes.run.Run.prior_pushforward`, shared with
:mod:`heritage_bayes.compare`), prior densities of the free parameters, rank
histograms (Vehtari et al. 2021) and Monte-Carlo standard errors (``arviz.mcse``).
Figures and sections only draw what it returns.

References
----------
.. [1] A. Vehtari, A. Gelman, D. Simpson, B. Carpenter, P.-C. Bürkner, "Rank-normalization,
   folding, and localization: an improved R-hat for assessing convergence of MCMC",
   Bayesian Analysis 16(2), 667–718 (2021), doi:10.1214/20-BA1221.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from heritage_bayes.format import fmt, quantity_label
from heritage_bayes.report.rundata import RunData, section_params
from heritage_bayes.rundir.summary import RunSummary

__all__ = [
    "N_PRIOR",
    "Coord",
    "identifiable_coordinates",
    "identifiable_correlation",
    "mcse_cells",
    "mcse_table",
    "prior_density",
    "rank_counts",
    "rank_groups",
    "scale_capacities",
]

#: Prior draws pushed through the model for the priors of derived quantities.
N_PRIOR = 4000
_PRIOR_SEED = 0  # fixed: the same report from the same run directory


@dataclass
class Coord:
    """One identifiable coordinate of a section's posterior.

    Attributes
    ----------
    name : str
        ``tau_1_h``, ``gain_Ti_Te``, ... or ``scale``.
    label : str
        Axis label with unit, e.g. ``"log10 τ1 [h]"``.
    log10 : bool
        Whether ``draws``, ``truth`` and ``prior`` are log10 of the quantity.
    draws : (chain, draw) array
        Posterior draws in the plotted coordinate (NaN where a draw is not admissible).
    truth : float or None
        The generating value (synthetic data), in the plotted coordinate.
    prior : (N_PRIOR,) array or None
        Push-forward prior draws in the plotted coordinate (finite ones only).
    """

    name: str
    label: str
    log10: bool
    draws: np.ndarray
    truth: float | None
    prior: np.ndarray | None


def scale_capacities(summary: RunSummary, m: str) -> list[str]:
    """Names of the free capacities of section ``m`` (the terms of the scale ΣC)."""
    return [
        n for n, e in section_params(summary, m).items() if e.kind == "capacity" and e.fixed is None
    ]


def _log10(x):
    with np.errstate(divide="ignore", invalid="ignore"):
        return np.where(np.asarray(x, dtype=float) > 0, np.log10(x), np.nan)


def _derived_names(rd: RunData, m: str) -> list[str]:
    post = rd.idata.posterior
    out = []
    for key in rd.summary.derived:
        sec, _, name = key.partition(".")
        if sec == m and key in post and name.startswith(("tau_", "gain_", "offset_")):
            out.append(name)
    return out


def _prior_pushforward(rd: RunData, m: str):
    """(P, derived) prior draws of section ``m`` or None if the config cannot rebuild them."""
    key = ("prior_pushforward", m)
    if key not in rd.cache:
        from heritage_bayes.errors import InputError

        try:
            rd.cache[key] = rd.run.prior_pushforward(m, N_PRIOR, _PRIOR_SEED)
        except (InputError, AttributeError, KeyError, ValueError):
            rd.cache[key] = None
    return rd.cache[key]


def identifiable_coordinates(rd: RunData, m: str) -> list[Coord]:
    """Time constants, gains/offsets and the scale of section ``m`` (cached on ``rd``).

    Returns
    -------
    list of Coord
        In the order τ's (slowest first), gains, offsets, scale; empty if the posterior
        holds no derived quantities of ``m``. Quantities the structure fixes (constant
        over the draws, e.g. the gain 1 from the only boundary of a one-node model) are
        left out: they have no correlation and no distribution to show.
    """
    key = ("coords", m)
    if key in rd.cache:
        return rd.cache[key]
    post = rd.idata.posterior
    derived = rd.summary.derived
    push = _prior_pushforward(rd, m)
    coords: list[Coord] = []
    for name in _derived_names(rd, m):
        x = np.asarray(post[f"{m}.{name}"].values, dtype=float)
        e = derived.get(f"{m}.{name}")
        truth = None if e is None else e.truth
        unit = (e and e.unit) or post[f"{m}.{name}"].attrs.get("unit", "")
        prior = None if push is None else push[1].get(name)
        if name.startswith("tau_"):
            log = True
            label = f"log10 τ{name[4:-2]} [h]"
        else:
            fin = x[np.isfinite(x)]
            log = bool(name.startswith("gain_") and unit not in ("", "-") and np.all(fin > 0))
            words = quantity_label(name, unit or "-", domain=m)
            label = f"log10 {words}" if log else words
        fin = x[np.isfinite(x)]
        if fin.size and np.ptp(fin) <= 1e-9 * max(1.0, float(np.max(np.abs(fin)))):
            continue  # fixed by the structure (e.g. the gain from a single boundary: 1)
        if log:
            x = _log10(x)
            truth = None if truth is None or not truth > 0 else math.log10(truth)
            prior = None if prior is None else _log10(prior)
        if prior is not None:
            prior = np.asarray(prior, dtype=float)
            prior = prior[np.isfinite(prior)]
        coords.append(Coord(name, label, log, x, truth, prior))
    if coords:
        scale = _scale_coord(rd, m, push)
        if scale is not None:
            coords.append(scale)
    rd.cache[key] = coords
    return coords


def _scale_coord(rd: RunData, m: str, push) -> Coord | None:
    caps = scale_capacities(rd.summary, m)
    post = rd.idata.posterior
    if not caps or any(f"{m}.{c}" not in post for c in caps):
        return None
    params = section_params(rd.summary, m)
    total = sum(np.asarray(post[f"{m}.{c}"].values, dtype=float) for c in caps)
    truths = [params[c].truth for c in caps]
    truth = math.log10(sum(truths)) if all(t is not None for t in truths) else None
    prior = None
    if push is not None:
        model = rd.run.models[m]
        idx = [list(model.parameter_names).index(c) for c in caps]
        prior = _log10(push[0][:, idx].sum(axis=1))
        prior = prior[np.isfinite(prior)]
    unit = params[caps[0]].unit
    return Coord("scale", f"log10 ΣC [{unit}]", True, _log10(total), truth, prior)


def identifiable_correlation(coords: list[Coord]) -> np.ndarray:
    """Posterior correlation matrix (d, d) of the coordinates, over draws where all are
    finite (NaN entries where a coordinate is constant)."""
    X = np.column_stack([c.draws.reshape(-1) for c in coords])
    X = X[np.all(np.isfinite(X), axis=1)]
    with np.errstate(divide="ignore", invalid="ignore"):
        return np.atleast_2d(np.corrcoef(X, rowvar=False))


def prior_density(prior, log10: bool, n: int = 400) -> tuple[np.ndarray, np.ndarray]:
    """Normalised prior density on a grid over the prior's bounds.

    Parameters
    ----------
    prior : heritage_bayes.inference.priors.Prior
    log10 : bool
        Density of ``y = log10 θ`` [1/decade] (``p(θ) · θ · ln 10``) instead of θ.
    n : int
        Grid points.

    Returns
    -------
    (x, density) : (n,) arrays
        ``x`` in the plotted coordinate (log10 θ or θ), ``density`` integrating to 1.
    """
    lo, hi = float(prior.lower), float(prior.upper)
    if log10:
        x = np.linspace(math.log10(lo), math.log10(hi), n)
        theta = 10.0**x
        logp = prior.logpdf(theta) + np.log(theta)  # |dθ/dy| = θ ln 10 (constant dropped)
    else:
        x = np.linspace(lo, hi, n)
        logp = prior.logpdf(x)
    p = np.exp(logp - np.max(logp))
    area = float(np.sum(0.5 * (p[1:] + p[:-1]) * np.diff(x)))
    return x, p / area


def rank_groups(n_chain: int) -> list[np.ndarray]:
    """Walker indices of the rank plot's groups: 4 (or 3, or 2) equal contiguous blocks.

    The posterior's ``chain`` dimension holds the emcee walkers (32 by default), each
    with only ``draws_per_walker`` thinned draws (about 30): a rank histogram per walker
    would be noise. Blocks of walkers give each group a few hundred draws, enough for
    ~16 bins; a group that started in (or got stuck in) another part of the posterior
    than the others still shows, because walkers are numbered in their start order.
    """
    for g in (4, 3, 2):
        if n_chain >= g and n_chain % g == 0:
            return list(np.arange(n_chain).reshape(g, -1))
    return [np.arange(n_chain)]


def rank_counts(draws: np.ndarray, groups: list[np.ndarray], bins: int | None = None):
    """Rank histograms of posterior draws, one per group of chains.

    Parameters
    ----------
    draws : (chain, draw) array
    groups : list of chain-index arrays (:func:`rank_groups`), of equal size
    bins : int, optional
        Default: √(draws per group), between 5 and 20.

    Returns
    -------
    counts : (G, bins) int array
        Draws of each group whose rank (among all finite draws pooled) falls in each bin.
    band : (2,) array
        Central 99 % interval of one bin's count if the groups sample the same
        distribution (binomial with p = 1/bins and the group's draw count).
    expected : float
        The uniform expectation per bin.
    """
    from scipy.stats import binom, rankdata

    x = np.asarray(draws, dtype=float)
    ok = np.isfinite(x)
    r = np.full(x.shape, np.nan)
    r[ok] = rankdata(x[ok], method="average")
    n_all = int(ok.sum())
    per_group = int(np.mean([ok[g].sum() for g in groups]))
    b = bins or int(np.clip(round(math.sqrt(per_group)), 5, 20))
    edges = np.linspace(0.5, n_all + 0.5, b + 1)
    counts = np.array([np.histogram(r[g][ok[g]], bins=edges)[0] for g in groups])
    band = np.asarray(binom.ppf([0.005, 0.995], per_group, 1.0 / b), dtype=float)
    return counts, band, per_group / b


def mcse_table(rd: RunData, names: list[str]) -> dict[str, dict[str, float]]:
    """Monte-Carlo standard errors of the median and the 5 %/95 % quantiles.

    ``az.mcse`` (``method="median"`` and ``"quantile"``) on the draws of
    ``posterior.nc``, the draws the tables' medians and intervals come from, in the
    variables' own units.

    Parameters
    ----------
    names : posterior variable names (``thermal.Cw``, ``thermal.tau_1_h``, ...)

    Returns
    -------
    dict name -> {"median", "q05", "q95"} (NaN where arviz cannot tell, e.g. a constant)
    """
    import arviz as az

    post = rd.idata.posterior
    names = [n for n in names if n in post]
    if not names:
        return {}
    ds = post[names]
    with np.errstate(all="ignore"):
        res = {
            "median": az.mcse(ds, method="median"),
            "q05": az.mcse(ds, method="quantile", prob=0.05),
            "q95": az.mcse(ds, method="quantile", prob=0.95),
        }
    return {n: {k: float(v[n].values) for k, v in res.items()} for n in names}


def mcse_cells(mc: dict | None) -> dict[str, str]:
    """Table cells of :func:`~heritage_bayes.report.identifiable.mcse_table`'s entry."""
    if not mc:
        return {"mcse_median": "—", "mcse_q": "—"}
    return {"mcse_median": fmt(mc["median"]), "mcse_q": f"{fmt(mc['q05'])} / {fmt(mc['q95'])}"}
