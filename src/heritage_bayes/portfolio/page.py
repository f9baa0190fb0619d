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
from heritage_bayes.portfolio.rooms import STATUSES
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

#: The overview's three tables: (id, heading, columns); a column is (key, header,
#: format). Each table fits the page at 1280 px; on a phone each room becomes a card
#: (one line per column), so no table scrolls sideways.
_TABLES = [
    (
        "calibration",
        "Calibration",
        [
            ("attention_rank", "#", "{:d}"),
            ("room", "room", "{}"),
            ("verdict", "status", "status"),
            ("unconverged_reasons", "why not converged", "{}"),
            ("max_rhat", "max R-hat", "{:.3f}"),
            ("thermal.Ti.FIT_cal", "FIT Ti cal [%]", "{:.1f}"),
            ("thermal.Ti.FIT_val", "FIT Ti val [%]", "{:.1f}"),
            ("thermal.Ti.coverage90_val", "90 % band covers, Ti val", "pct"),
            ("hygric.Pi.FIT_cal", "FIT Pi cal [%]", "{:.1f}"),
            ("hygric.Pi.FIT_val", "FIT Pi val [%]", "{:.1f}"),
            ("thermal.tau_1_h", "slowest τ thermal [h]", "{:.0f}"),
            ("hygric.tau_1_h", "slowest τ hygric [h]", "{:.0f}"),
            ("message", "message", "{}"),
        ],
    ),
    (
        "measured-risk",
        "Conservation risk of the measured climate",
        [
            ("attention_rank", "#", "{:d}"),
            ("room", "room", "{}"),
            ("risk_flags", "indicators at risk", "risk"),
            ("twpi_years", "TWPI [years]", "{:.0f}"),
            ("emc_range_pct", "EMC range [% MC]", "{:.1f}"),
            ("mould_index_max", "mould index max", "{:.2f}"),
            ("en15757_outside_pct", "outside EN 15757 band [% h]", "{:.1f}"),
            ("risk_note", "note", "{}"),
        ],
    ),
    (
        "projection",
        "Projection: the most severe case against the baseline",
        [
            ("attention_rank", "#", "{:d}"),
            ("room", "room", "{}"),
            ("proj.case", "most severe case", "{}"),
            ("proj.twpi.change", "Δ TWPI [years]", "{:+.1f}"),
            ("proj.twpi.p_worse", "P(TWPI worse)", "pct"),
            ("proj.vtt_mould_index_max.change", "Δ mould index max", "{:+.2f}"),
            ("proj.vtt_mould_index_max.p_worse", "P(mould worse)", "pct"),
            ("proj.en15757_outside_baseline.change", "Δ outside baseline EN 15757 band [% h]",
             "{:+.1f}"),
            ("proj.statement_text", "statement", "{}"),
            ("proj.probability", "P(statement)", "pct"),
        ],
    ),
]  # fmt: skip
#: Every column of the page (the rooms' link and rank repeat in each table).
_COLUMNS = [c for _, _, cols in _TABLES for c in cols]

#: The status of a room whose calibration task failed, by the task's ``status``.
_TASK_FAILED = {"failed": "failed", "error": "internal error"}
_STATUS_CLASS = {"converged": "ok", "checks failed": "warn", "not converged": "bad"}

# One card per room on a phone: the header row hidden, each cell a line "label  value"
# (the label from its data-label attribute); nothing wider than the screen.
_STYLE = """<style>
table.rooms { width: 100%; }
table.rooms th { font-size: 0.92em; }
table.rooms td.msg .v { overflow-wrap: anywhere; }
@media (max-width: 760px) {
  table.rooms, table.rooms tbody, table.rooms tr, table.rooms td { display: block; }
  table.rooms thead { display: none; }
  table.rooms tr { border: 1px solid var(--line); border-radius: 4px; margin: 0 0 10px; }
  table.rooms td { border: none; border-bottom: 1px solid #eee; display: flex; gap: 10px;
                   justify-content: space-between; text-align: right; white-space: normal; }
  table.rooms td::before { content: attr(data-label); font-weight: 600; text-align: left;
                           flex: 0 0 42%; }
  table.rooms td .v { min-width: 0; overflow-wrap: anywhere; }
}
</style>"""


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


def _status(r) -> tuple[str, str, str]:
    """(status, what the report's verdict says, css class) of one row."""
    task = str(r.get("status"))
    if task in _TASK_FAILED:
        return _TASK_FAILED[task], "", "bad"
    status = r.get("verdict")
    if not isinstance(status, str) or not status:  # a row of an older version
        status = "converged" if bool(r.get("converged")) else "not converged"
    title = r.get("verdict_title")
    title = title if isinstance(title, str) and status == "checks failed" else ""
    return status, title, _STATUS_CLASS.get(status, "")


