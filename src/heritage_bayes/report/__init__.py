"""The self-contained HTML calibration report: ``hbayes report RUN_DIR``; the house page.

:func:`write_report` reads a run directory written by ``hbayes calibrate`` and writes
``RUN_DIR/report.html``: one file, figures embedded, no script and no network request,
to share with people who do not run Python. See :mod:`heritage_bayes.report.build`
(assembly), :mod:`heritage_bayes.report.sections` (one module per section) and
:mod:`heritage_bayes.report.verdict` (the convergence verdict and notes).

:func:`render_page` and :class:`Section` (:mod:`heritage_bayes.report.page`) build every
other page of the package in the same style and with the same Content-Security-Policy.
"""

from __future__ import annotations

from heritage_bayes.report.build import write_report
from heritage_bayes.report.page import Section, render_page

__all__ = ["Section", "render_page", "write_report"]
