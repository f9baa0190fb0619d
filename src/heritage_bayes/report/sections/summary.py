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
    models = []
    for m, info in (s.get("models") or {}).items():
        n_free = len((s.get("correlations") or {}).get(m, {}).get("names", []))
        models.append(
            {
                "section": m,
                "model": info.get("model", "?"),
                "noise": info.get("noise", "?"),
                "n_free": n_free,
                "outputs": ", ".join(info.get("output_names", [])),
            }
        )
    periods = []
    for name, p in (s.get("periods") or {}).items():
        hours = p.get("steps", 0) * float(s.get("dt", 3600.0)) / 3600.0
        periods.append(
            {
                "name": name,
                "start": fmt_time(p.get("start")),
                "end": fmt_time(p.get("end")),
                "length": f"{hours / 24:.1f} d" if hours >= 48 else f"{hours:g} h",
            }
        )
    warmup_h = s.get("warmup_steps", 0) * float(s.get("dt", 3600.0)) / 3600.0
    return {
        "name": s.get("name") or rd.path.name,
        "building": s.get("building") or rd.cfg.building,
        "room": s.get("room") or rd.cfg.room,
        "notes": (s.get("notes") or rd.cfg.notes or "").strip(),
        "models": models,
        "periods": periods,
        "warmup": ""
        if warmup_h <= 0
        else (f"{warmup_h / 24:g} d" if warmup_h >= 24 else f"{warmup_h:g} h"),
        "created_at": fmt_time(s.get("created_at")),
        "version": s.get("heritage_bayes_version", "?"),
        "seed": s.get("seed"),
        "config_hash": s.get("config_hash", "?"),
        "irradiance": s.get("irradiance_source", "?"),
    }


def section(ctx: dict) -> Section:
    """This section of the page, from the report context."""
    return Section(
        TITLE,
        render_fragment("summary.html", ctx),
        id=ID,
        lead=render_fragment("verdict.html", ctx),
    )
