"""The output-path policy: where the package may write, checked before anything is made.

Every command that writes (``calibrate``, ``report``, ``project``, ``compare``,
``batch``, ``init``) takes its output paths through this module:

- :func:`check_name` — a name that becomes a folder or file name (``name:`` in a
  config, a room of a portfolio, a candidate model) is a *plain* name: no path
  separator, no ``..``, not hidden (``.x`` is the package's staging and lock
  namespace), no control character.
- :func:`resolve_output` — an output path is made absolute and resolved, symlinks
  included, *before* anything is created; the filesystem root, the home folder, the
  current folder (and their ancestors) and any ancestor of the config file or of a
  data file are refused, and so is a path that *is* one of those files.
- :func:`write_new_file` — a single-file writer's atomic "write this file unless it
  exists (or ``force``)": the text goes to a temporary file in the same folder and is
  linked into place only if no file of that name appeared meanwhile; a symlink at the
  path is never followed.

Layer: imports nothing of the package but :mod:`heritage_bayes.errors`, so that the
readers (``hbayes init``), the run directory and the orchestrators can all use it.
"""

from __future__ import annotations

import errno
import os
import tempfile
import unicodedata
from collections.abc import Iterable
from pathlib import Path

from heritage_bayes.errors import InputError

__all__ = [
    "check_name",
    "check_new_file",
    "protected_paths",
    "resolve_output",
    "write_new_file",
]

#: Longest plain name [characters]: far below NAME_MAX (255 bytes) once the staging
#: decorations (``.<name>.partial``) and UTF-8 are added.
MAX_NAME = 100


def check_name(name: str, *, what: str = "name") -> str:
    """Return ``name`` if it is a plain name (one path component the package may create).

    Parameters
    ----------
    name : str
        E.g. a config's ``name:``, a portfolio room, a catalogue model.
    what : str
        The key or option the name came from, for the message (``"name"``,
        ``"rooms[2].name"``).

    Raises
    ------
    InputError
        Empty, longer than :data:`MAX_NAME`, containing ``/`` or ``\\`` or a control
        character, ``.``/``..``, starting with ``.`` (hidden: the package's staging and
        lock files) or with white space at either end; the message says what was found.
    """
    if not isinstance(name, str):
        raise InputError(f"{what}: expected a plain name (got {type(name).__name__})")
    problem = None
    if not name:
        problem = "it is empty"
    elif len(name) > MAX_NAME:
        problem = f"it has {len(name)} characters (at most {MAX_NAME})"
    elif any(sep in name for sep in ("/", "\\", os.sep, os.altsep or "/")):
        problem = "it contains a path separator"
    elif name in (".", ".."):
        problem = "it names a folder, not a new one"
    elif name.startswith("."):
        problem = "it starts with '.' (hidden names are the package's staging and locks)"
    elif any(unicodedata.category(c).startswith("C") for c in name):
        problem = "it contains a control character"
    elif name != name.strip():
        problem = "it starts or ends with white space"
    if problem:
        raise InputError(
            f"{what}: {name[:120]!r} is not a plain name ({problem}); use letters, digits, "
            "'_', '-', '.' and spaces, e.g. 'nave_2019'"
        )
    return name


def protected_paths(*paths: str | Path | None) -> list[Path]:
    """Resolved paths of files the output must not be, nor be an ancestor of (the config
    file, data files); ``None`` entries are skipped."""
    return [Path(p).expanduser().resolve() for p in paths if p is not None]


def _forbidden_folders() -> list[tuple[Path, str]]:
    out = []
    for p, why in ((Path.home(), "the home folder"), (Path.cwd(), "the current folder")):
        try:
            out.append((p.resolve(), why))
        except (OSError, RuntimeError):  # no home (a container), a removed cwd
            continue
    return out


def _dangling_link(path: Path) -> Path | None:
    """The first component of ``path`` (absolute, as typed) that is a symbolic link to
    nothing, or None. Creating the missing folders of such a path would create them at
    the link's target, wherever that is."""
    q = Path(path.anchor)
    for part in path.parts[1:]:
        q = q / part
        if os.path.islink(q):
            try:
                os.stat(q)
            except FileNotFoundError:
                return q
            except OSError:  # a loop: resolve() names it
                return None
    return None


