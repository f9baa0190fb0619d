"""Baseline and future weather of a projection, and the model inputs built from them.

The baseline is the calibration's own weather (the demo's TMY3 file, or the configured
``data.weather``) unless the projection file gives ``baseline``. Every future is a
documented transformation of it (:mod:`heritage_bayes.climate.morph`) or a user file.
Model inputs are built exactly as for the calibration
(:func:`heritage_bayes.inputs.weather_inputs`, :func:`heritage_bayes.io.align`,
:func:`heritage_bayes.inputs.ground_input`): same surfaces, irradiance mode,
grid step and ground-temperature rule, so the building is the calibrated one and only
the weather changes.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np
import pandas as pd

from heritage_bayes.climate.risk._inputs import MIN_YEAR_HOURS
from heritage_bayes.climate.risk.registry import complete_year_hours
from heritage_bayes.errors import ConfigError, DataError, InputError

#: Largest distance between the calibration site and the site of a baseline or future
#: weather file, unless the projection file says ``allow_other_site: true``. [km]
#: 50 km: about the spacing of the KNMI synoptic stations and the size of a KNMI'14
#: region; a station further away has another climate (coast, altitude).
MAX_SITE_DISTANCE_KM = 50.0
_EARTH_RADIUS_KM = 6371.0

_WEATHER_COLUMNS = ("Te", "RHe", "Pe", "ghi", "dni", "dhi", "Tdew", "Ph", "wind", "precip")


@dataclass
class Case:
    """One weather to simulate: the baseline or a (scenario, horizon) future."""

    scenario: str
    horizon: int | None
    weather: pd.DataFrame
    note: dict = field(default_factory=dict)
    inputs: pd.DataFrame | None = None

    @property
    def label(self) -> str:
        return self.scenario if self.horizon is None else f"{self.scenario} {self.horizon}"


def _site_of(run, weather: pd.DataFrame) -> dict | None:
    if run.config.site is not None:
        return run.config.site.model_dump()
    site = weather.attrs.get("site")
    return dict(site) if site else None


def baseline_weather(run, pcfg) -> tuple[pd.DataFrame, dict | None, dict]:
    """The hourly baseline weather table, the site and a provenance note."""
    from heritage_bayes.sources import INPUT_COLUMNS, read_source

    if pcfg.baseline is not None:
        weather = read_source(pcfg, pcfg.baseline, "baseline", INPUT_COLUMNS)
        note = {"from": "projection file (baseline)", "path": weather.attrs.get("source")}
        site = _calibration_site(run)
        check_same_site(weather.attrs.get("site"), site, "baseline", pcfg.allow_other_site)
        if site is None:
            site = weather.attrs.get("site")
    else:  # the calibration's own weather source (a file, or the demo's generator)
        from heritage_bayes.sources import read_sources

        raw = read_sources(run.config)
        weather, site = raw.weather, (dict(raw.site) if raw.site else None)
        note = {"from": "the calibration's weather"} | dict(raw.notes.get("weather", {}))
    _check_year(weather, "baseline")
    note["first"] = str(weather.index[0])
    note["last"] = str(weather.index[-1])
    note["hours"] = len(weather)
    return weather, site, note


def _check_year(weather: pd.DataFrame, where: str) -> None:
    n = len(weather)
    span_h = (weather.index[-1] - weather.index[0]) / pd.Timedelta(hours=1) + 1 if n else 0
    if span_h < MIN_YEAR_HOURS:
        raise DataError(
            f"{where}: the weather covers {span_h:.0f} h ({weather.index[0]} to "
            f"{weather.index[-1]}); a projection needs at least a year "
            f"({MIN_YEAR_HOURS} h, a year less a day) for the yearly risk indicators"
        )


def futures(run, pcfg, base: pd.DataFrame, site: dict | None) -> list[Case]:
    """Every (scenario, horizon) weather of the projection file, in order."""
    from heritage_bayes.climate.morph import (
        knmi14_region,
        knmi14_transform,
        morph,
        read_monthly_deltas,
    )

    cases: list[Case] = []
    lat = (site or {}).get("latitude")
    if pcfg.knmi14 is not None:
        k = pcfg.knmi14
        folder = pcfg.path(k.tables)
        if not folder.is_dir():
            raise DataError(f"knmi14.tables: {folder}: folder not found")
        region = k.region
        if region is None:
            station = base.attrs.get("station")
            if not isinstance(station, int | np.integer):
                raise ConfigError(
                    "knmi14.region: required (the baseline weather is not a KNMI station "
                    "file, so its region is unknown); one of NWN, ZWN, NON, MON, ZON, NZK"
                )
            region = knmi14_region(folder, int(station))
        for h in k.horizons:
            for s in k.scenarios:
                w = knmi14_transform(
                    base, folder, s, int(h), region=region, latitude=lat,
                    humidity=pcfg.humidity, where="knmi14",
                )  # fmt: skip
                cases.append(Case(s, int(h), w, dict(w.attrs["transformation"])))
    for i, m in enumerate(pcfg.morphing):
        where = f"morphing[{i}]"
        src = m.deltas if isinstance(m.deltas, dict) else pcfg.path(m.deltas)
        deltas = read_monthly_deltas(src, f"{where}.deltas")
        w = morph(base, deltas, method=m.method, humidity=pcfg.humidity, where=where)
        cases.append(Case(m.scenario, m.horizon, w, dict(w.attrs["transformation"])))
    for i, f in enumerate(pcfg.files):
        from heritage_bayes.sources import INPUT_COLUMNS, read_source

        where = f"files[{i}].weather"
        w = read_source(pcfg, f.weather, where, INPUT_COLUMNS)
        _check_year(w, where)
        check_same_site(w.attrs.get("site"), site, where, pcfg.allow_other_site)
        note = {"method": "user-supplied future weather file", "path": w.attrs.get("source")}
        cases.append(Case(f.scenario, f.horizon, w, note))
    return cases


def _calibration_site(run) -> dict | None:
    """The site of the calibration: the config's ``site`` or that of its weather file."""
    if run.config.site is not None:
        return run.config.site.model_dump()
    from heritage_bayes.sources import read_sources

    site = read_sources(run.config).site
    return dict(site) if site else None


