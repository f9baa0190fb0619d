"""Shared machinery of the readers: standard columns, validation, finalising.

Time zones, durations and JSON conversion live in :mod:`heritage_bayes.convert` (layer 0,
also used by ``rc/`` and ``inference/``); they are re-exported here for the readers.

Private module: the public API is re-exported by :mod:`heritage_bayes.io`.
"""

from __future__ import annotations

import csv
import datetime as _dt
import zlib
from collections.abc import Iterable, Mapping
from dataclasses import dataclass
from pathlib import Path

import numpy as np
import pandas as pd

from heritage_bayes.convert import format_timedelta, parse_timezone, to_jsonable
from heritage_bayes.errors import DataError, InputError, quoted

__all__ = [
    "AVERAGED_BY_DEFAULT",
    "IRRADIANCE_NOISE",
    "STANDARD_COLUMNS",
    "format_timedelta",
    "parse_timezone",
    "to_jsonable",
]

#: Standard column names: name -> (unit, description, (lower, upper) physical range).
STANDARD_COLUMNS: dict[str, tuple[str, str, tuple[float, float]]] = {
    "Te": ("°C", "outdoor air temperature", (-60.0, 70.0)),
    "RHe": ("%", "outdoor relative humidity (over water)", (0.0, 100.0)),
    "ghi": ("W/m²", "global horizontal irradiance", (0.0, 1500.0)),
    "dni": ("W/m²", "direct normal irradiance", (0.0, 1500.0)),
    "dhi": ("W/m²", "diffuse horizontal irradiance", (0.0, 1500.0)),
    "Ti": ("°C", "indoor air temperature", (-60.0, 70.0)),
    "RHi": ("%", "indoor relative humidity (over water)", (0.0, 100.0)),
    "Pe": ("Pa", "outdoor vapour pressure", (0.0, 35000.0)),
    "Pi": ("Pa", "indoor vapour pressure", (0.0, 35000.0)),
    "Tdew": ("°C", "outdoor dew-point temperature", (-80.0, 70.0)),
    "Tf": ("°C", "fixed (ground, neighbouring room) temperature", (-60.0, 70.0)),
    "Ph": ("W", "known heat input into the air node (heating power)", (-1e7, 1e7)),
    "Isol": (
        "W/m²",
        "measured irradiance used as a model input as is (a pyranometer in the plane of "
        "the glazing, a test cell's solar sensor)",
        (0.0, 1500.0),
    ),
    "wind": ("m/s", "wind speed (a weather station's, 10 m above the ground)", (0.0, 75.0)),
    "precip": ("mm", "precipitation of the interval ending at the stamp (water)", (0.0, 500.0)),
}

#: Columns that are interval averages (stamped at the interval end) unless told otherwise.
AVERAGED_BY_DEFAULT = ("ghi", "dni", "dhi", "Ph")
IRRADIANCE = ("ghi", "dni", "dhi", "Isol")
#: Negative irradiance down to this value [W/m²] is sensor noise (thermopile night
#: offset) and is set to 0; below it the value is invalid.
IRRADIANCE_NOISE = 10.0


def modal_step(index: pd.DatetimeIndex) -> pd.Timedelta | None:
    """Most frequent positive spacing of a sorted index (None with fewer than 2 stamps)."""
    if len(index) < 2:
        return None
    diffs = np.diff(index.asi8)
    diffs = diffs[diffs > 0]
    if diffs.size == 0:
        return None
    values, counts = np.unique(diffs, return_counts=True)
    return pd.Timedelta(int(values[np.argmax(counts)]), unit=index.unit)


def source_name(path) -> str:
    """How messages name a data file: its name (a workbook's with the sheet read)."""
    from heritage_bayes.io.readers.workbook import is_workbook, sheet_label

    return sheet_label(path) if is_workbook(path) and Path(path).is_file() else Path(path).name


def check_file(path) -> Path:
    path = Path(path)
    if not path.exists():
        raise DataError(f"{path}: file not found")
    if path.is_dir():
        raise DataError(f"{path}: is a directory, expected a data file")
    return path


# ---------------------------------------------------------------------------------------
# Localisation of wall-clock timestamps (DST policy)
# ---------------------------------------------------------------------------------------


