"""emcee driver: moves, convergence monitoring, HDF5 checkpoint and resume.

The ensemble starts in a small ball around the MAP, kept inside the prior's support
whatever the MAP (see :func:`start_ensemble`: a MAP on or next to a bound is moved
inward and the ball reflected off the walls), or drawn from the Laplace approximation
(``start_hessian``, :mod:`heritage_bayes.inference.start`), and runs in chunks of ``check_every``
steps until converged: the chain is longer than ``tau_factor`` × the integrated
autocorrelation time τ of every parameter, and τ changed by less than ``tau_rtol``
since the previous check (Foreman-Mackey et al.'s recipe), and R-hat/bulk ESS meet
their targets; or the wall-time budget ``max_seconds`` or ``max_steps`` runs out
(run length comes from the chain: the step cap is a safety net, the time budget is
what a user sets).

Default moves: a mix of differential-evolution moves, 80 % ``DEMove`` and 20 %
``DESnookerMove`` (ter Braak & Vrugt 2008). RC-model posteriors are ridge-shaped (ratios
and time constants are well identified, absolute levels much less), with strong linear
correlations in log space; DE proposals are built from differences of walkers and so
adapt to that shape, and the snooker update helps along curved ridges and between
modes. The stretch move is available (``moves: stretch``), and ``de_global`` adds
global proposals to the DE part: a walker in ten proposes an independent draw from a
Student-t refitted to the chain at each convergence check
(:mod:`heritage_bayes.inference.moves`; not the default: measured in
docs/science/benchmarks.md). Where the Laplace check flags parameters the data leave to
their priors, a block move (``block``, ``block_weight``;
:class:`heritage_bayes.inference.moves.BlockDEMove`) takes a share of the steps and
moves those parameters alone; ``hbayes calibrate`` uses it for networks of three or
more nodes.

Checkpoint: emcee's own HDF5 backend writes every step (several ms each here, more than
the step itself), so the sampler runs in memory and each chunk is appended to an HDF5
file (``chain.h5``) together with the random-number state, committed by one attribute
written last (crash-consistent, see :class:`_Checkpoint`); Ctrl-C or SIGTERM stops the
chain after the current step and commits the steps done so far. ``resume=True``
continues the same chain exactly (same random stream), losing nothing already sampled;
only a hard kill (SIGKILL) can lose the current chunk, and a damaged file is detected
(checksums) and cut back to its valid steps.

References
----------
.. [1] D. Foreman-Mackey, D.W. Hogg, D. Lang, J. Goodman, "emcee: The MCMC Hammer",
   PASP 125 (2013) 306. doi:10.1086/670067
.. [2] C.J.F. ter Braak, J.A. Vrugt, "Differential Evolution Markov Chain with snooker
   updater and fewer chains", Stat. Comput. 18 (2008) 435-446.
   doi:10.1007/s11222-008-9104-9
.. [3] J. Goodman, J. Weare, "Ensemble samplers with affine invariance", Commun. Appl.
   Math. Comput. Sci. 5 (2010) 65-80.
.. [4] A. Gelman, J.B. Carlin, H.S. Stern, D.B. Dunson, A. Vehtari, D.B. Rubin,
   *Bayesian Data Analysis*, 3rd ed., CRC Press (2013), section 11.4 (discarding the
   first half of each chain as warm-up).
"""

from __future__ import annotations

import os
import time
from dataclasses import dataclass, field
from pathlib import Path

import emcee
import numpy as np

from heritage_bayes.errors import InputError
from heritage_bayes.inference.backend import _Checkpoint, read_compact
from heritage_bayes.inference.chainresult import (
    ChainResult,
    _burn_thin,
    _from_compact,
    _mixing_ok,
    _thinned,
    compact_checkpoint,
)
from heritage_bayes.inference.monitor import (
    ChainBuffer,
    _last_check,
    _next_check,
    _tau,
    make_moves,
)
from heritage_bayes.inference.moves import refit_moves
from heritage_bayes.inference.scale import with_scale_redraw
from heritage_bayes.inference.start import laplace_ensemble
from heritage_bayes.names import DEFAULT_MOVE
from heritage_bayes.rundir.signals import DeferSignals

__all__ = [
    "ChainResult",
    "compact_checkpoint",
    "make_moves",
    "run_sampler",
    "start_ensemble",
]


