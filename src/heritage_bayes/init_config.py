"""``hbayes init``: a commented configuration from a logger file and a weather file.

:func:`init_config` inspects the files with :mod:`heritage_bayes.io` (the export's layout
with :func:`~heritage_bayes.io.loggers.inspect_table`, the clocks with
:mod:`heritage_bayes.io.clock`), decides what it can — time column and format, the clock
of each file checked against the sun and the outdoor daily cycle, the columns of
temperature, relative humidity and irradiance and their units, the step, the gaps, the
usable span of overlapping data for the calibration and validation periods, the
models to start with — and writes a ``config.yaml`` whose comments say what was guessed
and why. What it cannot decide becomes a marked question (a value starting with ``??``,
see :mod:`heritage_bayes.questions`) that ``hbayes calibrate`` refuses until answered.
The written file is validated by the same schema as any config
(:func:`heritage_bayes.config.parse_config`).

Choices (the measurements behind them: docs/science/inputs.md, "The TRH-1 attics", and
docs/science/models.md, "Figures behind the code's choices"):

* **One solar aperture on the horizontal** (``surfaces: {H: [0, 0]}``), not the four
  facades: the data pin one aperture, where four leave some unidentified. A room that
  looks like an attic gets its roof's two slopes instead (``data.roof``,
  :mod:`heritage_bayes.init_roof`).
* **Periods**: chosen after the clocks, on UTC, in the usable span
  (:func:`~heritage_bayes.init_checks.usable_span`: the overlap of the files, else its
  most recent 12 months, with readings in 70 % of the hours from each file), within its
  most recent stretch run one way (:mod:`~heritage_bayes.init_regimes`: the RH band, the
  heating floor and the summer gain year by year), as
  :func:`~heritage_bayes.init_periods.choose_periods` says; spanning gaps (the calibration splits
  at those over ``data.max_gap``) but never starting or ending in one. While a clock is
  an open question they keep 14 h (the largest offset) inside the span, so that any
  answer keeps them inside the data.
* **Models**: what the data call for (:mod:`heritage_bayes.init_model`): the control
  (thermostat, humidistat band, a constant gain), the vapour sink or the sorbing buffer
  each from a measured signature, two thermal nodes from 60 days of calibration data;
  the evidence is written above the keys.
* **Irradiance stamps**: the reading of the stamps (interval end, instant, interval
  start) under which the sun confirms the declared clock (FMI: values at the stamp).

Example
-------
::

    hbayes init logger.csv --weather fmi.csv --latitude 60.21 --longitude 24.66 \\
        --name attic -o attic/config.yaml
    hbayes calibrate attic/config.yaml
"""

from __future__ import annotations

import datetime as _dt
import os
from dataclasses import dataclass, field
from pathlib import Path

import pandas as pd

from heritage_bayes.errors import DataError, InputError
from heritage_bayes.init_checks import (
    MAX_GAP_H,
    choose_periods,
    clock_step,
    clock_switch,
    extrapolated_seasons,
    heating_floor,
    logger_clock,
    marked,
    present_hours,
    raw_table,
    to_utc,
    usable_span,
    weather_clock,
)
from heritage_bayes.init_columns import fahrenheit_column_check, rh_column_check, usable
from heritage_bayes.init_model import propose_model
from heritage_bayes.init_regimes import regime_stretch
from heritage_bayes.init_roof import attic_evidence, roof_finding, solar_surface_lines
from heritage_bayes.init_sources import source_lines as _source_lines
from heritage_bayes.init_sources import timing_without_sun as _timing_without_sun
from heritage_bayes.io import clock as _clock
from heritage_bayes.io.loggers import TableLayout, inspect_table
from heritage_bayes.questions import MARK
from heritage_bayes.yaml_text import comment as _comment
from heritage_bayes.yaml_text import one_line_each as _one_line_each
from heritage_bayes.yaml_text import wrap_comment as _wrap
from heritage_bayes.yaml_text import yaml_value as _yaml_value

__all__ = ["InitResult", "init_config"]

#: The largest shift an open clock question can bring when answered (UTC+14, UTC-12).
CLOCK_MARGIN = pd.Timedelta(hours=14)

#: Weather formats ``init`` reads besides CSV (by the readers of :mod:`heritage_bayes.io`).
WEATHER_FORMATS = ("csv", "epw", "knmi", "tmy3")


