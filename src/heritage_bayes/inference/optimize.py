"""MAP warm start: global search, then local polish, with a count of agreeing starts.

The maximum a posteriori point is sought in the *unit cube* of the prior ranges: each
free parameter's position between its bounds, on the log scale for log-scale priors.
The objective is the log-likelihood plus the log prior density with respect to that
scale (flat for uniform/log-uniform priors) and the joint prior on the time constants
(:meth:`~heritage_bayes.inference.posterior.LogPosterior.time_constant_log_prior`), i.e.
the MAP of the log-parameters, the natural scale of capacities and conductances; it does
not depend on the sampler's logit transform.

Global step: :func:`scipy.optimize.differential_evolution` (vectorised, seeded), as the
paper used global optimisation because the surface has several minima; or seeded
multi-start. Local step: L-BFGS-B with batched central-difference gradients. The best
``starts`` distinct candidates are polished; the number that end within 1 log-posterior
unit of the best ("agreed") measures how unambiguous the optimum is.

Restarts (``restarts`` > 1): the global search again from other seeds. One population of
differential evolution collapses into one basin, so the polished starts of one search
agree even where the posterior has several optima (e.g. an interior mass merged into
the air and a slow one the sun does not reach: ``docs/science/benchmarks.md``, "The
interior area and several optima"). The first
search's optimum is kept unless a restart beats it by more than :data:`MODE_PICK`;
optima of the restarts within :data:`MODE_WINDOW` of the best, apart in the unit cube
(:data:`MODE_DISTANCE`) and separated by a dip of the log-posterior on the straight line
between them (:data:`MODE_BARRIER`; points of one ridge are not modes) are reported as
``modes``: the posterior is multimodal there, and a chain started at one of them
describes that one.

References
----------
.. [1] R. Storn, K. Price, "Differential evolution - a simple and efficient heuristic for
   global optimization over continuous spaces", J. Global Optim. 11 (1997) 341-359.
   doi:10.1023/A:1008202821328
"""

from __future__ import annotations

import time
from dataclasses import dataclass, field, replace

import numpy as np
from scipy.optimize import differential_evolution, minimize

from heritage_bayes.errors import InputError

__all__ = [
    "AffineCoordinates",
    "BudgetError",
    "LaplaceResult",
    "MAPResult",
    "affine_coordinates",
    "find_map",
    "laplace",
    "parameters_apart",
    "seconds_left",
    "share_deadline",
]

_EPS = 1e-9
#: Parameter sets evaluated per call of the likelihood: bounds the memory of a huge
#: optimiser population and lets a time budget be checked between chunks.
CHUNK = 2048


class BudgetError(InputError):
    """The wall-time budget ran out during the MAP search (``evaluations`` done)."""

    def __init__(self, message: str, evaluations: int):
        super().__init__(message)
        self.evaluations = evaluations


class _OutOfTimeError(Exception):
    """The deadline passed; ``args[0]`` may say why (an estimate made beforehand)."""


def _generation_seconds(n: int) -> float:
    """Measured cost [s] of the mutation step of one generation of scipy's
    differential evolution for a population of ``n``: for each member it shuffles the
    whole population index (``DifferentialEvolutionSolver._select_samples``, scipy
    1.17), so a generation costs ``n`` shuffles of ``n`` — quadratic, and beyond the
    reach of a deadline checked between likelihood evaluations (a large population's
    cost: docs/science/benchmarks.md, "Figures behind the code's choices")."""
    idx = np.arange(n)
    rng = np.random.default_rng(0)
    t0 = time.perf_counter()
    rng.shuffle(idx)
    return n * (time.perf_counter() - t0)


def share_deadline(end: float | None, parts_left: int) -> float | None:
    """One wall-time budget for several parts (the sections of a calibration): the next
    part may use an equal share of what is left before ``end`` (a
    :func:`time.perf_counter` value; None: no budget), returned as its deadline."""
    if end is None:
        return None
    now = time.perf_counter()
    return now + max(0.0, end - now) / max(1, parts_left)


def seconds_left(deadline: float | None) -> float | None:
    """Seconds until ``deadline`` (0 once passed; None without one)."""
    return None if deadline is None else max(0.0, deadline - time.perf_counter())


