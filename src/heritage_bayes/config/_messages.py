"""Error messages of the settings layer: pydantic's error locations turned into key
paths (``data.measurements[1].columns``), and an unknown key answered with the nearest
known one."""

from __future__ import annotations

import difflib
import re
import typing
from typing import Any

from pydantic import BaseModel

__all__ = ["format_error", "nearest_key", "validate"]


def _model_of(annotation) -> type[BaseModel] | None:
    """The pydantic model inside a field's annotation (``Source | None``, ``list[Source]``)."""
    for arg in [annotation, *typing.get_args(annotation)]:
        for cand in [arg, *typing.get_args(arg)]:
            if isinstance(cand, type) and issubclass(cand, BaseModel):
                return cand
    return None


def section_model(loc, root: type[BaseModel]) -> type[BaseModel] | None:
    """The model of the config section at key path ``loc`` (list indices and dict keys
    stay on the same model)."""
    cls: Any = root
    for key in loc:
        if not (isinstance(cls, type) and issubclass(cls, BaseModel)):
            return None
        field = cls.model_fields.get(str(key))
        if field is None:
            continue
        cls = _model_of(field.annotation)
    return cls if isinstance(cls, type) and issubclass(cls, BaseModel) else None


def _allowed_keys(loc, root: type[BaseModel]) -> list[str]:
    cls = section_model(loc, root)
    return [k for k in cls.model_fields if k != "base_dir"] if cls is not None else []


def _elsewhere(name: str, root: type[BaseModel]) -> list[str]:
    """Key paths in the schema whose last key is ``name`` (a key put in the wrong section)."""
    found: list[str] = []
    todo: list[tuple[str, type[BaseModel]]] = [("", root)]
    seen: set[type] = set()
    while todo:
        prefix, cls = todo.pop(0)
        if cls in seen:
            continue
        seen.add(cls)
        for k, f in cls.model_fields.items():
            path = f"{prefix}.{k}" if prefix else k
            if k == name:
                found.append(path)
            sub = _model_of(f.annotation)
            if sub is not None:
                todo.append((path, sub))
    return found


def nearest_key(name: str, allowed: list[str], root: type[BaseModel] | None = None) -> str:
    """A hint for an unknown key: the closest allowed key (spelling, case), or the
    section where a key of that name belongs; empty when nothing is close."""
    by_lower = {a.lower(): a for a in allowed}
    close = difflib.get_close_matches(str(name).lower(), list(by_lower), n=1, cutoff=0.6)
    if close:
        return f"did you mean {by_lower[close[0]]!r}?"
    if root is not None:
        other = _elsewhere(str(name), root)
        if other:
            return f"{name!r} belongs in {' or '.join(other)}"
    return ""


#: Names pydantic puts into error locations for the members of a union.
_TYPE_TAGS = {"str", "int", "float", "bool", "list", "dict", "tuple", "none", "is-instance"}


def key_path(loc, raw: Any) -> str:
    """``data.measurements[1].columns`` from a pydantic error location.

    Drops pydantic's validator/union tags (``function-after[...]``, ``list[...]``) and the
    index ``0`` that a single mapping gets when accepted as a list of one.
    """
    text = ""
    node = raw
    for x in loc:
        if isinstance(x, str) and "[" in x:
            continue
        if x in _TYPE_TAGS and not (isinstance(node, dict) and x in node):
            continue  # a union member's tag (``str``, ``int``, ...), not a key
        if isinstance(x, int):
            if isinstance(node, dict):  # a single mapping given where a list is allowed
                continue
            text += f"[{x}]"
            node = node[x] if isinstance(node, list) and -len(node) <= x < len(node) else None
            continue
        text += f".{x}" if text else str(x)
        node = node.get(x) if isinstance(node, dict) else None
    return text


_KEY_PREFIX = re.compile(r"^([A-Za-z_]\w*(?:\[\d+\])*(?:\.[A-Za-z_]\w*(?:\[\d+\])*)*): ")