def start_ensemble(
    logpost,
    x_map: np.ndarray,
    nwalkers: int,
    rng: np.random.Generator,
    *,
    init_ball: float = 1e-3,
    bounds: tuple[np.ndarray, np.ndarray] | None = None,
    margin: float = 0.01,
) -> tuple[np.ndarray, np.ndarray]:
    """Initial walkers inside the support, around the MAP, whatever the MAP.

    The centre is the MAP moved at least ``margin`` × the width of each bounded
    coordinate away from its bounds (a MAP on a bound is a finding about prior or
    model, reported elsewhere, not a reason to fail); the walkers are the centre plus
    ``init_ball`` × (the width, or 1 for unbounded coordinates) × standard normal
    draws, reflected off the bounds into the interior. Walkers whose log-posterior
    is still -inf (a wall the bounds do not describe, e.g. an unstable network) are
    redrawn with a ball twice as wide each round.

    Parameters
    ----------
    logpost : callable
        Vectorised log-posterior on (K, d).
    x_map : (d,) array
    nwalkers : int
    rng : numpy Generator
    init_ball : float
        Relative size of the ball.
    bounds : (lo, hi) arrays of shape (d,), optional
        The support in sampler coordinates (±inf where unbounded).
    margin : float
        Smallest distance of the centre from a bound, relative to the width.

    Returns
    -------
    p0 : (nwalkers, d) array
    lp0 : (nwalkers,) array, all finite

    Raises
    ------
    InputError
        No finite log-posterior anywhere near the (moved) MAP: the data or the
        likelihood, not the start, are at fault (e.g. NaN in a column).
    """
    x_map = np.asarray(x_map, dtype=float)
    d = x_map.size
    lo, hi = _support(bounds, d)
    width = hi - lo
    finite = np.isfinite(width)
    scale = np.where(finite, width, 1.0)
    pad = np.where(finite, margin * width, 0.0)
    centre = np.clip(x_map, lo + pad, hi - pad)

    def draw(k: int, ball: float) -> np.ndarray:
        p = centre + ball * scale * rng.standard_normal((k, d))
        # reflect off the walls (a ball wider than the box folds back inside)
        for _ in range(4):
            p = np.where(p < lo, 2 * lo - p, p)
            p = np.where(p > hi, 2 * hi - p, p)
        return np.clip(p, lo, hi)

    ball = init_ball
    p0 = draw(nwalkers, ball)
    lp0 = np.asarray(logpost(p0), dtype=float)
    for _ in range(30):
        bad = ~np.isfinite(lp0)
        if not bad.any():
            return p0, lp0
        ball = min(2 * ball, 0.25)
        p0[bad] = draw(int(bad.sum()), ball)
        lp0[bad] = logpost(p0[bad])
    raise InputError(
        "could not start the walkers: the log-posterior is -inf everywhere tried around "
        f"the MAP, inside the prior bounds (balls up to {ball:g} × the prior ranges); "
        "the likelihood cannot be evaluated there: check the data (non-finite values) "
        "and the noise model"
    )


def _support(bounds, d: int) -> tuple[np.ndarray, np.ndarray]:
    """(lo, hi) of the support, ±inf arrays when ``bounds`` is None."""
    if bounds is None:
        return np.full(d, -np.inf), np.full(d, np.inf)
    return tuple(np.asarray(b, dtype=float) for b in bounds)


def _tell(notice, msg: str) -> None:
    if notice is not None:
        notice(msg)


def run_sampler(logpost, x_map, **kwargs) -> ChainResult:
    """Sample the posterior with emcee until converged: see :func:`_run_sampler` for
    the parameters. BLAS runs single-threaded meanwhile (many small products)."""
    from threadpoolctl import threadpool_limits

    with threadpool_limits(limits=1, user_api="blas"):
        return _run_sampler(logpost, x_map, **kwargs)


