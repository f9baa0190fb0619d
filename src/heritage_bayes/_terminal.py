"""The terminal side of ``hbayes``: what any terminal or pipe can take.

- :func:`tolerant_streams`: stdout and stderr write escapes for what the terminal's
  encoding cannot hold, so a Latin-1 or ASCII terminal gets every message;
- :func:`reader_gone`: ``hbayes models | head -1`` ends quietly when the reader closes
  the pipe, as Unix tools do;
- :func:`print_error`: ``hbayes: error: MESSAGE`` with every line of bounded length.
"""

from __future__ import annotations

import sys

__all__ = ["EXIT_READER_GONE", "MAX_LINE", "print_error", "reader_gone", "tolerant_streams"]


#: Exit code when the reader of the output went away (``hbayes models | head -1``):
#: 128 + SIGPIPE, what a Unix tool killed by the signal returns.
EXIT_READER_GONE = 128 + 13


def reader_gone() -> int:
    """Stop quietly when stdout's reader closed it, as Unix tools do; stdout is pointed
    at the null device so that Python's last flush finds no broken pipe either."""
    import os

    try:
        fd = os.open(os.devnull, os.O_WRONLY)
        os.dup2(fd, sys.stdout.fileno())
        os.close(fd)
    except (OSError, ValueError, AttributeError):  # not a file (a test's capture)
        pass
    return EXIT_READER_GONE


def tolerant_streams() -> None:
    """stdout and stderr write what the terminal's encoding cannot hold as escapes
    (``\\xb0`` for °, ``\\u03c4`` for τ) instead of failing: a Latin-1 or ASCII
    terminal (``LC_ALL=C``, ``PYTHONIOENCODING=latin-1``) gets every message."""
    for stream in (sys.stdout, sys.stderr):
        try:
            stream.reconfigure(errors="backslashreplace")
        except (AttributeError, ValueError, OSError):  # not a text file of io
            pass


#: The longest line of a message printed (a safety net: the messages themselves quote
#: at most :data:`heritage_bayes.errors.QUOTE_LIMIT` characters of a user's data).
MAX_LINE = 2000


def print_error(exc: BaseException) -> None:
    """``hbayes: error: MESSAGE``, every line cut to :data:`MAX_LINE` characters."""
    from heritage_bayes.errors import shorten

    text = "\n".join(shorten(line, MAX_LINE) for line in str(exc).split("\n"))
    print(f"hbayes: error: {text}", file=sys.stderr)
