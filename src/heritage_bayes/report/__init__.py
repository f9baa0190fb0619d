"""The self-contained HTML calibration report: ``hbayes report RUN_DIR``.

:func:`write_report` reads a run directory written by ``hbayes calibrate`` and writes
``RUN_DIR/report.html``: one file, figures embedded, no script and no network request,
to share with people who do not run Python. See :mod:`heritage_bayes.report.build`.
"""

from __future__ import annotations

from heritage_bayes.report.build import write_report

__all__ = ["write_report"]
