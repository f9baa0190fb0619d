"""The result of a chain (:class:`ChainResult`), its compacted checkpoint, and the
burn-in, thinning and mixing check that the sampler's convergence rule applies to it.

Split from :mod:`heritage_bayes.inference.sampler` (which runs the chain and re-exports
:class:`ChainResult` and :func:`compact_checkpoint`).
"""

from __future__ import annotations

from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from heritage_bayes.errors import InputError
from heritage_bayes.inference.backend import write_compact

__all__ = ["ChainResult", "compact_checkpoint"]


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
    cpu_seconds : float
        Process CPU time (user + system) of the same part.
    stopped_by : str
        ``"converged"``, ``"max_steps"`` or ``"max_seconds"`` (the time budget).
    thinned : bool
        ``chain`` holds only the retained draws (read back from a compacted
        checkpoint, :func:`compact_checkpoint`); ``burn``/``thin`` describe the chain
        they came from, ``n_steps`` its length.
    coordinates : str
        What emcee moved in: ``"log"`` (the log-posterior's own coordinates) or the
        ``name`` of the change of variables (``"node_tau"``).
    stride : int
        Steps per row of ``chain`` (a chain longer than ``max_rows`` steps is held
        thinned, see :func:`run_sampler`); ``burn``/``thin`` and ``tau`` are in steps.
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
    cpu_seconds: float = 0.0
    stopped_by: str = ""  # "converged", "max_steps", "max_seconds"
    thinned: bool = False
    n_steps: int | None = None
    coordinates: str = "log"
    stride: int = 1

    @property
    def steps(self) -> int:
        return self.chain.shape[0] if self.n_steps is None else self.n_steps

    @property
    def acceptance(self) -> np.ndarray:
        return self.accepted / max(self.steps, 1)

    def draws(self, max_draws: int | None = None) -> tuple[np.ndarray, np.ndarray]:
        """Post burn-in, thinned samples: (walkers, draws, d) and log-prob (walkers, draws).

        ``max_draws`` caps walkers × draws by thinning further.
        """
        if self.thinned:
            x, lp = self.chain, self.log_prob
        else:
            burn, thin = self.burn // self.stride, max(1, self.thin // self.stride)
            x = self.chain[burn::thin]
            lp = self.log_prob[burn::thin]
        if max_draws is not None and x.shape[0] * x.shape[1] > max_draws:
            keep = max(1, max_draws // x.shape[1])
            step = int(np.ceil(x.shape[0] / keep))
            x, lp = x[-keep * step :: step], lp[-keep * step :: step]
        return np.swapaxes(x, 0, 1), lp.T


def compact_checkpoint(path, tag: str, result: ChainResult, max_draws: int) -> None:
    """Replace the checkpoint of a converged chain by its retained draws.

    Keeps what the run's outputs were built from (``result.draws(max_draws)``, float64)
    and what describes the chain (steps, burn, thin, τ, acceptance), so that
    ``--resume`` on the finished run rebuilds the same outputs without sampling. Why:
    the full chain is many times the size of its retained draws (sizes:
    docs/science/benchmarks.md, "Figures behind the code's choices"), and an
    unconverged chain (the case ``--resume`` is for) is never compacted.
    """
    if not result.converged or result.thinned:
        return
    X, lp = result.draws(max_draws)
    info = {
        "steps": int(result.steps),
        "burn": int(result.burn),
        "thin": int(result.thin),
        "tau": [float(t) for t in result.tau],
        "tau_history": [list(map(float, h)) for h in result.tau_history],
        "accepted": np.asarray(result.accepted, dtype=float).tolist(),
        "max_draws": int(max_draws),
    }
    write_compact(
        Path(path),
        tag,
        np.swapaxes(X, 0, 1),
        lp.T,
        info,
        result.chain,
        result.log_prob,
        row_steps=result.stride,
    )


def _from_compact(path: Path, kept, nwalkers: int, d: int, tau_factor: float) -> ChainResult:
    """The :class:`ChainResult` of a compacted checkpoint, if it meets ``tau_factor``."""
    draws, lp, info = kept
    if draws.shape[1:] != (nwalkers, d):
        raise InputError(
            f"{path}: checkpoint has {draws.shape[1]} walkers × {draws.shape[2]} "
            f"parameters, the run needs {nwalkers} × {d}; run without --resume"
        )
    tau = np.asarray(info["tau"], dtype=float)
    if info["steps"] < tau_factor * np.max(tau):
        raise InputError(
            f"{path}: holds the retained draws of a chain that converged after "
            f"{info['steps']} steps (τmax {np.max(tau):.0f}), fewer than tau_factor "
            f"{tau_factor:g} × τmax; a converged chain is stored without the steps that "
            "extending it would need: run without --resume to sample afresh"
        )
    return ChainResult(
        chain=draws,
        log_prob=lp,
        accepted=np.asarray(info["accepted"], dtype=float),
        tau=tau,
        tau_history=[tuple(h) for h in info["tau_history"]],
        converged=True,
        burn=int(info["burn"]),
        thin=int(info["thin"]),
        resumed_from=int(info["steps"]),
        stopped_by="converged",
        thinned=True,
        n_steps=int(info["steps"]),
    )


def _thinned(chain, x_last=None, lp_last=None) -> dict:
    """The checkpoint's keywords of a thinned chain (a :class:`ChainBuffer` or the
    ``_Saved`` of a loaded checkpoint): stride, steps and the last step; none at
    stride 1."""
    if chain.stride == 1:
        return {}
    last = (x_last, lp_last) if x_last is not None else chain.last
    return {"stride": chain.stride, "steps": chain.steps, "last": last}


def _burn_thin(tau: np.ndarray, steps: int, discard: float = 0.0) -> tuple[int, int]:
    """Burn-in and thinning [steps]: 2 τ (at most half the chain), and at least the part
    of the chain that τ was not estimated on (``discard``); thinning τ_min / 2."""
    tmax = float(np.nanmax(tau)) if np.isfinite(tau).any() else float(steps)
    burn = max(min(int(np.ceil(2 * tmax)), steps // 2), int(discard * steps))
    thin = max(1, int(0.5 * np.nanmin(tau))) if np.isfinite(tau).any() else 1
    return burn, thin


def _mixing_ok(chain, tau, max_rhat, min_ess, max_draws, discard: float = 0.0) -> bool:
    """R-hat and bulk ESS of the retained draws (walkers as chains) meet the targets."""
    from heritage_bayes._arviz import az

    burn, thin = _burn_thin(tau, chain.shape[0], discard)
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