@dataclass
class InitResult:
    """What :func:`init_config` wrote and found.

    ``text``: the YAML written; ``findings``: what was guessed and why (one line each);
    ``questions``: what is left open (key path: question).
    """

    path: Path
    text: str
    findings: list[str] = field(default_factory=list)
    questions: list[str] = field(default_factory=list)


def _doc(path: str) -> list[str]:
    """Comment lines for a key from the schema (:func:`describe_key`), indented as the key."""
    from heritage_bayes.config.reference import describe_key

    pad = "  " * path.count(".") + "# "
    return _wrap(describe_key(path).split(" ", 1)[1], pad, pad)


def _weather_format(path: Path, given: str | None) -> str:
    if given is not None:
        if given not in WEATHER_FORMATS:
            raise InputError(
                f"--weather-format: one of {', '.join(WEATHER_FORMATS)} (got {given!r})"
            )
        return given
    name = path.name.lower()
    if name.endswith(".epw"):
        return "epw"
    if name.startswith("uurgeg") or name.endswith(".txt.gz"):
        return "knmi"
    head = path.read_bytes()[:2000].decode("latin-1")
    if head.startswith("# STN") or "YYYYMMDD" in head[:2000]:
        return "knmi"
    return "csv"


def _clock_kind(zone: str | None) -> str | None:
    """``"fixed"`` for a fixed offset, ``"dst"`` for a zone with rules, None when not
    given or not readable (the reader's own message comes later)."""
    if not zone:
        return None
    from heritage_bayes.io import parse_timezone

    try:
        tz = parse_timezone(zone)
    except (ValueError, TypeError):
        return None
    return "fixed" if isinstance(tz, _dt.timezone) else "dst"


def _read_naive(layout: TableLayout, columns: dict[str, str], units: dict) -> pd.DataFrame:
    """The table on the file's own clock (read as if UTC), for inspection only."""
    from heritage_bayes.io import read_csv

    return read_csv(
        layout.path,
        time_column=layout.time_column,
        columns=columns,
        time_format=None if layout.time_format == "ISO8601" else layout.time_format,
        timezone=None if layout.time_format == "ISO8601" else "UTC",
        sep=layout.sep,
        decimal=layout.decimal,
        skiprows=layout.skiprows,
        encoding=layout.encoding,
        units=units or None,
        averaged=(),
        duplicates="first",
        sort=True,
        invalid="nan",
    )


def _pick(layout: TableLayout, kinds: dict[str, str], findings: list[str], what: str):
    """``{standard: column}`` and ``{standard: unit}`` from the layout's guesses."""
    columns, units = {}, {}
    for std, kind in kinds.items():
        found = layout.all(kind)
        if not found:
            continue
        c = found[0]
        columns[std] = c.name
        if c.unit in ("°F", "K", "fraction"):
            units[std] = c.unit
        also = (
            f" (also {', '.join(repr(x.name) for x in found[1:])}: not used)" if found[1:] else ""
        )
        findings.append(f"{what}: {std} = column {c.name!r}: {c.why}{also}")
    return columns, units


def _dropped_findings(df: pd.DataFrame, where: str, findings: list[str], questions: list[str]):
    dropped = dict(df.attrs.get("dropped") or {})
    if dropped:
        findings.append(f"{where}: the reader dropped or changed {dropped}")
    if dropped.get("sorted"):
        questions.append(
            f"questions: the {where} file's time stamps go backwards {dropped['sorted']} "
            "time(s); `sort: true` below reads its rows sorted by time, right for overlapping "
            "downloads joined in one file, wrong for a logger whose clock was reset (then "
            "fix the file's stamps); check which, then delete this question"
        )
    return dropped


def _refuse_data_folder(output: Path, inputs: dict[str, Path]) -> None:
    """InputError when ``output`` lies in (or below) the folder of an input file."""
    for opt, p in inputs.items():
        folder = p.resolve().parent
        if output.parent == folder or folder in output.parents:
            raise InputError(
                f"--output: {output} is in the folder of {opt} ({folder}); init writes no "
                "file among the data it reads. Give a path in a project folder of its own "
                "(e.g. --output rooms/<name>/config.yaml; the config refers to the data by "
                "relative paths), or add --in-data-folder to write it there anyway"
            )


