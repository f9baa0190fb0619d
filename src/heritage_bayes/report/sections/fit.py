"""Section 3, fit: measured vs the posterior-predictive model over the periods.

:func:`fit_outputs` lists the predicted and measured outputs; :func:`fit_context` draws
one figure per output and keeps the residuals of the posterior-median model for the
diagnostics (section 7).
"""

from __future__ import annotations

import numpy as np

from heritage_bayes.format import OUT_WORDS
from heritage_bayes.inference.likelihoods import NoiseModel, find_noise_model
from heritage_bayes.report.page import Section
from heritage_bayes.report.rundata import (
    RunData,
    measurement_gaps,
    model_label,
    predictive_quantiles,
    time_axis,
)
from heritage_bayes.report.sections._fragment import render_fragment

ID, TITLE = "fit", "3. Fit"


def fit_outputs(rd: RunData) -> list[dict]:
    """(section, output, pp var, sim var) for every predicted and measured output."""
    pp = rd.idata.posterior_predictive
    obs = rd.idata.observed_data
    out = []
    for m, info in rd.summary.models.items():
        for o in info.output_names:
            if f"{m}.{o}" in pp and f"{m}.{o}_sim" in pp and o in obs:
                out.append(
                    {
                        "section": m,
                        "output": o,
                        "pp": f"{m}.{o}",
                        "sim": f"{m}.{o}_sim",
                        "model": info.model,
                    }
                )
    if "RHi" in pp and "RHi_sim" in pp and "RHi" in obs:
        out.append(
            {
                "section": "combined",
                "output": "RHi",
                "pp": "RHi",
                "sim": "RHi_sim",
                "model": model_label(rd.summary, "combined"),
            }
        )
    return out


def fit_context(rd: RunData, outputs: list[dict]) -> list[dict]:
    from heritage_bayes.report.figures import fig_fit

    pp = rd.idata.posterior_predictive
    obs = rd.idata.observed_data
    const = rd.idata.constant_data
    times_pp = time_axis(pp)
    codes_all = np.asarray(const["period"].values)
    t_const = time_axis(const)
    codes = (
        codes_all
        if np.array_equal(t_const, times_pp)
        else np.asarray(const["period"].reindex(time=times_pp, fill_value=-1).values)
    )
    dt = np.median(np.diff(times_pp[:1000])) if times_pp.size > 1 else np.timedelta64(3600, "s")
    items = []
    for o in outputs:
        gaps = measurement_gaps(rd, dt, o["output"])
        med = predictive_quantiles(rd.idata, o["sim"], [0.5])[0]
        q = predictive_quantiles(rd.idata, o["pp"], [0.05, 0.25, 0.75, 0.95])
        q1 = _one_step_quantiles(rd, o, pp)  # None without a state-space noise model
        y = np.asarray(obs[o["output"]].reindex(time=times_pp).values, dtype=float)
        fig = fig_fit(
            times_pp,
            y,
            med,
            (q[1], q[2]),
            (q[0], q[3]),
            codes,
            output=o["output"],
            model_name=o["model"],
            gaps=gaps,
        )
        what = OUT_WORDS.get(o["output"], o["output"])
        info = rd.summary.models.get(o["section"])
        pred = None if info is None else info.predictive_noise.get(o["output"])
        band_note = ""
        if pred:
            nm = find_noise_model(info.noise) or NoiseModel()
            band_note = (
                nm.free_run_note + f"AR(1) of sd {pred.sigma:.3g} with hourly coefficient "
                f"{pred.phi:.3f} plus white noise of sd {pred.sigma_meas:.3g}, fitted "
                "to the calibration residuals of the posterior-median simulation."
            )
        sat = None if info is None else info.saturation
        if sat and o["output"] == "Pi":
            band_note += (
                " Predicted vapour pressure is limited to saturation at the predicted "
                f"indoor temperature ({sat.temperature}): the excess would condense. "
                f"The limit acted on {100 * sat.share_predictive_samples:.1f} % of the "
                "predictive samples and on the noise-free median in "
                f"{100 * sat.share_hours_median_saturated:.1f} % of the hours"
                + (
                    ": the model predicts condensation conditions that often; check them "
                    "against the measured RH before trusting its dampest hours."
                    if sat.share_hours_median_saturated > 0.01
                    else "."
                )
            )
        items.append(
            {
                "id": f"fig-fit-{o['section']}-{o['output']}",
                "title": f"{what} ({o['output']}) — `{o['model']}`",
                "figure": fig,
                "caption": (
                    f"Measured {what} (black) and the model's posterior "
                    "median (blue line) with the 50 % and 90 % posterior-"
                    "predictive bands (model and noise). Shading: warm-up "
                    "(grey, simulated but not fitted), calibration (green), "
                    "validation (orange); hatched: gaps in the data (no simulated value where an "
                    "input was missing too long to bridge). Bottom: "
                    "two-week details."
                )
                + band_note,
                "resid": (y - med),
                # a state-space noise model's check is on its one-step innovations
                "resid_1step": None if q1 is None else y - q1[2],
                "measured": y,
                "codes": codes,
                "times": times_pp,
                **o,
            }
        )
        if q1 is not None:
            items.append(_one_step_item(rd, o, q1, times_pp, y, codes, gaps, what))
    return items


def _one_step_quantiles(rd: RunData, o: dict, pp) -> np.ndarray | None:
    """The 5, 25, 50, 75 and 95 % quantiles of a state-space noise model's one-step-ahead
    prediction (``noise: kalman``; rows in that order), None for a run without one."""
    if f"{o['pp']}_1step" not in pp:
        return None
    return predictive_quantiles(rd.idata, f"{o['pp']}_1step", [0.05, 0.25, 0.5, 0.75, 0.95])


def _one_step_item(rd: RunData, o: dict, q, times, y, codes, gaps, what: str) -> dict:
    """The one-step-ahead band of a state-space noise model (``noise: kalman``) from its
    quantiles ``q`` (:func:`_one_step_quantiles`)."""
    from heritage_bayes.report.figures import fig_fit

    fig = fig_fit(
        times,
        y,
        q[2],
        (q[1], q[3]),
        (q[0], q[4]),
        codes,
        output=o["output"],
        model_name=o["model"],
        gaps=gaps,
    )
    cov = []
    for period in ("calibration", "validation"):
        met = rd.summary.metric(o["section"], o["output"], period)
        c = None if met is None else met.coverage90_1step
        if c is not None:
            cov.append(f"{period} {100 * c:.0f} %")
    return {
        "id": f"fig-fit-{o['section']}-{o['output']}-1step",
        "title": f"{what} ({o['output']}), one step ahead — `{o['model']}`",
        "figure": fig,
        "caption": (
            f"Measured {what} (black) and the Kalman filter's one-step-ahead prediction "
            "of each hour from the measurements before it (median, 50 % and 90 % bands "
            "over posterior draws; process and measurement noise): what the model can "
            "claim when it is updated with the logger, as in a forecast. The free-run "
            "bands above are what it claims without measurements (a projection); their "
            "process noise accumulates over the slowest time constant. "
            + (f"90 % one-step band coverage: {', '.join(cov)}." if cov else "")
        ),
        # the diagnostics (section 7) read the free-run item's residuals, not these
        "resid": None,
        "codes": codes,
        "times": times,
        **o,
    }


def section(ctx: dict) -> Section:
    """This section of the page, from the report context (figures already data URIs)."""
    return Section(TITLE, render_fragment("fit.html", ctx), id=ID)
