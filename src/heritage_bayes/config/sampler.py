"""Settings of the sampler (emcee) and of the MAP search that starts it."""

from __future__ import annotations

from typing import Annotated, Any, Literal

import pandas as pd
from pydantic import PlainSerializer, PlainValidator, WithJsonSchema

from heritage_bayes.config._base import DURATION_UNIT, Choices, _duration, _Strict, key
from heritage_bayes.convert import format_timedelta
from heritage_bayes.names import DEFAULT_MOVE, MOVES

#: ``optimizer.restarts`` of networks of :data:`BLOCK_MIN_NODES` or more capacity nodes
#: where the config does not set it: on the demo's data thermal_4a has two optima of
#: nearly equal height that one search finds one at a time (heritage_bayes.inference.
#: optimize, "Restarts").
RESTARTS = 3
#: ``sampler.block_weight`` of networks of :data:`BLOCK_MIN_NODES` or more capacity nodes
#: when the key is not set (measured: docs/science/benchmarks.md, "A block move for what
#: the data leave to the priors"); smaller networks get 0 (their chains as before)
BLOCK_WEIGHT = 0.2
BLOCK_MIN_NODES = 3

__all__ = ["Budget", "OptimizerSettings", "SamplerSettings"]


def _budget(v: Any) -> pd.Timedelta | None:
    if v is None or (isinstance(v, str) and v.strip().lower() == "none"):
        return None
    return _duration(v, positive=True)


#: A wall-time budget: a positive duration with its unit, or ``none`` (no budget).
Budget = Annotated[
    pd.Timedelta | None,
    PlainValidator(_budget),
    PlainSerializer(lambda v: "none" if v is None else format_timedelta(v), return_type=str),
    WithJsonSchema({"type": "string", "format": "duration-with-unit or none"}),
]


