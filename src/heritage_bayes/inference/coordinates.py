"""Sampling coordinates along node time constants (a non-affine change of variables).

The sampler's own coordinates are ``x = log θ`` for capacities and conductances (see
:mod:`heritage_bayes.inference.parameters`). In them the overall scale of an RC model
(all C and G multiplied by one factor) is a straight line, which emcee's
affine-invariant moves follow at no cost; what they cannot straighten is curvature. The
data of a node whose capacity is not pinned identify its *time constant*,
:math:`\\tau_i = C_i / \\sum_k G_{ik}` [s] (capacity over the sum of the conductances
attached to it, to other nodes and to boundaries), far better than :math:`C_i`
itself, and :math:`\\log \\tau_i = \\log C_i - \\log \\sum_k G_{ik}` is a curved
function of the log coordinates wherever two conductances of a node are of similar
size (a banana-shaped ridge between the capacity and its conductances).

:class:`NodeTimeConstants` samples ``y`` with :math:`y_{C_i} = \\log \\tau_i` in place of
:math:`\\log C_i` and every other coordinate unchanged. The map is triangular with a
unit diagonal (each :math:`\\log C_i` is its :math:`y` plus a function of conductance
coordinates only), so :math:`|\\partial x/\\partial y| = 1`: the log-density in ``y``
is the log-density in ``x``, no Jacobian term, the priors still stated on C and G.
The chain is stored in ``x``: convergence, summaries and outputs do not change.

Split solar gains (thermal_4a's ``fsol`` [-]: the share of each aperture ``fI_s`` [m²]
absorbed by the interior mass, the rest heating the air) can be re-coordinated the
same way (``solar=True``; opt-in, see below). The data see per surface the aperture
to the air :math:`a_s = fI_s (1 - f)` and to the mass :math:`m_s = fI_s f`; in the
sampler's coordinates (:math:`\\log fI_s`, :math:`v = \\mathrm{logit}\\, f`)
:math:`\\log a_s = \\log fI_s - \\mathrm{softplus}(v)` and
:math:`\\log m_s = \\log fI_s - \\mathrm{softplus}(-v)` are curved (a ridge bent
around :math:`f \\approx 1/2`). With ``solar=True`` :class:`NodeTimeConstants`
samples :math:`y_{fI_s} = \\log a_s = \\log fI_s + \\log(1 - f)` in place of
:math:`\\log fI_s`, ``v`` unchanged: then :math:`\\log a_s = y_{fI_s}` and
:math:`\\log m_s = y_{fI_s} + v` (for a prior on ``f`` over [0, 1]) are both linear,
a straight ridge the affine-invariant moves follow. The map is again triangular with
a unit diagonal (each :math:`\\log fI_s` is its ``y`` plus a function of ``v`` only):
unit Jacobian.

The fsol-aperture ridge is not what slows ``fsol`` (measured:
docs/science/benchmarks.md, "The coordinate of fsol"), and ``hbayes`` keeps the
apertures in log coordinates (``solar=False``, the default).

References
----------
.. [1] M.J. Betancourt, M. Girolami, "Hamiltonian Monte Carlo for hierarchical
   models", arXiv:1312.0906 (2013): reparameterisation along the directions the data
   identify.
.. [2] J. Goodman, J. Weare, "Ensemble samplers with affine invariance", Commun. Appl.
   Math. Comput. Sci. 5 (2010) 65-80 (why only a non-affine map can change the chain).
"""

from __future__ import annotations

import numpy as np
from scipy.special import expit

__all__ = [
    "NodeTimeConstants",
    "default_coordinates",
    "node_time_constants",
    "sampling_coordinates",
]

#: Networks with at least this many capacity nodes are sampled along node time
#: constants by default (:func:`default_coordinates`).
MIN_NODES = 3


