"""Reading the configured weather, measurement and ground-temperature sources.

``read_source`` dispatches a config ``Source`` (format, path(s), CSV options) to the
readers of :mod:`heritage_bayes.io`, checking CSV headers against the columns the
config maps, so that errors name the config key and the file.
"""

from __future__ import annotations

from collections.abc import Sequence
from pathlib import Path

import pandas as pd

from heritage_bayes.errors import ConfigError, DataError, InputError

__all__ = ["read_source"]


def _quote(names) -> str:
    return ", ".join(repr(n) for n in names)


def _csv_header(path: Path, src, where: str) -> list[str]:
    try:
        header = pd.read_csv(path, nrows=0, sep=src.sep, encoding="utf-8")
    except (pd.errors.ParserError, pd.errors.EmptyDataError, UnicodeDecodeError) as exc:
        raise DataError(f"{where}: {path.name}: cannot read the header line: {exc}") from None
    return [str(c).strip() for c in header.columns]


def _check_csv_columns(path: Path, src, where: str, allowed: Sequence[str]) -> None:
    """Check the config's column names against the file header (precise key paths)."""
    from heritage_bayes.io import STANDARD_COLUMNS

    header = _csv_header(path, src, where)
    tcols = [src.time_column] if isinstance(src.time_column, str) else list(src.time_column)
    for c in tcols:
        if c.strip() not in header:
            raise DataError(
                f"{where}.time_column: column {c!r} not found in {path.name}; columns are: "
                f"{_quote(header)}"
            )
    for std, col in (src.columns or {}).items():
        if std not in STANDARD_COLUMNS:
            raise ConfigError(
                f"{where}.columns.{std}: not a standard column name; use one of {_quote(allowed)}"
            )
        if std not in allowed:
            role = "weather (model inputs)" if "Te" in allowed else "measurements (outputs)"
            raise ConfigError(
                f"{where}.columns.{std}: not a column of the {role}; allowed here: "
                f"{_quote(allowed)}"
            )
        if str(col).strip() not in header:
            raise DataError(
                f"{where}.columns.{std}: column {col!r} not found in {path.name}; columns "
                f"are: {_quote(header)}"
            )


def _csv_kwargs(src) -> dict:
    kw = {
        "time_column": src.time_column,
        "time_format": src.time_format,
        "timezone": src.timezone,
        "sep": src.sep,
        "decimal": src.decimal,
        "averaged": src.averaged,
        "interval": src.interval,
        "label": src.label,
        "duplicates": src.duplicates,
        "invalid": src.invalid,
    }
    if src.na_values is not None:
        kw["na_values"] = src.na_values
    return kw


def _resolve_paths(cfg, src, where: str) -> Path | list[Path]:
    paths = [
        cfg.path(p).resolve() for p in (src.path if isinstance(src.path, list) else [src.path])
    ]
    for p in paths:
        if not p.is_file():
            what = "is a directory, expected a data file" if p.is_dir() else "file not found"
            raise DataError(f"{where}.path: {p}: {what}")
    return paths if isinstance(src.path, list) else paths[0]


def read_source(cfg, src, where: str, allowed: Sequence[str]) -> pd.DataFrame:
    """Read one configured :class:`~heritage_bayes.config.Source`; errors name ``where``."""
    from heritage_bayes.io import read_csv, read_epw, read_knmi_hourly, read_tmy3

    path = _resolve_paths(cfg, src, where)
    try:
        if src.format == "csv":
            _check_csv_columns(path, src, where, allowed)
            df = read_csv(path, columns=src.columns, **_csv_kwargs(src))
        elif src.format == "epw":
            df = read_epw(path, year=src.year, invalid=src.invalid)
        elif src.format == "tmy3":
            df = read_tmy3(path, year=src.year, invalid=src.invalid)
        else:
            df = read_knmi_hourly(path, invalid=src.invalid)
    except ConfigError:
        raise
    except DataError as exc:
        raise DataError(f"{where}: {exc}") from None
    except InputError as exc:
        raise ConfigError(f"{where}: {exc}") from None
    # columns of the other role picked up by name (no 'columns' mapping) are not used
    extra = [c for c in df.columns if c not in allowed]
    out = df.drop(columns=extra)
    out.attrs = dict(df.attrs)
    if len(out) < 2:
        files = path if isinstance(path, list | tuple) else [path]
        rows = "no data rows" if len(out) == 0 else "only one data row"
        raise DataError(
            f"{where}: {', '.join(str(p) for p in files)}: {rows} (after dropping invalid "
            "ones); a time series of at least two readings is needed"
        )
    if not len(out.columns):
        raise DataError(
            f"{where}: {Path(str(df.attrs.get('source', ''))).name} has none of the columns "
            f"{_quote(allowed)} (found {_quote(df.columns)})"
        )
    return out


def _ground_column(cfg, gt, where: str) -> tuple[pd.DataFrame, dict]:
    """Read the measured ``Tf`` series of ground_temperature mode 'column'."""
    from heritage_bayes.io import read_csv

    candidates = []
    if gt.source is not None:
        candidates.append((gt.source, f"{where}.source"))
    else:
        if cfg.data.weather is not None and cfg.data.weather.format == "csv":
            candidates.append((cfg.data.weather, "data.weather"))
        for i, m in enumerate(cfg.data.measurements or []):
            if m.format == "csv":
                key = "data.measurements" + (f"[{i}]" if len(cfg.data.measurements) > 1 else "")
                candidates.append((m, key))
    if not candidates:
        raise ConfigError(
            f"{where}.column: mode 'column' needs a CSV table holding {gt.column!r}: give "
            f"{where}.source, or use CSV weather or measurement files"
        )
    seen = []
    for src, key in candidates:
        path = _resolve_paths(cfg, src, key)
        header = _csv_header(path, src, key)
        if gt.column.strip() not in header:
            seen.append(f"{path.name}: {_quote(header)}")
            continue
        kw = _csv_kwargs(src)
        kw["averaged"] = None
        try:
            df = read_csv(path, columns={"Te": gt.column}, **kw)
        except DataError as exc:
            raise DataError(f"{where} (column {gt.column!r} of {key}): {exc}") from None
        except InputError as exc:
            raise ConfigError(f"{where} (column {gt.column!r} of {key}): {exc}") from None
        df = df.rename(columns={"Te": "Tf"})
        df.attrs["units"] = {"Tf": "°C"}
        df.attrs["averaged"] = ()
        return df, {"mode": "column", "column": gt.column, "file": str(path), "key": key}
    raise DataError(
        f"{where}.column: column {gt.column!r} not found; columns are: " + "; ".join(seen)
    )


# ---------------------------------------------------------------------------------------
