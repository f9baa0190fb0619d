"""The run marker: what makes a folder one the package wrote, and which files it owns.

A folder is a run directory (or another output folder of the package) only if it holds
a valid marker, ``.hbayes-run.json``, written *first*, before any other file:

.. code-block:: json

    {"format": "hbayes-run", "version": 1, "kind": "calibration",
     "run_id": "6f1c...", "created": "2026-11-25T13:40:02+00:00",
     "files": ["chain_thermal.h5", "config.yaml", "posterior.nc", "summary.json"]}

``--force`` and ``--resume`` act only on folders with a valid marker and only on the
files it lists; any other entry of the folder (a user's notes, a projection written
into the run later) is left as it is. A folder without a marker is never taken for a
run directory, whatever its files are called.
"""

from __future__ import annotations

import datetime
import json
import os
import stat
import uuid
from dataclasses import dataclass, field, replace
from pathlib import Path

from heritage_bayes.errors import InputError
from heritage_bayes.rundir.atomic import atomic_write_text

__all__ = ["MARKER", "RunMarker", "new_marker", "read_marker", "write_marker"]

#: File name of the marker (hidden: it is the package's, not the user's).
MARKER = ".hbayes-run.json"
FORMAT = "hbayes-run"
VERSION = 1
_MAX_BYTES = 1 << 20
KINDS = ("calibration", "projection", "comparison", "portfolio")


@dataclass(frozen=True)
class RunMarker:
    """The content of a marker file.

    Attributes
    ----------
    kind : {"calibration", "projection", "comparison", "portfolio"}
        Which command made the folder.
    run_id : str
        32 hex digits (``uuid4``), new for each folder the package makes.
    created : str
        ISO 8601 creation time [UTC].
    files : tuple of str
        Entries of the folder the package wrote (plain names; folders included, e.g. a
        candidate's run directory inside a comparison).
    version : int
        Format version of the marker.
    """

    kind: str
    run_id: str
    created: str
    files: tuple[str, ...] = field(default_factory=tuple)
    version: int = VERSION

    def with_files(self, *names: str) -> RunMarker:
        """The marker with ``names`` added to :attr:`files` (sorted, no duplicates)."""
        return replace(self, files=tuple(sorted({*self.files, *names})))

    def owns(self, name: str) -> bool:
        return name in self.files or name == MARKER

    def to_json(self) -> str:
        return json.dumps(
            {
                "format": FORMAT,
                "version": self.version,
                "kind": self.kind,
                "run_id": self.run_id,
                "created": self.created,
                "files": list(self.files),
            },
            indent=1,
        )


def new_marker(kind: str, files=()) -> RunMarker:
    """A marker for a folder the package is about to make (new run id, time now)."""
    if kind not in KINDS:
        raise ValueError(f"kind: expected one of {KINDS} (got {kind!r})")
    now = datetime.datetime.now(datetime.UTC).isoformat(timespec="seconds")
    return RunMarker(kind, uuid.uuid4().hex, now, tuple(sorted(set(files))))


def _invalid(path: Path, why: str) -> InputError:
    return InputError(
        f"{path}: not a valid run marker of hbayes ({why}); the folder is not taken for "
        "one the package wrote: choose another folder"
    )


def read_marker(folder: str | Path) -> RunMarker | None:
    """The marker of ``folder``, or None if it has none.

    Raises
    ------
    InputError
        A marker that is a symlink or not a regular file, too large, not JSON, of
        another format or a newer version, or listing a name that is not a plain file
        name (``..``, a separator, the marker itself).
    """
    path = Path(folder) / MARKER
    try:
        st = os.lstat(path)
    except FileNotFoundError:
        return None
    except NotADirectoryError:
        return None
    if not stat.S_ISREG(st.st_mode):
        raise _invalid(path, "a symlink or not a regular file")
    if st.st_size > _MAX_BYTES:
        raise _invalid(path, f"{st.st_size} bytes")
    fd = os.open(path, os.O_RDONLY | os.O_NOFOLLOW)
    with os.fdopen(fd, "rb") as fh:
        raw = fh.read(_MAX_BYTES + 1)
    try:
        d = json.loads(raw.decode("utf-8"))
    except (UnicodeDecodeError, json.JSONDecodeError) as exc:
        raise _invalid(path, f"not JSON: {type(exc).__name__}") from None
    if not isinstance(d, dict) or d.get("format") != FORMAT:
        raise _invalid(path, f"format is not {FORMAT!r}")
    version = d.get("version")
    if not isinstance(version, int) or not 1 <= version <= VERSION:
        raise _invalid(path, f"version {version!r}; this hbayes reads up to {VERSION}")
    kind, run_id, created, files = (d.get(k) for k in ("kind", "run_id", "created", "files"))
    if kind not in KINDS:
        raise _invalid(path, f"kind {kind!r}")
    if not isinstance(run_id, str) or len(run_id) != 32 or not _hex(run_id):
        raise _invalid(path, "run_id is not 32 hex digits")
    if not isinstance(created, str):
        raise _invalid(path, "no creation time")
    if not isinstance(files, list) or not all(isinstance(f, str) for f in files):
        raise _invalid(path, "files is not a list of names")
    for f in files:
        if not f or f in (".", "..", MARKER) or "/" in f or "\\" in f or "\x00" in f:
            raise _invalid(path, f"it lists {f[:80]!r}, not a plain file name")
    return RunMarker(kind, run_id, created, tuple(sorted(set(files))), version)


def _hex(s: str) -> bool:
    try:
        int(s, 16)
    except ValueError:
        return False
    return True


def write_marker(folder: str | Path, marker: RunMarker) -> Path:
    """Write (or replace) the marker of ``folder`` atomically; ``folder`` must exist.

    The marker is renamed over the old one: a symlink named like the marker is
    replaced, never followed.
    """
    return atomic_write_text(Path(folder) / MARKER, marker.to_json())
