"""Strict YAML for settings files: safe, no duplicate keys, no tags, bounded anchors.

:func:`read_yaml` is the one reader of every YAML file the package accepts (calibration,
projection, portfolio configs): YAML's silent choices are refused with the line.
"""

from __future__ import annotations

import re
from pathlib import Path
from typing import Any

import yaml

from heritage_bayes.errors import ConfigError

__all__ = ["MAX_ALIASES", "MAX_BYTES", "MAX_DEPTH", "MAX_NODES", "load_yaml_text", "read_yaml"]

#: Limits of a settings file: size [bytes], aliases (``*name``) in one file, values
#: after expanding anchors, nesting depth. A hand-written config uses a handful of each.
MAX_BYTES = 1_000_000
MAX_ALIASES = 100
MAX_NODES = 100_000
MAX_DEPTH = 40


class _Loader(yaml.SafeLoader):
    """Safe YAML, stricter:

    - a key given twice in one mapping is an error (YAML would keep the last silently);
    - an explicit tag (``!!python/object``, ``!!binary``, ``!custom``, even ``!!str``) is
      an error: a settings file holds plain values, and a tag changes what a value is;
    - more than :data:`MAX_ALIASES` aliases is an error (an "anchor bomb" expands
      exponentially when walked);
    - an impossible date (``2019-13-02``) stays text, so that the config check names its
      key instead of failing inside the YAML parser;
    - a number in scientific notation is a number as written (``1.3e7``, ``5e-3``,
      ``2E+8``): PyYAML follows YAML 1.1, which reads a mantissa without a dot or an
      exponent without a sign as text, so that ``Cint: {median: 1.3e7}`` was refused as
      "not a number" (YAML 1.2, and every other reader, takes it as the float).
    """

    def __init__(self, stream):
        super().__init__(stream)
        self._aliases = 0

    def compose_node(self, parent, index):
        event = self.peek_event()
        if isinstance(event, yaml.AliasEvent):
            self._aliases += 1
            if self._aliases > MAX_ALIASES:
                raise yaml.composer.ComposerError(
                    None,
                    None,
                    f"more than {MAX_ALIASES} aliases (*name); a config needs far fewer",
                    event.start_mark,
                )
        elif getattr(event, "tag", None) not in (None, "!"):
            raise yaml.composer.ComposerError(
                None,
                None,
                f"the tag {event.tag!r} is not allowed (a settings file holds plain values: "
                "remove the tag, and quote a value to keep it as text)",
                event.start_mark,
            )
        return super().compose_node(parent, index)

    def construct_mapping(self, node, deep=False):
        if isinstance(node, yaml.MappingNode):
            seen: dict[str, int] = {}
            for key_node, _ in node.value:
                if key_node.tag == "tag:yaml.org,2002:merge" or not isinstance(
                    key_node, yaml.ScalarNode
                ):
                    continue
                if key_node.value in seen:
                    raise yaml.constructor.ConstructorError(
                        None,
                        None,
                        f"duplicate key {key_node.value!r} (first given at line "
                        f"{seen[key_node.value] + 1})",
                        key_node.start_mark,
                    )
                seen[key_node.value] = key_node.start_mark.line
        return super().construct_mapping(node, deep=deep)

    def _timestamp(self, node):
        try:
            return self.construct_yaml_timestamp(node)
        except ValueError:
            return self.construct_scalar(node)


_Loader.add_constructor("tag:yaml.org,2002:timestamp", _Loader._timestamp)
# YAML 1.2's floats that YAML 1.1 leaves as text: a mantissa without a dot (1e7) or an
# exponent without a sign (1.3e7). The resolvers already registered (ints, 1.1 floats)
# are tried first, so nothing they read changes.
_Loader.add_implicit_resolver(
    "tag:yaml.org,2002:float",
    re.compile(r"^[-+]?(?:[0-9][0-9_]*(?:\.[0-9_]*)?|\.[0-9_]+)[eE][-+]?[0-9]+$"),
    list("-+0123456789."),
)


def _check_size(raw: Any, source: str) -> None:
    """Refuse anchor bombs and absurd nesting before anything walks the structure."""
    count = 0
    todo = [(raw, 0)]
    while todo:
        v, depth = todo.pop()
        count += 1
        if count > MAX_NODES:
            raise ConfigError(
                f"{source}: more than {MAX_NODES} values after expanding YAML anchors "
                "(aliases *name); a config is far smaller"
            )
        if depth > MAX_DEPTH:
            raise ConfigError(f"{source}: nested more than {MAX_DEPTH} levels deep")
        if isinstance(v, dict):
            todo.extend((x, depth + 1) for kv in v.items() for x in kv)
        elif isinstance(v, list | tuple):
            todo.extend((x, depth + 1) for x in v)


def read_yaml(path, *, what: str = "config file") -> tuple[Any, str]:
    """Parse a YAML file strictly; return ``(data, text)``.

    Parameters
    ----------
    path : path-like
    what : str
        What the file is, for messages (``'projection file'``).

    Raises
    ------
    ConfigError
        Missing, too large, not UTF-8, invalid YAML (with line and column), a duplicate
        key, an explicit tag, too many aliases, nesting or expanded size beyond the
        limits (:data:`MAX_BYTES`, :data:`MAX_ALIASES`, :data:`MAX_NODES`,
        :data:`MAX_DEPTH`).
    """
    p = Path(path)
    if not p.is_file():
        raise ConfigError(f"{p}: {what} not found")
    size = p.stat().st_size
    if size > MAX_BYTES:
        raise ConfigError(f"{p}: {size} bytes, too large for a {what} (at most {MAX_BYTES})")
    data = p.read_bytes()
    try:
        text = data.decode("utf-8-sig")
    except UnicodeDecodeError as exc:
        raise ConfigError(
            f"{p}: not UTF-8 text (byte 0x{data[exc.start]:02x} at offset {exc.start}); "
            "save the file as UTF-8"
        ) from None
    return load_yaml_text(text, source=str(p)), text


def load_yaml_text(text: str, *, source: str) -> Any:
    """Parse YAML text with the rules of :func:`read_yaml` (``source`` names it in
    messages): a config ``hbayes init`` writes and a snippet of the manual are read as a
    config file is."""
    try:
        raw = yaml.load(text, Loader=_Loader)  # a SafeLoader
    except yaml.YAMLError as exc:
        mark = getattr(exc, "problem_mark", None)
        where = f" at line {mark.line + 1}, column {mark.column + 1}" if mark else ""
        problem = getattr(exc, "problem", None) or str(exc).splitlines()[0]
        raise ConfigError(f"{source}: not valid YAML{where}: {str(problem)[:200]}") from None
    except RecursionError:
        raise ConfigError(f"{source}: nested more than {MAX_DEPTH} levels deep") from None
    _check_size(raw, source)
    return raw