def _operation(ti_utc, te_utc, rhi_utc, rhe_utc, s, e, span, findings):
    """The most recent stretch of ``[s, e]`` over which the room was run one way, and its
    heating floor.

    Returns
    -------
    s, e : pandas.Timestamp
        The stretch [UTC] (the whole overlap when the operation did not change).
    span : str
        Its description for the periods' comment.
    regime_why : str
        The per-year evidence of a change (empty when none), appended to that comment.
    floor : tuple
        ``(floor [°C], held days, days)`` of :func:`heating_floor` over the stretch (the
        whole overlap when the operation did not change).
    """
    rs, re_, regime_notes = regime_stretch(ti_utc, te_utc, rhi_utc, rhe_utc, s, e)
    findings += [f"operation: {n}" for n in regime_notes]
    regime_why = ""
    if (rs, re_) != (s, e) or len(regime_notes) > 1:  # a change: its evidence by the periods
        regime_why = ". " + ". ".join(n[0].upper() + n[1:] for n in regime_notes[::-1])
    floor_ti, floor_te = ti_utc, te_utc  # the floor over the whole overlap, or the stretch
    if (rs, re_) != (s, e):
        s, e = rs, re_
        span = f"the stretch run one way ({s:%Y-%m-%d} to {e:%Y-%m-%d})"
        floor_ti, floor_te = ti_utc[s:e], te_utc[s:e]
    floor, held, ndays = heating_floor(floor_ti, floor_te)
    heated = held >= max(20, 0.05 * ndays)
    findings.append(
        f"control: the indoor daily minimum sat at {floor:.1f} °C (within 0.5 K) on {held} of "
        f"{ndays} days while the outdoor air averaged 5 K colder"
        + (": heated (a thermostat's floor)" if heated else ": free-running")
    )
    return s, e, span, regime_why, (floor, held, ndays)


