"""emcee driver: moves, convergence monitoring, HDF5 checkpoint and resume.

The ensemble starts in a small ball around the MAP (in the unconstrained space, so
inside the bounds) and runs in chunks of ``check_every`` steps until converged: the
chain is longer than ``tau_factor`` × the integrated autocorrelation time τ of every
parameter, and τ changed by less than ``tau_rtol`` since the previous check (Foreman-
Mackey et al.'s recipe), or ``max_steps`` is reached.

Default moves: a mix of differential-evolution moves, 80 % ``DEMove`` and 20 %
``DESnookerMove`` (ter Braak & Vrugt 2008). RC-model posteriors are ridge-shaped (ratios
and time constants are well identified, absolute levels much less), with strong linear
correlations in log space; DE proposals are built from differences of walkers and so
adapt to that shape, and the snooker update helps along curved ridges and between
modes. The stretch move is available (``moves: stretch``).

Checkpoint: emcee's own HDF5 backend writes every step (several ms each here, more than
the step itself), so the sampler runs in memory and each chunk is appended to an HDF5
file (``chain.h5``) together with the random-number state; on Ctrl-C or SIGTERM the
steps done so far in the current chunk are written too. ``resume=True`` continues the
same chain exactly (same random stream), losing nothing already sampled; only a hard
kill (SIGKILL) can lose the current chunk.

References
----------
.. [1] D. Foreman-Mackey, D.W. Hogg, D. Lang, J. Goodman, "emcee: The MCMC Hammer",
   PASP 125 (2013) 306. doi:10.1086/670067
.. [2] C.J.F. ter Braak, J.A. Vrugt, "Differential Evolution Markov Chain with snooker
   updater and fewer chains", Stat. Comput. 18 (2008) 435-446.
   doi:10.1007/s11222-008-9104-9
.. [3] J. Goodman, J. Weare, "Ensemble samplers with affine invariance", Commun. Appl.
   Math. Comput. Sci. 5 (2010) 65-80.
"""

from __future__ import annotations

import os
import signal
import time
from dataclasses import dataclass, field
from pathlib import Path

import emcee
import h5py
import numpy as np

from heritage_bayes.errors import InputError

__all__ = ["ChainResult", "make_moves", "run_sampler"]


def make_moves(name: str):
    """emcee moves by name: ``de_snooker`` (default), ``de`` or ``stretch``."""
    if name == "de_snooker":
        return [(emcee.moves.DEMove(), 0.8), (emcee.moves.DESnookerMove(), 0.2)]
    if name == "de":
        return [(emcee.moves.DEMove(), 1.0)]
    if name == "stretch":
        return [(emcee.moves.StretchMove(), 1.0)]
    raise ValueError(f"sampler.moves must be 'de_snooker', 'de' or 'stretch' (got {name!r})")


