"""The verdict on a run: convergence level (green/amber/red) and its reasons, and the notes.

Pure functions on the run's summary (typed,
:class:`~heritage_bayes.rundir.summary.RunSummary`, or its ``summary.json`` object) and
what the report found in the run directory; no HTML here (the summary section renders
the verdict box, :mod:`heritage_bayes.report.sections.summary`). Change the rules here
and every page that shows a verdict (report, portfolio) follows: the report records the
verdict it shows in ``summary.json`` (:func:`verdict_record`), where the portfolio
reads it.

- :func:`convergence_verdict`: the level, a title, plain-words text, one line per model
  naming what failed, the statistics and the advice;
- the notes shown under the verdict are :func:`heritage_bayes.report.notes.run_notes`
  (re-exported here);
- :func:`rhat_class`, :func:`ess_class`: the traffic-light class of one R-hat or bulk-ESS
  value (``"ok"``, ``"warn"``, ``"bad"``) used by the parameter tables.
"""

from __future__ import annotations

import math

from heritage_bayes.format import fmt, fmt_int, fmt_interval, quantity_name
from heritage_bayes.report.accuracy import accuracy_failures, missing_physics
from heritage_bayes.report.notes import run_notes
from heritage_bayes.rundir.summary import RunSummary, Verdict, typed_summary

__all__ = [
    "AMBER",
    "convergence_verdict",
    "ess_class",
    "model_checks",
    "prior_pinned",
    "prior_pinned_lines",
    "rhat_class",
    "run_notes",
    "truth_advice",
    "truth_misses",
    "verdict_record",
]

#: "Close to converged" (amber) thresholds; green uses the run's own criteria.
AMBER = {"max_rhat": 1.05, "min_ess_bulk": 100.0}


def model_checks(summary: RunSummary | dict, residuals: list[dict] | None = None) -> list[str]:
    """What is wrong with the noise model of a run, in words (empty: nothing found).

    - **Whiteness** (``residuals``: the report's residual checks, one per output): what
      the noise model leaves of the calibration residuals must be white (at most 10 %
      of the lags 1-72 h outside the 95 % band, cumulative periodogram inside its band).
    - **Coverage on validation**: the share of validation hours inside the 90 %
      predictive band must lie within the binomial 99 % range around 0.90 for the
      number of effectively independent hours, n (1 - φ)/(1 + φ) with φ the noise
      model's (predictive) AR coefficient.
    - **Truths** (synthetic data, ``truth`` in the summary): every derived quantity
      with a known true value (time constants, static gains, offsets) must have it
      inside its 90 % interval; a miss is reported with its distance from the median
      in posterior standard deviations. The report draws the same intervals and truth
      markers, so the verdict cannot be green while a marker lies outside its bar.
    """
    problems = []
    for r in residuals or []:
        c = r.get("check") or {}
        if not r.get("adequate", True):
            problems.append(
                f"{r['section']} {r['output']}: the noise model leaves correlated "
                f"innovations ({100 * c.get('out_share', float('nan')):.0f} % of the lags "
                f"1-72 h outside the 95 % band; largest {c.get('worst_rho', float('nan')):.2f} "
                f"at {c.get('worst_lag_h', float('nan')):g} h)"
            )
    rs = typed_summary(summary)
    for (sec, out), periods in rs.metrics_by_output().items():
        if sec == "combined":
            continue
        info = rs.models.get(sec)
        val = periods.get("validation")
        cov, n = (None, None) if val is None else (val.coverage90, val.n)
        if cov is None or not n:
            continue
        pred = None if info is None else info.predictive_noise.get(out)
        if pred is not None:
            phi = pred.phi
        else:
            e = rs.parameters.get(f"{sec}.phi_{out}")
            phi = 0.0 if e is None else e.median
        phi = min(max(float(phi or 0.0), 0.0), 0.999)
        n_eff = max(1.0, n * (1 - phi) / (1 + phi))
        tol = 2.58 * math.sqrt(0.09 / n_eff)
        if abs(cov - 0.90) > tol:
            problems.append(
                f"{sec} {out}: the 90 % predictive band covers {100 * cov:.0f} % of "
                f"the validation hours (expected 90 ± {100 * tol:.0f} % for about "
                f"{n_eff:.0f} independent hours)"
            )
    problems += truth_misses(summary)
    return problems


