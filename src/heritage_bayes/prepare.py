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

from collections.abc import Mapping, Sequence
from dataclasses import dataclass, field

import numpy as np
import pandas as pd

from heritage_bayes.convert import to_jsonable
from heritage_bayes.errors import ConfigError, DataError
from heritage_bayes.inputs import (
    _with_vapour_pressure,
    annual_mean_temperature,
    fixed_node_temperature,
    solar_inputs,
    weather_inputs,
)
from heritage_bayes.prepare_steps import (
    _check_observations,
    _check_plausible,
    align_tables,
    check_outputs,
    complete_frame,
    demo_truth,
    fitted_mask,
    inside,
    period_rows,
)
from heritage_bayes.sources import INPUT_COLUMNS, OUTPUT_COLUMNS, _ground_column, read_sources

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
        Row positions of the validation period: before, after or inside the calibration
        period (:attr:`validation_inside`: its rows are held out of the fit,
        :meth:`calibration_observed`).
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

    @property
    def validation_inside(self) -> bool:
        """The validation period lies inside the calibration period: the model is
        simulated through it, its observations are not fitted."""
        return inside(self.calibration, self.validation)

    @property
    def held_out(self) -> slice | None:
        """The rows of a validation inside the calibration period, counted from the
        calibration's start (None when the validation lies outside it)."""
        if not self.validation_inside:
            return None
        c, v = self.calibration.start, self.validation
        return slice(v.start - c, v.stop - c)

    def fitted_rows(self) -> np.ndarray:
        """(N,) bool: the rows whose observations the calibration fits: the calibration
        period after its warm-up, without the validation rows inside it."""
        return fitted_mask(self.n_rows, self.calibration, self.validation, self.warmup_steps)

    def calibration_observed(self, section: str, model) -> np.ndarray:
        """:meth:`observed` over the calibration rows, NaN (missing, as a logger gap) on
        the rows of a validation inside it: what the likelihood fits."""
        obs = self.observed(section, model)[self.calibration].copy()
        if self.held_out is not None:
            obs[self.held_out] = np.nan
        return obs

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


def _extra_inputs(cfg, models: Sequence) -> list[str]:
    """Inputs of ``models`` beyond those built here (Te, Pe, Tf, I_<surface>), in model
    order."""
    built = {"Te", "Pe", "Tf"} | {f"I_{s}" for s in cfg.data.surfaces}
    extra: list[str] = []
    for m in models:
        generated = set(getattr(m, "calendar_inputs", {}))  # from the time grid
        for name in m.input_names:
            if name in generated:
                continue
            if name not in built and name not in extra and name not in OUTPUT_COLUMNS:
                extra.append(name)
    return extra


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


def prepare(cfg, models: Mapping | None = None) -> Prepared:
    """Read, derive, align: the model-ready data of a validated configuration.

    Parameters
    ----------
    cfg : heritage_bayes.config.CalibrationConfig
    models : mapping, optional
        Section -> :class:`~heritage_bayes.rc.model.RCModel` of every configured section,
        as the run built them (:func:`heritage_bayes.models.models_of`): they decide the
        inputs prepared. Default: built here from ``cfg``.

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
    thermal, hygric = cfg.thermal is not None, cfg.hygric is not None
    if not (thermal or hygric):
        raise ConfigError("give at least one of 'thermal' and 'hygric'")
    _check_models_vs_irradiance(cfg)
    data = cfg.data
    surfaces = {k: tuple(v) for k, v in data.surfaces.items()}
    truth = None

    # -- read ------------------------------------------------------------------------------
    raw = read_sources(cfg)
    weather, meas_tables, site, monument = raw.weather, raw.measurements, raw.site, raw.monument
    sources = dict(raw.notes)
    if models is None:
        from heritage_bayes.models import models_of  # the models decide their inputs

        models = models_of(cfg)[0]
    ordered = [models[s] for s in _SECTIONS if getattr(cfg, s) is not None]

    # -- inputs ----------------------------------------------------------------------------
    tables, note = weather_inputs(
        weather,
        thermal=thermal,
        hygric=hygric,
        irradiance=data.irradiance,
        site=site,
        surfaces=surfaces,
        where="data.weather",
        extra=_extra_inputs(cfg, ordered),
        **(data.roof.input_keywords() if data.roof is not None else {}),
    )
    sources["irradiance"] = note["irradiance"]
    irradiance_source = note["irradiance_source"]
    if monument is not None and irradiance_source == "measured":
        irradiance_source = monument.info["irradiance_label"]
    gt = data.ground_temperature
    # Tf: thermal, or a hygric sink at it
    ground = thermal or (hygric and "Tf" in models["hygric"].input_names)
    if ground and gt.mode == "column":
        tf_table, sources["ground_temperature"] = _ground_column(cfg, gt, "data.ground_temperature")
        tables.append(tf_table)

    # -- outputs, alignment, the frame -----------------------------------------------------
    meas_tables = [_with_vapour_pressure(m, "Pi", "data.measurements") for m in meas_tables]
    check_outputs(meas_tables, thermal, hygric)
    aligned = align_tables(cfg, tables, meas_tables)
    frame, flags = complete_frame(cfg, aligned, weather, ordered, ground, sources)

    # -- period rows -----------------------------------------------------------------------
    cal, val, sources["periods"], warmup_steps, init_steps = period_rows(cfg, frame, models)
    _check_observations(frame, cal, val, warmup_steps, thermal, hygric, data.step)
    _check_plausible(frame, cfg)

    if monument is not None:
        truth = demo_truth(cfg, monument, frame, cal, warmup_steps, val)
    if cfg.fixed_node_temperature is None and any("Pf" in m.parameter_names for m in ordered):
        te, const = weather.get("Te"), (gt.value if gt.mode == "constant" else None)
        sources["fixed_node_temperature"] = fixed_node_temperature(frame, cal, te, const)
    return Prepared(
        frame=frame,
        flags=flags,
        alignment=aligned.report.to_dict(),
        dt=float(data.step.total_seconds()),
        calibration=cal,
        validation=val,
        warmup_steps=warmup_steps,
        init_steps=init_steps,
        irradiance_source=irradiance_source,
        truth=truth,
        sources=to_jsonable(sources),
        breaks=aligned.breaks if aligned.breaks.any() else None,
    )
