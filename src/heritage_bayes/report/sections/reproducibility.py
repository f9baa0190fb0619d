"""Section 8, reproducibility: seed, config, library versions, timings, files."""

from __future__ import annotations

from heritage_bayes._version import __version__
from heritage_bayes.format import fmt, fmt_time
from heritage_bayes.report.page import Section
from heritage_bayes.report.rundata import RunData
from heritage_bayes.report.sections._fragment import render_fragment
from heritage_bayes.report.snippet import from_python
from heritage_bayes.rundir.summary import RunSummary

ID, TITLE = "reproducibility", "8. Reproducibility"

_VERSIONS = (
    "numpy",
    "scipy",
    "pandas",
    "xarray",
    "emcee",
    "arviz",
    "matplotlib",
    "corner",
    "pvlib",
    "numba",
    "h5py",
    "jinja2",
)


def library_versions(s: RunSummary) -> tuple[list[dict], str]:
    """The library versions the run recorded (``"run"``), else those of this Python
    (``"report"``)."""
    from importlib.metadata import PackageNotFoundError, version

    if s.versions:
        return [{"name": k, "version": str(v)} for k, v in s.versions.items()], "run"
    rows = [{"name": "heritage_bayes", "version": __version__}]
    import platform

    rows.append({"name": "python", "version": platform.python_version()})
    for name in _VERSIONS:
        try:
            rows.append({"name": name, "version": version(name)})
        except PackageNotFoundError:
            rows.append({"name": name, "version": "not installed"})
    return rows, "report"


def timings(s: RunSummary) -> list[dict]:
    """The run's timings [s], the calibration's total last."""
    rows = []
    for k, v in s.timings.items():
        rows.append({"name": k.removesuffix("_seconds").replace("_", " "), "seconds": fmt(v)})
    if s.wall_seconds is not None:
        rows.append({"name": "calibration, total", "seconds": fmt(s.wall_seconds)})
    return rows


def reproducibility_context(rd: RunData) -> dict:
    """Seed, config hash, run date, timings, run-directory files, library versions and
    the Python lines that open this run (:func:`heritage_bayes.report.snippet.from_python`)."""
    versions, when = library_versions(rd.summary)
    return {
        "config": rd.config_text,
        "from_python": from_python(rd.path, rd.run.sections, rd.idata.posterior.data_vars),
        "versions": versions,
        "versions_from": when,
        "seed": rd.summary.seed,
        "config_hash": rd.summary.config_hash or "?",
        "created_at": fmt_time(rd.summary.created_at or None),
        "timings": timings(rd.summary),
        "files": sorted(
            p.name for p in rd.path.iterdir() if p.is_file() and not p.name.startswith(".")
        ),
    }


def section(ctx: dict) -> Section:
    """This section of the page, from the report context (figures already data URIs)."""
    return Section(TITLE, render_fragment("reproducibility.html", ctx), id=ID)
