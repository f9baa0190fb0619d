"""The named steps of :func:`heritage_bayes.prepare.prepare`: align, complete the frame,
place the periods, check the observations.

Each step takes the validated configuration and the data of the steps before it; the
conventions (UTC grid, interval-mean inputs, outputs at an instant, periods rounded up to
the next row) are those stated in :mod:`heritage_bayes.prepare`.
"""

from __future__ import annotations

import math

import numpy as np
import pandas as pd

from heritage_bayes.convert import format_timedelta
from heritage_bayes.errors import ConfigError, DataError, InputError
from heritage_bayes.inputs import (
    add_slope_columns,
    calendar_inputs,
    ground_cycle_inputs,
    ground_input,
)
from heritage_bayes.names import DEFAULT_NOISE
from heritage_bayes.rc.catalog import GROUND_CYCLE_INPUTS
from heritage_bayes.sources import OUTPUT_COLUMNS, _iso

# -- periods ----------------------------------------------------------------------------


def _utc(text: str) -> pd.Timestamp:
    ts = pd.Timestamp(text)
    return ts.tz_localize("UTC") if ts.tzinfo is None else ts.tz_convert("UTC")


def _rows(t: pd.Timestamp, start: pd.Timestamp, step: pd.Timedelta) -> int:
    """Grid row of instant ``t`` (rounded up to the next row)."""
    return math.ceil((t - start) / step - 1e-9)


def check_outputs(meas_tables, thermal: bool, hygric: bool) -> None:
    """Refuse measurements without the outputs the configured sections fit: ``Ti`` [°C]
    for the thermal section, ``Pi`` [Pa] (or ``Ti`` and ``RHi`` [%] to derive it) for the
    hygric one."""
    key = "data.measurements"
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


def align_tables(cfg, tables, meas_tables):
    """Inputs and measurements on one regular UTC grid of ``data.step``, over the span of
    the periods (the common period of all data without periods).

    Returns
    -------
    heritage_bayes.io.align result
        Frame, flags, slopes, breaks and the alignment report.
    """
    from heritage_bayes.io import align

    data, per = cfg.data, cfg.periods
    start = end = None
    if per.calibration is not None:
        bounds = [per.calibration] + ([per.validation] if per.validation is not None else [])
        start = min(_utc(p.start) for p in bounds)
        end = max(_utc(p.end) for p in bounds)
    try:
        return align(
            tables,
            meas_tables,
            step=data.step,
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


def complete_frame(cfg, aligned, weather, models, ground: bool, sources: dict):
    """The aligned frame with the inputs built on its grid, in model order.

    Adds the ground temperature ``Tf`` [°C] (unless a measured column came through the
    alignment), the calendar inputs (hours of use, [-]), the indoor vapour pressure ``Pi``
    [Pa] from ``Ti`` and ``RHi`` where not measured, orders the columns (inputs, then
    outputs), sets the ``inputs``/``outputs``/``units`` attributes and adds the
    first-order-hold slope columns. Notes where each built input came from in ``sources``.

    Returns
    -------
    frame, flags : pandas.DataFrame
    """
    gt, step = cfg.data.ground_temperature, cfg.data.step
    surfaces = cfg.data.surfaces
    frame = aligned.frame.copy()
    flags = aligned.flags.copy()
    n = len(frame)

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
    if any(c in m.input_names for m in models for c in GROUND_CYCLE_INPUTS):
        cols, note = ground_cycle_inputs(weather["Te"], frame.index + step / 2)
        for name, col in cols.items():
            frame[name], flags[name] = col, False
        gt_note = sources.setdefault("ground_temperature", {})
        gt_note["estimated_depth"] = note
        if "method" in gt_note and note.startswith("depth estimated"):
            gt_note["method"] += "; the thermal model moves it to the depth zf it estimates"
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

    known = ("Te", *[f"I_{k}" for k in surfaces], "Tf", *GROUND_CYCLE_INPUTS, "Pe")
    order = [c for c in known if c in frame]
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
        **{c: "K" for c in GROUND_CYCLE_INPUTS if c in order},
        **{c: "-" for m in models for c in getattr(m, "calendar_inputs", {})},
    }
    add_slope_columns(frame, models, aligned.slopes, flags)  # the first-order hold
    return frame, flags


