"""Section 4, fit metrics: MSE, MAE, FIT (the paper's Table 2) and band coverage."""

from __future__ import annotations

import math

from heritage_bayes.report.format import OUT_UNITS, fmt, fmt_int, fmt_pct
from heritage_bayes.report.page import Section
from heritage_bayes.report.rundata import RunData, model_label
from heritage_bayes.report.sections._fragment import render_fragment

ID, TITLE = "metrics", "4. Fit metrics"


def metrics_context(rd: RunData) -> dict:
    metrics = rd.summary.get("metrics") or {}
    groups = []
    for m, outs in metrics.items():
        for o, per in outs.items():
            u = OUT_UNITS.get(o, "")
            groups.append(
                {
                    "label": f"{model_label(rd.summary, m)} — {o}",
                    "output": o,
                    "unit": u,
                    "per": per,
                }
            )
    periods = [p for p in ("calibration", "validation") if any(p in g["per"] for g in groups)]
    rows = []
    cov_rows = []
    for p in periods:
        cells, cov = [], []
        for g in groups:
            v = g["per"].get(p) or {}
            cells += [
                fmt(v.get("MSE")),
                fmt(v.get("MAE")),
                fmt(v.get("FIT"), 3)
                if v.get("FIT") is None
                else f"{v['FIT']:.1f}".replace("-", "−"),
            ]
            cov += [
                fmt_int(v.get("n")),
                _cov_cell(v.get("coverage50"), 0.5),
                _cov_cell(v.get("coverage90"), 0.9),
            ]
        rows.append({"period": p, "cells": cells})
        cov_rows.append({"period": p, "cells": cov})
    return {"groups": groups, "rows": rows, "cov_rows": cov_rows}


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
