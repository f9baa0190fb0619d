"""The writer's side of a run directory (and of any folder written as one group, a
projection): marker, lock, staging folder, swap at the end.

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
resolved path, checked before anything is looked at (a run that is creating its
staging folder is "another run", never a folder to remove).

:class:`StagedFolder` is the mechanism for any ``kind`` of the marker; a projection
(``projection.nc``, ``.json``, ``.csv``, ``.html``) is staged and swapped in whole the
same way, so an interrupted re-projection leaves the previous one whole.
:class:`RunWriter` adds what is a calibration's own: its file names, ``--resume`` and
the chains kept in the staging folder.
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
from heritage_bayes.rundir.signals import DeferSignals

__all__ = [
    "RUN_FILES",
    "RunWriter",
    "StagedFolder",
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


def is_run_directory(path: str | Path, kind: str = "calibration") -> bool:
    """True for a folder with a valid marker of a calibration (or of ``kind``, see
    :mod:`heritage_bayes.rundir.marker`); an invalid marker counts as none."""
    p = Path(path)
    if not p.is_dir():
        return False
    try:
        m = read_marker(p)
    except InputError:
        return False
    return m is not None and m.kind == kind


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


def _own_folder(folder: Path, kind: str = "calibration") -> bool:
    """A real folder (not a symlink) with a valid marker of ``kind``."""
    try:
        st = os.lstat(folder)
    except (FileNotFoundError, NotADirectoryError):
        return False
    return stat.S_ISDIR(st.st_mode) and is_run_directory(folder, kind)


def _check_own(folder: Path, role: str, hint: str, kind: str = "calibration") -> bool:
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
    if not is_run_directory(folder, kind):
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


class StagedFolder:
    """A folder written as one group: staged beside it, swapped in whole (see the module
    documentation).

    Use as a context manager: ``with StagedFolder(out, kind=...) as w: ... write into
    w.staging ...; w.commit()``. :meth:`check` (called by ``__enter__``, or earlier to
    fail before the data are read) resolves ``out`` under the output-path policy,
    ``protect`` listing the input files (config, data) it may not hold.

    Parameters
    ----------
    out : path
        As typed (``--out``).
    kind : str
        The marker's kind (``"calibration"``, ``"projection"``).
    names : iterable of str
        The entries the writer writes (a folder without a marker may not hold one of
        them, even with ``force``).
    force : bool
        Write beside the entries of a folder hbayes did not make.
    protect : iterable of path
        Input files ``out`` may not be nor hold.
    what : str
        The option ``out`` came from, for messages.
    noun : str, optional
        How messages name the folder (default ``"folder"``).
    """

    #: How messages name the folder and its outputs.
    noun = "folder"
    outputs = "its outputs"

    def __init__(
        self,
        out: str | Path,
        *,
        kind: str,
        names: Iterable[str] = (),
        force: bool = False,
        protect: Iterable[str | Path] = (),
        what: str = "--out",
        noun: str | None = None,
    ):
        if noun is not None:
            self.noun = noun
        self.typed = out
        self.out = Path(out).absolute()
        self.kind = kind
        self.names = frozenset(names)
        self.force = force
        self.resume = False
        self.protect = list(protect)
        self.what = what
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

    def writes(self, name: str) -> bool:
        """True for an entry name this writer writes."""
        return name in self.names or name == MARKER

    def _keep_staging(self) -> bool:
        """Whether an unfinished staging folder is kept (a calibration's chains)."""
        return False

    # -- checks that need no data: called before anything is read
    def check(self) -> None:
        """Raise :class:`InputError` if ``out`` cannot or may not be written (another
        run writing it included)."""
        out = self.out = resolve_output(self.typed, what=self.what, protect=self.protect)
        if self._lock is None:  # another run holding it (ours is held when checked again)
            FolderLock(out, what=self.what).check_free()
        hint = f"remove or rename it, or choose another {self.what}"
        _check_own(self.staging, "staging folder of an unfinished run", hint, self.kind)
        _check_own(_old_path(out), "previous output kept by an interrupted swap", hint, self.kind)
        if out.is_dir():
            marker = read_marker(out)
            entries = sorted(e.name for e in out.iterdir())
            if marker is not None and marker.kind != self.kind:
                raise InputError(
                    f"{self.what} {out}: holds a {marker.kind} of hbayes, not a "
                    f"{self.noun}; choose another folder"
                )
            if marker is None and entries:
                shown = ", ".join(entries[:5]) + (", ..." if len(entries) > 5 else "")
                clash = [e for e in entries if self.writes(e)]
                if not self.force:
                    raise InputError(
                        f"{self.what} {out}: the folder exists and is not a {self.noun} of "
                        f"hbayes (no {MARKER}; it holds {shown}); choose another folder, "
                        "or add --force to write beside those files (none of them is "
                        "replaced)"
                    )
                if clash:
                    raise InputError(
                        f"{self.what} {out}: the folder is not a {self.noun} of hbayes (no "
                        f"{MARKER}) and holds {', '.join(clash)}, named like {self.outputs}; "
                        "hbayes does not replace files it did not write, even with "
                        "--force: move them away or choose another folder"
                    )
        self._checked = True

    def __enter__(self):
        self.check()
        self._made_parent = not self.out.parent.exists()
        try:
            self.out.parent.mkdir(parents=True, exist_ok=True)
            self._lock = FolderLock(self.out, what=self.what).acquire()
        except PermissionError as exc:
            raise InputError(f"{self.what} {self.out}: cannot write ({exc.strerror})") from None
        try:
            self._check_again_and_recover()
            self._prepare_staging()
        except BaseException:
            self._release()
            raise
        return self

    def _check_again_and_recover(self) -> None:
        staging = self.staging
        try:  # an empty staging folder: made by a run killed before its marker
            if stat.S_ISDIR(os.lstat(staging).st_mode) and not any(staging.iterdir()):
                staging.rmdir()
        except (FileNotFoundError, NotADirectoryError):
            pass
        self.check()  # under the lock: nothing changed since the first check
        out, old = self.out, _old_path(self.out)
        if _check_own(old, "previous output", "", self.kind) and not out.exists():
            os.rename(old, out)  # a swap was cut short: undo it
        elif old.exists():
            _remove_owned(old)
        journal = staging / _JOURNAL
        if staging.is_dir() and journal.is_file():  # the swap never happened
            for name in json.loads(journal.read_text(encoding="utf-8")):
                if (staging / name).exists() and not (out / name).exists():
                    os.rename(staging / name, out / name)
            journal.unlink()
        (out / _JOURNAL).unlink(missing_ok=True)  # the swap happened; the journal is stale

    def _prepare_staging(self) -> None:
        staging = self.staging
        if staging.exists() and not self.resume:
            left = _remove_owned(staging, extra=[n for n in _staged_names(staging)
                                                  if self.writes(n)])  # fmt: skip
            if left:
                raise InputError(
                    f"{staging}: holds {', '.join(left)}, not written by hbayes; it is "
                    "left as it is: move those away"
                )
        if not staging.exists():
            os.mkdir(staging)  # exclusive (the lock is held): never an existing folder
            try:
                write_marker(staging, new_marker(self.kind))  # first
            except BaseException:  # interrupted: the folder is empty, remove it
                shutil.rmtree(staging, ignore_errors=True)
                raise

    def commit(self) -> None:
        """Make the staging folder ``out``, keeping every entry of ``out`` its marker
        does not list (moved across by rename, byte for byte). Signals wait until the
        swap is done: ``out`` is the previous output or the new one, never a mix."""
        out, staging, old = self.out, self.staging, _old_path(self.out)
        names = _staged_names(staging)
        marker = read_marker(staging) or new_marker(self.kind)
        with DeferSignals():
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
                        f"{self.what} {out}: {', '.join(clash)} appeared while the output "
                        f"was written; it is left as it is and the output kept in {staging}"
                    )
                if keep:
                    (staging / _JOURNAL).write_text(json.dumps(keep), encoding="utf-8")
                    for n in keep:
                        os.rename(out / n, staging / n)
                os.rename(out, old)
            os.rename(staging, out)
            self.committed = True
            (out / _JOURNAL).unlink(missing_ok=True)
            if old.exists():  # before a deferred signal ends the process
                _remove_owned(old)

    def left_behind(self) -> str:
        """What an unfinished output leaves, for the error message."""
        if self.committed:
            return f"{self.out} was written in full before the interrupt came"
        if self.out.exists():
            return f"{self.out} is unchanged"
        return f"nothing was written to {self.out}"

    def _release(self) -> None:
        if self._lock is not None:
            self._lock.release()
            self._lock = None

    def __exit__(self, *exc):
        staging = self.staging
        if not self.committed and _own_folder(staging, self.kind):
            if not self._keep_staging():
                _remove_owned(staging, extra=[n for n in _staged_names(staging)
                                              if self.writes(n)])  # fmt: skip
        self._release()
        if self._made_parent and not self.committed:
            try:  # nothing left: remove the folder this run created
                self.out.parent.rmdir()
            except OSError:
                pass
        return False


