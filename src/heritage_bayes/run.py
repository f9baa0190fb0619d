"""The run directory: what ``hbayes calibrate`` writes and every consumer reads.

A run directory holds ``posterior.nc`` (arviz InferenceData: posterior, sample_stats,
log_likelihood, observed_data, constant_data, posterior_predictive), ``summary.json``
(convergence, fit criteria, derived quantities), ``config.yaml`` (the resolved config)
and, after the report, ``report.html``. :func:`load_run` returns a :class:`Run`: the
models, the resolved config, the InferenceData and methods to simulate posterior draws
on new inputs (the entry point for climate-change projections).

Layer: above the models and the inference core, below every consumer (report,
projection, comparison, portfolio) and the orchestrator that writes it
(:mod:`heritage_bayes.calibrate`); it imports none of them.
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path

import numpy as np
import yaml

from heritage_bayes.climate.psychro import saturation_vapour_pressure
from heritage_bayes.config import CalibrationConfig, parse_config
from heritage_bayes.errors import InputError
from heritage_bayes.models import SECTIONS, build_model
from heritage_bayes.rc.model import RCModel
from heritage_bayes.rc.simulate import check_inputs

__all__ = ["Run", "load_run"]


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
        ``summary.json``.
    models : dict
        Section name (``thermal``/``hygric``) -> RCModel.
    """

    path: Path
    config: CalibrationConfig
    idata: object
    summary: dict
    models: dict

    @property
    def sections(self) -> tuple[str, ...]:
        return tuple(self.models)

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

        Returns
        -------
        (K, N, n_out) array of noise-free outputs ([°C] or [Pa]).
        """
        from heritage_bayes.rc.discretize import modal_form
        from heritage_bayes.rc.simulate import modal_simulate

        model = self._model(section)
        U = check_inputs(model, inputs)
        dt = float(dt or self.summary.get("dt", 3600.0))
        draws = self.draws(section, n_draws, seed)
        P, _ = model.param_array(draws)
        mf = modal_form(model, P, dt)
        if x0 is not None:
            z0 = mf.to_modal(np.asarray(x0, dtype=float))
        else:
            w = init_window or int(self.summary.get("init_steps", 720))
            z0 = mf.steady_state_modal(U[: max(1, w)].mean(axis=0))
        return modal_simulate(mf, U, np.ascontiguousarray(np.broadcast_to(z0, mf.lam.shape)))

    def simulate_rh(
        self, thermal_inputs, hygric_inputs, n_draws: int | None = 200, seed: int = 0, **kw
    ) -> np.ndarray:
        """Indoor RH [%] from paired thermal and hygric draws: RH = Pi / Psat(Ti)."""
        Ti = self.simulate(thermal_inputs, "thermal", n_draws, seed, **kw)[..., 0]
        Pi = self.simulate(hygric_inputs, "hygric", n_draws, seed, **kw)[..., 0]
        return 100.0 * Pi / saturation_vapour_pressure(Ti)


def load_run(path: str | Path) -> Run:
    """Load a run directory written by ``hbayes calibrate``.

    Raises
    ------
    InputError
        The folder or one of ``posterior.nc``, ``summary.json``, ``config.yaml`` is
        missing.
    """
    import json

    from heritage_bayes._arviz import az

    p = Path(path)
    for name in ("posterior.nc", "summary.json", "config.yaml"):
        if not (p / name).is_file():
            raise InputError(
                f"{p}: not a complete run directory ({name} is missing); "
                "run `hbayes calibrate` first"
            )
    raw = yaml.safe_load((p / "config.yaml").read_text(encoding="utf-8"))
    cfg = parse_config(raw, source=str(p / "config.yaml"))
    summary = json.loads((p / "summary.json").read_text(encoding="utf-8"))
    idata = az.from_netcdf(str(p / "posterior.nc"), engine="h5netcdf")
    models = {s: build_model(cfg, s) for s in SECTIONS if getattr(cfg, s) is not None}
    return Run(path=p, config=cfg, idata=idata, summary=summary, models=models)
