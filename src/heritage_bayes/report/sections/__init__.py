"""The report's sections, one module each, in the order a reader needs them.

Each module has ``ID`` and ``TITLE``, a ``*_context`` function that reads the run
(:class:`~heritage_bayes.report.rundata.RunData`) into plain values and matplotlib figures,
and ``section(ctx) -> Section`` that renders its fragment ``templates/sections/<ID>.html``
from the report context (figures already embedded as ``data:`` URIs).
:mod:`heritage_bayes.report.build` assembles them with the house page builder
(:func:`heritage_bayes.report.page.render_page`); ``build.SECTION_MODULES`` lists them
in page order.
"""
