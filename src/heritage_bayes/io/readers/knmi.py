"""Reader of KNMI hourly station data (``uurgeg_*.txt``, plain or gzipped):
:func:`read_knmi_hourly`.

See :mod:`heritage_bayes.io` for the conventions every reader follows.
"""

from __future__ import annotations

import gzip
from collections.abc import Sequence
from os import PathLike
from pathlib import Path

import numpy as np
import pandas as pd

from heritage_bayes.errors import DataError, InputError
from heritage_bayes.io._common import (
    INVALID_POLICIES,
    READ_ERRORS,
    _quote_list,
    check_choice,
    check_file,
    damaged,
    finalize,
    order_and_deduplicate,
    source_name,
    validate_ranges,
)

__all__ = ["read_knmi_hourly"]

_KNMI_REQUIRED = ("YYYYMMDD", "HH", "T", "U", "Q")


def _open_text(path: Path):
    if path.suffix == ".gz":
        return gzip.open(path, "rt", encoding="latin-1")
    return open(path, encoding="latin-1")


def read_knmi_hourly(
    path: str | PathLike | Sequence[str | PathLike], *, invalid: str = "raise"
) -> pd.DataFrame:
    """Read KNMI hourly station data (``uurgeg_<STN>_<period>.txt``, also ``.gz``).

    Parameters
    ----------
    path : str, path-like, or sequence of them
        One file, or several consecutive files of the same station (they are
        concatenated; overlapping identical hours are dropped once).
    invalid : {"raise", "nan"}, default "raise"
        Values outside physical ranges: raise, or set to NaN (counted).

    Returns
    -------
    pandas.DataFrame
        UTC index; columns ``Te`` [°C] (``T``, at the observation), ``Tdew`` [°C]
        (``TD``, when present), ``RHe`` [%] (``U``, at the observation) and ``ghi``
        [W/m²] (``Q``, the mean of the hour ending at the stamp); with ``FH``,
        ``wind`` [m/s] (the mean wind speed of the hour ending at the stamp).
        ``attrs["averaged"] == ("ghi",)`` (and ``"wind"``), ``attrs["interval"] == "1h"``,
        ``attrs["station"]`` the station number.

    Notes
    -----
    ``HH`` is the hour **ending** at HH UT (1..24; ``HH = 24`` is midnight of the next
    day), so the stamp is ``YYYYMMDD + HH h`` in UTC: exactly the interval-end convention
    of this package. Units in the file: ``T``, ``TD`` in 0.1 °C; ``FH`` in 0.1 m/s;
    ``U`` in %; ``Q`` in
    J/cm² per hour, hence
    :math:`G_h\\,[\\mathrm{W/m^2}] = Q \\cdot 10^4 / 3600`.
    Empty fields are missing values (NaN).

    References
    ----------
    .. [1] KNMI, "Hourly data of the weather in the Netherlands",
       https://www.knmi.nl/nederland-nu/klimatologie/uurgegevens
    """
    check_choice(invalid, INVALID_POLICIES, "invalid")
    paths = [path] if isinstance(path, str | PathLike) else list(path)
    if not paths:
        raise InputError("path: no file given")
    parts = [_read_knmi_one(check_file(p), invalid) for p in paths]
    parts.sort(key=lambda part: part[0].index[0])  # files given in any order
    frame = pd.concat([p[0] for p in parts])
    counts: dict[str, int] = {}
    for _, c, _ in parts:
        for k, v in c.items():
            counts[k] = counts.get(k, 0) + v
    stations = sorted({p[2] for p in parts})
    names = ", ".join(source_name(p) for p in paths)
    if len(stations) > 1:
        raise DataError(f"{names}: files of different stations {stations}; read them separately")
    frame = order_and_deduplicate(frame, names, duplicates="raise", sort=False, counts=counts)
    frame = frame.drop(columns="__line")
    return finalize(
        frame,
        source=str(paths[0]) if len(paths) == 1 else [str(p) for p in paths],
        fmt="knmi-hourly",
        averaged=("ghi", "wind") if "wind" in frame else ("ghi",),
        interval=pd.Timedelta("1h"),
        counts=counts,
        clipped={},
        extra={"timezone": "UTC", "station": stations[0]},
    )


