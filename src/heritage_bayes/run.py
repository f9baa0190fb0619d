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

from heritage_bayes.climate.psychro import saturation_vapour_pressure
from heritage_bayes.config import CalibrationConfig, parse_config, read_yaml
from heritage_bayes.errors import InputError
from heritage_bayes.models import SECTIONS, build_model
from heritage_bayes.rc.model import RCModel
from heritage_bayes.rc.simulate import check_inputs

__all__ = ["Run", "load_run", "section_parameters"]


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
    priors : mapping, optional
        Prior overrides (default: the section's ``priors``).

    Returns
    -------
    (NoiseModel, ParameterSet)
    """
    from heritage_bayes.inference.likelihoods import get_noise_model
    from heritage_bayes.inference.parameters import parameters_for

    sec_cfg = getattr(cfg, section)
    noise = get_noise_model(sec_cfg.noise)
    params = parameters_for(
        model,
        noise,
        sec_cfg.priors if priors is None else priors,
        room_volume=sec_cfg.room_volume or cfg.room_volume,
        air_change_rate=cfg.air_change_rate,
        air_change_sigma=cfg.air_change_sigma,
        floor_area=cfg.floor_area,
        envelope_area=cfg.envelope_area,
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
        dt = float(dt or self.summary.get("dt", 3600.0))
        draws = self.draws(section, n_draws, seed)
        P, _ = model.param_array(draws)
        if control is not True:
            model = model.with_control(control)
        w = init_window or int(self.summary.get("init_steps", 720))
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
    raw, _ = read_yaml(p / "config.yaml", what="run config")
    cfg = parse_config(raw, source=str(p / "config.yaml"))
    summary = json.loads((p / "summary.json").read_text(encoding="utf-8"))
    idata = az.from_netcdf(str(p / "posterior.nc"), engine="h5netcdf")
    models = {s: build_model(cfg, s) for s in SECTIONS if getattr(cfg, s) is not None}
    return Run(path=p, config=cfg, idata=idata, summary=summary, models=models)


# ------------------------------------------------------------------ writing a run
#: What ``hbayes calibrate`` writes into a run directory (besides ``chain_<model>.h5``).
RUN_FILES = (
    "config.yaml",
    "config.original.yaml",
    "posterior.nc",
    "summary.json",
    "report.html",
)


def _ours(name: str) -> bool:
    return name in RUN_FILES or (name.startswith("chain_") and ".h5" in name)


def is_run_directory(path: str | Path) -> bool:
    """True for a folder ``hbayes calibrate`` wrote (outputs or chain checkpoints)."""
    p = Path(path)
    if not p.is_dir():
        return False
    done = (p / "summary.json").is_file() and (p / "posterior.nc").is_file()
    return done or any(p.glob("chain_*.h5"))


def saved_chains(out: str | Path) -> list[Path]:
    """The chain checkpoints ``--resume`` would continue for the run directory ``out``:
    those of an unfinished run (its staging folder) or else of the finished one."""
    out = Path(out)
    staged = sorted(staging_path(out).glob("chain_*.h5"))
    return staged or sorted(out.glob("chain_*.h5"))


def staging_path(out: Path) -> Path:
    """Where a run into ``out`` is written until it is complete (a hidden sibling)."""
    return out.parent / f".{out.name}.partial"


class RunWriter:
    """The writer's side of a run directory: lock, staging folder, swap at the end.

    A run writes into ``.<name>.partial`` beside ``out`` (chains included, so that
    ``--resume`` continues them) and only a complete run replaces ``out``, by renaming:
    a failed or interrupted re-run leaves the previous run intact. One run at a time:
    ``.<name>.lock`` beside ``out`` is locked (``flock``, released by the kernel even
    when the process is killed) and names the holder. ``out`` must be a run directory,
    empty or new; anything else is refused unless ``force`` (files named like the
    run's outputs are then replaced, others kept).

    Use as a context manager: ``with RunWriter(out) as w: ... write into w.staging ...;
    w.commit()``.
    """

    def __init__(self, out: str | Path, *, force: bool = False, resume: bool = False):
        self.out = Path(out).absolute()
        self.force = force
        self.resume = resume
        self.staging = staging_path(self.out)
        self.lock_path = self.out.parent / f".{self.out.name}.lock"
        self.committed = False
        self._fd: int | None = None
        self._made_parent = False

    # -- checks that need no data: called before anything is read
    def check(self) -> None:
        """Raise :class:`InputError` if ``out`` cannot or may not be written."""
        out = self.out
        if out.exists() and not out.is_dir():
            raise InputError(f"--out {out}: is a file, not a folder")
        anc = out.parent
        while not anc.exists():
            anc = anc.parent
        if not anc.is_dir():
            raise InputError(f"--out {out}: {anc} is a file, not a folder")
        import os

        if not os.access(anc, os.W_OK | os.X_OK):
            raise InputError(f"--out {out}: no permission to write in {anc}")
        if out.is_dir() and not self.force and not is_run_directory(out):
            entries = sorted(e.name for e in out.iterdir())
            if entries:
                shown = ", ".join(entries[:5]) + (", ..." if len(entries) > 5 else "")
                raise InputError(
                    f"--out {out}: the folder exists and is not a run directory of hbayes "
                    f"(it holds {shown}); choose another folder, or add --force to write "
                    "into it (files named like the run's outputs are then replaced, "
                    "others kept)"
                )

    def __enter__(self):
        import fcntl
        import os
        import shutil

        self.check()
        self._made_parent = not self.out.parent.exists()
        try:
            self.out.parent.mkdir(parents=True, exist_ok=True)
            self._lock(fcntl, os)
        except PermissionError as exc:
            raise InputError(f"--out {self.out}: cannot write ({exc.strerror})") from None
        old = self.out.parent / f".{self.out.name}.old"
        if old.is_dir() and not self.out.exists():  # a swap was cut short: undo it
            os.rename(old, self.out)
        elif old.is_dir():
            shutil.rmtree(old, ignore_errors=True)
        if not self.resume and self.staging.exists():
            shutil.rmtree(self.staging)
        self.staging.mkdir(exist_ok=True)
        if self.resume:  # extend a finished run: its chains the staging folder lacks
            for p in self.out.glob("chain_*.h5"):
                if not (self.staging / p.name).exists():
                    shutil.copy2(p, self.staging / p.name)
        return self

    def _lock(self, fcntl, os) -> None:
        import datetime
        import socket

        while True:
            fd = os.open(self.lock_path, os.O_RDWR | os.O_CREAT | os.O_NOFOLLOW, 0o644)
            try:
                fcntl.flock(fd, fcntl.LOCK_EX | fcntl.LOCK_NB)
            except BlockingIOError:
                holder = os.read(fd, 1000).decode("utf-8", "replace").strip() or "unknown"
                os.close(fd)
                raise InputError(
                    f"--out {self.out}: another hbayes run is writing it ({holder}); "
                    "wait for it to end or choose another folder"
                ) from None
            try:  # the file may have been removed by the holder that just released it
                same = os.stat(self.lock_path).st_ino == os.fstat(fd).st_ino
            except FileNotFoundError:
                same = False
            if same:
                break
            os.close(fd)
        now = datetime.datetime.now(datetime.UTC).isoformat(timespec="seconds")
        os.ftruncate(fd, 0)
        os.write(fd, f"pid {os.getpid()} on {socket.gethostname()}, since {now}".encode())
        self._fd = fd

    def commit(self) -> None:
        """Make the staging folder the run directory (keeping the user's other files)."""
        import os
        import shutil

        from heritage_bayes.inference.sampler import _DeferSignals

        old = self.out.parent / f".{self.out.name}.old"
        with _DeferSignals():
            if self.out.is_dir():
                for e in self.out.iterdir():
                    if not _ours(e.name) and not (self.staging / e.name).exists():
                        os.rename(e, self.staging / e.name)
                os.rename(self.out, old)
            os.rename(self.staging, self.out)
            self.committed = True
        shutil.rmtree(old, ignore_errors=True)

    def left_behind(self) -> str:
        """What an unfinished run leaves, for the error message."""
        chains = sorted(p.name for p in self.staging.glob("chain_*.h5"))
        prev = (
            f"{self.out} is unchanged"
            if self.out.exists()
            else f"nothing was written to {self.out}"
        )
        if chains:
            return (
                f"{prev}; the chains so far ({', '.join(chains)}) are kept in "
                f"{self.staging}, which --resume continues"
            )
        return prev

    def __exit__(self, *exc):
        import os
        import shutil

        if not self.committed and self.staging.is_dir():
            if not any(self.staging.glob("chain_*.h5")):
                shutil.rmtree(self.staging, ignore_errors=True)
        if self._fd is not None:
            try:
                os.unlink(self.lock_path)
            finally:
                os.close(self._fd)
                self._fd = None
        if self._made_parent and not self.committed:
            try:  # nothing left: remove the folder this run created
                self.out.parent.rmdir()
            except OSError:
                pass
        return False