@dataclass
class Localized:
    """UTC stamps for the rows that survived, and what was dropped."""

    utc: pd.DatetimeIndex
    keep: np.ndarray  # boolean mask over the input rows
    ambiguous_dropped: int
    nonexistent_dropped: int


def localize(naive: pd.DatetimeIndex, tz: _dt.tzinfo) -> Localized:
    """Attach time zone ``tz`` to wall-clock stamps ``naive`` (in file order) and go to UTC.

    Fixed offsets are exact. For a local clock with daylight-saving time:

    * a stamp in the repeated autumn hour is resolved by file order: within a run of
      consecutive rows inside the repeated hour, a stamp that does not increase on its
      predecessor starts the second pass (standard time); rows of the first pass are
      daylight time. A run with only one pass cannot be resolved and is dropped;
    * a stamp in the skipped spring hour does not exist on that clock and is dropped.
    """
    n = len(naive)
    if isinstance(tz, _dt.timezone):
        return Localized(naive.tz_localize(tz).tz_convert("UTC"), np.ones(n, bool), 0, 0)
    first = naive.tz_localize(tz, ambiguous="NaT", nonexistent="NaT")
    as_dst = naive.tz_localize(tz, ambiguous=np.ones(n, dtype=bool), nonexistent="NaT")
    nonexistent = np.asarray(as_dst.isna())
    ambiguous = np.asarray(first.isna()) & ~nonexistent
    keep = ~nonexistent
    dst_flags = np.ones(n, dtype=bool)
    amb_dropped = 0
    if ambiguous.any():
        pos = np.flatnonzero(ambiguous)
        values = naive.asi8
        # runs of consecutive ambiguous rows (in file order)
        breaks = np.flatnonzero(np.diff(pos) != 1) + 1
        for run in np.split(pos, breaks):
            passes = np.zeros(run.size, dtype=int)
            passes[1:] = np.cumsum(values[run[1:]] <= values[run[:-1]])
            if passes.max() == 0:
                keep[run] = False
                amb_dropped += run.size
                continue
            dst_flags[run] = passes == 0
            extra = run[passes >= 2]
            keep[extra] = False
            amb_dropped += extra.size
    kept = naive[keep]
    local = kept.tz_localize(tz, ambiguous=dst_flags[keep], nonexistent="raise")
    return Localized(local.tz_convert("UTC"), keep, amb_dropped, int(nonexistent.sum()))


# ---------------------------------------------------------------------------------------
# Value validation
# ---------------------------------------------------------------------------------------


def validate_ranges(
    frame: pd.DataFrame,
    lines: np.ndarray,
    name: str,
    source_columns: Mapping[str, str],
    invalid: str,
    counts: dict,
) -> dict[str, int]:
    """Check physical ranges in place; returns the number of clipped noise values per column.

    Irradiance in [-IRRADIANCE_NOISE, 0) is set to 0 (counted). Anything else outside the
    range of :data:`STANDARD_COLUMNS` raises (``invalid='raise'``) or becomes NaN.
    """
    clipped: dict[str, int] = {}
    for col in frame.columns:
        if col not in STANDARD_COLUMNS:
            continue
        unit, _, (lo, hi) = STANDARD_COLUMNS[col]
        values = frame[col].to_numpy(dtype=float, copy=True)
        if col in IRRADIANCE:
            noise = (values < 0) & (values >= -IRRADIANCE_NOISE)
            if noise.any():
                values[noise] = 0.0
                clipped[col] = int(noise.sum())
        with np.errstate(invalid="ignore"):
            bad = (values < lo) | (values > hi)
        if bad.any():
            first = int(np.flatnonzero(bad)[0])
            src = source_columns.get(col, col)
            lo_txt = -IRRADIANCE_NOISE if col in IRRADIANCE else lo
            if invalid == "raise":
                raise DataError(
                    f"{name}: column {quoted(src)} ({col}) line {int(lines[first])}: value "
                    f"{values[first]:g} {unit} is outside the physical range "
                    f"[{lo_txt:g}, {hi:g}] {unit} ({int(bad.sum())} such values)"
                    f"{_unit_hint(col, values)}; "
                    f"fix the file, declare sentinels with na_values=, or pass invalid='nan'"
                )
            values[bad] = np.nan
            counts["out_of_range"] = counts.get("out_of_range", 0) + int(bad.sum())
        frame[col] = values
    return clipped


