"""The ``data.weather`` and ``data.measurements`` sections ``hbayes init`` writes
(:mod:`heritage_bayes.init_config`): the reading settings of a CSV source, how its values
are stamped, and the policies the calibration needs to read the file as init did.
"""

from __future__ import annotations

from heritage_bayes.io.loggers import TableLayout
from heritage_bayes.yaml_text import yaml_value as _yaml_value

__all__ = ["source_lines", "timing_without_sun"]


def timing_without_sun(layout: TableLayout, findings: list[str]) -> str:
    """How a weather CSV without irradiance stamps its values (the sun cannot tell):
    hour-ending means for a DMI portal export (``Station;Year;Month;Day;Hour (UTC)``,
    "hourly averages" in its description), readings at the stamp otherwise."""
    tc = layout.time_column if isinstance(layout.time_column, list) else [layout.time_column]
    if "Station" in layout.header and "Hour (UTC)" in tc:
        findings.append(
            "weather: a DMI export (Station, Year, Month, Day, Hour (UTC)): its values are "
            "hourly averages, taken as means of the hour ending at the stamp"
        )
        return "means_end"
    findings.append(
        "weather: no irradiance to time the stamps against the sun: Te and RHe taken as "
        "readings at the stamp; if the file holds interval means, list them under averaged"
    )
    return "instant"


def source_lines(
    key: str, layout: TableLayout, rel: str, zone, columns, units, label, dropped
) -> list[str]:
    out = [f"  {key}:", "    format: csv", f"    path: {_yaml_value(rel)}"]
    tc = layout.time_column
    out.append(f"    time_column: {_yaml_value(tc)}")
    if layout.time_format != "ISO8601":
        out.append(f"    time_format: {_yaml_value(layout.time_format)}")
        out.append(f"    timezone: {_yaml_value(zone)}")
    if layout.sep != ",":
        out.append(f"    sep: {_yaml_value(layout.sep)}")
    if layout.decimal != ".":
        out.append(f"    decimal: {_yaml_value(layout.decimal)}")
    if layout.skiprows:
        out.append(f"    skiprows: {_yaml_value(layout.skiprows)}   # {layout.layout} layout")
    if layout.encoding != "utf-8":
        out.append(f"    encoding: {layout.encoding}")
    out.append(f"    columns: {_yaml_value(columns)}")
    if units:
        out.append(f"    units: {_yaml_value(units)}   # converted on reading")
    irr = [c for c in ("ghi", "dni", "dhi") if c in columns]
    if label == "means_end":
        out.append(
            f"    averaged: {_yaml_value(sorted(columns))}   # means of the hour ending at "
            "the stamp (the file's documentation): constant over their hour"
        )
    elif label == "instant" or (label is not None and not irr):
        out.append(
            "    averaged: []   # every column read at the stamp (irradiance: see the clock "
            "check): linear between readings"
        )
    elif label in ("end", "start"):
        out.append(
            f"    averaged: {_yaml_value(irr)}   # means of the hour "
            f"{'ending' if label == 'end' else 'starting'} at the stamp (the clock check); "
            "the others read at the stamp"
        )
        if label == "start":
            out.append("    label: start")
    out += _policy_lines(dropped)
    return out


#: What the reader dropped while init inspected a file, and the key that lets the
#: calibration read the file the same way (its default would refuse it).
_POLICIES = {
    "duplicates": ("duplicates: first", "stamps repeated with other values: the first kept"),
    "sorted": ("sort: true", "time stamps going backwards: the rows sorted by time"),
    "bad_timestamps": ("invalid: nan", "unreadable time stamps: those rows dropped"),
    "unparseable_values": ("invalid: nan", "unreadable values: left out"),
    "out_of_range": ("invalid: nan", "values outside the physical range: left out"),
}


def _policy_lines(dropped: dict) -> list[str]:
    lines: dict[str, list[str]] = {}
    for what, n in (dropped or {}).items():
        if what in _POLICIES and n:
            setting, why = _POLICIES[what]
            lines.setdefault(setting, []).append(f"{n} {why}")
    return [f"    {k}   # {'; '.join(v)}" for k, v in lines.items()]
