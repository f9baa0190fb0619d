"""The notes on a run shown under its verdict (amber or info), before its results.

Pure functions on the run's typed summary
(:class:`~heritage_bayes.rundir.summary.RunSummary`): a solar input that was not
measured (a cloudless sky, or the estimate from the daily temperature range),
parameters at a prior bound, non-identifiable directions, separate optima of the MAP
search, missing chain files, synthetic data. The verdict itself is
:func:`heritage_bayes.report.verdict.convergence_verdict`.
"""

from __future__ import annotations

from heritage_bayes.format import fmt_int, prior_text, quantity_name
from heritage_bayes.inference.likelihoods import noise_parameter_names
from heritage_bayes.rundir.summary import RunSummary, typed_summary

__all__ = ["run_notes"]


def _modes_note(m: str, modes, restarts) -> dict:
    """The note of a MAP search whose restarts found separate optima (``summary.json``'s
    ``models.<m>.map.modes``, the chain's start first): their heights and the
    parameters in which they differ most (a factor of 3 or more, or 0.1 for
    fractions; :func:`heritage_bayes.inference.optimize.parameters_apart`)."""
    from heritage_bayes.inference.optimize import parameters_apart

    kept = modes[0]["values"]
    parts = []
    for other in modes[1:]:
        v = other["values"]
        what = ", ".join(f"{n} {kept[n]:.3g} vs {v[n]:.3g}" for n in parameters_apart(kept, v))
        parts.append(f"{other['log_posterior']:.1f}" + (f" ({what})" if what else ""))
    return {
        "level": "amber",
        "title": f"The {m} posterior has separate optima",
        "text": f"The MAP search ({restarts or len(modes)} global searches from different "
        f"seeds) found {len(modes)} optima of similar height: the chain started at "
        f"log-posterior {modes[0]['log_posterior']:.1f}, the other"
        + (" is at " if len(modes) == 2 else "s are at ")
        + "; ".join(parts)
        + ". An ensemble sampler rarely crosses between separated optima, so the "
        "intervals describe the reading of the room around the first; summary.json "
        f"(models.{m}.map.modes) holds the others. Decide between them with knowledge "
        "the data lack (a survey's interior_area or envelope_area, a prior on the "
        "parameters named), or use the smaller model of the ladder.",
    }


def run_notes(
    summary: RunSummary | dict,
    chains_missing: list[str],
    *,
    irradiance_setting: str | None = None,
) -> list[dict]:
    """Notes on the run to read before its results (under the verdict).

    Parameters
    ----------
    summary : RunSummary or dict
        The run's summary (or its ``summary.json`` object).
    chains_missing : list of str
        Chain files (``chain_<model>.h5``) not found in the run directory.
    irradiance_setting : str, optional
        The config's ``data.irradiance`` (``"clear_sky"`` flags a clear-sky proxy even when
        the summary does not say so).

    Returns
    -------
    list of dict
        ``level`` (``"amber"`` or ``"info"``), ``title`` and ``text`` (plain text) per note.
    """
    s = typed_summary(summary)
    out = _irradiance_notes(s.irradiance_source, irradiance_setting) + _bound_notes(s)
    for m, i in s.models.items():
        out += _model_notes(m, i)
    return out + _closing_notes(s, chains_missing)


def _irradiance_notes(irr: str, irradiance_setting: str | None) -> list[dict]:
    """A note on a solar input that was not measured (a clear-sky proxy, an estimate)."""
    out = []
    if "clear" in irr.lower() or irradiance_setting == "clear_sky":
        out.append(
            {
                "level": "amber",
                "title": "Solar radiation is a clear-sky proxy",
                "text": "The solar input was computed for a cloudless sky, not measured "
                f"(source: {irr}). The solar apertures then absorb the missing "
                "cloudiness (they are biased) and the fit is poorer on cloudy days; "
                "use measured irradiance when it is available.",
            }
        )
    elif "estimated from the daily" in irr:
        out.append(
            {
                "level": "info",
                "title": "Solar radiation is estimated from the outdoor temperature",
                "text": "No irradiance was measured: each day's global radiation was "
                "estimated from the day's temperature range (Hargreaves-Samani) and spread "
                f"over the day as the sun's path gives it (source: {irr}). Day-to-day "
                "cloudiness is followed, cloud within a day is not; use measured "
                "irradiance when it is available.",
            }
        )
    return out


def _bound_notes(s) -> list[dict]:
    """A note on the parameters whose posterior presses against a prior bound."""
    out = []
    bound = []
    for e in s.parameters.values():
        if e.at_bound:
            unit = f" {e.unit}" if e.unit and e.unit != "-" else ""
            bound.append(
                f"{quantity_name(e.key, e.description or None)} (at the {e.at_bound} end of "
                f"its prior {prior_text(e.prior)}{unit})"
            )
    if bound:
        out.append(
            {
                "level": "amber",
                "title": "Parameters pressed against a prior bound",
                "text": "The data push these parameters to the edge of the allowed "
                "range, so their interval is cut off by the prior: "
                + "; ".join(bound)
                + ". Check the model and data, or widen "
                "the prior if the bound is not physical.",
            }
        )
    return out