def site_distance_km(a: dict, b: dict) -> float:
    """Great-circle distance between two sites (``latitude``, ``longitude`` [°]). [km]

    Haversine formula on a sphere of radius 6371 km.
    """
    p1, p2 = np.radians(float(a["latitude"])), np.radians(float(b["latitude"]))
    dl = np.radians(float(b["longitude"]) - float(a["longitude"]))
    h = np.sin((p2 - p1) / 2) ** 2 + np.cos(p1) * np.cos(p2) * np.sin(dl / 2) ** 2
    return float(2 * _EARTH_RADIUS_KM * np.arcsin(np.sqrt(min(1.0, h))))


def check_same_site(other: dict | None, site: dict | None, where: str, allow: bool) -> None:
    """Refuse weather of a site more than :data:`MAX_SITE_DISTANCE_KM` from the
    calibration's, unless ``allow`` (``allow_other_site: true``).

    Raises
    ------
    heritage_bayes.errors.InputError
        Naming ``where``, both sites and the distance.
    """
    if not other or not site or allow:
        return
    d = site_distance_km(other, site)
    if d > MAX_SITE_DISTANCE_KM:
        raise InputError(
            f"{where}: the file is for another site ({float(other['latitude']):.2f}°N, "
            f"{float(other['longitude']):.2f}°E), {d:.0f} km from where the room was "
            f"calibrated ({float(site['latitude']):.2f}°N, {float(site['longitude']):.2f}°E); "
            f"expected within {MAX_SITE_DISTANCE_KM:g} km. If this weather does stand for "
            "the room's climate, say so with 'allow_other_site: true' in the projection file"
        )


