"""Exception types.

User errors (a bad config, a bad data file, bad arguments) subclass :class:`InputError`,
itself a :class:`ValueError`; the CLI maps them to exit code 2 and prints the message
without a traceback. Anything else is an internal error (exit code 1).
"""

from __future__ import annotations

__all__ = ["ConfigError", "DataError", "InputError"]


class InputError(ValueError):
    """Bad input from the user: the message says what was expected and what was found."""


class ConfigError(InputError):
    """An invalid configuration: the message names the key path."""


class DataError(InputError):
    """An invalid data file or table: the message names the file, column and row."""