#: A restart's optimum replaces the first search's when its log-posterior is higher by
#: more than this: optima closer than that are equally good starts by their height (the
#: mass of a mode is its height times its width, which the search does not see), and
#: keeping the first keeps the chains of configs that found the best optimum before.
MODE_PICK = 2.0
#: Optima within this many log-posterior units of the best are reported as modes: one
#: 10 units lower holds e^-10 of the mass only if it is as wide as the best.
MODE_WINDOW = 10.0
#: Optima at least this far apart in some parameter (its position between its prior
#: bounds, log scale for log-scale priors) are distinct modes ...
MODE_DISTANCE = 0.1
#: ... when the log-posterior on the straight line between them drops more than this
#: below the lower of the two: otherwise they are two points of one ridge or broad mode
#: (the overall scale of C and G without a known heat input is such a ridge), which a
#: chain crosses.
MODE_BARRIER = 3.0
#: Points on that line (evenly spaced, ends excluded).
MODE_PATH_POINTS = 15


def parameters_apart(a: dict, b: dict, most: int = 4) -> list[str]:
    """Names of the parameters in which two optima (``{name: value}``) differ most,
    farthest first, at most ``most``: by a factor of 3 or more (positive values above 1:
    capacities, conductances, apertures), or by 0.1 or more (fractions, noise
    parameters). What the run's warning and the report's note name."""

    def apart(x: float, y: float) -> float:
        if x > 0 and y > 0 and max(x, y) > 1:
            return abs(np.log10(x / y)) / np.log10(3.0)
        return abs(x - y) / 0.1

    far = [n for n in a if n in b and apart(a[n], b[n]) >= 1]
    return sorted(far, key=lambda n: -apart(a[n], b[n]))[:most]


@dataclass
class MAPResult:
    """Result of :func:`find_map`.

    Attributes
    ----------
    x : (d,) array
        MAP in the sampler's unconstrained coordinates.
    theta : (P,) array
        All parameter values at the MAP (model then noise, fixed included).
    log_post : float
        Objective at the MAP (log-likelihood + log prior on the unit-cube scale).
    n_starts, n_agreed : int
        Polished candidates and how many reached the best value within 1 unit.
    candidates : list of float
        Final objective of each polished start, best first (``carried``: that of the
        carried ``start``, None without one).
    n_evaluations : int
    unit : (d,) array, optional
        The MAP's free parameters in the unit cube of the search.
    restarts : int
        Global searches run (the first and its restarts).
    modes : list of dict
        Distinct optima of the restarts within :data:`MODE_WINDOW` of the best, this
        MAP first: ``{"log_posterior": float, "theta": (P,) array}``; one entry when
        no other was found.
    """

    x: np.ndarray
    theta: np.ndarray
    log_post: float
    n_starts: int
    n_agreed: int
    candidates: list[float] = field(default_factory=list)
    n_evaluations: int = 0
    method: str = ""
    unit: np.ndarray | None = None
    restarts: int = 1
    modes: list[dict] = field(default_factory=list)
    carried: float | None = None

    def to_dict(self, names) -> dict:
        out = {
            "values": {n: float(v) for n, v in zip(names, self.theta, strict=True)},
            "log_posterior": float(self.log_post),
            "starts": int(self.n_starts),
            "agreed": int(self.n_agreed),
            "candidates": [float(c) for c in self.candidates],
            "evaluations": int(self.n_evaluations),
            "method": self.method,
        }
        if self.restarts > 1:
            out["restarts"] = int(self.restarts)
            out["modes"] = [
                {
                    "log_posterior": float(m["log_posterior"]),
                    "values": {n: float(v) for n, v in zip(names, m["theta"], strict=True)},
                }
                for m in self.modes
            ]
        return out