def model_inputs(run, pcfg, weather: pd.DataFrame, site: dict | None, where: str) -> pd.DataFrame:
    """Model inputs on the run's grid from a weather table (as for the calibration).

    Returns a frame with every input column of the run's models (``Te``, ``I_<surface>``,
    ``Tf``, ``Pe``, ...), regular UTC index, cut to the complete years of the weather
    (:func:`~heritage_bayes.climate.risk.registry.complete_year_hours`;
    ``frame.attrs["hours_dropped"]`` counts the hours after the last complete year).
    """
    from heritage_bayes.inputs import (
        add_slope_columns,
        calendar_inputs,
        ground_cycle_inputs,
        ground_input,
        weather_inputs,
    )
    from heritage_bayes.io import align
    from heritage_bayes.prepare import _extra_inputs
    from heritage_bayes.rc.catalog import GROUND_CYCLE_INPUTS

    cfg = run.config
    data = cfg.data
    thermal, hygric = "thermal" in run.models, "hygric" in run.models
    step = data.step
    tables, _ = weather_inputs(
        weather[[c for c in weather.columns if c in _WEATHER_COLUMNS]],
        thermal=thermal,
        hygric=hygric,
        irradiance=data.irradiance,
        site=site,
        surfaces={k: tuple(v) for k, v in data.surfaces.items()},
        where=where,
        extra=_extra_inputs(cfg, list(run.models.values())),
        roof=tuple(data.roof.planes()) if data.roof is not None else (),
    )
    try:
        aligned = align(tables, None, step=step, max_gap=data.max_gap)
    except (DataError, InputError) as exc:
        raise DataError(f"{where}: putting the weather on the run's grid: {exc}") from None
    frame = aligned.frame.copy()
    if thermal or any("Tf" in m.input_names for m in run.models.values()):
        gt = pcfg.ground_temperature or data.ground_temperature
        cycle = any(c in m.input_names for m in run.models.values() for c in GROUND_CYCLE_INPUTS)
        mids = frame.index + step / 2
        if gt.mode == "constant":
            frame["Tf"] = float(gt.value)
        elif gt.mode in ("seasonal", "annual_mean"):
            # with a calibrated depth zf, Tf is the soil at the reference depth (1 m)
            depth = None if cycle else gt.depth
            frame["Tf"], _ = ground_input(gt.mode, weather["Te"], mids, depth)
        else:
            raise ConfigError(
                "ground_temperature: the run measured its ground temperature (mode "
                "'column'), which has no future; give ground_temperature: {mode: "
                "seasonal} or {mode: constant, value: ...} in the projection file"
            )
        # a ground at the calibrated depth zf: the future's own annual cycle (none for a
        # constant or annual-mean ground, which has no cycle at any depth)
        if cycle and gt.mode == "seasonal":
            for name, col in ground_cycle_inputs(weather["Te"], mids)[0].items():
                frame[name] = col
        elif cycle:
            for name in GROUND_CYCLE_INPUTS:
                frame[name] = 0.0
    # inputs the models make from a calendar (a thermostat's weekly hours of use): the
    # calibrated use goes on into the future, on the projection's own dates
    for name, col in calendar_inputs(
        run.models.values(), frame.index, step.total_seconds()
    ).items():
        frame[name] = col
    # the run's hold: an input's change over the step where its model has the
    # first-order hold (readings at an instant), zeros for interval means
    add_slope_columns(frame, run.models.values(), aligned.slopes)
    for section, model in run.models.items():
        simulated = coupled_columns(run, section, where)  # another model's output
        missing = [c for c in model.input_names if c not in frame.columns and c not in simulated]
        if missing:
            raise DataError(
                f"{where}: the {section} model needs {missing}, which this weather does "
                f"not provide (columns {list(weather.columns)})"
            )
    if len(frame) < MIN_YEAR_HOURS:
        raise DataError(
            f"{where}: {len(frame)} rows on the grid; a projection needs at least "
            f"{MIN_YEAR_HOURS} h"
        )
    # the yearly indicators depend on the season covered: complete years only
    n = complete_year_hours(len(frame))
    out = frame.iloc[:n].copy()
    out.attrs["hours_dropped"] = len(frame) - n
    return out


def coupled_columns(run, section: str, where: str = "projection") -> tuple[str, ...]:
    """Input columns of ``section``'s model that a projection takes from another model's
    simulation of the same draw: ``Ti`` of a hygric model whose buffer sorbs at the
    indoor temperature (the thermal model's noise-free ``Ti``).

    Raises
    ------
    DataError
        Such a hygric model in a run without a thermal model: nothing can give the
        future indoor temperature.
    """
    m = run.models.get(section)
    if section != "hygric" or not getattr(m, "time_varying", False) or "Ti" not in m.input_names:
        return ()
    if "Ti" not in getattr(run.models.get("thermal"), "output_names", ()):
        raise DataError(
            f"{where}: the hygric model {m.name!r} couples its buffer to the indoor "
            "temperature Ti, which was measured in the calibration but has no future: the "
            f"run {run.path} has no thermal model to simulate it. Calibrate the room with "
            "a thermal model too (a 'thermal:' section beside 'hygric:'), or project a "
            "hygric model that does not take Ti (e.g. hygric_2c)"
        )
    return ("Ti",)
