"""YAML text the package writes line by line (``hbayes init``'s commented config):
values through the YAML emitter, on one line; comments escaped.

Text from the user's files — a folder name, a column name — may hold a line break
(``\\n``, ``\\r``, U+0085, U+2028, U+2029: YAML reads each as one). Written raw into a
comment it would end the comment and add a key (a data folder named
``"x\\nroom_volume: 1"``); written raw as a plain or single-quoted value it would
fold onto the next line. Here a value is emitted by :mod:`yaml` (double-quoted, with
its escapes, when it holds such a character) and a comment writes the character as its
escape; :func:`one_line_each` refuses a line that is not one.
"""

from __future__ import annotations

import textwrap
import unicodedata

import yaml

__all__ = ["comment", "one_line_each", "wrap_comment", "yaml_value"]

#: The characters YAML reads as a line break.
LINE_BREAKS = "\r\n\x85\u2028\u2029"


def comment(text) -> str:
    """``text`` made safe inside a YAML comment: every line break and every control or
    format character written as its escape (``\\n``, ``\\u2028``)."""
    return "".join(
        c.encode("unicode_escape").decode("ascii")
        if unicodedata.category(c)[0] == "C" or unicodedata.category(c) in ("Zl", "Zp")
        else c
        for c in str(text)
    )


def wrap_comment(text, first: str, rest: str, width: int = 92) -> list[str]:
    """Comment lines of at most ``width`` characters, ``text`` escaped (:func:`comment`);
    ``first`` and ``rest`` are the prefixes (``"# "``, indented as the key)."""
    lines = textwrap.wrap(comment(text), width, initial_indent=first, subsequent_indent=rest)
    return lines or [first]


class _OneLineDumper(yaml.SafeDumper):
    """The YAML emitter, with a string that holds a line break or a control character
    written double-quoted (its escapes on one line)."""


def _str_scalar(dumper, v: str):
    style = '"' if comment(v) != v else None
    return dumper.represent_scalar("tag:yaml.org,2002:str", v, style=style)


_OneLineDumper.add_representer(str, _str_scalar)


def yaml_value(v) -> str:
    """``v`` (a scalar, list or mapping) in YAML's flow style, on one line."""
    text = yaml.dump(
        v, Dumper=_OneLineDumper, default_flow_style=True, allow_unicode=True, width=10**9
    ).strip()
    return text[:-4].strip() if text.endswith("\n...") else text.removesuffix("...").strip()


def one_line_each(lines: list[str]) -> str:
    """The file's text from its lines; a line holding a line break is a bug (a value or
    comment not written through this module), raised as ValueError."""
    for line in lines:
        if any(c in line for c in LINE_BREAKS):
            raise ValueError(f"a line of YAML text is not one line: {line[:100]!r}")
    return "\n".join(lines)