class RunWriter(StagedFolder):
    """The writer's side of a run directory (see the module documentation): a
    :class:`StagedFolder` of kind ``calibration`` whose names are a run's
    (:func:`run_file_name`), with ``--resume`` (the chains of an unfinished run, kept
    in its staging folder, or of the finished one, continued)."""

    noun = "run directory"
    outputs = "the run's files"

    def __init__(
        self,
        out: str | Path,
        *,
        force: bool = False,
        resume: bool = False,
        protect: Iterable[str | Path] = (),
    ):
        super().__init__(out, kind="calibration", force=force, protect=protect)
        self.resume = resume

    def writes(self, name: str) -> bool:
        return run_file_name(name)

    def _keep_staging(self) -> bool:
        return any(self.staging.glob("chain_*.h5"))

    def _prepare_staging(self) -> None:
        super()._prepare_staging()
        staging = self.staging
        if self.resume and _own_folder(self.out):  # extend a finished run's chains
            owned = read_marker(self.out).files
            for p in sorted(self.out.glob("chain_*.h5")):
                if p.name in owned and not (staging / p.name).exists():
                    shutil.copy2(p, staging / p.name, follow_symlinks=False)

    def left_behind(self) -> str:
        """What an unfinished run leaves, for the error message."""
        chains = (
            sorted(p.name for p in self.staging.glob("chain_*.h5"))
            if _own_folder(self.staging)
            else []
        )
        prev = super().left_behind()
        if chains:
            return (
                f"{prev}; the chains so far ({', '.join(chains)}) are kept in "
                f"{self.staging}, which --resume continues"
            )
        return prev
