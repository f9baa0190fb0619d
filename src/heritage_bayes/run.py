"""The run directory: what ``hbayes calibrate`` writes and every consumer reads.

A run directory holds ``posterior.nc`` (arviz InferenceData: posterior, sample_stats,
log_likelihood, observed_data, constant_data, posterior_predictive), ``summary.json``
(convergence, fit criteria, derived quantities), ``config.yaml`` (the resolved config)
and, after the report, ``report.html``. :func:`load_run` returns a :class:`Run`: the
models, the resolved config, the InferenceData and methods to simulate posterior draws
on new inputs (the entry point for climate-change projections).

Layer: above the models and the inference core, below every consumer (report,
projection, comparison, portfolio) and the orchestrator that writes it
(:mod:`heritage_bayes.calibration.calibrate`); it imports none of them.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from functools import cached_property
from pathlib import Path

import numpy as np

from heritage_bayes.climate.psychro import saturation_vapour_pressure
from heritage_bayes.config import CalibrationConfig, parse_config, read_yaml
from heritage_bayes.errors import ConfigError, InputError
from heritage_bayes.models import SECTIONS, build_model
from heritage_bayes.rc.model import RCModel
from heritage_bayes.rc.simulate import check_inputs
from heritage_bayes.rundir.summary import RunSummary
from heritage_bayes.rundir.writer import (  # the writer's side, re-exported
    RUN_FILES,
    RunWriter,
    is_run_directory,
    saved_chains,
    staging_path,
)

__all__ = [
    "RUN_FILES",
    "Run",
    "RunWriter",
    "config_yaml",
    "is_run_directory",
    "load_run",
    "saved_chains",
    "section_parameters",
    "staging_path",
    "stamp_provenance",
]


def section_parameters(cfg: CalibrationConfig, section: str, model: RCModel, priors=None):
    """Noise model and :class:`~heritage_bayes.inference.parameters.ParameterSet` of a
    config section, priors validated: the one place a config maps to the sampler's
    parameters (room volume and air-change priors, ``data.step`` for per-step noise
    priors).

    Parameters
    ----------
    cfg : CalibrationConfig
    section : {"thermal", "hygric"}
    model : RCModel
        The section's model.
    priors : mapping name -> PriorSpec, optional
        Prior overrides, typed (default: the section's ``priors``).

    Returns
    -------
    (NoiseModel, ParameterSet)
    """
    from heritage_bayes.inference.likelihoods import get_noise_model, residual_noise_models
    from heritage_bayes.inference.parameters import parameters_for

    sec_cfg = getattr(cfg, section)
    noise = get_noise_model(sec_cfg.noise)
    if model.time_varying and model.isotherm != "linear" and noise.statespace:
        raise ConfigError(
            f"{section}.noise: {sec_cfg.noise!r} filters a model linear in its state; "
            f"{model.name} has the {model.isotherm!r} isotherm (transitions that follow the "
            f"state): use one of {', '.join(residual_noise_models())}"
        )
    params = parameters_for(
        model,
        noise,
        sec_cfg.priors if priors is None else priors,
        room_volume=sec_cfg.room_volume or cfg.room_volume,
        air_change_rate=cfg.air_change_rate,
        air_change_sigma=cfg.air_change_sigma,
        floor_area=cfg.floor_area,
        envelope_area=cfg.envelope_area,
        interior_area=cfg.interior_area,
        glazing_area=cfg.glazing_area,
        roof_area=cfg.data.roof.plane_areas() if cfg.data.roof else None,
        fixed_node_temperature=cfg.fixed_node_temperature,
        where=f"{section}.priors",
        dt=cfg.data.step.total_seconds(),
    )
    return noise, params


@dataclass
class Run:
    """A calibration run loaded from its directory.

    Attributes
    ----------
    path : Path
    config : CalibrationConfig
        The resolved config.
    idata : arviz.InferenceData
    summary : dict
        ``summary.json`` as JSON; :attr:`run_summary` is the same, typed.
    models : dict
        Section name (``thermal``/``hygric``) -> RCModel.
    notes : list of str
        On the config: :attr:`config` is the one recorded in the provenance (SHA-256
        checked), and a note says if the visible ``config.yaml`` differs from it.
    """

    path: Path
    config: CalibrationConfig
    idata: object
    summary: dict
    models: dict
    notes: list = field(default_factory=list)

    @property
    def sections(self) -> tuple[str, ...]:
        return tuple(self.models)

    @cached_property
    def run_summary(self) -> RunSummary:
        """:attr:`summary` typed (:class:`heritage_bayes.rundir.summary.RunSummary`)."""
        return RunSummary.from_dict(self.summary, source=self.path / "summary.json")

    def draws(self, section: str, n: int | None = None, seed: int = 0) -> dict[str, np.ndarray]:
        """Posterior draws of the model parameters: name -> (K,) arrays [SI units].

        ``n`` draws chosen at random without replacement (default all).
        """
        model = self._model(section)
        post = self.idata.posterior
        cols = [post[f"{section}.{p}"].values.reshape(-1) for p in model.parameter_names]
        K = cols[0].size
        idx = np.arange(K)
        if n is not None and n < K:
            idx = np.sort(np.random.default_rng(seed).choice(K, size=n, replace=False))
        return {p: c[idx] for p, c in zip(model.parameter_names, cols, strict=True)}

    def prior_pushforward(
        self, section: str, n: int, seed: int = 0
    ) -> tuple[np.ndarray, dict[str, np.ndarray]]:
        """Prior draws of the model parameters and their derived quantities.

        The prior of a derived quantity (time constant, static gain) is the push-forward
        of the parameter priors: ``n`` draws of every parameter from its prior (fixed ones
        repeated; :meth:`ParameterSet.sample_prior` with ``default_rng(seed)``) through
        :func:`heritage_bayes.rc.identify.derived_quantities`.

        Returns
        -------
        P : (n, P) array
            Model parameters in ``model.parameter_names`` order [SI units] (the noise
            parameters' draws are left out).
        derived : dict name -> (n,) array
            ``tau_1_h`` [h] ..., ``gain_<out>_<in>``, ``offset_<out>_<const>``; NaN where
            a draw is not admissible.
        """
        from heritage_bayes.rc.identify import derived_quantities

        model = self._model(section)
        _, params = section_parameters(self.config, section, model)
        theta = params.sample_prior(np.random.default_rng(seed), n)
        P = theta[:, : len(model.parameter_names)]
        with np.errstate(all="ignore"):
            dq = derived_quantities(model, P)
        return P, {k: np.broadcast_to(np.asarray(v, dtype=float), (n,)) for k, v in dq.items()}

    def _model(self, section: str) -> RCModel:
        if section not in self.models:
            raise InputError(
                f"run {self.path} has no {section!r} model; it has {list(self.models)}"
            )
        return self.models[section]

    def simulate(
        self,
        inputs,
        section: str = "thermal",
        n_draws: int | None = 200,
        seed: int = 0,
        dt: float | None = None,
        x0=None,
        init_window: int | None = None,
        control: bool | dict = True,
    ) -> np.ndarray:
        """Simulate posterior draws on new inputs (e.g. future weather).

        Parameters
        ----------
        inputs : DataFrame or (N, m) array
            Model inputs (``model.input_names``), e.g. a morphed weather file prepared
            like the calibration data.
        section : {"thermal", "hygric"}
        n_draws : int or None
            Number of posterior draws (random, seeded); None for all.
        dt : float, optional
            Time step [s]; default the calibration's.
        init_window : int, optional
            Steps of inputs averaged for the steady-state initial state (default the
            calibration's ``periods.init_window``); or give ``x0``.
        control : bool or mapping, default True
            For a controlled room (thermostat, humidistat, sources; see
            :mod:`heritage_bayes.rc.control`): keep the calibrated control (True), run
            the room free-running (False), or switch components, e.g.
            ``{"humidistat": False}`` ("what if the dehumidifier fails?"). The inputs
            still need the control's columns (``Ti`` for a humidistat).

        Returns
        -------
        (K, N, n_out) array of noise-free outputs ([°C] or [Pa]).
        """
        model = self._model(section)
        U = check_inputs(model, inputs)
        rs = self.run_summary
        dt = float(dt or rs.dt)
        draws = self.draws(section, n_draws, seed)
        P, _ = model.param_array(draws)
        if control is not True:
            model = model.with_control(control)
        w = init_window or (720 if rs.init_steps is None else int(rs.init_steps))
        u0 = U[: max(1, w)].mean(axis=0)
        return model.forward(P, U, dt, u_init=u0, x0=x0)[0]

    def simulate_rh(
        self, thermal_inputs, hygric_inputs, n_draws: int | None = 200, seed: int = 0, **kw
    ) -> np.ndarray:
        """Indoor RH [%] from paired thermal and hygric draws: RH = Pi / Psat(Ti), capped
        at 100 % (a vapour pressure above saturation condenses; the cap also keeps
        rounding from handing the risk indicators 100.01 %)."""
        Ti = self.simulate(thermal_inputs, "thermal", n_draws, seed, **kw)[..., 0]
        Pi = self.simulate(hygric_inputs, "hygric", n_draws, seed, **kw)[..., 0]
        return np.minimum(100.0 * Pi / saturation_vapour_pressure(Ti), 100.0)


def config_yaml(cfg: CalibrationConfig) -> str:
    """The text of a run's ``config.yaml``: the resolved config, data paths absolute."""
    import yaml

    return yaml.safe_dump(cfg.portable(), sort_keys=False, allow_unicode=True)


def _snapshot_sha256(snapshot: dict) -> str:
    import hashlib
    import json

    blob = json.dumps(snapshot, sort_keys=True, ensure_ascii=False, allow_nan=False)
    return hashlib.sha256(blob.encode("utf-8")).hexdigest()


def stamp_provenance(cfg: CalibrationConfig, idata, summary: dict) -> None:
    """Record the config that produces a posterior: the snapshot (what ``config.yaml``
    holds, as data) and its SHA-256 in ``summary["provenance"]``, the hash also in the
    attributes of every InferenceData group, so that an edited ``config.yaml`` or
    snapshot is detected by :func:`load_run`."""
    snapshot = cfg.portable()
    sha = _snapshot_sha256(snapshot)
    summary["provenance"] = {"config": snapshot, "config_sha256": sha}
    for g in idata.groups():
        idata[g].attrs["config_sha256"] = sha


def _recorded_config(p: Path, rs: RunSummary, idata) -> tuple[CalibrationConfig | None, list]:
    """The config recorded in the provenance of run ``p`` (hash checked) and the notes
    on it: None for a run written before the provenance was recorded."""
    prov = rs.provenance
    if not prov.recorded:
        return None, ["the run records no config snapshot (an older hbayes): the report "
                      "shows config.yaml as it is now"]  # fmt: skip
    snapshot = prov.snapshot()
    sha = _snapshot_sha256(snapshot)
    stamped = {idata[g].attrs.get("config_sha256") for g in idata.groups()} - {None}
    if sha != prov.config_sha256 or stamped - {sha}:
        raise InputError(
            f"{p / 'summary.json'}: the config snapshot recorded in the provenance does not "
            f"match its SHA-256 (recorded {prov.config_sha256!s:.16}, posterior.nc "
            f"{', '.join(sorted(stamped)) or 'none'}, computed {sha:.16}): the run directory "
            "was edited; run `hbayes calibrate` again"
        )
    cfg = parse_config(snapshot, source=f"{p / 'summary.json'} (provenance)")
    notes = []
    seen = (p / "config.yaml").read_text(encoding="utf-8", errors="replace")
    if seen != config_yaml(cfg):
        notes.append(
            f"{p / 'config.yaml'} differs from the config that produced this posterior "
            "(recorded with its SHA-256 in summary.json); the report uses and shows the "
            "recorded one"
        )
    return cfg, notes


def load_run(path: str | Path) -> Run:
    """Load a run directory written by ``hbayes calibrate``.

    Raises
    ------
    InputError
        The folder or one of ``posterior.nc``, ``summary.json``, ``config.yaml`` is
        missing, truncated, of the wrong type or another file (see
        :mod:`heritage_bayes.rundir.reader`), the summary's schema is newer than this
        hbayes reads, or the recorded config snapshot does not match its SHA-256.
    """
    from heritage_bayes.rundir.reader import (
        check_run_files,
        damaged,
        read_posterior,
        read_summary,
    )

    p = check_run_files(path)
    summary = read_summary(p)
    rs = RunSummary.from_dict(summary, source=p / "summary.json")
    cfg = None
    if not rs.provenance.recorded:  # an older run: config.yaml
        raw, _ = read_yaml(p / "config.yaml", what="run config")
        cfg = parse_config(raw, source=str(p / "config.yaml"))
    idata = read_posterior(p)
    recorded, notes = _recorded_config(p, rs, idata)
    cfg = recorded or cfg
    models = {s: build_model(cfg, s) for s in SECTIONS if getattr(cfg, s) is not None}
    for s, m in models.items():  # a posterior of other models (another run's file)
        absent = [n for n in m.parameter_names if f"{s}.{n}" not in idata.posterior]
        if absent:
            raise damaged(
                p / "posterior.nc",
                f"no draws of {s}.{absent[0]} of the run's {m.name}: not this run's posterior",
            )
    models = hold_as_recorded(models, rs)
    return Run(path=p, config=cfg, idata=idata, summary=summary, models=models, notes=notes)


def hold_as_recorded(models: dict[str, RCModel], summary: RunSummary | dict) -> dict[str, RCModel]:
    """The models with the input hold the run was calibrated with: a run made before
    ``data.input_hold`` existed recorded input names without slope columns (every input
    held at its step mean), which its config, read today, would give."""
    rs = summary if isinstance(summary, RunSummary) else RunSummary.from_dict(summary)
    out = dict(models)
    for s, m in models.items():
        info = rs.models.get(s)
        names = None if info is None else info.input_names
        if m.slope_inputs and names is not None and not set(m.slope_columns) & set(names):
            out[s] = m.with_slopes(())
    return out
