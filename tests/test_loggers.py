"""Logger exports (io.loggers): each documented layout, written in tmp_path, is recognised
and read back exactly by read_csv with the options inspect_table found."""

from __future__ import annotations

import numpy as np
import pandas as pd
import pytest

from heritage_bayes.errors import DataError, InputError
from heritage_bayes.io import read_csv
from heritage_bayes.io.loggers import inspect_table

#: 3 days of half-hourly readings, the values every layout below writes.
TIMES = pd.date_range("2021-03-01 00:00", periods=144, freq="30min")
T_C = np.round(18 + 2 * np.sin(np.arange(144) / 48 * 2 * np.pi), 3)
RH = np.round(50 + 5 * np.cos(np.arange(144) / 48 * 2 * np.pi), 2)


def _read(layout, **extra):
    cols = {"Ti": layout.first("T").name, "RHi": layout.first("RH").name}
    units = {k: c.unit for k, c in (("Ti", layout.first("T")), ("RHi", layout.first("RH")))}
    units = {k: u for k, u in units.items() if u not in ("°C", "%")}
    return read_csv(
        layout.path,
        time_column=layout.time_column,
        columns=cols,
        time_format=layout.time_format,
        timezone=layout.timezone or "UTC",
        sep=layout.sep,
        decimal=layout.decimal,
        skiprows=layout.skiprows,
        encoding=layout.encoding,
        units=units or None,
        **extra,
    )


def _check(df, t_expected=T_C, rh_expected=RH, offset_h=0):
    np.testing.assert_allclose(df["Ti"].to_numpy(), t_expected, atol=1e-3)
    np.testing.assert_allclose(df["RHi"].to_numpy(), rh_expected, atol=1e-3)
    want = (TIMES - pd.Timedelta(hours=offset_h)).tz_localize("UTC")
    assert (df.index == want).all()


def _hobo(path, title, header, temps, tail, encoding="utf-8"):
    """A HOBOware CSV: title line, header, numbered rows (US 12-hour time stamps)."""
    lines = [f'"Plot Title: {title}"', header]
    for i, (t, a, b) in enumerate(zip(TIMES, temps, RH, strict=True)):
        lines.append(f"{i + 1},{t:%m/%d/%y %I:%M:%S %p},{a:.3f},{b:.3f}{tail}")
    path.write_bytes(("\r\n".join(lines) + "\r\n").encode(encoding))
    return path


def test_hobo_hoboware_csv(tmp_path):
    # HOBOware CSV as in building-energy/hoboreader tests/sample_hobo_u12_data.csv
    header = (
        '"#","Time, GMT+01:00","Temp, °C()","RH, %()","Intensity, Lux()","Bad Battery()",'
        '"Host Connected()","Stopped()","End Of File()"'
    )
    p = _hobo(tmp_path / "hobo.csv", "01_10_13 ", header, T_C, ",11.8,,,,")
    lay = inspect_table(p)
    assert lay.layout == "hobo"
    assert lay.time_column == "Time, GMT+01:00"
    assert lay.time_format == "%m/%d/%y %I:%M:%S %p"
    assert lay.timezone == "UTC+1"  # the clock HOBOware names in the header
    assert lay.first("T").name == "Temp, °C()" and lay.first("T").unit == "°C"
    assert "Intensity, Lux()" not in {c.name for c in lay.columns if c.kind}
    _check(_read(lay), offset_h=1)


def test_hobo_pendant_fahrenheit_cp1252(tmp_path):
    # HOBO pendant export in °F (hoboreader tests/sample_hobo_pendant_data.csv), saved
    # by an older Windows HOBOware: cp1252 degree sign
    t_f = np.round(T_C * 1.8 + 32, 3)
    header = (
        '"#","Date Time, GMT+01:00","Temp, °F (LGR S/N: 10469238, SEN S/N: 10469238)",'
        '"RH, % (LGR S/N: 10469238)","Stopped (LGR S/N: 10469238)"'
    )
    p = _hobo(tmp_path / "pendant.csv", "P12_4", header, t_f, ",", encoding="cp1252")
    lay = inspect_table(p)
    assert (lay.layout, lay.encoding) == ("hobo", "cp1252")
    assert lay.first("T").unit == "°F"
    _check(_read(lay), offset_h=1)


