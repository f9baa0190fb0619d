"""What a calibration says before it samples: findings at the MAP.

:func:`say_findings` warns (and the run keeps in its summary) what the MAP and the
identifiability check show about the priors and the model: a noise parameter at its cap,
a frozen node, a parameter on a prior bound, several separate optima, parameters the
data do not pin. Split from :mod:`heritage_bayes.calibration.calibrate`, which calls it with each
section (its model, log-posterior, MAP, identifiability and Laplace results).
"""

from __future__ import annotations

from collections.abc import Mapping

import numpy as np

from heritage_bayes.rc.catalog import DomainView, model_ladder
from heritage_bayes.rc.derived import frozen_time_constant

__all__ = ["LADDERS", "modes_finding", "say_findings"]

#: The model-order ladder of each section, smallest first (the report's ladder, the
#: candidates of ``hbayes compare``, the smaller model a finding suggests): the
#: catalogue entries marked ``ladder`` (:func:`heritage_bayes.rc.catalog.model_ladder`).
LADDERS: Mapping[str, tuple[str, ...]] = DomainView(model_ladder)


def say_findings(say, s, priors: Mapping | tuple = ()) -> None:
    """Before sampling: a MAP on a prior bound, and parameters the data do not pin.

    Findings about the prior or the model, warned (and kept in the summary); a parameter
    whose prior the config sets (``priors``) is a decision taken: a capped phi is said,
    not warned, and one the data do not pin is not flagged (its prior closes it).
    """
    s.map_at_bound = s.logpost.params.at_bound(s.map.x)
    nm = s.logpost.noise
    specs = nm.parameter_specs(s.model.output_names, s.model.state_names)
    caps = {n for n, kind, _ in specs if kind in nm.capped_kinds}
    capped = [n for n, side in s.map_at_bound if n in caps and side == "upper"]
    told = {(n, "upper") for n in capped}
    if told:
        ph = s.logpost.params.parameters[s.logpost.params.names.index(capped[0])].prior.upper
        hours = -s.logpost.dt / 3600.0 / np.log(ph)
        (say.say if capped[0] in priors else say.warn)(
            f"[{s.name}] {', '.join(capped)} at its cap {ph:g}: the misfit stays correlated "
            f"for longer than the noise model allows (about {hours:.0f} h), so the model "
            "misses a slow process (a missing input such as solar gains, a heat or "
            "moisture source, a controlled climate). The simulation is kept responsible "
            "for the slow response; widen the cap with a prior on "
            f"{capped[0]} only if the slow misfit is measurement drift"
        )
    lp = s.logpost
    record = lp.record_seconds
    tau = frozen_time_constant(s.model, s.map.theta[: lp.n_model], record)
    if tau is not None:  # a frozen node (see frozen_time_constant)
        free = lp.initial_state == "estimate" or isinstance(lp.initial_state, Mapping)
        sd = lp.initial_state_sd / np.hypot(1.0, tau / lp.initial_state_horizon) if free else 0.0
        unit = "K" if s.model.domain == "thermal" else "Pa"
        s.frozen_node = {
            "tau_h": tau / 3600.0,
            "records": tau / record,
            "start_free": bool(free and sd > 0.5 * lp.initial_state_sd),
            "start_sd": sd,
            "unit": unit,
        }
        say.warn(
            f"[{s.name}] the slowest time constant at the MAP, {tau / 3600:.3g} h, is "
            f"{tau / record:.0f} times the calibration record: that node barely moves, a "
            "constant standing in for a fixed node, a missing input or a missing node; "
            + (
                "its start is estimated freely, so it is a free offset: compare with "
                "the default initial_state_horizon or initial_state: steady"
                if s.frozen_node["start_free"]
                else f"its start is held to the steady state (prior sd {sd:.2g} {unit})"
            )
            + ", or model the fixed node (thermal: options.ground; hygric: hygric_2c_fixed)"
        )
    if unexplained := [b for b in s.map_at_bound if b not in told]:  # not flagged twice
        what = ", ".join(f"{n} ({side})" for n, side in unexplained)
        say.warn(
            f"[{s.name}] the MAP lies on a prior bound for {what}: the data push "
            "these parameters to the edge of the allowed range. Check the prior (is the "
            "bound physical? widen it if not) and the model (a missing input or node "
            "often shows up this way)"
        )
    ident = s.identifiability
    # the overall scale of C and G (no known heat input) is a null direction only a
    # prior closes: reported in the identifiability section, not flagged here
    ok = ident.identifiable_given_scale if ident.has_scale_direction else ident.identifiable
    structural = [p for p, good in ok.items() if not good and p not in priors]
    practical = list(s.laplace.unidentified) if s.laplace is not None else []
    poor = [p for p in practical if p in s.model.parameter_names and p not in priors]
    ladder = LADDERS.get(s.name, ())
    k = ladder.index(s.model.name) if s.model.name in ladder else 0
    smaller = ladder[k - 1] if k > 0 else None
    if len(s.map.modes) > 1:
        say.warn(modes_finding(s, smaller))
    if structural or poor:
        parts = []
        if structural:
            parts.append(f"structurally not identifiable: {', '.join(structural)}")
        if poor:
            parts.append(
                "practically not identified at the MAP (Laplace sd > 25 % of the prior "
                f"range): {', '.join(poor)}"
            )
        say.warn(
            f"[{s.name}] {s.model.name} is over-parameterised for these data ("
            + "; ".join(parts)
            + "). The chain will mix slowly and these posteriors will be their priors. "
            f"Choose: fix them ({s.name}.priors: {{NAME: {{fixed: VALUE}}}}), add an "
            "informative prior (room_volume, air_change_rate, or a lognormal prior on "
            "them)" + (f", or use the smaller model ({s.name}.model: {smaller})" if smaller else "")
        )


def modes_finding(s, smaller: str | None) -> str:
    """The warning for a MAP search whose restarts found several optima of similar
    height (:attr:`MAPResult.modes`): where they differ, and what a user can do."""
    from heritage_bayes.inference.optimize import parameters_apart

    names = s.logpost.params.names
    kept, *others = s.map.modes
    at_kept = dict(zip(names, kept["theta"], strict=True))
    parts = []
    for m in others:
        at_m = dict(zip(names, m["theta"], strict=True))
        diff = ", ".join(
            f"{n} {at_kept[n]:.3g} vs {at_m[n]:.3g}" for n in parameters_apart(at_kept, at_m)
        )
        parts.append(f"log-posterior {m['log_posterior']:.1f} with {diff}")
    return (
        f"[{s.name}] the MAP search found {len(s.map.modes)} separate optima of similar "
        f"height ({s.map.restarts} searches): the chain starts at the one with "
        f"log-posterior {kept['log_posterior']:.1f}; the other"
        + (" has " if len(others) == 1 else "s have ")
        + "; ".join(parts)
        + ". The posterior is multimodal: these data fit more than one reading of "
        "the room, an ensemble sampler rarely crosses between separated optima, and the "
        "intervals describe the region the chain samples. Decide between them with "
        "knowledge the data lack (a survey's interior_area, envelope_area, or a prior "
        "on the parameters named)"
        + (f", or use the smaller model ({s.name}.model: {smaller})" if smaller else "")
    )
