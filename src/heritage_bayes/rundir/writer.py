"""The writer's side of a run directory: marker, lock, staging folder, swap at the end.

A run writes into ``.<name>.partial`` beside ``out`` — created exclusively
(``mkdir``), never through a symlink, its marker written first — and only a complete
run replaces ``out``, by renaming: a failed or interrupted re-run leaves the previous
run intact, and ``--resume`` continues the chains kept in the staging folder.

What may be written where:

- ``out`` new or an empty folder: the run becomes it.
- ``out`` with a valid marker of a calibration (:mod:`heritage_bayes.rundir.marker`):
  a re-run replaces the files the marker lists; any other entry (the user's notes, a
  projection written into the run) is kept, byte for byte.
- ``out`` without a marker and not empty: refused, naming what it holds; with
  ``force`` the run is written beside those entries, provided none of them has a name
  the run writes (those are named and refused: nothing of the user's is replaced).
- A staging folder, ``.<name>.old`` left by an interrupted swap, or the marker itself
  that is a symlink, not a folder, or has no valid marker: refused, named.

One run at a time per folder: :class:`~heritage_bayes.rundir.lock.FolderLock` on the
resolved path.
"""

from __future__ import annotations

import json
import os
import shutil
import stat
from collections.abc import Iterable
from pathlib import Path

from heritage_bayes.errors import InputError
from heritage_bayes.rundir.lock import FolderLock, lock_path
from heritage_bayes.rundir.marker import MARKER, new_marker, read_marker, write_marker
from heritage_bayes.rundir.policy import resolve_output

__all__ = [
    "RUN_FILES",
    "RunWriter",
    "is_run_directory",
    "published_path",
    "run_file_name",
    "saved_chains",
    "staging_path",
]

#: What ``hbayes calibrate`` writes into a run directory (besides ``chain_<model>.h5``).
RUN_FILES = (
    "config.yaml",
    "config.original.yaml",
    "posterior.nc",
    "summary.json",
    "report.html",
)
#: The commit journal: entries of ``out`` moved into the staging folder for the swap.
_JOURNAL = ".hbayes-commit.json"


def run_file_name(name: str) -> bool:
    """True for a name a calibration writes (outputs, chains, the marker)."""
    return name in RUN_FILES or name == MARKER or (name.startswith("chain_") and ".h5" in name)


def _is_temporary(name: str) -> bool:
    return name.startswith(".") and name.endswith(".tmp")


def is_run_directory(path: str | Path) -> bool:
    """True for a folder with a valid marker of a calibration (see
    :mod:`heritage_bayes.rundir.marker`); an invalid marker counts as none."""
    p = Path(path)
    if not p.is_dir():
        return False
    try:
        m = read_marker(p)
    except InputError:
        return False
    return m is not None and m.kind == "calibration"


def staging_path(out: Path) -> Path:
    """Where a run into ``out`` is written until it is complete (a hidden sibling)."""
    return out.parent / f".{out.name}.partial"


def published_path(folder: str | Path) -> Path:
    """The run directory that ``folder`` becomes when its run is complete: the folder
    itself, or for a staging folder (:func:`staging_path`) the run directory it is
    swapped into. Text that names a run (the report's Python lines) names this one,
    not a folder that is gone once the run is committed."""
    p = Path(folder).absolute()
    name = p.name
    if name.startswith(".") and name.endswith(".partial") and len(name) > len("..partial"):
        return p.parent / name[1 : -len(".partial")]
    return p


def _old_path(out: Path) -> Path:
    return out.parent / f".{out.name}.old"


def saved_chains(out: str | Path) -> list[Path]:
    """The chain checkpoints ``--resume`` would continue for the run directory ``out``:
    those of an unfinished run (its staging folder) or else of the finished one; only
    in folders with a valid marker."""
    out = Path(out).absolute()
    for folder in (staging_path(out), out):
        if _own_folder(folder):
            found = sorted(folder.glob("chain_*.h5"))
            if found:
                return found
    return []


def _own_folder(folder: Path) -> bool:
    """A real folder (not a symlink) with a valid calibration marker."""
    try:
        st = os.lstat(folder)
    except (FileNotFoundError, NotADirectoryError):
        return False
    return stat.S_ISDIR(st.st_mode) and is_run_directory(folder)


