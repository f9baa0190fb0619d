"""Reading the configured weather, measurement and ground-temperature sources.

Layer: config → **data**. :func:`read_sources` gives the raw tables of a config: from its
files, or from the built-in demo (:mod:`heritage_bayes.demo`), a data source beside the
file readers. :func:`read_source` dispatches one config ``Source`` (format, path(s), CSV
options) to the readers of :mod:`heritage_bayes.io`, checking CSV headers against the
columns the config maps, so that errors name the config key and the file.
:mod:`heritage_bayes.prepare` derives the model inputs from these tables and aligns them.
"""

from __future__ import annotations

from collections.abc import Sequence
from pathlib import Path
from typing import NamedTuple

import pandas as pd

from heritage_bayes.errors import ConfigError, DataError, InputError, quoted

__all__ = [
    "INPUT_COLUMNS",
    "OUTPUT_COLUMNS",
    "RawData",
    "check_clocks",
    "input_paths",
    "read_source",
    "read_sources",
]

#: Standard columns that weather files may provide (model inputs and what they derive from).
#: ("Ph": a known heat input [W], e.g. measured heating power of a test cell; "wind": wind
#: speed [m/s], which weights the sun on roof planes.)
INPUT_COLUMNS = ("Te", "RHe", "Pe", "ghi", "dni", "dhi", "Tdew", "Ph", "Isol", "wind", "precip")
#: Standard columns that measurement files may provide (model outputs).
OUTPUT_COLUMNS = ("Ti", "RHi", "Pi")


def _quote(names) -> str:
    from heritage_bayes.io._common import _quote_list

    return _quote_list(names)


def _csv_header(path: Path, src, where: str) -> list[str]:
    from heritage_bayes.io._common import READ_ERRORS, damaged, looks_like_table, sniff_text
    from heritage_bayes.io.readers.workbook import is_workbook, table_source

    encoding = None
    try:
        if not is_workbook(path):  # binary, damaged or truncated: say so at once
            encoding = sniff_text(path, path.name, encoding=src.encoding)
        header = pd.read_csv(
            table_source(path)(), nrows=0, sep=src.sep, encoding=encoding, skiprows=src.skiprows
        )
    except DataError as exc:
        raise DataError(f"{where}: {exc}") from None
    except READ_ERRORS as exc:
        raise DataError(f"{where}: {damaged(path.name, exc)}") from None
    except (pd.errors.ParserError, pd.errors.EmptyDataError, UnicodeDecodeError) as exc:
        raise DataError(f"{where}: {path.name}: cannot read the header line: {exc}") from None
    if encoding is not None and not looks_like_table(path, src.sep, src.skiprows, encoding):
        raise DataError(
            f"{where}: {path.name}: not a table: its first lines do not split into the same "
            f"two or more fields by the separator {src.sep!r} (check the path and sep; the "
            "file's content is not shown)"
        )
    return [str(c).strip() for c in header.columns]


def _check_csv_columns(path: Path, src, where: str, allowed: Sequence[str]) -> None:
    """Check the config's column names against the file header (precise key paths)."""
    from heritage_bayes.io import STANDARD_COLUMNS

    header = _csv_header(path, src, where)
    tcols = [src.time_column] if isinstance(src.time_column, str) else list(src.time_column)
    for c in tcols:
        if c.strip() not in header:
            raise DataError(
                f"{where}.time_column: column {quoted(c)} not found in {path.name}; columns are: "
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
                f"{where}.columns.{std}: column {quoted(col)} not found in {path.name}; columns "
                f"are: {_quote(header)}"
            )


