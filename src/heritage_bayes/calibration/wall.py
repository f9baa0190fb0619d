"""A buffer the MAP leaves decoupled from the outdoors: its link held at the prior's
floor for the sampler.

Under a state-space noise model (``noise: kalman``) the filter's process noise at the
buffer node does what the buffer's own link to the outdoors (``Gw``, the conductance
between the buffer ``Cw`` and the outdoor vapour pressure) would do. Where the data
leave that link idle, its conductance is a flat direction of the posterior from the
prior's floor up to where the link starts to move the buffer within the record, and an
ensemble sampler wanders along it without mixing (the Ørholm store, whose
chain converges with ``Gw`` fixed at its floor: docs/science/sbc.md, "`kalman` at
`T=2`, and a real cellar's check", "The cellars' default").

:func:`decoupled_wall` decides at the MAP: the link is idle when the buffer's exchange
time through it, ``Cw/Gw``, is at least :data:`DECOUPLED_RECORDS` calibration records
(over one record the link moves the buffer by at most 1 - exp(-1/100), 1 %, of its
distance from the outdoors) and a likelihood-ratio check agrees: the log-posterior with
``Gw`` at its floor, the other parameters at the MAP, is within :data:`FLAT_NATS` of the
MAP's (no evidence, at the sampler's temperature, against the link being absent). The
link is then fixed at the floor: the limit the posterior's flat direction runs into,
where the buffer exchanges with the indoor air only. A prior the user sets on ``Gw``
is a decision taken: the rule stays out of it.
"""

from __future__ import annotations

import dataclasses
from collections.abc import Callable, Mapping

import numpy as np

from heritage_bayes.rundir.summary_parts import DecoupledWall

__all__ = [
    "DECOUPLED_RECORDS",
    "FLAT_NATS",
    "WALL_LINKS",
    "DecoupledWall",
    "config_with_fixed_walls",
    "decoupled_wall",
    "fix_decoupled_wall",
    "fix_section_wall",
]

#: The buffer's exchange time through its outdoor link, in calibration records, from
#: which the link counts as idle (at most 1 % of the buffer's distance from the
#: outdoors moved over a record).
DECOUPLED_RECORDS = 100.0
#: [nats] The log-posterior (at the sampler's temperature) may drop by at most this
#: much when the link is set to its prior's floor, the rest at the MAP.
FLAT_NATS = 0.5
#: A buffer's link to the outdoors -> the capacity it drains (the catalogue's names).
WALL_LINKS: Mapping[str, str] = {"Gw": "Cw"}


def decoupled_wall(logpost, theta: np.ndarray, priors: Mapping = ()) -> DecoupledWall | None:
    """The buffer link the MAP leaves idle, or None (see the module docstring).

    Parameters
    ----------
    logpost : LogPosterior
        The section's; only a state-space noise model (``noise.statespace``) is checked.
    theta : (P,) array
        The MAP, every parameter (``MAPResult.theta``).
    priors : mapping
        The section's configured priors: a link named there is left alone.

    Returns
    -------
    DecoupledWall or None
    """
    ps = logpost.params
    if not logpost.noise.statespace:
        return None
    theta = np.asarray(theta, dtype=float)
    for link, cap in WALL_LINKS.items():
        if link in priors or link not in ps.names or cap not in ps.names:
            continue
        p = ps[link]
        if not p.free or not p.prior.log_scale:
            continue
        j, floor = ps.names.index(link), float(p.prior.lower)
        tau = float(theta[ps.names.index(cap)] / theta[j])
        records = tau / logpost.record_seconds
        if not records >= DECOUPLED_RECORDS:
            continue
        at = theta.copy()
        at[j] = floor
        lp = logpost(ps.to_unconstrained(np.vstack([theta, at])))
        delta = float(lp[1] - lp[0])
        if not delta >= -FLAT_NATS:
            continue
        return DecoupledWall(link, cap, floor, float(theta[j]), tau / 3600.0, records, delta)
    return None


def fix_decoupled_wall(
    finding: DecoupledWall, rebuild: Callable, priors: Mapping, map_result
) -> tuple[object, object, dict]:
    """The log-posterior with the link fixed at its floor and the MAP moved there.

    ``rebuild(priors)`` makes the section's log-posterior from its priors (a mapping
    name -> :class:`~heritage_bayes.config.priors.PriorSpec`); ``priors`` are the
    section's. Returns ``(logpost, map_result, priors)``: the new log-posterior, the
    MAP with the link at the floor (``x`` in the new sampler's coordinates,
    ``log_post`` the objective there; the search's other records kept) and the priors
    with the link fixed, which the run's ``config.yaml`` records so that every reader
    of the run rebuilds the log-posterior the chain sampled.
    """
    from heritage_bayes.config.priors import prior_specs

    fixed = {**priors, **prior_specs({finding.parameter: {"fixed": finding.floor}})}
    logpost = rebuild(fixed)
    theta = np.array(map_result.theta, dtype=float)
    theta[logpost.params.names.index(finding.parameter)] = finding.floor
    x = logpost.params.to_unconstrained(theta[None])[0]
    moved = dataclasses.replace(
        map_result,
        x=x,
        theta=theta,
        log_post=float(map_result.log_post) + finding.delta_log_posterior,
        unit=None,
    )
    return logpost, moved, fixed


def fix_section_wall(cfg, prep, s, say) -> None:
    """:func:`decoupled_wall` at section ``s``'s MAP in ``hbayes calibrate``; where it
    fires, :func:`fix_decoupled_wall` updates ``s.logpost``, ``s.map``,
    ``s.decoupled_wall`` and ``s.fixed_priors`` (for the run's config.yaml), and the
    note is warned with ``say``."""
    from functools import partial

    from heritage_bayes.calibration.ladder import section_log_posterior

    priors = getattr(cfg, s.name).priors
    if (wall := decoupled_wall(s.logpost, s.map.theta, priors)) is None:
        return
    rebuild = partial(section_log_posterior, cfg, prep, s.name, s.model)
    s.logpost, s.map, s.fixed_priors = fix_decoupled_wall(wall, rebuild, priors, s.map)
    s.decoupled_wall = wall
    say.warn(wall.text(s.name))


def config_with_fixed_walls(cfg, sections):
    """``cfg`` with each section's priors as the sampler had them (``fixed_priors`` of
    the sections where :func:`fix_section_wall` fired), or None where none did."""
    fixed = {s.name: s.fixed_priors for s in sections if s.fixed_priors is not None}
    if not fixed:
        return None
    return cfg.model_copy(
        update={k: getattr(cfg, k).model_copy(update={"priors": v}) for k, v in fixed.items()}
    )