def _unit_hint(col: str, values: np.ndarray) -> str:
    """A guess at the unit of a temperature column out of range: Kelvin or °F."""
    if STANDARD_COLUMNS[col][0] != "°C":
        return ""
    med = float(np.nanmedian(values)) if np.isfinite(values).any() else float("nan")
    if 200 <= med <= 340:
        return f"; the median {med:.1f} looks like Kelvin: subtract 273.15"
    if 32 <= med <= 130 and np.nanmax(values) > 70:
        return f"; the median {med:.1f} looks like °F: convert with (F - 32) / 1.8"
    return ""


# ---------------------------------------------------------------------------------------
# Ordering and duplicates
# ---------------------------------------------------------------------------------------

DUPLICATE_POLICIES = ("raise", "first", "last", "mean")
INVALID_POLICIES = ("raise", "nan")


def check_choice(value, allowed: Iterable[str], what: str) -> str:
    allowed = tuple(allowed)
    if value not in allowed:
        raise InputError(f"{what} must be one of {', '.join(map(repr, allowed))} (got {value!r})")
    return value


def order_and_deduplicate(
    frame: pd.DataFrame,
    name: str,
    *,
    duplicates: str,
    sort: bool,
    counts: dict,
    describe=None,
) -> pd.DataFrame:
    """Check the UTC index is increasing and unique, applying the duplicate policy.

    ``frame`` carries the file line of each row in a column ``"__line"`` (kept);
    ``describe(line)`` adds a description of that line's timestamp to messages. Rows that
    repeat a timestamp with identical values are dropped (counted in
    ``counts['identical_duplicates']``); conflicting duplicates follow ``duplicates``.
    """

    def where(i: int) -> str:
        line = int(frame["__line"].iloc[i])
        extra = describe(line) if describe else f"{frame.index[i]:%Y-%m-%d %H:%M:%S} UTC"
        return f"line {line} ({extra})"

    idx = frame.index.asi8
    if idx.size > 1:
        back = np.flatnonzero(np.diff(idx) < 0)
        if back.size:
            if not sort:
                i = int(back[0]) + 1
                raise DataError(
                    f"{name}: timestamps are not in increasing order: {where(i)} comes "
                    f"after {where(i - 1)}; {back.size} such step(s) back. Fix the file, or "
                    "sort the rows by time (config key sort: true; read_csv(..., sort=True))"
                )
            frame = frame.iloc[np.argsort(idx, kind="stable")]
            counts["sorted"] = int(back.size)
    if frame.index.has_duplicates:
        values = frame.drop(columns="__line").reset_index()
        identical = values.duplicated(keep="first").to_numpy()
        if identical.any():
            counts["identical_duplicates"] = int(identical.sum())
            frame = frame[~identical]
        conflicting = frame.index.duplicated(keep="first")
        if conflicting.any():
            n = int(conflicting.sum())
            if duplicates == "raise":
                i = int(np.flatnonzero(conflicting)[0])
                j = int(np.flatnonzero(frame.index == frame.index[i])[0])
                raise DataError(
                    f"{name}: {n} duplicate timestamp(s) with different values; first on "
                    f"{where(i)}, the same UTC time as {where(j)}. Pass duplicates='first', "
                    f"'last' or 'mean' (config key duplicates: first) to resolve them, or "
                    "fix the file"
                )
            counts["duplicates"] = n
            if duplicates == "mean":
                frame = frame.groupby(level=0, sort=True).mean()
            else:
                frame = frame[~frame.index.duplicated(keep=duplicates)]
    return frame


def finalize(
    frame: pd.DataFrame,
    *,
    source: str,
    fmt: str,
    averaged: Iterable[str],
    interval,
    counts: dict,
    clipped: dict,
    extra: Mapping | None = None,
) -> pd.DataFrame:
    """Set the index name/unit and the documented ``attrs``."""
    frame = frame.astype(float)
    frame.index = pd.DatetimeIndex(frame.index).tz_convert("UTC").as_unit("ns")
    frame.index.name = "time"
    attrs = {
        "source": source,
        "format": fmt,
        "units": {c: STANDARD_COLUMNS[c][0] for c in frame.columns if c in STANDARD_COLUMNS},
        "averaged": tuple(c for c in averaged if c in frame.columns),
        "interval": format_timedelta(interval) if interval is not None else None,
        "label": "interval averages stamped at the interval end; others at the reading",
        "dropped": {k: int(v) for k, v in counts.items() if v},
        "clipped": {k: int(v) for k, v in clipped.items() if v},
    }
    if any(c in frame.columns for c in IRRADIANCE):
        attrs["irradiance_source"] = "measured"
    if extra:
        attrs.update(extra)
    frame.attrs = attrs
    return frame


