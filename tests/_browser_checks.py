"""Browser checks of the tests on top of :mod:`heritage_bayes.report._browser`."""

from __future__ import annotations

from pathlib import Path

import pytest

from heritage_bayes.report._browser import PHONE_OVERFLOW_JS, find_chromium, open_page

__all__ = ["phone_layout"]


def phone_layout(path: str | Path, *, width: int = 390, height: int = 844, extra: str = ""):
    """Open ``path`` at ``width`` px and check that the page has no horizontal scroll:
    the document no wider than the screen, no element outside the sideways-scrolling
    tables and code sticking out (:data:`PHONE_OVERFLOW_JS`), no console error. Skips
    the calling test when Chromium is not installed. Returns the layout dict, with the
    value of the JavaScript expression ``extra`` under ``"extra"``."""
    chromium = find_chromium()
    if chromium is None:
        pytest.skip("chromium not installed: the page was not opened in a real browser")
    js = PHONE_OVERFLOW_JS
    if extra:
        js = f"Object.assign({PHONE_OVERFLOW_JS}, {{extra: {extra}}})"
    res = open_page(path, chromium=chromium, width=width, height=height, extra_js=js)
    assert res.errors == [], res.errors
    lay = res.dom["extra"]
    assert lay["docw"] <= lay["W"] <= width, (Path(path).name, lay)
    assert lay["wide"] == [], (Path(path).name, lay["wide"])
    return lay
