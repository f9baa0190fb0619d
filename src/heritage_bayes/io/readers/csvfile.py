"""Reader of generic CSV files (data loggers, exported weather): :func:`read_csv`.

Column mapping to standard names, units, local clocks, the time-stamp label (start or end
of an averaging interval) and the duplicate and invalid-value policies. See
:mod:`heritage_bayes.io` for the conventions every reader follows.
"""

from __future__ import annotations

from collections.abc import Iterable, Mapping, Sequence
from os import PathLike

import numpy as np
import pandas as pd

from heritage_bayes.errors import DataError, InputError, quoted
from heritage_bayes.io._common import (
    AVERAGED_BY_DEFAULT,
    DUPLICATE_POLICIES,
    INVALID_POLICIES,
    READ_ERRORS,
    STANDARD_COLUMNS,
    _quote_list,
    check_choice,
    check_file,
    damaged,
    finalize,
    localize,
    modal_step,
    order_and_deduplicate,
    parse_timezone,
    sniff_text,
    source_name,
    validate_ranges,
)

__all__ = ["read_csv"]

_LABELS = ("end", "start")


def read_csv(
    path: str | PathLike,
    *,
    time_column: str | Sequence[str],
    columns: Mapping[str, str] | None = None,
    time_format: str | None = None,
    timezone=None,
    time_origin: str | None = None,
    sep: str = ",",
    decimal: str = ".",
    averaged: Iterable[str] | None = None,
    interval=None,
    label: str = "end",
    duplicates: str = "raise",
    sort: bool = False,
    invalid: str = "raise",
    na_values: Iterable | None = None,
    skiprows: int | Sequence[int] = 0,
    encoding: str = "utf-8",
    units: Mapping[str, str] | None = None,
) -> pd.DataFrame:
    """Read a delimited text table (logger export, weather service) into standard columns.

    Parameters
    ----------
    path : str or path-like
        The file: delimited text, or an Excel workbook (``.xlsx``, ``.xlsm``: its first
        sheet, see :mod:`heritage_bayes.io.readers.workbook`). Header names are compared
        after stripping surrounding whitespace (logger exports often pad them); CRLF line
        ends are fine.
    time_column : str or sequence of str
        Column holding the timestamp, or several columns whose values are joined with a
        single space before parsing (e.g. ``("Year", "Month", "Day", "Hour (UTC)")`` with
        ``time_format="%Y %m %d %H"``).
    columns : mapping of str to str, optional
        ``{standard_name: source_column}``, e.g. ``{"Ti": "TEMP C", "RHi": "%RH"}``.
        Standard names and units: ``Te`` [°C], ``RHe`` [%], ``ghi``, ``dni``, ``dhi``
        [W/m²], ``Ti`` [°C], ``RHi`` [%], ``Pe``, ``Pi`` [Pa], ``Tdew`` [°C]. Default: the
        file's columns that already carry a standard name.
    time_format : str, optional
        :func:`~datetime.datetime.strptime` format, e.g. ``"%d-%m-%Y %H:%M"``. Default:
        inferred from the first timestamp (and every row must then match it).
    time_origin : str, optional
        The time column holds elapsed **seconds** since this instant (e.g.
        ``"2016-03-01 00:00"``, on the clock of ``timezone``), as test-cell and
        simulation exports do (pySIP's ``Time``). ``time_format`` is then not used.
    timezone : str or tzinfo, optional
        Clock of the naive timestamps: ``"UTC"``, a fixed offset (``"UTC+2"``,
        ``"UTC-03:30"``; no DST) or an IANA zone with DST (``"Europe/Copenhagen"``).
        Required unless every timestamp carries its own UTC offset (ISO 8601 ``+02:00``
        or ``Z``), in which case it must be omitted.
    sep, decimal : str
        Field separator and decimal mark (``sep=";", decimal=","`` for many European
        exports).
    averaged : iterable of str, optional
        Standard names of the columns that are interval averages (or sums expressed as
        mean rates). Default: the irradiance columns present (``ghi``, ``dni``, ``dhi``).
        Pass ``()`` when the file holds instantaneous (or centred) irradiance values.
    interval : str or Timedelta, optional
        Length of the averaging interval [e.g. ``"1h"``]. Default: the most frequent
        spacing of the timestamps.
    label : {"end", "start"}, default "end"
        Where the file stamps its interval averages. With ``"start"`` the averaged
        columns are moved to the interval end (``+interval``), the returned convention.
    duplicates : {"raise", "first", "last", "mean"}, default "raise"
        What to do with rows that share a UTC timestamp but have different values
        (rows that repeat a timestamp with identical values are always dropped and
        counted). Daylight-saving repeats are handled before this step (see Notes).
    sort : bool, default False
        Sort rows whose UTC timestamps go backwards; by default that is an error.
    invalid : {"raise", "nan"}, default "raise"
        Unparseable timestamps, unparseable numbers and values outside physical ranges
        (T outside −60..70 °C, RH outside 0..100 %, irradiance below −10 W/m² or above
        1500 W/m²): raise a :class:`~heritage_bayes.errors.DataError` naming the file,
        column and line, or drop the row (bad timestamp) / set the value to NaN, counted
        in ``attrs["dropped"]``.
    na_values : iterable, optional
        Extra markers of missing values, e.g. ``[-9999, "ERR"]`` (empty cells, ``NA``,
        ``NaN`` and ``null`` are always missing).
    skiprows : int or sequence of int, default 0
        Lines to skip before the header line, or the 0-based numbers of the lines to
        skip anywhere (logger exports put metadata lines before the header and between
        it and the data: Tinytag Explorer, Rotronic HW4; see
        :mod:`heritage_bayes.io.loggers`).
    encoding : str, default "utf-8"
        ``"utf-8-sig"`` for a file starting with a byte-order mark, ``"cp1252"`` for an
        export of older Windows software.
    units : mapping of str to str, optional
        ``{standard_name: unit in the file}`` for columns not in the standard unit,
        converted on reading: temperatures ``"°F"`` or ``"K"`` (to °C), relative
        humidity ``"fraction"`` (0-1, to %); see :data:`UNIT_CONVERSIONS`.

    Returns
    -------
    pandas.DataFrame
        UTC index ``time``; one float column per entry of ``columns`` (in that order).
        ``attrs``: ``source``, ``format``, ``timezone``, ``units``, ``averaged``,
        ``interval``, ``dropped`` (counts of rows or values removed and why), ``clipped``
        (irradiance noise set to 0) and ``irradiance_source``.

    Raises
    ------
    heritage_bayes.errors.DataError
        Missing file, missing column (the message lists the columns that exist), bad
        timestamps or values (file, column, line), timestamps going backwards, duplicate
        timestamps with conflicting values.

    Notes
    -----
    Daylight-saving policy for a local clock (IANA ``timezone``):

    * **repeated autumn hour**: resolved by file order. Inside a run of consecutive rows
      stamped in the repeated hour, the first pass is daylight time and a stamp that does
      not increase on its predecessor starts the second pass (standard time). When the
      file holds only one pass (the logger skipped or overwrote the repeat), the pass
      cannot be placed and its rows are dropped, counted as ``ambiguous_dst``;
    * **skipped spring hour**: stamps inside it do not exist on that clock; such rows
      (a logger that did not switch in time) are dropped, counted as ``nonexistent_dst``.
      Otherwise the spring hour is simply absent, a one-hour gap.

    Nothing is ever duplicated: after conversion to UTC the index is checked for order
    and uniqueness.

    Examples
    --------
    >>> df = read_csv("oerholm.csv", sep=";", time_column="DATE AND TIME",
    ...               time_format="%d-%m-%Y %H:%M", timezone="Europe/Copenhagen",
    ...               columns={"Ti": "TEMP C", "RHi": "%RH"},
    ...               duplicates="first")  # doctest: +SKIP
    """
    path = check_file(path)
    name = source_name(path)
    check_choice(duplicates, DUPLICATE_POLICIES, "duplicates")
    check_choice(invalid, INVALID_POLICIES, "invalid")
    check_choice(label, _LABELS, "label")
    if not isinstance(sort, bool):
        raise InputError(f"sort must be True or False (got {sort!r})")
    time_cols = [time_column] if isinstance(time_column, str) else list(time_column)
    if not time_cols or not all(isinstance(c, str) for c in time_cols):
        raise InputError(
            f"time_column must be a column name or a list of names ({quoted(time_column)})"
        )
    skip_list = None
    if not isinstance(skiprows, int | bool) and isinstance(skiprows, Sequence):
        if not all(isinstance(i, int) and not isinstance(i, bool) and i >= 0 for i in skiprows):
            raise InputError(f"skiprows: line numbers must be non-negative integers ({skiprows!r})")
        skip_list = sorted(set(skiprows))
    elif isinstance(skiprows, bool) or not isinstance(skiprows, int) or skiprows < 0:
        raise InputError(f"skiprows must be a non-negative integer (got {skiprows!r})")
    conversions = _unit_conversions(units)
    tz = parse_timezone(timezone) if timezone is not None else None
    na_list = list(na_values) if na_values is not None else []
    na_numeric = [float(v) for v in na_list if isinstance(v, int | float)]
    read_kw = {"sep": sep, "skiprows": skiprows, "encoding": encoding}

    # -- header --------------------------------------------------------------------------
    from heritage_bayes.io.readers.workbook import is_workbook, table_source

    if is_workbook(path):  # the first sheet as CSV text (see .workbook)
        if (sep, decimal) != (",", "."):
            raise InputError(f"{name}: a workbook is read as sep ',' and decimal '.'")
        read_kw["encoding"] = None
    else:
        read_kw["encoding"] = encoding = sniff_text(path, name, encoding=encoding)
    table = table_source(path)
    try:
        header = pd.read_csv(table(), nrows=0, **read_kw)
    except pd.errors.EmptyDataError as exc:
        raise DataError(f"{name}: file is empty, expected a header line") from exc
    except (pd.errors.ParserError, UnicodeDecodeError) as exc:
        raise DataError(f"{name}: cannot read the header: {exc}") from exc
    except READ_ERRORS as exc:
        raise damaged(name, exc) from None
    stripped = [str(c).strip() for c in header.columns]

    if columns is None:
        columns = {c: c for c in stripped if c in STANDARD_COLUMNS}
        if not columns:
            raise DataError(
                f"{name}: no column has a standard name and no columns= mapping was given; "
                f"columns are: {_quote_list(stripped)}; pass e.g. "
                f"columns={{'Ti': {quoted(stripped[-1])}}}"
            )
    if not isinstance(columns, Mapping) or not columns:
        raise InputError("columns must be a non-empty mapping {standard_name: source_column}")
    unknown = [k for k in columns if k not in STANDARD_COLUMNS]
    if unknown:
        raise InputError(
            f"columns: unknown standard name(s) {_quote_list(unknown)}; standard names are "
            f"{_quote_list(STANDARD_COLUMNS)}"
        )
    wanted = {std: str(src).strip() for std, src in columns.items()}

    def position(col: str) -> int:
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

    time_pos = [position(c) for c in time_cols]
    value_pos = {std: position(src) for std, src in wanted.items()}
    usecols = sorted(set(time_pos) | set(value_pos.values()))

    # -- body ------------------------------------------------------------------------------
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

    # -- timestamps ------------------------------------------------------------------------
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

    # -- values ----------------------------------------------------------------------------
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

    # -- time zone -------------------------------------------------------------------------
    stamp_index = pd.DatetimeIndex(stamps)
    line_text = dict(zip(lines.tolist(), text.tolist(), strict=True))
    if stamp_index.tz is not None:
        if tz is not None:
            raise DataError(
                f"{name}: timestamps carry their own UTC offset (line {int(lines[0])}: "
                f"{quoted(text.iloc[0])}); omit timezone= (got {timezone!r})"
            )
        utc = stamp_index.tz_convert("UTC")
        keep = np.ones(len(utc), dtype=bool)
        tz_label = "from the timestamps"
    else:
        if tz is None:
            raise DataError(
                f"{name}: timestamps have no UTC offset (line {int(lines[0])}: "
                f"{quoted(text.iloc[0])}); pass timezone=, e.g. 'UTC', 'UTC+2' or "
                f"'Europe/Copenhagen'"
            )
        loc = localize(stamp_index, tz)
        utc, keep = loc.utc, loc.keep
        counts["ambiguous_dst"] = loc.ambiguous_dropped
        counts["nonexistent_dst"] = loc.nonexistent_dropped
        tz_label = str(timezone)
    frame = pd.DataFrame({k: v[keep] for k, v in data.items()}, index=utc)
    lines = lines[keep]

    clipped = validate_ranges(frame, lines, name, wanted, invalid, counts)
    frame["__line"] = lines
    frame = order_and_deduplicate(
        frame,
        name,
        duplicates=duplicates,
        sort=sort,
        counts=counts,
        describe=lambda line: quoted(line_text[int(line)]),
    )
    frame = frame.drop(columns="__line")

    # -- interval averages -----------------------------------------------------------------
    if averaged is None:
        averaged_cols = tuple(c for c in AVERAGED_BY_DEFAULT if c in frame.columns)
    else:
        averaged_cols = (averaged,) if isinstance(averaged, str) else tuple(averaged)
        missing = [c for c in averaged_cols if c not in frame.columns]
        if missing:
            raise InputError(
                f"averaged: {_quote_list(missing)} not among the columns read "
                f"({_quote_list(frame.columns)})"
            )
    step = _as_timedelta(interval, "interval") if interval is not None else modal_step(frame.index)
    if averaged_cols and step is None:
        raise DataError(f"{name}: cannot infer the averaging interval from one row; pass interval=")
    if label == "start" and averaged_cols:
        frame = _shift_columns(frame, averaged_cols, step)

    return finalize(
        frame,
        source=str(path),
        fmt="csv",
        averaged=averaged_cols,
        interval=step,
        counts=counts,
        clipped=clipped,
        extra={"timezone": tz_label, "source_columns": dict(wanted)},
    )


