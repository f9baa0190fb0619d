"""The one result format: arviz InferenceData on disk, fit metrics, atomic writes.

Run directory (``hbayes calibrate``):

- ``posterior.nc``: arviz InferenceData (NetCDF4/HDF5). Variables are qualified by the
  calibrated model: ``thermal.Cw``, ``hygric.Ci``, ``thermal.tau_1_h``, ...

  Every group but ``posterior_retained_<model>`` holds the same draws: ``sampler.n_predictive``
  (default 1000) evenly spaced retained draws over all walkers (``chain``), with the
  same ``draw`` labels.

  - ``posterior``: parameters (fixed ones included as constants) and derived
    identifiable quantities (time constants [h], static gains);
  - ``posterior_retained_<model>`` (not an arviz group): every draw the model's sampler
    retained (after burn-in and thinning by τ, up to ``sampler.max_draws``) of its free
    parameters and of its varying derived quantities, ``draw`` labels of its own (the
    coordinate ``in_posterior`` marks, in order, the draws ``posterior`` keeps): the
    draws the run's R-hat and ESS are computed on. Older runs do not have it;
  - ``sample_stats``: ``<model>.lp`` (log-posterior), ``<model>.acceptance_rate``;
  - ``log_likelihood``: the pointwise terms of the calibration likelihood, only the
    hours that enter it (no warm-up, no gap), so ``az.loo(idata)``, ``az.waic(idata)``
    and ``az.compare`` work on the InferenceData as it is, without ``var_name``: with one
    output the variable ``<model>.<output>`` (axis ``time.<model>.<output>``), with
    several one variable ``all_outputs`` holding all of them on an ``observation`` axis
    (coordinates ``observation_variable``, ``observation_time``); with AR(1) noise each
    term is the density of the hour given the previous residual;
    (the per-output terms are not stored twice: ``inference.interop.split_outputs``
    rebuilds ``<model>.<output>`` from ``all_outputs``);
  - ``log_predictive_density_validation`` (not an arviz group): per output, the log of
    the posterior-mean predictive density of each validation hour [nats] (over the
    saved draws, from the simulation continued past (or through) calibration; their sum is the
    expected log predictive density of new data). Older runs, without this group, hold
    the terms per draw instead (``log_likelihood_validation``); both are read by
    ``heritage_bayes.compare.scores.elpd_validation``;
  - ``observed_data``: ``Ti``, ``Pi``, ``RHi`` on the ``time`` axis;
  - ``constant_data``: the model inputs and a ``period`` code (0 warm-up, 1 calibration,
    2 validation, -1 outside);
  - ``posterior_predictive``: ``<model>.<output>`` with noise and
    ``<model>.<output>_sim`` without, over calibration and validation periods, for a
    bounded subset of about 64 of those draws (``draw`` labels are the posterior's;
    and ``RHi`` combining thermal and hygric draws);
  - ``predictive_bands`` (not an arviz group): the 5, 25, 50, 75 and 95 % quantiles
    (axis ``quantile``) of every ``posterior_predictive`` variable over *all* saved
    draws, computed before the subset is taken: the report's bands and medians;
  - attributes: package version, seed, config hash, creation time.

  Written by :func:`write_inference_data`: every variable compressed (gzip level 4 with
  byte shuffle); predictive series and bands stored as integers of a fixed quantum
  (0.01 °C, 0.1 Pa, 0.01 %RH: below any logger's resolution), log-likelihood terms as
  float32 rounded to 12 mantissa bits (relative error at most 1.2e-4, i.e. below 1e-3
  nats per hour). See :func:`write_inference_data` for the demo's sizes.

- ``summary.json``: per parameter median, 5 %, 95 % (of the ``posterior`` group's
  draws), r_hat, ess_bulk, ess_tail (of every retained draw: ``az.summary`` of the
  group ``posterior_retained_<model>`` gives the same), τ; fit metrics; convergence verdict;
  MAP; identifiability.
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
    "PREDICTIVE_QUANTUM",
    "as_stored",
    "atomic_write",
    "atomic_write_text",
    "coverage",
    "ensure_free_space",
    "fit_metrics",
    "write_inference_data",
]

#: Storage quantum of predictive series and bands by unit: the value is stored as an
#: integer multiple of it (CF ``scale_factor`` packing, decoded on reading). Half of it
#: is the largest rounding error: 0.005 °C, 0.05 Pa, 0.005 %RH, ten times below the
#: resolution of the loggers the package reads (0.1 °C, 1 %RH).
PREDICTIVE_QUANTUM = {"°C": 0.01, "Pa": 0.1, "%": 0.01}
#: Groups whose values are stored packed by :data:`PREDICTIVE_QUANTUM`.
_PACKED_GROUPS = ("posterior_predictive", "predictive_bands")
#: Mantissa bits kept of float32 log-likelihood terms (of 23).
_LOGLIK_BITS = 12
#: Hours (or observations) per chunk of (chain, draw, hour) arrays.
_CHUNK_HOURS = 256


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


def _round_mantissa(a: np.ndarray, keep: int) -> np.ndarray:
    """float32 copy of ``a`` rounded to ``keep`` mantissa bits (round half up on the
    bit pattern: relative error at most 2**-(keep + 1)). The zeroed low bits compress
    to almost nothing (Klöwer et al., Nat. Comput. Sci. 1 (2021) 713-724,
    doi:10.1038/s43588-021-00156-2: bit rounding of climate data)."""
    bits = np.ascontiguousarray(a, dtype=np.float32).view(np.uint32)
    drop = 23 - keep
    half = np.uint32(1 << (drop - 1))
    mask = np.uint32(0xFFFFFFFF ^ ((1 << drop) - 1))
    finite = np.isfinite(bits.view(np.float32))
    out = np.where(finite, (bits + half) & mask, bits)
    return out.view(np.float32)


def _packing(quantum: float) -> dict:
    """NetCDF encoding that stores a value as an int32 multiple of ``quantum`` (CF
    ``scale_factor`` packing): the one definition :func:`_encoding` writes with and
    :func:`as_stored` reproduces."""
    return {"dtype": "int32", "scale_factor": quantum, "_FillValue": np.iinfo(np.int32).min}


def _encoding(group: str, da) -> dict:
    """NetCDF encoding of one variable of ``group`` (see :func:`write_inference_data`)."""
    if not np.issubdtype(da.dtype, np.number):
        return {}
    enc = {"zlib": True, "complevel": 4, "shuffle": True}
    if da.dims[:2] == ("chain", "draw") and da.ndim == 3 and da.size:
        # every draw of a few hundred hours in one chunk: the terms (or values) of one
        # hour over the draws are alike, and after the byte shuffle their leading bytes
        # compress together, smaller than with the library's default chunks (figure:
        # docs/science/benchmarks.md, "Figures behind the code's choices")
        enc["chunksizes"] = (da.shape[0], da.shape[1], min(_CHUNK_HOURS, da.shape[2]))
    quantum = PREDICTIVE_QUANTUM.get(da.attrs.get("unit", ""))
    if group in _PACKED_GROUPS and quantum is not None and np.issubdtype(da.dtype, np.floating):
        enc.update(_packing(quantum))
    return enc


def as_stored(values: np.ndarray, unit: str) -> np.ndarray:
    """``values`` as :func:`write_inference_data` stores and xarray reads them back
    from a predictive group: float32, packed to the multiple of
    :data:`PREDICTIVE_QUANTUM` [``unit``] where the unit is listed (through xarray's own
    CF encoder and decoder, the path of the write). Statistics that the summary states
    and a reader recomputes from ``posterior.nc`` (band coverage: a measurement on a
    band's edge) are taken from these values, so that the two agree exactly."""
    import xarray as xr

    a = np.asarray(values, dtype=np.float32)
    quantum = PREDICTIVE_QUANTUM.get(unit)
    if quantum is None:
        return a.astype(float)
    var = xr.Variable(
        tuple(f"dim_{i}" for i in range(a.ndim)),
        a,
        encoding=_packing(quantum),
    )
    encoded = xr.conventions.encode_cf_variable(var)
    return np.asarray(xr.conventions.decode_cf_variable("values", encoded).values, dtype=float)


def write_inference_data(idata, path: str | Path) -> None:
    """Write an InferenceData to ``path`` (NetCDF4/HDF5, one HDF5 group per group),
    compressed; a plain file: ``arviz.from_netcdf`` and ``xarray`` read it.

    Every numeric variable is gzip-compressed (level 4, byte shuffle). The
    predictive series and bands (groups ``posterior_predictive``,
    ``predictive_bands``) of a unit in :data:`PREDICTIVE_QUANTUM` are stored as int32
    multiples of its quantum; log-likelihood terms (groups starting with
    ``log_likelihood``) as float32 rounded to 12 mantissa bits (the error on the demo's
    terms and its effect on PSIS-LOO: docs/science/benchmarks.md, "Figures behind the
    code's choices"). Posterior draws and the data keep their
    precision. Not atomic by itself: call it through :func:`atomic_write`.

    The demo's file sizes before and after this format, with the command: the
    run-directory table in ``benchmarks/README.md``.
    """
    mode = "w"
    for group in idata.groups():
        ds = idata[group]
        if group.startswith("log_likelihood"):
            ds = ds.copy()
            for v in ds.data_vars:
                if np.issubdtype(ds[v].dtype, np.floating):
                    ds[v].values = _round_mantissa(ds[v].values, _LOGLIK_BITS)
        enc = {v: _encoding(group, ds[v]) for v in ds.data_vars}
        ds.to_netcdf(str(path), mode=mode, group=group, engine="h5netcdf", encoding=enc)
        mode = "a"


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
        (Kramer, van Schijndel & Schellen; Ljung's goodness of fit), ``SD`` the
        standard deviation of the measured signal [unit] (FIT's yardstick: on a nearly
        constant series, e.g. a humidistat-held RH, FIT is strongly negative whatever
        the accuracy; read MAE there), and ``n``.
    """
    m = np.asarray(measured, dtype=float)
    s = np.asarray(simulated, dtype=float)
    ok = np.isfinite(m) & np.isfinite(s)
    if ok.sum() < 2:
        nan = float("nan")
        return {"MSE": nan, "MAE": nan, "FIT": nan, "SD": nan, "n": int(ok.sum())}
    e = m[ok] - s[ok]
    denom = np.linalg.norm(m[ok] - m[ok].mean())
    fit = 100.0 * (1.0 - np.linalg.norm(e) / denom) if denom > 0 else float("nan")
    return {
        "MSE": float(np.mean(e**2)),
        "MAE": float(np.mean(np.abs(e))),
        "FIT": float(fit),
        "SD": float(denom / np.sqrt(ok.sum())),
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
