"""The reader's side of a run directory: one place that opens its files.

Every consumer of a run (``hbayes report``, ``project``, ``compare``, ``batch``,
:func:`heritage_bayes.run.load_run`) reads ``summary.json``, ``posterior.nc`` and the
JSON outputs of the package through these functions, so that a missing, truncated,
mistyped or foreign file is one :class:`~heritage_bayes.errors.InputError` naming the
file and what was expected (the CLI's exit code 2), never a traceback:

- :func:`read_json_object` — a JSON file that must hold an object (``{...}``);
- :func:`read_summary` — ``summary.json``: an object whose keys read by the consumers
  have the types the calibration writes (:data:`SUMMARY_TYPES`);
- :func:`read_posterior` — ``posterior.nc``: an HDF5/NetCDF file arviz opens, with a
  ``posterior`` group.

A file's content is never quoted in a message: it may not be the user's (a system file
copied or linked into the folder).
"""

from __future__ import annotations

import json
from pathlib import Path

from heritage_bayes.errors import InputError

__all__ = [
    "SCHEMA_VERSION",
    "SUMMARY_TYPES",
    "check_run_files",
    "damaged",
    "read_json_object",
    "read_posterior",
    "read_summary",
]

#: Version of the ``summary.json`` layout this hbayes writes and reads up to (a summary
#: without ``schema_version`` is version 1: every hbayes before the typed summary).
SCHEMA_VERSION = 2

#: The files every consumer of a calibration run needs.
RUN_INPUTS = ("posterior.nc", "summary.json", "config.yaml")

#: Keys of ``summary.json`` read by the consumers, and the JSON types they must have
#: when present (a run written by an older hbayes may lack some).
SUMMARY_TYPES: dict[str, tuple[type, ...]] = {
    "models": (dict,),
    "converged": (bool,),
    "unconverged_reasons": (list,),
    "provenance": (dict,),
    "parameters": (dict,),
    "derived": (dict,),
    "metrics": (dict,),
    "correlations": (dict,),
    "alignment": (dict,),
    "periods": (dict,),
    "dt": (int, float),
    "init_steps": (int,),
    "config_hash": (str,),
    "schema_version": (int,),
}

_JSON_NAMES = {dict: "an object", list: "a list", str: "a text", bool: "true/false",
               int: "a number", float: "a number", type(None): "null"}  # fmt: skip


def damaged(path: Path, why: str) -> InputError:
    """The error for a file of a run directory that cannot be used: named, with why,
    and what to do (the run is the package's output: calibrate again)."""
    return InputError(
        f"{path}: {why}; the run directory is damaged or holds a file hbayes did not "
        "write: run `hbayes calibrate` again"
    )


def check_run_files(run_dir: str | Path, names=RUN_INPUTS) -> Path:
    """The run directory as a Path, after checking that it is a folder holding the
    regular files ``names``.

    Raises
    ------
    InputError
        The folder does not exist, or names the files that are missing.
    """
    p = Path(run_dir)
    if not p.is_dir():
        what = "is not a folder" if p.exists() else "not found"
        raise InputError(f"{p}: run directory {what}; run `hbayes calibrate` first")
    missing = [n for n in names if not (p / n).is_file()]
    if missing:
        raise InputError(
            f"{p}: not a complete run directory ({', '.join(missing)} "
            f"{'is' if len(missing) == 1 else 'are'} missing); run `hbayes calibrate` first"
        )
    return p


def read_json_object(path: str | Path, what: str = "a JSON object") -> dict:
    """The object held by a JSON file written by the package.

    Parameters
    ----------
    path : path
    what : str
        What the file should hold, for the message.

    Raises
    ------
    InputError
        Missing, unreadable, not UTF-8, not JSON (truncated), or JSON that is not an
        object: named, its content not quoted.
    """
    path = Path(path)
    try:
        raw = path.read_bytes()
    except FileNotFoundError:
        raise InputError(f"{path}: file not found") from None
    except IsADirectoryError:
        raise damaged(path, "is a folder, not a file") from None
    except OSError as exc:
        raise damaged(path, f"cannot be read ({exc.strerror})") from None
    try:
        data = json.loads(raw.decode("utf-8"))
    except UnicodeDecodeError:
        raise damaged(path, f"not UTF-8 text, so not {what}") from None
    except json.JSONDecodeError as exc:
        short = " (it ends early: truncated)" if exc.pos >= len(raw.rstrip()) else ""
        raise damaged(
            path, f"not valid JSON at line {exc.lineno}, column {exc.colno}{short}"
        ) from None
    except RecursionError:
        raise damaged(path, "JSON nested too deeply") from None
    if not isinstance(data, dict):
        raise damaged(path, f"expected {what}, found {_JSON_NAMES.get(type(data), 'JSON')}")
    return data


def read_summary(run_dir: str | Path) -> dict:
    """``summary.json`` of a run directory, its keys of :data:`SUMMARY_TYPES` checked.

    Raises
    ------
    InputError
        Not a JSON object, a key of the wrong type (named), an object with none of
        the keys of a run summary (another file), or a schema newer than
        :data:`SCHEMA_VERSION`.
    """
    path = Path(run_dir) / "summary.json"
    s = read_json_object(path, "the object of a run summary")
    if s and "models" not in s and not set(s) & set(SUMMARY_TYPES):
        raise damaged(path, "not the summary of a calibration (none of its keys is one)")
    for key, types in SUMMARY_TYPES.items():
        v = s.get(key)
        if v is None or (isinstance(v, types) and (bool in types or not isinstance(v, bool))):
            continue
        want = " or ".join(dict.fromkeys(_JSON_NAMES[t] for t in types))
        raise damaged(path, f"key {key!r}: expected {want}, found {_JSON_NAMES[type(v)]}")
    version = s.get("schema_version", 1)
    if version < 1:
        raise damaged(path, "key 'schema_version': expected a positive whole number")
    if version > SCHEMA_VERSION:
        raise damaged(
            path,
            f"written with summary schema {version}, this hbayes reads up to "
            f"{SCHEMA_VERSION} (upgrade heritage_bayes)",
        )
    models = s.get("models") or {}
    for name, m in models.items():
        if not isinstance(m, dict):
            raise damaged(path, f"key 'models.{name}': expected an object")
    return s


def read_posterior(run_dir: str | Path):
    """``posterior.nc`` of a run directory as arviz InferenceData.

    arviz is imported first, outside the check: a problem of arviz itself (its cache
    folder, say) is not reported as a damaged file.

    Raises
    ------
    InputError
        Not HDF5/NetCDF (truncated, another file) or without a ``posterior`` group.
    """
    from heritage_bayes._arviz import az

    path = Path(run_dir) / "posterior.nc"
    if not path.is_file():
        raise InputError(f"{path}: file not found; run `hbayes calibrate` first")
    with path.open("rb") as f:
        head = f.read(8)
    if head != b"\x89HDF\r\n\x1a\n":
        raise damaged(path, "not a NetCDF-4/HDF5 file (its first bytes are not HDF5's)")
    try:
        idata = az.from_netcdf(str(path), engine="h5netcdf")
    except (OSError, ValueError, KeyError, TypeError, AttributeError) as exc:
        reason = str(exc).splitlines()[0][:100] if str(exc) else type(exc).__name__
        raise damaged(path, f"cannot be read ({reason})") from None
    if "posterior" not in idata.groups():
        raise damaged(path, "holds no 'posterior' group: not the posterior of a calibration")
    return idata