def _model_notes(m: str, i) -> list[dict]:
    """The notes on one model: its MAP on a bound, a frozen node, parameters the data
    leave to their priors, several MAP modes, a chain out of time or continued with the
    time the other models left."""
    out = []
    on_bound = [f"{quantity_name(n, domain=m)} ({side})" for n, side in i.map_at_bound]
    if on_bound:
        out.append(
            {
                "level": "amber",
                "title": f"The {m} MAP lies on a prior bound",
                "text": "The most probable parameter set presses against the prior "
                f"for {', '.join(on_bound)}: a finding about the prior (is the bound "
                "physical? widen it if not) or the model (a node or input the data do "
                "not support often shows up this way). The sampler started inside the "
                "bounds regardless.",
            }
        )
    out += _frozen_notes(m, i)
    if (w := i.decoupled_wall) is not None:
        out.append(
            {
                "level": "info",
                "title": f"The {m} buffer's link to the outdoors was fixed at its floor",
                "text": w.text(m).split("] ", 1)[1] + ".",
            }
        )
    noise = noise_parameter_names(i.noise, i.output_names, i.state_names)
    flagged = [n for n in i.unidentified if n not in noise]
    if flagged:
        out.append(
            {
                "level": "amber",
                "title": f"The {m} model is over-parameterised for these data",
                "text": "At the MAP the data leave the "
                + ", ".join(quantity_name(n, domain=m) for n in flagged)
                + " almost as uncertain as their priors (Laplace standard deviation "
                "above 25 % of the prior range, with the overall scale held fixed): "
                "their posteriors are mostly prior and slow the chain. Choose: fix "
                "them, add an informative prior, or use the smaller model of the "
                "ladder.",
            }
        )
    if len(i.map_modes) > 1:
        out.append(_modes_note(m, i.map_modes, i.map_restarts))
    if i.stopped_by == "max_seconds":
        more = "" if i.continued is None else f", even {i.continued.words}"
        out.append(
            {
                "level": "amber",
                "title": f"The {m} chain ran out of time",
                "text": f"The wall-time budget `sampler.max_time` ended the chain{more} "
                "before it converged: raise the budget, or continue it with `--resume`.",
            }
        )
    elif i.continued is not None:
        end = {"converged": "converged", "max_steps": "reached the step cap"}
        out.append(
            {
                "level": "info",
                "title": f"The {m} chain was continued with the time left",
                "text": f"Its share of the wall-time budget `sampler.max_time` ran out; "
                f"once every model had been sampled it was {i.continued.words}, and "
                f"{end.get(i.stopped_by, 'stopped')} at {fmt_int(i.steps)} steps.",
            }
        )
    return out


def _frozen_notes(m: str, i) -> list[dict]:
    """A note on a node that barely moves at the MAP, or on draws that freeze one."""
    out = []
    fz, share = i.frozen_node, i.frozen_share
    branch = (
        f" {share:.0%} of the posterior draws lie on this branch (the slowest time "
        "constant beyond ten records), the rest on one where every node moves: the "
        "posterior has two modes, and the intervals of the time constants span both."
        if share and share >= 0.05
        else ""
    )
    if fz:
        out.append(
            {
                "level": "amber",
                "title": f"A {m} node barely moves over the record",
                "text": f"At the MAP the slowest time constant is {fz.tau_h:.3g} h, "
                f"{fz.records:.0f} times the calibration record: that node keeps its "
                "start value, a constant standing in for a fixed node, a missing input "
                "or a missing node"
                + (
                    "; its start is estimated freely, so it acts as a free offset "
                    "(compare with the default initial_state_horizon or "
                    "initial_state: steady)."
                    if fz.start_free
                    else "; its start is held to the steady state of the first "
                    "window's mean inputs."
                )
                + branch,
            }
        )
    elif branch:
        out.append(
            {
                "level": "amber",
                "title": f"Some {m} draws freeze a node",
                "text": "The MAP's nodes all move over the record, but" + branch,
            }
        )
    return out


def _closing_notes(s, chains_missing: list[str]) -> list[dict]:
    """The notes on identifiability, missing chain files and synthetic data."""
    out = []
    nulls = [m for m, i in s.models.items() if i.identifiability.n_null]
    if nulls:
        out.append(
            {
                "level": "info",
                "title": "Not every parameter is identifiable",
                "text": "For the "
                + " and ".join(nulls)
                + (" models" if len(nulls) > 1 else " model")
                + ", some parameter combinations "
                "cannot be determined from these data (section 6): read the "
                "time constants, static gains and ratios, not the absolute "
                "capacities and conductances, unless prior knowledge pins "
                "them.",
            }
        )
    if chains_missing:
        out.append(
            {
                "level": "amber",
                "title": "Chain files missing",
                "text": "Trace plots are not available: "
                + ", ".join(f"`{c}`" for c in chains_missing)
                + " not found in the run directory.",
            }
        )
    if s.has_truth:
        p_truth = any(e.truth is not None for e in s.parameters.values())
        d_truth = any(e.truth is not None for e in s.derived.values())
        if p_truth:
            where = "the true values are shown next to the estimates"
        elif d_truth:
            where = (
                "the calibrated model is not the generating one, so true values are shown "
                "only for the quantities both share (static gains, slowest time constant)"
            )
        else:
            where = "the calibrated model is not the generating one: no true values to compare"
        out.append(
            {
                "level": "info",
                "title": "Synthetic data",
                "text": "The measurements were generated from known parameters (the "
                f"built-in virtual monument): {where}.",
            }
        )
    return out
