"""Render one section's jinja2 fragment (``templates/sections/<name>``) of the report."""

from __future__ import annotations

from functools import lru_cache

from markupsafe import Markup

from heritage_bayes.format import fmt, prose_html

__all__ = ["render_fragment"]


@lru_cache(maxsize=1)
def _env():
    import jinja2

    env = jinja2.Environment(
        loader=jinja2.PackageLoader("heritage_bayes.report", "templates"),
        autoescape=True,
        undefined=jinja2.StrictUndefined,
        trim_blocks=True,
        lstrip_blocks=True,
    )
    env.filters["fmt"] = fmt
    env.filters["prose"] = lambda text: Markup(prose_html(text))
    return env


def render_fragment(name: str, ctx: dict) -> Markup:
    """The HTML of ``templates/sections/<name>`` rendered with ``ctx`` (autoescaping on:
    every text from the run is escaped)."""
    return Markup(_env().get_template(f"sections/{name}").render(**ctx))