class _Objective:
    """Negative MAP objective on the unit cube, vectorised, counting evaluations."""

    def __init__(self, logpost, deadline: float | None = None):
        self.lp, self.ps = logpost, logpost.params
        self.n = 0
        self.deadline = deadline  # time.perf_counter() value, or None

    def values(self, S: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """Unit-cube (K, d) -> (theta (K, P), log prior w.r.t. the unit-cube scale)."""
        ps = self.ps
        y = ps._a + ps._w * S
        theta = np.tile(ps._fixed, (S.shape[0], 1))
        theta[:, ps._free_idx] = np.where(ps._log, np.exp(np.where(ps._log, y, 0.0)), y)
        lprior = ps.log_density_y(y).sum(axis=1)
        return theta, lprior

    def __call__(self, S: np.ndarray) -> np.ndarray:
        S = np.clip(np.atleast_2d(S), _EPS, 1 - _EPS)
        out = np.empty(S.shape[0])
        for i in range(0, S.shape[0], CHUNK):
            if self.deadline is not None and time.perf_counter() > self.deadline:
                raise _OutOfTimeError
            out[i : i + CHUNK] = self._values(S[i : i + CHUNK])
            self.n += min(CHUNK, S.shape[0] - i)
        return out

    def _values(self, S: np.ndarray) -> np.ndarray:
        theta, lprior = self.values(S)
        with np.errstate(all="ignore"):
            ll = self.lp.log_likelihood(theta)
            lprior = lprior + self.lp.time_constant_log_prior(theta[:, : self.lp.n_model])
        val = -(ll + lprior)
        # not 1e300: differential evolution takes the std of the energies, whose squares
        # overflowed (a numpy RuntimeWarning on configs/orholm.yaml); 1e100 squares safely
        return np.where(np.isfinite(val), val, 1e100)

    def fun_and_grad(self, s: np.ndarray, h: float = 1e-6):
        d = s.size
        pts = np.empty((2 * d + 1, d))
        pts[0] = s
        for i in range(d):
            step = h if s[i] + h <= 1 - _EPS else -h
            pts[1 + 2 * i] = s
            pts[2 + 2 * i] = s
            pts[1 + 2 * i, i] = s[i] + step
            pts[2 + 2 * i, i] = s[i] - step
        f = self(pts)
        g = (f[1::2] - f[2::2]) / (2 * np.where(s + h <= 1 - _EPS, h, -h))
        return float(f[0]), g


def find_map(logpost, **kwargs) -> MAPResult:
    """Global-then-local maximisation of the posterior (see module docstring).

    Parameters
    ----------
    logpost : LogPosterior
    seed : int
        Seeds the global search and the random starts: same seed, same result.
    method : {"differential_evolution", "multistart"}
    popsize, maxiter : int
        Differential-evolution settings (population = popsize × d).
    starts : int
        Candidates polished with L-BFGS-B (the best distinct DE members, or random
        starts for ``multistart``).
    restarts : int
        Global searches (default 1): the first with ``seed``, restart k with the seed
        sequence ``[seed, k]``; see the module docstring for which optimum is kept and
        what is reported as ``modes``. A deadline that passes during a restart ends
        the restarts and keeps what was found.
    deadline : float, optional
        A :func:`time.perf_counter` value: the search stops when it passes (checked
        every :data:`CHUNK` evaluations, a population of any size included).
    budget : str
        Names the budget in the message, e.g. ``"sampler.max_time = 30s"``.
    start : (d,) array, optional
        A point of the unit cube put into the first search's population and polished as
        one more start (a nested simpler model's MAP: it adds a candidate, no more).

    Raises
    ------
    BudgetError
        The deadline passed before the search ended (no MAP: the sampler needs one).

    BLAS runs single-threaded meanwhile (many small products: threads only spin).
    """
    from threadpoolctl import threadpool_limits

    with threadpool_limits(limits=1, user_api="blas"):
        return _find_map(logpost, **kwargs)


def _find_map(
    logpost,
    *,
    seed: int = 1,
    method: str = "differential_evolution",
    popsize: int = 10,
    maxiter: int = 300,
    starts: int = 4,
    restarts: int = 1,
    deadline: float | None = None,
    budget: str = "the time budget",
    start: np.ndarray | None = None,
) -> MAPResult:
    """Implementation of :func:`find_map` (same parameters)."""
    if restarts < 1:
        raise ValueError(f"optimizer.restarts must be at least 1 (got {restarts})")
    obj = _Objective(logpost, deadline)
    try:
        first = _search(logpost, obj, seed, method, popsize, maxiter, starts, start)
    except _OutOfTimeError as exc:
        d = logpost.params.ndim
        pop = f"a population of {popsize} × {d} = {popsize * d}" if method != "multistart" else ""
        why = f"; {exc.args[0]}" if exc.args else ""
        raise BudgetError(
            f"{budget} ran out during the MAP search ({method}{', ' if pop else ''}{pop}; "
            f"{obj.n} parameter sets evaluated{why}): nothing was sampled. Raise the budget, "
            "or lower optimizer.popsize / optimizer.maxiter / optimizer.starts",
            obj.n,
        ) from None
    if restarts == 1:
        return first
    found = [first]
    for k in range(1, restarts):
        try:
            found.append(_search(logpost, obj, [seed, k], method, popsize, maxiter, starts))
        except _OutOfTimeError:
            break
    try:
        return _with_modes(found, obj)
    except _OutOfTimeError:  # the deadline passed while the modes were compared
        return found[0]


def _separated(a: MAPResult, b: MAPResult, objective) -> bool:
    """Two optima apart (:data:`MODE_DISTANCE`) with a dip of more than
    :data:`MODE_BARRIER` on the straight line between them in the unit cube."""
    if np.abs(a.unit - b.unit).max() <= MODE_DISTANCE:
        return False
    t = np.linspace(0.0, 1.0, MODE_PATH_POINTS + 2)[1:-1, None]
    path = -objective(a.unit[None, :] + t * (b.unit - a.unit)[None, :])
    return bool(min(a.log_post, b.log_post) - path.min() > MODE_BARRIER)


def _with_modes(found: list[MAPResult], objective) -> MAPResult:
    """The MAP kept among the searches' optima (``found``, the first search's first) and
    the separate modes among them (see the module docstring); ``objective``: the
    negative log-posterior on the unit cube (:class:`_Objective`)."""
    first = found[0]
    best = max(found, key=lambda r: r.log_post)
    keep = best if best.log_post > first.log_post + MODE_PICK else first
    modes: list[MAPResult] = [keep]
    for r in sorted(found, key=lambda r: -r.log_post):
        if r.log_post < best.log_post - MODE_WINDOW or r is keep:
            continue
        if all(_separated(m, r, objective) for m in modes):
            modes.append(r)
    return replace(
        keep,
        n_evaluations=getattr(objective, "n", 0),
        restarts=len(found),
        modes=[{"log_posterior": m.log_post, "theta": m.theta} for m in modes],
    )


def _search(logpost, obj, seed, method, popsize, maxiter, starts, start=None) -> MAPResult:
    d = logpost.params.ndim
    rng = np.random.default_rng(seed)
    x0 = None if start is None else np.clip(np.asarray(start, dtype=float), 0.01, 0.99)
    if method == "differential_evolution":
        if obj.deadline is not None:  # a generation cannot be stopped once started
            gen = _generation_seconds(popsize * d)
            left = obj.deadline - time.perf_counter()
            if gen > left:
                raise _OutOfTimeError(
                    f"one generation's mutation step alone takes about {gen:.0f} s (measured; "
                    f"quadratic in the population), {max(left, 0):.0f} s were left"
                )
        res = differential_evolution(
            lambda S: obj(S.T),
            bounds=[(0.0, 1.0)] * d,
            popsize=popsize,
            maxiter=maxiter,
            tol=1e-7,
            seed=rng,
            vectorized=True,
            updating="deferred",
            polish=False,
            init="latinhypercube",
            x0=x0,
        )
        pop = np.asarray(res.population)
        energies = np.asarray(res.population_energies)
        order = np.argsort(energies)
        cands = [pop[order[0]]]
        for i in order[1:]:
            if len(cands) >= starts:
                break
            if min(np.abs(pop[i] - c).max() for c in cands) > 0.02:
                cands.append(pop[i])
        while len(cands) < starts:  # population collapsed: perturb the best
            cands.append(np.clip(pop[order[0]] + rng.normal(0, 0.05, d), 0.01, 0.99))
        if x0 is not None and min(np.abs(x0 - c).max() for c in cands) > 0.02:
            cands.append(x0)
    elif method == "multistart":
        cands = list(rng.uniform(0.02, 0.98, (max(starts, 1), d))) + ([] if x0 is None else [x0])
    else:
        raise ValueError(
            f"optimizer.method must be 'differential_evolution' or 'multistart' (got {method!r})"
        )
    finals = []
    for s0 in cands:
        r = minimize(
            obj.fun_and_grad,
            np.asarray(s0, dtype=float),
            jac=True,
            method="L-BFGS-B",
            bounds=[(_EPS, 1 - _EPS)] * d,
            options={"maxiter": 500, "ftol": 1e-12, "gtol": 1e-8},
        )
        finals.append((float(r.fun), np.clip(r.x, _EPS, 1 - _EPS), s0 is x0))
    finals.sort(key=lambda t: t[0])
    best_f, best_s, _ = finals[0]
    agreed = sum(1 for f, *_ in finals if f - best_f <= 1.0)
    theta, _ = obj.values(best_s[None])
    x = logpost.params.to_unconstrained(theta)[0]
    return MAPResult(
        x=x,
        theta=theta[0],
        log_post=-best_f,
        n_starts=len(finals),
        n_agreed=agreed,
        candidates=[-f for f, *_ in finals],
        n_evaluations=obj.n,
        method=method,
        unit=best_s,
        carried=next((-f for f, _, c in finals if c), None),
    )


@dataclass
class LaplaceResult:
    """Curvature of the log-posterior at the MAP (sampling coordinates).

    Attributes
    ----------
    x : (d,) array
        Where the Hessian was taken (the MAP, moved off a bound if it sat on one).
    hessian : (d, d) array
        Of the negative log-posterior.
    sd : (d,) array
        Laplace standard deviations, sqrt(diag(H⁻¹)) (pseudo-inverse; inf along a
        direction of zero or negative curvature).
    rel_sd : (d,) array
        ``sd`` relative to the width of each coordinate's prior range (log range for
        log-scale priors; logit coordinates: sd / 4, 4 logit units spanning most of
        the range).
    unidentified : list of str
        Free parameters with ``rel_sd`` above the threshold: the data do not pin them
        (practical non-identifiability at the MAP).
    """

    x: np.ndarray
    hessian: np.ndarray
    sd: np.ndarray
    rel_sd: np.ndarray
    unidentified: list[str]

    def to_dict(self, names) -> dict:
        return {
            "rel_sd": {n: float(v) for n, v in zip(names, self.rel_sd, strict=True)},
            "unidentified": list(self.unidentified),
        }


def laplace(
    logpost, x_map, *, given: tuple[str, ...] = (), rel_step: float = 1e-3, threshold: float = 0.25
):
    """Practical identifiability at the MAP from the Laplace approximation.

    Central second differences of the log-posterior in the sampler's coordinates
    (one vectorised call of 2 d² + 1 points); a parameter whose Laplace standard
    deviation exceeds ``threshold`` × its prior range is flagged: the data leave it
    almost as uncertain as the prior does, so sampling it is slow and its posterior
    is the prior's (Raue et al. 2009 call this practical non-identifiability).

    Parameters
    ----------
    logpost : LogPosterior
        Vectorised, with ``params`` (a ParameterSet).
    x_map : (d,) array
    rel_step : float
        Difference step relative to each coordinate's range (1 for logit ones).
    given : tuple of str
        Parameters held at their MAP value for the standard deviations (conditional
        variances: the inverse of the Hessian without their rows and columns), e.g.
        the capacity through which the overall scale of C and G is pinned, so that the
        scale ridge, which only a prior can close, does not flag every C and G.
    threshold : float

    Returns
    -------
    LaplaceResult or None
        None when the log-posterior is not finite around the MAP.

    References
    ----------
    .. [1] A. Raue et al., "Structural and practical identifiability analysis of
       partially observed dynamical models by exploiting the profile likelihood",
       Bioinformatics 25 (2009) 1923-1929. doi:10.1093/bioinformatics/btp358
    """
    ps = logpost.params
    lo, hi = ps.bounds
    width = hi - lo
    bounded = np.isfinite(width)
    scale = np.where(bounded, width, 4.0)
    h = rel_step * np.where(bounded, width, 1.0)
    pad = np.where(bounded, 3 * h, 0.0)
    x0 = np.clip(np.asarray(x_map, dtype=float), lo + pad, hi - pad)
    d = x0.size
    pts = [x0]
    pairs = [(i, j) for i in range(d) for j in range(i, d)]
    for i, j in pairs:
        for si, sj in ((1, 1), (1, -1), (-1, 1), (-1, -1)):
            p = x0.copy()
            p[i] += si * h[i]
            p[j] += sj * h[j]
            pts.append(p)
    P = np.array(pts)
    f = -np.concatenate([np.asarray(logpost(P[k : k + 64]), float) for k in range(0, len(P), 64)])
    if not np.all(np.isfinite(f)):
        return None
    H = np.empty((d, d))
    for k, (i, j) in enumerate(pairs):
        fpp, fpm, fmp, fmm = f[1 + 4 * k : 5 + 4 * k]
        H[i, j] = H[j, i] = (fpp - fpm - fmp + fmm) / (4 * h[i] * h[j])
    names = ps.free_names
    keep = np.array([n not in given for n in names])
    Hk = 0.5 * (H + H.T)[np.ix_(keep, keep)]
    w, V = np.linalg.eigh(Hk)
    # variance along each eigendirection, capped at the widest prior range squared:
    # flat or negatively curved directions (a ridge, or a MAP on a bound where the
    # optimum is not stationary) count as unpinned, in proportion to each loading
    cap = float(np.max(scale[keep])) ** 2 if keep.any() else 1.0
    var_dir = np.where(w > 1.0 / cap, 1.0 / np.where(w > 1.0 / cap, w, 1.0), cap)
    var = V**2 @ var_dir
    sd = np.zeros(d)
    sd[keep] = np.sqrt(var)
    rel = sd / scale
    flagged = [n for n, r in zip(names, rel, strict=True) if r > threshold]
    return LaplaceResult(x0, H, sd, rel, flagged)


@dataclass
class AffineCoordinates:
    """Whitened sampling coordinates from the Laplace approximation: x = x0 + L z.

    ``L`` is a square root of the Laplace covariance H⁻¹ (eigenvalues floored so that
    flat or negatively curved directions, e.g. the scale ridge, get at most the prior's
    width). The density in z is the density in x times |det L|, a constant, so the
    posterior is the same distribution; :meth:`__call__` returns log p(x(z)) +
    log|det L|.

    Note: emcee's stretch and differential-evolution moves are affine invariant
    (Goodman & Weare 2010; ter Braak & Vrugt 2008), so with them this changes the
    chain only through DE's tiny isotropic jitter and the snooker update's metric;
    ``benchmarks/bench_sampling.py`` measures it.
    """

    logpost: object
    x0: np.ndarray
    L: np.ndarray
    log_det: float

    def __call__(self, Z: np.ndarray) -> np.ndarray:
        return self.logpost(self.to_x(Z)) + self.log_det

    def to_x(self, Z: np.ndarray) -> np.ndarray:
        return self.x0 + np.atleast_2d(Z) @ self.L.T

    def to_z(self, X: np.ndarray) -> np.ndarray:
        return np.linalg.solve(self.L, (np.atleast_2d(X) - self.x0).T).T


def affine_coordinates(logpost, lap: LaplaceResult) -> AffineCoordinates:
    """Whitening transform about ``lap.x`` from its Hessian (see :class:`AffineCoordinates`)."""
    lo, hi = logpost.params.bounds
    width = np.where(np.isfinite(hi - lo), hi - lo, 4.0)
    w, V = np.linalg.eigh(0.5 * (lap.hessian + lap.hessian.T))
    floor = 1.0 / float(np.max(width)) ** 2  # at most the widest prior range
    L = V * (1.0 / np.sqrt(np.maximum(w, floor)))
    return AffineCoordinates(logpost, lap.x.copy(), L, float(np.linalg.slogdet(L)[1]))
