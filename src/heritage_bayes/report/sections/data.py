"""Section 2, data: the inputs and measurements over time, and what the alignment did."""

from __future__ import annotations

import numpy as np

from heritage_bayes.format import fmt_int, fmt_time
from heritage_bayes.report.page import Section
from heritage_bayes.report.rundata import RunData, measurement_gaps, time_axis
from heritage_bayes.report.sections._fragment import render_fragment
from heritage_bayes.rundir.summary import SourceNote

ID, TITLE = "data", "2. Data"


def _input_units(rd: RunData) -> dict:
    units = {}
    for model in rd.run.models.values():
        for c in model.input_names:
            try:
                units[c] = model.network.input_unit(c)
            except (StopIteration, KeyError, AttributeError):
                units[c] = ""
    return units


def _sources(notes: tuple[SourceNote, ...]) -> list[dict]:
    """One row per source file and role: the tables derived from one record (its
    facade irradiance, ``"<file> (irradiance on surfaces)"``) join its row."""
    rows: dict[tuple, dict] = {}
    names = {src.source for src in notes}
    for src in notes:
        name = src.source
        base = name.rsplit(" (", 1)[0] if name.endswith(")") else name
        base = base if base in names else name
        key = (src.role, base)
        row = rows.setdefault(
            key,
            {"role": key[0], "source": base, "columns": [], "timezone": [], "averaged": []},
        )
        for k in ("columns", "averaged"):
            row[k] += [c for c in getattr(src, k) if c not in row[k]]
        if src.timezone and src.timezone not in row["timezone"]:
            row["timezone"].append(src.timezone)
    return [
        {k: v if isinstance(v, str) else ", ".join(v) for k, v in row.items()}
        for row in rows.values()
    ]


def data_context(rd: RunData) -> dict:
    al = rd.summary.alignment
    rows = [
        {"role": role, "rows_in": fmt_int(n), "dropped": fmt_int(al.rows_dropped.get(role))}
        for role, n in al.rows_in.items()
    ]
    interp = [
        {"column": c, "filled": fmt_int(n), "flagged": fmt_int(al.flagged_rows.get(c))}
        for c, n in al.interpolated.items()
    ]
    missing = [{"column": c, "n": fmt_int(n)} for c, n in al.measurement_missing.items()]
    return {
        "figure": _overview_figure(rd),
        "rows": rows,
        "interpolated": interp,
        "gaps": _gap_rows(al),
        "missing": missing,
        "sources": _sources(al.sources),
        "hold": _hold_words(rd),
        "words": _alignment_words(al),
        "irradiance": rd.summary.irradiance_source or "?",
        "ground": rd.summary.ground_temperature,
    }


def _overview_figure(rd: RunData):
    """The figure of the inputs and measurements over the whole record, periods shaded,
    interpolated values marked, measurement gaps hatched."""
    from heritage_bayes.report.figures import fig_data_overview

    const = rd.idata.constant_data
    times = time_axis(const)
    codes = np.asarray(const["period"].values)
    dt = np.median(np.diff(times[:1000])) if times.size > 1 else np.timedelta64(3600, "s")
    units = _input_units(rd)
    inputs = [
        c
        for c in const.data_vars
        if c != "period" and not c.startswith("interpolated.") and not c.endswith("_slope")
    ]  # an input's change over the step (first-order hold) is not plotted
    flags = {
        c.split(".", 1)[1]: np.asarray(const[c].values).astype(bool)
        for c in const.data_vars
        if c.startswith("interpolated.")
    }
    panels = _panels(times, const, rd.idata.observed_data, inputs, units)
    return fig_data_overview(times, codes, panels, measurement_gaps(rd, dt), flags)


