"""Sampling along the exact scale direction of a room without a measured heat input.

A room observed through temperatures (or vapour pressures) only, driven by the outdoor
air, the ground and the sun, with no heat (moisture) flow logged in watts (kg/s), has
an exact symmetry: multiplying every capacity [J/K], conductance [W/K], solar aperture
[m²], constant source [W] and heating power limit [W] by one factor :math:`e^t`
leaves every simulated temperature unchanged (the state equation
:math:`C\\dot T = G T + B u` divided through by the factor), so the likelihood is
constant along the line :math:`x + t s` of the sampler's log coordinates (``s`` 1 on
those parameters, 0 elsewhere). Only the priors bound :math:`t`; with log-uniform
priors the posterior along the line is flat between the nearest prior bounds, a
ridge whose ends move with every other coordinate. An ensemble started in a small
ball needs thousands of steps to stretch along it.

:class:`ScaleLine` samples that direction exactly. Its coordinates are the others
with the scale removed (``y_j = z_j - s_j z_k``, ratios to a reference parameter ``k``
in the log coordinates) and, in place of ``z_k``, the logit of the *prior's
conditional distribution function* along the line,

.. math::

    v = \\mathrm{logit}\\, F(t \\mid r),\\qquad
    F(t \\mid r) = \\frac{\\int_{t_0}^{t} p(r + t' s)\\,dt'}{\\int p(r + t' s)\\,dt'},

with ``p`` the prior density in the log coordinates and ``r`` the point of the line at
``t = 0``. :math:`F` is computed on 64 cells between the prior bounds along the line
(the prior taken constant within a cell; one cell, exact, where every member's prior is
log-uniform) and inverted
piecewise linearly; the log-density in ``y`` is the log-posterior plus
:math:`\\log|dt/dv|` of that same map, so the target is exact whatever the grid. As the
likelihood does not depend on ``t``, the posterior in ``y`` is
:math:`p(\\text{data} \\mid r)\\,Z(r)\\,\\sigma(v)(1 - \\sigma(v))`, ``Z(r)`` the prior's
mass along the line: ``v`` is independent of the rest and logistic, and the ridge with
moving ends becomes one coordinate of fixed shape. :meth:`ScaleLine.spread` draws it
exactly for the start, and :class:`ScaleRedraw` redraws it (an independence
Metropolis-Hastings move, accepted with probability one where the prior along the line
is as the grid has it). The chain is stored in the log coordinates as before.

Whether a run has the symmetry is measured, not assumed: :func:`scale_line` checks that
the log-likelihood at the MAP does not change along ``±s`` (a measured heat input, a
gain fixed in watts or a prior family without bounds breaks it; then the sampler keeps
its coordinates).

References
----------
.. [1] H. Madsen, J. Holst, "Estimation of continuous-time models for the heat dynamics
   of a building", Energy and Buildings 22 (1995) 67-79 (only time constants and gains
   are identified from temperatures).
.. [2] M.J. Betancourt, M. Girolami, "Hamiltonian Monte Carlo for hierarchical models",
   arXiv:1312.0906 (2013): reparameterisation along the directions the data identify.
"""

from __future__ import annotations

import emcee
import numpy as np
from scipy.special import expit

__all__ = [
    "SCALE_KINDS",
    "SCALE_REDRAW_WEIGHT",
    "ScaleLine",
    "ScaleRedraw",
    "scale_direction",
    "scale_line",
    "with_scale_redraw",
]

#: Parameter kinds scaled together by the symmetry (those carrying J/K, W/K, m², W or
#: their hygric counterparts).
SCALE_KINDS = ("capacity", "conductance", "gain", "sorption_capacity", "source", "power")

#: Cells of the prior's distribution function along the line.
CELLS = 64

#: Largest relative change of the log-likelihood along ±s accepted as "constant".
RTOL = 1e-9


def scale_direction(logpost) -> np.ndarray | None:
    """(d,) the overall scale in the log-posterior's free coordinates (1 on every free
    log-scale parameter of a :data:`SCALE_KINDS` kind, 0 elsewhere), or None when
    there is none or a member's prior has no finite range along it."""
    model, params = getattr(logpost, "model", None), logpost.params
    kinds = {info.name: info.kind for info in getattr(model, "parameters", ())}
    lo, hi = params.bounds
    s = np.zeros(params.ndim)
    for k, j in enumerate(params._free_idx):
        p = params.parameters[int(j)]
        if kinds.get(p.name) in SCALE_KINDS and p.prior.log_scale:
            if not (np.isfinite(lo[k]) and np.isfinite(hi[k])):
                return None
            s[k] = 1.0
    return s if s.any() else None


