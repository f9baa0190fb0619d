"""Shared fixtures.

Real measured data lives in ``../shared/data`` beside the checkout (never copied into the
project). Tests that need it use the ``shared_data`` fixture, which skips when absent.
"""

from __future__ import annotations

from pathlib import Path

import pytest

SHARED_DATA = Path(__file__).resolve().parents[2] / "shared" / "data"


@pytest.fixture(scope="session")
def shared_data() -> Path:
    """Path to ``../shared/data``; skips the test when it is not beside the checkout."""
    if not SHARED_DATA.is_dir():
        pytest.skip(f"real data folder not found at {SHARED_DATA}")
    return SHARED_DATA


@pytest.fixture(scope="session", autouse=True)
def _nothing_left_in_the_checkout():
    """Tests write into temporary folders only: the checkout's ``reports/`` (the default
    run folder) must look the same after the session as before it."""
    reports = Path(__file__).resolve().parents[1] / "reports"
    before = sorted(p.name for p in reports.iterdir()) if reports.is_dir() else []
    yield
    after = sorted(p.name for p in reports.iterdir()) if reports.is_dir() else []
    assert after == before, f"tests left {sorted(set(after) - set(before))} in {reports}"
