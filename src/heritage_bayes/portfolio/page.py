"""The portfolio's ``index.html``: rooms in attention order, sortable, linked reports."""

from __future__ import annotations

import math
import os
from pathlib import Path

import numpy as np
import pandas as pd

from heritage_bayes.climate.risk.registry import indicator_info
from heritage_bayes.errors import InputError
from heritage_bayes.format import fmt_pct
from heritage_bayes.portfolio.spec import Portfolio

__all__ = ["render_index"]


# Sorting by a click on a column header: the page's only script, allowed by its hash in
# the Content-Security-Policy (no other script, no network access).
_SORT_JS = """
document.querySelectorAll('table.sortable th').forEach(function (th, col) {
  th.addEventListener('click', function () {
    var tbody = th.closest('table').tBodies[0];
    var rows = Array.prototype.slice.call(tbody.rows);
    var asc = th.getAttribute('aria-sort') !== 'ascending';
    th.closest('tr').querySelectorAll('th').forEach(function (h) {
      h.removeAttribute('aria-sort');
    });
    th.setAttribute('aria-sort', asc ? 'ascending' : 'descending');
    rows.sort(function (a, b) {
      var x = a.cells[col].getAttribute('data-v'), y = b.cells[col].getAttribute('data-v');
      var nx = parseFloat(x), ny = parseFloat(y);
      var c = (!isNaN(nx) && !isNaN(ny)) ? nx - ny : String(x).localeCompare(String(y));
      return asc ? c : -c;
    });
    rows.forEach(function (r) { tbody.appendChild(r); });
  });
});
""".strip()

_COLUMNS = [
    ("attention_rank", "#", "{:d}"),
    ("room", "room", "{}"),
    ("status", "status", "{}"),
    ("converged", "converged", "{}"),
    ("unconverged_reasons", "why not converged", "{}"),
    ("max_rhat", "max R-hat", "{:.3f}"),
    ("thermal.Ti.FIT_cal", "FIT Ti cal [%]", "{:.1f}"),
    ("thermal.Ti.FIT_val", "FIT Ti val [%]", "{:.1f}"),
    ("thermal.Ti.coverage90_val", "90 % band covers, Ti val", "pct"),
    ("hygric.Pi.FIT_cal", "FIT Pi cal [%]", "{:.1f}"),
    ("hygric.Pi.FIT_val", "FIT Pi val [%]", "{:.1f}"),
    ("thermal.tau_1_h", "slowest τ thermal [h]", "{:.0f}"),
    ("hygric.tau_1_h", "slowest τ hygric [h]", "{:.0f}"),
    ("risk_flags", "indicators at risk", "risk"),
    ("twpi_years", "TWPI [years]", "{:.0f}"),
    ("emc_range_pct", "EMC range [% MC]", "{:.1f}"),
    ("mould_index_max", "mould index max", "{:.2f}"),
    ("en15757_outside_pct", "outside EN 15757 band [% h]", "{:.1f}"),
    ("risk_note", "measured-risk note", "{}"),
    ("proj.case", "projection: most severe case", "{}"),
    ("proj.twpi.change", "Δ TWPI [years]", "{:+.1f}"),
    ("proj.twpi.p_worse", "P(TWPI worse)", "pct"),
    ("proj.vtt_mould_index_max.change", "Δ mould index max", "{:+.2f}"),
    ("proj.vtt_mould_index_max.p_worse", "P(mould worse)", "pct"),
    ("proj.en15757_outside_baseline.change", "Δ outside baseline EN 15757 band [% h]", "{:+.1f}"),
    ("proj.probability", "P(statement)", "pct"),
    ("proj.statement", "statement", "{}"),
    ("message", "message", "{}"),
]


def _cell(value, fmt: str) -> tuple[str, str]:
    """(display text, sort key) of one table cell."""
    if value is None or (isinstance(value, float) and not math.isfinite(value)):
        return "–", ""
    if isinstance(value, bool | np.bool_):
        return ("yes" if value else "no"), str(int(value))
    if fmt == "pct":  # a share or a probability, in % as on the rooms' reports
        return fmt_pct(value), str(value)
    if fmt == "{:d}":
        try:
            value = int(value)
        except (TypeError, ValueError):
            return str(value), str(value)
    try:
        text = fmt.format(value)
    except (TypeError, ValueError):
        text = str(value)
    return text, str(value)