def _check_own(folder: Path, role: str, hint: str) -> bool:
    """False if ``folder`` does not exist; True if it is a real folder with a valid
    marker; otherwise an InputError naming it."""
    try:
        st = os.lstat(folder)
    except (FileNotFoundError, NotADirectoryError):
        return False
    if stat.S_ISLNK(st.st_mode) or not stat.S_ISDIR(st.st_mode):
        kind = "a symlink" if stat.S_ISLNK(st.st_mode) else "not a folder"
        raise InputError(
            f"{folder}: the {role} is {kind}, not one hbayes made; it is not followed nor "
            f"removed: {hint}"
        )
    if not is_run_directory(folder):
        raise InputError(
            f"{folder}: the {role} has no valid {MARKER}: hbayes did not make it and leaves "
            f"it as it is: {hint}"
        )
    return True


def _remove_owned(folder: Path, *, extra: Iterable[str] = ()) -> list[str]:
    """Delete the entries of ``folder`` its marker lists (plus ``extra`` names and
    temporary files), then the marker and the folder if nothing else is left; return
    the names left (not the package's)."""
    marker = read_marker(folder)
    owned = set(marker.files if marker else ()) | set(extra)
    left = []
    for e in sorted(folder.iterdir(), key=lambda q: q.name):
        if e.name in owned or _is_temporary(e.name):
            if e.is_dir() and not e.is_symlink():
                shutil.rmtree(e)
            else:
                e.unlink()
        elif e.name != MARKER:
            left.append(e.name)
    if not left:
        (folder / MARKER).unlink(missing_ok=True)
        folder.rmdir()
    return left


def _staged_names(staging: Path) -> list[str]:
    return sorted(
        e.name
        for e in staging.iterdir()
        if e.name not in (MARKER, _JOURNAL) and not _is_temporary(e.name)
    )


