"""Recognising a logger or weather export: layout, time column, columns, units.

:func:`inspect_table` reads the first lines of a delimited text export and works out
what :func:`heritage_bayes.io.read_csv` needs to read it (``skiprows``, ``sep``,
``decimal``, ``encoding``, the time column and its format, the columns of temperature,
relative humidity and irradiance with their units), saying for each guess why. It knows
the exports of the loggers found in heritage buildings, as their layouts are published in
the code and test files of public projects that read them:

``hobo``
    Onset HOBOware CSV: a ``Plot Title:`` line, then a header whose time column names
    the clock (``Date Time, GMT+01:00``), values such as ``Temp, °C (LGR S/N: ...)`` or
    ``Temp, °F``, times ``%m/%d/%y %I:%M:%S %p``. Layout as in the test files of
    building-energy/hoboreader (``tests/sample_hobo_u12_data.csv``,
    ``tests/sample_hobo_pendant_data.csv``) and the format list of the ``hobo`` package
    by D. A. Riggs (Lava Beds National Monument).
``hanwell``
    Hanwell stand-alone logger export: a preamble (``Database Valid``, ``Sensor:``,
    ``Data Starts:``, ``No. of Readings:``), then ``Time, Temperature (C),Humidity
    (RH(%)),`` and times ``%H:%M:%S %d/%b/%Y``. Layout as in abazemore/dataloggergraphs
    (``tests/testthat/fixtures/hanwell/Hanwell.csv``, ``R/parse.R: parse_hanwell``).
``meaco``
    Meaco radio-transmitter export: ``RECEIVER,TRANSMITTER,DATE,TEMPERATURE,HUMIDITY``
    with quoted names and ``%Y-%m-%d %H:%M``; abazemore/dataloggergraphs
    (``fixtures/meaco/Meaco_1.csv``, ``parse_meaco``).
``tinytag``
    Gemini Tinytag Explorer CSV: header ``,Time,1,2``, then the lines ``S/N``, ``Type``,
    ``Description`` and ``Property`` (which names the channels ``Temperature``,
    ``Humidity``) before the data; abazemore/dataloggergraphs
    (``fixtures/tinytag/TinyTag_1.csv``, ``parse_tinytag``).
``rotronic``
    Rotronic HW4 export: sections ``[#I]``, ``[#S]``, one per channel (``[#1]``
    ``Humidity = %rh``, ``[#2]`` ``Temperature = °C``), the header after ``[#H]``
    (``Date,Time,Humidity,Temperature``), the data after ``[#D]``, dates
    ``%d/%m/%Y`` and times ``%H:%M:%S`` in two columns; comma- or tab-separated
    (the ``.xls`` export is tab-separated text). abazemore/dataloggergraphs
    (``fixtures/tinytag/Rotronic_1.csv``, ``parse_rotronic``).
``generic``
    Any delimited table with one header line (``,``, ``;`` or tab; decimal comma with
    ``;``), found by the consistency of its field counts.
"""

from __future__ import annotations

import csv
import itertools
import re
from dataclasses import dataclass, field
from datetime import datetime
from pathlib import Path

import numpy as np

from heritage_bayes.errors import DataError, quoted
from heritage_bayes.io._common import UTF16_BOMS, _quote_list, source_name

__all__ = ["ColumnGuess", "TableLayout", "inspect_table"]

_SAMPLE_LINES = 2000
#: The longest line of an export read [characters]: hundreds of channels fit.
_MAX_LINE = 1 << 16

