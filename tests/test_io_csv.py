"""read_csv on synthetic files: DST, gaps, bad rows, wrong columns, duplicates, ranges."""

from __future__ import annotations

import numpy as np
import pandas as pd
import pytest

from _io_helpers import write
from heritage_bayes.errors import DataError, InputError
from heritage_bayes.io import STANDARD_COLUMNS, parse_timezone, read_csv

LOGGER = dict(
    sep=";", time_column="DATE AND TIME", time_format="%d-%m-%Y %H:%M",
    columns={"Ti": "TEMP C", "RHi": "%RH"},
)  # fmt: skip


def logger_file(tmp_path, rows, name="logger.csv", newline="\r\n"):
    header = "DATE AND TIME; TEMP C; %RH          "
    return write(tmp_path, name, "\n".join([header, *rows]) + "\n", newline)


def utc(*stamps):
    return pd.DatetimeIndex(list(stamps), tz="UTC")


# -- basics ----------------------------------------------------------------------------


def test_padded_header_crlf_fixed_offset(tmp_path):
    path = logger_file(tmp_path, ["01-01-2021 00:00;10.5;50", "01-01-2021 01:00;10.7;51.5"])
    df = read_csv(path, timezone="UTC+2", **LOGGER)
    assert list(df.columns) == ["Ti", "RHi"]
    assert df.index.equals(utc("2020-12-31 22:00", "2020-12-31 23:00"))
    assert str(df.index.dtype) == "datetime64[ns, UTC]"
    assert df.index.name == "time"
    assert df["Ti"].tolist() == [10.5, 10.7]
    assert df.attrs["units"] == {"Ti": "°C", "RHi": "%"}
    assert df.attrs["averaged"] == ()
    assert df.attrs["interval"] == "1h"
    assert df.attrs["source"] == str(path)
    assert df.attrs["timezone"] == "UTC+2"


@pytest.mark.parametrize(
    ("text", "hours"),
    [("UTC", 0), ("utc+2", 2), ("UTC-03:30", -3.5), ("+01:00", 1), ("GMT+1", 1)],
)
def test_parse_fixed_offsets(text, hours):
    tz = parse_timezone(text)
    assert tz.utcoffset(None) == pd.Timedelta(hours=hours)


def test_parse_timezone_rejects_unknown():
    with pytest.raises(InputError, match="unknown timezone 'Europe/Kopenhagen'"):
        parse_timezone("Europe/Kopenhagen")


def test_multi_column_time_decimal_comma(tmp_path):
    text = (
        "Station;Year;Month;Day;Hour (UTC);TEMP C;%RH\n"
        "1;2021;3;1;23;-1,5;93\n1;2021;3;2;0;2,5;99,8\n"
    )
    path = write(tmp_path, "dmi.csv", text)
    df = read_csv(
        path, sep=";", decimal=",", time_column=("Year", "Month", "Day", "Hour (UTC)"),
        time_format="%Y %m %d %H", timezone="UTC", columns={"Te": "TEMP C", "RHe": "%RH"},
    )  # fmt: skip
    assert df.index.equals(utc("2021-03-01 23:00", "2021-03-02 00:00"))
    assert df["Te"].tolist() == [-1.5, 2.5]
    assert df["RHe"].tolist() == [93.0, 99.8]


def test_default_columns_are_standard_names(tmp_path):
    path = write(tmp_path, "std.csv", "time,Ti,RHi,other\n2021-01-01 00:00,1,50,x\n")
    df = read_csv(path, time_column="time", timezone="UTC")
    assert list(df.columns) == ["Ti", "RHi"]


def test_iso_offsets_in_timestamps(tmp_path):
    text = "t,T\n2021-03-28T00:00+01:00,1\n2021-03-28T03:00+02:00,2\n"
    df = read_csv(write(tmp_path, "iso.csv", text), time_column="t", columns={"Ti": "T"})
    assert df.index.equals(utc("2021-03-27 23:00", "2021-03-28 01:00"))
    with pytest.raises(DataError, match="carry their own UTC offset"):
        read_csv(write(tmp_path, "iso.csv", text), time_column="t", columns={"Ti": "T"},
                 timezone="UTC")  # fmt: skip


def test_naive_timestamps_need_a_timezone(tmp_path):
    path = logger_file(tmp_path, ["01-01-2021 00:00;10.5;50"])
    with pytest.raises(DataError, match=r"no UTC offset .*pass timezone="):
        read_csv(path, **LOGGER)


# -- daylight-saving time ---------------------------------------------------------------


