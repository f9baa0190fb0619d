"""The house page: one self-contained HTML page in the calibration report's style.

For every page the package writes besides the calibration report (portfolio overview,
and pages of later layers): the same CSS (``templates/house.css``, shared with
``report.html``), the same Content-Security-Policy (no network access, images only as
``data:`` URIs), autoescaped titles. Section bodies are HTML the caller built and
escaped; an optional inline script is allowed by its SHA-256 hash only.
"""

from __future__ import annotations

import base64
import hashlib
import re
from collections.abc import Sequence
from functools import lru_cache

from markupsafe import Markup

__all__ = ["render_page", "script_hash"]


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
    sections: Sequence[tuple[str, str]],
    *,
    subtitle: str = "",
    generator: str = "heritage_bayes",
    footer: str = "",
    script: str = "",
) -> str:
    """A self-contained page in the house style.

    Parameters
    ----------
    title, subtitle : str
        Plain text (escaped here).
    sections : sequence of (title, html)
        Section titles (plain text) and bodies (trusted HTML: escape user text in them).
    generator, footer : str
        Plain text for the ``generator`` meta tag and the footer.
    script : str
        An optional inline script, allowed by its hash in the CSP (no other script runs).

    Returns
    -------
    str
        The HTML page.
    """
    secs = [
        {"id": _slug(t, i), "title": t, "body": Markup(body)}
        for i, (t, body) in enumerate(sections)
    ]
    return (
        _env()
        .get_template("page.html")
        .render(
            title=title,
            subtitle=subtitle,
            sections=secs,
            generator=generator,
            footer=footer,
            script=Markup(script) if script else "",
            script_hash=script_hash(script) if script else "",
        )
    )
