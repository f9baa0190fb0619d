"""Section 1, summary: what was calibrated, on which data, and the convergence verdict.

The verdict box and the notes (rules in :mod:`heritage_bayes.report.verdict`) lead the
section, above its heading: the first thing a reader sees.
"""

from __future__ import annotations

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
    for p in s.periods:
        hours = p.steps * s.dt / 3600.0
        periods.append(
            {
                "name": p.name,
                "start": fmt_time(p.start),
                "end": fmt_time(p.end),
                "length": f"{hours / 24:.1f} d" if hours >= 48 else f"{hours:g} h",
            }
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


def section(ctx: dict) -> Section:
    """This section of the page, from the report context."""
    return Section(
        TITLE,
        render_fragment("summary.html", ctx),
        id=ID,
        lead=render_fragment("verdict.html", ctx),
    )