def test_hanwell(tmp_path):
    # abazemore/dataloggergraphs tests/testthat/fixtures/hanwell/Hanwell.csv
    lines = [
        "",
        "Database Valid",
        "  Sensor:,Thermistor/RH",
        "  Style:,Stand-Alone",
        "  Serial No:,0000-00000",
        f"  Data Starts:,{TIMES[0]:%H:%M %d/%b/%Y}",
        f"  Data Ends:,{TIMES[-1]:%H:%M %d/%b/%Y}",
        "",
        "",
        f"  No. of Readings:,{len(TIMES)}",
        "",
        "",
        "Time, Temperature (C),Humidity (RH(%)),",
    ]
    lines += [
        f"{t:%H:%M:%S %d/%b/%Y},{a:.3f},{b:.2f}," for t, a, b in zip(TIMES, T_C, RH, strict=True)
    ]
    p = tmp_path / "hanwell.csv"
    p.write_text("\n".join(lines) + "\n", encoding="utf-8")
    lay = inspect_table(p)
    assert lay.layout == "hanwell"
    assert (lay.skiprows, lay.time_column, lay.time_format) == (12, "Time", "%H:%M:%S %d/%b/%Y")
    assert lay.timezone is None
    _check(_read(lay))


def test_meaco(tmp_path):
    # abazemore/dataloggergraphs fixtures/meaco/Meaco_1.csv
    lines = ["RECEIVER,TRANSMITTER,DATE,TEMPERATURE,HUMIDITY"]
    lines += [
        f'"Anonymous Library","Archive 1","{t:%Y-%m-%d %H:%M}",{a:.3f},{b:.2f}'
        for t, a, b in zip(TIMES, T_C, RH, strict=True)
    ]
    p = tmp_path / "meaco.csv"
    p.write_text("\n".join(lines) + "\n", encoding="utf-8")
    lay = inspect_table(p)
    assert (lay.layout, lay.time_column, lay.time_format) == ("meaco", "DATE", "%Y-%m-%d %H:%M")
    assert lay.first("T").name == "TEMPERATURE" and lay.first("RH").name == "HUMIDITY"
    _check(_read(lay))


def test_tinytag(tmp_path):
    # abazemore/dataloggergraphs fixtures/tinytag/TinyTag_2.csv (Tinytag Explorer)
    lines = [
        ",Time,1,2",
        "S/N,,000000,000000",
        "Type,,Tinytag Ultra H°C/%RH,Tinytag Ultra H°C/%RH",
        "Description,,Archive 2,Archive 2",
        "Property,,Temperature,Humidity",
    ]
    lines += [
        f"{i + 1},{t:%Y-%m-%d %H:%M:%S},{a:.3f},{b:.1f}"
        for i, (t, a, b) in enumerate(zip(TIMES, T_C, np.round(RH, 1), strict=True))
    ]
    p = tmp_path / "tinytag.csv"
    p.write_text("\n".join(lines) + "\n", encoding="utf-8")
    lay = inspect_table(p)
    assert lay.layout == "tinytag"
    assert lay.skiprows == [1, 2, 3, 4]
    assert (lay.first("T").name, lay.first("RH").name) == ("1", "2")  # from 'Property'
    _check(_read(lay), rh_expected=np.round(RH, 1))


@pytest.mark.parametrize("sep", [",", "\t"])
def test_rotronic_hw4(tmp_path, sep):
    # abazemore/dataloggergraphs fixtures/tinytag/Rotronic_1.csv (HW4 export; the
    # .xls export is the same text, tab-separated)
    pad = sep * 3
    lines = [
        f"[#I]Device Description{pad}",
        f"Arch1  {pad}",
        pad,
        f"[#S]Device Information{pad}",
        f"Version = V2.2-2{pad}",
        f"Serial Number = A00000000{pad}",
        f"Log Interval = 00:30:00{pad}",
        pad,
        f"[#1]{pad}",
        f"Humidity = %rh{pad}",
        pad,
        f"[#2]{pad}",
        f"Temperature = °C{pad}",
        pad,
        f"[#H]{pad}",
        sep.join(["Date", "Time", "Humidity", "Temperature"]),
        pad,
        f"[#D]{pad}",
    ]
    lines += [
        sep.join([f"{t:%d/%m/%Y}", f"{t:%H:%M:%S}", f"{b:.2f}", f"{a:.3f}"])
        for t, a, b in zip(TIMES, T_C, RH, strict=True)
    ]
    p = tmp_path / "rotronic.csv"
    p.write_text("\n".join(lines) + "\n", encoding="utf-8")
    lay = inspect_table(p)
    assert (lay.layout, lay.sep) == ("rotronic", sep)
    assert lay.time_column == ["Date", "Time"]
    assert lay.time_format == "%d/%m/%Y %H:%M:%S"
    assert lay.skiprows == [*range(15), 16, 17]
    _check(_read(lay))


