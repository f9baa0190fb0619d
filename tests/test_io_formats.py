"""KNMI, EPW and TMY3 readers on synthetic and edited files (written to tmp_path)."""

from __future__ import annotations

import gzip

import numpy as np
import pandas as pd
import pytest

from _io_helpers import pvlib_tmy3_path, write
from heritage_bayes.errors import DataError, InputError
from heritage_bayes.io import read_epw, read_knmi_hourly, read_tmy3

KNMI_HEAD = """BRON: KONINKLIJK NEDERLANDS METEOROLOGISCH INSTITUUT (KNMI)

YYYYMMDD  = datum
HH        = tijd

# STN,YYYYMMDD,   HH,   DD,    T,   TD,    Q,   RH,    U

"""


def knmi_rows(rows):
    return KNMI_HEAD + "\n".join(
        f"  {stn:>3},{day},{hh:>5},  240,{t:>5},{td:>5},{q:>5},   -1,{u:>5}"
        for stn, day, hh, t, td, q, u in rows
    ) + "\n"  # fmt: skip


ROWS = [
    (260, 20210620, 23, 150, 120, 0, 80),
    (260, 20210620, 24, 140, 118, "", 85),
    (260, 20210621, 1, 130, "", 0, 88),
    (260, 20210621, 2, 125, 117, 36, 90),
]


def test_knmi_units_and_hour_ending_stamps(tmp_path):
    df = read_knmi_hourly(write(tmp_path, "uurgeg_260_test.txt", knmi_rows(ROWS)))
    assert df.index.equals(pd.date_range("2021-06-20 23:00", periods=4, freq="h", tz="UTC"))
    np.testing.assert_allclose(df["Te"], [15.0, 14.0, 13.0, 12.5])
    assert np.isnan(df["Tdew"].iloc[2]) and np.isnan(df["ghi"].iloc[1])  # blank fields
    assert df["ghi"].iloc[3] == pytest.approx(100.0)  # 36 J/cm² in an hour = 100 W/m²
    assert df["RHe"].tolist() == [80, 85, 88, 90]
    assert df.attrs["averaged"] == ("ghi",) and df.attrs["interval"] == "1h"


def test_knmi_gzip(tmp_path):
    path = tmp_path / "uurgeg_260_test.txt.gz"
    with gzip.open(path, "wt", encoding="latin-1") as fh:
        fh.write(knmi_rows(ROWS))
    assert len(read_knmi_hourly(path)) == 4


def test_knmi_overlapping_files_and_order(tmp_path):
    a = write(tmp_path, "a.txt", knmi_rows(ROWS[:3]))
    b = write(tmp_path, "b.txt", knmi_rows(ROWS[2:]))
    df = read_knmi_hourly([b, a])
    assert len(df) == 4 and df.attrs["dropped"] == {"identical_duplicates": 1}
    clash = [(*ROWS[2][:3], 99, *ROWS[2][4:])]
    c = write(tmp_path, "c.txt", knmi_rows(clash))
    with pytest.raises(DataError, match="duplicate timestamp"):
        read_knmi_hourly([a, c])


def test_knmi_errors(tmp_path):
    with pytest.raises(DataError, match="not a KNMI hourly file"):
        read_knmi_hourly(write(tmp_path, "x.txt", "a,b\n1,2\n"))
    no_q = knmi_rows(ROWS).replace("    Q,", "   QQ,")
    with pytest.raises(DataError, match=r"column\(s\) 'Q' not found; columns are: 'STN'"):
        read_knmi_hourly(write(tmp_path, "noq.txt", no_q))
    bad_hh = [(260, 20210620, 25, 150, 120, 0, 80)]
    with pytest.raises(DataError, match=r"column 'HH' .*expected an hour 1\.\.24, found 25"):
        read_knmi_hourly(write(tmp_path, "hh.txt", knmi_rows(bad_hh)))
    bad_u = [(260, 20210620, 5, 150, 120, 0, 180)]
    path = write(tmp_path, "u.txt", knmi_rows(bad_u))
    with pytest.raises(DataError, match=r"u.txt: column 'U' \(RHe\) line 8: value 180"):
        read_knmi_hourly(path)
    assert np.isnan(read_knmi_hourly(path, invalid="nan")["RHe"].iloc[0])
    two = write(tmp_path, "two.txt", knmi_rows([ROWS[0], (280, *ROWS[1][1:])]))
    with pytest.raises(DataError, match="several stations"):
        read_knmi_hourly(two)
    with pytest.raises(DataError, match="file not found"):
        read_knmi_hourly(tmp_path / "missing.txt.gz")


# -- EPW ---------------------------------------------------------------------------------


def _epw_lines(shared_data):
    path = shared_data / "epw" / "BEL_VLG_Uccle.064470_TMYx.2007-2021.epw"
    return path.read_text(encoding="latin-1").splitlines()


@pytest.mark.shared_data
def test_epw_missing_markers_become_nan(shared_data, tmp_path):
    lines = _epw_lines(shared_data)
    fields = lines[8].split(",")
    fields[6], fields[8], fields[13] = "99.9", "999", "9999"  # temp_air, RH, GHI
    lines[8] = ",".join(fields)
    df = read_epw(write(tmp_path, "m.epw", "\n".join(lines) + "\n"))
    assert df.iloc[0][["Te", "RHe", "ghi"]].isna().all()
    assert not df.iloc[1][["Te", "RHe", "ghi"]].isna().any()


@pytest.mark.shared_data
def test_epw_actual_year_kept_when_in_order(shared_data, tmp_path):
    lines = _epw_lines(shared_data)
    rows = [",".join(["2015", *ln.split(",")[1:]]) for ln in lines[8:]]
    df = read_epw(write(tmp_path, "y.epw", "\n".join(lines[:8] + rows) + "\n"))
    assert df.attrs["coerced_year"] is None and df.index[0].year == 2015


def test_epw_and_tmy3_errors(tmp_path):
    with pytest.raises(DataError, match="file not found"):
        read_epw(tmp_path / "none.epw")
    with pytest.raises(DataError, match=r"bad\.epw: cannot read as EPW"):
        read_epw(write(tmp_path, "bad.epw", "not,an,epw\n"))
    with pytest.raises(DataError, match=r"bad\.csv: cannot read as TMY3"):
        read_tmy3(write(tmp_path, "bad.csv", "nothing here\n"))
    with pytest.raises(InputError, match="year must be an integer"):
        read_tmy3(pvlib_tmy3_path(), year="2019")
