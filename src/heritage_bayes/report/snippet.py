"""The report's "From Python" lines: how to open this very run in Python.

Rendered from ``templates/from_python.jinja`` with the run's own path, sections and
identifiable quantities (time constants ``<section>.tau_*``, static gains
``<section>.gain_*``), printed in the report's reproducibility section and in the
manual; ``tests/test_docs.py`` executes the rendered text on a real run, so what the
report prints runs as printed.
"""

from __future__ import annotations

from functools import lru_cache
from pathlib import Path

from heritage_bayes._version import __version__
from heritage_bayes.rundir.writer import published_path

__all__ = ["from_python"]


@lru_cache(maxsize=1)
def _template():
    import jinja2

    env = jinja2.Environment(
        loader=jinja2.PackageLoader("heritage_bayes.report", "templates"),
        autoescape=False,  # Python source, escaped by the HTML page that shows it
        undefined=jinja2.StrictUndefined,
        trim_blocks=True,
        lstrip_blocks=True,
        keep_trailing_newline=True,
    )
    env.filters["pyrepr"] = repr  # every value enters the code as a Python literal
    return env.get_template("from_python.jinja")


def from_python(run_dir: str | Path, sections, posterior_names) -> str:
    """Python source that opens a run directory and prints what it holds.

    Parameters
    ----------
    run_dir : str or Path
        The run directory (written into the code resolved to an absolute path; a
        staging folder is named by the run directory it becomes).
    sections : iterable of str
        The run's model sections (``"thermal"``, ``"hygric"``).
    posterior_names : iterable of str
        Variable names of the run's posterior group; the time constants and static
        gains among them (``<section>.tau_*``, ``<section>.gain_*``) are summarised.

    Returns
    -------
    str
        Source that runs as printed (``python -c``, a notebook cell) where
        heritage_bayes and arviz are installed and the run directory is readable.
    """
    names = [n for n in posterior_names if n.partition(".")[2].startswith(("tau_", "gain_"))]
    return _template().render(
        version=__version__,
        run_dir=repr(str(published_path(Path(run_dir).resolve()))),
        var_names=names,
        sections=list(sections),
    )
