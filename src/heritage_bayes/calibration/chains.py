"""The sections' chains in one time budget: the sampler's call, the continuation of a
chain the budget stopped, and the draws the sections share.

``hbayes calibrate`` samples its sections (thermal, then hygric) one after another inside
one wall-time budget, ``sampler.max_time``: each section gets an equal share of what is
left (:func:`heritage_bayes.inference.optimize.share_deadline`). A section sampled early
whose chain runs out of its share (``stopped_by == "max_seconds"``) while a later one
finishes before its own would leave budget unused and the run unconverged. So, once
every section has sampled, :func:`continue_chains` continues each chain the budget
stopped with the time left before the run's end (all of it for one such chain, equal
shares of it for several), until it converges, reaches ``sampler.max_steps`` or the
budget is spent. The continuation is the same chain: it resumes from the section's
checkpoint (:func:`heritage_bayes.inference.sampler.run_sampler` with ``resume=True``:
the same random stream and convergence checks at the same step counts), so it gives
the steps one uninterrupted chain given more time would have given; a run without
budget pressure never continues anything and is unchanged. The time a ``model: auto``
screen took is spent before any section samples (the shares are of what it left); the
model-order ladder (``ladder: true``) runs after the continuation and gets what it
leaves. ``--resume`` of a run interrupted during a continuation resumes that chain in
its section's own turn, from the steps its checkpoint holds.

What the run records of it: ``summary.json``'s ``models.<section>.chain.continued``
(the steps the chain had, the seconds it was given and the sections that left them;
present only for a continued chain), the chain's final ``steps`` and ``stopped_by``,
its ``cpu_seconds`` over both parts, ``timings``' ``<section>_continuation_seconds``
and ``<section>_continuation_cpu_seconds``; the console and the report say it in words
(:class:`heritage_bayes.rundir.summary_parts.Continuation`).
"""

from __future__ import annotations

import dataclasses
import time
from pathlib import Path

import numpy as np

from heritage_bayes.convert import format_timedelta
from heritage_bayes.rundir.summary_parts import Continuation

__all__ = ["common_draws", "continue_chains", "run_chain", "sampler_args", "say_share_spent"]

#: The clock of the run's budget (:func:`time.perf_counter` seconds; tests replace it).
_now = time.perf_counter


def sampler_args(cfg, s, i: int, nwalkers: int, out: Path) -> dict:
    """The arguments of section ``s``'s :func:`~heritage_bayes.inference.sampler.run_sampler`
    call but the budget, ``resume`` and the progress output: the same for its first part
    and its continuation (a resumed chain must be sampled as it began). ``s`` is the
    ``i``-th section, its MAP and Laplace check done; sets ``s.block_move``."""
    from heritage_bayes.calibration.outputs import CONVERGENCE
    from heritage_bayes.config import chain_tag
    from heritage_bayes.inference.coordinates import sampling_coordinates
    from heritage_bayes.inference.moves import unidentified_block
    from heritage_bayes.inference.scale import scale_line
    from heritage_bayes.inference.start import start_hessian

    coords = sampling_coordinates(s.logpost, cfg.sampler.coordinates)
    if cfg.sampler.coordinates == "auto":  # the exact scale direction on its own axis
        coords = scale_line(s.logpost, coords, s.map.x)
    hessian = start_hessian(s.logpost, s.laplace, cfg.sampler.start)
    block = unidentified_block(s.logpost, s.laplace)
    s.block_move = {
        "parameters": [s.logpost.params.free_names[k] for k in block],
        "weight": cfg.sampler.block_weight_for(s.model.n_states) if block else 0.0,
    }
    return {
        "seed": cfg.seed + 101 * i,
        "nwalkers": nwalkers,
        "moves": cfg.sampler.moves,
        "block": block,
        "block_weight": s.block_move["weight"],
        "max_steps": cfg.sampler.max_steps,
        "bounds": s.logpost.params.bounds,
        "check_every": cfg.sampler.check_every,
        "tau_factor": cfg.sampler.tau_factor,
        "tau_rtol": cfg.sampler.tau_rtol,
        "tau_discard": cfg.sampler.tau_discard,
        "init_ball": cfg.sampler.init_ball,
        "checkpoint": out / f"chain_{s.name}.h5",
        "tag": f"{chain_tag(cfg)}:{s.logpost.data_hash()}:{s.name}",
        "max_rhat": CONVERGENCE["max_rhat"],
        "min_ess": CONVERGENCE["min_ess_bulk"],
        "max_draws": cfg.sampler.max_draws,
        "coordinates": coords,
        "compact": True,
        "start_hessian": hessian,
        "max_rows": cfg.sampler.max_stored_steps,
    }


def run_chain(s, say, seconds: float | None, *, resume: bool, label: str = ""):
    """Sample section ``s`` with its :attr:`sampler_args` for at most ``seconds`` [s]
    (None: no budget), continuing its checkpoint with ``resume``; its progress on
    ``say``'s bar or lines (``label``: the bar's, default the section's name)."""
    from heritage_bayes.inference.sampler import run_sampler

    update = say.sampler(label or s.name, s.sampler_args["max_steps"])
    try:
        return run_sampler(
            s.logpost,
            s.map.x,
            **s.sampler_args,
            max_seconds=seconds,
            resume=resume,
            progress=update,
            notice=say.warn,
        )
    finally:
        say.close()


