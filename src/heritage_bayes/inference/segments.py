"""A record split at input gaps: one likelihood over segments, each with its own start.

An input gap longer than ``data.max_gap`` (a weather station or a logger's sensor down
for a day and a half) leaves steps that the simulation cannot take from measured
inputs. Rather than bridging it with invented weather, the record is split there into
segments (:func:`segments_of`): the simulation stops before the gap and starts again
after it, from an initial state of its own, estimated from the data of that segment
and integrated out exactly as for a single record (:mod:`heritage_bayes.inference.posterior`).
The segments share the parameters, so the log-likelihood is the sum of the segments'
log-likelihoods,

.. math::

    \\log p(y\\mid\\theta) = \\sum_s \\log p(y_s\\mid\\theta),

each :math:`\\log p(y_s\\mid\\theta)` the marginal over that segment's initial state
(its prior mean the steady state of the segment's own first ``init_window`` inputs, its
damping horizon the segment's length). This is the exact likelihood of the
observations given the parameters when the states after a gap are unknown a priori:
the segments are independent given :math:`\\theta`. Segments shorter than
:data:`MIN_SEGMENT_HOURS` (after a warm-up) are dropped: a start estimated from a day
of data is nearly all the fit there is.

Simulation over a whole frame (:meth:`SegmentedLogPosterior.simulate_frame`): each
calibration segment from its own estimated start; no value inside a gap (NaN). The
validation period, which has no data to estimate a start from, continues from the
state the simulation carries across its gaps (on the interpolated inputs), as across
the short gaps that are bridged; only the values inside the gap are withheld. A
validation inside the calibration period is held out of the fit (its observations
missing) and simulated likewise, from the segment before it or, after a gap inside it,
from the next segment's start, which its later calibration data estimate.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from heritage_bayes.inference.posterior import LogPosterior

__all__ = ["MIN_SEGMENT_HOURS", "SegmentedLogPosterior", "calibration_segments", "segments_of"]

#: Shortest calibration segment kept [h] (after its warm-up): two days, the least
#: observed time of a calibration period.
MIN_SEGMENT_HOURS = 48.0


def segments_of(breaks: np.ndarray, min_rows: int) -> tuple[list, list]:
    """Runs of rows without a break: ``(kept, dropped)``, lists of ``(a, b)`` row ranges
    ``[a, b)``; a run shorter than ``min_rows`` is dropped."""
    ok = ~np.asarray(breaks, dtype=bool)
    edges = np.diff(np.concatenate([[0], ok.astype(np.int8), [0]]))
    runs = list(zip(np.flatnonzero(edges == 1), np.flatnonzero(edges == -1), strict=True))
    kept = [(int(a), int(b)) for a, b in runs if b - a >= min_rows]
    dropped = [(int(a), int(b)) for a, b in runs if b - a < min_rows]
    return kept, dropped


def calibration_segments(prep) -> tuple[list, list]:
    """``(kept, dropped)`` row ranges ``[a, b)`` of a prepared calibration period
    (relative to its first row) between input gaps (``prep.breaks``); kept: at least the
    warm-up plus :data:`MIN_SEGMENT_HOURS`."""
    cal = prep.calibration
    n = cal.stop - cal.start
    br = np.zeros(n, dtype=bool) if prep.breaks is None else prep.breaks[cal]
    return segments_of(br, prep.warmup_steps + math.ceil(MIN_SEGMENT_HOURS * 3600.0 / prep.dt))


@dataclass
class SegmentedLogPosterior(LogPosterior):
    """:class:`LogPosterior` over the segments of a record (see the module docstring).

    Parameters (beyond those of :class:`LogPosterior`, whose ``inputs`` and
    ``observed`` cover the whole calibration period)
    ----------------------------------------------------------------------------------
    segments : sequence of (a, b)
        Row ranges ``[a, b)`` of ``inputs`` that are fitted, each with its own initial
        state and its own warm-up; rows outside them are not fitted.
    frame_breaks : (N_frame,) bool array, optional
        Rows of the whole frame inside an input gap: NaN in :meth:`simulate_frame`.
    held_out : slice, optional
        Rows of ``inputs`` of a validation inside the calibration period (its
        observations NaN in ``observed``): simulated by :meth:`simulate_frame` as the
        validation after a calibration is, outside an input gap, even where no segment
        holds them.
    """

    segments: tuple = ()
    frame_breaks: np.ndarray | None = None
    held_out: slice | None = None

    def __post_init__(self):
        self.inputs = np.ascontiguousarray(self.inputs, dtype=float)
        obs = np.array(self.observed, dtype=float, copy=True)
        if obs.ndim == 1:
            obs = obs[:, None]
        fitted = np.zeros(obs.shape[0], dtype=bool)
        segs = []
        for a, b in self.segments:
            if b - a > self.warmup and np.isfinite(obs[a + self.warmup : b]).any():
                segs.append((int(a), int(b)))
                fitted[a + self.warmup : b] = True
        if not segs:
            raise ValueError(
                "no part of the calibration period between input gaps longer than "
                f"data.max_gap is long enough (the warm-up plus {MIN_SEGMENT_HOURS:g} h) and "
                "holds observations: choose a calibration period with fewer gaps, or raise "
                "data.max_gap to bridge them by interpolation"
            )
        self.segments = tuple(segs)
        self.parts = [
            LogPosterior(
                self.model,
                self.params,
                self.noise,
                self.inputs[a:b],
                obs[a:b],
                dt=self.dt,
                warmup=self.warmup,
                init_window=self.init_window,
                initial_state=self.initial_state,
                initial_state_sd=self.initial_state_sd,
                initial_state_horizon=self.initial_state_horizon,
                time_constant_cap=self.time_constant_cap,
                temperature=self.temperature,
            )
            for a, b in segs
        ]
        obs[~fitted] = np.nan
        self.observed = obs
        first = self.parts[0]
        self.n_model = first.n_model
        self.u_init = first.u_init
        self.x0_fixed, self.x0_free = first.x0_fixed, first.x0_free
        self._time_varying = first._time_varying
        self.initial_state_sd = first.initial_state_sd
        # reported: the longest segment's (each segment damps with its own length)
        self.initial_state_horizon = max(p.initial_state_horizon for p in self.parts)

    def _loglik(self, theta: np.ndarray) -> np.ndarray:
        """(K,) sum of the segments' log-likelihoods; -inf where any is."""
        return np.sum([p._loglik(theta) for p in self.parts], axis=0)

    def initial_states(self, theta, rng=None):
        """(K, n) initial states of the first segment (see :class:`LogPosterior`)."""
        return self.parts[0].initial_states(theta, rng)

    def pointwise_log_likelihood(self, theta: np.ndarray) -> np.ndarray:
        """(K, N, n_out) log-likelihood terms, NaN outside the segments."""
        theta = np.atleast_2d(theta)
        out = np.full((theta.shape[0], *self.observed.shape), np.nan)
        for (a, b), p in zip(self.segments, self.parts, strict=True):
            out[:, a:b] = p.pointwise_log_likelihood(theta)
        return out

    def simulate_frame(self, theta, inputs, start=0, rng=None, x0=None):
        """Noise-free outputs (K, N, n_out) over a frame whose row ``start`` is the first
        calibration row: each segment from its own initial state (``x0`` overrides the
        first one's), NaN in the calibration rows outside the segments and in the
        frame's break rows (``frame_breaks``)."""
        theta = np.atleast_2d(np.asarray(theta, dtype=float))
        tm = theta[:, : self.n_model]
        U = np.ascontiguousarray(inputs, dtype=float)
        a0 = self.segments[0][0]
        Y, valid = self.parts[0].simulate_frame(theta, U, start + a0, rng, x0)
        Y = np.array(Y, dtype=float)
        for i, ((a, _), p) in enumerate(zip(self.segments, self.parts, strict=True)):
            if i == 0:
                continue
            stop = start + self.segments[i + 1][0] if i + 1 < len(self.segments) else U.shape[0]
            Ui = U[start + a : stop]
            xi = p.initial_states(theta, rng)
            if xi is None:  # controlled: its own start from the mean inputs
                u0 = Ui[: max(1, self.init_window)].mean(axis=0)
                Yi, vi = self.model.forward(tm, Ui, self.dt, u_init=u0)
            else:
                Yi, vi = self.model.forward(tm, Ui, self.dt, x0=xi)
            Y[:, start + a : stop] = Yi
            valid = valid & vi
        outside = np.ones(self.inputs.shape[0], dtype=bool)
        for a, b in self.segments:
            outside[a:b] = False
        if self.held_out is not None:
            outside[self.held_out] = False
        rows = np.zeros(U.shape[0], dtype=bool)
        rows[start : start + outside.size] = outside
        if self.frame_breaks is not None and self.frame_breaks.size == U.shape[0]:
            rows |= self.frame_breaks
        Y[:, rows] = np.nan
        return Y, valid