def resolve_output(
    path: str | Path,
    *,
    what: str = "--out",
    kind: str = "dir",
    protect: Iterable[str | Path] = (),
) -> Path:
    """Resolve an output path and check it against the policy; create nothing.

    Parameters
    ----------
    path : path
        As the user typed it (``~`` expanded; relative to the current folder).
    what : str
        The option or key it came from, for the message.
    kind : {"dir", "file"}
        A folder the package fills (a run directory, a comparison, a portfolio) or one
        file (``hbayes init``'s config). A folder may not be the root, home or current
        folder nor an ancestor of them, nor contain a protected file; a file may not be
        a protected file. Either may not be an existing thing of the other kind.
    protect : iterable of path
        The config file and the data files of the command (see
        :func:`protected_paths`); resolved here again, so plain paths are fine.

    Returns
    -------
    Path
        Absolute, symlinks resolved (``Path.resolve(strict=False)``: missing trailing
        components are kept as typed, after the existing part is resolved). For
        ``kind="file"`` only the folder is resolved: a symbolic link at the file's own
        name is the output itself, which :func:`write_new_file` refuses (or, with
        ``force``, replaces), never the file it points to.

    Raises
    ------
    InputError
        Naming the option, the path as typed and as resolved, and the rule it breaks;
        among them a component that is a symbolic link to nothing (its missing folders
        would be created wherever the link points).
    """
    if kind not in ("dir", "file"):
        raise ValueError(f"kind: expected 'dir' or 'file' (got {kind!r})")
    typed = str(path)
    if not typed or "\x00" in typed:
        raise InputError(f"{what}: {typed!r} is not a path")
    absolute = Path(typed).expanduser().absolute()
    # a file is the link itself when it is one (write_new_file never writes through it)
    own = kind == "file" and absolute.name not in ("", ".", "..")
    link = _dangling_link(absolute.parent if own else absolute)
    if link is not None:
        raise InputError(
            f"{what}: {typed}: {link} is a symbolic link to {os.readlink(link)}, which does "
            "not exist; hbayes creates nothing through a link: remove the link or give "
            "another path"
        )
    try:
        p = absolute.parent.resolve() / absolute.name if own else absolute.resolve()
    except (OSError, RuntimeError) as exc:  # a symlink loop
        raise InputError(f"{what}: {typed} cannot be resolved ({exc})") from None
    shown = typed if typed == str(p) else f"{typed} (resolved: {p})"
    if p == Path(p.anchor):
        raise InputError(f"{what}: {shown} is the filesystem root; choose a folder of its own")
    if kind == "dir":
        for folder, why in _forbidden_folders():
            if p == folder or p in folder.parents:
                rel = "is" if p == folder else "is an ancestor of"
                raise InputError(
                    f"{what}: {shown} {rel} {why}; the package writes a folder of its "
                    "own: give a new or empty folder, e.g. reports/<name>"
                )
    for f in protected_paths(*protect):
        if p == f and not f.is_dir():
            raise InputError(f"{what}: {shown} is an input file of this command; choose another")
        if kind == "dir" and (p == f or p in f.parents):
            raise InputError(
                f"{what}: {shown} holds an input file of this command ({f}); choose a "
                "folder that holds no config or data file"
            )
    if p.exists() and not p.is_symlink():
        if kind == "dir" and not p.is_dir():
            raise InputError(f"{what}: {shown} is a file, not a folder")
        if kind == "file" and not p.is_file():
            raise InputError(f"{what}: {shown} exists and is not a regular file")
    anc = p.parent
    while not anc.exists():
        anc = anc.parent
    if not anc.is_dir():
        raise InputError(f"{what}: {shown}: {anc} is a file, not a folder")
    if not os.access(anc, os.W_OK | os.X_OK):
        raise InputError(f"{what}: {shown}: no permission to write in {anc}")
    return p


def check_new_file(path: str | Path, *, force: bool = False, what: str = "--output") -> Path:
    """Raise :class:`InputError` if :func:`write_new_file` would refuse ``path``: a
    folder; without ``force``, an existing file or any symbolic link (dangling too),
    named as such. Return ``path``."""
    path = Path(path)
    if path.is_dir() and not path.is_symlink():
        raise InputError(f"{what}: {path} is a folder, not a file")
    if not force and path.is_symlink():
        raise InputError(
            f"{what}: {path} is a symbolic link (to {os.readlink(path)}); hbayes never "
            "writes through a link: choose another name, or add --force to replace the "
            "link itself (the file it points to is left as it is)"
        )
    if not force and path.exists():
        raise InputError(f"{what}: {path} exists; choose another name or add --force")
    return path


def write_new_file(
    path: str | Path,
    content: str | bytes,
    *,
    force: bool = False,
    what: str = "--output",
    mode: int = 0o666,
) -> Path:
    """Write one file atomically; refuse to replace an existing one unless ``force``.

    The content goes to a temporary file (exclusive creation) in the target's folder;
    without ``force`` it is hard-linked to ``path``, which fails if anything of that
    name exists (a file, a folder, a dangling symlink) — no window between the check and
    the write. With ``force`` it replaces ``path`` by rename, which replaces a symlink
    itself, never the file it points to; an existing folder is refused either way.

    Parameters
    ----------
    path : path
        Should come from :func:`resolve_output` with ``kind="file"``; its folder is
        created if missing.
    content : str or bytes
        Text is written as UTF-8.
    force : bool
        Replace an existing file.
    what : str
        The option the path came from, for the message.
    mode : int
        Permission bits before the umask (default ``0o666``, as ``open`` gives).

    Returns
    -------
    Path
    """
    path = check_new_file(path, force=force, what=what)
    data = content.encode("utf-8") if isinstance(content, str) else bytes(content)
    link = _dangling_link(path.parent)
    if link is not None:  # resolve_output refuses it; checked again before mkdir
        raise InputError(f"{what}: {path}: {link} is a symbolic link to nothing")
    path.parent.mkdir(parents=True, exist_ok=True)
    fd, tmp = tempfile.mkstemp(prefix=f".{path.name}.", suffix=".tmp", dir=path.parent)
    try:
        with os.fdopen(fd, "wb") as fh:
            fh.write(data)
            fh.flush()
            os.fsync(fh.fileno())
        umask = os.umask(0)
        os.umask(umask)
        os.chmod(tmp, mode & ~umask)
        if force:
            os.replace(tmp, path)
            return path
        try:
            os.link(tmp, path, follow_symlinks=False)
        except FileExistsError:
            raise InputError(f"{what}: {path} exists; choose another name or add --force") from None
        except OSError as exc:  # a filesystem without hard links: exclusive create + copy
            if exc.errno not in (errno.EPERM, errno.ENOTSUP, errno.EOPNOTSUPP, errno.EXDEV):
                raise
            try:
                out = os.open(path, os.O_WRONLY | os.O_CREAT | os.O_EXCL | os.O_NOFOLLOW, mode)
            except FileExistsError:
                raise InputError(
                    f"{what}: {path} exists; choose another name or add --force"
                ) from None
            with os.fdopen(out, "wb") as fh:
                fh.write(data)
        os.unlink(tmp)
    except BaseException:
        Path(tmp).unlink(missing_ok=True)
        raise
    return path