def _read_knmi_one(path: Path, invalid: str):
    name = source_name(path)
    header_line = None
    try:
        with _open_text(path) as fh:
            for number, line in enumerate(fh):
                if line.lstrip().startswith("# STN"):
                    header_line = number, line
                    break
                if number > 500:
                    break
    except READ_ERRORS as exc:
        raise damaged(name, exc) from None
    if header_line is None:
        raise DataError(
            f"{name}: not a KNMI hourly file: no header line starting with "
            f"'# STN,YYYYMMDD,HH,...' in the first 500 lines"
        )
    number, line = header_line
    names = [c.strip() for c in line.strip().lstrip("#").split(",")]
    missing = [c for c in _KNMI_REQUIRED if c not in names]
    if missing:
        raise DataError(
            f"{name}: KNMI column(s) {_quote_list(missing)} not found; columns are: "
            f"{_quote_list(names)}"
        )
    use = [c for c in ("STN", *_KNMI_REQUIRED, "TD", "FH") if c in names]
    try:
        raw = pd.read_csv(
            path,
            skiprows=number + 1,
            header=None,
            names=names,
            usecols=use,
            skipinitialspace=True,
            skip_blank_lines=True,
            dtype=float,
            encoding="latin-1",
        )
    except (ValueError, pd.errors.ParserError) as exc:
        raise DataError(f"{name}: malformed KNMI data: {exc}") from exc
    except READ_ERRORS as exc:
        raise damaged(name, exc) from None
    if raw.empty:
        raise DataError(f"{name}: no data rows after the header line {number + 1}")
    if raw[["YYYYMMDD", "HH"]].isna().any().any():
        i = int(np.flatnonzero(raw[["YYYYMMDD", "HH"]].isna().any(axis=1).to_numpy())[0])
        raise DataError(f"{name}: data row {i + 1}: empty YYYYMMDD or HH")
    hh = raw["HH"].to_numpy()
    bad_hh = (hh < 1) | (hh > 24) | (hh != np.round(hh))
    if bad_hh.any():
        i = int(np.flatnonzero(bad_hh)[0])
        raise DataError(
            f"{name}: column 'HH' data row {i + 1} (YYYYMMDD={int(raw['YYYYMMDD'].iloc[i])}): "
            f"expected an hour 1..24, found {hh[i]:g}"
        )
    dates = pd.to_datetime(
        raw["YYYYMMDD"].astype("int64").astype(str), format="%Y%m%d", errors="coerce"
    )
    if dates.isna().any():
        i = int(np.flatnonzero(dates.isna().to_numpy())[0])
        raise DataError(
            f"{name}: column 'YYYYMMDD' data row {i + 1}: cannot parse "
            f"{raw['YYYYMMDD'].iloc[i]:.0f} as a date"
        )
    index = pd.DatetimeIndex(dates + pd.to_timedelta(hh, unit="h")).tz_localize("UTC")
    stations = raw["STN"].dropna().unique() if "STN" in raw else np.array([np.nan])
    if len(stations) > 1:
        raise DataError(f"{name}: holds several stations {sorted(stations.astype(int))}")
    frame = pd.DataFrame(
        {
            "Te": raw["T"].to_numpy() / 10.0,
            **({"Tdew": raw["TD"].to_numpy() / 10.0} if "TD" in raw else {}),
            "RHe": raw["U"].to_numpy(),
            "ghi": raw["Q"].to_numpy() * 1.0e4 / 3600.0,
            **({"wind": raw["FH"].to_numpy() / 10.0} if "FH" in raw else {}),
        },
        index=index,
    )
    lines = np.arange(len(frame)) + number + 3  # header, blank line, then data
    counts: dict[str, int] = {}
    source_cols = {"Te": "T", "Tdew": "TD", "RHe": "U", "ghi": "Q", "wind": "FH"}
    validate_ranges(frame, lines, name, source_cols, invalid, counts)
    frame["__line"] = lines
    station = int(stations[0]) if np.isfinite(stations[0]) else None
    return frame, counts, station