def init_config(
    indoor,
    weather,
    *,
    output,
    weather_format: str | None = None,
    latitude: float | None = None,
    longitude: float | None = None,
    name: str | None = None,
    timezone: str | None = None,
    weather_timezone: str | None = None,
    force: bool = False,
    in_data_folder: bool = False,
) -> InitResult:
    """Inspect a logger file and a weather file; write a commented configuration.

    Parameters
    ----------
    indoor : path-like
        The logger export (indoor T and RH): generic CSV/TSV (any header, decimal comma)
        or a HOBO, Hanwell, Meaco, Tinytag or Rotronic export
        (:mod:`heritage_bayes.io.loggers`).
    weather : path-like
        The weather file: CSV (outdoor T, RH, measured irradiance when available), EPW,
        KNMI hourly or TMY3.
    output : path-like
        The configuration to write; paths in it are relative to its folder.
    weather_format : {"csv", "epw", "knmi", "tmy3"}, optional
        Default: from the file name and first line.
    latitude, longitude : float, optional
        The site [° north, ° east]; needed for the sun (irradiance on the facades) and
        to measure the files' clocks. EPW and TMY3 files carry their own.
    name : str, optional
        Run name (default: the output file's stem, or its folder's name for
        ``config.yaml``).
    timezone, weather_timezone : str, optional
        The clocks of the logger and weather files when their headers do not name them
        (``UTC+1``, ``Europe/Amsterdam``): checked against the data either way.
    force : bool
        Replace an existing ``output``.
    in_data_folder : bool
        Allow ``output`` in the folder of the logger or the weather file (or below it).
        Off by default: data folders are often archives of raw measurements, shared or
        read-only, where a derived file does not belong (and a test once wrote there).

    Returns
    -------
    InitResult

    Raises
    ------
    heritage_bayes.errors.InputError
        ``output`` exists (without ``force``), lies in a data folder (without
        ``in_data_folder``), a file cannot be read as a table, no
        indoor temperature column, no overlap of the two files.
    """
    from heritage_bayes.rundir.policy import (
        check_name,
        check_new_file,
        resolve_output,
        write_new_file,
    )

    name_given = name is not None

    indoor, weather = Path(indoor), Path(weather)
    for p, opt in ((indoor, "INDOOR_FILE"), (weather, "--weather")):
        if not p.is_file():
            raise DataError(f"{opt}: {p}: " + ("is a folder" if p.is_dir() else "file not found"))
    output = resolve_output(output, what="--output", kind="file", protect=(indoor, weather))
    if not in_data_folder:
        _refuse_data_folder(output, {"INDOOR_FILE": indoor, "--weather": weather})
    check_new_file(output, force=force, what="--output")  # before the inspection
    findings: list[str] = []
    questions: list[str] = []
    base = output.parent  # resolved; a link at the file's own name is not followed

    def rel(p: Path) -> str:
        return Path(os.path.relpath(p.resolve(), base)).as_posix()

    # -- the logger --------------------------------------------------------------------------
    lay = inspect_table(indoor, what="logger file")
    findings.append(
        f"logger: {lay.layout} layout, separator {lay.sep!r}, decimal {lay.decimal!r}, time "
        f"column {lay.time_column!r} as {lay.time_format!r}"
        + (f", clock {lay.timezone} (named in the header)" if lay.timezone else "")
    )
    findings += [f"logger: {n}" for n in lay.notes]
    icols, iunits = _pick(lay, {"Ti": "T", "RHi": "RH"}, findings, "logger")
    if "Ti" not in icols:
        raise DataError(
            f"{indoor.name}: no indoor temperature column found; columns: "
            + "; ".join(f"{c.name!r} ({c.why})" for c in lay.columns)
        )
    rh_column_check(lay, icols, "RHi", findings, questions, "data.measurements")
    din = _read_naive(lay, usable(icols), usable(iunits))
    step = clock_step(din.index)
    findings.append(
        f"logger: {len(din)} rows, step {step}, {din.index[0]:%Y-%m-%d} to "
        f"{din.index[-1]:%Y-%m-%d} (file clock)"
    )

    # -- the weather -------------------------------------------------------------------------
    wfmt = _weather_format(weather, weather_format)
    lat, lon = latitude, longitude
    wlay = None
    wlabel = "end"
    wzone = weather_timezone
    if wfmt == "csv":
        wlay = inspect_table(weather, what="weather file")
        findings.append(
            f"weather: {wlay.layout} layout, time column {wlay.time_column!r} as "
            f"{wlay.time_format!r}"
            + (f", clock {wlay.timezone} (named in the header)" if wlay.timezone else "")
        )
        wcols, wunits = _pick(
            wlay,
            {"Te": "T", "RHe": "RH", "ghi": "ghi", "dhi": "dhi", "dni": "dni", "wind": "wind"},
            findings,
            "weather",
        )
        if "Te" not in wcols:
            raise DataError(
                f"{weather.name}: no outdoor temperature column found (columns {wlay.header})"
            )
        rh_column_check(wlay, wcols, "RHe", findings, questions, "data.weather")
        dw = _read_naive(wlay, usable(wcols), usable(wunits))
        wdropped = _dropped_findings(dw, "weather", findings, questions)
        declared = weather_timezone or wlay.timezone
        if wlay.time_format == "ISO8601":  # stamps with their UTC offset: the clock is known
            wzone, wq = None, None
            findings.append("weather: time stamps carry their UTC offset")
        else:
            wzone, wlabel, wq = weather_clock(
                dw, lon, declared, findings, "weather", lat=lat, layout=wlay
            )
        if wq:
            wzone = marked(wq)
            questions.append(f"data.weather.timezone: {wq}")
        te_utc = to_utc(dw["Te"], wzone)
        irr = "measured" if {"ghi"} <= set(wcols) or {"ghi", "dhi"} & set(wcols) else None
        if irr is None:
            wlabel = _timing_without_sun(wlay, findings)
    else:
        from heritage_bayes.io import read_epw, read_knmi_hourly, read_tmy3

        reader = {"epw": read_epw, "knmi": read_knmi_hourly, "tmy3": read_tmy3}[wfmt]
        dw = reader(weather)
        te_utc = dw["Te"]
        site = dw.attrs.get("site") or {}
        lat = lat if lat is not None else site.get("latitude")
        lon = lon if lon is not None else site.get("longitude")
        irr = "measured" if {"ghi", "dhi", "dni"} & set(dw.columns) else None
        findings.append(f"weather: {wfmt} file, {len(dw)} rows, columns {list(dw.columns)}")
        if lon is not None and "ghi" in dw:
            est = _clock.solar_clock_offset(dw.index, dw["ghi"], lon)
            findings.append(f"weather: clock check (the reader's UTC): {est.describe()}")

    # -- the unit of an unlabelled indoor temperature: the outdoor file tells ---------------
    if fahrenheit_column_check(lay, icols, iunits, te_utc, findings, questions):
        din = _read_naive(lay, usable(icols), usable(iunits))
    idropped = _dropped_findings(din, "logger", findings, questions)

    # -- the logger's clock (after the weather's) -----------------------------------------------
    if lay.time_format == "ISO8601":  # stamps with their UTC offset: the clock is known
        izone = None
        findings.append("logger: time stamps carry their UTC offset")
    else:
        declared = timezone or lay.timezone
        switch = clock_switch(raw_table(lay).index, lat, lon, _clock_kind(declared))
        if switch is not None:  # the clock changed within the file: one part is kept
            findings.append(f"logger: {switch.why}")
            din = switch.keep(din)
            declared = declared or switch.zone
        izone = logger_clock(lay, din, declared, lon, findings, "logger", lat)
    if izone and izone.startswith(MARK):
        questions.append(f"data.measurements.timezone: {izone[len(MARK) :].strip()}")
    ti_utc = to_utc(din["Ti"], izone)

    # -- site, periods, models ------------------------------------------------------------------
    if lat is None or lon is None:
        site_value = marked(
            "the site: {latitude: DEG north, longitude: DEG east}; give --latitude, --longitude"
        )
        questions.append("site: the site's latitude and longitude (the sun on the facades)")
    else:
        site_value = {
            "latitude": round(float(lat), 4),
            "longitude": round(float(lon), 4),
            "altitude": 0,
        }
    try:
        s, e, span, gap_notes = usable_span(ti_utc, te_utc)
    except DataError as exc:
        typical = (
            " (a typical year cannot calibrate a room: use the weather measured over "
            "the logger's period)"
            if wfmt in ("epw", "tmy3")
            else ""
        )
        raise DataError(f"{indoor.name}, {weather.name}: {exc}{typical}") from None
    findings.append(f"overlap: {span}: {s:%Y-%m-%d %H:%M} to {e:%Y-%m-%d %H:%M} UTC")
    findings += [f"overlap: {g}" for g in gap_notes]
    # an RH column that needs an answer keeps the hygric section: answered, it runs
    rhe_open = wlay is not None and str(wcols.get("RHe", "")).startswith(MARK)
    hygric = "RHi" in icols and ("RHe" in dw.columns or rhe_open)
    rhi_utc = to_utc(din["RHi"], izone) if "RHi" in din else None
    rhe_utc = (to_utc(dw["RHe"], wzone) if wlay is not None else dw["RHe"]) if "RHe" in dw else None
    s, e, span, regime_why, (floor, held, ndays) = _operation(
        ti_utc, te_utc, rhi_utc if hygric else None, rhe_utc, s, e, span, findings
    )
    if any(z and str(z).startswith(MARK) for z in (izone, wzone)):
        # an open clock moves the data by up to 14 h when answered: periods chosen on the
        # file's clock keep that far inside the stretch, so any answer keeps them inside
        s, e = s + CLOCK_MARGIN, e - CLOCK_MARGIN
        findings.append(
            "periods: a clock is still an open question: the periods keep "
            f"{CLOCK_MARGIN / pd.Timedelta(hours=1):.0f} h inside the stretch on the files' "
            "own clocks, so that any answer keeps them inside the data; after answering, "
            "`hbayes init` again (--timezone, --weather-timezone) chooses them on UTC"
        )
    # the inputs must hold a reading at both ends of the periods (the outputs need not)
    cs, ce, vs, ve, why = choose_periods(s, e, present_hours(te_utc, te_utc), span)
    findings.append(f"periods: {why}")
    why += regime_why
    if season := extrapolated_seasons(te_utc, cs, ce, ve):
        findings.append(f"periods: {season}")
        why = f"{why}. Note: {season}"
    prop = propose_model(
        ti_utc,
        te_utc,
        rhi_utc if hygric else None,
        rhe_utc,
        start=cs,
        mid=ce,
        end=ve,
        heated=(floor, held, ndays),
    )
    findings += [f"model: {x}" for x in prop.thermal_evidence + prop.hygric_evidence]
    name = name or (output.parent.name if output.stem == "config" else output.stem) or "room"
    check_name(name, what="--name" if name_given else "name (from --output)")

    # a solar input: the surfaces it falls on; an estimate only where the room shows a sun
    sunlit = irr == "measured" or (lat is not None and prop.daily_sun is not False)
    attic = attic_evidence((indoor.stem, name), ti_utc[cs:ve], te_utc[cs:ve]) if sunlit else None
    findings += [roof_finding(attic)] if attic else []
    lines = [
        f"# Written by `hbayes init` on {_dt.date.today():%Y-%m-%d} from",
        f"#   logger:  {_comment(rel(indoor))}",
        f"#   weather: {_comment(rel(weather))}",
        "# What init found, and why (check each):",
        *[
            line
            for f in findings
            if not f.startswith("model: ")  # written above the keys they propose
            for line in _wrap(f, "#   - ", "#     ")
        ],
        "# Values starting with '??' are open questions: `hbayes calibrate` refuses this file",
        "# until each is answered. Dates are UTC; paths are relative to this file.",
        "",
        f"name: {_yaml_value(name)}",
        'building: ""',
        'room: ""',
        "seed: 1",
        "",
        f"site: {_yaml_value(site_value)}",
        "",
        "data:",
    ]
    if wlay is not None:
        lines += _source_lines(
            "weather", wlay, rel(weather), wzone, wcols, wunits, wlabel, wdropped
        )
    else:
        lines += ["  weather:", f"    format: {wfmt}", f"    path: {_yaml_value(rel(weather))}"]
    lines += _source_lines("measurements", lay, rel(indoor), izone, icols, iunits, None, idropped)
    if sunlit:
        lines += [
            "  irradiance: measured"
            if irr == "measured"
            else "  irradiance: estimated   # no measured irradiance: from the daily Te range",
            *solar_surface_lines(attic),
        ]
    else:
        no_sun = lat is not None and prop.daily_sun is False
        lines += [
            "  irradiance: none"
            + ("   # no measured irradiance, and no daily sun in the room" if no_sun else "")
        ]
    lines += [*_doc("data.step"), "  step: 1h", *_doc("data.max_gap"), f"  max_gap: {MAX_GAP_H}h"]
    lines += [*_doc("data.input_hold"), "  input_hold: exact"]
    lines += ["", "periods:", *_wrap(why, "  # ", "  # ")]
    lines += [
        f"  calibration: {{start: {cs}, end: {ce}}}",
        f"  validation: {{start: {vs}, end: {ve}}}",
        "",
        "# The model the data call for (what init measured over the periods):",
        *[x for f in prop.thermal_evidence for x in _wrap(f, "#   - ", "#     ")],
        "# Tf, the fixed node, is the outdoor annual cycle 1 m deep in the soil (the ground",
        "# under the floor). A room without a floor on the ground (an attic, an upper storey): set",
        "# options: {ground: false}, or give the neighbouring space's measured temperature",
        "# (data.ground_temperature: {mode: column, column: ..., source: {...}}).",
        "thermal:",
        f"  model: {prop.thermal_model}",
        *([f"  options: {_yaml_value(prop.thermal_options)}"] if prop.thermal_options else []),
    ]
    if hygric:
        lines += ["", *[x for f in prop.hygric_evidence for x in _wrap(f, "#   - ", "#     ")]]
        lines += ["hygric:", f"  model: {prop.hygric_model}"]
        if prop.hygric_options:
            lines.append(f"  options: {_yaml_value(prop.hygric_options)}")
    lines += ["", "sampler:", *_doc("sampler.max_time"), "  max_time: 30min", ""]
    extra = [q.split(": ", 1)[1] for q in questions if q.startswith("questions: ")]
    if extra:
        lines += ["questions:", *[f"  - {_yaml_value(MARK + ' ' + q)}" for q in extra], ""]
    text = _one_line_each(lines)
    if not questions:  # the same schema as every config: it must load
        from heritage_bayes.config import load_yaml_text, parse_config

        raw = load_yaml_text(text, source=str(output))
        parse_config(raw, source=str(output), base_dir=str(base), name=name)
    if output.is_symlink():  # with --force: the link itself is replaced, not its target
        findings.append(
            f"--output {output} was a symbolic link (to {os.readlink(output)}): the link is "
            "replaced by the config; the file it pointed to is left as it is"
        )
    write_new_file(output, text, force=force, what="--output")
    return InitResult(output, text, findings, questions)