def test_dst_repeated_autumn_hour_resolved_by_order(tmp_path):
    rows = ["31-10-2021 00:00;1;50", "31-10-2021 01:00;2;50", "31-10-2021 02:00;3;50",
            "31-10-2021 02:00;4;50", "31-10-2021 03:00;5;50"]  # fmt: skip
    df = read_csv(logger_file(tmp_path, rows), timezone="Europe/Copenhagen", **LOGGER)
    assert df.index.equals(pd.date_range("2021-10-30 22:00", periods=5, freq="h", tz="UTC"))
    assert df["Ti"].tolist() == [1, 2, 3, 4, 5]
    assert df.attrs["dropped"] == {}


def test_dst_repeated_hour_10min_logger(tmp_path):
    labels = ["01:50"] + [f"02:{m:02d}" for m in range(0, 60, 10)] * 2 + ["03:00"]
    rows = [f"31-10-2021 {lab};{i};50" for i, lab in enumerate(labels)]
    df = read_csv(logger_file(tmp_path, rows), timezone="Europe/Copenhagen", **LOGGER)
    assert df.index.equals(pd.date_range("2021-10-30 23:50", periods=14, freq="10min", tz="UTC"))
    assert df["Ti"].tolist() == list(range(14))


def test_dst_single_pass_of_repeated_hour_is_dropped_and_counted(tmp_path):
    rows = ["31-10-2021 01:00;2;50", "31-10-2021 02:00;3;50", "31-10-2021 03:00;5;50"]
    df = read_csv(logger_file(tmp_path, rows), timezone="Europe/Copenhagen", **LOGGER)
    assert df.index.equals(utc("2021-10-30 23:00", "2021-10-31 02:00"))
    assert df.attrs["dropped"] == {"ambiguous_dst": 1}
    assert not df.index.has_duplicates


def test_dst_missing_spring_hour_is_a_gap(tmp_path):
    rows = ["28-03-2021 00:00;1;50", "28-03-2021 01:00;2;50", "28-03-2021 03:00;3;50"]
    df = read_csv(logger_file(tmp_path, rows), timezone="Europe/Copenhagen", **LOGGER)
    assert df.index.equals(pd.date_range("2021-03-27 23:00", periods=3, freq="h", tz="UTC"))
    assert df.attrs["dropped"] == {}


def test_dst_nonexistent_spring_stamp_is_dropped_and_counted(tmp_path):
    rows = ["28-03-2021 01:00;2;50", "28-03-2021 02:00;9;50", "28-03-2021 03:00;3;50"]
    df = read_csv(logger_file(tmp_path, rows), timezone="Europe/Copenhagen", **LOGGER)
    assert df["Ti"].tolist() == [2, 3]
    assert df.attrs["dropped"] == {"nonexistent_dst": 1}


# -- bad files, columns, rows -------------------------------------------------------------


def test_missing_file(tmp_path):
    with pytest.raises(DataError, match=r"nope\.csv: file not found"):
        read_csv(tmp_path / "nope.csv", timezone="UTC", **LOGGER)


def test_empty_file(tmp_path):
    with pytest.raises(DataError, match="empty"):
        read_csv(write(tmp_path, "e.csv", ""), timezone="UTC", **LOGGER)


def test_misspelt_column_lists_existing(tmp_path):
    path = logger_file(tmp_path, ["01-01-2021 00:00;10.5;50"], name="oerholm.csv")
    with pytest.raises(DataError) as err:
        read_csv(path, timezone="UTC", **{**LOGGER, "columns": {"Ti": "TEMP", "RHi": "%RH"}})
    assert str(err.value) == (
        "oerholm.csv: column 'TEMP' not found; columns are: 'DATE AND TIME', 'TEMP C', '%RH'"
    )


def test_misspelt_time_column(tmp_path):
    path = logger_file(tmp_path, ["01-01-2021 00:00;10.5;50"])
    with pytest.raises(DataError, match="column 'DATE' not found"):
        read_csv(path, timezone="UTC", **{**LOGGER, "time_column": "DATE"})


def test_unknown_standard_name_rejected(tmp_path):
    path = logger_file(tmp_path, ["01-01-2021 00:00;10.5;50"])
    with pytest.raises(InputError, match=r"unknown standard name.*'Tin'"):
        read_csv(path, timezone="UTC", **{**LOGGER, "columns": {"Tin": "TEMP C"}})


def test_unknown_keyword_rejected(tmp_path):
    path = logger_file(tmp_path, ["01-01-2021 00:00;10.5;50"])
    with pytest.raises(TypeError):
        read_csv(path, timezone="UTC", tz="UTC", **LOGGER)
    with pytest.raises(InputError, match="duplicates must be one of"):
        read_csv(path, timezone="UTC", duplicates="keep", **LOGGER)