def _run_sampler(
    logpost,
    x_map: np.ndarray,
    *,
    seed: int,
    nwalkers: int | None = None,
    moves: str = DEFAULT_MOVE,
    block=(),
    block_weight: float = 0.0,
    max_steps: int = 200_000,
    max_seconds: float | None = None,
    bounds: tuple[np.ndarray, np.ndarray] | None = None,
    check_every: int = 500,
    tau_factor: float = 50.0,
    tau_rtol: float = 0.05,
    tau_discard: float = 0.0,
    init_ball: float = 1e-3,
    checkpoint: str | Path | None = None,
    tag: str = "",
    resume: bool = False,
    progress=None,
    notice=None,
    max_rhat: float | None = 1.01,
    min_ess: float | None = 400.0,
    max_draws: int = 4000,
    coordinates=None,
    compact: bool = False,
    start_hessian: np.ndarray | None = None,
    max_rows: int | None = None,
) -> ChainResult:
    """Sample the posterior with emcee until converged (see module docstring).

    Parameters
    ----------
    logpost : callable
        Vectorised log-posterior on (K, d) unconstrained arrays.
    x_map : (d,) array
        Start (the MAP) in unconstrained coordinates.
    seed : int
        Seeds the initial ball and emcee's random stream: same seed, same chain.
    nwalkers : int, optional
        Default ``max(32, 2 d + 2)`` (even).
    block : sequence of int
        Coordinates (indices) that a :class:`~heritage_bayes.inference.moves.BlockDEMove`
        moves on their own in a share ``block_weight`` of the steps (see
        :func:`heritage_bayes.inference.monitor.make_moves`); ``hbayes calibrate`` passes
        the parameters the Laplace check flags as practically not identified. Empty (or
        ``block_weight`` 0): the named ``moves`` alone.
    max_steps : int
        Safety cap on the chain length [steps].
    max_seconds : float, optional
        Wall-time budget of this call [s]: no chunk starts after it is spent (the
        chain is then returned unconverged, ``stopped_by="max_seconds"``).
    bounds : (lo, hi) arrays, optional
        Support in sampler coordinates, for the start (see :func:`start_ensemble`).
    checkpoint : path, optional
        HDF5 file for the chain; with ``resume=True`` an existing file is continued
        (its ``tag`` must match).
    progress : callable, optional
        Called after every chunk as ``progress(steps_done, total, info_dict)``, ``total``
        the current estimate of the chain length needed (τ × ``tau_factor``, at most
        ``max_steps``); ``info_dict`` also holds ``seconds`` (wall time so far).
    notice : callable, optional
        Called with a message when a resume does not go as asked (no checkpoint, a
        damaged one: see :class:`_Checkpoint`).
    tau_discard : float
        Fraction of the chain left out of the estimate of τ, in [0, 1) (0: the whole
        chain, the default); the retained draws then come from the part τ was estimated
        on (burn-in at least that fraction). Leaving out the first half is the classical
        burn-in of Gelman et al. [4]_ and removes the walkers' spread from their start
        ball from the estimate; it is not the default because it can underestimate τ
        while a slow direction is still being explored (measured:
        docs/science/benchmarks.md, "Sampler moves, ensemble size and the estimate of
        τ").
    max_rhat, min_ess : float or None
        Once the chain is long enough for τ, it also runs until the rank-normalised
        R-hat (walkers as chains) is at most ``max_rhat`` and the bulk ESS at least
        ``min_ess`` for every parameter, on the draws kept after burn-in and thinning
        (at most ``max_draws``); None skips that check. Both statistics are invariant
        under the monotone transforms of the sampling space.
    start_hessian : (d, d) array, optional
        Hessian of the negative log-posterior at ``x_map``: the walkers start from the
        Laplace approximation N(x_map, H⁻¹) (:func:`heritage_bayes.inference.start.
        laplace_ensemble`) instead of the ``init_ball`` around it (the fallback when
        that start finds no finite log-posterior).
    max_rows : int, optional
        Bound on the steps held in memory and in the checkpoint (None: every step).
        Past it, at a convergence check, the chain is thinned in place: every other
        stored step is dropped and the stride (steps per row) doubles
        (:class:`heritage_bayes.inference.monitor.ChainBuffer`); τ is then estimated
        on the thinned chain and scaled by the stride, exact enough while the stride
        is well below τ, so the stride never exceeds τmax/10 (τmax of the previous
        check; the chain grows past ``max_rows`` rather than break that). The chain
        itself (emcee's steps and random stream) does not change, only which of its
        steps are kept; ``resume=True`` rebuilds the same rows. A chain shorter than
        ``max_rows`` steps is held and decided exactly as without the bound.
    """
    nwalkers, d = _walkers(x_map, nwalkers, max_rows, tau_discard)
    target = logpost if coordinates is None else coordinates
    move_list = with_scale_redraw(make_moves(moves, block, block_weight), coordinates)
    c = _Chain(
        emcee.EnsembleSampler(nwalkers, d, target, vectorize=True, moves=move_list),
        move_list,
        ChainBuffer(nwalkers, d),
        _Checkpoint(Path(checkpoint), tag) if checkpoint is not None else None,
        coordinates,
        nwalkers,
        d,
        np.zeros(nwalkers),
    )
    kept = read_compact(c.ck.path, tag) if resume and c.ck is not None else None
    if kept is not None:  # a converged chain, compacted: its draws are the result
        return _from_compact(c.ck.path, kept, nwalkers, d, tau_factor)
    if resume and c.ck is not None:
        _resume(c, seed, notice)
    resumed_from = c.done
    if c.done == 0:
        _start(c, logpost, target, x_map, seed, start_hessian, bounds, init_ball)
    t0 = time.perf_counter()
    c0 = time.process_time()
    out_of_time = False
    converged = False
    tau = np.full(d, np.nan)
    rule = _Rule(tau_factor, tau_rtol, tau_discard, max_rhat, min_ess, max_draws)
    if c.done > 0:  # resumed: the saved chain may already be long enough, decided as
        # the chain decided then (τ's stability against the check before this one)
        tau, _, converged = rule.decide(c.buf, [h for h in c.tau_hist if h[0] < c.done], c.done)
    # SIGINT/SIGTERM only set a flag while sampling: the chain stops after the current
    # step, the steps done are committed, then KeyboardInterrupt (never an exception
    # inside emcee's likelihood call, which would print the parameter matrix)
    with DeferSignals(redeliver=False) as sig:
        while c.done < max_steps and not converged:
            # the budget is checked between chunks (at least one chunk runs)
            spent = time.perf_counter() - t0
            if max_seconds is not None and c.done > resumed_from and spent >= max_seconds:
                out_of_time = True
                break
            # chunk boundaries at fixed step counts (resume-invariant)
            n = min(_next_check(c.done, check_every) - c.done, max_steps - c.done)
            x, lp, rows = _chunk(c, n, check_every, sig)
            halved = _bound_rows(c.buf, max_rows, c.tau_hist)
            tau, tmax, converged = rule.decide(c.buf, c.tau_hist, c.done)
            c.tau_hist.append((float(c.done), tmax))
            if c.ck is not None:
                _save_chunk(c, x, lp, rows, halved)
            del x, lp, rows
            if progress is not None:
                progress(
                    c.done,
                    int(min(max_steps, max(c.done, tau_factor * tmax))),
                    {
                        "seconds": time.perf_counter() - t0,
                        "tau_max": tmax,
                        "needed": tau_factor * tmax,
                        "acceptance": float(np.mean(c.accepted) / c.done),
                    },
                )
            if converged:
                break
    buf = c.buf
    burn, thin = _burn_thin(tau / buf.stride, buf.chain.shape[0], tau_discard)
    result = ChainResult(
        chain=buf.chain,
        log_prob=buf.log_prob,
        accepted=c.accepted,
        tau=tau,
        tau_history=c.tau_hist,
        converged=bool(converged),
        burn=burn * buf.stride,
        thin=thin * buf.stride,
        wall_seconds=time.perf_counter() - t0,
        resumed_from=resumed_from,
        cpu_seconds=time.process_time() - c0,
        stopped_by="converged" if converged else "max_seconds" if out_of_time else "max_steps",
        coordinates="log" if coordinates is None else getattr(coordinates, "name", "custom"),
        n_steps=buf.steps if buf.stride > 1 else None,
        stride=buf.stride,
    )
    if compact and c.ck is not None:
        compact_checkpoint(c.ck.path, tag, result, max_draws)
    return result


