"""From a validated configuration to model-ready arrays: read, derive, add sun, align.

:func:`prepare` is the bridge between :mod:`heritage_bayes.config` and the calibration
engine. It reads the weather and measurement files with the readers of
:mod:`heritage_bayes.io` (or the demo; both through :func:`heritage_bayes.sources.read_sources`),
derives vapour pressures, computes the irradiance on the solar surfaces
(:func:`heritage_bayes.climate.surface_irradiance`), builds the fixed (ground)
temperature input ``Tf``, and puts everything on one regular UTC grid with
:func:`heritage_bayes.io.align`. The demo goes through exactly the same path as real data.

Conventions (those of :func:`~heritage_bayes.io.align`)
-------------------------------------------------------
* Row ``k`` of :attr:`Prepared.frame` is the instant ``t_k`` (UTC). Input columns hold
  the mean over ``[t_k, t_k + dt)``, output columns the measured value at ``t_k`` (NaN
  where missing: the likelihood masks it). With ``data.input_hold: exact`` (files' default)
  ``<input>_slope`` columns hold ``u(t_{k+1}) - u(t_k)`` of readings at an instant (the
  first-order hold), zero for interval means.
* Input columns: ``Te`` [°C], ``I_<surface>`` [W/m²] (one per key of ``data.surfaces``),
  ``Tf`` [°C] for the thermal models; ``Pe`` [Pa] for the hygric models. Output columns:
  ``Ti`` [°C], ``Pi`` [Pa], and ``RHi`` [%] when measured (for the combined RH check).
* Vapour pressures come from T and RH (over water, IAPWS, :mod:`heritage_bayes.climate.psychro`)
  row by row at the native resolution, before any averaging.

Periods
-------
Dates in the config are UTC unless they carry an offset. The frame spans the earliest
start to the latest end of the periods; the simulation runs over the whole frame except
inside input gaps longer than ``data.max_gap`` (:attr:`Prepared.breaks`: the record splits
there into segments). Without ``periods``: the common period of all inputs and
measurements, its first 2/3 (whole rows) for calibration, the rest for validation. Period
bounds off the grid are rounded up to the next row. ``warmup_steps`` (``periods.warmup``):
the first rows of the calibration period, simulated but not fitted.

Ground temperature ``Tf``
-------------------------
``seasonal`` (files' default), :func:`~heritage_bayes.inputs.seasonal_ground_temperature`:
the annual cycle of the outdoor temperature in the **whole** weather record, damped and
delayed at a depth in the soil. ``annual_mean`` (the demo's), :func:`annual_mean_temperature`:
the mean outdoor temperature of a year around each instant (a constant for records
shorter than 365 days). ``constant``: a given value. ``column``: a measured series (e.g.
the heated room below an attic, a crypt), aligned like the other inputs.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass, field

import numpy as np
import pandas as pd

from heritage_bayes.convert import format_timedelta, to_jsonable
from heritage_bayes.errors import ConfigError, DataError, InputError
from heritage_bayes.inputs import (
    _with_vapour_pressure,
    add_slope_columns,
    annual_mean_temperature,
    calendar_inputs,
    fixed_node_temperature,
    ground_input,
    solar_inputs,
    weather_inputs,
)
from heritage_bayes.sources import INPUT_COLUMNS, OUTPUT_COLUMNS, _ground_column, _iso, read_sources

__all__ = [
    "INPUT_COLUMNS",
    "OUTPUT_COLUMNS",
    "Prepared",
    "annual_mean_temperature",
    "prepare",
    "solar_inputs",
]

_SECTIONS = ("thermal", "hygric")


# -- the result -------------------------------------------------------------------------


@dataclass
class Prepared:
    """Model-ready data of a calibration run (see :func:`prepare`).

    Attributes
    ----------
    frame : pandas.DataFrame
        Regular UTC grid (tz-aware index ``time``): the model inputs (``Te``,
        ``I_<surface>``, ``Tf`` [°C, W/m², °C]; ``Pe`` [Pa]) then the outputs (``Ti``
        [°C], ``Pi`` [Pa], ``RHi`` [%]); NaN = missing output.
    flags : pandas.DataFrame
        Boolean, same index and columns: True where an input value depends on an
        interpolated (gap-filled) sample.
    alignment : dict
        :meth:`heritage_bayes.io.AlignmentReport.to_dict` (JSON-serialisable).
    dt : float
        Grid step [s].
    calibration : slice
        Row positions ``[start, stop)`` of the calibration period in ``frame``.
    validation : slice or None
        Row positions of the validation period.
    warmup_steps, init_steps : int
        Rows of ``periods.warmup`` and ``periods.init_window``.
    irradiance_source : str
        ``"measured"``, ``"estimated from the daily Te range (Hargreaves-Samani)"``,
        ``"clear-sky proxy (pvlib Ineichen)"``, ``"none"``, or the demo's description.
    breaks : numpy.ndarray or None
        (N,) bool: rows inside an input gap longer than ``data.max_gap``, where the record
        splits into segments (:mod:`heritage_bayes.inference.segments`); None: no such gap.
    truth : dict or None
        Demo only: ``{"thermal": {name: value}, "hygric": {...}}``, the true parameters
        and the **nominal** noise parameters (``sigma_Ti``, ``phi_Ti``, ``sigma_Pi``,
        ``phi_Pi``) of the realised noise in the calibration period (see
        :func:`heritage_bayes.demo.nominal_noise`).
    sources : dict
        Provenance: files, formats, site, irradiance, ground temperature, demo settings
        (JSON-serialisable).
    """

    frame: pd.DataFrame
    flags: pd.DataFrame
    alignment: dict
    dt: float
    calibration: slice
    validation: slice | None
    warmup_steps: int
    init_steps: int
    irradiance_source: str
    truth: dict | None = None
    sources: dict = field(default_factory=dict)
    breaks: np.ndarray | None = None

    @property
    def n_rows(self) -> int:
        return len(self.frame)

    def model_inputs(self, section: str, model) -> np.ndarray:
        """The (N, m) float array of ``model.input_names`` columns of :attr:`frame`.

        Raises
        ------
        ConfigError
            The model needs an input the data do not provide (named, with the config
            key that would provide it).
        """
        _check_section(section)
        names = tuple(model.input_names)
        missing = [c for c in names if c not in self.frame.columns]
        if missing:
            raise ConfigError(
                f"{section}.model: model {model.name!r} needs input(s) {missing} that the "
                f"prepared data do not provide ({_input_hint(missing, self)}); inputs "
                f"available: {[c for c in self.frame.columns if c not in OUTPUT_COLUMNS]}"
            )
        U = np.array(self.frame.loc[:, list(names)].to_numpy(dtype=float))
        for j, c in enumerate(names):
            if c in OUTPUT_COLUMNS:
                # a measured indoor quantity as a control input (the humidistat's Ti,
                # conservation heating's Pi): gaps interpolated linearly in time
                U[:, j] = _filled(U[:, j], section, c)
        if not np.isfinite(U).all():  # align fills or rejects input gaps: internal error
            col = names[int(np.argwhere(~np.isfinite(U))[0, 1])]
            raise RuntimeError(f"prepared input {col!r} has non-finite values")
        return np.ascontiguousarray(U)

    def observed(self, section: str, model) -> np.ndarray:
        """The (N, n_out) float array of ``model.output_names`` columns (NaN = missing).

        Raises
        ------
        ConfigError
            An output the measurements do not provide.
        """
        _check_section(section)
        names = tuple(model.output_names)
        missing = [c for c in names if c not in self.frame.columns]
        if missing:
            raise ConfigError(
                f"{section}.model: model {model.name!r} predicts {missing}, which the "
                f"measurements do not provide ({_output_hint(missing)}); measured: "
                f"{[c for c in self.frame.columns if c in OUTPUT_COLUMNS]}"
            )
        return np.ascontiguousarray(self.frame.loc[:, list(names)].to_numpy(dtype=float))

    def period_index(self, which: str) -> pd.DatetimeIndex:
        """Timestamps of the ``"calibration"`` or ``"validation"`` rows."""
        sl = {"calibration": self.calibration, "validation": self.validation}[which]
        return self.frame.index[sl] if sl is not None else self.frame.index[:0]


def _filled(v: np.ndarray, section: str, name: str) -> np.ndarray:
    """``v`` with NaN gaps interpolated linearly (held at the ends)."""
    ok = np.isfinite(v)
    if not ok.any():
        raise DataError(
            f"{section}.model: the control input {name!r} (measured indoor data) has no "
            "values in the prepared period"
        )
    if ok.all():
        return v
    idx = np.arange(v.size)
    return np.interp(idx, idx[ok], v[ok])


def _check_section(section: str) -> None:
    if section not in _SECTIONS:
        raise ValueError(f"section must be 'thermal' or 'hygric' (got {section!r})")


def _input_hint(missing: Sequence[str], prep: Prepared) -> str:
    hints = []
    solar = [c for c in missing if c.startswith("I_")]
    if solar:
        if prep.irradiance_source == "none":
            hints.append(
                "data.irradiance is 'none': build the thermal model without solar surfaces, "
                "or remove data.irradiance (measured irradiance, else estimated)"
            )
        else:
            hints.append(
                f"solar surfaces come from data.surfaces, which has "
                f"{sorted(c[2:] for c in prep.frame.columns if c.startswith('I_'))}"
            )
    if "Pe" in missing:
        hints.append("Pe is prepared for a 'hygric' section from the weather's Te and RHe")
    if "Tf" in missing or "Te" in missing:
        hints.append("Te and Tf are prepared for a 'thermal' section")
    other = [c for c in missing if not c.startswith("I_") and c not in ("Pe", "Tf", "Te")]
    if other:
        hints.append(f"{other}: not an input the data layer provides")
    return "; ".join(hints)


def _output_hint(missing: Sequence[str]) -> str:
    hints = []
    if "Ti" in missing:
        hints.append("map the indoor temperature in data.measurements.columns.Ti")
    if "Pi" in missing:
        hints.append(
            "Pi is derived from Ti and RHi: map data.measurements.columns.Ti and "
            "data.measurements.columns.RHi"
        )
    return "; ".join(hints) or "unknown output"


def _extra_inputs(cfg) -> list[str]:
    """Model inputs beyond those built here (Te, Pe, Tf, I_<surface>), in model order."""
    from heritage_bayes.models import build_model  # the models decide their inputs

    built = {"Te", "Pe", "Tf"} | {f"I_{s}" for s in cfg.data.surfaces}
    extra: list[str] = []
    for section in ("thermal", "hygric"):
        if getattr(cfg, section) is None:
            continue
        m = build_model(cfg, section)
        generated = set(getattr(m, "calendar_inputs", {}))  # from the time grid
        for name in m.input_names:
            if name in generated:
                continue
            if name not in built and name not in extra and name not in OUTPUT_COLUMNS:
                extra.append(name)
    return extra


# -- periods ----------------------------------------------------------------------------


def _utc(text: str) -> pd.Timestamp:
    ts = pd.Timestamp(text)
    return ts.tz_localize("UTC") if ts.tzinfo is None else ts.tz_convert("UTC")


def _rows(t: pd.Timestamp, start: pd.Timestamp, step: pd.Timedelta) -> int:
    """Grid row of instant ``t`` (rounded up to the next row)."""
    return math.ceil((t - start) / step - 1e-9)


# -- prepare ----------------------------------------------------------------------------


def _check_models_vs_irradiance(cfg) -> None:
    sec = cfg.thermal
    if sec is None or cfg.data.irradiance != "none":
        return
    surf = sec.options.surfaces
    if surf:
        raise ConfigError(
            f"thermal.options.surfaces: {list(surf)} are solar surfaces, but data.irradiance "
            f"is 'none' (no solar input): remove thermal.options.surfaces (the thermal model "
            f"is then built without solar apertures) or remove data.irradiance (measured "
            f"irradiance, else estimated)"
        )


def prepare(cfg) -> Prepared:
    """Read, derive, align: the model-ready data of a validated configuration.

    Parameters
    ----------
    cfg : heritage_bayes.config.CalibrationConfig

    Returns
    -------
    Prepared

    Raises
    ------
    heritage_bayes.errors.ConfigError
        A setting that does not fit the data or the models (names the key path).
    heritage_bayes.errors.DataError
        A data problem: missing file or column, bad values, input gaps longer than
        ``data.max_gap`` inside the frame, a period not covered by the inputs, no
        observations in a period (names the key path and the file, column or row).
    """
    from heritage_bayes.io import align

    thermal, hygric = cfg.thermal is not None, cfg.hygric is not None
    if not (thermal or hygric):
        raise ConfigError("give at least one of 'thermal' and 'hygric'")
    _check_models_vs_irradiance(cfg)
    data, step = cfg.data, cfg.data.step
    surfaces = {k: tuple(v) for k, v in data.surfaces.items()}
    truth = None

    # -- read ------------------------------------------------------------------------------
    raw = read_sources(cfg)
    weather, meas_tables, site, monument = raw.weather, raw.measurements, raw.site, raw.monument
    sources = dict(raw.notes)

    # -- inputs ----------------------------------------------------------------------------
    tables, note = weather_inputs(
        weather,
        thermal=thermal,
        hygric=hygric,
        irradiance=data.irradiance,
        site=site,
        surfaces=surfaces,
        where="data.weather",
        extra=_extra_inputs(cfg),
        **(data.roof.input_keywords() if data.roof is not None else {}),
    )
    sources["irradiance"] = note["irradiance"]
    irradiance_source = note["irradiance_source"]
    if monument is not None and irradiance_source == "measured":
        irradiance_source = monument.info["irradiance_label"]
    gt = data.ground_temperature
    from heritage_bayes.models import build_model  # Tf: thermal, or a hygric sink at it

    ground = thermal or (hygric and "Tf" in build_model(cfg, "hygric").input_names)
    if ground and gt.mode == "column":
        tf_table, sources["ground_temperature"] = _ground_column(cfg, gt, "data.ground_temperature")
        tables.append(tf_table)

    # -- outputs ---------------------------------------------------------------------------
    key = "data.measurements"
    meas_tables = [_with_vapour_pressure(m, "Pi", key) for m in meas_tables]
    measured = {c for m in meas_tables for c in m.columns}
    if thermal and "Ti" not in measured:
        raise ConfigError(
            f"{key}.columns.Ti: the thermal section needs the indoor temperature Ti; the "
            f"measurements provide {sorted(measured)}"
        )
    if hygric and "Pi" not in measured and not {"Ti", "RHi"} <= measured:
        raise ConfigError(
            f"{key}.columns.RHi: the hygric section needs the indoor vapour pressure Pi, "
            f"or Ti and RHi to derive it; the measurements provide {sorted(measured)}"
        )

    # -- periods and alignment -------------------------------------------------------------
    per = cfg.periods
    start = end = None
    if per.calibration is not None:
        bounds = [per.calibration] + ([per.validation] if per.validation is not None else [])
        start = min(_utc(p.start) for p in bounds)
        end = max(_utc(p.end) for p in bounds)
    try:
        aligned = align(
            tables,
            meas_tables,
            step=step,
            max_gap=data.max_gap,
            start=start,
            end=end,
            long_gaps="split",
        )
    except DataError as exc:
        what = (
            f"the periods ({_iso(start)} to {_iso(end)})"
            if start is not None
            else "the common period of all data (no periods given)"
        )
        raise DataError(
            f"data.weather/data.measurements: aligning on {what} with data.step="
            f"{format_timedelta(data.step)}, data.max_gap={format_timedelta(data.max_gap)}: "
            f"{exc}"
        ) from None
    except InputError as exc:
        raise ConfigError(f"data: {exc}") from None

    frame = aligned.frame.copy()
    flags = aligned.flags.copy()
    n = len(frame)
    s0 = frame.index[0]

    # Tf (seasonal, annual mean or constant); column mode came through align
    if ground and gt.mode != "column":
        if gt.mode == "constant":
            tf = np.full(n, float(gt.value))
            sources["ground_temperature"] = {"mode": "constant", "value": float(gt.value)}
        else:
            mids = frame.index + step / 2
            tf, sources["ground_temperature"] = ground_input(gt.mode, weather["Te"], mids, gt.depth)
        frame["Tf"] = tf
        flags["Tf"] = False
    sections = [s for s in _SECTIONS if getattr(cfg, s) is not None]
    models = [build_model(cfg, s) for s in sections]
    for name, col in calendar_inputs(models, frame.index, step.total_seconds()).items():
        frame[name] = col  # hours of use from a weekly calendar (thermostat.schedule)
        flags[name] = False
    for m in models:
        for name, cal in getattr(m, "calendar_inputs", {}).items():
            sources.setdefault("calendar", {})[name] = {
                "weekly": list(cal.entries),
                "timezone": cal.timezone,
                "hours_per_week": cal.hours_per_week,
            }
    if "Pi" not in frame.columns and {"Ti", "RHi"} <= set(frame.columns):
        from heritage_bayes.io.derive import add_vapour_pressure  # censored at saturation

        frame["Pi"] = add_vapour_pressure(frame[["Ti", "RHi"]])["Pi"].to_numpy()
        flags["Pi"] = False

    order = [c for c in ("Te", *[f"I_{k}" for k in surfaces], "Tf", "Pe") if c in frame]
    order += [c for c in frame.columns if c not in order and c not in OUTPUT_COLUMNS]
    order += [c for c in ("Ti", "Pi", "RHi") if c in frame]
    frame = frame[order]
    flags = flags[order]
    frame.attrs = dict(aligned.frame.attrs)
    frame.attrs["inputs"] = tuple(c for c in order if c not in OUTPUT_COLUMNS)
    frame.attrs["outputs"] = tuple(c for c in order if c in OUTPUT_COLUMNS)
    frame.attrs["units"] = {
        **frame.attrs.get("units", {}),
        **{c: "W/m²" for c in order if c.startswith("I_")},
        **{c: u for c, u in (("Tf", "°C"), ("Pi", "Pa")) if c in order},
        **{c: "-" for m in models for c in getattr(m, "calendar_inputs", {})},
    }
    add_slope_columns(frame, models, aligned.slopes, flags)  # the first-order hold

    # -- period rows -----------------------------------------------------------------------
    if per.calibration is not None:
        cal = slice(
            _rows(_utc(per.calibration.start), s0, step),
            min(n, _rows(_utc(per.calibration.end), s0, step)),
        )
        val = None
        if per.validation is not None:
            val = slice(
                _rows(_utc(per.validation.start), s0, step),
                min(n, _rows(_utc(per.validation.end), s0, step)),
            )
        period_note = "config"
    else:
        k = round(2 * n / 3)
        if k < 1 or k >= n:
            raise DataError(
                f"periods: the common period of all data has only {n} rows of "
                f"{format_timedelta(data.step)}; too short to split into calibration and validation"
            )
        cal, val = slice(0, k), slice(k, n)
        period_note = "default: first 2/3 of the common period of all data, then the rest"
    dt = float(step.total_seconds())
    from heritage_bayes.models import default_warmup

    warmup = per.warmup if per.warmup is not None else default_warmup(cfg)
    warmup_steps = math.ceil(warmup / step - 1e-9)
    init_steps = math.ceil(per.init_window / step - 1e-9)
    cal_rows = cal.stop - cal.start
    if warmup_steps >= cal_rows:
        raise ConfigError(
            f"periods.warmup: {format_timedelta(warmup)} ({warmup_steps} rows) is not shorter "
            f"than the calibration period ({cal_rows} rows, {_iso(frame.index[cal.start])} to "
            f"{_iso(frame.index[cal.stop - 1] + step)})"
        )
    _check_observations(frame, cal, val, warmup_steps, thermal, hygric, step)
    _check_plausible(frame, cfg)

    def _span(sl):
        if sl is None:
            return None
        return {
            "start": _iso(frame.index[sl.start]),
            "end": _iso(frame.index[sl.stop - 1] + step),
            "rows": [sl.start, sl.stop],
        }

    sources["periods"] = {
        "from": period_note,
        "calibration": _span(cal),
        "validation": _span(val),
        "warmup": format_timedelta(warmup),
        "warmup_steps": warmup_steps,
        "init_window": format_timedelta(per.init_window),
        "init_steps": init_steps,
    }

    if monument is not None:
        from heritage_bayes.demo import nominal_noise

        truth = {sec: dict(vals) for sec, vals in monument.truth.items()}
        rows = frame.index[cal.start + warmup_steps : cal.stop]
        for sec, out in (("thermal", "Ti"), ("hygric", "Pi")):
            sec_cfg = getattr(cfg, sec)
            kind = sec_cfg.noise if sec_cfg is not None else "ar1_white"
            truth[sec].update(nominal_noise(monument, out, rows, noise=kind))

    if cfg.fixed_node_temperature is None and any("Pf" in m.parameter_names for m in models):
        te, const = weather.get("Te"), (gt.value if gt.mode == "constant" else None)
        sources["fixed_node_temperature"] = fixed_node_temperature(frame, cal, te, const)
    return Prepared(
        frame=frame,
        flags=flags,
        alignment=aligned.report.to_dict(),
        dt=dt,
        calibration=cal,
        validation=val,
        warmup_steps=warmup_steps,
        init_steps=init_steps,
        irradiance_source=irradiance_source,
        truth=truth,
        sources=to_jsonable(sources),
        breaks=aligned.breaks if aligned.breaks.any() else None,
    )


def _check_observations(frame, cal, val, warmup_steps, thermal, hygric, step) -> None:
    needed = (["Ti"] if thermal else []) + (["Pi"] if hygric else [])
    periods = [("calibration (after the warm-up)", slice(cal.start + warmup_steps, cal.stop))]
    if val is not None:
        if val.stop <= val.start:
            raise ConfigError("periods.validation: has no rows on the grid")
        periods.append(("validation", val))
    for what, sl in periods:
        hours = MIN_OBSERVED_HOURS[what.split()[0]]
        n_min = max(2, math.ceil(pd.Timedelta(hours=hours) / step))
        for col in needed:
            n_obs = int(np.isfinite(frame[col].to_numpy()[sl]).sum())
            if n_obs < n_min:
                a = frame.index[sl.start] if sl.start < len(frame) else frame.index[-1]
                b = frame.index[max(sl.stop - 1, 0)] + step
                found = (
                    f"no {col} observation" if n_obs == 0 else f"only {n_obs} {col} observations"
                )
                raise DataError(
                    f"data.measurements: {found} in the {what} period "
                    f"{_iso(a)} to {_iso(b)}; at least {n_min} ({hours} h of data) are needed "
                    "for a meaningful fit; check periods and the measurement file's time zone"
                )


#: Least observed time in each period: fewer gives fit figures without meaning.
MIN_OBSERVED_HOURS = {"calibration": 48, "validation": 24}


def _column_origin(cfg, col: str) -> str:
    """Where a standard column came from, for a message: config key, file, column."""
    data = cfg.data
    for i, m in enumerate(data.measurements or []):
        if m.columns and col in m.columns:
            return f"data.measurements[{i}] ({m.path}, column {m.columns[col]!r})"
    if data.weather is not None:
        return f"data.weather ({data.weather.path})"
    return col


def _check_plausible(frame: pd.DataFrame, cfg) -> None:
    """Units the physical range checks cannot catch: relative humidity given as a
    fraction (0-1) instead of percent, temperatures in °F beside ones in °C."""
    for col in ("RHi", "RHe"):
        if col in frame:
            v = frame[col].to_numpy(dtype=float)
            v = v[np.isfinite(v)]
            if v.size >= 24 and np.percentile(v, 99) <= 1.0:
                raise DataError(
                    f"{_column_origin(cfg, col)}: relative humidity {col} never exceeds "
                    f"{v.max():.3g}: a fraction (0-1)? hbayes expects percent (0-100); "
                    "multiply the column by 100"
                )
    if {"Ti", "Te"} <= set(frame.columns):
        ti, te = frame["Ti"].to_numpy(dtype=float), frame["Te"].to_numpy(dtype=float)
        ok = np.isfinite(ti) & np.isfinite(te)
        if ok.sum() >= 24:
            mi, me = float(ti[ok].mean()), float(te[ok].mean())
            for col, m, other in (("Ti", mi, me), ("Te", me, mi)):
                if m > 40 and m - other > 20:
                    raise DataError(
                        f"{_column_origin(cfg, col)}: {col} averages {m:.1f} °C against "
                        f"{other:.1f} °C for the other temperature: °F? hbayes expects °C; "
                        "convert with (F - 32) / 1.8"
                    )
