"""One writer per output folder: an ``flock`` on ``.<name>.lock`` in the resolved parent.

The lock file lives in the folder that holds the output, reached through its *resolved*
path: two paths to the same folder (a symlink alias, ``a/../b``) resolve to the same
parent folder (device + inode) and the same lock file, so they exclude each other. The
kernel releases an ``flock`` when its holder dies (``kill -9`` included); the file names
the holder for the message of a second writer.
"""

from __future__ import annotations

import datetime
import os
import socket
from pathlib import Path

from heritage_bayes.errors import InputError

__all__ = ["FolderLock", "lock_path"]


def lock_path(out: Path) -> Path:
    """The lock file of the output folder ``out`` (a hidden sibling)."""
    return out.parent / f".{out.name}.lock"


class FolderLock:
    """An exclusive, non-blocking lock on the output folder ``out`` (resolved first).

    Use as a context manager, or :meth:`acquire` / :meth:`release`. ``what`` names the
    option for the message (``--out``).
    """

    def __init__(self, out: str | Path, *, what: str = "--out"):
        self.out = Path(out).resolve()
        self.path = lock_path(self.out)
        self.what = what
        self._fd: int | None = None

    def key(self) -> tuple[int, int, str]:
        """(device, inode) of the resolved parent folder and the output's name."""
        st = os.stat(self.out.parent)
        return st.st_dev, st.st_ino, self.out.name

    def _busy(self, fd: int) -> InputError:
        holder = os.read(fd, 1000).decode("utf-8", "replace").strip() or "unknown"
        return InputError(
            f"{self.what} {self.out}: another hbayes run is writing it ({holder}); "
            "wait for it to end or choose another folder"
        )

    def check_free(self) -> None:
        """Raise the message of :meth:`acquire` if another process holds the lock now;
        creates nothing. Called before a writer looks at the output's folder: a run
        that is creating its staging folder is then "another run", never a folder
        left behind."""
        import fcntl

        try:
            fd = os.open(self.path, os.O_RDWR | os.O_NOFOLLOW)
        except OSError:  # no lock file (nobody holds it), or not ours (acquire says so)
            return
        try:
            fcntl.flock(fd, fcntl.LOCK_SH | fcntl.LOCK_NB)
        except BlockingIOError:
            err = self._busy(fd)
            os.close(fd)
            raise err from None
        os.close(fd)  # releases the shared lock

    def acquire(self) -> FolderLock:
        import fcntl

        key = self.key()
        while True:
            fd = os.open(self.path, os.O_RDWR | os.O_CREAT | os.O_NOFOLLOW, 0o644)
            try:
                fcntl.flock(fd, fcntl.LOCK_EX | fcntl.LOCK_NB)
            except BlockingIOError:
                err = self._busy(fd)
                os.close(fd)
                raise err from None
            try:  # the file may have been removed by the holder that just released it
                same = os.stat(self.path).st_ino == os.fstat(fd).st_ino
                same = same and self.key() == key  # the parent was not swapped meanwhile
            except FileNotFoundError:
                same = False
            if same:
                break
            os.close(fd)
        now = datetime.datetime.now(datetime.UTC).isoformat(timespec="seconds")
        os.ftruncate(fd, 0)
        os.write(
            fd,
            f"pid {os.getpid()} on {socket.gethostname()}, since {now} "
            f"(folder {key[0]}:{key[1]}/{key[2]})".encode(),
        )
        self._fd = fd
        return self

    def release(self) -> None:
        if self._fd is None:
            return
        try:
            os.unlink(self.path)
        except FileNotFoundError:
            pass
        finally:
            os.close(self._fd)
            self._fd = None

    def __enter__(self):
        return self.acquire()

    def __exit__(self, *exc):
        self.release()
        return False