def test_unparseable_timestamp_names_line(tmp_path):
    rows = ["01-01-2021 00:00;1;50", "01-01-2021 01:00;2;50", "2021-01-01 02:00;3;50"]
    path = logger_file(tmp_path, rows, name="log.csv")
    with pytest.raises(DataError) as err:
        read_csv(path, timezone="UTC", **LOGGER)
    msg = str(err.value)
    assert "log.csv" in msg and "'2021-01-01 02:00'" in msg and "line 4" in msg
    assert "'%d-%m-%Y %H:%M'" in msg
    df = read_csv(path, timezone="UTC", invalid="nan", **LOGGER)
    assert len(df) == 2 and df.attrs["dropped"] == {"bad_timestamps": 1}


def test_unparseable_value_names_column_and_line(tmp_path):
    rows = ["01-01-2021 00:00;1;50", "01-01-2021 01:00;ERR;50", "01-01-2021 02:00;3;50"]
    path = logger_file(tmp_path, rows, name="log.csv")
    with pytest.raises(DataError, match=r"log.csv: column 'TEMP C' line 3: cannot parse 'ERR'"):
        read_csv(path, timezone="UTC", **LOGGER)
    df = read_csv(path, timezone="UTC", na_values=["ERR"], **LOGGER)
    assert np.isnan(df["Ti"].iloc[1]) and df.attrs["dropped"] == {}


def test_blank_and_empty_cells(tmp_path):
    rows = ["01-01-2021 00:00;1;50", "", "01-01-2021 01:00;;51", "01-01-2021 02:00;3;52"]
    df = read_csv(logger_file(tmp_path, rows), timezone="UTC", **LOGGER)
    assert len(df) == 3 and np.isnan(df["Ti"].iloc[1])
    assert df.attrs["dropped"] == {"blank_rows": 1}


def test_wrong_number_of_fields(tmp_path):
    rows = ["01-01-2021 00:00;1;50", "01-01-2021 01:00;2;50;7;8"]
    with pytest.raises(DataError, match=r"logger\.csv: malformed table"):
        read_csv(logger_file(tmp_path, rows), timezone="UTC", **LOGGER)


def test_numeric_sentinel(tmp_path):
    rows = ["01-01-2021 00:00;-9999;50", "01-01-2021 01:00;2;50"]
    df = read_csv(logger_file(tmp_path, rows), timezone="UTC", na_values=[-9999], **LOGGER)
    assert np.isnan(df["Ti"].iloc[0]) and df["Ti"].iloc[1] == 2


# -- order and duplicates -----------------------------------------------------------------


def test_non_monotonic_raises_or_sorts(tmp_path):
    rows = ["01-01-2021 00:00;1;50", "01-01-2021 02:00;3;50", "01-01-2021 01:00;2;50"]
    path = logger_file(tmp_path, rows, name="log.csv")
    with pytest.raises(DataError, match=r"log.csv: .*not in increasing order: line 4"):
        read_csv(path, timezone="UTC", **LOGGER)
    df = read_csv(path, timezone="UTC", sort=True, **LOGGER)
    assert df["Ti"].tolist() == [1, 2, 3] and df.attrs["dropped"] == {"sorted": 1}


def test_duplicates_policies(tmp_path):
    rows = ["01-01-2021 00:00;1;50", "01-01-2021 01:00;2;50", "01-01-2021 01:00;4;52",
            "01-01-2021 02:00;3;50"]  # fmt: skip
    path = logger_file(tmp_path, rows, name="log.csv")
    with pytest.raises(DataError, match=r"1 duplicate timestamp.*line 4 .*line 3"):
        read_csv(path, timezone="UTC", **LOGGER)
    expected = {"first": 2.0, "last": 4.0, "mean": 3.0}
    for policy, value in expected.items():
        df = read_csv(path, timezone="UTC", duplicates=policy, **LOGGER)
        assert len(df) == 3 and df["Ti"].iloc[1] == value
        assert df.attrs["dropped"] == {"duplicates": 1}
        assert df.index.is_unique and df.index.is_monotonic_increasing


def test_identical_duplicate_rows_dropped_and_counted(tmp_path):
    rows = ["01-01-2021 00:00;1;50", "01-01-2021 00:00;1;50", "01-01-2021 01:00;2;50"]
    df = read_csv(logger_file(tmp_path, rows), timezone="UTC", **LOGGER)
    assert len(df) == 2 and df.attrs["dropped"] == {"identical_duplicates": 1}


# -- physical ranges ------------------------------------------------------------------------


