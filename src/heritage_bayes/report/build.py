"""``RUN_DIR/report.html``: the self-contained HTML report of a calibration run.

Reads only the run directory (``posterior.nc``, ``summary.json``, ``config.yaml`` and
the chain files ``chain_<model>.h5``), draws the figures with matplotlib and ``corner``
(PNG, embedded as ``data:`` URIs), and renders each section's jinja2 fragment
(autoescaping on: building, room and notes are untrusted text) into the house page
(:func:`heritage_bayes.report.page.render_page`). The page needs no script, no font and
no network: it opens from a USB stick. A Content-Security-Policy in the page forbids
scripts and every external load as a second line of defence.

Sections, in the order a reader needs them (one module each in
:mod:`heritage_bayes.report.sections`): 1 summary with the convergence verdict
(rules in :mod:`heritage_bayes.report.verdict`), 2 data, 3 fit, 4 metrics (the paper's
Table 2), 5 parameters, 6 identifiability, 7 diagnostics, 8 reproducibility.
"""

from __future__ import annotations

import os
import time
from pathlib import Path

from heritage_bayes._version import __version__
from heritage_bayes.errors import InputError
from heritage_bayes.report.accuracy import residual_shape, resolutions
from heritage_bayes.report.page import render_page
from heritage_bayes.report.rundata import REQUIRED_FILES, load_run_data
from heritage_bayes.report.sections import (
    data,
    diagnostics,
    fit,
    identifiability,
    metrics,
    parameters,
    reproducibility,
    summary,
)
from heritage_bayes.report.verdict import convergence_verdict, run_notes, verdict_record
from heritage_bayes.rundir.summary import RunSummary

__all__ = [
    "REQUIRED_FILES",
    "SECTIONS",
    "build_context",
    "convergence_verdict",
    "record_verdict",
    "render",
    "write_report",
]

#: The section modules, in page order.
SECTION_MODULES = (
    summary,
    data,
    fit,
    metrics,
    parameters,
    identifiability,
    diagnostics,
    reproducibility,
)
#: (id, title) of the report's sections, in order.
SECTIONS = tuple((m.ID, m.TITLE) for m in SECTION_MODULES)

_FOOTER = (
    "Written by hbayes {version}. This file is self-contained: it needs no "
    "internet connection and no other file."
)


def _render_figures(obj, dpi: float | None = None):
    """Replace every Figure in a nested structure by its PNG data URI."""
    from matplotlib.figure import Figure

    from heritage_bayes.report.figures import to_png_uri

    if isinstance(obj, Figure):
        return to_png_uri(obj, dpi=dpi)
    if isinstance(obj, dict):
        return {k: _render_figures(v, dpi) for k, v in obj.items()}
    if isinstance(obj, list):
        return [_render_figures(v, dpi) for v in obj]
    return obj


def residual_shapes(summary: RunSummary, fits: list[dict], res: dict) -> dict:
    """(section, output) -> :func:`~heritage_bayes.report.accuracy.residual_shape` of
    the posterior-median residuals over the validation period (the calibration period
    without one), hours read in the site's solar time when the run knows the site."""
    out = {}
    for f in fits:
        if f.get("resid") is None:
            continue
        codes = f["codes"]
        sel = codes == 2 if (codes == 2).any() else codes == 1
        shape = residual_shape(
            f["resid"][sel],
            f["measured"][sel],
            f["times"][sel],
            longitude=summary.longitude,
            resolution=res.get(f["output"]),
        )
        if shape is not None:
            out[(f["section"], f["output"])] = shape
    return out