def format_error(err: dict, raw: Any, root: type[BaseModel]) -> str:
    """One line for one pydantic error: ``key.path: what is wrong (got value)``.

    ``root``: the schema the location starts from (e.g. the calibration config).
    """
    loc = key_path(err["loc"], raw)
    msg = err["msg"]
    if msg.startswith("Value error, "):
        msg = msg[len("Value error, ") :]
    typ = err["type"]
    if typ == "extra_forbidden":
        allowed = _allowed_keys(err["loc"][:-1], root)
        hint = nearest_key(str(err["loc"][-1]), allowed, root)
        listed = f"allowed keys: {', '.join(allowed)}" if allowed else ""
        if hint and listed:
            listed = listed[0].upper() + listed[1:]
        return (
            f"{loc}: unknown key"
            + (f"; {hint}" if hint else "")
            + ((" " if hint else "; ") + listed if listed else "")
        )
    found = err.get("input")
    if typ == "missing":
        return f"{loc}: required"
    if isinstance(found, dict):  # a section-level check: its message says what was found
        # "warmup: ..." raised by the section 'periods' reads as "periods.warmup: ..."
        m = _KEY_PREFIX.match(msg)
        if m and loc:
            return f"{loc}.{m.group(1)}: {msg[m.end() :]}"
        return f"{loc or '(top level)'}: {msg}"
    if typ in _BOUND_ERRORS:
        rng = _range_of(err["loc"], root)
        if rng:
            return f"{loc}: outside the allowed range {rng} (got {_short(found)})"
    if "(got " in msg:  # the check already says what it found
        return f"{loc or '(top level)'}: {msg}"
    return f"{loc or '(top level)'}: {msg} (got {_short(found)})"


#: pydantic's error types of a bound (``ge``, ``gt``, ``le``, ``lt``).
_BOUND_ERRORS = {"greater_than", "greater_than_equal", "less_than", "less_than_equal"}


def _range_of(loc, root: type[BaseModel]) -> str:
    """The allowed range with its unit of the key at ``loc`` (empty if unknown)."""
    from heritage_bayes.config._base import range_text

    names = [x for x in loc if isinstance(x, str) and "[" not in x]
    if not names:
        return ""
    cls = section_model(loc[: len(loc) - 1 - loc[::-1].index(names[-1])], root)
    field = cls.model_fields.get(names[-1]) if cls is not None else None
    return range_text(field) if field is not None else ""


def _short(value: Any, limit: int | None = None) -> str:
    """``repr`` of a value echoed in a message, cut to a readable length (a text to
    :data:`heritage_bayes.errors.QUOTE_LIMIT` characters, as every message does)."""
    import reprlib

    from heritage_bayes.errors import QUOTE_LIMIT, quoted

    limit = QUOTE_LIMIT if limit is None else limit
    if isinstance(value, str):
        return quoted(value, limit)

    r = reprlib.Repr()  # keyword arguments only from Python 3.12
    r.maxstring = r.maxother = limit
    r.maxlist = r.maxtuple = r.maxdict = r.maxset = 8
    r.maxlevel = 3
    text = r.repr(value)
    return text if len(text) <= limit + 10 else text[:limit] + "..."


def validate(cls: type[BaseModel], raw: Any, source: str, what: str = "configuration"):
    """``cls.model_validate(raw)``, every error turned into one line naming its key path.

    Raises
    ------
    ConfigError
        ``raw`` is not a mapping, or one line per wrong key (:func:`format_error`).
    """
    from pydantic import ValidationError

    from heritage_bayes.errors import ConfigError, check_known_keys

    if not isinstance(raw, dict):
        raise ConfigError(
            f"{source}: expected a YAML mapping at the top level (got {type(raw).__name__})"
        )
    # a mapping with none of the schema's keys is another file: named, never quoted
    known = [k for k in cls.model_fields if k != "base_dir"]
    check_known_keys(raw, known, source=source, what=what)
    try:
        return cls.model_validate(raw)
    except ValidationError as exc:
        lines = join_errors(exc.errors(), raw, cls)
        raise ConfigError(f"{source}: invalid {what}:\n  " + "\n  ".join(lines)) from None


def join_errors(errors: list[dict], raw: Any, root: type[BaseModel]) -> list[str]:
    """One line per key path: the messages of a union's members joined with 'or'."""
    lines: list[str] = []
    for e in errors:
        line = format_error(e, raw, root)
        key, _, msg = line.partition(": ")
        prev = next((i for i, x in enumerate(lines) if x.startswith(f"{key}: ")), None)
        if prev is not None and msg.startswith("Input should be "):
            head, got, tail = lines[prev].rpartition(" (got ")
            extra = msg[len("Input should be ") :].partition(" (got ")[0]
            lines[prev] = f"{head} or {extra} (got {tail}" if got else f"{lines[prev]} or {extra}"
            continue
        lines.append(line)
    return lines
