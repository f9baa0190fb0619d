"""Output folders of the package that hold several outputs: a comparison, a portfolio,
a projection. Made with a marker first; an entry is written only if it is new or the
marker lists it."""

from __future__ import annotations

import os
from collections.abc import Iterable
from pathlib import Path

from heritage_bayes.errors import InputError
from heritage_bayes.rundir.lock import FolderLock
from heritage_bayes.rundir.marker import MARKER, RunMarker, new_marker, read_marker, write_marker
from heritage_bayes.rundir.policy import check_name, resolve_output

__all__ = ["OutputFolder", "claim_file"]


def _shown(names: list[str], n: int = 5) -> str:
    return ", ".join(names[:n]) + (", ..." if len(names) > n else "")


class OutputFolder:
    """A folder the package fills with named entries, under the output-path policy.

    Parameters
    ----------
    path : path
        As typed (``--out``); resolved by :func:`~heritage_bayes.rundir.resolve_output`.
    kind : str
        The marker's kind (``"comparison"``, ``"portfolio"``, ``"projection"``).
    what : str
        The option the path came from, for messages.
    protect : iterable of path
        Input files (config, data) the folder may not hold.
    force : bool
        Write into an existing folder without a marker (then only entries of new names
        are written; an existing entry of the same name is refused, named).

    Notes
    -----
    Use as a context manager: the folder is resolved and checked, locked (see
    :class:`~heritage_bayes.rundir.lock.FolderLock`), created if missing and its marker
    written before anything else; :meth:`claim` then lists each entry in the marker
    before it is written.
    """

    def __init__(
        self,
        path: str | Path,
        *,
        kind: str,
        what: str = "--out",
        protect: Iterable[str | Path] = (),
        force: bool = False,
    ):
        self.typed = path
        self.kind = kind
        self.what = what
        self.protect = list(protect)
        self.force = force
        self.path = Path(path)
        self.marker: RunMarker | None = None
        self._lock: FolderLock | None = None

    def check(self) -> Path:
        """Resolve and check the folder (creates nothing); return its resolved path."""
        self.path = p = resolve_output(self.typed, what=self.what, protect=self.protect)
        if self._lock is None:  # a run making the folder now is another run, not a stranger
            FolderLock(p, what=self.what).check_free()
        if not p.is_dir():
            return p
        marker = read_marker(p)
        if marker is not None and marker.kind != self.kind:
            raise InputError(
                f"{self.what} {p}: holds a {marker.kind} of hbayes, not a {self.kind}; "
                "choose another folder"
            )
        if marker is None:
            entries = sorted(e.name for e in p.iterdir())
            if entries and not self.force:
                raise InputError(
                    f"{self.what} {p}: the folder exists and was not made by hbayes (no "
                    f"{MARKER}; it holds {_shown(entries)}); choose a new or empty folder, "
                    "or add --force to write beside those files (none of them is replaced)"
                )
        return p

    def __enter__(self) -> OutputFolder:
        p = self.check()
        made = not p.exists()
        p.parent.mkdir(parents=True, exist_ok=True)
        self._lock = FolderLock(p, what=self.what).acquire()
        try:
            if made:
                os.mkdir(p)  # exclusive: a folder made meanwhile is checked again
            marker = read_marker(p)
            if marker is None:
                marker = new_marker(self.kind)
                write_marker(p, marker)  # first, before any output
            self.marker = marker
        except FileExistsError:
            self._lock.release()
            self._lock = None
            return self.__enter__()
        except BaseException:
            self._lock.release()
            self._lock = None
            raise
        return self

    def __exit__(self, *exc):
        if self._lock is not None:
            self._lock.release()
        return False

    def claim(self, *names: str, folders_from=None) -> list[Path]:
        """List ``names`` in the marker (written before the entries); return their paths.

        Parameters
        ----------
        names : str
            Plain names of files or folders about to be written.
        folders_from : callable, optional
            ``folders_from(path) -> bool``: whether an existing folder of that name that
            the marker does not list may still be taken (e.g. a run directory with its
            own valid marker).

        Raises
        ------
        InputError
            A name that is not plain, or an existing entry the marker does not list,
            naming it.
        """
        if self.marker is None:
            raise RuntimeError("OutputFolder.claim outside its context manager")
        for name in names:
            self.marker = _claim(self.path, self.marker, name, self.what, folders_from)
        return [self.path / n for n in names]


def _claim(folder: Path, marker: RunMarker | None, name: str, what: str, folders_from=None):
    """Check that ``name`` may be written into ``folder`` and list it in the marker
    (written first); return the marker (None stays None: a folder without one)."""
    check_name(name, what=f"{what} entry")
    q = folder / name
    owned = marker is not None and marker.owns(name)
    taken = folders_from is not None and q.is_dir() and not q.is_symlink() and folders_from(q)
    if not owned and not taken and (q.exists() or q.is_symlink()):
        raise InputError(
            f"{what} {folder}: {name} exists and was not written by hbayes (the folder's "
            f"{MARKER} does not list it); it is left as it is: move it away or choose "
            "another folder"
        )
    if marker is not None and name not in marker.files:
        marker = marker.with_files(name)
        write_marker(folder, marker)
    return marker


def claim_file(folder: str | Path, name: str, *, what: str = "RUN_DIR") -> Path:
    """Claim one output file in a folder the package made (``report.html`` in a run
    directory): allowed if absent or listed by the folder's marker, which then lists it.

    Raises
    ------
    InputError
        An invalid marker, or an existing ``name`` the marker does not list (a folder
        without a marker lists nothing: an existing file there is never replaced).
    """
    folder = Path(folder)
    _claim(folder, read_marker(folder), name, what)
    return folder / name