def test_generic_semicolon_decimal_comma_bom_kelvin_fraction(tmp_path):
    # a European spreadsheet export: ';', decimal comma, byte-order mark, a preamble,
    # temperature in K and RH as a fraction, day-first dates
    lines = ["Export from the building management system", "Room 12", ""]
    lines.append("Datum/Tijd;Temperatuur [K];Relative humidity [-];Battery")
    lines += [
        f"{t:%d-%m-%Y %H:%M};{a + 273.15:.3f};{b / 100:.4f};3,1".replace(".", ",")
        for t, a, b in zip(TIMES, T_C, RH, strict=True)
    ]
    p = tmp_path / "bms.csv"
    p.write_bytes(("\r\n".join(lines) + "\r\n").encode("utf-8-sig"))
    lay = inspect_table(p)
    assert (lay.layout, lay.sep, lay.decimal, lay.encoding) == ("generic", ";", ",", "utf-8-sig")
    assert lay.skiprows == 3
    assert lay.time_format == "%d-%m-%Y %H:%M"
    assert (lay.first("T").unit, lay.first("RH").unit) == ("K", "fraction")
    _check(_read(lay))


def test_day_first_told_from_month_first(tmp_path):
    # 01/03 .. 03/03: both readings parse; only day-first gives a regular series
    lines = ["time,T,RH"] + [
        f"{t:%d/%m/%Y %H:%M},{a},{b}" for t, a, b in zip(TIMES, T_C, RH, strict=True)
    ]
    p = tmp_path / "dayfirst.csv"
    p.write_text("\n".join(lines), encoding="utf-8")
    assert inspect_table(p).time_format == "%d/%m/%Y %H:%M"


def test_inspect_errors_name_the_file(tmp_path):
    p = tmp_path / "x.xls"
    p.write_bytes(b"\xd0\xcf\x11\xe0\x00\x00binary")  # an old binary .xls
    with pytest.raises(DataError, match=r"x\.xls: a binary file, not a text table"):
        inspect_table(p)
    p = tmp_path / "x.xlsx"
    p.write_bytes(b"PK\x03\x04\x00\x00damaged")
    with pytest.raises(DataError, match=r"x\.xlsx: cannot read the workbook"):
        inspect_table(p)
    q = tmp_path / "notime.csv"
    q.write_text("a,b\n1,2\n3,4\n5,6\n", encoding="utf-8")
    with pytest.raises(DataError, match=r"notime\.csv: no column holds time stamps"):
        inspect_table(q)


def test_read_csv_units_and_errors(tmp_path):
    p = tmp_path / "u.csv"
    p.write_text("t,T,RH\n2021-01-01 00:00,68,0.5\n2021-01-01 01:00,77,0.6\n", encoding="utf-8")
    df = read_csv(
        p,
        time_column="t",
        columns={"Ti": "T", "RHi": "RH"},
        timezone="UTC",
        units={"Ti": "°F", "RHi": "fraction"},
    )
    np.testing.assert_allclose(df["Ti"], [20.0, 25.0])
    np.testing.assert_allclose(df["RHi"], [50.0, 60.0])
    with pytest.raises(InputError, match=r"units\.Ti: one of '°C', '°F', 'K' \(got 'F'\)"):
        read_csv(p, time_column="t", columns={"Ti": "T"}, timezone="UTC", units={"Ti": "F"})
    with pytest.raises(InputError, match=r"units\.ghi: only temperatures"):
        read_csv(p, time_column="t", columns={"ghi": "T"}, timezone="UTC", units={"ghi": "K"})


def test_xlsx_workbook(tmp_path):
    # a logger export saved as .xlsx: real date cells, a title row, °C and %RH columns
    from openpyxl import Workbook

    wb = Workbook()
    ws = wb.active
    ws.append(["Store 3, exported 2021-03-04"])
    ws.append(["Date/time", "Temperature (°C)", "RH (%)"])
    for t, a, b in zip(TIMES, T_C, RH, strict=True):
        ws.append([t.to_pydatetime(), float(a), float(b)])
    p = tmp_path / "store.xlsx"
    wb.save(p)
    lay = inspect_table(p)
    assert (lay.layout, lay.sep, lay.skiprows) == ("generic", ",", 1)
    assert (lay.time_column, lay.time_format) == ("Date/time", "%Y-%m-%d %H:%M:%S")
    _check(_read(lay))


def test_weather_service_date_parts(tmp_path):
    # DMI's layout (Station;Year;Month;Day;Hour (UTC);TEMP C;%RH): time over four columns
    lines = ["Station;Year;Month;Day;Hour (UTC);TEMP C;%RH"] + [
        f"618100;{t.year};{t.month};{t.day};{t.hour};{a:.1f};{b:.0f}"
        for t, a, b in zip(TIMES, T_C, RH, strict=True)
    ]
    p = tmp_path / "dmi.csv"
    p.write_text("\n".join(lines), encoding="utf-8")
    lay = inspect_table(p)
    assert lay.time_column == ["Year", "Month", "Day", "Hour (UTC)"]
    assert (lay.time_format, lay.timezone, lay.sep) == ("%Y %m %d %H", "UTC", ";")
    assert lay.first("T").name == "TEMP C" and lay.first("RH").name == "%RH"