def truth_misses(summary: RunSummary | dict) -> list[str]:
    """Quantities whose known true value lies outside their 90 % interval: the derived
    quantities, and the parameters the data identify (a parameter on a scale direction
    only the priors pin is named by :func:`prior_pinned` instead)."""
    rs = typed_summary(summary)
    out = []
    for key in _truth_keys(summary):
        e = rs.estimate(key)
        if e.truth_inside is not False or e.median is None:
            continue
        far = f", {abs(e.truth - e.median) / e.sd:.1f} σ from the median" if e.sd else ""
        out.append(
            f"{e.label}: the true value {fmt(e.truth)} lies outside the 90 % interval "
            f"{fmt_interval(e.q05, e.q95)}{far}"
        )
    return out


def _truth_keys(summary: RunSummary | dict) -> list[str]:
    """The quantities whose known true value the verdict weighs: derived quantities,
    then free parameters not on a scale direction only the priors pin."""
    rs = typed_summary(summary)
    pinned = {e.key for es in prior_pinned(summary).values() for e in es}
    es = [*rs.derived.values(), *(e for e in rs.parameters.values() if e.free)]
    return [e.key for e in es if e.truth is not None and e.key not in pinned]


def prior_pinned(summary: RunSummary | dict) -> dict[str, list]:
    """Per section, the free parameters whose absolute value the measurements cannot
    tell: those on a scale direction of the structural identifiability analysis
    (identifiable only once the scale is pinned). Their posterior follows the priors
    along that direction (posterior ≈ prior on the scale), so a known true value
    outside their intervals says the priors' scale is off, not the model.

    Returns
    -------
    dict
        section -> list of :class:`~heritage_bayes.rundir.summary.Estimate` (empty
        sections left out).
    """
    rs = typed_summary(summary)
    out = {}
    for m, info in rs.models.items():
        idf = info.identifiability
        if not idf.has_scale_direction:
            continue
        on_scale = [n for n in idf.parameters if idf.on_scale(n)]
        es = [rs.parameters[f"{m}.{n}"] for n in on_scale if f"{m}.{n}" in rs.parameters]
        es = [e for e in es if e.free]
        if es:
            out[m] = es
    return out


def prior_pinned_lines(summary: RunSummary | dict) -> list[str]:
    """The verdict's words on the parameters :func:`prior_pinned` names: which, and,
    with known true values, those outside their intervals and by what factor."""
    lines = []
    for m, es in prior_pinned(summary).items():
        misses = [e for e in es if e.truth_inside is False and e.truth and e.median]
        what = "capacities, conductances and solar apertures"
        if not any(e.name.startswith("fI_") for e in es):
            what = "capacities and conductances"
        text = (
            f"{m} model: the measurements do not tell the absolute scale of its "
            f"{len(es)} {what} (only their ratios, time constants and gains): the "
            "priors pin it"
        )
        if misses:
            ratios = [e.median / e.truth for e in misses]
            gm = math.exp(sum(math.log(abs(r)) for r in ratios) / len(ratios))
            text += (
                f", which puts {len(misses)} of them outside their true values, at about "
                f"{fmt(gm, 2)} × the truth: "
                + ", ".join(quantity_name(e.name, e.description, domain=m) for e in misses)
                + ". These are scale parameters pinned by the priors, not misses of the "
                "model; a prior from the room volume or a measured heat input moves them"
            )
        lines.append(text + ".")
    return lines


def truth_advice(summary: RunSummary | dict, k: int) -> str:
    """What ``k`` known truths outside their 90 % intervals mean, in words.

    With n derived quantities checked, a calibrated posterior puts about n/10 truths
    outside by chance; P(at least k) is the binomial tail for independent quantities
    (an approximation: derived quantities share parameters, e.g. the static gains of
    one node sum to one, so misses come in pairs): one data set cannot tell bad luck
    from bias (the demo's misses over its logger-noise seeds: docs/science/noise.md,
    "Figures behind the code's choices").
    """
    n = len(_truth_keys(summary))
    p = sum(math.comb(n, j) * 0.1**j * 0.9 ** (n - j) for j in range(k, n + 1))
    return (
        f"Of {n} quantities with a known true value, {k} "
        f"{'lies' if k == 1 else 'lie'} outside their 90 % interval, where about "
        f"{0.1 * n:.1f} are expected by chance (at least {k} with "
        f"probability {p:.2g} if they were independent; gains of one node that sum to one "
        "miss together). One data set cannot tell bad luck from bias: regenerate the "
        "data with other seeds (a bias keeps the misses on one side), and read misses "
        "beyond 3 σ as a bias."
    )