def scale_line(logpost, inner, x_map: np.ndarray):
    """:class:`ScaleLine` over the coordinates ``inner`` (None: the log coordinates) when
    the likelihood at ``x_map`` is constant along the scale direction, else ``inner``."""
    s = scale_direction(logpost)
    if s is None:
        return inner
    x = np.asarray(x_map, dtype=float)
    X = np.stack([x, x + s, x - s])
    ll = logpost.log_likelihood(logpost.params.transform(X)[0])
    if not np.all(np.isfinite(ll)) or np.max(np.abs(ll[1:] - ll[0])) > RTOL * max(1.0, abs(ll[0])):
        return inner
    z = X if inner is None else inner.to_y(X[:2])
    s_z = z[1] - z[0]
    if not np.allclose(s_z, np.round(s_z), atol=1e-9) or not np.any(np.round(s_z) == 1):
        return inner  # the inner coordinates do not carry the line as a unit shift
    return ScaleLine(logpost, inner, s, np.round(s_z))


class ScaleLine:
    """Sampler coordinates with the overall scale as the logit of its conditional prior
    distribution function (see the module docstring).

    Parameters
    ----------
    logpost : LogPosterior
    inner : coordinates or None
        The coordinates the line is taken out of (e.g.
        :class:`~heritage_bayes.inference.coordinates.NodeTimeConstants`); None: the
        log coordinates.
    s_x, s_z : (d,) arrays
        The scale direction in the log coordinates and in ``inner``'s (0/1 entries).

    Attributes
    ----------
    index : int
        The coordinate that holds ``v`` (the first with ``s_z`` = 1).
    """

    def __init__(self, logpost, inner, s_x: np.ndarray, s_z: np.ndarray):
        self.logpost, self.inner = logpost, inner
        self.s_x, self.s_z = np.asarray(s_x, float), np.asarray(s_z, float)
        self.index = int(np.flatnonzero(self.s_z == 1)[0])
        self.name = (getattr(inner, "name", "log") if inner is not None else "log") + "+scale"
        lo, hi = logpost.params.bounds
        on = self.s_x == 1
        self._on, self._lo, self._hi = on, lo[on], hi[on]
        # log-uniform members only: the prior is constant along the line inside its
        # bounds (the other parameters do not move), one cell is exact
        free = [logpost.params.parameters[int(j)] for j in logpost.params._free_idx]
        flat = all(p.prior.dist == "loguniform" for p, o in zip(free, on, strict=True) if o)
        self.cells = 1 if flat else CELLS

    @property
    def ndim(self) -> int:
        return self.logpost.ndim

    def _z_to_x(self, Z: np.ndarray) -> np.ndarray:
        return Z if self.inner is None else self.inner.to_x(Z)

    def _cells(self, X0: np.ndarray):
        """(t of the cell edges (K, CELLS+1), distribution function at them (K, CELLS+1),
        log cell width (K,)) of the prior along ``X0 + t s_x``; NaN rows where the line
        misses the support."""
        t_lo = np.max(self._lo - X0[:, self._on], axis=1)
        t_hi = np.min(self._hi - X0[:, self._on], axis=1)
        width = t_hi - t_lo
        ok = width > 0
        frac = np.linspace(0.0, 1.0, self.cells + 1)
        edges = t_lo[:, None] + width[:, None] * frac
        mids = 0.5 * (edges[:, 1:] + edges[:, :-1])
        F = np.full(edges.shape, np.nan)
        if self.cells == 1:
            F[ok] = frac
        elif ok.any():
            pts = X0[ok, None, :] + mids[ok, :, None] * self.s_x
            logp = self.logpost.params.transform(pts.reshape(-1, X0.shape[1]))[1]
            logp = logp.reshape(-1, self.cells)
            top = np.max(logp, axis=1, keepdims=True)
            good = np.isfinite(top[:, 0])
            mass = np.where(good[:, None], np.exp(logp - np.where(good[:, None], top, 0.0)), 0.0)
            cum = np.concatenate([np.zeros((mass.shape[0], 1)), np.cumsum(mass, axis=1)], axis=1)
            with np.errstate(invalid="ignore", divide="ignore"):
                F[ok] = np.where(good[:, None], cum / cum[:, -1:], np.nan)
        with np.errstate(divide="ignore", invalid="ignore"):
            return edges, F, np.log(width / self.cells)

    def _split(self, Y: np.ndarray):
        """(Z0: inner coordinates at t = 0, X0: the same in log coordinates, u)."""
        Y = np.array(np.atleast_2d(Y), dtype=float, copy=True)
        u = expit(Y[:, self.index])
        Y[:, self.index] = 0.0
        return Y, self._z_to_x(Y), u

    def _t_and_logj(self, X0: np.ndarray, u: np.ndarray):
        """(t (K,), log |dt/dv| (K,)) for the distribution-function values ``u``."""
        edges, F, log_w = self._cells(X0)
        ok = np.isfinite(F[:, -1]) & (u > 0.0) & (u < 1.0)
        Fz = np.where(ok[:, None], F, 0.0)
        c = np.clip(np.sum(Fz[:, 1:-1] <= u[:, None], axis=1), 0, self.cells - 1)
        rows = np.arange(u.size)
        dF = Fz[rows, c + 1] - Fz[rows, c]
        ok &= dF > 0
        with np.errstate(divide="ignore", invalid="ignore"):
            frac = np.where(ok, (u - Fz[rows, c]) / dF, np.nan)
            t = edges[rows, c] + frac * (edges[rows, c + 1] - edges[rows, c])
            # dt/du = cell width / cell mass; du/dv = u (1 - u)
            logj = log_w - np.log(dF) + np.log(u) + np.log1p(-u)
        return np.where(ok, t, np.nan), np.where(ok, logj, -np.inf)

    def to_x(self, Y: np.ndarray) -> np.ndarray:
        """Scale-line coordinates (K, d) -> the log coordinates (K, d)."""
        _, X0, u = self._split(Y)
        t, _ = self._t_and_logj(X0, u)
        return X0 + t[:, None] * self.s_x

    def to_y(self, X: np.ndarray) -> np.ndarray:
        """The log coordinates (K, d) -> scale-line coordinates (K, d)."""
        X = np.atleast_2d(np.asarray(X, dtype=float))
        Z = X if self.inner is None else self.inner.to_y(X)
        t = Z[:, self.index].copy()
        Y = Z - t[:, None] * self.s_z
        X0 = X - t[:, None] * self.s_x
        edges, F, _ = self._cells(X0)
        ok = np.isfinite(F[:, -1])
        rows = np.arange(t.size)
        with np.errstate(invalid="ignore"):
            pos = (t - edges[:, 0]) / (edges[:, -1] - edges[:, 0]) * self.cells
            c = np.clip(np.floor(np.where(ok, pos, 0.0)).astype(int), 0, self.cells - 1)
            Fz = np.where(ok[:, None], F, 0.0)
            u = Fz[rows, c] + np.clip(pos - c, 0.0, 1.0) * (Fz[rows, c + 1] - Fz[rows, c])
        u = np.where(ok, u, np.nan)
        with np.errstate(divide="ignore"):
            Y[:, self.index] = np.log(u) - np.log1p(-u)
        return Y

    def __call__(self, Y: np.ndarray) -> np.ndarray:
        """(K,) log-density in scale-line coordinates (the log-posterior plus log|dt/dv|)."""
        Z0, X0, u = self._split(Y)
        t, logj = self._t_and_logj(X0, u)
        out = np.full(t.shape, -np.inf)
        ok = np.isfinite(logj)
        if ok.any():
            Z = Z0[ok] + t[ok, None] * self.s_z
            inner = self.logpost if self.inner is None else self.inner
            out[ok] = np.asarray(inner(Z), dtype=float) + logj[ok]
        out[~np.isfinite(out)] = -np.inf
        return out

    def spread(self, Y: np.ndarray, rng: np.random.Generator) -> np.ndarray:
        """The walkers ``Y`` with ``v`` drawn afresh from the logistic distribution (its
        conditional where the prior along the line is as the cells have it)."""
        Y = np.array(Y, dtype=float, copy=True)
        u = rng.uniform(size=Y.shape[0])
        Y[:, self.index] = np.log(u) - np.log1p(-u)
        return Y


