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
(:func:`heritage_bayes.config.parse_config`). The inspection runs in named steps
(:mod:`heritage_bayes.init_steps`): the logger, the weather, the logger's clock, the periods.

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
  :func:`~heritage_bayes.init_periods.choose_periods` says (a record shorter than a
  year validates on its middle or first third where only then the calibration covers
  the validation's outdoor conditions); spanning gaps (the calibration splits
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
from heritage_bayes.init_checks import MAX_GAP_H
from heritage_bayes.init_model import propose_model
from heritage_bayes.init_roof import attic_evidence, roof_finding, solar_surface_lines
from heritage_bayes.init_sources import source_lines as _source_lines
from heritage_bayes.init_steps import (
    choose_span,
    inspect_logger,
    inspect_weather,
    settle_logger,
    site_value,
)
from heritage_bayes.questions import MARK
from heritage_bayes.yaml_text import comment as _comment
from heritage_bayes.yaml_text import one_line_each as _one_line_each
from heritage_bayes.yaml_text import wrap_comment as _wrap
from heritage_bayes.yaml_text import yaml_value as _yaml_value

__all__ = ["InitResult", "init_config"]


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

    log = inspect_logger(indoor, findings, questions)
    wx = inspect_weather(
        weather, weather_format, weather_timezone, latitude, longitude, findings, questions
    )
    settle_logger(log, wx, timezone, findings, questions)
    site = site_value(wx.latitude, wx.longitude, questions)
    per = choose_span(log, wx, indoor, weather, findings)
    prop = propose_model(
        log.ti_utc,
        wx.te_utc,
        per.rhi_utc if per.hygric else None,
        per.rhe_utc,
        start=per.span[0],
        mid=pd.Timestamp(per.span[0]) + per.calibration_length,
        end=per.span[1],
        heated=per.floor,
    )
    findings += [f"model: {x}" for x in prop.thermal_evidence + prop.hygric_evidence]
    name = name or (output.parent.name if output.stem == "config" else output.stem) or "room"
    check_name(name, what="--name" if name_given else "name (from --output)")

    # a solar input: the surfaces it falls on; an estimate only where the room shows a sun
    sunlit = wx.irradiance == "measured" or (
        wx.latitude is not None and prop.daily_sun is not False
    )
    attic = (
        attic_evidence(
            (indoor.stem, name), log.ti_utc[slice(*per.span)], wx.te_utc[slice(*per.span)]
        )
        if sunlit
        else None
    )
    findings += [roof_finding(attic)] if attic else []
    text = _config_text(
        output, indoor, weather, name, site, log, wx, per, prop, sunlit, attic, findings, questions
    )
    if not questions:  # the same schema as every config: it must load
        from heritage_bayes.config import load_yaml_text, parse_config

        raw = load_yaml_text(text, source=str(output))
        parse_config(raw, source=str(output), base_dir=str(output.parent), name=name)
    if output.is_symlink():  # with --force: the link itself is replaced, not its target
        findings.append(
            f"--output {output} was a symbolic link (to {os.readlink(output)}): the link is "
            "replaced by the config; the file it pointed to is left as it is"
        )
    write_new_file(output, text, force=force, what="--output")
    return InitResult(output, text, findings, questions)


def _config_text(
    output, indoor, weather, name, site, log, wx, per, prop, sunlit, attic, findings, questions
) -> str:
    """The commented YAML: what init found, then the keys (one line each)."""
    base = output.parent  # resolved; a link at the file's own name is not followed

    def rel(p: Path) -> str:
        return Path(os.path.relpath(p.resolve(), base)).as_posix()

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
        f"site: {_yaml_value(site)}",
        "",
        "data:",
    ]
    if wx.layout is not None:
        lines += _source_lines(
            "weather", wx.layout, rel(weather), wx.zone, wx.columns, wx.units, wx.label, wx.dropped
        )
    else:
        lines += ["  weather:", f"    format: {wx.fmt}", f"    path: {_yaml_value(rel(weather))}"]
    lines += _source_lines(
        "measurements", log.layout, rel(indoor), log.zone, log.columns, log.units, None, log.dropped
    )
    if sunlit:
        lines += [
            "  irradiance: measured"
            if wx.irradiance == "measured"
            else "  irradiance: estimated   # no measured irradiance: from the daily Te range",
            *solar_surface_lines(attic),
        ]
    else:
        no_sun = wx.latitude is not None and prop.daily_sun is False
        lines += [
            "  irradiance: none"
            + ("   # no measured irradiance, and no daily sun in the room" if no_sun else "")
        ]
    lines += [*_doc("data.step"), "  step: 1h", *_doc("data.max_gap"), f"  max_gap: {MAX_GAP_H}h"]
    lines += [*_doc("data.input_hold"), "  input_hold: exact"]
    if attic:  # no floor on the soil: no soil depth to estimate
        lines += [
            "  # an attic has no floor on the soil: its ground node Tf stands in for the",
            "  # storey below, so Tf stays the outdoor annual cycle at a fixed 1 m",
            "  ground_temperature: {mode: seasonal, depth: 1}",
        ]
    lines += ["", "periods:", *_wrap(per.why, "  # ", "  # ")]
    lines += [
        f"  calibration: {{start: {per.cs}, end: {per.ce}}}",
        f"  validation: {{start: {per.vs}, end: {per.ve}}}",
        "",
        "# The model the data call for (what init measured over the periods):",
        *[x for f in prop.thermal_evidence for x in _wrap(f, "#   - ", "#     ")],
        "# Tf, the fixed node, is the outdoor annual cycle in the soil under the floor, damped",
        "# and delayed at a depth zf [m] the calibration estimates (Kusuda-Achenbach; a fixed",
        "# depth: data.ground_temperature: {mode: seasonal, depth: ...}; an attic: 1 m). A",
        "# room without a floor on the ground (an attic, an upper storey): set",
        "# options: {ground: false}, or give the neighbouring space's measured temperature",
        "# (data.ground_temperature: {mode: column, column: ..., source: {...}}).",
        "thermal:",
        f"  model: {prop.thermal_model}",
        *([f"  options: {_yaml_value(prop.thermal_options)}"] if prop.thermal_options else []),
        *([f"  priors: {_yaml_value(prop.thermal_priors)}"] if prop.thermal_priors else []),
    ]
    if per.hygric:
        lines += ["", *[x for f in prop.hygric_evidence for x in _wrap(f, "#   - ", "#     ")]]
        lines += ["hygric:", f"  model: {prop.hygric_model}"]
        if prop.hygric_options:
            lines.append(f"  options: {_yaml_value(prop.hygric_options)}")
    lines += ["", "sampler:", *_doc("sampler.max_time"), "  max_time: 30min", ""]
    extra = [q.split(": ", 1)[1] for q in questions if q.startswith("questions: ")]
    if extra:
        lines += ["questions:", *[f"  - {_yaml_value(MARK + ' ' + q)}" for q in extra], ""]
    return _one_line_each(lines)
