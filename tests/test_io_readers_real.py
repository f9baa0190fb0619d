"""Readers on the real files in ../shared/data and the TMY3 file shipped with pvlib."""

from __future__ import annotations

import json

import numpy as np
import pandas as pd
import pytest

from _io_helpers import knmi_2011_2020, pvlib_tmy3_path
from heritage_bayes.errors import DataError
from heritage_bayes.io import read_csv, read_epw, read_knmi_hourly, read_tmy3

pytestmark = pytest.mark.shared_data

ORHOLM_KW = dict(
    sep=";", time_column="DATE AND TIME", time_format="%d-%m-%Y %H:%M",
    columns={"Ti": "TEMP C", "RHi": "%RH"},
)  # fmt: skip


def _tidy(df: pd.DataFrame) -> None:
    assert str(df.index.dtype) == "datetime64[ns, UTC]"
    assert df.index.is_monotonic_increasing and df.index.is_unique
    json.dumps(df.attrs, default=str)


def test_orholm_indoor_local_time(shared_data):
    path = shared_data / "orholm" / "oerholm-indoor-climate-data_2009-2021.csv"
    with pytest.raises(DataError, match=r"duplicate timestamp.*line 7304 \('01-11-2009 05:00'\)"):
        read_csv(path, timezone="Europe/Copenhagen", **ORHOLM_KW)
    df = read_csv(path, timezone="Europe/Copenhagen", duplicates="first", **ORHOLM_KW)
    _tidy(df)
    assert list(df.columns) == ["Ti", "RHi"]
    # 31-12-2008 23:00 local (CET) is 22:00 UTC
    assert df.index[0] == pd.Timestamp("2008-12-31 22:00", tz="UTC")
    assert df["Ti"].iloc[0] == 7.3 and df["RHi"].iloc[0] == 50
    # the file's clock quirks are dropped and counted, never duplicated
    dropped = df.attrs["dropped"]
    assert dropped["ambiguous_dst"] > 0 and dropped["nonexistent_dst"] > 0
    assert dropped["duplicates"] > 0
    assert 107601 - sum(dropped.values()) == len(df)
    assert df["RHi"].between(0, 100).all()
    # ~29 missing days in December 2010
    assert df.loc["2010-12"].shape[0] < 100


def test_annisse_indoor_reads_in_local_and_standard_time(shared_data):
    path = shared_data / "orholm" / "annisse-indoor-climate-data_2014-2018.csv"
    local = read_csv(path, timezone="Europe/Copenhagen", **ORHOLM_KW)
    _tidy(local)
    # The Annisse file has no DST signature (no repeated or missing hour in four years):
    # read as local time, its spring stamps do not exist and autumn hours have one pass.
    assert local.attrs["dropped"]["nonexistent_dst"] == 5
    standard = read_csv(path, timezone="UTC+1", **ORHOLM_KW)
    steps = standard.index.to_series().diff().dropna().unique()
    assert list(steps) == [pd.Timedelta("1h")] and len(standard) == 36842


def test_dmi_outdoor_utc(shared_data):
    path = shared_data / "orholm" / "DMI_outdoor-climate-data_2009-2021.csv"
    df = read_csv(
        path, sep=";", time_column=("Year", "Month", "Day", "Hour (UTC)"),
        time_format="%Y %m %d %H", timezone="UTC", columns={"Te": "TEMP C", "RHe": "%RH"},
    )  # fmt: skip
    _tidy(df)
    assert df.index[0] == pd.Timestamp("2008-12-31 23:00", tz="UTC")
    assert df.index[-1] == pd.Timestamp("2021-03-02 00:00", tz="UTC")
    assert len(df) == 106634 and df.attrs["dropped"] == {}
    assert "irradiance_source" not in df.attrs  # no solar data: a proxy must be opted into


@pytest.mark.parametrize(
    "name", ["indoor1.csv", "roofmiddle_airmiddle.csv", "roofmiddle_airtop.csv"]
)
def test_trh1_attic_fixed_utc_plus_2(shared_data, name):
    df = read_csv(
        shared_data / "trh1-espoo-attic" / name, time_column="t_UTC+2", timezone="UTC+2",
        columns={"Ti": "T", "RHi": "RH"},
    )  # fmt: skip
    _tidy(df)
    assert df.index[0] == pd.Timestamp("2010-11-22 22:00", tz="UTC")
    assert len(df) == 13921


def test_trh1_fmi_weather_with_radiation(shared_data):
    df = read_csv(
        shared_data / "trh1-espoo-attic" / "fmi.csv", time_column="t_UTC+2", timezone="UTC+2",
        columns={"Te": "Te", "RHe": "RHe", "ghi": "Rglob", "dhi": "Rdif"}, averaged=(),
    )  # fmt: skip
    _tidy(df)
    assert list(df.columns) == ["Te", "RHe", "ghi", "dhi"]
    # two pyranometers: diffuse exceeds global by 2-47 W/m² in ~230 overcast hours
    assert (df["dhi"] <= df["ghi"] + 50).all()
    # Why averaged=(): the radiation centroid of each summer month falls on solar transit
    # (≈ 10:21 UTC at 24.8° E) at the stamps themselves. Hour-ending averages would put
    # it half an hour later, hour-starting ones half an hour earlier.
    summer = df.loc["2011-05":"2011-08", "ghi"]
    hours = summer.index.hour + summer.index.minute / 60
    centroid = float((hours * summer).sum() / summer.sum())
    assert abs(centroid - 10.35) < 0.2


