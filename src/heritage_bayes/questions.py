"""Open questions in a configuration: what ``hbayes init`` could not decide.

``hbayes init`` writes a value it could not decide as a marked question, a string
starting with :data:`MARK` (``timezone: "?? the logger's clock: ..."``), and may list
further ones under a top-level key ``questions:``. Neither is a valid setting: a
configuration with open questions is refused by :func:`check_answered` (called by
:func:`heritage_bayes.config.parse_config` before the schema), naming each question by
its key path, so that a run never starts on a guess.
"""

from __future__ import annotations

from typing import Any

from heritage_bayes.errors import ConfigError

__all__ = ["MARK", "check_answered", "open_questions"]

#: The prefix of an unanswered value.
MARK = "??"


def open_questions(raw: Any) -> list[str]:
    """``"key.path: question"`` for every marked value and every entry of ``questions:``."""
    found: list[str] = []

    def walk(node: Any, path: str) -> None:
        if isinstance(node, dict):
            for k, v in node.items():
                walk(v, f"{path}.{k}" if path else str(k))
        elif isinstance(node, list | tuple):
            for i, v in enumerate(node):
                walk(v, f"{path}[{i}]")
        elif isinstance(node, str) and node.lstrip().startswith(MARK):
            found.append(f"{path}: {node.lstrip()[len(MARK) :].strip()}")

    if isinstance(raw, dict):
        extra = raw.get("questions")
        for q in extra if isinstance(extra, list) else [extra] if extra else []:
            found.append(f"questions: {str(q).lstrip(MARK).strip()}")
        walk({k: v for k, v in raw.items() if k != "questions"}, "")
    return found


def check_answered(raw: Any, source: str = "config") -> None:
    """Refuse a configuration with open questions.

    Raises
    ------
    ConfigError
        Naming each open question by its key path, with what to do.
    """
    found = open_questions(raw)
    if found:
        raise ConfigError(
            f"{source}: {len(found)} open question(s) left by `hbayes init`; answer each "
            "(replace the '??' value; delete the 'questions:' list when done):\n  "
            + "\n  ".join(found)
        )
