"""Section 4, fit metrics: MSE, MAE, FIT (the paper's Table 2) and band coverage."""

from __future__ import annotations

import math

from heritage_bayes.format import OUT_UNITS, fmt, fmt_int, fmt_pct
from heritage_bayes.report.accuracy import NEARLY_CONSTANT_RESOLUTIONS, nearly_constant
from heritage_bayes.report.page import Section
from heritage_bayes.report.rundata import RunData, model_label
from heritage_bayes.report.sections._fragment import render_fragment
from heritage_bayes.rundir.summary import FitMetrics

ID, TITLE = "metrics", "4. Fit metrics"
#: The metrics of a period the run did not write.
_NONE = FitMetrics("", "", "")


def metrics_context(rd: RunData, resolutions: dict | None = None) -> dict:
    """The metrics table; ``resolutions`` (output -> sensor resolution) decides where a
    series is nearly constant (:func:`_nearly_constant`)."""
    groups = [
        {
            "label": f"`{model_label(rd.summary, m)}` — {o}",
            "output": o,
            "unit": OUT_UNITS.get(o, ""),
            "per": per,
        }
        for (m, o), per in rd.summary.metrics_by_output().items()
    ]
    periods = [p for p in ("calibration", "validation") if any(p in g["per"] for g in groups)]
    rows = []
    cov_rows = []
    notes: list[str] = []
    for p in periods:
        cells, cov = [], []
        for g in groups:
            v = g["per"].get(p) or _NONE
            cells += [
                fmt(v.MAE),
                fmt(v.MSE),
                fmt(v.FIT, 3) if v.FIT is None else f"{v.FIT:.1f}".replace("-", "−"),
            ]
            flat = _nearly_constant(v, (resolutions or {}).get(g["output"]))
            if flat:
                notes.append(f"{g['label']}, {p}: {flat}")
            cov += [
                fmt_int(v.n),
                _cov_cell(v.coverage50, 0.5),
                _cov_cell(v.coverage90, 0.9),
            ]
        rows.append({"period": p, "cells": cells})
        cov_rows.append({"period": p, "cells": cov})
    return {"groups": groups, "rows": rows, "cov_rows": cov_rows, "notes": notes}


def _nearly_constant(v: FitMetrics, resolution: float | None) -> str:
    """Words when FIT says nothing: the measured series varies within a few sensor
    resolutions (:func:`heritage_bayes.report.accuracy.nearly_constant`) and less than
    twice the model's mean absolute error (standard deviation SD ≤ 2 MAE, i.e. FIT ≲
    40 % for Gaussian errors), e.g. a humidistat-held RH; empty otherwise (a poor fit
    of a varying series is a poor fit, not a constant series)."""
    mae, mse, fit, sd = v.MAE, v.MSE, v.FIT, v.SD
    if sd is None and None not in (mse, fit) and fit < 100:
        sd = math.sqrt(mse) / (1 - fit / 100)  # runs written before SD was stored
    if sd is None or mae is None or not (math.isfinite(sd) and math.isfinite(mae)):
        return ""
    if sd > 2 * mae or not nearly_constant(sd, resolution):
        return ""
    return (
        f"the measurements vary little (standard deviation {fmt(sd)}) against the "
        f"model's error (MAE {fmt(mae)}), within "
        f"{NEARLY_CONSTANT_RESOLUTIONS:g} sensor resolutions ({fmt(resolution)} each): FIT, "
        "which divides the error by that "
        "variation, is no measure of accuracy on such a nearly constant series. "
        "Read the MAE and the band coverage."
    )


def _cov_cell(v, nominal: float) -> dict:
    if v is None or not math.isfinite(float(v)):
        return {"text": "—", "cls": ""}
    v = float(v)
    # within ±10 percentage points of nominal: fine; too narrow bands are the usual risk
    cls = "ok" if abs(v - nominal) <= 0.1 else "warn"
    return {"text": fmt_pct(v), "cls": cls}


def section(ctx: dict) -> Section:
    """This section of the page, from the report context (figures already data URIs)."""
    return Section(TITLE, render_fragment("metrics.html", ctx), id=ID)