@dataclass
class ChainResult:
    """The full chain and what convergence monitoring found.

    Attributes
    ----------
    chain : (steps, walkers, d) array
        Unconstrained coordinates.
    log_prob : (steps, walkers) array
    accepted : (walkers,) array
        Accepted proposals per walker.
    tau : (d,) array
        Integrated autocorrelation time per parameter [steps] at the end.
    tau_history : list of (steps, max τ)
    converged : bool
        Chain length ≥ tau_factor × max τ and τ stable.
    burn, thin : int
        Burn-in and thinning derived from τ.
    wall_seconds : float
        Sampling time of this call (resumed runs: only the new part).
    """

    chain: np.ndarray
    log_prob: np.ndarray
    accepted: np.ndarray
    tau: np.ndarray
    tau_history: list = field(default_factory=list)
    converged: bool = False
    burn: int = 0
    thin: int = 1
    wall_seconds: float = 0.0
    resumed_from: int = 0

    @property
    def steps(self) -> int:
        return self.chain.shape[0]

    @property
    def acceptance(self) -> np.ndarray:
        return self.accepted / max(self.steps, 1)

    def draws(self, max_draws: int | None = None) -> tuple[np.ndarray, np.ndarray]:
        """Post burn-in, thinned samples: (walkers, draws, d) and log-prob (walkers, draws).

        ``max_draws`` caps walkers × draws by thinning further.
        """
        x = self.chain[self.burn :: self.thin]
        lp = self.log_prob[self.burn :: self.thin]
        if max_draws is not None and x.shape[0] * x.shape[1] > max_draws:
            keep = max(1, max_draws // x.shape[1])
            step = int(np.ceil(x.shape[0] / keep))
            x, lp = x[-keep * step :: step], lp[-keep * step :: step]
        return np.swapaxes(x, 0, 1), lp.T


def _burn_thin(tau: np.ndarray, steps: int) -> tuple[int, int]:
    tmax = float(np.nanmax(tau)) if np.isfinite(tau).any() else float(steps)
    burn = min(int(np.ceil(2 * tmax)), steps // 2)
    thin = max(1, int(0.5 * np.nanmin(tau))) if np.isfinite(tau).any() else 1
    return burn, thin


def _mixing_ok(chain, tau, max_rhat, min_ess, max_draws) -> bool:
    """R-hat and bulk ESS of the retained draws (walkers as chains) meet the targets."""
    from heritage_bayes._arviz import az

    burn, thin = _burn_thin(tau, chain.shape[0])
    res = ChainResult(
        chain=chain,
        log_prob=np.zeros(chain.shape[:2]),
        accepted=np.zeros(chain.shape[1]),
        tau=tau,
        burn=burn,
        thin=thin,
    )
    X, _ = res.draws(max_draws)
    ds = az.convert_to_dataset({"x": X})
    if max_rhat is not None and float(az.rhat(ds)["x"].max()) > max_rhat:
        return False
    return min_ess is None or float(az.ess(ds, method="bulk")["x"].min()) >= min_ess


def _tau(chain: np.ndarray) -> np.ndarray:
    return emcee.autocorr.integrated_time(chain, c=5, tol=0, quiet=True)


class _Checkpoint:
    """Appends chain chunks and the RNG state to an HDF5 file."""

    def __init__(self, path: Path, tag: str):
        self.path = Path(path)
        self.tag = tag

    def create(self, nwalkers: int, ndim: int) -> None:
        tmp = self.path.with_suffix(".h5.tmp")
        with h5py.File(tmp, "w") as f:
            f.attrs["tag"] = self.tag
            f.attrs["iteration"] = 0
            f.create_dataset(
                "chain",
                (0, nwalkers, ndim),
                maxshape=(None, nwalkers, ndim),
                dtype="f8",
                chunks=(64, nwalkers, ndim),
            )
            f.create_dataset(
                "log_prob",
                (0, nwalkers),
                maxshape=(None, nwalkers),
                dtype="f8",
                chunks=(64, nwalkers),
            )
            f.create_dataset("accepted", data=np.zeros(nwalkers))
        os.replace(tmp, self.path)

    def append(self, chain, log_prob, accepted, random_state, tau_history) -> None:
        with h5py.File(self.path, "a") as f:
            n0 = f["chain"].shape[0]
            n = chain.shape[0]
            f["chain"].resize(n0 + n, axis=0)
            f["log_prob"].resize(n0 + n, axis=0)
            f["chain"][n0:] = chain
            f["log_prob"][n0:] = log_prob
            f["accepted"][...] = accepted
            for k in [k for k in f.attrs if k.startswith("rng_")]:
                del f.attrs[k]
            name, keys, pos, has_gauss, cached = random_state
            f.attrs["rng_name"] = name
            f.attrs["rng_keys"] = keys
            f.attrs["rng_pos"] = pos
            f.attrs["rng_has_gauss"] = has_gauss
            f.attrs["rng_cached"] = cached
            f.attrs["tau_history"] = np.asarray(tau_history, dtype=float).reshape(-1, 2)
            f.attrs["iteration"] = n0 + n

    def load(self):
        with h5py.File(self.path, "r") as f:
            if f.attrs.get("tag") != self.tag:
                raise InputError(
                    f"{self.path}: this checkpoint belongs to a different configuration "
                    "or model; run without --resume (it will be replaced) or restore "
                    "the config it was made with"
                )
            chain = f["chain"][...]
            log_prob = f["log_prob"][...]
            accepted = f["accepted"][...]
            rs = None
            if "rng_name" in f.attrs:
                rs = (
                    str(f.attrs["rng_name"]),
                    np.asarray(f.attrs["rng_keys"]),
                    int(f.attrs["rng_pos"]),
                    int(f.attrs["rng_has_gauss"]),
                    float(f.attrs["rng_cached"]),
                )
            hist = [tuple(r) for r in np.asarray(f.attrs.get("tau_history", []))]
        return chain, log_prob, accepted, rs, hist


class _Interrupt:
    """Turn SIGTERM into KeyboardInterrupt while sampling (so the chunk is saved)."""

    def __enter__(self):
        self._old = None
        try:
            self._old = signal.signal(signal.SIGTERM, self._raise)
        except ValueError:  # not in the main thread
            self._old = None
        return self

    @staticmethod
    def _raise(signum, frame):
        raise KeyboardInterrupt

    def __exit__(self, *exc):
        if self._old is not None:
            signal.signal(signal.SIGTERM, self._old)
        return False


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
    moves: str = "de_snooker",
    max_steps: int = 20000,
    check_every: int = 500,
    tau_factor: float = 50.0,
    tau_rtol: float = 0.05,
    init_ball: float = 1e-3,
    checkpoint: str | Path | None = None,
    tag: str = "",
    resume: bool = False,
    progress=None,
    max_rhat: float | None = 1.01,
    min_ess: float | None = 400.0,
    max_draws: int = 4000,
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
    checkpoint : path, optional
        HDF5 file for the chain; with ``resume=True`` an existing file is continued
        (its ``tag`` must match).
    progress : callable, optional
        Called after every chunk as ``progress(steps_done, max_steps, info_dict)``.
    max_rhat, min_ess : float or None
        Once the chain is long enough for τ, it also runs until the rank-normalised
        R-hat (walkers as chains) is at most ``max_rhat`` and the bulk ESS at least
        ``min_ess`` for every parameter, on the draws kept after burn-in and thinning
        (at most ``max_draws``); None skips that check. Both statistics are invariant
        under the monotone transforms of the sampling space.
    """
    d = int(np.size(x_map))
    if nwalkers is None:
        nwalkers = max(32, 2 * d + 2)
    nwalkers += nwalkers % 2
    if nwalkers < 2 * d:
        raise InputError(
            f"sampler.walkers: need at least 2 × dimensions = {2 * d} (got {nwalkers})"
        )
    sampler = emcee.EnsembleSampler(nwalkers, d, logpost, vectorize=True, moves=make_moves(moves))
    ck = _Checkpoint(Path(checkpoint), tag) if checkpoint is not None else None
    chunks_x: list[np.ndarray] = []
    chunks_lp: list[np.ndarray] = []
    accepted = np.zeros(nwalkers)
    tau_hist: list[tuple[float, float]] = []
    done = 0
    if resume and ck is not None and ck.path.exists():
        chain0, lp0, accepted, rs, tau_hist = ck.load()
        if chain0.shape[1:] != (nwalkers, d):
            raise InputError(
                f"{ck.path}: checkpoint has {chain0.shape[1]} walkers × "
                f"{chain0.shape[2]} parameters, the run needs {nwalkers} × "
                f"{d}; run without --resume"
            )
        if chain0.shape[0] > 0 and rs is not None:
            chunks_x.append(chain0)
            chunks_lp.append(lp0)
            done = chain0.shape[0]
            state = emcee.State(chain0[-1], log_prob=lp0[-1], random_state=rs)
            sampler.random_state = rs
    resumed_from = done
    if done == 0:
        rng = np.random.default_rng(seed)
        p0 = x_map + init_ball * rng.standard_normal((nwalkers, d))
        lp_init = logpost(p0)
        for _ in range(100):  # redraw walkers that start outside the support
            bad = ~np.isfinite(lp_init)
            if not bad.any():
                break
            p0[bad] = x_map + init_ball * rng.standard_normal((int(bad.sum()), d))
            lp_init[bad] = logpost(p0[bad])
        else:
            raise InputError(
                "could not start the walkers: the log-posterior is -inf "
                "around the MAP (check priors and data)"
            )
        sampler.random_state = np.random.RandomState(seed).get_state()
        state = emcee.State(p0, log_prob=lp_init, random_state=sampler.random_state)
        if ck is not None:
            ck.create(nwalkers, d)
    t0 = time.perf_counter()
    converged = False
    tau = np.full(d, np.nan)
    if done > 0:  # resumed: the saved chain may already be long enough
        tau = _tau(np.concatenate(chunks_x))
        tmax = float(np.max(tau))
        stable = bool(tau_hist) and abs(tmax - tau_hist[-1][1]) / tmax < tau_rtol
        converged = bool(done >= tau_factor * tmax and stable and np.all(np.isfinite(tau)))
        if converged and (max_rhat is not None or min_ess is not None):
            converged = _mixing_ok(np.concatenate(chunks_x), tau, max_rhat, min_ess, max_draws)
    with _Interrupt():
        while done < max_steps and not converged:
            # chunk boundaries on absolute multiples of check_every (resume-invariant)
            n = min(check_every - done % check_every, max_steps - done)
            sampler.reset()
            try:
                state = sampler.run_mcmc(state, n, progress=False)
            except KeyboardInterrupt:
                k = sampler.backend.iteration
                if ck is not None and k > 0:
                    ck.append(
                        sampler.get_chain(),
                        sampler.get_log_prob(),
                        accepted + sampler.backend.accepted,
                        sampler.backend.random_state,
                        tau_hist,
                    )
                raise
            x, lp = sampler.get_chain(), sampler.get_log_prob()
            accepted = accepted + sampler.backend.accepted
            chunks_x.append(x)
            chunks_lp.append(lp)
            done += n
            tau = _tau(np.concatenate(chunks_x))
            tmax = float(np.max(tau))
            stable = bool(tau_hist) and abs(tmax - tau_hist[-1][1]) / tmax < tau_rtol
            tau_hist.append((float(done), tmax))
            if ck is not None:
                ck.append(x, lp, accepted, state.random_state, tau_hist)
            converged = done >= tau_factor * tmax and stable and np.all(np.isfinite(tau))
            if converged and (max_rhat is not None or min_ess is not None):
                converged = _mixing_ok(np.concatenate(chunks_x), tau, max_rhat, min_ess, max_draws)
            if progress is not None:
                progress(
                    done,
                    max_steps,
                    {
                        "tau_max": tmax,
                        "needed": tau_factor * tmax,
                        "acceptance": float(np.mean(accepted) / done),
                    },
                )
            if converged:
                break
    chain = np.concatenate(chunks_x)
    log_prob = np.concatenate(chunks_lp)
    burn, thin = _burn_thin(tau, chain.shape[0])
    return ChainResult(
        chain=chain,
        log_prob=log_prob,
        accepted=accepted,
        tau=tau,
        tau_history=tau_hist,
        converged=bool(converged),
        burn=burn,
        thin=thin,
        wall_seconds=time.perf_counter() - t0,
        resumed_from=resumed_from,
    )
