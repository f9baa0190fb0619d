"""The text-table steps of :func:`~heritage_bayes.io.readers.csvfile.read_csv`.

Header, rows, timestamps and numbers, in the order ``read_csv`` takes them: each step
reads or parses one thing and raises a :class:`~heritage_bayes.errors.DataError` naming
the file, the column and the line when the file does not hold what was declared (or,
with ``invalid="nan"``, drops or blanks it and counts it in ``counts``, which becomes
``attrs["dropped"]``).
"""

from __future__ import annotations

from collections.abc import Callable, Mapping

import numpy as np
import pandas as pd

from heritage_bayes.errors import DataError, InputError, quoted
from heritage_bayes.io._common import READ_ERRORS, _quote_list, damaged, sniff_text

__all__ = ["parse_timestamps", "parse_values", "read_body", "read_header"]


def read_header(
    path, name: str, sep: str, decimal: str, skiprows, encoding: str
) -> tuple[Callable, dict, list[str]]:
    """Open the table (delimited text or a workbook's first sheet) and read its header.

    Returns
    -------
    table : callable
        Returns a fresh readable source of the table on each call.
    read_kw : dict
        ``sep``, ``skiprows`` and ``encoding`` for :func:`pandas.read_csv` (the encoding
        sniffed from the text; None for a workbook, which arrives as text already).
    stripped : list of str
        The header names without surrounding whitespace.

    Raises
    ------
    heritage_bayes.errors.DataError
        An empty file, an unreadable header, a damaged file.
    heritage_bayes.errors.InputError
        A workbook with another separator or decimal mark than ``","`` and ``"."``.
    """
    from heritage_bayes.io.readers.workbook import is_workbook, table_source

    read_kw = {"sep": sep, "skiprows": skiprows, "encoding": encoding}
    if is_workbook(path):  # the first sheet as CSV text (see .workbook)
        if (sep, decimal) != (",", "."):
            raise InputError(f"{name}: a workbook is read as sep ',' and decimal '.'")
        read_kw["encoding"] = None
    else:
        read_kw["encoding"] = sniff_text(path, name, encoding=encoding)
    table = table_source(path)
    try:
        header = pd.read_csv(table(), nrows=0, **read_kw)
    except pd.errors.EmptyDataError as exc:
        raise DataError(f"{name}: file is empty, expected a header line") from exc
    except (pd.errors.ParserError, UnicodeDecodeError) as exc:
        raise DataError(f"{name}: cannot read the header: {exc}") from exc
    except READ_ERRORS as exc:
        raise damaged(name, exc) from None
    return table, read_kw, [str(c).strip() for c in header.columns]


def _position(name: str, stripped: list[str], col: str) -> int:
    """The 0-based position of header name ``col``, which must appear exactly once."""
    hits = [i for i, c in enumerate(stripped) if c == col]
    if not hits:
        raise DataError(
            f"{name}: column {quoted(col)} not found; columns are: {_quote_list(stripped)}"
        )
    if len(hits) > 1:
        raise DataError(
            f"{name}: column name {quoted(col)} appears {len(hits)} times in the header"
        )
    return hits[0]


def read_body(
    table: Callable,
    read_kw: dict,
    name: str,
    encoding: str,
    stripped: list[str],
    time_cols: list[str],
    wanted: Mapping[str, str],
    na_list: list,
    skiprows,
    skip_list: list[int] | None,
) -> tuple[pd.DataFrame, np.ndarray, dict[str, int]]:
    """Read the rows of the used columns as text, with their line numbers in the file.

    Every row is read as strings (parsing follows, with errors naming the line); rows
    whose used cells are all empty are dropped and counted as ``blank_rows``.

    Returns
    -------
    raw : pandas.DataFrame
        The time and value columns (header names), one row per non-blank data line.
    lines : numpy.ndarray of int
        The 1-based line number in the file of each row of ``raw``.
    counts : dict of str to int
        ``{"blank_rows": n}`` when blank rows were dropped, else empty; the later steps
        add their own counts to it.

    Raises
    ------
    heritage_bayes.errors.DataError
        A missing or repeated column name, a malformed table (rows with more fields than
        the header), text not in the given encoding, a damaged file.
    """
    time_pos = [_position(name, stripped, c) for c in time_cols]
    value_pos = {std: _position(name, stripped, src) for std, src in wanted.items()}
    usecols = sorted(set(time_pos) | set(value_pos.values()))
    try:
        raw = pd.read_csv(
            table(),
            header=0,
            index_col=False,
            dtype=str,
            na_values=[str(v) for v in na_list] or None,
            skip_blank_lines=False,
            **read_kw,
        )
    except pd.errors.ParserError as exc:
        raise DataError(f"{name}: malformed table: {exc}") from exc
    except UnicodeDecodeError as exc:
        encoding = read_kw["encoding"] or encoding  # the sniffed one, or the one given
        raise DataError(f"{name}: not {encoding}-encoded text ({exc}); pass encoding=") from exc
    except READ_ERRORS as exc:
        raise damaged(name, exc) from None
    if raw.shape[1] != len(stripped):
        raise DataError(f"{name}: malformed table: rows have more fields than the header")
    raw = raw.iloc[:, usecols]
    raw.columns = [stripped[i] for i in usecols]
    if skip_list is None:
        lines = np.arange(len(raw)) + skiprows + 2  # 1-based line numbers, header on skiprows+1
    else:  # the lines pandas kept: header first, then the body
        kept, skip, i = [], set(skip_list), 0
        while len(kept) < len(raw) + 1:
            if i not in skip:
                kept.append(i + 1)
            i += 1
        lines = np.asarray(kept[1:], dtype=int)
    counts: dict[str, int] = {}
    blank = raw.isna().all(axis=1).to_numpy()
    if blank.any():
        counts["blank_rows"] = int(blank.sum())
        raw = raw[~blank]
        lines = lines[~blank]
    return raw, lines, counts