@pytest.mark.parametrize(
    ("temp", "rh"), [("71", "50"), ("-61", "50"), ("10", "100.5"), ("10", "-1")]
)
def test_out_of_range_values(tmp_path, temp, rh):
    rows = ["01-01-2021 00:00;10;50", f"01-01-2021 01:00;{temp};{rh}"]
    path = logger_file(tmp_path, rows, name="log.csv")
    with pytest.raises(DataError, match=r"log.csv: column '(TEMP C|%RH)' \((Ti|RHi)\) line 3"):
        read_csv(path, timezone="UTC", **LOGGER)
    df = read_csv(path, timezone="UTC", invalid="nan", **LOGGER)
    assert df.iloc[1].isna().sum() == 1 and df.attrs["dropped"] == {"out_of_range": 1}


def test_irradiance_noise_clipped_beyond_noise_rejected(tmp_path):
    text = "t,G\n2021-06-01 00:00,-3\n2021-06-01 01:00,0\n2021-06-01 02:00,120\n"
    df = read_csv(write(tmp_path, "g.csv", text), time_column="t", timezone="UTC",
                  columns={"ghi": "G"})  # fmt: skip
    assert df["ghi"].tolist() == [0, 0, 120]
    assert df.attrs["clipped"] == {"ghi": 1}
    assert df.attrs["averaged"] == ("ghi",) and df.attrs["irradiance_source"] == "measured"
    bad = text.replace("-3", "-25")
    with pytest.raises(DataError, match=r"column 'G' \(ghi\) line 2: value -25"):
        read_csv(write(tmp_path, "g.csv", bad), time_column="t", timezone="UTC",
                 columns={"ghi": "G"})  # fmt: skip


# -- interval averages -------------------------------------------------------------------------


def test_start_labelled_averages_move_to_interval_end(tmp_path):
    text = "t,T,G\n2021-06-01 10:00,20,100\n2021-06-01 11:00,21,200\n"
    df = read_csv(write(tmp_path, "g.csv", text), time_column="t", timezone="UTC",
                  columns={"Te": "T", "ghi": "G"}, label="start")  # fmt: skip
    assert df.index.equals(utc("2021-06-01 10:00", "2021-06-01 11:00", "2021-06-01 12:00"))
    assert df["Te"].tolist()[:2] == [20, 21] and np.isnan(df["Te"].iloc[2])
    assert np.isnan(df["ghi"].iloc[0]) and df["ghi"].tolist()[1:] == [100, 200]


def test_averaged_override_and_interval(tmp_path):
    text = "t,T,G\n2021-06-01 10:00,20,100\n2021-06-01 10:10,21,200\n"
    path = write(tmp_path, "g.csv", text)
    df = read_csv(path, time_column="t", timezone="UTC", columns={"Te": "T", "ghi": "G"},
                  averaged=("Te", "ghi"), interval="10min")  # fmt: skip
    assert df.attrs["averaged"] == ("Te", "ghi") and df.attrs["interval"] == "10min"
    df = read_csv(path, time_column="t", timezone="UTC", columns={"ghi": "G"}, averaged=())
    assert df.attrs["averaged"] == ()
    with pytest.raises(InputError, match="averaged"):
        read_csv(path, time_column="t", timezone="UTC", columns={"ghi": "G"}, averaged=("Te",))


def test_standard_columns_have_units():
    for name, (unit, description, (lo, hi)) in STANDARD_COLUMNS.items():
        assert unit and description and lo < hi, name


def test_elapsed_seconds_since_an_origin(tmp_path):
    """Test-cell exports count seconds (pySIP's ``Time``): ``time_origin`` anchors them."""
    path = write(
        tmp_path, "cell.csv", "Time,T_ext,I_sol\n0.0,15.4,14.2\n1800.0,15.0,0\n3600,14.9,3\n"
    )
    df = read_csv(
        path,
        time_column="Time",
        time_origin="2020-01-01 00:00",
        timezone="UTC+1",
        columns={"Te": "T_ext", "Isol": "I_sol"},
        averaged=(),
    )
    assert list(df.index) == list(
        pd.date_range("2019-12-31 23:00", periods=3, freq="30min", tz="UTC")
    )
    assert df["Te"].tolist() == [15.4, 15.0, 14.9] and df["Isol"].tolist() == [14.2, 0.0, 3.0]
    with pytest.raises(DataError, match="line 3"):
        bad = write(tmp_path, "bad.csv", "Time,T_ext\n0,1\nx,2\n")
        read_csv(
            bad,
            time_column="Time",
            time_origin="2020-01-01",
            timezone="UTC",
            columns={"Te": "T_ext"},
        )
