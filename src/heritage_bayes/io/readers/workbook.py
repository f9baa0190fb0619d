"""Excel workbooks (``.xlsx``, ``.xlsm``) read as the delimited text of their first sheet.

Logger software and spreadsheets export ``.xlsx`` as often as CSV. :func:`workbook_text`
turns the first worksheet into comma-separated text (dates and times as
``YYYY-MM-DD HH:MM:SS``, numbers with a decimal point, empty cells empty), so that
:func:`heritage_bayes.io.read_csv` and :func:`heritage_bayes.io.loggers.inspect_table`
read a workbook exactly as they read a CSV file: a config names it with ``format: csv``.
Read with openpyxl (read-only, cached values of formulas).

Only the first sheet is read; messages about a workbook name it
(:func:`sheet_label`), so that data on another sheet are not a mystery. A first sheet
without any value, while another sheet has some, is refused naming both. Formulas are
read through the values Excel stores with them; a file written by a program that
stores none (a script, some exporters) is refused, naming the sheet and the first such
cell: open and save it in Excel or LibreOffice, which computes and stores them.
"""

from __future__ import annotations

import csv
import datetime as _dt
import io
from pathlib import Path

from heritage_bayes.errors import DataError, quoted

__all__ = ["WORKBOOK_SUFFIXES", "is_workbook", "sheet_label", "table_source", "workbook_text"]

WORKBOOK_SUFFIXES = (".xlsx", ".xlsm")


def is_workbook(path) -> bool:
    return Path(path).suffix.lower() in WORKBOOK_SUFFIXES


def _cell(v) -> str:
    if v is None:
        return ""
    if isinstance(v, _dt.datetime):
        return v.strftime("%Y-%m-%d %H:%M:%S")
    if isinstance(v, _dt.date):
        return v.strftime("%Y-%m-%d")
    if isinstance(v, _dt.time):
        return v.strftime("%H:%M:%S")
    if isinstance(v, float):
        return repr(v)
    return str(v)


def _open(path: Path, data_only: bool = True):
    import zipfile

    from openpyxl import load_workbook

    try:
        return load_workbook(path, read_only=True, data_only=data_only)
    except (OSError, zipfile.BadZipFile, KeyError, ValueError) as exc:
        raise DataError(f"{path.name}: cannot read the workbook: {exc}") from None


def sheet_label(path) -> str:
    """How messages name a workbook: ``book.xlsx, sheet 'Readings'``, and with several
    sheets which one is read: ``book.xlsx, sheet 'Cover' (the first of 'Cover',
    'Data': only the first is read)``."""
    path = Path(path)
    wb = _open(path)
    try:
        names = list(wb.sheetnames)
    finally:
        wb.close()
    if not names:
        return path.name
    label = f"{path.name}, sheet {quoted(names[0], 40)}"
    if len(names) > 1:
        shown = ", ".join(quoted(n, 40) for n in names[:8]) + (", ..." if len(names) > 8 else "")
        label += f" (the first of {shown}: only the first is read)"
    return label


def _column_letter(i: int) -> str:
    from openpyxl.utils import get_column_letter

    return get_column_letter(i + 1)


def _formula_without_value(path: Path, sheet: str, rows: list[tuple]) -> str | None:
    """The first cell (``C2``) holding a formula whose value the file does not store,
    among the cells empty in ``rows`` (the sheet read with stored values)."""
    wb = _open(path, data_only=False)
    try:
        for r, raw in enumerate(wb[sheet].iter_rows(values_only=True)):
            got = rows[r] if r < len(rows) else ()
            for c, v in enumerate(raw):
                if isinstance(v, str) and v.startswith("=") and (c >= len(got) or got[c] is None):
                    return f"{_column_letter(c)}{r + 1}"
    finally:
        wb.close()
    return None


def workbook_text(path) -> str:
    """The first worksheet of an Excel workbook as comma-separated text.

    Raises
    ------
    heritage_bayes.errors.DataError
        Not a readable workbook; its first sheet empty while another is not; cells
        with formulas but no stored values (the message names the file, the sheet and
        the first such cell).
    """
    path = Path(path)
    wb = _open(path)
    try:
        sheets = list(wb.sheetnames)
        ws = wb.worksheets[0]
        rows = [tuple(r) for r in ws.iter_rows(values_only=True)]
        filled = [n for n in sheets[1:] if _has_values(wb[n])] if not _any(rows) else []
    finally:
        wb.close()
    if not _any(rows) and filled:
        raise DataError(
            f"{path.name}: its first sheet {quoted(sheets[0], 40)}, the one read, holds no "
            f"value; the data seem to be on sheet {quoted(filled[0], 40)}: move that sheet "
            "first (or save it as CSV) and read the file again"
        )
    header = rows[0] if rows else ()
    gaps = any(
        c < len(header) and header[c] is not None and v is None
        for row in rows[1:]
        for c, v in enumerate(row)
    )
    if gaps or any(v is None for v in header):
        cell = _formula_without_value(path, sheets[0], rows)
        if cell is not None:
            raise DataError(
                f"{path.name}, sheet {quoted(sheets[0], 40)}: cell {cell} holds a formula "
                "whose value the file does not store (it was written by a program that "
                "does not compute formulas): the values are missing. Open the file in Excel "
                "or LibreOffice and save it again (that stores the values), or export CSV"
            )
    buf = io.StringIO()
    w = csv.writer(buf, lineterminator="\n")
    for row in rows:
        w.writerow([_cell(v) for v in row])
    return buf.getvalue()


def _any(rows) -> bool:
    return any(v is not None and v != "" for row in rows for v in row)


def _has_values(ws) -> bool:
    return any(v is not None and v != "" for row in ws.iter_rows(values_only=True) for v in row)


def table_source(path):
    """A callable giving what :func:`pandas.read_csv` reads: the path itself, or for a
    workbook a fresh text buffer of its first sheet each call."""
    if not is_workbook(path):
        return lambda: path
    text = workbook_text(path)
    return lambda: io.StringIO(text)