def _walkers(x_map, nwalkers: int | None, max_rows: int | None, tau_discard: float):
    """(walkers, dimensions) of a chain, its settings checked (see :func:`_run_sampler`)."""
    if max_rows is not None and max_rows < 2:
        raise InputError(f"sampler.max_stored_steps: expected at least 2 (got {max_rows})")
    d = int(np.size(x_map))
    if not 0.0 <= tau_discard < 1.0:
        raise InputError(f"sampler.tau_discard: expected a fraction in [0, 1) (got {tau_discard})")
    if nwalkers is None:
        nwalkers = max(32, 2 * d + 2)
    nwalkers += nwalkers % 2
    if nwalkers < 2 * d:
        raise InputError(
            f"sampler.walkers: need at least 2 × dimensions = {2 * d} (got {nwalkers})"
        )
    return nwalkers, d


@dataclass
class _Chain:
    """One sampling call's state: emcee's sampler and moves, the rows kept, their
    checkpoint, the acceptance counts, τ's history, the steps done and emcee's state."""

    sampler: emcee.EnsembleSampler
    moves: list
    buf: ChainBuffer
    ck: _Checkpoint | None
    coordinates: object
    nwalkers: int
    d: int
    accepted: np.ndarray
    tau_hist: list = field(default_factory=list)
    done: int = 0
    state: emcee.State | None = None

    def to_x(self, a: np.ndarray) -> np.ndarray:
        """(..., d) in emcee's coordinates -> the log-posterior's."""
        if self.coordinates is None:
            return a
        return self.coordinates.to_x(a.reshape(-1, self.d)).reshape(a.shape)

    def to_y(self, a: np.ndarray) -> np.ndarray:
        return a if self.coordinates is None else self.coordinates.to_y(a)

    def internal(self, y_last: np.ndarray) -> dict:
        """The last step in emcee's coordinates for the checkpoint (a resume starts
        there; the stored positions' round trip is exact only to rounding)."""
        return {} if self.coordinates is None else {"internal": np.array(y_last, dtype=float)}