def test_knmi_de_bilt(shared_data):
    df = knmi_2011_2020(shared_data)
    _tidy(df)
    assert list(df.columns) == ["Te", "Tdew", "RHe", "ghi", "wind"]
    # HH=1 of 2011-01-01 is the hour ending 01:00 UT; HH=24 of 2020-12-31 is midnight
    assert df.index[0] == pd.Timestamp("2011-01-01 01:00", tz="UTC")
    assert df.index[-1] == pd.Timestamp("2021-01-01 00:00", tz="UTC")
    assert len(df) == 87672 and not df[["Te", "RHe", "ghi"]].isna().any().any()
    assert df["Te"].iloc[0] == pytest.approx(3.6) and df["Tdew"].iloc[0] == pytest.approx(3.4)
    assert df.attrs["averaged"] == ("ghi", "wind") and df.attrs["interval"] == "1h"
    assert df.attrs["station"] == 260
    # FH, the hour's mean wind in 0.1 m/s: De Bilt's mean 10 m wind is 3-4 m/s
    assert df["wind"].iloc[0] == pytest.approx(0.1 * int(_knmi_field(shared_data, "FH")))
    assert 2.5 < df["wind"].loc["2015"].mean() < 4.5 and df["wind"].min() >= 0
    # Q in J/cm² per hour -> W/m²: annual sum ~ 1000-1150 kWh/m² in De Bilt
    annual = df["ghi"].loc["2015"].sum() / 1000
    assert 950 < annual < 1200
    # The interval-end convention: the June radiation centroid at the stamps lies half an
    # hour after solar transit (≈ 11:39 UTC at 5.18° E).
    june = df.loc["2015-06", "ghi"]
    hours = june.index.hour + june.index.minute / 60
    centroid = float((np.where(hours == 0, 24, hours) * june).sum() / june.sum())
    assert abs(centroid - (11.65 + 0.5)) < 0.1


def _knmi_field(shared_data, field: str) -> str:
    """Field ``field`` of the first data line of De Bilt's 2011-2020 file, as written."""
    import gzip

    with gzip.open(shared_data / "knmi-debilt" / "uurgeg_260_2011-2020.txt.gz", "rt") as fh:
        lines = iter(fh)
        header = next(line for line in lines if line.startswith("# STN"))
        names = [c.strip() for c in header[1:].split(",")]
        next(lines)  # the blank line after the header
        return next(lines).split(",")[names.index(field)].strip()


def test_knmi_two_files_concatenated(shared_data):
    folder = shared_data / "knmi-debilt"
    df = read_knmi_hourly(
        [folder / "uurgeg_260_2021-2030.txt.gz", folder / "uurgeg_260_2011-2020.txt.gz"]
    )
    _tidy(df)
    assert df.index[0] == pd.Timestamp("2011-01-01 01:00", tz="UTC")
    assert df.index[-1] == pd.Timestamp("2025-05-27 00:00", tz="UTC")
    assert (df.index.to_series().diff().dropna() == pd.Timedelta("1h")).all()


def test_epw_uccle(shared_data):
    df = read_epw(shared_data / "epw" / "BEL_VLG_Uccle.064470_TMYx.2007-2021.epw")
    _tidy(df)
    assert len(df) == 8760
    # hour 1 of 1 January, UTC+1, ends 01:00 local = 00:00 UTC; typical year -> 2019
    assert df.index[0] == pd.Timestamp("2019-01-01 00:00", tz="UTC")
    assert df.index[-1] == pd.Timestamp("2019-12-31 23:00", tz="UTC")
    assert df.attrs["coerced_year"] == 2019
    assert df.attrs["site"] == {"latitude": 50.7969, "longitude": 4.3581, "altitude": 101.0}
    assert df["Te"].iloc[0] == 7.1 and df["RHe"].iloc[0] == 95
    assert df.attrs["averaged"] == ("ghi", "dni", "dhi")
    assert not df[["Te", "RHe", "ghi", "dni", "dhi", "wind"]].isna().any().any()
    # the wind speed field [m/s], the 22nd of a data line
    path = shared_data / "epw" / "BEL_VLG_Uccle.064470_TMYx.2007-2021.epw"
    first = path.read_text(encoding="latin-1").splitlines()[8].split(",")
    assert df["wind"].iloc[0] == float(first[21])
    assert 2.0 < df["wind"].mean() < 6.0


def test_epw_explicit_year(shared_data):
    df = read_epw(shared_data / "epw" / "BEL_VLG_Uccle.064470_TMYx.2007-2021.epw", year=2021)
    assert df.index[0] == pd.Timestamp("2021-01-01 00:00", tz="UTC")


def test_tmy3_shipped_with_pvlib():
    df = read_tmy3(pvlib_tmy3_path())
    _tidy(df)
    assert len(df) == 8760
    # TZ = -5: 01:00 local standard time on 1 Jan is 06:00 UTC; last row 24:00 on 31 Dec
    assert df.index[0] == pd.Timestamp("2019-01-01 06:00", tz="UTC")
    assert df.index[-1] == pd.Timestamp("2020-01-01 05:00", tz="UTC")
    assert df.attrs["site"]["latitude"] == pytest.approx(36.1)
    assert {"Te", "RHe", "ghi", "dni", "dhi"} <= set(df.columns)
    assert read_tmy3(pvlib_tmy3_path(), year=2010).index[0].year == 2010
