"""The schema as data: every key with its type, default, unit and description.

The one source of the configuration reference in the docs and of the comments
``hbayes init`` writes: walk :func:`config_keys` instead of repeating the schema.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

from pydantic import BaseModel
from pydantic_core import PydanticUndefined

from heritage_bayes.config._base import Choices
from heritage_bayes.config._messages import _model_of

__all__ = ["ConfigKey", "config_keys", "describe_key", "field_description"]


@dataclass(frozen=True)
class ConfigKey:
    """One key of the schema.

    Attributes
    ----------
    path : str
        Dotted key path, e.g. ``sampler.max_time`` (``data.measurements`` sections hold
        a list of tables: their keys read ``data.measurements.format``).
    type : str
        The annotation as text.
    required : bool
    default : object
        The default as written in YAML (durations as text, e.g. ``'30min'``), or None.
    unit : str or None
        ``'°C'``, ``'m³'``, ``'-'``, ``'duration'``, ...; None for text and choices.
    description : str
    section : bool
        True when the key holds a section of further keys.
    """

    path: str
    type: str
    required: bool
    default: Any
    unit: str | None
    description: str
    section: bool


def field_description(field) -> str:
    """A key's description, with the names of a registry and what each is when its
    :class:`~heritage_bayes.config._base.Choices` asks for them (``noise:``)."""
    text = field.description or ""
    for meta in field.metadata:
        if isinstance(meta, Choices):
            text = meta.describe(text)
    return text


def _default(field) -> Any:
    if field.default_factory is not None:
        value = field.default_factory()
    elif field.default is PydanticUndefined:
        return None
    else:
        value = field.default
    if isinstance(value, BaseModel):
        return value.model_dump(mode="json")
    return value


def _type_text(annotation) -> str:
    text = getattr(annotation, "__name__", None) if isinstance(annotation, type) else None
    text = text or str(annotation)
    return text.replace("typing.", "").replace("heritage_bayes.config.", "")


def config_keys(root: type[BaseModel] | None = None, prefix: str = "") -> list[ConfigKey]:
    """Every key of the schema below ``root`` (default: the calibration config), in the
    order of the YAML file, sections followed by their keys.

    Examples
    --------
    >>> from heritage_bayes.config import config_keys
    >>> k = {k.path: k for k in config_keys()}["sampler.max_time"]
    >>> k.unit, k.default
    ('duration', '30min')
    """
    if root is None:
        from heritage_bayes.config.calibration import CalibrationConfig

        root = CalibrationConfig
    rows: list[ConfigKey] = []
    for name, field in root.model_fields.items():
        if name == "base_dir":
            continue
        path = f"{prefix}{name}"
        extra = field.json_schema_extra if isinstance(field.json_schema_extra, dict) else {}
        sub = _model_of(field.annotation)
        rows.append(
            ConfigKey(
                path=path,
                type=_type_text(field.annotation),
                required=field.is_required(),
                default=_default(field),
                unit=extra.get("unit"),
                description=field_description(field),
                section=sub is not None,
            )
        )
        if sub is not None:
            rows.extend(config_keys(sub, prefix=f"{path}."))
    return rows


def describe_key(path: str) -> str:
    """One line for a key: ``sampler.max_time [duration] = 30min: wall-time budget ...``
    (for comments in a generated config and for messages)."""
    keys = {k.path: k for k in config_keys()}
    if path not in keys:
        raise KeyError(path)
    k = keys[path]
    unit = f" [{k.unit}]" if k.unit else ""
    default = "required" if k.required else f"default {k.default}"
    return f"{k.path}{unit} ({default}): {k.description}"