def convergence_verdict(
    summary: RunSummary | dict,
    residuals: list[dict] | None = None,
    *,
    shapes: dict | None = None,
    resolutions: dict | None = None,
) -> dict:
    """The plain-words verdict of a run's ``summary.json``: accuracy, convergence, then
    the noise model's checks (:func:`model_checks`, with the report's ``residuals``).

    Accuracy comes first: a model whose fit of a measured output fails the rule of
    :func:`heritage_bayes.report.accuracy.accuracy_failures` (FIT below 50 % on the
    validation period, or the calibration period without one; the 90 % band covering
    under 75 % of the validation hours) gets a red verdict "this model does not
    reproduce the room", whatever the sampler did, with the most likely missing
    physics as advice (:func:`heritage_bayes.report.accuracy.missing_physics`, from
    ``shapes``: (section, output) -> residual shape, and the run's model ladder).
    ``resolutions`` (output -> sensor resolution) exempts nearly constant series
    from the FIT rule.

    Returns
    -------
    dict
        ``level`` (``"red"`` when the model does not reproduce the room; else
        ``"green"``: the stopping rule met — 50 τ with a stable τ, R-hat and bulk ESS
        within the run's criteria on the sampler's retained draws — *and* the run's
        R-hat and ESS (:attr:`~heritage_bayes.rundir.summary.Convergence.draws`) within
        the same criteria, and the residual, coverage and truth checks pass;
        ``"amber"``: the rule met but those figures or a check fail, or close to
        converged — max R-hat ≤ 1.05 and min bulk ESS ≥ 100; ``"red"``: not
        converged), ``status`` (one of
        :data:`~heritage_bayes.rundir.summary.STATUSES`: *converged* when green,
        *checks failed* when the stopping rule was met and the headline does not say
        otherwise, else *not converged*), ``title``, ``text``, ``rule`` (the rule
        applied, in words, for the page), ``models`` (one plain-words line per model,
        per failed check and per model whose scale only the priors pin,
        :func:`prior_pinned_lines`), ``checks``, ``accuracy`` (the failures of the
        accuracy rule) and ``advice``.

    Notes
    -----
    ``summary["converged"]`` is the stopping rule's decision, the one ``hbayes
    calibrate`` prints and its exit code follows. ``max_rhat`` and ``min_ess_bulk``
    are those of every retained draw in the parameters' own coordinates (group
    ``posterior_retained_<model>`` of ``posterior.nc``: ``az.summary`` of it gives them), the
    draws the rule checked and the parameter table's R-hat and ESS describe; the thinned
    draws of the ``posterior`` group (what the quantiles and bands use) are too few per
    walker for R-hat to mean much and are named beside, deciding nothing. In a run
    written before the retained draws were stored the figures are the thinned draws'
    and decide as they did. A run whose figures miss the stated criteria is amber,
    never green, and the page states the rule and which draws.
    """
    rs = typed_summary(summary)
    conv = rs.convergence
    r_ok, e_ok, tf = conv.target_rhat, conv.target_ess, conv.tau_factor
    max_rhat = _nan_low(conv.max_rhat)
    min_ess = _nan_high(conv.min_ess_bulk)
    within_amber = max_rhat <= AMBER["max_rhat"] and min_ess >= AMBER["min_ess_bulk"]
    # the run's decision (the stopping rule), with its R-hat/ESS within the amber limits
    rule_ok = conv.converged and conv.converged_tau and within_amber
    # green also needs the R-hat/ESS the parameter tables show within the criteria
    saved_ok = conv.draws_ok
    lines = _model_lines(rs, rule_ok)
    stats = (
        f"max R-hat {max_rhat:.3f} (target ≤ {r_ok:g}), min bulk ESS "
        f"{fmt_int(min_ess)} (target ≥ {e_ok:g}) of the {conv.draws_name}, chain length "
        f"≥ {tf:g} τ: {'yes' if conv.converged_tau else 'no'}; stopping rule "
        f"met: {'yes' if conv.converged else 'no'}"
    )
    rule = (
        "Rule applied: green only when the sampler's stopping rule is met (chains of "
        f"at least {tf:g} τ with a stable τ), the R-hat and bulk ESS of {conv.draws_where}, "
        f"which the parameter tables show, meet the stated criteria (R-hat ≤ {r_ok:g}, "
        f"bulk ESS ≥ {e_ok:g}, as arviz recomputes them from the file) and the checks "
        "pass." + (f" Beside them, {conv.saved_text}." if conv.saved_text else "")
    )
    checks = model_checks(summary, residuals)
    level, title, text, advice = _sampling_verdict(
        summary, rs, rule_ok, saved_ok, within_amber, checks
    )
    if rule_ok:  # the stopping rule met: the failed checks are the reasons
        lines += [f"Check: {c}." for c in checks]
    failures = accuracy_failures(summary, resolutions)
    # the headline says the sampling did not converge (the portfolio's "not converged")
    says_unconverged = level == "red"
    if failures:
        converged = rule_ok and saved_ok
        says_unconverged = not converged
        title, text, advice = _accuracy_verdict(
            summary, failures, shapes, converged, nearly=level == "amber" and not converged
        )
        level = "red"
    lines += prior_pinned_lines(summary)
    if level == "green":
        status = "converged"
    elif conv.converged and conv.converged_tau and not says_unconverged:
        status = "checks failed"
    else:
        status = "not converged"
    return {
        "level": level,
        "status": status,
        "title": title,
        "text": text,
        "rule": rule,
        "stats": stats,
        "models": lines,
        "checks": checks,
        "accuracy": failures,
        "advice": advice.strip(),
    }