def _quote_list(names: Iterable[str], limit: int = 30) -> str:
    """Names for a message: each cut to 40 characters, at most ``limit`` of them."""
    names = list(names)
    shown = [repr(n) if len(str(n)) <= 40 else repr(str(n)[:40]) + "..." for n in names[:limit]]
    more = f", ... ({len(names)} in all)" if len(names) > limit else ""
    return ", ".join(shown) + more


#: What a damaged or truncated compressed file raises while it is read.
READ_ERRORS = (OSError, EOFError, zlib.error)


def damaged(name: str, exc: BaseException) -> DataError:
    """The error for a file that cannot be read to its end."""
    return DataError(f"{name}: cannot read the file (damaged or truncated?): {exc}")


def looks_like_table(path: Path, sep, skiprows=None, encoding: str = "utf-8") -> bool:
    """Whether a text file's first lines split into one number (two or more) of fields
    by ``sep``: a table, whose header may be quoted in a message. A file that does not
    (``/etc/passwd`` given as a logger file) is named, its lines never shown: they may
    not be the user's. True when it cannot tell (a regex separator, a list of rows to
    skip)."""
    import gzip

    if not isinstance(sep, str) or len(sep) != 1 or not isinstance(skiprows, int | None):
        return True
    try:
        with gzip.open(path, "rb") if path.suffix == ".gz" else open(path, "rb") as fh:
            head = fh.read(1 << 16)
    except READ_ERRORS:
        return True  # the reader names a damaged file
    text = head.decode(encoding if encoding else "utf-8", errors="replace")
    lines = [ln for ln in text.splitlines()[(skiprows or 0) :][:21] if ln.strip()]
    if len(head) == 1 << 16 and len(lines) > 1:
        lines = lines[:-1]  # the last line may be cut by the sample's end
    if not lines:
        return False
    widths = [len(next(csv.reader([ln], delimiter=sep))) for ln in lines]
    same = sum(w == widths[0] for w in widths[1:])
    return widths[0] >= 2 and same >= 0.8 * (len(widths) - 1)


#: Byte-order marks of UTF-16 text ("Unicode text" of Excel and Windows tools).
UTF16_BOMS = (b"\xff\xfe", b"\xfe\xff")


def text_encoding(head: bytes, declared: str | None = "utf-8") -> str | None:
    """The encoding to read a text file with: UTF-16 when it starts with a UTF-16
    byte-order mark and the declared encoding is the default UTF-8 (an export saved as
    "Unicode text"), otherwise the declared one."""
    utf8 = declared is None or declared.lower().replace("_", "-") in ("utf-8", "utf8", "utf-8-sig")
    return "utf-16" if utf8 and head.startswith(UTF16_BOMS) else declared


def sniff_text(path: Path, name: str, size: int = 1 << 16, encoding: str | None = "utf-8"):
    """Refuse a binary file, or one without a line break early on, before pandas reads
    it whole (a 100 MB 'header' of NUL bytes); return the encoding to read it with
    (:func:`text_encoding`: a UTF-16 export is text, not a binary file)."""
    import gzip

    try:
        with gzip.open(path, "rb") if path.suffix == ".gz" else open(path, "rb") as fh:
            head = fh.read(size)
    except READ_ERRORS as exc:
        raise damaged(name, exc) from None
    encoding = text_encoding(head, encoding)
    wide = str(encoding).lower().replace("_", "-").startswith(("utf-16", "utf16", "utf-32"))
    text = head.decode(encoding, errors="replace") if wide else None
    if (b"\x00" in head) if text is None else ("\x00" in text):
        raise DataError(
            f"{name}: a binary file (NUL bytes in the first {len(head)} bytes), not a text table"
        )
    if len(head) == size and b"\n" not in head and b"\r" not in head:
        raise DataError(f"{name}: no line break in the first {size} bytes: not a text table")
    return encoding