@dataclass(frozen=True)
class _Rule:
    """The stopping rule: ``tau_factor`` τ with τ stable to ``tau_rtol``, then R-hat and
    bulk ESS within ``max_rhat`` and ``min_ess`` (see :func:`_run_sampler`)."""

    tau_factor: float
    tau_rtol: float
    tau_discard: float
    max_rhat: float | None
    min_ess: float | None
    max_draws: int

    def decide(self, buf: ChainBuffer, tau_hist: list, done: int):
        """(τ per parameter [steps], τmax, converged) of the rows in ``buf`` after
        ``done`` steps, τ's earlier estimates in ``tau_hist``."""
        tau = _tau(buf.chain, self.tau_discard) * buf.stride
        tmax = float(np.max(tau))
        stable = bool(tau_hist) and abs(tmax - tau_hist[-1][1]) / tmax < self.tau_rtol
        converged = bool(done >= self.tau_factor * tmax and stable and np.all(np.isfinite(tau)))
        if converged and (self.max_rhat is not None or self.min_ess is not None):
            converged = _mixing_ok(
                buf.chain,
                tau / buf.stride,
                self.max_rhat,
                self.min_ess,
                self.max_draws,
                self.tau_discard,
            )
        return tau, tmax, converged


def _resume(c: _Chain, seed: int, notice) -> None:
    """Continue the chain saved in ``c.ck`` (a damaged file rewritten from its valid
    steps), or say why a new chain starts."""
    ck, nwalkers, d = c.ck, c.nwalkers, c.d
    if not ck.path.exists():
        _tell(notice, f"--resume: no checkpoint {ck.path}; starting a new chain")
        return
    saved = ck.load()
    if saved.chain.shape[1:] != (nwalkers, d):
        raise InputError(
            f"{ck.path}: checkpoint has {saved.chain.shape[1]} walkers × "
            f"{saved.chain.shape[2]} parameters, the run needs {nwalkers} × "
            f"{d}; run without --resume"
        )
    if saved.problem is not None:
        _tell(notice, f"{ck.path}: {saved.problem}")
    done = saved.chain.shape[0] if saved.steps is None else saved.steps
    if done == 0:
        _tell(notice, f"--resume: {ck.path} holds no steps yet; starting a new chain")
        return
    rs = saved.random_state
    if rs is None:  # continue the kept steps with a stream of their own
        rs = np.random.RandomState([seed, done]).get_state()
        _tell(
            notice,
            f"{ck.path}: no random-number state for step {done}; continuing "
            "with a new random stream (seeded by the seed and the step count): "
            "a valid chain, but not bit-identical to an uninterrupted run",
        )
    c.done = done
    c.accepted = saved.accepted
    c.tau_hist = [h for h in saved.tau_history if h[0] <= done]
    if saved.problem is not None:  # keep the damaged file, write a clean one
        kept = ck.path.with_name(ck.path.name + ".damaged")
        os.replace(ck.path, kept)
        ck.create(nwalkers, d)
        ck.append(saved.chain, saved.log_prob, c.accepted, rs, c.tau_hist, **_thinned(saved))
        _tell(
            notice,
            f"{ck.path}: rewritten from the valid steps; the damaged file is kept as {kept}",
        )
    c.buf = ChainBuffer(nwalkers, d, stride=saved.stride)
    c.buf.load(saved.chain, saved.log_prob, done)
    x_last, lp_last = saved.last or (c.buf.chain[-1], c.buf.log_prob[-1])
    y_last = saved.internal if saved.internal is not None else c.to_y(x_last)
    del saved
    c.state = emcee.State(y_last, log_prob=lp_last, random_state=rs)
    c.sampler.random_state = rs