def parse_timestamps(
    raw: pd.DataFrame,
    lines: np.ndarray,
    name: str,
    time_cols: list[str],
    time_format: str | None,
    time_origin: str | None,
    invalid: str,
    counts: dict[str, int],
):
    """Parse the time column(s) into timestamps (naive, or carrying their UTC offset).

    Several time columns are joined with one space. With ``time_origin`` the text is
    elapsed seconds since that instant; otherwise it is parsed with ``time_format``
    (inferred from the first stamp when None; mixed UTC offsets are parsed to UTC).

    Returns
    -------
    raw, text, stamps, lines
        The rows whose timestamp parsed (all rows, or with ``invalid="nan"`` the others
        dropped and counted as ``bad_timestamps`` in ``counts``), their joined time text,
        their timestamps and their line numbers.

    Raises
    ------
    heritage_bayes.errors.DataError
        With ``invalid="raise"``, an unparseable timestamp (its text, column(s), line and
        the expected format).
    """
    parts = [raw[c].str.strip() for c in time_cols]
    text = parts[0]
    for part in parts[1:]:
        text = text + " " + part
    if time_origin is not None:
        secs = pd.to_numeric(text, errors="coerce")
        stamps = pd.Timestamp(time_origin) + pd.to_timedelta(secs, unit="s")
        time_format = "seconds since " + str(time_origin)
    else:
        try:
            stamps = pd.to_datetime(text, format=time_format, errors="coerce")
        except ValueError:  # mixed UTC offsets
            stamps = pd.to_datetime(text, format=time_format, errors="coerce", utc=True)
    bad = stamps.isna().to_numpy()
    if bad.any():
        i = int(np.flatnonzero(bad)[0])
        if invalid == "raise":
            expected = f"format {time_format!r}" if time_format else "the format of line 2"
            shown = text.iloc[i] if isinstance(text.iloc[i], str) else ""
            raise DataError(
                f"{name}: cannot parse timestamp {quoted(shown)} in column(s) "
                f"{_quote_list(time_cols)} on line {int(lines[i])} (expected {expected}); "
                f"{int(bad.sum())} bad timestamp(s). Fix the file or pass invalid='nan' to "
                f"drop such rows"
            )
        counts["bad_timestamps"] = int(bad.sum())
        raw, text, stamps, lines = raw[~bad], text[~bad], stamps[~bad], lines[~bad]
    return raw, text, stamps, lines


def parse_values(
    raw: pd.DataFrame,
    lines: np.ndarray,
    name: str,
    wanted: Mapping[str, str],
    decimal: str,
    na_numeric: list[float],
    conversions: Mapping[str, Callable],
    invalid: str,
    counts: dict[str, int],
) -> dict[str, np.ndarray]:
    """Parse each value column to floats in its standard unit.

    The decimal mark is replaced by ``"."``, numeric missing-value markers become NaN and
    declared units are converted (see :data:`UNIT_CONVERSIONS`). Empty cells are NaN.

    Returns
    -------
    dict of str to numpy.ndarray
        ``{standard_name: values}`` in the order of ``wanted``.

    Raises
    ------
    heritage_bayes.errors.DataError
        With ``invalid="raise"``, a non-empty cell that is not a number (column, line,
        text); with ``invalid="nan"`` such cells are NaN, counted as
        ``unparseable_values`` in ``counts``.
    """
    data = {}
    for std, src in wanted.items():
        cell = raw[src].str.strip()
        if decimal != ".":
            cell = cell.str.replace(decimal, ".", regex=False)
        num = pd.to_numeric(cell, errors="coerce").astype(float)
        unparsed = (num.isna() & cell.notna() & (cell != "")).to_numpy()
        if unparsed.any():
            i = int(np.flatnonzero(unparsed)[0])
            if invalid == "raise":
                raise DataError(
                    f"{name}: column {quoted(src)} line {int(lines[i])}: cannot parse "
                    f"{quoted(raw[src].iloc[i])} as a number (decimal mark {decimal!r}); "
                    f"{int(unparsed.sum())} such value(s). Declare missing-value markers "
                    f"with na_values= or pass invalid='nan'"
                )
            counts["unparseable_values"] = counts.get("unparseable_values", 0) + int(unparsed.sum())
        values = num.to_numpy(copy=True)
        if na_numeric:
            values[np.isin(values, na_numeric)] = np.nan
        if std in conversions:
            values = conversions[std](values)
        data[std] = values
    return data