def _csv_kwargs(src) -> dict:
    kw = {
        "time_column": src.time_column,
        "time_format": src.time_format,
        "time_origin": src.time_origin,
        "timezone": src.timezone,
        "sep": src.sep,
        "decimal": src.decimal,
        "averaged": src.averaged,
        "interval": src.interval,
        "label": src.label,
        "duplicates": src.duplicates,
        "sort": src.sort,
        "invalid": src.invalid,
        "skiprows": src.skiprows,
        "encoding": src.encoding,
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
            df = read_csv(path, columns=src.columns, units=src.units, **_csv_kwargs(src))
        elif src.format == "epw":
            df = read_epw(path, year=src.year, invalid=src.invalid)
        elif src.format == "tmy3":
            df = read_tmy3(path, year=src.year, invalid=src.invalid)
        else:
            df = read_knmi_hourly(path, invalid=src.invalid)
    except ConfigError:
        raise
    except DataError as exc:
        msg = str(exc)  # the header checks already name the key
        raise DataError(msg if msg.startswith(where) else f"{where}: {msg}") from None
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
# All sources of a config: its files, or the built-in demo
# ---------------------------------------------------------------------------------------


class RawData(NamedTuple):
    """What the configured sources provide, before derivation and alignment.

    Attributes
    ----------
    weather : pandas.DataFrame
        Standard input columns (:data:`INPUT_COLUMNS`), native time stamps (UTC).
    measurements : list of pandas.DataFrame
        One table per configured measurement source (standard output columns).
    site : dict or None
        ``latitude``, ``longitude`` [°], ``altitude`` [m] when known.
    notes : dict
        Provenance: ``weather``, ``measurements``, ``site`` and, for the
        demo, its settings under ``demo``.
    monument : heritage_bayes.demo.VirtualMonument or None
        The demo's dataset (truth, noise) when ``data.demo`` is set.
    """

    weather: pd.DataFrame
    measurements: list[pd.DataFrame]
    site: dict | None
    notes: dict
    monument: object | None


def read_sources(cfg) -> RawData:
    """Read the weather and measurement sources of a validated config.

    The built-in demo (``data.demo``, :func:`heritage_bayes.demo.virtual_monument`) is a
    data source beside the file readers: it yields the same tables as a weather file and
    a logger file would, and the rest of the preparation does not tell them apart.
    """
    data = cfg.data
    sources: dict = {}
    monument = None
    if data.demo is not None:
        monument = _demo(data.demo, cfg)
        weather = monument.weather
        meas_tables = [monument.measurements]
        site = dict(monument.info["site"])
        sources["demo"] = monument.info["settings"] | {
            "description": monument.info["description"],
            "weather_file": monument.info["weather_file"],
            "station": monument.info["station"],
            "true_Tf": monument.info["Tf"],
        }
        sources["weather"] = {
            "path": monument.info["weather_file"],
            "format": "tmy3",
            "note": "shipped with pvlib",
        }
        sources["measurements"] = [{"generated": monument.measurements.attrs["source"]}]
        sources["site"] = site | {"from": "weather file (TMY3 metadata)"}
    else:
        weather = read_source(cfg, data.weather, "data.weather", INPUT_COLUMNS)
        many = len(data.measurements) > 1
        meas_tables = []
        for i, src in enumerate(data.measurements):
            key = "data.measurements" + (f"[{i}]" if many else "")
            meas_tables.append(read_source(cfg, src, key, OUTPUT_COLUMNS))
        if cfg.site is not None:
            site = cfg.site.model_dump()
            sources["site"] = site | {"from": "config"}
        else:
            site = weather.attrs.get("site")
            if site is not None:
                sources["site"] = dict(site) | {"from": "weather file"}
        sources["clock"] = check_clocks(weather, meas_tables, site)
        sources["weather"] = _source_note(weather, data.weather.format)
        sources["measurements"] = [
            _source_note(m, s.format) for m, s in zip(meas_tables, data.measurements, strict=True)
        ]
    return RawData(weather, meas_tables, site, sources, monument)


def check_clocks(weather: pd.DataFrame, measurements: list, site: dict | None) -> dict:
    """The declared clock of each table against its data
    (:func:`heritage_bayes.io.clock.check_declared_clock`: the sun, DST changes).

    Returns ``{key: {"sun": ..., "warnings": [...]}, "warnings": [all of them]}``; a
    warning names the config key and states the measured offset.
    """
    from heritage_bayes.io.clock import check_declared_clock

    lon, lat = (site or {}).get("longitude"), (site or {}).get("latitude")
    out = {"data.weather": check_declared_clock(weather, lon, "data.weather", lat)}
    for i, m in enumerate(measurements):
        key = "data.measurements" + (f"[{i}]" if len(measurements) > 1 else "")
        out[key] = check_declared_clock(m, lon, key, lat)
    out["warnings"] = [w for v in out.values() for w in v["warnings"]]
    return out


def _source_note(df: pd.DataFrame, fmt: str) -> dict:
    attrs = df.attrs
    note = {
        "path": attrs.get("source"),
        "format": fmt,
        "columns": list(df.columns),
        "rows": len(df),
        "first": _iso(df.index[0]) if len(df) else None,
        "last": _iso(df.index[-1]) if len(df) else None,
    }
    for key in ("timezone", "dropped", "clipped", "station", "source_columns", "coerced_year"):
        if attrs.get(key) not in (None, {}, ()):
            note[key] = attrs[key]
    return note


def _demo(settings, cfg):
    from heritage_bayes.demo import virtual_monument

    path = settings.weather_path
    if path is not None:
        where = "data.demo.weather_path"
        paths = [cfg.path(p).resolve() for p in (path if isinstance(path, list) else [path])]
        for p in paths:
            if not p.is_file():
                raise DataError(f"{where}: {p}: file not found")
        path = (
            tuple(str(p) for p in paths)
            if isinstance(settings.weather_path, list)
            else str(paths[0])
        )

    truth = settings.truth or {}
    try:
        return virtual_monument(
            seed=settings.seed,
            weather=settings.weather,
            weather_path=path,
            sensor_noise_T=settings.sensor_noise_T,
            sensor_noise_RH=settings.sensor_noise_RH,
            model_error_T=settings.model_error_T,
            model_error_P=settings.model_error_P,
            model_error_phi=settings.model_error_phi,
            gap=settings.gap,
            thermal=truth.get("thermal"),
            hygric=truth.get("hygric"),
            thermal_model=settings.thermal_model,
        )
    except InputError as exc:  # its messages start with the setting's name
        raise ConfigError(f"data.demo.{exc}") from None


def _iso(ts: pd.Timestamp) -> str:
    return ts.tz_convert("UTC").strftime("%Y-%m-%dT%H:%M:%SZ")


def input_paths(cfg) -> list[Path]:
    """The config's folder and every data file it names (absolute): what an output
    folder may not be nor hold (:func:`heritage_bayes.rundir.resolve_output`)."""
    d = cfg.portable()["data"]
    paths = [Path(cfg.base_dir)] if cfg.base_dir else []
    sources = [d.get("weather"), *(d.get("measurements") or [])]
    sources.append((d.get("ground_temperature") or {}).get("source"))
    found = [src.get("path") for src in sources if src]
    found.append((d.get("demo") or {}).get("weather_path"))
    for p in found:
        for q in [p] if isinstance(p, str) else p or []:
            paths.append(Path(q))
    return paths