def _row_cells(r, cols, out: Path) -> str:
    import html

    cells = []
    for key, header, fmt in cols:
        cls = "num" if fmt not in ("{}", "status", "risk") else ""
        if fmt == "status":
            status, title, scls = _status(r)
            text = f"<b class='{scls}'>{html.escape(status)}</b>"
            if title:
                text += f"<br><small>{html.escape(title)}</small>"
            order = (*_TASK_FAILED.values(), *STATUSES)
            sort = str(order.index(status)) if status in order else ""
        else:
            value = r.get(key)
            if key == "proj.statement_text" and not isinstance(value, str):
                value = r.get("proj.statement")
            text, sort = _cell(value, fmt)
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
                cls = "msg"
                msg = html.escape(str(value or "")[:600]).replace("/", "/<wbr>")  # paths
                text = f"<span class='pre-wrap'>{msg}</span>"
        attr = f" class='{cls}'" if cls else ""
        cells.append(
            f"<td{attr} data-label='{html.escape(header)}' data-v='{html.escape(sort)}'>"
            f"<span class='v'>{text}</span></td>"
        )
    return "".join(cells)


def render_index(pf: Portfolio, df: pd.DataFrame, out: Path) -> str:
    """The portfolio's ``index.html``: a self-contained page (no network access) with
    the rooms in attention order, in three tables (calibration, measured risk,
    projection), each sortable by any column, linking each room's calibration report
    and projection page. A room's status is its report's verdict (converged, checks
    failed, not converged); shares and probabilities in %."""
    import html

    from heritage_bayes._version import __version__
    from heritage_bayes.report.page import render_page

    tables = []
    for tid, heading, all_cols in _TABLES:
        cols = [c for c in all_cols if c[0] in df.columns or c[2] == "status"]
        if tid == "calibration" and "message" in df.columns:
            if not df["message"].fillna("").astype(str).str.strip().any():
                cols = [c for c in cols if c[0] != "message"]
        if len(cols) <= 2:  # rank and room only: nothing to show
            continue
        head = "".join(
            f"<th scope='col' title='click to sort'>{html.escape(t)}</th>" for _, t, _ in cols
        )
        body = []
        for _, r in df.iterrows():
            tr_cls = " class='bad'" if str(r.get("status")) in _TASK_FAILED else ""
            body.append(f"<tr{tr_cls}>{_row_cells(r, cols, out)}</tr>")
        tables.append(
            f"<h3 id='{tid}'>{html.escape(heading)}</h3>"
            f"<table class='sortable rooms' id='table-{tid}'><thead><tr>{head}</tr></thead>"
            f"<tbody>{''.join(body)}</tbody></table>"
        )
    n = len(pf.rooms)
    n_ok = int(df["status"].isin(["done", "skipped"]).sum()) if len(df) else 0
    counts = {s: 0 for s in STATUSES}
    for _, r in df.iterrows():
        status = _status(r)[0]
        if status in counts:
            counts[status] += 1
    intro = (
        f"<p>{n_ok} of {n} room(s) calibrated ({len(df)} finished): "
        f"<b class='ok'>{counts['converged']} converged</b>, "
        f"<b class='warn'>{counts['checks failed']} converged but their report's checks "
        f"fail</b>, <b class='bad'>{counts['not converged']} not converged</b> "
        "(<code>hbayes batch</code> exits with code 3 when a room is unconverged and none "
        "failed). A room's status is its report's verdict: <em>checks failed</em> means the "
        "sampler converged but the residual, coverage, known-truth or accuracy checks "
        "of its report fail. "
        "Rows are in <strong>attention order</strong>: rooms whose calibration failed or did "
        "not converge first, then those whose checks fail (their figures cannot be trusted "
        "yet), then the most conservation-risk indicators rated <em>risk</em> by their "
        "published thresholds, then the shortest time-weighted preservation index (TWPI). "
        "The risk columns are computed from each room's <em>measured</em> indoor climate "
        "over its data period; the mould index, ASHRAE classes and the EN 15757 band need a "
        "year of data and show “–” for shorter logs. Rooms with a projection file add the "
        "projected change of their most severe case (the warmest scenario and horizon) "
        "relative to their baseline: the median change over the paired draws (noise "
        "included) and the probability that the indicator gets worse; the case links to "
        "the projection page. Click a column header to sort by it.</p>"
    )
    return render_page(
        f"Portfolio — {pf.name}",
        [("Rooms", _STYLE + intro + "".join(tables))],
        subtitle=pf.notes,
        generator=f"heritage_bayes {__version__}",
        script=_SORT_JS,
    )
