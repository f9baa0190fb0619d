"""The terminal side of ``hbayes``: what any terminal or pipe can take.

- :func:`tolerant_streams`: stdout and stderr write escapes for what the terminal's
  encoding cannot hold, so a Latin-1 or ASCII terminal gets every message;
- :func:`reader_gone`: ``hbayes models | head -1`` ends quietly when the reader closes
  the pipe, as Unix tools do;
- :func:`print_error`: ``hbayes: error: MESSAGE`` with every line of bounded length;
- :func:`disk_error_text` for a full or read-only disk, :func:`internal_error` for a bug.
"""

from __future__ import annotations

import errno
import sys

__all__ = [
    "DISK_ERRORS",
    "EXIT_READER_GONE",
    "MAX_LINE",
    "disk_error_text",
    "internal_error",
    "print_error",
    "reader_gone",
    "tolerant_streams",
]


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


#: A full or read-only disk: the user's to fix, not a bug (``hbayes`` exits 2).
DISK_ERRORS = (errno.ENOSPC, errno.EDQUOT, errno.EROFS)


def disk_error_text(exc: OSError, args) -> str:
    """A full or read-only disk, named by the file or, when the library that wrote
    (HDF5, NetCDF) did not say which, by the command's output."""
    where = exc.filename or next(
        (v for v in (getattr(args, k, None) for k in ("out", "output", "run_dir")) if v), None
    )
    text = exc.strerror or str(exc)
    if where:
        text += f" while writing {where}"
    return (
        text + "; free some space or choose another --out (earlier outputs are kept as they were)"
    )


def internal_error() -> int:
    """Show the traceback of the exception being handled (a bug) and return exit code 1."""
    import traceback

    traceback.print_exc()
    print(
        "hbayes: internal error (exit code 1); please report it with the traceback above",
        file=sys.stderr,
    )
    return 1