class NodeTimeConstants:
    """Sampler coordinates with log node time constants in place of log capacities.

    Parameters
    ----------
    logpost : LogPosterior
        Its ``params`` (free parameters in sampler coordinates) and ``model`` (the RC
        network: which conductances attach to which node).

    Attributes
    ----------
    nodes : list of (int, list of (int or None, float, bool))
        Per re-coordinated node: the free index of its capacity and, per attached
        conductance, (free index or None when fixed, fixed value, log-scale?).
    splits : list of (int, float, float, list of int)
        Per split fraction ``f`` [-] of a solar source (thermal_4a's ``fsol``): its free
        (logit) index, the prior's lower bound and width (``f = lo + width σ(v)``), and
        the free indices of the log-scale apertures [m²] it splits, whose coordinate is
        the log of the aperture to the air, ``log(fI_s (1 - f))``. Empty when ``solar``
        is False.
    """

    name = "node_tau"

    def __init__(self, logpost, solar: bool = False, air_share: bool = False, series: bool = False):
        self.logpost = logpost
        params, model = logpost.params, logpost.model
        free = {int(j): k for k, j in enumerate(params._free_idx)}
        ix = model._ix
        attached: dict[int, list[int]] = {a: [] for a in range(model.n_states)}
        for a, b, g in ix["nn"]:
            attached[a].append(g)
            attached[b].append(g)
        for a, _, g in list(ix["nu"]) + list(ix["nc"]):
            attached[a].append(g)
        self.nodes = []
        for a, c in enumerate(ix["cap"]):
            c = int(c)
            if c not in free or not params.parameters[c].prior.log_scale or not attached[a]:
                continue
            gs = []
            for g in attached[a]:
                p = params.parameters[g]
                gs.append((free.get(g), float(p.fixed or 0.0), bool(p.prior.log_scale)))
            self.nodes.append((free[c], gs))
        self.splits = _splits(params, model, free) if solar else []
        # (free index of G_a, of G_b) of nodes between exactly two free log-scale
        # conductances, sampled as log G_a G_b / (G_a + G_b) and log G_a / G_b
        self.pairs = _pairs(self.nodes) if series else []
        # (free index, lo, width) of split fractions sampled as log(1 - f) [-]
        self.shares = (
            [(k, lo, w) for k, lo, w, _ in _splits(params, model, free)] if air_share else []
        )

    @property
    def ndim(self) -> int:
        return self.logpost.ndim

    def _log_conductance_sum(self, X: np.ndarray, gs) -> np.ndarray:
        """(K,) log of the sum of a node's conductances [log W/K] at coordinates X."""
        total = np.zeros(X.shape[0])
        for k, value, log_scale in gs:
            if k is None:
                total = total + value
            else:
                total = total + (np.exp(np.clip(X[:, k], -700, 700)) if log_scale else X[:, k])
        with np.errstate(divide="ignore", invalid="ignore"):
            return np.log(total)

    @staticmethod
    def _log_air_share(v: np.ndarray, lo: float, width: float) -> np.ndarray:
        """(K,) log(1 - f) [-] of a split fraction f = lo + width σ(v) (logit v)."""
        if lo == 0.0 and width == 1.0:
            return -np.logaddexp(0.0, v)  # log(1 - σ(v)), exact in both tails
        with np.errstate(divide="ignore", invalid="ignore"):
            return np.log1p(-(lo + width * expit(v)))

    def _share_to_logit(self, Y: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """log(1 - f) coordinates -> (the logit coordinates of f (K, len(shares)),
        log|dv/dy| summed (K,)); outside the prior's support NaN and -inf."""
        V = np.empty((Y.shape[0], len(self.shares)))
        logj = np.zeros(Y.shape[0])
        for i, (k, lo, width) in enumerate(self.shares):
            with np.errstate(divide="ignore", invalid="ignore", over="ignore"):
                s = (-np.expm1(Y[:, k]) - lo) / width  # σ(v) = (1 - e^y - lo) / width
                ok = (s > 0) & (s < 1)
                V[:, i] = np.where(ok, np.log(s) - np.log1p(-s), np.nan)
                # |dv/dy| = e^y / (width σ (1 - σ))
                logj += np.where(ok, Y[:, k] - np.log(width) - np.log(s) - np.log1p(-s), -np.inf)
        return V, logj

    def to_x(self, Y: np.ndarray) -> np.ndarray:
        """Time-constant coordinates (K, d) -> the sampler's log coordinates (K, d)."""
        X = np.array(np.atleast_2d(Y), dtype=float, copy=True)
        for ka, kb in self.pairs:  # (log series conductance, log ratio) -> log G_a, log G_b
            s, r = X[:, ka].copy(), X[:, kb].copy()
            X[:, ka] = s + np.logaddexp(0.0, r)
            X[:, kb] = s + np.logaddexp(0.0, -r)
        if self.shares:
            V, _ = self._share_to_logit(X)
            for i, (k, _, _) in enumerate(self.shares):
                X[:, k] = V[:, i]
        for c, gs in self.nodes:  # conductance coordinates are the same in x and y
            X[:, c] = X[:, c] + self._log_conductance_sum(X, gs)
        for f, lo, width, gains in self.splits:  # f's coordinate is the same in x and y
            share = self._log_air_share(X[:, f], lo, width)
            for g in gains:
                X[:, g] = X[:, g] - share
        return X

    def to_y(self, X: np.ndarray) -> np.ndarray:
        """The sampler's log coordinates (K, d) -> time-constant coordinates (K, d)."""
        X = np.atleast_2d(np.asarray(X, dtype=float))
        Y = X.copy()
        for c, gs in self.nodes:
            Y[:, c] = X[:, c] - self._log_conductance_sum(X, gs)
        for f, lo, width, gains in self.splits:
            share = self._log_air_share(X[:, f], lo, width)
            for g in gains:
                Y[:, g] = X[:, g] + share
        for k, lo, width in self.shares:
            Y[:, k] = self._log_air_share(X[:, k], lo, width)
        for ka, kb in self.pairs:
            a, b = X[:, ka], X[:, kb]
            Y[:, ka] = a + b - np.logaddexp(a, b)
            Y[:, kb] = a - b
        return Y

    def __call__(self, Y: np.ndarray) -> np.ndarray:
        """(K,) log-posterior at time-constant coordinates (unit Jacobian)."""
        X = self.to_x(Y)
        logj = self._share_to_logit(np.atleast_2d(Y))[1] if self.shares else 0.0
        ok = np.all(np.isfinite(X), axis=1)
        out = np.full(X.shape[0], -np.inf)
        if ok.any():
            out[ok] = self.logpost(X[ok])
        return out + logj


def _pairs(nodes) -> list[tuple[int, int]]:
    """The conductance pairs of :attr:`NodeTimeConstants.pairs`: per re-coordinated node
    with exactly two attached conductances, both free and log-scale (an envelope node
    between the outdoor and the indoor air: thermal_2c's and thermal_4a's ``Cw`` with
    ``Gw`` and ``Gi``), their free indices; a conductance is in one pair at most.

    The data see the steady conductance of the path through the node, G_a G_b / (G_a +
    G_b) [W/K], far better than how it splits (G_a / G_b sets where the node's
    temperature sits between the two sides); in log G_a, log G_b a constant series
    conductance is a curve (log G_b constant where G_a >> G_b, log G_a where G_a <<
    G_b). The map (log G_a, log G_b) -> (s, r) = (log G_a G_b/(G_a + G_b), log G_a/G_b)
    has the inverse log G_a = s + softplus(r), log G_b = s + softplus(-r) and Jacobian
    determinant -1 (∂s/∂ log G_a = G_b/(G_a + G_b), ∂s/∂ log G_b = G_a/(G_a + G_b)):
    unit |Jacobian|, no term in the log-density."""
    out: list[tuple[int, int]] = []
    used: set[int] = set()
    for _, gs in nodes:
        if len(gs) != 2 or not all(k is not None and log for k, _, log in gs):
            continue
        (ka, _, _), (kb, _, _) = gs
        if ka == kb or ka in used or kb in used:
            continue
        used |= {ka, kb}
        out.append((ka, kb))
    return out


def _splits(params, model, free: dict[int, int]) -> list[tuple[int, float, float, list[int]]]:
    """The split fractions of a network's sources to re-coordinate (see
    :attr:`NodeTimeConstants.splits`): a free logit fraction whose prior lies in
    [0, 1] and the free log-scale gains it splits (sources with fraction ``"1-f"``)."""
    index = {p.name: j for j, p in enumerate(params.parameters)}
    out: dict[int, list[int]] = {}
    for src in model.network.sources:
        frac = src.fraction_param
        if frac is None or not frac[1] or not isinstance(src.gain, str):
            continue
        f, g = index.get(frac[0]), index.get(src.gain)
        if f not in free or g not in free or not params.parameters[g].prior.log_scale:
            continue
        k = free[f]
        if not params._logit[k] or free[g] in out.get(k, []):
            continue
        out.setdefault(k, []).append(free[g])
    splits = []
    for k, gains in out.items():
        lo, width = float(params._a[k]), float(params._w[k])
        if lo >= 0.0 and lo + width <= 1.0:  # 1 - f > 0 inside the prior
            splits.append((k, lo, width, gains))
    return splits


def node_time_constants(
    logpost, solar: bool = False, air_share: bool = False, series: bool = False
) -> NodeTimeConstants | None:
    """:class:`NodeTimeConstants` for a log-posterior, or None when no node's capacity
    is a free log-scale parameter and no solar gain is split (nothing to re-coordinate).
    ``solar=False`` leaves the split solar apertures in the log coordinates."""
    coords = NodeTimeConstants(logpost, solar=solar, air_share=air_share, series=series)
    return coords if coords.nodes or coords.splits or coords.shares else None


def sampling_coordinates(logpost, choice: str = "auto") -> NodeTimeConstants | None:
    """The coordinates of ``sampler.coordinates``: ``"auto"`` (:func:`default_coordinates`),
    ``"log"`` (None: the log-posterior's own) or ``"node_tau"`` (node time constants
    wherever a capacity is a free log-scale parameter, whatever the network's size, and
    split solar fractions as the log of the air's share, ``air_share``).
    """
    if choice == "auto":
        return default_coordinates(logpost)
    if choice == "log":
        return None
    if choice == "node_tau":
        return node_time_constants(logpost, air_share=True)
    raise ValueError(f"sampler.coordinates must be 'auto', 'log' or 'node_tau' (got {choice!r})")


def default_coordinates(logpost) -> NodeTimeConstants | None:
    """The sampling coordinates ``hbayes calibrate`` uses: node time constants for
    networks of :data:`MIN_NODES` or more capacity nodes, the log coordinates (None)
    for smaller ones.

    Chosen by measured τ (docs/science/benchmarks.md, "Figures behind the code's
    choices"): on networks of three or more nodes τ fell, while on the two-node models
    it changed nothing beyond the noise of the τ estimate (their node time constants
    are nearly their modes' already), and the log coordinates are kept there. A
    two-node room with a loose envelope node can gain: ``sampler.coordinates:
    node_tau`` in a config chooses them for such rooms (:func:`sampling_coordinates`);
    the default for two-node networks stays until the statistical tests that pin their
    chains have been re-run with it.

    A split solar fraction (thermal_4a's ``fsol``) is sampled as ``log(1 - fsol)``
    (``air_share``): it is tied to the envelope's time constant, ``log(1 - fsol)``
    nearly linear in ``log Cw/(Gw + Gi)``, and the logit stretched its tail towards 0
    (measured: docs/science/benchmarks.md, "The coordinate of fsol"). Only networks
    with such a fraction change.
    """
    if logpost.model.n_states < MIN_NODES:
        return None
    return node_time_constants(logpost, air_share=True)