def _model_lines(rs, rule_ok: bool) -> list[str]:
    """One plain-words line per model: its chain length against τ and the R-hat and bulk
    ESS (of the draws the run's figures are on) against the run's criteria."""
    conv = rs.convergence
    r_ok, e_ok, tf = conv.target_rhat, conv.target_ess, conv.tau_factor
    lines = []
    for m, info in rs.models.items():
        pr = [e for e in rs.parameters.values() if e.section == m and e.r_hat is not None]
        problems = []
        steps, tmax = info.steps, info.tau_max
        if not info.converged_tau:
            if steps is not None and tmax is not None:
                problems.append(
                    f"the chains ran {fmt_int(steps)} steps but need at least "
                    f"{tf:g} × τ = {fmt_int(tf * tmax)} steps (τ ≈ {fmt_int(tmax)}) with a "
                    "stable τ"
                )
            else:
                problems.append("the autocorrelation-time (τ) criterion was not met")
        rhat_text = ess_text = None  # the judged draws' R-hat / ESS beyond the targets
        if pr:
            worst_r = max(pr, key=lambda e: _nan_low(e.r_hat))
            worst_e = min(pr, key=lambda e: _nan_high(e.ess_bulk))
            rmax, emin = _nan_low(worst_r.r_hat), _nan_high(worst_e.ess_bulk)
            if not rmax <= r_ok:
                rhat_text = f"R-hat up to {rmax:.3f} for the {quantity_name(worst_r.key)}"
            if not emin >= e_ok:
                ess_text = f"bulk ESS down to {fmt_int(emin)} for the {quantity_name(worst_e.key)}"
        name = f"{m} model (`{info.model}`)"
        saved = [t for t in (rhat_text, ess_text) if t]
        if rule_ok and not problems and saved:
            lines.append(
                f"{name}: the stopping rule is met on the sampler's retained draws, but "
                f"{conv.draws_where} give "
                + " and ".join(saved)
                + f" (criteria R-hat ≤ {r_ok:g}, bulk ESS ≥ {e_ok:g})."
            )
            continue
        if rhat_text:
            problems.append(f"the walkers disagree: {rhat_text} (should be ≤ {r_ok:g})")
        if ess_text:
            problems.append(f"too few independent samples: {ess_text} (should be ≥ {e_ok:g})")
        if problems:
            lines.append(f"{name}: " + "; ".join(problems) + ".")
        else:
            lines.append(f"{name}: all criteria met.")
    return lines