#: Units a column may be declared in (``units=``) and their conversion to the standard
#: unit: temperatures to °C, relative humidity to %.
UNIT_CONVERSIONS = {
    "temperature": {
        "°C": lambda v: v,
        "°F": lambda v: (v - 32.0) / 1.8,
        "K": lambda v: v - 273.15,
    },
    "humidity": {"%": lambda v: v, "fraction": lambda v: 100.0 * v},
}
_KIND = {"Te": "temperature", "Ti": "temperature", "Tdew": "temperature", "Tf": "temperature"}
_KIND |= {"RHe": "humidity", "RHi": "humidity"}


def _unit_conversions(units) -> dict:
    if units is None:
        return {}
    if not isinstance(units, Mapping):
        raise InputError(f"units must be a mapping {{standard_name: unit}} (got {units!r})")
    out = {}
    for std, unit in units.items():
        kind = _KIND.get(std)
        if kind is None:
            raise InputError(
                f"units.{std}: only temperatures (Te, Ti, Tdew, Tf) and relative "
                f"humidities (RHe, RHi) take a unit"
            )
        table = UNIT_CONVERSIONS[kind]
        if unit not in table:
            raise InputError(f"units.{std}: one of {', '.join(map(repr, table))} (got {unit!r})")
        out[std] = table[unit]
    return out


def _as_timedelta(value, what: str) -> pd.Timedelta:
    try:
        td = pd.Timedelta(value)
    except (ValueError, TypeError) as exc:
        raise InputError(
            f"{what} must be a duration such as '1h' or '10min' (got {value!r})"
        ) from exc
    if td <= pd.Timedelta(0):
        raise InputError(f"{what} must be positive (got {value!r})")
    return td


def _shift_columns(frame: pd.DataFrame, cols: Sequence[str], by: pd.Timedelta) -> pd.DataFrame:
    """Move ``cols`` forward in time by ``by`` (start-stamped averages to end stamps)."""
    others = [c for c in frame.columns if c not in cols]
    moved = frame[list(cols)].copy()
    moved.index = moved.index + by
    if not others:
        return moved
    out = frame[others].join(moved, how="outer")
    return out[list(frame.columns)]
