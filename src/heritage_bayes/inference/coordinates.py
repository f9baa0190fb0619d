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

Measured τ per parameter, before and after: ``benchmarks/bench_coordinates.py`` (the
table is in ``benchmarks/README.md``).

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
    """

    name = "node_tau"

    def __init__(self, logpost):
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

    def to_x(self, Y: np.ndarray) -> np.ndarray:
        """Time-constant coordinates (K, d) -> the sampler's log coordinates (K, d)."""
        X = np.array(np.atleast_2d(Y), dtype=float, copy=True)
        for c, gs in self.nodes:  # conductance coordinates are the same in x and y
            X[:, c] = X[:, c] + self._log_conductance_sum(X, gs)
        return X

    def to_y(self, X: np.ndarray) -> np.ndarray:
        """The sampler's log coordinates (K, d) -> time-constant coordinates (K, d)."""
        X = np.atleast_2d(np.asarray(X, dtype=float))
        Y = X.copy()
        for c, gs in self.nodes:
            Y[:, c] = X[:, c] - self._log_conductance_sum(X, gs)
        return Y

    def __call__(self, Y: np.ndarray) -> np.ndarray:
        """(K,) log-posterior at time-constant coordinates (unit Jacobian)."""
        X = self.to_x(Y)
        ok = np.all(np.isfinite(X), axis=1)
        out = np.full(X.shape[0], -np.inf)
        if ok.any():
            out[ok] = self.logpost(X[ok])
        return out


def node_time_constants(logpost) -> NodeTimeConstants | None:
    """:class:`NodeTimeConstants` for a log-posterior, or None when no node's capacity
    is a free log-scale parameter (nothing to re-coordinate)."""
    coords = NodeTimeConstants(logpost)
    return coords if coords.nodes else None


def sampling_coordinates(logpost, choice: str = "auto") -> NodeTimeConstants | None:
    """The coordinates of ``sampler.coordinates``: ``"auto"`` (:func:`default_coordinates`),
    ``"log"`` (None: the log-posterior's own) or ``"node_tau"`` (node time constants
    wherever a capacity is a free log-scale parameter, whatever the network's size).
    """
    if choice == "auto":
        return default_coordinates(logpost)
    if choice == "log":
        return None
    if choice == "node_tau":
        return node_time_constants(logpost)
    raise ValueError(f"sampler.coordinates must be 'auto', 'log' or 'node_tau' (got {choice!r})")


def default_coordinates(logpost) -> NodeTimeConstants | None:
    """The sampling coordinates ``hbayes calibrate`` uses: node time constants for
    networks of :data:`MIN_NODES` or more capacity nodes, the log coordinates (None)
    for smaller ones.

    Chosen by measured τ (``benchmarks/bench_coordinates.py``, 30 000 steps from the
    same MAP and seed): on the demo's data thermal_4a's τ fell for every one of its 16
    parameters (τmax 1 686 → 1 190 steps, min bulk ESS per CPU second × 1.60), while on
    the two-node models it changed nothing beyond the noise of the τ estimate and
    never helped (demo thermal_2c τmax 133 → 149, hygric_2c 47 → 50, ESS per CPU
    second × 1.05 and × 0.87): their node time constants are nearly their modes'
    already, and the log coordinates are kept there. TRH-1's thermal_2c (a loose
    envelope node, 30 000 steps) gained most (τmax 2 889 → 855, ESS per CPU second
    × 6.3): ``sampler.coordinates: node_tau`` in a config chooses them for such rooms
    (:func:`sampling_coordinates`); the default for two-node networks stays until the
    statistical tests that pin their chains have been re-run with it.
    """
    if logpost.model.n_states < MIN_NODES:
        return None
    return node_time_constants(logpost)
