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
    STANDARD_COLUMNS,
    _quote_list,
    check_choice,
    check_file,
    finalize,
    localize,
    modal_step,
    order_and_deduplicate,
    parse_timezone,
    source_name,
    validate_ranges,
)
from heritage_bayes.io.readers._csvtext import (
    parse_timestamps,
    parse_values,
    read_body,
    read_header,
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
    time_cols, skip_list = _check_options(duplicates, invalid, label, sort, time_column, skiprows)
    conversions = _unit_conversions(units)
    tz = parse_timezone(timezone) if timezone is not None else None
    na_list = list(na_values) if na_values is not None else []
    na_numeric = [float(v) for v in na_list if isinstance(v, int | float)]

    table, read_kw, stripped = read_header(path, name, sep, decimal, skiprows, encoding)
    wanted = _wanted_columns(name, columns, stripped)
    raw, lines, counts = read_body(
        table, read_kw, name, encoding, stripped, time_cols, wanted, na_list, skiprows, skip_list
    )
    raw, text, stamps, lines = parse_timestamps(
        raw, lines, name, time_cols, time_format, time_origin, invalid, counts
    )
    data = parse_values(raw, lines, name, wanted, decimal, na_numeric, conversions, invalid, counts)
    line_text = dict(zip(lines.tolist(), text.tolist(), strict=True))
    frame, lines, tz_label = _on_utc(data, stamps, text, lines, name, tz, timezone, counts)

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
    frame, averaged_cols, step = _interval_averages(frame, name, averaged, interval, label)
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


# ---------------------------------------------------------------------------------------
# The steps of read_csv, in order
# ---------------------------------------------------------------------------------------


def _check_options(
    duplicates: str, invalid: str, label: str, sort, time_column, skiprows
) -> tuple[list[str], list[int] | None]:
    """Validate the policy options of :func:`read_csv` before the file is opened.

    Returns
    -------
    time_cols : list of str
        The time column(s), as a list.
    skip_list : list of int or None
        The sorted distinct 0-based line numbers to skip, when ``skiprows`` is a sequence;
        None when it is a count of lines before the header.

    Raises
    ------
    heritage_bayes.errors.InputError
        An unknown policy, a non-boolean ``sort``, a time column that is not a name or a
        list of names, a negative or non-integer ``skiprows``.
    """
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
    return time_cols, skip_list


def _wanted_columns(name: str, columns, stripped: list[str]) -> dict[str, str]:
    """The ``{standard_name: header name}`` mapping to read.

    Default (``columns`` None): the header names that are standard names already.

    Raises
    ------
    heritage_bayes.errors.DataError
        No mapping given and no header name is a standard name.
    heritage_bayes.errors.InputError
        An empty or non-mapping ``columns``, an unknown standard name.
    """
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
    return {std: str(src).strip() for std, src in columns.items()}


def _on_utc(
    data: Mapping[str, np.ndarray],
    stamps,
    text: pd.Series,
    lines: np.ndarray,
    name: str,
    tz,
    timezone,
    counts: dict[str, int],
) -> tuple[pd.DataFrame, np.ndarray, str]:
    """Put the values on a UTC index: convert stamps with an offset, localize naive ones.

    Naive stamps are read on the clock ``tz`` (see :func:`read_csv`, Notes, for the
    daylight-saving policy); rows that cannot be placed are dropped and counted as
    ``ambiguous_dst`` and ``nonexistent_dst`` in ``counts``.

    Returns
    -------
    frame : pandas.DataFrame
        The values on their UTC times (not yet sorted or deduplicated).
    lines : numpy.ndarray of int
        The line numbers of the rows kept.
    tz_label : str
        The clock, for ``attrs["timezone"]``: ``str(timezone)`` or
        ``"from the timestamps"``.

    Raises
    ------
    heritage_bayes.errors.DataError
        Stamps with an offset and a ``timezone`` given, or naive stamps and none given.
    """
    stamp_index = pd.DatetimeIndex(stamps)
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
    return frame, lines[keep], tz_label


def _interval_averages(
    frame: pd.DataFrame, name: str, averaged, interval, label: str
) -> tuple[pd.DataFrame, tuple[str, ...], pd.Timedelta | None]:
    """Name the interval-average columns and put them on the interval-end convention.

    Returns
    -------
    frame : pandas.DataFrame
        With ``label="start"``, the averaged columns moved forward by one interval (to
        the end of the interval they average); otherwise unchanged.
    averaged_cols : tuple of str
        The averaged columns: ``averaged``, or by default the irradiance columns present.
    step : pandas.Timedelta or None
        The averaging interval: ``interval``, or the modal spacing of the index (None
        for a single row).

    Raises
    ------
    heritage_bayes.errors.InputError
        An averaged column that was not read, an ``interval`` that is not a positive
        duration.
    heritage_bayes.errors.DataError
        Averaged columns, one row and no ``interval``.
    """
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
    return frame, averaged_cols, step


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