class RunWriter:
    """The writer's side of a run directory (see the module documentation).

    Use as a context manager: ``with RunWriter(out) as w: ... write into w.staging ...;
    w.commit()``. :meth:`check` (called by ``__enter__``, or earlier to fail before the
    data are read) resolves ``out`` under the output-path policy, ``protect`` listing the
    config's folder and the data files.
    """

    def __init__(
        self,
        out: str | Path,
        *,
        force: bool = False,
        resume: bool = False,
        protect: Iterable[str | Path] = (),
    ):
        self.typed = out
        self.out = Path(out).absolute()
        self.force = force
        self.resume = resume
        self.protect = list(protect)
        self.committed = False
        self._lock: FolderLock | None = None
        self._made_parent = False
        self._checked = False

    @property
    def staging(self) -> Path:
        return staging_path(self.out)

    @property
    def lock_path(self) -> Path:
        return lock_path(self.out)

    # -- checks that need no data: called before anything is read
    def check(self) -> None:
        """Raise :class:`InputError` if ``out`` cannot or may not be written."""
        out = self.out = resolve_output(self.typed, what="--out", protect=self.protect)
        hint = "remove or rename it, or choose another --out"
        _check_own(self.staging, "staging folder of an unfinished run", hint)
        _check_own(_old_path(out), "previous run kept by an interrupted swap", hint)
        if out.is_dir():
            marker = read_marker(out)
            entries = sorted(e.name for e in out.iterdir())
            if marker is not None and marker.kind != "calibration":
                raise InputError(
                    f"--out {out}: holds a {marker.kind} of hbayes, not a run directory; "
                    "choose another folder"
                )
            if marker is None and entries:
                shown = ", ".join(entries[:5]) + (", ..." if len(entries) > 5 else "")
                clash = [e for e in entries if run_file_name(e)]
                if not self.force:
                    raise InputError(
                        f"--out {out}: the folder exists and is not a run directory of "
                        f"hbayes (no {MARKER}; it holds {shown}); choose another folder, "
                        "or add --force to write the run beside those files (none of "
                        "them is replaced)"
                    )
                if clash:
                    raise InputError(
                        f"--out {out}: the folder is not a run directory of hbayes (no "
                        f"{MARKER}) and holds {', '.join(clash)}, named like the run's "
                        "files; hbayes does not replace files it did not write, even with "
                        "--force: move them away or choose another folder"
                    )
        self._checked = True

    def __enter__(self):
        self.check()
        self._made_parent = not self.out.parent.exists()
        try:
            self.out.parent.mkdir(parents=True, exist_ok=True)
            self._lock = FolderLock(self.out).acquire()
        except PermissionError as exc:
            raise InputError(f"--out {self.out}: cannot write ({exc.strerror})") from None
        try:
            self._check_again_and_recover()
            self._prepare_staging()
        except BaseException:
            self._release()
            raise
        return self

    def _check_again_and_recover(self) -> None:
        self.check()  # under the lock: nothing changed since the first check
        out, old = self.out, _old_path(self.out)
        if _check_own(old, "previous run", "") and not out.exists():
            os.rename(old, out)  # a swap was cut short: undo it
        elif old.exists():
            _remove_owned(old)
        journal = self.staging / _JOURNAL
        if self.staging.is_dir() and journal.is_file():  # the swap never happened
            for name in json.loads(journal.read_text(encoding="utf-8")):
                if (self.staging / name).exists() and not (out / name).exists():
                    os.rename(self.staging / name, out / name)
            journal.unlink()
        (out / _JOURNAL).unlink(missing_ok=True)  # the swap happened; the journal is stale

    def _prepare_staging(self) -> None:
        staging = self.staging
        if staging.exists() and not self.resume:
            left = _remove_owned(staging, extra=[n for n in _staged_names(staging)
                                                  if run_file_name(n)])  # fmt: skip
            if left:
                raise InputError(
                    f"{staging}: holds {', '.join(left)}, not written by hbayes; it is "
                    "left as it is: move those away"
                )
        if not staging.exists():
            os.mkdir(staging)  # exclusive (the lock is held): never an existing folder
            write_marker(staging, new_marker("calibration"))  # first
        if self.resume and _own_folder(self.out):  # extend a finished run's chains
            owned = read_marker(self.out).files
            for p in sorted(self.out.glob("chain_*.h5")):
                if p.name in owned and not (staging / p.name).exists():
                    shutil.copy2(p, staging / p.name, follow_symlinks=False)

    def commit(self) -> None:
        """Make the staging folder the run directory, keeping every entry of ``out`` its
        marker does not list (moved across by rename, byte for byte)."""
        from heritage_bayes.inference.backend import _DeferSignals

        out, staging, old = self.out, self.staging, _old_path(self.out)
        names = _staged_names(staging)
        marker = read_marker(staging) or new_marker("calibration")
        with _DeferSignals():
            write_marker(staging, marker.with_files(*names))
            if out.is_dir():
                prev = read_marker(out)
                owned = set(prev.files) if prev else set()
                keep = [
                    e.name
                    for e in out.iterdir()
                    if e.name not in owned and e.name not in (MARKER, _JOURNAL)
                    and not (prev is not None and _is_temporary(e.name))
                ]  # fmt: skip
                clash = [n for n in keep if (staging / n).exists()]
                if clash:  # checked before the run; a file appeared since
                    raise InputError(
                        f"--out {out}: {', '.join(clash)} appeared while the run was "
                        f"written; it is left as it is and the run kept in {staging}"
                    )
                if keep:
                    (staging / _JOURNAL).write_text(json.dumps(keep), encoding="utf-8")
                    for n in keep:
                        os.rename(out / n, staging / n)
                os.rename(out, old)
            os.rename(staging, out)
            self.committed = True
            (out / _JOURNAL).unlink(missing_ok=True)
        if old.exists():
            _remove_owned(old)

    def left_behind(self) -> str:
        """What an unfinished run leaves, for the error message."""
        chains = (
            sorted(p.name for p in self.staging.glob("chain_*.h5"))
            if _own_folder(self.staging)
            else []
        )
        prev = (
            f"{self.out} is unchanged"
            if self.out.exists()
            else f"nothing was written to {self.out}"
        )
        if chains:
            return (
                f"{prev}; the chains so far ({', '.join(chains)}) are kept in "
                f"{self.staging}, which --resume continues"
            )
        return prev

    def _release(self) -> None:
        if self._lock is not None:
            self._lock.release()
            self._lock = None

    def __exit__(self, *exc):
        staging = self.staging
        if not self.committed and _own_folder(staging):
            if not any(staging.glob("chain_*.h5")):
                _remove_owned(staging, extra=[n for n in _staged_names(staging)
                                              if run_file_name(n)])  # fmt: skip
        self._release()
        if self._made_parent and not self.committed:
            try:  # nothing left: remove the folder this run created
                self.out.parent.rmdir()
            except OSError:
                pass
        return False
