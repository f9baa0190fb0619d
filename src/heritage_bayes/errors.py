"""Exception types.

User errors (a bad config, a bad data file, bad arguments) subclass :class:`InputError`,
itself a :class:`ValueError`; the CLI maps them to exit code 2 and prints the message
without a traceback. Anything else is an internal error (exit code 1).
"""

from __future__ import annotations

__all__ = [
    "QUOTE_LIMIT",
    "ConfigError",
    "DataError",
    "InputError",
    "check_known_keys",
    "quoted",
    "shorten",
]

#: The most characters of a user's data a message quotes (one cell, one line, one name):
#: a 100 MB line in a logger file is named by its position, not echoed.
QUOTE_LIMIT = 100


class InputError(ValueError):
    """Bad input from the user: the message says what was expected and what was found."""


class ConfigError(InputError):
    """An invalid configuration: the message names the key path."""


class DataError(InputError):
    """An invalid data file or table: the message names the file, column and row."""


def check_known_keys(raw, known, *, source: str, what: str) -> None:
    """Refuse a mapping none of whose top-level keys is a known one, *without quoting
    them*: it is not a file of that kind (``/etc/shadow`` given as a config), and its
    lines are not the user's data to echo. A file with at least one known key is taken
    for the user's own, and its unknown keys are named as usual.

    Parameters
    ----------
    raw : object
        The parsed YAML.
    known : iterable of str
        The keys a file of this kind may have at the top level.
    source : str
        The file, for the message.
    what : str
        E.g. ``"calibration config"``.

    Raises
    ------
    ConfigError
    """
    known = sorted(known)
    if isinstance(raw, dict) and raw and not any(k in known for k in raw):
        raise ConfigError(
            f"{source}: not a {what}: none of its {len(raw)} top-level key(s) is one "
            f"(expected some of {', '.join(known)}); is it the right file? (its content is "
            "not shown: only files a config declares as data are quoted)"
        )


def shorten(text: object, limit: int = QUOTE_LIMIT) -> str:
    """``str(text)`` cut to ``limit`` characters, saying how long it was.

    >>> shorten("x" * 1000, 5)
    'xxxxx... (1000 characters)'
    """
    text = str(text)
    return text if len(text) <= limit else f"{text[:limit]}... ({len(text)} characters)"


def quoted(value: object, limit: int = QUOTE_LIMIT) -> str:
    """``repr`` of a user's value (a cell, a line, a column name) for a message, cut to
    ``limit`` characters of its text: ``'abc'``, ``'AAAA'... (2000000 characters)``.

    >>> quoted("abc")
    "'abc'"
    >>> quoted("A" * 500, 4)
    "'AAAA'... (500 characters)"
    """
    if not isinstance(value, str):
        value = str(value)
    if len(value) <= limit:
        return repr(value)
    return f"{value[:limit]!r}... ({len(value)} characters)"
