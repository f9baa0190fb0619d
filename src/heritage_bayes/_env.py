"""Writable cache folders for the libraries underneath, set before they are imported.

arviz writes a stamp under the user's cache folder at import (``~/.cache/arviz``),
numba its compiled kernels (beside the sources, else ``~/.cache/numba``) and
matplotlib its font list (``~/.config/matplotlib``). With a read-only or missing home
(a service account, a container) arviz's import fails with an OSError, which a reader
of ``posterior.nc`` would take for a damaged file. :func:`writable_caches` points
``XDG_CACHE_HOME`` and ``MPLCONFIGDIR`` at a private temporary folder when, and only
when, the folder they name (or their default) cannot be written.
"""

from __future__ import annotations

import os
import stat
import tempfile
from pathlib import Path

__all__ = ["writable_caches"]

#: Variable -> its default under the home folder.
_CACHES = {"XDG_CACHE_HOME": (".cache",), "MPLCONFIGDIR": (".config", "matplotlib")}


def _writable(path: Path) -> bool:
    """Whether ``path`` is, or can be created as, a folder this process may write."""
    p = path
    while not p.exists():
        if p.is_symlink() or p.parent == p:  # a dangling link, or nothing exists
            return False
        p = p.parent
    return p.is_dir() and os.access(p, os.W_OK | os.X_OK)


def _private_folder(name: str) -> str:
    """``<tmp>/hbayes-<uid>/<name>``, made for this user only (mode 0700); a folder of
    that name that is a link, or another user's, or open to others is not used: then a
    new one from ``mkdtemp``."""
    uid = os.getuid() if hasattr(os, "getuid") else 0
    base = Path(tempfile.gettempdir()) / f"hbayes-{uid}"
    try:
        base.mkdir(mode=0o700, exist_ok=True)
        st = os.lstat(base)
        if stat.S_ISDIR(st.st_mode) and st.st_uid == uid and not st.st_mode & 0o077:
            (base / name).mkdir(mode=0o700, exist_ok=True)
            return str(base / name)
    except OSError:
        pass
    return tempfile.mkdtemp(prefix=f"hbayes-{name}-")


def writable_caches() -> dict[str, str]:
    """Point the cache variables whose folder cannot be written at a private temporary
    folder; return what was set (empty in the usual case)."""
    try:
        home = Path.home()
    except (RuntimeError, KeyError):  # no HOME and no password entry
        home = None
    changed = {}
    for var, parts in _CACHES.items():
        given = os.environ.get(var)
        path = Path(given) if given else (home.joinpath(*parts) if home else None)
        if path is not None and _writable(path):
            continue
        changed[var] = os.environ[var] = _private_folder(var.lower())
    return changed
