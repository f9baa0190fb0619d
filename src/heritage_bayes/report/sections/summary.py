"""Section 1, summary: what was calibrated, on which data, and the convergence verdict.

The verdict box and the notes (rules in :mod:`heritage_bayes.report.verdict`) lead the
section, above its heading: the first thing a reader sees.
"""

from __future__ import annotations

import pandas as pd

from heritage_bayes.format import fmt_time
from heritage_bayes.report.page import Section
from heritage_bayes.report.rundata import RunData
from heritage_bayes.report.sections._fragment import render_fragment

ID, TITLE = "summary", "1. Summary"


def header_context(rd: RunData) -> dict:
    s = rd.summary
    models = [
        {
            "section": m,
            "model": info.model,
            "noise": info.noise or "?",
            "n_free": len(info.free_names),
            "outputs": ", ".join(info.output_names),
        }
        for m, info in s.models.items()
    ]
    periods = []
    inside = _validation_inside(s.periods)
    for p in s.periods:
        hours = p.steps * s.dt / 3600.0
        length = f"{hours / 24:.1f} d" if hours >= 48 else f"{hours:g} h"
        if inside and p.name == "calibration":
            length += "; the validation inside it is held out of the fit"
        periods.append(
            {"name": p.name, "start": fmt_time(p.start), "end": fmt_time(p.end), "length": length}
        )
    warmup_h = s.warmup_steps * s.dt / 3600.0
    return {
        "name": s.name or rd.path.name,
        "building": s.building or rd.cfg.building,
        "room": s.room or rd.cfg.room,
        "notes": (s.notes or rd.cfg.notes or "").strip(),
        "models": models,
        "periods": periods,
        "warmup": ""
        if warmup_h <= 0
        else (f"{warmup_h / 24:g} d" if warmup_h >= 24 else f"{warmup_h:g} h"),
        "created_at": fmt_time(s.created_at or None),
        "version": s.heritage_bayes_version or "?",
        "seed": s.seed,
        "config_hash": s.config_hash or "?",
        "irradiance": s.irradiance_source or "?",
    }


def _validation_inside(periods) -> bool:
    """The validation period lies inside the calibration period (``summary.json``'s
    periods, ISO instants in UTC)."""
    by = {p.name: p for p in periods}
    cal, val = by.get("calibration"), by.get("validation")
    if cal is None or val is None or None in (cal.start, cal.end, val.start, val.end):
        return False
    t = pd.Timestamp
    return t(cal.start) < t(val.start) and t(val.end) < t(cal.end)


def section(ctx: dict) -> Section:
    """This section of the page, from the report context."""
    return Section(
        TITLE,
        render_fragment("summary.html", ctx),
        id=ID,
        lead=render_fragment("verdict.html", ctx),
    )
