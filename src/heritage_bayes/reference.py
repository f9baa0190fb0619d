"""Generated references: the configuration keys from the schema, the CLI from its parser.

The documentation's configuration and command-line references are produced by these
functions at build time (``docs/reference/*.md`` call them in executed blocks), never
written by hand: a key added to a pydantic model, a description or unit given to a field,
an option or a subcommand added to :func:`heritage_bayes.cli._build_parser` appears in
the next build with no edit of the docs.

The walk is generic: :func:`schema_reference` follows any pydantic model through its
``model_fields`` (nested models, optional models, lists and mappings of models), and
:func:`parser_reference` any :class:`argparse.ArgumentParser` through its actions and
sub-parsers. What a field states is what the reference prints: its type, its default
(or *required*), its bounds (``ge``/``gt``/``le``/``lt``, lengths), its description, and
a unit or examples when the field carries them (``json_schema_extra={"unit": "m³"}``,
``examples=[...]``).

Layer: documentation tooling beside the CLI; it reads the config schema, the projection
schema and the parser, and nothing reads it.
"""

from __future__ import annotations

import argparse
import enum
import re
import types
import typing

from pydantic import BaseModel
from pydantic.fields import FieldInfo

__all__ = [
    "check_config_snippet",
    "check_projection_snippet",
    "cli_reference",
    "config_reference",
    "parser_reference",
    "schema_reference",
]

#: a Sphinx cross-reference role in a docstring, ``:func:`~a.b``` -> ``a.b``
_ROLE = re.compile(r":[a-z]+:`~?([^`]+)`")
_BOUNDS = (("ge", "≥"), ("gt", ">"), ("le", "≤"), ("lt", "<"))
_LENGTHS = (("min_length", "at least {} items"), ("max_length", "at most {} items"))


# --------------------------------------------------------------------------- schema
def _type_text(tp) -> str:
    """A readable type: ``str | none``, ``"estimate" | "steady"``, ``list[float]``."""
    origin = typing.get_origin(tp)
    args = typing.get_args(tp)
    if tp is type(None):
        return "none"
    if origin is typing.Literal:
        return " | ".join(f'"{a}"' if isinstance(a, str) else repr(a) for a in args)
    if origin in (typing.Union, types.UnionType):
        return " | ".join(_type_text(a) for a in args)
    if origin is typing.Annotated:
        return _type_text(args[0])
    if origin in (list, tuple, set, frozenset):
        inner = ", ".join("…" if a is Ellipsis else _type_text(a) for a in args)
        return f"{origin.__name__}[{inner}]" if inner else origin.__name__
    if origin is dict:
        if not args:
            return "mapping"
        return f"mapping[{_type_text(args[0])}, {_type_text(args[1])}]"
    if isinstance(tp, type) and issubclass(tp, BaseModel):
        return "section"
    if isinstance(tp, type) and issubclass(tp, enum.Enum):
        return " | ".join(f'"{m.value}"' for m in tp)
    if tp is typing.Any:
        return "any"
    name = getattr(tp, "__name__", None) or str(tp).replace("typing.", "")
    return {"Timedelta": "duration", "NoneType": "none"}.get(name, name)


def _cell(text: str) -> str:
    """Text safe inside a markdown table cell."""
    return " ".join(str(text).split()).replace("|", "\\|")


def _anchor(root: type[BaseModel], path: str) -> str:
    """Anchor of a section's table, unique per page (two roots may share key names)."""
    slug = re.sub(r"[^a-z0-9]+", "-", path.lower()).strip("-")
    return f"{root.__name__.lower()}-{slug}" if slug else root.__name__.lower()


def _value_text(value) -> str:
    if value is None:
        return "none"
    if isinstance(value, bool):
        return "true" if value else "false"
    if isinstance(value, enum.Enum):
        value = value.value
    if value in ({}, [], ""):
        return "empty"
    return _cell(f"`{value}`")


def _bounds_text(field: FieldInfo) -> str:
    parts = []
    for meta in field.metadata:
        for attr, sign in _BOUNDS:
            v = getattr(meta, attr, None)
            if v is not None:
                parts.append(f"{sign} {v:g}" if isinstance(v, float) else f"{sign} {v}")
        for attr, text in _LENGTHS:
            v = getattr(meta, attr, None)
            if v is not None:
                parts.append(text.format(v))
    return ", ".join(parts)


