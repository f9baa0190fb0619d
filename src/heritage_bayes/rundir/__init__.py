"""Where the package writes: the output-path policy, the run marker, staging and locks.

Every command that writes goes through this package (see
:mod:`heritage_bayes.rundir.policy`). Public API::

    from heritage_bayes.rundir import check_name, resolve_output, write_new_file

- ``check_name(name, what=...)`` — a plain name (no separator, no ``..``, not hidden);
- ``resolve_output(path, what=..., kind="dir"|"file", protect=[config, data...])`` —
  absolute, symlinks resolved, refusing root/home/current folder, ancestors of the
  config or of a data file; creates nothing;
- ``write_new_file(path, text, force=False, what=...)`` — atomic; an existing file is
  refused (named) unless ``force``.
"""

from heritage_bayes.rundir.policy import (
    check_name,
    protected_paths,
    resolve_output,
    write_new_file,
)

__all__ = ["check_name", "protected_paths", "resolve_output", "write_new_file"]