class ScaleRedraw(emcee.moves.MHMove):
    """Independence Metropolis-Hastings move of the scale coordinate ``v`` of a
    :class:`ScaleLine`: a fresh logistic draw, accepted with the ratio of the target to
    the logistic density (one where ``v`` is logistic and independent of the rest)."""

    def __init__(self, index: int):
        self.index = int(index)
        super().__init__(self._propose)

    @staticmethod
    def _log_logistic(v: np.ndarray) -> np.ndarray:
        a = np.abs(v)
        return -a - 2.0 * np.log1p(np.exp(-a))

    def _propose(self, coords: np.ndarray, random):
        q = np.array(coords, dtype=float, copy=True)
        u = random.uniform(size=q.shape[0])
        u = np.clip(u, 1e-300, 1.0 - 1e-16)
        q[:, self.index] = np.log(u) - np.log1p(-u)
        old, new = coords[:, self.index], q[:, self.index]
        return q, self._log_logistic(old) - self._log_logistic(new)


#: Share of the steps that redraw the scale coordinate of a scale line.
SCALE_REDRAW_WEIGHT = 0.1


def with_scale_redraw(move_list: list, coordinates) -> list:
    """The moves ``[(move, weight), ...]``, plus the independence redraw of the scale
    coordinate (:class:`ScaleRedraw`, a share :data:`SCALE_REDRAW_WEIGHT` of the steps)
    when the coordinates are a :class:`ScaleLine`."""
    if not isinstance(coordinates, ScaleLine):
        return move_list
    rest = 1.0 - SCALE_REDRAW_WEIGHT
    redraw = ScaleRedraw(coordinates.index)
    return [(m, w * rest) for m, w in move_list] + [(redraw, SCALE_REDRAW_WEIGHT)]
