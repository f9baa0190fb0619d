"""Excel workbooks (``.xlsx``, ``.xlsm``) read as the delimited text of their first sheet.

Logger software and spreadsheets export ``.xlsx`` as often as CSV. :func:`workbook_text`
turns the first worksheet into comma-separated text (dates and times as
``YYYY-MM-DD HH:MM:SS``, numbers with a decimal point, empty cells empty), so that
:func:`heritage_bayes.io.read_csv` and :func:`heritage_bayes.io.loggers.inspect_table`
read a workbook exactly as they read a CSV file: a config names it with ``format: csv``.
Read with openpyxl (read-only, cached values of formulas).
"""

from __future__ import annotations

import csv
import datetime as _dt
import io
from pathlib import Path

from heritage_bayes.errors import DataError

__all__ = ["WORKBOOK_SUFFIXES", "is_workbook", "table_source", "workbook_text"]

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


def workbook_text(path) -> str:
    """The first worksheet of an Excel workbook as comma-separated text.

    Raises
    ------
    heritage_bayes.errors.DataError
        Not a readable workbook (the message names the file).
    """
    import zipfile

    from openpyxl import load_workbook

    path = Path(path)
    try:
        wb = load_workbook(path, read_only=True, data_only=True)
    except (OSError, zipfile.BadZipFile, KeyError, ValueError) as exc:
        raise DataError(f"{path.name}: cannot read the workbook: {exc}") from None
    try:
        ws = wb.worksheets[0]
        buf = io.StringIO()
        w = csv.writer(buf, lineterminator="\n")
        for row in ws.iter_rows(values_only=True):
            w.writerow([_cell(v) for v in row])
    finally:
        wb.close()
    return buf.getvalue()


def table_source(path):
    """A callable giving what :func:`pandas.read_csv` reads: the path itself, or for a
    workbook a fresh text buffer of its first sheet each call."""
    if not is_workbook(path):
        return lambda: path
    text = workbook_text(path)
    return lambda: io.StringIO(text)