def period_rows(cfg, frame: pd.DataFrame, models):
    """Row slices of the calibration and validation periods on the frame's grid, and the
    warm-up and initial-state windows in rows.

    Without ``periods``: the first 2/3 of the rows (whole rows) for calibration, the rest
    for validation. The warm-up (``periods.warmup``, else the default of ``models``,
    section -> model: :func:`heritage_bayes.models.default_warmup`) must be shorter than
    the calibration period.

    Returns
    -------
    cal, val : slice, slice or None
    note : dict
        What was used, for ``Prepared.sources["periods"]``.
    warmup_steps, init_steps : int
    """
    from heritage_bayes.models import default_warmup

    per, step = cfg.periods, cfg.data.step
    n, s0 = len(frame), frame.index[0]
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
                f"{format_timedelta(step)}; too short to split into calibration and validation"
            )
        cal, val = slice(0, k), slice(k, n)
        period_note = "default: first 2/3 of the common period of all data, then the rest"

    warmup = per.warmup if per.warmup is not None else default_warmup(cfg, models)
    warmup_steps = math.ceil(warmup / step - 1e-9)
    init_steps = math.ceil(per.init_window / step - 1e-9)
    cal_rows, before = cal.stop - cal.start, ""
    if inside(cal, val):  # the warm-up ends before it
        cal_rows, before = val.start - cal.start, " before the validation inside it"
    if warmup_steps >= cal_rows:
        a, b = frame.index[cal.start], frame.index[cal.start + cal_rows - 1] + step
        raise ConfigError(
            f"periods.warmup: {format_timedelta(warmup)} ({warmup_steps} rows) is not shorter "
            f"than the calibration period{before} ({cal_rows} rows, {_iso(a)} to {_iso(b)})"
        )

    def _span(sl):
        if sl is None:
            return None
        return {
            "start": _iso(frame.index[sl.start]),
            "end": _iso(frame.index[sl.stop - 1] + step),
            "rows": [sl.start, sl.stop],
        }

    note = {
        "from": period_note,
        "calibration": _span(cal),
        "validation": _span(val),
        "warmup": format_timedelta(warmup),
        "warmup_steps": warmup_steps,
        "init_window": format_timedelta(per.init_window),
        "init_steps": init_steps,
    }
    return cal, val, note, warmup_steps, init_steps


def inside(cal: slice, val: slice | None) -> bool:
    """The validation rows ``val`` start inside the calibration rows ``cal`` (the
    configuration puts them inside with calibration rows on both sides)."""
    return val is not None and cal.start <= val.start < cal.stop


def fitted_mask(n: int, cal: slice, val: slice | None, warmup_steps: int) -> np.ndarray:
    """(n,) bool: the rows whose observations the calibration fits: the calibration
    period after its warm-up, without the rows of a validation inside it."""
    rows = np.zeros(n, dtype=bool)
    rows[cal.start + warmup_steps : cal.stop] = True
    if inside(cal, val):
        rows[val] = False
    return rows


def demo_truth(cfg, monument, frame: pd.DataFrame, cal: slice, warmup_steps: int, val=None):
    """The demo monument's true parameters per section, with the nominal noise parameters
    of its outputs over the fitted rows of the calibration period (without a validation
    ``val`` inside it)."""
    from heritage_bayes.demo import nominal_noise

    truth = {sec: dict(vals) for sec, vals in monument.truth.items()}
    rows = frame.index[fitted_mask(len(frame), cal, val, warmup_steps)]
    for sec, out in (("thermal", "Ti"), ("hygric", "Pi")):
        sec_cfg = getattr(cfg, sec)
        kind = sec_cfg.noise if sec_cfg is not None else DEFAULT_NOISE
        truth[sec].update(nominal_noise(monument, out, rows, noise=kind))
    return truth


# -- checks -----------------------------------------------------------------------------


def _check_observations(frame, cal, val, warmup_steps, thermal, hygric, step) -> None:
    needed = (["Ti"] if thermal else []) + (["Pi"] if hygric else [])
    fitted = fitted_mask(len(frame), cal, val, warmup_steps)
    periods = [("calibration (after the warm-up)", slice(cal.start + warmup_steps, cal.stop))]
    if val is not None:
        if val.stop <= val.start:
            raise ConfigError("periods.validation: has no rows on the grid")
        periods.append(("validation", val))
    for what, sl in periods:
        hours = MIN_OBSERVED_HOURS[what.split()[0]]
        n_min = max(2, math.ceil(pd.Timedelta(hours=hours) / step))
        rows = fitted[sl] if what.startswith("calibration") else slice(None)
        for col in needed:
            n_obs = int(np.isfinite(frame[col].to_numpy()[sl][rows]).sum())
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
