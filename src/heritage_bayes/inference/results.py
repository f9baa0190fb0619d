"""The one result format: arviz InferenceData on disk, fit metrics, atomic writes.

Run directory (``hbayes calibrate``):

- ``posterior.nc``: arviz InferenceData (NetCDF4/HDF5). Variables are qualified by the
  calibrated model: ``thermal.Cw``, ``hygric.Ci``, ``thermal.tau_1_h``, ...

  Every group holds the same draws: ``sampler.n_predictive`` (default 1000) evenly
  spaced retained draws over all walkers (``chain``), with the same ``draw`` labels.

  - ``posterior``: parameters (fixed ones included as constants) and derived
    identifiable quantities (time constants [h], static gains);
  - ``sample_stats``: ``<model>.lp`` (log-posterior), ``<model>.acceptance_rate``;
  - ``log_likelihood``: ``<model>.<output>``, the pointwise terms of the calibration
    likelihood, only the hours that enter it (axis ``time.<model>.<output>``: no warm-up,
    no gap), so ``az.loo``/``az.compare`` work on the InferenceData as it is; with AR(1)
    noise each term is the density of the hour given the previous residual;
  - ``log_likelihood_validation`` (not an arviz group): the same over the validation
    period, from the simulation continued past calibration (expected log predictive
    density of new data);
  - ``observed_data``: ``Ti``, ``Pi``, ``RHi`` on the ``time`` axis;
  - ``constant_data``: the model inputs and a ``period`` code (0 warm-up, 1 calibration,
    2 validation, -1 outside);
  - ``posterior_predictive``: ``<model>.<output>`` with noise and
    ``<model>.<output>_sim`` without, over calibration and validation periods, for a
    subset of draws (and ``RHi`` combining thermal and hygric draws);
  - attributes: package version, seed, config hash, creation time.

- ``summary.json``: per parameter median, 5 %, 95 %, r_hat, ess_bulk, ess_tail, τ; fit
  metrics; convergence verdict; MAP; identifiability.
- ``config.yaml``: the resolved config.

All files are written to a temporary name in the same folder and renamed into place.
"""

from __future__ import annotations

import json
import os
from pathlib import Path

import numpy as np

from heritage_bayes.convert import to_jsonable
from heritage_bayes.rundir.atomic import atomic_write, atomic_write_text

__all__ = [
    "atomic_write",
    "atomic_write_text",
    "coverage",
    "ensure_free_space",
    "fit_metrics",
]


def ensure_free_space(path: str | Path, nbytes: int, margin: int = 4 << 20) -> None:
    """Raise :class:`~heritage_bayes.errors.InputError` unless the file system of
    ``path`` has ``nbytes`` + ``margin`` bytes free.

    Checked before HDF5/NetCDF writes: a full disk in the middle of one leaves the HDF5
    library in a state that can crash the interpreter at exit.
    """
    from heritage_bayes.errors import InputError

    folder = Path(path).parent
    try:
        st = os.statvfs(folder)
    except (OSError, AttributeError):  # no statvfs (not POSIX): let the write try
        return
    free = st.f_bavail * st.f_frsize
    need = int(nbytes) + margin
    if free < need:
        raise InputError(
            f"{folder}: not enough free disk space to write {Path(path).name} "
            f"({free / 2**20:.1f} MiB free, about {need / 2**20:.1f} MiB needed); free some "
            "space or choose another --out"
        )


def fit_metrics(measured: np.ndarray, simulated: np.ndarray) -> dict[str, float]:
    """The paper's fit criteria over the finite measurement pairs.

    Parameters
    ----------
    measured : (N,) array
        Measured signal :math:`y'` (NaN = missing).
    simulated : (N,) array
        Simulated signal :math:`y`.

    Returns
    -------
    dict
        ``MSE`` = :math:`\\frac1N\\sum(y'-y)^2` [unit²], ``MAE`` = :math:`\\frac1N\\sum|y'-y|`
        [unit], ``FIT`` = :math:`100\\,(1 - \\|y'-y\\| / \\|y'-\\bar{y}'\\|)` [%]
        (Kramer, van Schijndel & Schellen; Ljung's goodness of fit), and ``n``.
    """
    m = np.asarray(measured, dtype=float)
    s = np.asarray(simulated, dtype=float)
    ok = np.isfinite(m) & np.isfinite(s)
    if ok.sum() < 2:
        return {"MSE": float("nan"), "MAE": float("nan"), "FIT": float("nan"), "n": int(ok.sum())}
    e = m[ok] - s[ok]
    denom = np.linalg.norm(m[ok] - m[ok].mean())
    fit = 100.0 * (1.0 - np.linalg.norm(e) / denom) if denom > 0 else float("nan")
    return {
        "MSE": float(np.mean(e**2)),
        "MAE": float(np.mean(np.abs(e))),
        "FIT": float(fit),
        "n": int(ok.sum()),
    }


def coverage(measured: np.ndarray, draws: np.ndarray, level: float) -> float:
    """Share of measurements inside the central ``level`` predictive band.

    ``draws`` is (K, N) posterior-predictive samples; ``level`` e.g. 0.9.
    """
    m = np.asarray(measured, dtype=float)
    lo, hi = np.quantile(draws, [(1 - level) / 2, (1 + level) / 2], axis=0)
    ok = np.isfinite(m)
    if not ok.any():
        return float("nan")
    return float(np.mean((m[ok] >= lo[ok]) & (m[ok] <= hi[ok])))


def dump_json(path: str | Path, data: dict) -> Path:
    """Atomically write ``data`` as indented JSON (NaN/inf -> null)."""
    return atomic_write_text(
        path, json.dumps(to_jsonable(data), indent=2, ensure_ascii=False) + "\n"
    )
