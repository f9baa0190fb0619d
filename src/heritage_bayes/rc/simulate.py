"""The fast simulation kernel: one or many parameter sets over long input series.

The simulation runs in modal coordinates (see :mod:`heritage_bayes.rc.discretize`): each
mode is an independent first-order recursion ``z[k+1] = a z[k] + w[k]``, whose forcing
``w = u @ Bdz.T + edz`` for all modes of all parameter sets comes from one BLAS product.
The recursion itself is a small compiled loop (numba) over time, vectorised across
modes and parameter sets; the work is chunked over parameter sets and time so that
memory stays bounded (``max_block`` doubles of forcing at a time).

Conventions: ``x[k+1] = Ad x[k] + Bd u[k]``, ``y[k] = C x[k] + D u[k]``, the input row
``u[k]`` held constant over :math:`[t_k, t_k + \\Delta t)`. The initial state ``x[0]`` is
given, or by default the steady state of the first input row
(:math:`x_0 = -A^{-1}(B u_0 + e)`), which removes most of the start-up transient but not
that of slow modes (use a warm-up period for those).
"""

from __future__ import annotations

from collections.abc import Iterator, Mapping

import numba
import numpy as np
import pandas as pd

from heritage_bayes.rc.discretize import ModalForm, _check_dt, modal_form

__all__ = ["check_inputs", "iter_simulate", "modal_simulate", "simulate"]

#: Forcing values held in memory at once by default (doubles): 2**22 = 32 MiB.
MAX_BLOCK = 2**22


@numba.njit(cache=True, nogil=True)
def _modal_run(ad, W, z, Cz, out, k0):  # pragma: no cover - compiled
    """Advance modal states over the rows of W, writing outputs out[:, k0 + k, :].

    ad : (K*n,) poles; W : (Nb, K*n) forcing; z : (K*n,) state, updated in place;
    Cz : (K, n_out, n) modal output matrix; out : (K, N, n_out).
    """
    Nb, Kn = W.shape
    K, n_out, n = Cz.shape
    for k in range(Nb):
        for p in range(K):
            for o in range(n_out):
                acc = 0.0
                for j in range(n):
                    acc += Cz[p, o, j] * z[p * n + j]
                out[p, k0 + k, o] = acc
        for i in range(Kn):
            z[i] = ad[i] * z[i] + W[k, i]


def check_inputs(model, inputs, *, where: str = "inputs") -> np.ndarray:
    """Validate and return inputs as a float (N, m) array in ``model.input_names`` order.

    ``inputs`` is an (N, m) array or a DataFrame holding (at least) the model's input
    columns. Raises ValueError for a wrong width, missing columns or non-finite values,
    naming the column and the first bad row.
    """
    names = model.input_names
    if isinstance(inputs, pd.DataFrame):
        missing = [c for c in names if c not in inputs.columns]
        if missing:
            raise ValueError(
                f"{where}: missing column(s) {missing} for model "
                f"{model.name!r}; columns are {list(inputs.columns)}"
            )
        labels = inputs.index
        U = inputs.loc[:, list(names)].to_numpy(dtype=float)
    else:
        U = np.asarray(inputs, dtype=float)
        labels = None
        if U.ndim == 1 and len(names) == 1:
            U = U[:, None]
        if U.ndim != 2 or U.shape[1] != len(names):
            raise ValueError(
                f"{where}: expected an (N, {len(names)}) array with columns "
                f"{list(names)} for model {model.name!r} "
                f"(got shape {U.shape})"
            )
    if U.shape[0] == 0:
        raise ValueError(f"{where}: no rows")
    bad = ~np.isfinite(U)
    if bad.any():
        row, col = (int(v) for v in np.argwhere(bad)[0])
        at = f"row {row}" + (f" ({labels[row]})" if labels is not None else "")
        raise ValueError(
            f"{where}: column {names[col]!r} has a non-finite value "
            f"({U[row, col]}) at {at}; {int(bad[:, col].sum())} such "
            "value(s) in that column; fill or interpolate gaps first"
        )
    return np.ascontiguousarray(U)


def _initial_modal(mf: ModalForm, U: np.ndarray, x0) -> np.ndarray:
    K, n = mf.lam.shape
    if x0 is None:
        z0 = mf.steady_state_modal(U[0])
    else:
        x0 = np.asarray(x0, dtype=float)
        if x0.shape not in ((n,), (K, n)):
            raise ValueError(f"x0: expected shape ({n},) or ({K}, {n}) (got {x0.shape})")
        z0 = mf.to_modal(x0)
    return np.ascontiguousarray(np.broadcast_to(z0, (K, n)))


