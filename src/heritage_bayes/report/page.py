"""The house page builder: one self-contained HTML page in the package's style.

Every page the package writes is built here: the calibration report
(:mod:`heritage_bayes.report.build`), the portfolio overview, and the pages of later
layers (projection, comparison). One function, :func:`render_page`, takes a title and a
list of sections and returns the page, with

- the house CSS (``templates/house.css``: verdict boxes ``div.verdict.green|amber|red``,
  notes ``div.note.amber|info``, tables in ``div.scroll``, ``td.num``, ``.ok``/``.warn``/
  ``.bad`` cells, figures, ``dl.meta``, ``pre.config``, ``table.sortable``);
- the same Content-Security-Policy: no network access, images only as ``data:`` URIs
  (embed figures with :func:`heritage_bayes.report.figures.to_png_uri`), no script
  unless one is passed, which is then allowed by its SHA-256 hash only;
- autoescaped titles; a table of contents when there is more than one section.

Section bodies are trusted HTML that the caller built: escape every user or run text in
them (``html.escape``, or a jinja2 template with autoescaping).

Example
-------
>>> from heritage_bayes.report.page import Section, render_page
>>> html = render_page(
...     "Projection — Castle X",
...     [
...         ("Summary", "<p>Warmer by 1.2 °C in 2050.</p>"),
...         Section("Risk", "<p>…</p>", id="risk", lead="<div class='note amber'>…</div>"),
...     ],
...     subtitle="Great hall",
...     generator="heritage_bayes 0.1.0",
... )
>>> html.startswith("<!DOCTYPE html>") and 'id="risk"' in html
True
"""

from __future__ import annotations

import base64
import hashlib
import re
from collections.abc import Sequence
from functools import lru_cache
from typing import NamedTuple

from markupsafe import Markup

__all__ = ["Section", "render_page", "script_hash"]


class Section(NamedTuple):
    """One section of a house page.

    Attributes
    ----------
    title : str
        Heading (``<h2>``) and table-of-contents entry; plain text (escaped), or
        ``markupsafe.Markup`` for trusted HTML (a model name set as code).
    body : str
        Trusted HTML under the heading.
    id : str
        Anchor of the section (``<section id=…>``); default: a slug of the title.
    lead : str
        Trusted HTML above the heading (e.g. the report's verdict box, which must be the
        first thing a reader sees); default none.
    """

    title: str
    body: str
    id: str = ""
    lead: str = ""


@lru_cache(maxsize=1)
def _env():
    import jinja2

    return jinja2.Environment(
        loader=jinja2.PackageLoader("heritage_bayes.report", "templates"),
        autoescape=True,
        undefined=jinja2.StrictUndefined,
    )


def script_hash(script: str) -> str:
    """The CSP source expression (``sha256-…``) that allows exactly this inline script."""
    return "sha256-" + base64.b64encode(hashlib.sha256(script.encode("utf-8")).digest()).decode()


def _slug(text: str, i: int) -> str:
    s = re.sub(r"[^a-z0-9]+", "-", text.lower()).strip("-")
    return s or f"section-{i + 1}"


def render_page(
    title: str,
    sections: Sequence[Section | tuple[str, str]],
    *,
    subtitle: str = "",
    generator: str = "heritage_bayes",
    footer: str = "",
    script: str = "",
    window_title: str = "",
    header_note: str = "",
) -> str:
    """A self-contained page in the house style.

    Parameters
    ----------
    title, subtitle : str
        The page heading (``<h1>``) and the line under it; plain text (escaped here).
    sections : sequence of Section or (title, html)
        The sections in page order: a :class:`Section`, or a ``(title, body)`` pair
        (plain-text title, trusted-HTML body: escape user text in it).
    generator : str
        Plain text for the ``generator`` meta tag (e.g. ``"heritage_bayes 0.1.0"``).
    footer : str
        Plain text of the footer; default: ``generator``.
    script : str
        An optional inline script, allowed by its hash in the CSP (no other script runs).
    window_title : str
        Plain text of ``<title>`` (the browser tab); default: ``title``.
    header_note : str
        Plain text in a muted line under the heading; default none.

    Returns
    -------
    str
        The HTML page.
    """
    secs = []
    for i, sec in enumerate(sections):
        s = Section(*sec)
        secs.append(
            {
                "id": s.id or _slug(s.title, i),
                "title": s.title,
                "body": Markup(s.body),
                "lead": Markup(s.lead),
            }
        )
    return (
        _env()
        .get_template("page.html")
        .render(
            title=title,
            window_title=window_title or title,
            subtitle=subtitle,
            header_note=header_note,
            sections=secs,
            generator=generator,
            footer=footer,
            script=Markup(script) if script else "",
            script_hash=script_hash(script) if script else "",
        )
    )