def _flagged_text(count, codes: str) -> str:
    """``2: mould index (VTT), EN 15757 band`` — the count and the indicators' names."""
    names = [c.strip() for c in codes.split(",") if c.strip()]
    if not names:
        return "0" if count in (None, 0) else str(count)
    readable = []
    for n in names:
        try:
            readable.append(indicator_info(n).name)
        except InputError:  # a column this version does not know: its code
            readable.append(n)
    return f"{len(names)}: " + ", ".join(readable)


def render_index(pf: Portfolio, df: pd.DataFrame, out: Path) -> str:
    """The portfolio's ``index.html``: a self-contained page (no network access) with
    one row per room in attention order, sortable by any column, linking each room's
    calibration report."""
    import html

    from heritage_bayes._version import __version__
    from heritage_bayes.report.page import render_page

    cols = [c for c in _COLUMNS if c[0] in df.columns]
    head = "".join(
        f"<th scope='col' title='click to sort'>{html.escape(t)}</th>" for _, t, _ in cols
    )
    body = []
    for _, r in df.iterrows():
        cells = []
        for key, _, fmt in cols:
            text, sort = _cell(r.get(key), fmt)
            text = html.escape(text)
            if key == "room" and r.get("report"):
                rel = os.path.relpath(str(r["report"]), start=str(out))
                text = f"<a href='{html.escape(Path(rel).as_posix())}'>{text}</a>"
            if key == "proj.case" and isinstance(r.get("projection"), str) and r["projection"]:
                rel = os.path.relpath(str(r["projection"]), start=str(out))
                text = f"<a href='{html.escape(Path(rel).as_posix())}'>{text}</a>"
            if key == "risk_flags" and isinstance(r.get("risk_flagged"), str):
                text = html.escape(_flagged_text(r.get(key), r["risk_flagged"]))
            if key == "message":
                text = f"<span class='pre-wrap'>{html.escape(str(r.get(key) or '')[:600])}</span>"
            cls = " class='num'" if fmt != "{}" else ""
            cells.append(f"<td{cls} data-v='{html.escape(sort)}'>{text}</td>")
        status = str(r.get("status"))
        tr_cls = " class='bad'" if status in ("failed", "error") else ""
        body.append(f"<tr{tr_cls}>" + "".join(cells) + "</tr>")
    n = len(pf.rooms)
    n_ok = int(df["status"].isin(["done", "skipped"]).sum()) if len(df) else 0
    n_conv = int(df.get("converged", pd.Series(dtype=bool)).fillna(False).astype(bool).sum())
    intro = (
        f"<p>{n_ok} of {n} room(s) calibrated ({len(df)} finished), {n_conv} converged, "
        f"{n_ok - n_conv} finished unconverged (<code>hbayes batch</code> exits with code 3 "
        "when a room is unconverged and none failed). "
        "Rows are in <strong>attention order</strong>: rooms whose calibration failed or did "
        "not converge first (their figures cannot be trusted yet), then the most "
        "conservation-risk indicators rated <em>risk</em> by their published thresholds, "
        "then the shortest time-weighted preservation index (TWPI). The risk columns are "
        "computed from each room's <em>measured</em> indoor climate over its data period; "
        "the mould index, ASHRAE classes and the EN 15757 band need a year of data and show "
        "“–” for shorter logs. Rooms with a projection file add the projected change of "
        "their most severe case (the warmest scenario and horizon) relative to their "
        "baseline: the median change over the paired draws (noise included) and the "
        "probability that the indicator gets worse; the case links to the projection page. "
        "Click a column header to sort by it.</p>"
    )
    table = (
        "<div class='scroll'><table class='sortable'><thead><tr>"
        + head
        + "</tr></thead><tbody>"
        + "".join(body)
        + "</tbody></table></div>"
    )
    return render_page(
        f"Portfolio — {pf.name}",
        [("Rooms", intro + table)],
        subtitle=pf.notes,
        generator=f"heritage_bayes {__version__}",
        script=_SORT_JS,
    )