def modal_simulate(
    mf: ModalForm,
    U: np.ndarray,
    z0: np.ndarray,
    *,
    out: np.ndarray | None = None,
    max_block: int = MAX_BLOCK,
) -> np.ndarray:
    """Simulate a :class:`ModalForm` batch over validated inputs (low-level).

    Parameters
    ----------
    mf : ModalForm
    U : (N, m) array
    z0 : (K, n) modal initial states
    out : (K, N, n_out) array, optional
        Written in place when given.

    Returns
    -------
    (K, N, n_out) array of outputs.
    """
    K, n = mf.lam.shape
    N = U.shape[0]
    n_out = mf.Cz.shape[1]
    if out is None:
        out = np.empty((K, N, n_out))
    Bcat = mf.Bdz.reshape(K * n, -1).T  # (m, K*n)
    ecat = mf.edz.reshape(K * n)
    ad = np.ascontiguousarray(mf.ad.reshape(K * n))
    z = np.ascontiguousarray(z0.reshape(K * n)).copy()
    Cz = np.ascontiguousarray(mf.Cz)
    rows = max(256, max_block // max(K * n, 1))
    for k0 in range(0, N, rows):
        W = U[k0 : k0 + rows] @ Bcat
        if ecat.any():
            W += ecat
        _modal_run(ad, W, z, Cz, out, k0)
    return out


def iter_simulate(
    model,
    params_batch: Mapping[str, object],
    inputs,
    dt: float = 3600.0,
    x0=None,
    *,
    chunk: int | None = None,
    max_block: int = MAX_BLOCK,
) -> Iterator[tuple[slice, np.ndarray]]:
    """Simulate many parameter sets chunk by chunk, yielding ``(slice, Y_chunk)``.

    For runs whose full output would not fit in memory (1000 posterior draws × 100 years
    hourly is 7 GB per output): each chunk holds ``chunk`` parameter sets, so peak memory
    is about ``chunk × N × n_out`` doubles plus ``max_block`` doubles of forcing.

    Parameters
    ----------
    chunk : int, optional
        Parameter sets per chunk (default: as many as fit in 2**24 output doubles).
    """
    dt = _check_dt(dt)
    P, _ = model.param_array(params_batch)
    model.check_values(P)
    U = check_inputs(model, inputs)
    K, N = P.shape[0], U.shape[0]
    if chunk is None:
        chunk = max(1, 2**24 // max(N * model.n_outputs, 1))
    for s in range(0, K, chunk):
        sl = slice(s, min(s + chunk, K))
        mf = modal_form(model, P[sl], dt)
        _raise_invalid(model, mf, P[sl])
        x0s = x0
        if x0 is not None and np.ndim(x0) == 2:
            x0s = np.asarray(x0)[sl]
        # a controlled room (heating, humidistat, sources) or one coupled to a
        # temperature (heritage_bayes.rc.sorption): no constant modal recursion
        if model.control is not None or model.time_varying:
            yield sl, model.forward(P[sl], U, dt, x0=x0s)[0]
            continue
        z0 = _initial_modal(mf, U, x0s)
        yield sl, modal_simulate(mf, U, z0, max_block=max_block)


def simulate(
    model,
    params: Mapping[str, object],
    inputs,
    dt: float = 3600.0,
    x0=None,
    *,
    max_block: int = MAX_BLOCK,
) -> np.ndarray:
    """Simulate an RC model for one parameter set or a batch.

    Parameters
    ----------
    model : RCModel
        E.g. ``heritage_bayes.model("thermal_4a")``.
    params : mapping
        Name -> float (one parameter set) or name -> (K,) array (a batch; scalars are
        broadcast), SI units ([J/K], [W/K], [m²], ...).
    inputs : (N, m) array or DataFrame
        Input series in ``model.input_names`` order (a DataFrame is selected by column
        name). Must be finite.
    dt : float
        Time step [s], default 3600.
    x0 : (n,) or (K, n) array, optional
        Initial state in physical units ([°C] or [Pa]); default the steady state for the
        first input row.

    Returns
    -------
    (N, n_out) array for one parameter set, (K, N, n_out) for a batch.

    Raises
    ------
    ValueError
        Missing/unknown parameter names, non-physical values (capacity <= 0), wrong input
        width, non-finite inputs, dt <= 0.

    Examples
    --------
    >>> import numpy as np, heritage_bayes as hb
    >>> m = hb.model("hygric_2c")
    >>> p = dict(Cw=5e-3, Ci=1e-4, Gw=1e-8, Gi=5e-8, Gfast=2e-8)
    >>> y = hb.simulate(m, p, np.full((48, 1), 1000.0))
    >>> y.shape, round(float(y[-1, 0]), 6)
    ((48, 1), 1000.0)
    """
    dt = _check_dt(dt)
    P, batch = model.param_array(params)
    model.check_values(P)
    U = check_inputs(model, inputs)
    out = np.empty((P.shape[0], U.shape[0], model.n_outputs))
    for sl, Y in iter_simulate(model, params, U, dt, x0, max_block=max_block, chunk=P.shape[0]):
        out[sl] = Y
    return out if batch else out[0]


def _raise_invalid(model, mf: ModalForm, P: np.ndarray) -> None:
    if not mf.valid.all():
        k = int(np.argmin(mf.valid))
        vals = ", ".join(f"{n}={v:g}" for n, v in zip(model.parameter_names, P[k], strict=True))
        raise ValueError(
            f"model {model.name!r}: parameter set {k} gives a singular or "
            f"unstable network (a node cut off from every boundary?): {vals}"
        )
