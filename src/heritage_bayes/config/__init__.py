"""Settings: the validated YAML configuration of ``hbayes calibrate``, parsed once.

The CLI and the Python API turn a YAML file into typed settings here and nowhere else:
durations become :class:`pandas.Timedelta` (a duration needs its unit: ``10min``, ``2h``,
``14d``; a bare number is refused with the units suggested), clocks become tzinfo
objects, data paths resolve against the config's folder (:meth:`CalibrationConfig.path`).
Code below this boundary receives those values and never parses a string.

Unknown keys are refused with the nearest known key; every error names the key path,
the expected form and the value found, e.g. ``priors.Gw.lower: must be < upper (got 500
> 200)``. Every key carries a description, unit and default in the schema
(:func:`config_keys`: the source of the generated configuration reference).

Modules, by topic: :mod:`~heritage_bayes.config.sources` (``site``, the tables),
:mod:`~heritage_bayes.config.data` (``data``: solar input, ground, grid),
:mod:`~heritage_bayes.config.periods`, :mod:`~heritage_bayes.config.models` (one
calibrated model: noise, initial state), :mod:`~heritage_bayes.config.options`
(its options: the network's, and the thermostat, humidistat and source, typed),
:mod:`~heritage_bayes.config.priors` (a parameter's prior or fixed value),
:mod:`~heritage_bayes.config.sampler` (``sampler``, ``optimizer``),
:mod:`~heritage_bayes.config.calibration` (the top level, outputs, :func:`load_config`),
:mod:`~heritage_bayes.config.loader` (strict YAML), :mod:`~heritage_bayes.config.reference`
(the schema as data).

Layout (see ``configs/demo.yaml`` for a complete, commented example)::

    name: my_room                  # run name; default: the config file's stem
    building: Castle X             # free text, shown in the report (escaped)
    room: Great hall
    notes: ...
    seed: 1
    site: {latitude: 52.1, longitude: 5.18, altitude: 2}
    room_volume: 800               # [m³], optional: log-normal prior on each model's Ci
    floor_area: 160                # [m²] on the ground, optional: log-normal prior on Gf
    envelope_area: 420             # [m²] walls + roof outside, optional: bounds Gw, Cw
    interior_area: 300             # [m²] floor, inner walls, contents: prior on Gint (4a)
    glazing_area: {S: 12, E: 4}    # [m²] of windows per surface, optional: priors on fI
    data:
      demo: {seed: 7, gap: [2019-03-10, 2019-03-17]}   # the built-in virtual monument
                                   # (heritage_bayes.demo), or real files:
      weather: {format: knmi, path: ../shared/data/knmi-debilt/uurgeg_260_2011-2020.txt.gz}
      measurements: {format: csv, path: logger.csv, time_column: ..., timezone: ...,
                     columns: {Ti: "TEMP C", RHi: "%RH"}}   # or a list of such tables
      irradiance: measured         # measured | estimated | clear_sky | none (default:
                                   # measured if the weather has it, else estimated)
      surfaces: {N: [90, 0], E: [90, 90], S: [90, 180], W: [90, 270]}  # (tilt, azimuth)
      roof: {pitch: 45, ridge_azimuth: 90, area: 220}   # an attic: its two slopes
                        # roof_N, roof_S as surfaces (in place of the facades if
                        # 'surfaces' is not given); area [m²]: prior on their fI
      ground_temperature: {mode: seasonal, depth: 1}   # or {mode: annual_mean},
                        # {mode: constant, value: 10},
                        # {mode: column, column: T, source: {format: csv, path: ...}}
      step: 1h
      max_gap: 6h
    periods:                       # dates: UTC unless they carry an offset
      calibration: {start: 2019-01-01, end: 2019-07-01}   # [start, end)
      validation: {start: 2019-07-01, end: 2020-01-01}
      warmup: 14d                  # durations carry a unit: 1h, 30min, 14d
    thermal: {model: thermal_4a, noise: ar1, priors: {Gf: {fixed: 0}}}
    hygric: {model: hygric_2c_fixed, noise: ar1}
    sampler: {max_time: 30min}     # wall-time budget of the run; the chain decides
    optimizer: {method: differential_evolution}
"""

from __future__ import annotations

from heritage_bayes.config._base import MAX_SEED, DateText, Duration, TimeZone, _Strict, key
from heritage_bayes.config._messages import format_error as _format_error
from heritage_bayes.config._messages import nearest_key
from heritage_bayes.config.calibration import (
    CalibrationConfig,
    chain_tag,
    config_hash,
    load_config,
    parse_config,
)
from heritage_bayes.config.data import Data, GroundTemperature
from heritage_bayes.config.loader import load_yaml_text, read_yaml
from heritage_bayes.config.models import ModelSection
from heritage_bayes.config.periods import Period, Periods
from heritage_bayes.config.priors import PriorSpec, prior_specs
from heritage_bayes.config.reference import ConfigKey, config_keys, describe_key
from heritage_bayes.config.sampler import OptimizerSettings, SamplerSettings
from heritage_bayes.config.sources import DemoData, Site, Source
from heritage_bayes.convert import parse_duration

__all__ = [
    "MAX_SEED",
    "CalibrationConfig",
    "ConfigKey",
    "Data",
    "DateText",
    "DemoData",
    "Duration",
    "GroundTemperature",
    "ModelSection",
    "OptimizerSettings",
    "Period",
    "Periods",
    "PriorSpec",
    "SamplerSettings",
    "Site",
    "Source",
    "TimeZone",
    "_Strict",
    "_format_error",
    "chain_tag",
    "config_hash",
    "config_keys",
    "describe_key",
    "key",
    "load_config",
    "load_yaml_text",
    "nearest_key",
    "parse_config",
    "parse_duration",
    "prior_specs",
    "read_yaml",
]