#: Time formats tried on the time column (strptime), most specific first.
TIME_FORMATS = (
    "%Y-%m-%d %H:%M:%S",
    "%Y-%m-%d %H:%M",
    "%Y-%m-%dT%H:%M:%S",
    "%Y-%m-%dT%H:%M",
    "%Y/%m/%d %H:%M:%S",
    "%Y/%m/%d %H:%M",
    "%d-%m-%Y %H:%M:%S",
    "%d-%m-%Y %H:%M",
    "%d.%m.%Y %H:%M:%S",
    "%d.%m.%Y %H:%M",
    "%d/%m/%Y %H:%M:%S",
    "%d/%m/%Y %H:%M",
    "%m/%d/%Y %H:%M:%S",
    "%m/%d/%Y %H:%M",
    "%d/%m/%y %H:%M:%S",
    "%d/%m/%y %H:%M",
    "%m/%d/%y %H:%M:%S",
    "%m/%d/%y %H:%M",
    "%m/%d/%y %I:%M:%S %p",
    "%m/%d/%Y %I:%M:%S %p",
    "%m/%d/%Y %I:%M %p",
    "%d/%m/%Y %I:%M:%S %p",
    "%H:%M:%S %d/%b/%Y",
    "%H:%M %d/%b/%Y",
)

# Column roles by header text (case-insensitive); order matters: first match wins.
_ROLE_PATTERNS = (
    ("wind", r"wind.?(speed|spd)|^ws\d*$|^wind$|^ff$|^fh$|windsnelheid|tuulen ?nopeus"),
    ("precip", r"precip|^rain|rainfall|neerslag|sademäärä|niederschlag"),
    (
        "skip",
        r"wind|precip|rain|press|batt|lux|\buv\b|co2|dew|^#$|logged|host|stopped|"
        r"end of file|coupler|alarm|setpoint|receiver|transmitter|^ws$|^wd$",
    ),
    ("dhi", r"\bdhi\b|diffus|^r_?dif|rdif"),
    ("dni", r"\bdni\b|direct|beam"),
    ("ghi", r"\bghi\b|glob|rglob|irradi|radiation|solar|pyrano|sw_?down|^q$"),
    ("RH", r"\brh|humid|feucht|kosteus|%rh|^u$|^rh"),
    ("T", r"temp|^t$|^t[ _(]|^ta$|^te$|^ti$|°c|°f|deg ?[cf]|lämpö|^t\d*$"),
)


@dataclass
class ColumnGuess:
    """One column of the table and what it was taken for.

    ``kind``: ``"T"`` (temperature), ``"RH"``, ``"ghi"``, ``"dhi"``, ``"dni"``,
    ``"wind"`` (wind speed), ``"precip"`` (precipitation [mm]) or None;
    ``unit``: the unit in the file (``"°C"``, ``"°F"``, ``"K"``, ``"%"``,
    ``"fraction"``, ``"W/m²"``); ``why``: the evidence; ``stats``: min, median, max of
    the sampled values; ``named``: the role its name suggests, also when the values
    refuse it (an RH column out of range or empty); ``labelled``: the name states the
    unit (``°C``, ``(F)``, ``kelvin``).
    """

    name: str
    kind: str | None
    unit: str | None = None
    why: str = ""
    stats: tuple[float, float, float] | None = None
    named: str | None = None
    labelled: bool = False


@dataclass
class TableLayout:
    """What :func:`inspect_table` found: the options of
    :func:`heritage_bayes.io.read_csv` and the evidence for each."""

    path: Path
    layout: str
    encoding: str
    sep: str
    decimal: str
    skiprows: int | list[int]
    header: list[str]
    time_column: str | list[str]
    time_format: str
    timezone: str | None
    columns: list[ColumnGuess] = field(default_factory=list)
    notes: list[str] = field(default_factory=list)

    def first(self, kind: str) -> ColumnGuess | None:
        """The first column taken for ``kind``."""
        return next((c for c in self.columns if c.kind == kind), None)

    def all(self, kind: str) -> list[ColumnGuess]:
        return [c for c in self.columns if c.kind == kind]


