"""Command-line interface: ``hbayes``.

Thin: parse arguments, call the library, map errors to exit codes
(0 success, 2 user error, 1 internal error). Tested by calling :func:`main` directly.
"""

from __future__ import annotations

import argparse
import sys

from heritage_bayes._version import __version__
from heritage_bayes.errors import InputError

__all__ = ["main"]


def _build_parser() -> argparse.ArgumentParser:
    parser = argparse.ArgumentParser(
        prog="hbayes",
        description="Bayesian calibration of RC models of the indoor climate of monuments.",
    )
    parser.add_argument("--version", action="version", version=f"hbayes {__version__}")
    parser.add_subparsers(dest="command", metavar="COMMAND")
    return parser


def main(argv: list[str] | None = None) -> int:
    """Run ``hbayes``; return the exit code."""
    parser = _build_parser()
    try:
        args = parser.parse_args(argv)
    except SystemExit as exc:  # --help, --version, or argparse usage errors
        return int(exc.code or 0)
    if args.command is None:
        parser.print_help()
        return 2
    try:
        return int(args.func(args) or 0)
    except InputError as exc:
        print(f"hbayes: error: {exc}", file=sys.stderr)
        return 2
    except KeyboardInterrupt:
        print("hbayes: interrupted", file=sys.stderr)
        return 130


if __name__ == "__main__":  # pragma: no cover
    sys.exit(main())