def _panels(times, const, obs, inputs: list[str], units: dict) -> list[dict]:
    """The overview's panels: temperatures, vapour pressures, RH, the daily means of the
    irradiances, then one per other input."""
    import pandas as pd

    from heritage_bayes.report.figures import C_MEAS

    used: set[str] = set()

    def series(name, label, style, source):
        used.add(name)
        return (name, f"{name} {label}", times, np.asarray(source[name].values, dtype=float), style)

    panels = []
    temp = [
        series(c, lab, st, const)
        for c, lab, st in (
            ("Te", "(outdoor)", {"color": "#7f8c8d", "lw": 0.6}),
            ("Tf", "(fixed / ground)", {"color": "#8e44ad", "lw": 1.0, "ls": "--"}),
        )
        if c in inputs
    ]
    if "Ti" in obs:
        temp.append(series("Ti", "(indoor, measured)", {"color": C_MEAS, "lw": 0.7}, obs))
    if temp:
        panels.append({"ylabel": "temperature [°C]", "series": temp})
    vap = (
        [series("Pe", "(outdoor)", {"color": "#7f8c8d", "lw": 0.6}, const)]
        if "Pe" in inputs
        else []
    )
    vap += [
        series(c, lab, st, const)
        for c, lab, st in (("Pf", "(fixed)", {"color": "#8e44ad", "lw": 1.0, "ls": "--"}),)
        if c in inputs
    ]
    if "Pi" in obs:
        vap.append(series("Pi", "(indoor, measured)", {"color": C_MEAS, "lw": 0.7}, obs))
    if vap:
        panels.append({"ylabel": "vapour pressure [Pa]", "series": vap})
    if "RHi" in obs:
        panels.append(
            {
                "ylabel": "relative humidity [%]",
                "series": [series("RHi", "(indoor, measured)", {"color": C_MEAS, "lw": 0.7}, obs)],
            }
        )
    irr = [c for c in inputs if units.get(c) == "W/m²" or c.startswith("I_")]
    if irr:
        ser = []
        for c in irr:
            daily = (
                pd.Series(np.asarray(const[c].values, dtype=float), index=pd.DatetimeIndex(times))
                .resample("1D")
                .mean()
            )
            ser.append(
                (
                    c,
                    f"{c} (daily mean)",
                    daily.index.values + np.timedelta64(12, "h"),
                    daily.to_numpy(),
                    {"lw": 1.0},
                )
            )
            used.add(c)
        panels.append({"ylabel": "solar irradiance [W/m²]", "series": ser})
    for c in inputs:
        if c not in used:
            u = units.get(c, "")
            panels.append(
                {
                    "ylabel": f"{c} [{u}]" if u else c,
                    "series": [series(c, "(input)", {"color": "#7f8c8d", "lw": 0.6}, const)],
                }
            )
    return panels


def _gap_rows(al) -> list[dict]:
    """One row per input or measurement gap of the alignment."""
    gaps = []
    for kind, key in (
        ("input (filled by interpolation)", "input_gaps"),
        ("measurement", "measurement_gaps"),
    ):
        for g in getattr(al, key):
            long = key == "input_gaps" and not g.filled
            gaps.append(
                {
                    "kind": "input (too long: not simulated, the record splits)" if long else kind,
                    "column": g.column,
                    "start": fmt_time(g.start),
                    "end": fmt_time(g.end),
                    "length": g.length,
                    "n": fmt_int(g.n_missing),
                    "filled": "yes" if g.filled else "no",
                }
            )
    return gaps


def _alignment_words(al) -> str:
    """The alignment in words: the grid, interpolated inputs, measurement gaps, rows
    outside the period."""
    n_interp = sum(int(v or 0) for v in al.interpolated.values())
    n_flag = sum(int(v or 0) for v in al.flagged_rows.values())
    spans: dict[tuple, list[str]] = {}
    for g in al.measurement_gaps:
        spans.setdefault((g.start, g.end), []).append(g.column)
    n_gap_meas = len(spans)
    words = (
        f"The data were aligned on a {al.step} grid from "
        f"{fmt_time(al.start)} to {fmt_time(al.end)} "
        f"({fmt_int(al.n_rows)} rows). "
    )
    if n_interp:
        words += (
            f"{fmt_int(n_interp)} missing input values were filled by interpolation "
            f"(gaps up to {al.max_gap}), affecting {fmt_int(n_flag)} "
            "rows (marked × in the figure). "
        )
    else:
        words += "No input value had to be interpolated. "
    if n_gap_meas:
        longest = max((g.length_hours for g in al.measurement_gaps), default=0.0)
        words += (
            f"The measurements have {n_gap_meas} "
            f"{'gap' if n_gap_meas == 1 else 'gaps'} (hatched; the longest "
            f"{longest:g} h): missing measurements are left out of the likelihood "
            "and the metrics, never filled. "
        )
    else:
        words += "The measurements have no gaps. "
    dropped = [
        f"{fmt_int(n)} {role.removesuffix('s')} rows"
        for role, n in al.rows_dropped.items()
        if int(n or 0)
    ]
    if dropped:
        words += f"{' and '.join(dropped)} lie outside this period and were not used."
    return words.strip()


def _hold_words(rd: RunData) -> str:
    """How the inputs were held over each step (``data.input_hold``)."""
    slopes = sorted({u for m in rd.run.models.values() for u in m.slope_inputs})
    if slopes:
        return (
            "Inputs as they were measured: interval averages constant over the interval "
            "they describe; readings at an instant linear between readings (the exact "
            f"first-order hold; `data.input_hold: exact`; inputs {', '.join(slopes)})."
        )
    return "Every input held at its mean over each step (`data.input_hold: interval_mean`)."


def section(ctx: dict) -> Section:
    """This section of the page, from the report context (figures already data URIs)."""
    return Section(TITLE, render_fragment("data.html", ctx), id=ID)