def _description_text(field: FieldInfo, unit: str | None) -> str:
    from heritage_bayes.config.reference import field_description

    text = " ".join(field_description(field).split())
    if unit and unit != "-" and f"[{unit}]" not in text:
        text = f"[{unit}] {text}".strip()
    examples = field.examples
    if examples:
        text += (" " if text else "") + "Example: " + ", ".join(f"`{e}`" for e in examples)
    return _cell(_ROLE.sub(r"`\1`", text))


def _doc_text(model: type[BaseModel] | None) -> str:
    """The first paragraph of a model's own docstring (not pydantic's BaseModel's)."""
    doc = (model.__dict__.get("__doc__") if model is not None else None) or ""
    first = " ".join(doc.strip().split("\n\n")[0].split())
    return _ROLE.sub(r"`\1`", first)


def schema_reference(model: type[BaseModel], *, title: str | None = None, level: int = 2) -> str:
    """The keys of a config schema as markdown: one table per section.

    The keys come from :func:`heritage_bayes.config.config_keys` (the schema's one
    walk: key paths, defaults as written in YAML, units, descriptions); the types and
    bounds (``ge``/``gt``/``le``/``lt``, lengths) from the pydantic fields themselves.

    Parameters
    ----------
    model : type[pydantic.BaseModel]
        The root of the schema, e.g. :class:`heritage_bayes.config.CalibrationConfig`.
    title : str, optional
        Heading of the root table (default: the model's name).
    level : int
        Markdown heading level of each table.

    Returns
    -------
    str
        Markdown: the root's keys, then for every section (a key that holds further
        keys) a heading with its key path, the section's docstring and a table
        *key | type | default | allowed | description*; a section's row in its parent's
        table links to its own table.
    """
    from heritage_bayes.config import config_keys
    from heritage_bayes.config._messages import section_model

    keys = config_keys(model)
    tables: dict[str, list] = {"": []}
    for k in keys:
        parent = k.path.rpartition(".")[0]
        tables.setdefault(parent, []).append(k)
        if k.section:
            tables.setdefault(k.path, [])
    hashes = "#" * level
    out = []
    for path, rows in tables.items():
        sec = model if not path else section_model(path.split("."), model)
        heading = (title or model.__name__) if not path else f"`{path}`"
        out.append(f"{hashes} {heading} {{ #{_anchor(model, path)} }}\n")
        doc = _doc_text(sec)
        if doc:
            out.append(doc + "\n")
        out.append("| key | type | default | allowed | description |")
        out.append("|---|---|---|---|---|")
        for k in rows:
            field = sec.model_fields[k.path.rpartition(".")[2]]
            if k.section:
                type_text = f"[section](#{_anchor(model, k.path)})"
                default = "see section" if not k.required else "**required**"
            else:
                choices = next((m.names for m in field.metadata if hasattr(m, "names")), None)
                type_text = _cell(
                    _type_text(typing.Literal[choices] if choices else field.annotation)
                )
                default = "**required**" if k.required else _value_text(k.default)
            out.append(
                f"| `{k.path}` | {type_text} | {default} | {_bounds_text(field)} "
                f"| {_description_text(field, k.unit)} |"
            )
        out.append("")
    return "\n".join(out)


def config_reference() -> str:
    """The reference of the calibration config and of the projection file (markdown)."""
    from heritage_bayes.config import CalibrationConfig
    from heritage_bayes.projection.config import ProjectionConfig

    return "\n".join(
        [
            schema_reference(CalibrationConfig, title="Calibration config (`hbayes calibrate`)"),
            schema_reference(ProjectionConfig, title="Projection file (`hbayes project`)"),
        ]
    )


# --------------------------------------------------------------------------- parser
def _subcommands(parser: argparse.ArgumentParser):
    for action in parser._actions:
        if isinstance(action, argparse._SubParsersAction):
            helps = {a.dest: a.help for a in action._choices_actions}
            for name, sub in action.choices.items():
                yield name, sub, helps.get(name)


def _action_help(parser: argparse.ArgumentParser, action: argparse.Action) -> str:
    if not action.help or action.help == argparse.SUPPRESS:
        return ""
    text = parser._get_formatter()._expand_help(action)
    if action.choices and not isinstance(action, argparse._SubParsersAction):
        names = [str(c) for c in action.choices]
        choices = ", ".join(f"`{c}`" for c in names)
        text = text.replace(", ".join(names), choices)  # a help listing %(choices)s
        if choices not in text:
            text += f" (one of {choices})"
    default = action.default
    if (
        action.option_strings
        and action.nargs != 0
        and default not in (None, False, argparse.SUPPRESS)
        and str(default) not in text
    ):
        text += f" (default `{default}`)"
    return _cell(" ".join(text.split()))