class SamplerSettings(_Strict):
    """emcee settings. Run length comes from the chain (τ, R-hat, ESS); ``max_time`` is
    the wall-time budget of the whole calibration — data, MAP search, sampling, ladder;
    each model gets an equal share of what is left (a duration, e.g. ``10min``, or
    ``none``), and a chain that ran out of its share continues from its checkpoint with
    the time the later models left (:mod:`heritage_bayes.calibration.chains`); and
    ``max_steps`` a safety cap on memory. A run that stops at either before converging
    exits with code 3 (see :mod:`heritage_bayes.cli`)."""

    walkers: int | None = key(
        None, unit=None, description="ensemble size (default max(32, 2 d + 2))", ge=4, le=4096
    )
    max_steps: int = key(
        200_000, unit="steps", description="safety cap on the chain length", ge=100
    )
    max_stored_steps: int | None = key(
        20_000,
        unit="steps",
        description="steps of each chain held in memory and in its checkpoint at most: past "
        "it the chain is thinned in place (every other stored step dropped, the stride "
        "doubled, never beyond τ/10) and τ estimated on the thinned chain × the stride; "
        "null: every step (a long chain's memory: docs/science/benchmarks.md)",
        ge=100,
    )
    max_time: Budget = key(
        "30min",
        unit=DURATION_UNIT,
        description="wall-time budget of the whole calibration, MAP search included, shared "
        "equally by the models (e.g. 10min, 2h) or none; a chain that runs out of its share "
        "continues, once every model has been sampled, with the time the others left; the "
        "chain stops earlier once converged",
        validate_default=True,
    )
    check_every: int = key(500, unit="steps", description="steps between convergence checks", ge=50)
    tau_factor: float = key(
        50.0,
        unit="τ",
        description="converged when the chain is this many autocorrelation times long",
        ge=10,
    )
    tau_rtol: float = key(
        0.05,
        unit="-",
        description="and the estimate of τ changed by less than this fraction",
        gt=0,
        le=1,
    )
    tau_discard: float = key(
        0.0,
        unit="-",
        description="fraction of the chain left out of the estimate of τ and of the "
        "retained draws (0: the whole chain; 0.5: the classical burn-in of half the chain, "
        "which can underestimate τ of a slow direction: docs/science/benchmarks.md)",
        ge=0,
        lt=1,
    )
    moves: Annotated[str, Choices(MOVES, described=True)] = key(
        DEFAULT_MOVE,
        unit=None,
        description="emcee's proposal moves, their τ compared in docs/science/benchmarks.md "
        '("Global proposals")',
    )
    block_weight: float | None = key(
        None,
        unit="-",
        description="share of the steps in which only the parameters the Laplace check "
        "flags as practically not identified move (differential evolution within that "
        "block; heritage_bayes.inference.moves.BlockDEMove), so that the wide directions "
        "the data leave to the priors are crossed in larger steps. Default (none): "
        f"{BLOCK_WEIGHT} for networks of three or more capacity nodes (thermal_4a), 0 for "
        "smaller ones (their chains as before). With no parameter flagged there is no "
        "block move; 0 turns it off",
        ge=0,
        lt=1,
    )
    coordinates: Literal["auto", "log", "node_tau"] = key(
        "auto",
        unit=None,
        description="what the walkers move in: log (log C, log G), node_tau (log node time "
        "constants in place of log capacities, and a split solar fraction such as "
        "thermal_4a's fsol as log(1 - fsol)), or auto: node_tau for networks of three or "
        "more nodes, log for smaller ones, and where the likelihood is constant along the "
        "overall scale of C, G and the gains in watts (no measured heat input) that scale "
        "on an axis of its own, drawn from the priors along it "
        "(heritage_bayes.inference.scale); the chain is stored in log coordinates either "
        "way",
    )
    start: Literal["auto", "ball", "laplace"] = key(
        "ball",
        unit=None,
        description="where the walkers start: ball (init_ball around the MAP), laplace "
        "(drawn from the Laplace approximation N(MAP, H^-1), flat directions at most the "
        "widest prior range), or auto: laplace for networks of three or more nodes, ball "
        "for smaller ones. Default ball: a room whose data leave directions to the priors "
        "converged from the ball and not from laplace (docs/science/benchmarks.md, "
        '"Where the demo\'s thermal_4a spends its steps")',
    )
    init_ball: float = key(
        1e-3,
        unit="-",
        description="walkers start in a ball of this radius around the MAP (unconstrained)",
        gt=0,
        le=1,
    )
    max_draws: int = key(
        4000, unit="draws", description="posterior draws kept (all walkers)", ge=100
    )
    n_predictive: int = key(
        1000,
        unit="draws",
        description="draws (all walkers) saved in posterior.nc, the same in the posterior "
        "and log-likelihood groups (the predictive keeps about 64 of them, its bands all); "
        "PSIS-LOO and the report's R-hat and ESS use them (fewer make the R-hat of the saved "
        "draws noisy: docs/science/benchmarks.md)",
        ge=10,
    )

    @property
    def max_seconds(self) -> float | None:
        """``max_time`` in seconds (None: no budget)."""
        return None if self.max_time is None else self.max_time.total_seconds()

    def block_weight_for(self, n_nodes: int) -> float:
        """The share of steps of the block move for a network of ``n_nodes`` capacity
        nodes: ``block_weight`` when set, else :data:`BLOCK_WEIGHT` from
        :data:`BLOCK_MIN_NODES` nodes on and 0 below."""
        if self.block_weight is not None:
            return float(self.block_weight)
        return BLOCK_WEIGHT if n_nodes >= BLOCK_MIN_NODES else 0.0


class OptimizerSettings(_Strict):
    """The MAP search (global, then local) that starts the chains."""

    method: Literal["differential_evolution", "multistart"] = key(
        "differential_evolution", unit=None, description="global search of the MAP"
    )
    popsize: int = key(
        10, unit="-", description="differential evolution: population per parameter", ge=4
    )
    maxiter: int = key(
        300, unit="generations", description="differential evolution: generations", ge=10
    )
    starts: int = key(4, unit="starts", description="local searches from the best points", ge=1)
    restarts: int | None = key(
        None,
        unit="searches",
        description="global searches from different seeds; optima within 10 log-posterior "
        "units of the best, apart and separated by a dip of more than 3 on the line "
        "between them are reported as modes (a multimodal posterior, which one chain "
        "does not cross), and a restart's optimum replaces the first's "
        f"when higher by more than 2. Default (none): {RESTARTS} for networks of "
        f"{BLOCK_MIN_NODES} or more capacity nodes (thermal_4a), 1 for smaller ones (their "
        "MAP as before)",
        ge=1,
        le=20,
    )

    def restarts_for(self, n_nodes: int) -> int:
        """Global searches for a network of ``n_nodes`` capacity nodes: ``restarts`` when
        set, else :data:`RESTARTS` from :data:`BLOCK_MIN_NODES` nodes on, 1 below."""
        if self.restarts is not None:
            return int(self.restarts)
        return RESTARTS if n_nodes >= BLOCK_MIN_NODES else 1