def build_context(run_dir) -> dict:
    """Everything the sections need (figures as data URIs)."""
    import matplotlib

    from heritage_bayes.report.figures import RC_PARAMS

    t0 = time.perf_counter()
    rd = load_run_data(run_dir)
    with matplotlib.rc_context(RC_PARAMS):
        fits = fit.fit_context(rd, fit.fit_outputs(rd))
        diag = diagnostics.diagnostics_context(rd, fits)
        res = resolutions({k: rd.idata.observed_data[k].values for k in rd.idata.observed_data})
        ctx = {
            "sections": SECTIONS,
            "header": summary.header_context(rd),
            "verdict": convergence_verdict(
                rd.summary,
                diag["residuals"],
                shapes=residual_shapes(rd.summary, fits, res),
                resolutions=res,
            ),
            "warnings": run_notes(
                rd.summary, diag["missing"], irradiance_setting=rd.cfg.data.irradiance
            )
            + [{"level": "amber", "title": "The run's config", "text": n} for n in rd.run.notes],
            "data": data.data_context(rd),
            "fits": [{k: f[k] for k in ("id", "title", "figure", "caption")} for f in fits],
            "metrics": metrics.metrics_context(rd, res),
            "parameters": parameters.parameter_tables(rd),
            "identifiability": identifiability.identifiability_context(rd),
            "ladder": identifiability.ladder_context(rd.summary),
            "diagnostics": diag,
        }
        ctx = _render_figures(ctx)
    ctx["repro"] = reproducibility.reproducibility_context(rd)
    ctx["generated"] = {"seconds": time.perf_counter() - t0, "version": __version__}
    return ctx


def render(ctx: dict) -> str:
    """The report page from :func:`build_context`'s context (autoescaping on)."""
    h = ctx["header"]
    window = f"Calibration report — {h['building'] or h['name']}"
    if h["room"]:
        window += f" — {h['room']}"
    return render_page(
        h["building"] or "Calibration report",
        [m.section(ctx) for m in SECTION_MODULES],
        subtitle=h["room"] or "",
        window_title=window,
        header_note=f"Calibration report of run “{h['name']}” — hbayes {h['version']}",
        generator=f"heritage_bayes {ctx['generated']['version']}",
        footer=_FOOTER.format(version=ctx["generated"]["version"]),
    )


def _umask() -> int:
    """The process umask, read without changing it (Linux), else the usual 022."""
    try:
        for line in Path("/proc/self/status").read_text().splitlines():
            if line.startswith("Umask:"):
                return int(line.split()[1], 8)
    except (OSError, ValueError, IndexError):
        pass
    return 0o022


def write_report(run_dir) -> Path:
    """Write ``RUN_DIR/report.html`` (atomically) and return its path; the verdict
    the page shows goes to ``summary.json`` too (:func:`record_verdict`).

    Raises
    ------
    InputError
        ``run_dir`` is not a complete run directory (the message names the missing
        file) or one of its files cannot be read.
    """
    from heritage_bayes.inference.results import atomic_write
    from heritage_bayes.rundir.folder import claim_file

    t0 = time.perf_counter()
    ctx = build_context(run_dir)
    target = claim_file(run_dir, "report.html")  # not a file hbayes did not write
    html_text = None

    def _write(tmp: Path) -> None:
        tmp.write_text(html_text, encoding="utf-8")
        # mkstemp creates 0600 files: make the report readable like a normal file
        os.chmod(tmp, 0o666 & ~_umask())

    ctx["generated"]["seconds"] = time.perf_counter() - t0
    html_text = render(ctx)
    record_verdict(run_dir, ctx["verdict"])
    return atomic_write(target, _write)


def record_verdict(run_dir, verdict: dict) -> bool:
    """Record the page's verdict in ``RUN_DIR/summary.json`` (``verdict``: its level,
    status, headline, text, reasons and advice, :func:`verdict_record`), so that the
    portfolio reads the verdict the report shows. The rest of the file is written back
    as it was; an unchanged verdict leaves the file untouched. A ``summary.json`` the
    run's marker does not list (a folder hbayes did not make) is not touched.

    Returns
    -------
    bool
        Whether the file was written.
    """
    from heritage_bayes.inference.results import dump_json
    from heritage_bayes.rundir.folder import claim_file
    from heritage_bayes.rundir.reader import read_summary

    record = verdict_record(verdict).to_dict()
    summary = read_summary(run_dir)
    if summary.get("verdict") == record:
        return False
    try:
        target = claim_file(run_dir, "summary.json")
    except InputError:
        return False
    summary["verdict"] = record
    dump_json(target, summary)
    return True