def _action_rows(parser: argparse.ArgumentParser) -> list[str]:
    rows = []
    for action in parser._actions:
        if isinstance(action, argparse._SubParsersAction) or action.help == argparse.SUPPRESS:
            continue
        if action.option_strings:
            names = ", ".join(f"`{s}`" for s in action.option_strings)
            takes = action.nargs != 0
            metavar = action.metavar or action.dest.upper()
            arg = f"`{metavar}`" if takes else ""
        else:
            names = f"`{action.metavar or action.dest.upper()}`"
            arg = "optional" if action.nargs in ("?", "*") else "required"
        rows.append(f"| {names} | {arg} | {_action_help(parser, action)} |")
    return rows


def parser_reference(parser: argparse.ArgumentParser, *, level: int = 2) -> str:
    """Every command of an argparse parser as markdown.

    Parameters
    ----------
    parser : argparse.ArgumentParser
        The program's parser, sub-parsers included (e.g. ``hbayes``'s).
    level : int
        Markdown heading level of each command.

    Returns
    -------
    str
        Markdown: the program's usage and options, then for every subcommand (recursively)
        a heading ``prog command``, its description, its usage line and a table
        *argument | value | help* with the defaults and choices argparse knows.
    """
    out = []

    def visit(p: argparse.ArgumentParser, lvl: int, summary: str | None) -> None:
        hashes = "#" * lvl
        out.append(f"{hashes} `{p.prog}`\n")
        text = p.description or summary
        if text:
            out.append(" ".join(text.split()) + "\n")
        usage = " ".join(p.format_usage().removeprefix("usage: ").split())
        out.append(f"```text\n{usage}\n```\n")
        rows = _action_rows(p)
        if rows:
            out.append("| argument | value | help |")
            out.append("|---|---|---|")
            out.extend(rows)
            out.append("")
        for _name, sub, help_ in _subcommands(p):
            visit(sub, min(lvl + 1, 6), help_)

    visit(parser, level, None)
    return "\n".join(out)


def cli_reference() -> str:
    """The reference of the ``hbayes`` command line (markdown), from its parser."""
    from heritage_bayes.cli import _build_parser

    return parser_reference(_build_parser())


# --------------------------------------------------------------------------- snippets
def _merge(base: dict, extra: dict) -> dict:
    out = dict(base)
    for k, v in extra.items():
        out[k] = _merge(out[k], v) if isinstance(v, dict) and isinstance(out.get(k), dict) else v
    return out


def check_config_snippet(snippet: str, base: str = "configs/demo.yaml") -> str:
    """Validate a piece of a calibration config as the docs show it; return it as given.

    The snippet (YAML text) is merged key by key into the config ``base`` and the result
    goes through the same checks as ``hbayes calibrate`` before it reads any data: the
    schema (:func:`heritage_bayes.config.parse_config`) and the models with their
    options and priors (:func:`heritage_bayes.calibration.calibrate.check_models`). The manual's
    how-to pages print their config examples through this function, so an example with
    a misspelt key or an option a model does not take fails the docs build.

    Parameters
    ----------
    snippet : str
        YAML text: keys of a calibration config, nested as in a file.
    base : str
        A complete config the snippet is merged into (its paths are not read).

    Returns
    -------
    str
        ``snippet`` as a fenced YAML block, ready to print into a page.

    Raises
    ------
    heritage_bayes.ConfigError
        The merged config is not valid; the message names the key path.
    """
    from heritage_bayes.calibration.calibrate import check_models
    from heritage_bayes.config import load_yaml_text, parse_config, read_yaml

    raw, _ = read_yaml(base)
    extra = load_yaml_text(snippet, source="config snippet")
    if not isinstance(extra, dict):
        raise ValueError(f"a config snippet is a YAML mapping, got {type(extra).__name__}")
    check_models(parse_config(_merge(raw, extra), source=f"snippet merged into {base}"))
    return f"```yaml\n{snippet.strip()}\n```"


def check_projection_snippet(snippet: str) -> str:
    """Validate a projection file as the docs show it; return it as a fenced YAML block.

    The snippet is a complete projection file (:class:`ProjectionConfig`), validated by
    :func:`heritage_bayes.projection.config.parse_projection_config` as ``hbayes
    project`` does before it runs anything.

    Raises
    ------
    heritage_bayes.ConfigError
        The file is not valid; the message names the key path.
    """
    from heritage_bayes.config import load_yaml_text
    from heritage_bayes.projection.config import parse_projection_config

    raw = load_yaml_text(snippet, source="projection snippet")
    parse_projection_config(raw, source="projection snippet")
    return f"```yaml\n{snippet.strip()}\n```"