def _sampling_verdict(summary, rs, rule_ok: bool, saved_ok: bool, within_amber: bool, checks):
    """(level, title, text, advice) of the sampling and the noise model's checks, before
    the accuracy rule (see :func:`convergence_verdict`)."""
    green = rule_ok and saved_ok
    if rule_ok and not saved_ok:
        level, title = (
            "amber",
            f"Stopping rule met, but the {rs.convergence.draws_name} miss the criteria",
        )
        text = (
            f"The sampler's stopping rule was met on its retained draws, but "
            f"{rs.convergence.draws_text}. Medians are usable; treat the intervals, "
            "bands and tail values as approximate."
        )
        advice = (
            "Continue the chains: raise `sampler.max_steps` in the config and run "
            "`hbayes calibrate CONFIG --out RUN_DIR --resume`."
        )
    elif green and checks:
        level, title = "amber", "Converged, but the checks below fail"
        text = (
            "The sampler met every convergence criterion, but the checks below fail: "
            "the residuals keep structure the noise model does not describe, the "
            "validation band misses, or a known true value lies outside its interval. "
            "Intervals and bands may be too narrow; medians and the fit figures are "
            "usable."
        )
        misses = truth_misses(summary)
        advice = (
            ""
            if len(misses) == len(checks)
            else "Look at the residual diagnostics (section 7): a daily cycle points at "
            "a missing input (solar gains on another facade, occupancy); a slow drift at "
            "a missing node or a controlled climate; try the model-order ladder."
        )
        if misses:
            advice += " " + truth_advice(summary, len(misses))
    elif green:
        level, title = "green", "Converged"
        text = (
            "The sampler met every convergence criterion: the posterior summaries, "
            "intervals and predictive bands in this report are reliable, within the "
            "assumptions of the model."
        )
        advice = ""
    elif within_amber:
        level, title = "amber", "Nearly converged — use with care"
        text = (
            "The chains are close to, but do not meet, the convergence criteria. "
            "Medians are usable; treat the intervals, bands and tail values as "
            "approximate."
        )
        advice = (
            "Run the sampler longer before relying on the intervals: raise "
            "`sampler.max_steps` in the config and run `hbayes calibrate CONFIG --out "
            "RUN_DIR --resume`, which continues the saved chains."
        )
    else:
        level, title = "red", "NOT CONVERGED — do not use these results yet"
        text = (
            "The sampler did not reach a stable posterior. The parameter values, "
            "intervals and predictive bands below may be wrong."
        )
        advice = (
            "Run the sampler longer: raise `sampler.max_steps` in the config and run "
            "`hbayes calibrate CONFIG --out RUN_DIR --resume`, which continues the saved "
            "chains; if it still does not converge, the model may be over-parameterised "
            "for the data (see the identifiability section and the model-order ladder)."
        )
    if level != "green" and any(i.identifiability.n_null for i in rs.models.values()):
        advice += (
            " Parameter combinations that the data cannot identify (section 6) "
            "slow the sampler down: pinning them with prior knowledge, e.g. the "
            "room volume (`room_volume`), usually helps."
        )
    return level, title, text, advice


def _accuracy_verdict(summary, failures, shapes, converged: bool, nearly: bool):
    """(title, text, advice) of a model that fails the accuracy rule: red, whatever the
    sampler did, with the most likely missing physics as advice."""
    title = "This model does not reproduce the room"
    if not converged:
        title += " — and " + ("not fully converged" if nearly else "NOT CONVERGED")
    text = (
        "The posterior-median model misses the measurements: "
        + "; ".join(f["text"] for f in failures)
        + ". Its parameters, intervals and projections describe a model that lacks "
        "part of the room's physics: do not use them to judge the room. "
        + (
            "The sampler converged; the fault is the model, not the sampling."
            if converged
            else "The sampler did not converge either."
        )
    )
    causes = missing_physics(summary, failures, shapes)
    advice = (
        ("Most likely missing: " + " ".join(causes) + " " if causes else "")
        + "Compare the model orders of the ladder (section 6) and the residual "
        "diagnostics (section 7), change the model, and calibrate again."
    )
    return title, text, advice


def verdict_record(verdict: dict) -> Verdict:
    """What ``summary.json`` records of a :func:`convergence_verdict` (its level,
    status, headline, text, reasons and advice): the report writes it beside the page
    it shows it on, and the portfolio reads it from there."""
    return Verdict(
        level=verdict["level"],
        status=verdict["status"],
        title=verdict["title"],
        text=verdict["text"],
        reasons=tuple(verdict["models"]),
        advice=verdict["advice"],
    )


def _nan_low(v) -> float:
    """NaN/None -> +inf (counts as worst for 'max must be small')."""
    try:
        f = float(v)
    except (TypeError, ValueError):
        return math.inf
    return f if math.isfinite(f) else math.inf


def _nan_high(v) -> float:
    try:
        f = float(v)
    except (TypeError, ValueError):
        return -math.inf
    return f if math.isfinite(f) else -math.inf


def _grade(ok: bool, close: bool) -> str:
    return "ok" if ok else ("warn" if close else "bad")


def rhat_class(r, r_ok: float) -> str:
    """``"ok"`` if R-hat ≤ ``r_ok`` (the run's criterion), ``"warn"`` if ≤ the amber
    threshold, else ``"bad"`` (NaN counts as bad)."""
    return _grade(_nan_low(r) <= r_ok, _nan_low(r) <= AMBER["max_rhat"])


def ess_class(e, e_ok: float) -> str:
    """``"ok"`` if the bulk ESS ≥ ``e_ok`` (the run's criterion), ``"warn"`` if ≥ the amber
    threshold, else ``"bad"`` (NaN counts as bad)."""
    return _grade(_nan_high(e) >= e_ok, _nan_high(e) >= AMBER["min_ess_bulk"])
