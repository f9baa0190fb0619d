"""Helpers for the data-layer tests: synthetic files and once-per-session real data."""

from __future__ import annotations

import functools
from pathlib import Path

import pandas as pd

DE_BILT = {"latitude": 52.10, "longitude": 5.18, "altitude": 2.0}
ESPOO = {"latitude": 60.2, "longitude": 24.8, "altitude": 20.0}
ORHOLM = {"latitude": 55.65, "longitude": 12.3, "altitude": 20.0}


def write(tmp_path: Path, name: str, text: str, newline: str = "\n") -> Path:
    """Write ``text`` (lines separated by ``\\n``) with the given line ends."""
    path = tmp_path / name
    path.write_bytes(text.replace("\n", newline).encode("utf-8"))
    return path


@functools.cache
def knmi_2011_2020(shared_data: Path) -> pd.DataFrame:
    """The 10-year De Bilt file, read once per test session (callers must not mutate)."""
    from heritage_bayes.io import read_knmi_hourly

    return read_knmi_hourly(shared_data / "knmi-debilt" / "uurgeg_260_2011-2020.txt.gz")


def pvlib_tmy3_path() -> Path:
    import pvlib

    return Path(pvlib.__file__).parent / "data" / "723170TYA.CSV"