def _decode(path: Path) -> tuple[str, str]:
    from heritage_bayes.io.readers.workbook import is_workbook, workbook_text

    if is_workbook(path):
        return workbook_text(path), "utf-8"
    data = path.read_bytes()[: 1 << 22]
    if data.startswith(UTF16_BOMS):  # "Unicode text": UTF-16 with its byte-order mark
        text = data[: len(data) // 2 * 2].decode("utf-16", errors="replace")
        if "\x00" not in text[:2048]:
            return text, "utf-16"
    if b"\x00" in data[:4096]:
        raise DataError(
            f"{path.name}: a binary file, not a text table (workbooks are read when named "
            ".xlsx or .xlsm; save others as CSV)"
        )
    if data.startswith(b"\xef\xbb\xbf"):
        return data[3:].decode("utf-8", errors="replace"), "utf-8-sig"
    try:
        return data.decode("utf-8"), "utf-8"
    except UnicodeDecodeError as exc:
        if exc.start > len(data) - 4:  # a character cut by the sample's end
            return data[: exc.start].decode("utf-8"), "utf-8"
        return data.decode("cp1252", errors="replace"), "cp1252"


def _split(line: str, sep: str) -> list[str]:
    return next(csv.reader([line], delimiter=sep)) if line else []


def _sep_for(lines: list[str]) -> str:
    """The separator giving the most consistent multi-field rows over the last lines;
    among equals, the one whose table starts earliest (its header line has the same
    width: ``;`` over ``,`` in a file with decimal commas)."""
    body = [ln for ln in lines[-200:] if ln.strip()]
    best, best_key = ",", None
    for sep in (",", ";", "\t"):
        counts = [len(_split(ln, sep)) for ln in body]
        if not counts:
            continue
        mode = max(set(counts), key=counts.count)
        score = counts.count(mode) / len(counts) if mode > 1 else 0.0
        widths = [len(_split(ln, sep)) for ln in lines[:200]]
        start = next((k for k, w in enumerate(widths) if w == mode), len(widths))
        key = (round(score, 2), -start, mode)
        if best_key is None or key > best_key:
            best, best_key = sep, key
    return best


def _number(text: str, decimal: str) -> float | None:
    t = text.strip().strip('"')
    if decimal == ",":
        t = t.replace(",", ".")
    try:
        return float(t)
    except ValueError:
        return None


def _time_format(values: list[str]) -> str | None:
    """The format that parses every value and gives increasing times with the fewest
    distinct steps (tells ``%d/%m`` from ``%m/%d``)."""
    vals = [v.strip() for v in values if v and v.strip()]
    if not vals:
        return None
    if all(
        re.match(r"^\d{4}-\d\d-\d\d[T ]\d\d:\d\d(:\d\d(\.\d+)?)?(Z|[+-]\d\d:?\d\d)$", v)
        for v in vals[:50]
    ):
        return "ISO8601"
    best, best_key = None, None
    for fmt in TIME_FORMATS:
        try:
            ts = [datetime.strptime(v, fmt) for v in vals]
        except ValueError:
            continue
        steps = np.diff([t.timestamp() for t in ts])
        key = (int((steps < 0).sum()), len(set(steps.tolist())))
        if best_key is None or key < best_key:
            best, best_key = fmt, key
    return best


def _zone_in(text: str) -> str | None:
    """A clock named in a header: ``t_UTC+2`` -> ``UTC+2``, ``GMT+01:00`` -> ``UTC+01:00``."""
    m = re.search(r"(?:UTC|GMT)\s*([+-])\s*(\d{1,2})(?::?(\d{2}))?", text, re.IGNORECASE)
    if m:
        sign, h, mm = m.groups()
        return f"UTC{sign}{int(h)}" + (f":{mm}" if mm and mm != "00" else "")
    if re.search(r"\b(UTC|GMT)\b", text, re.IGNORECASE):
        return "UTC"
    return None


def _layout(lines: list[str]) -> tuple[str, int, list[int], str | None]:
    """(layout, header line, extra lines to skip after it, separator or None)."""
    head = [ln.strip() for ln in lines[:40]]
    if head and head[0].strip('"').startswith("Plot Title:"):
        return "hobo", 1, [], ","
    if any(ln.startswith("Database Valid") for ln in head[:3]):
        i = next((k for k, ln in enumerate(lines) if ln.startswith("Time,")), None)
        if i is not None:
            return "hanwell", i, [], ","
    if head and re.match(r"^,\s*Time\s*,", head[0]):
        prop = next((k for k, ln in enumerate(head[:12]) if ln.startswith("Property")), None)
        if prop is not None:
            return "tinytag", 0, list(range(1, prop + 1)), ","
    if any(ln.startswith("[#H]") for ln in head):
        h = next(k for k, ln in enumerate(lines) if ln.strip().startswith("[#H]")) + 1
        d = next((k for k, ln in enumerate(lines) if ln.strip().startswith("[#D]")), h)
        sep = "\t" if "\t" in lines[h] else ","
        return "rotronic", h, list(range(h + 1, d + 1)), sep
    if head and re.match(r'^"?RECEIVER"?,"?TRANSMITTER"?,"?DATE"?', head[0]):
        return "meaco", 0, [], ","
    return "generic", -1, [], None


def inspect_table(path, *, what: str = "file") -> TableLayout:
    """Work out how to read a logger or weather export (see the module docstring).

    Parameters
    ----------
    path : path-like
        A delimited text file.
    what : str
        How to name the file in messages (``"logger file"``, ``"weather file"``).

    Returns
    -------
    TableLayout

    Raises
    ------
    heritage_bayes.errors.DataError
        Not a text table, no header line, or no column that parses as time stamps (the
        message names the file and what was found).
    """
    path = Path(path)
    if not path.is_file():
        raise DataError(f"{path}: {what} not found")
    text, encoding = _decode(path)
    lines = text.splitlines()[:_SAMPLE_LINES]
    long = next((k for k, ln in enumerate(lines) if len(ln) > _MAX_LINE), None)
    if long is not None:
        raise DataError(
            f"{source_name(path)}: line {long + 1} has {len(lines[long])} characters, more than "
            f"a logger export's {_MAX_LINE}: not a table of readings (the line is not shown)"
        )
    if len(lines) < 3:
        raise DataError(
            f"{source_name(path)}: {len(lines)} line(s); a {what} needs a header and data"
        )
    layout, h, after, sep = _layout(lines)
    notes: list[str] = []
    if sep is None:
        sep, h = _table_header(path, lines)
    header = [c.strip().strip('"') for c in _split(lines[h], sep)]
    skip_set = set(range(h)) | set(after)
    body = [_split(ln, sep) for k, ln in enumerate(lines) if k > h and k not in skip_set]
    body = [r for r in body if any(c.strip() for c in r)]
    if not body:
        raise DataError(
            f"{source_name(path)}: a header line ({quoted(lines[h], 80)}) but no data lines"
        )
    cols = {name: [r[i] if i < len(r) else "" for r in body] for i, name in enumerate(header)}
    if layout == "tinytag":  # channel names are on the 'Property' line
        prop = _split(lines[after[-1]], sep)
        notes.append(
            "Tinytag Explorer export: channels "
            + ", ".join(
                f"{quoted(header[i])} = {quoted(prop[i])}"
                for i in range(2, min(len(prop), len(header)))
            )
        )

    time_column, fmt = _time_column(path, cols, header, body, lines[h + 1])
    tnames = [time_column] if isinstance(time_column, str) else time_column
    zone = None if fmt == "ISO8601" else _zone_in(" ".join(tnames))

    # -- decimal mark ----------------------------------------------------------------------
    value_cols = [n for n in cols if n not in tnames and n]
    decimal = "."
    if sep != ",":
        commas = sum(
            bool(re.match(r"^-?\d+,\d+$", v.strip())) for n in value_cols for v in cols[n][:200]
        )
        if commas:
            decimal = ","
            notes.append(f"decimal comma ({commas} values like '{_first_comma(cols, value_cols)}')")

    # -- value columns ---------------------------------------------------------------------
    prop_names = _split(lines[after[-1]], sep) if layout == "tinytag" else None
    guesses = _column_guesses(header, cols, tnames, decimal, prop_names, lines[:h], layout)
    return TableLayout(
        path=path,
        layout=layout,
        encoding=encoding,
        sep=sep,
        decimal=decimal,
        skiprows=sorted(skip_set - {h}) if after else h,
        header=header,
        time_column=time_column,
        time_format=fmt,
        timezone=zone,
        columns=guesses,
        notes=notes,
    )


def _table_header(path: Path, lines: list[str]) -> tuple[str, int]:
    """(separator, header line) of a plain table: the first line from which every line
    has the table's width (the commonest in its last 200 lines)."""
    sep = _sep_for(lines)
    counts = [len(_split(ln, sep)) for ln in lines]
    width = max(set(counts[-200:]), key=counts[-200:].count)
    # the header: the first line from which every line has the table's width
    filled = [sum(bool(c.strip()) for c in _split(ln, sep)) for ln in lines]
    h = next(  # (a title line padded to the table's width is not the header)
        (
            k
            for k in range(len(lines))
            if all(c == width for c in counts[k : k + 20]) and filled[k] >= min(2, width)
        ),
        None,
    )
    if h is None or width < 2:
        raise DataError(
            f"{source_name(path)}: no table found (no run of lines with the same number of "
            f"fields separated by ',', ';' or tab)"
        )
    return sep, h


def _time_column(path: Path, cols: dict, header: list[str], body: list, first: str):
    """(time column or columns, strptime format) of a table: one column of time stamps,
    a date and a time column side by side, or Year, Month, Day, Hour [, Minute]
    columns; the format checked on the whole sample (``first``: its first data line,
    for the message)."""
    time_column: str | list[str] | None = None
    fmt = None
    for name, vals in cols.items():
        f = _time_format(vals[:300])
        if f is not None:
            time_column, fmt = name, f
            break
    if time_column is None:  # a date column and a time column
        names = list(cols)
        for a, b in itertools.pairwise(names):
            f = _time_format(
                [f"{x} {y}" for x, y in zip(cols[a][:300], cols[b][:300], strict=True)]
            )
            if f is not None:
                time_column, fmt = [a, b], f
                break
    if time_column is None:  # weather services: Year, Month, Day, Hour [, Minute]
        time_column, fmt = _split_date_columns(cols)
    if time_column is None:
        raise DataError(
            f"{source_name(path)}: no column holds time stamps in a known format; columns are "
            f"{_quote_list(header)}; first data line {quoted(first, 80)}"
        )
    tnames = [time_column] if isinstance(time_column, str) else time_column
    if fmt != "ISO8601":  # check the format on the whole sample
        joined = [" ".join(r[header.index(n)] for n in tnames) for r in body]
        fmt = _time_format(joined) or fmt
    return time_column, fmt


def _column_guesses(header, cols, tnames, decimal: str, prop_names, head: list[str], layout):
    """A :class:`ColumnGuess` per value column: empty, not numeric, or classified from its
    label (``prop_names``: Tinytag's channel names), its range and the file's header
    lines ``head``."""
    guesses = []
    for i, name in enumerate(header):
        if name in tnames or not name:
            continue
        label = prop_names[i] if prop_names and i < len(prop_names) else name
        nums = [_number(v, decimal) for v in cols[name]]
        vals = np.array([v for v in nums if v is not None], dtype=float)
        if vals.size < 0.5 * len(nums) or vals.size == 0:
            empty = sum(not str(v).strip() for v in cols[name])
            why = "empty" if empty == len(nums) else "not numeric"
            guesses.append(ColumnGuess(name, None, why=why, named=_named_role(label)))
            continue
        stats = (float(vals.min()), float(np.median(vals)), float(vals.max()))
        guesses.append(_classify(name, label, stats, head, layout))
    return guesses


_PARTS = (("year", "%Y"), ("month", "%m"), ("day", "%d"), ("hour", "%H"), ("minute", "%M"))


def _split_date_columns(cols: dict) -> tuple[list[str] | None, str | None]:
    """Time split over columns named Year, Month, Day, Hour (and Minute), as DMI and
    other weather services export it: the columns and the strptime format of their
    values joined by spaces, or (None, None)."""
    names, fmts = [], []
    for part, f in _PARTS:
        hit = next((n for n in cols if re.match(rf"^{part}\b", n.strip().lower())), None)
        if hit is None:
            if part in ("year", "month", "day", "hour"):
                return None, None
            break
        names.append(hit)
        fmts.append(f)
    fmt = " ".join(fmts)
    sample = [
        " ".join(cols[n][i].strip() for n in names) for i in range(min(300, len(cols[names[0]])))
    ]
    try:
        for v in sample:
            datetime.strptime(v, fmt)
    except ValueError:
        return None, None
    return names, fmt


def _first_comma(cols, names) -> str:
    for n in names:
        for v in cols[n]:
            if re.match(r"^-?\d+,\d+$", v.strip()):
                return v.strip()
    return ""


def _named_role(label: str) -> str | None:
    """The role a column's name suggests (``"skip"`` for non-climate columns)."""
    low = label.lower()
    return next((k for k, pat in _ROLE_PATTERNS if re.search(pat, low)), None)


def _classify(name: str, label: str, stats, preamble: list[str], layout: str) -> ColumnGuess:
    """The role and unit of one numeric column, from its name and its values."""
    g = _classify_values(name, label, stats)
    g.named = _named_role(label)
    g.labelled = bool(re.search(_UNIT_IN_NAME, label.lower()))
    return g


#: A temperature unit stated in a column's name.
_UNIT_IN_NAME = r"°\s*[cf]|\([cfk]\)|\[[cfk]\]|deg ?[cf]|fahrenheit|celsius|kelvin"


def _classify_values(name: str, label: str, stats) -> ColumnGuess:
    """The role and unit of one numeric column, from its name and its values."""
    low = label.lower()
    kind = _named_role(label)
    lo, med, hi = stats
    rng = f"values {lo:g} to {hi:g} (median {med:g}; first {_SAMPLE_LINES} lines)"
    if kind == "skip" or kind is None:
        return ColumnGuess(
            name, None, why=f"name {label!r} not temperature, RH or irradiance; {rng}", stats=stats
        )
    if kind == "T":
        if re.search(r"°\s*f|\(f\)|degf|fahrenheit", low):
            return ColumnGuess(name, "T", "°F", f"name {label!r} says °F; {rng}", stats)
        if re.search(r"\[k\]|\(k\)|kelvin", low) or 200 <= med <= 340:
            return ColumnGuess(name, "T", "K", f"name {label!r}; {rng}: Kelvin", stats)
        if hi > 70 and hi <= 158 and not re.search(r"°\s*c|\(c\)|degc", low):
            # above 70 is no air temperature in °C; -76 to 158 °F is -60 to 70 °C
            return ColumnGuess(name, "T", "°F", f"name {label!r}; {rng}: above 70, so °F", stats)
        if not -60 <= lo <= hi <= 70:
            return ColumnGuess(
                name, None, why=f"name {label!r} but {rng}: not air temperature in °C", stats=stats
            )
        return ColumnGuess(name, "T", "°C", f"name {label!r}; {rng} °C", stats)
    if kind == "wind":
        if lo < 0 or hi > 75:
            return ColumnGuess(
                name, None, why=f"name {label!r} but {rng}: not wind speed in m/s", stats=stats
            )
        return ColumnGuess(name, "wind", "m/s", f"name {label!r}; {rng} m/s", stats)
    if kind == "precip":
        if lo < 0 or hi > 500:
            why = f"name {label!r} but {rng}: not precipitation in mm"
            return ColumnGuess(name, None, why=why, stats=stats)
        return ColumnGuess(name, "precip", "mm", f"name {label!r}; {rng} mm", stats)
    if kind == "RH":
        if hi <= 1.0 and lo >= 0:
            return ColumnGuess(
                name, "RH", "fraction", f"name {label!r}; {rng}: a fraction 0-1", stats
            )
        if lo < 0 or hi > 100.5:
            return ColumnGuess(
                name, None, why=f"name {label!r} but {rng}: not RH in %", stats=stats
            )
        return ColumnGuess(name, "RH", "%", f"name {label!r}; {rng} %", stats)
    if lo < -10 or hi > 1500:
        return ColumnGuess(
            name, None, why=f"name {label!r} but {rng}: not irradiance in W/m²", stats=stats
        )
    return ColumnGuess(name, kind, "W/m²", f"name {label!r}; {rng} W/m²", stats)
