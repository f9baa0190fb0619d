"""Portfolio files: rooms, their calibration configs, validation before any work."""

from __future__ import annotations

import copy
import re
from collections.abc import Mapping
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

from heritage_bayes.errors import ConfigError, check_known_keys

__all__ = ["Portfolio", "RoomSpec", "load_portfolio"]

_NAME = re.compile(r"^[A-Za-z0-9][A-Za-z0-9_.-]{0,99}$")
_TOP_KEYS = {"name", "rooms", "defaults", "notes"}
_ROOM_KEYS = {"name", "config", "overrides", "projection"}


@dataclass
class RoomSpec:
    """One room of a portfolio: a validated calibration config and where it runs."""

    name: str
    config_path: Path
    raw: dict  # the room's config as a YAML mapping, defaults and overrides merged
    base_dir: str  # folder of the room's config file (relative data paths)
    projection: Path | None = None


@dataclass
class Portfolio:
    """A validated portfolio file (see the module documentation)."""

    name: str
    path: Path
    rooms: list[RoomSpec] = field(default_factory=list)
    notes: str = ""


def _deep_merge(base: dict, extra: Mapping) -> dict:
    out = copy.deepcopy(base)
    for k, v in extra.items():
        if isinstance(v, Mapping) and isinstance(out.get(k), dict):
            out[k] = _deep_merge(out[k], v)
        else:
            out[k] = copy.deepcopy(v)
    return out


def _read_yaml(path: Path, where: str) -> Any:
    """The strict loader of every config (:func:`heritage_bayes.config.read_yaml`:
    duplicate keys refused, anchors and nesting bounded, no tags), errors prefixed
    with the key that named the file."""
    from heritage_bayes.config import read_yaml

    if where == "portfolio":
        return read_yaml(path, what="portfolio file")[0]
    try:
        return read_yaml(path, what="config file")[0]
    except ConfigError as exc:
        raise ConfigError(f"{where}: {exc}") from None


def load_portfolio(path: str | Path) -> Portfolio:
    """Read a portfolio file and validate every room's config before any work starts.

    Raises
    ------
    ConfigError
        Listing *every* bad entry (missing or invalid config, duplicate room name,
        invalid overrides, missing or invalid projection file), each with its room name
        and key path.
    """
    from heritage_bayes.calibration.calibrate import check_models
    from heritage_bayes.config import parse_config
    from heritage_bayes.projection.config import load_projection_config

    p = Path(path)
    raw = _read_yaml(p, "portfolio")
    if not isinstance(raw, dict):
        raise ConfigError(f"{p}: expected a YAML mapping with 'rooms' (got {type(raw).__name__})")
    check_known_keys(raw, _TOP_KEYS, source=str(p), what="portfolio file")
    unknown = sorted(set(raw) - _TOP_KEYS)
    if unknown:
        raise ConfigError(f"{p}: unknown key(s) {unknown}; expected some of {sorted(_TOP_KEYS)}")
    rooms = raw.get("rooms")
    if not isinstance(rooms, list) or not rooms:
        raise ConfigError(f"{p}: rooms: expected a non-empty list of rooms (got {rooms!r:.80})")
    defaults = raw.get("defaults") or {}
    if not isinstance(defaults, dict):
        raise ConfigError(f"{p}: defaults: expected a mapping (got {type(defaults).__name__})")
    name = raw.get("name") or p.stem
    if not isinstance(name, str) or not _NAME.match(name):
        raise ConfigError(f"{p}: name: expected letters, digits, '_', '.', '-' (got {name!r:.80})")
    base = p.parent.resolve()
    errors: list[str] = []
    specs: list[RoomSpec] = []
    seen: set[str] = set()
    for i, entry in enumerate(rooms):
        where = f"rooms[{i}]"
        if not isinstance(entry, dict):
            errors.append(f"{where}: expected a mapping with 'name' and 'config'")
            continue
        rname = entry.get("name")
        if isinstance(rname, str):
            where = f"rooms[{i}] ({rname})"
        bad = sorted(set(entry) - _ROOM_KEYS)
        if bad:
            errors.append(f"{where}: unknown key(s) {bad}; expected some of {sorted(_ROOM_KEYS)}")
            continue
        if not isinstance(rname, str) or not _NAME.match(rname):
            errors.append(
                f"{where}.name: expected letters, digits, '_', '.', '-' (got {rname!r:.80})"
            )
            continue
        if rname in seen:
            errors.append(f"{where}.name: room name {rname!r} is used twice")
            continue
        seen.add(rname)
        cpath = entry.get("config")
        if not isinstance(cpath, str):
            errors.append(f"{where}.config: expected the path of a calibration config")
            continue
        cfile = Path(cpath).expanduser()
        cfile = cfile if cfile.is_absolute() else base / cfile
        overrides = entry.get("overrides") or {}
        if not isinstance(overrides, dict):
            errors.append(f"{where}.overrides: expected a mapping")
            continue
        try:
            room_raw = _read_yaml(cfile, f"{where}.config")
            if not isinstance(room_raw, dict):
                raise ConfigError(f"{where}.config: {cfile} is not a YAML mapping")
            merged = _deep_merge(_deep_merge(room_raw, defaults), overrides)
            # the run is the room: its reports and summary carry the room's name, not
            # the shared config's (several rooms often share one config)
            merged["name"] = overrides.get("name", rname)
            cfg = parse_config(
                merged, source=f"{where} ({cfile})", base_dir=str(cfile.parent), name=rname
            )
            try:
                check_models(cfg)
            except ConfigError as exc:
                raise ConfigError(f"{where} ({cfile}): {exc}") from None
        except ConfigError as exc:
            errors.append(str(exc))
            continue
        proj = entry.get("projection")
        proj_path = None
        if proj is not None:
            proj_path = Path(str(proj)).expanduser()
            proj_path = proj_path if proj_path.is_absolute() else base / proj_path
            if not proj_path.is_file():
                errors.append(f"{where}.projection: file not found: {proj_path}")
                continue
            try:  # the file validated now, not after the room's calibration
                load_projection_config(proj_path)
            except ConfigError as exc:
                errors.append(f"{where}.projection: {exc}")
                continue
            if cfg.thermal is None or cfg.hygric is None:
                has = [s for s in ("thermal", "hygric") if getattr(cfg, s) is not None]
                errors.append(
                    f"{where}.projection: a projection of risk needs both the thermal and the "
                    f"hygric model (indoor T and RH); the room's config has {has}"
                )
                continue
            if cfg.data.step.total_seconds() != 3600.0:
                errors.append(
                    f"{where}.projection: the risk indicators need an hourly grid; the room's "
                    f"data.step is {cfg.data.step.total_seconds():g} s"
                )
                continue
        specs.append(RoomSpec(rname, cfile, merged, str(cfile.parent), proj_path))
    if errors:
        raise ConfigError(
            f"{p}: {len(errors)} of {len(rooms)} room(s) are invalid; nothing was run:\n  "
            + "\n  ".join(e.replace("\n", "\n    ") for e in errors)
        )
    return Portfolio(name=name, path=p, rooms=specs, notes=str(raw.get("notes") or ""))