def _start(c: _Chain, logpost, target, x_map, seed, start_hessian, bounds, init_ball) -> None:
    """A new chain: the walkers' start (the Laplace approximation at the MAP, else a
    ball around it), emcee's random stream seeded, the checkpoint created."""
    rng = np.random.default_rng(seed)
    got = None
    if start_hessian is not None:
        got = laplace_ensemble(
            logpost, x_map, start_hessian, c.nwalkers, rng, bounds=_support(bounds, c.d)
        )
    p0, lp_init = got or start_ensemble(
        logpost, x_map, c.nwalkers, rng, init_ball=init_ball, bounds=bounds
    )
    y0 = c.to_y(p0)
    if hasattr(c.coordinates, "spread"):  # a coordinate drawn exactly (the scale line)
        y0 = c.coordinates.spread(y0, rng)
    if c.coordinates is not None:  # the density emcee compares: in its own coordinates
        lp_init = np.asarray(target(y0), dtype=float)
    c.sampler.random_state = np.random.RandomState(seed).get_state()
    c.state = emcee.State(y0, log_prob=lp_init, random_state=c.sampler.random_state)
    if c.ck is not None:
        c.ck.create(c.nwalkers, c.d)


def _chunk(c: _Chain, n: int, check_every: int, sig):
    """``n`` steps of emcee from ``c.state``, appended to ``c.buf``: (their positions
    (n, walkers, d), log-posteriors (n, walkers), the rows kept). On SIGINT/SIGTERM
    (``sig``) the steps done are checkpointed, then KeyboardInterrupt."""
    sampler = c.sampler
    # global proposals: refitted to the rows up to the last check (the same rows after a
    # resume mid-chunk)
    last = _last_check(c.done, check_every)
    refit_moves(c.moves, c.buf.chain[: last // c.buf.stride], c.to_y)
    sampler.reset()
    try:
        for step in sampler.sample(c.state, iterations=n):  # noqa: B007
            if sig.received is not None:
                raise KeyboardInterrupt
        c.state = step
    except KeyboardInterrupt:
        if c.ck is not None and sampler.backend.iteration > 0:
            x, lp = c.to_x(sampler.get_chain()), sampler.get_log_prob()
            rows = c.buf.append(x, lp)
            c.ck.append(
                *rows,
                c.accepted + sampler.backend.accepted,
                sampler.backend.random_state,
                c.tau_hist,
                **_thinned(c.buf, x[-1], lp[-1]),
                **c.internal(sampler.get_chain()[-1]),
            )
        raise KeyboardInterrupt from None
    x, lp = c.to_x(sampler.get_chain()), sampler.get_log_prob()
    c.accepted = c.accepted + sampler.backend.accepted
    rows = c.buf.append(x, lp)
    c.done += n
    return x, lp, rows


def _bound_rows(buf: ChainBuffer, max_rows: int | None, tau_hist: list) -> bool:
    """Thin ``buf`` in place while it holds over ``max_rows`` rows and the stride stays
    at most τmax/10 (of the last check); True if it was thinned."""
    halved = False
    while (
        max_rows is not None
        and buf.n > max_rows
        and tau_hist
        and 2 * buf.stride <= tau_hist[-1][1] / 10
    ):
        buf.halve()
        halved = True
    return halved


def _save_chunk(c: _Chain, x, lp, rows, halved: bool) -> None:
    """Checkpoint a chunk: its rows appended, or the whole buffer rewritten once thinned."""
    thinned = _thinned(c.buf, x[-1], lp[-1]) | c.internal(c.state.coords)
    rs = c.state.random_state
    if halved:
        c.ck.rewrite(c.buf.chain, c.buf.log_prob, c.accepted, rs, c.tau_hist, **thinned)
    else:
        c.ck.append(*rows, c.accepted, rs, c.tau_hist, **thinned)