def _need(cfg, chain) -> str:
    """``τmax 315, about 15 750 steps needed`` of a chain's last τ estimate (or, for a
    chain already that long, that τ or R-hat and ESS had not settled)."""
    tmax = float(np.nanmax(chain.tau))
    need = cfg.sampler.tau_factor * tmax
    if chain.steps >= need:
        return f"τmax {tmax:.0f}: long enough, but τ not yet stable or R-hat/ESS not yet met"
    return f"τmax {tmax:.0f}, about {need:.0f} steps needed"


def say_share_spent(cfg, s, say) -> None:
    """Console line for a section, not the last, whose chain ran out of its share of the
    budget: it continues once the later sections are done if they leave time."""
    say.say(
        f"[{s.name}] its share of the time budget ran out after {s.chain.steps} steps "
        f"({_need(cfg, s.chain)}): the chain continues after the other sections with the "
        "time they leave, if any"
    )


def _warn_out_of_time(cfg, s, say) -> None:
    """The warning of a chain the budget stopped for good (after its continuation,
    ``s.continued``, if it had one)."""
    budget = format_timedelta(cfg.sampler.max_time)
    how = "" if s.continued is None else f" ({Continuation.from_dict(s.continued).words})"
    say.warn(
        f"[{s.name}] the time budget sampler.max_time = {budget} ran out after "
        f"{s.chain.steps} steps{how} ({_need(cfg, s.chain)}): raise it, or run again with "
        "--resume to continue the chain"
    )


def continue_chains(cfg, sections: list, end: float | None, say) -> None:
    """Continue every section's chain the time budget stopped, with the time left
    before ``end`` (the run's budget, a :data:`_now` value; None: no budget), shared
    equally by those still to continue (see the module docstring). Each continued
    section gets ``continued`` (the record ``summary.json`` keeps), its longer chain and
    the continuation's timings; a chain still out of time, or given none, is warned
    about as before."""
    late = [s for s in sections if s.chain is not None and s.chain.stopped_by == "max_seconds"]
    for j, s in enumerate(late):
        seconds = 0.0 if end is None else max(0.0, end - _now()) / (len(late) - j)
        if seconds > 0:
            _continue(cfg, sections, s, seconds, say)
        if s.chain.stopped_by == "max_seconds":
            _warn_out_of_time(cfg, s, say)


def _continue(cfg, sections: list, s, seconds: float, say) -> None:
    """Continue section ``s``'s chain from its checkpoint for ``seconds`` [s]."""
    k = sections.index(s)
    left_by = [t.name for t in sections[k + 1 :] if t.chain.stopped_by != "max_seconds"]
    first = s.chain
    s.continued = {
        "from_steps": int(first.steps),
        "seconds_given": float(seconds),
        "left_by": left_by,
    }
    words = Continuation.from_dict(s.continued).words
    say.say(f"[{s.name}] the chain {words.replace('continued', 'continues', 1)}")
    steps, resumed_from, wall, cpu = (
        first.steps,
        first.resumed_from,
        first.wall_seconds,
        first.cpu_seconds,
    )
    s.chain = first = None  # one chain in memory: the continuation reads it back
    t0 = time.perf_counter()
    chain = run_chain(s, say, seconds, resume=True, label=f"{s.name}, continued")
    s.timings["continuation_seconds"] = time.perf_counter() - t0
    s.timings["continuation_cpu_seconds"] = chain.cpu_seconds
    # the chain's record covers both parts; resumed_from stays what --resume loaded
    s.chain = dataclasses.replace(
        chain,
        resumed_from=resumed_from,
        wall_seconds=wall + chain.wall_seconds,
        cpu_seconds=cpu + chain.cpu_seconds,
    )
    if chain.resumed_from != steps:  # the checkpoint did not give the chain back
        s.continued["from_steps"] = int(chain.resumed_from)
    how = {"converged": "converged", "max_steps": "reached the step cap sampler.max_steps"}
    end = how.get(s.chain.stopped_by, "ran out of time again")
    say.say(
        f"[{s.name}] {words}: {end} at {s.chain.steps} steps (τmax {np.nanmax(s.chain.tau):.0f})"
    )


def common_draws(cfg, sections: list) -> None:
    """The draws each sampler checked (R-hat, ESS) give the summaries; the posterior
    group holds a common number per walker, so draw i of one model pairs with draw i of
    the other (combined RH). Sets ``X``, ``lp``, ``theta`` (common) and ``X_kept``,
    ``theta_kept`` (all checked draws) on each section."""
    for s in sections:
        s.X, s.lp = s.chain.draws(cfg.sampler.max_draws)
        s.X_kept = s.X
        s.theta_kept = s.logpost.params.values(s.X.reshape(-1, s.X.shape[-1])).reshape(
            *s.X.shape[:2], -1
        )
    n_draw = min(s.X.shape[1] for s in sections)
    for s in sections:
        s.X, s.lp = s.X[:, -n_draw:], s.lp[:, -n_draw:]
        s.theta = s.theta_kept[:, -n_draw:]
