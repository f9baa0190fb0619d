"""Input checking and shared array helpers for :mod:`heritage_bayes.climate.risk`.

Private module: the public functions call these to turn user input (numpy arrays, lists,
scalars, pandas Series) into validated float arrays, and to put results back into the
shape the user passed (float, array or Series).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import pandas as pd

from heritage_bayes.errors import InputError

#: Hours in a (non-leap) year: the minimum length of the yearly indicators [h].
HOURS_PER_YEAR = 8760
#: Shortest series the yearly indicators accept [h]: a year less one day, so that a
#: typical-year file put on a grid (8759 h), or a year whose first or last day is
#: partial, counts as a year; per-year figures are normalised by the actual length.
MIN_YEAR_HOURS = HOURS_PER_YEAR - 24

NAN_POLICIES = ("propagate", "omit", "raise")
EDGES = ("shrink", "wrap")


def check_choice(func: str, name: str, value, allowed) -> None:
    """Raise :class:`InputError` unless ``value`` is one of ``allowed``."""
    if value not in allowed:
        opts = ", ".join(repr(a) for a in allowed)
        raise InputError(f"{func}: {name} must be one of {opts}; got {value!r}")


def check_positive(func: str, name: str, value) -> float:
    """A finite, strictly positive float, else :class:`InputError`."""
    try:
        v = float(value)
    except (TypeError, ValueError):
        raise InputError(f"{func}: {name} must be a positive number; got {value!r}") from None
    if not np.isfinite(v) or v <= 0:
        raise InputError(f"{func}: {name} must be a positive number; got {value!r}")
    return v


def _to_array(x, label: str, func: str) -> tuple[np.ndarray, pd.Index | None]:
    if isinstance(x, pd.DataFrame):
        cols = ", ".join(map(str, list(x.columns)[:5]))
        raise InputError(
            f"{func}: {label} must be a 1-D Series/array (hours) or a 2-D array "
            f"(draws × hours); got a DataFrame with columns [{cols}]. Pass one column, "
            f"e.g. df[{str(x.columns[0])!r}], or df.to_numpy().T for draws in columns"
        )
    if isinstance(x, pd.Series):
        try:
            arr = x.to_numpy(dtype=float, na_value=np.nan)
        except (TypeError, ValueError):
            raise InputError(
                f"{func}: {label} must be numeric; got a Series of dtype {x.dtype}"
            ) from None
        return arr, x.index
    try:
        arr = np.asarray(x, dtype=float)
    except (TypeError, ValueError):
        raise InputError(
            f"{func}: {label} must be numeric (array, list or Series); got {type(x).__name__}"
        ) from None
    return arr, None


def validate_T(arr: np.ndarray, func: str, label: str = "T") -> None:
    """Temperature in °C: reject infinities, kelvin and absurd values."""
    if np.isinf(arr).any():
        raise InputError(f"{func}: {label} contains infinite values; expected °C")
    finite = arr[np.isfinite(arr)]
    if finite.size == 0:
        return
    lo, hi = float(finite.min()), float(finite.max())
    if lo > 150.0:
        raise InputError(
            f"{func}: {label} looks like kelvin (min {lo:.1f}); expected °C (subtract 273.15)"
        )
    if lo < -100.0 or hi > 100.0:
        raise InputError(f"{func}: {label} must be in °C within -100…100; found {lo:.4g}…{hi:.4g}")


def validate_RH(arr: np.ndarray, func: str, label: str = "RH") -> None:
    """Relative humidity in percent 0–100: reject fractions, negatives, > 100, inf."""
    if np.isinf(arr).any():
        raise InputError(f"{func}: {label} contains infinite values; expected percent 0–100")
    finite = arr[np.isfinite(arr)]
    if finite.size == 0:
        return
    lo, hi = float(finite.min()), float(finite.max())
    if lo < 0.0:
        raise InputError(
            f"{func}: {label} must be in percent 0–100; found a negative value ({lo:.4g})"
        )
    if 0.0 < hi <= 1.0:
        raise InputError(
            f"{func}: {label} looks like a fraction (max {hi:.2f}); expected percent 0–100 "
            f"(multiply by 100)"
        )
    if hi > 100.0:
        raise InputError(
            f"{func}: {label} must be at most 100 %; found max {hi:.4g} %. Model output "
            f"above saturation must be clipped explicitly, e.g. np.clip({label}, 0, 100)"
        )


def check_hourly(idx: pd.Index | None, label: str, func: str) -> None:
    """A DatetimeIndex must advance by exactly one hour at every step."""
    if not isinstance(idx, pd.DatetimeIndex) or len(idx) < 2:
        return
    steps = idx[1:] - idx[:-1]
    bad = np.asarray(steps != pd.Timedelta(hours=1))
    if bad.any():
        i = int(np.flatnonzero(bad)[0])
        raise InputError(
            f"{func}: {label} must be a regular hourly series; found a step of "
            f"{steps[i]} after {idx[i]} ({int(bad.sum())} irregular step(s) in total). "
            f"Regularise it first, e.g. {label}.resample('h').mean()"
        )


def _check_nan(arr: np.ndarray, label: str, func: str, nan_policy: str) -> None:
    if nan_policy == "raise":
        k = int(np.isnan(arr).sum())
        if k:
            raise InputError(
                f"{func}: {label} contains {k} NaN value(s) and nan_policy='raise'; "
                f"use nan_policy='omit' to skip them or 'propagate'"
            )


@dataclass
class Hourly:
    """Validated hourly input: 2-D float arrays (draws × hours) plus output metadata."""

    T: np.ndarray | None
    RH: np.ndarray | None
    index: pd.Index | None
    ndim: int  # 1 (one series) or 2 (draws × hours)
    dropped: int = 0  # hours after the last complete year, not used

    @property
    def n_hours(self) -> int:
        a = self.RH if self.RH is not None else self.T
        return a.shape[-1]

    def reduce(self, values: np.ndarray):
        """Per-draw values (draws,) → float for a single series, else the array."""
        values = np.asarray(values, dtype=float)
        return float(values[0]) if self.ndim == 1 else values

    def series(self, values: np.ndarray, name: str | None = None):
        """Per-hour values (draws, hours) → the caller's shape (Series if indexed)."""
        if self.ndim == 2:
            return values
        out = values[0]
        if self.index is not None:
            return pd.Series(out, index=self.index, name=name)
        return out


def hourly(
    func: str,
    *,
    nan_policy: str = "propagate",
    min_hours: int | None = None,
    what: str = "",
    **inputs,
) -> Hourly:
    """Validate an hourly series (or a batch of them, draws × hours).

    ``inputs`` are ``T`` and/or ``RH``, each 1-D (hours) or 2-D (draws × hours); a 1-D
    one is broadcast against a 2-D one with the same number of hours.
    Series with a DatetimeIndex must be regular hourly; two Series must share the index.
    ``min_hours`` gives the error for indicators that need at least a year.
    """
    check_choice(func, "nan_policy", nan_policy, NAN_POLICIES)
    arrays: dict[str, np.ndarray] = {}
    index = None
    for label, x in inputs.items():
        if x is None:
            raise InputError(f"{func}: {label} is None; expected an hourly series")
        arr, idx = _to_array(x, label, func)
        if arr.ndim not in (1, 2):
            raise InputError(
                f"{func}: {label} must be 1-D (hours) or 2-D (draws × hours); "
                f"got {arr.ndim}-D with shape {arr.shape}"
            )
        if arr.shape[-1] == 0 or arr.size == 0:
            raise InputError(f"{func}: {label} is empty; expected an hourly series")
        if idx is not None:
            check_hourly(idx, label, func)
            if index is not None and not idx.equals(index):
                raise InputError(
                    f"{func}: T and RH are Series with different indices; align them "
                    f"first, e.g. T, RH = T.align(RH, join='inner')"
                )
            index = idx
        (validate_T if label == "T" else validate_RH)(arr, func, label)
        _check_nan(arr, label, func, nan_policy)
        arrays[label] = arr
    if len(arrays) == 2:
        a, b = arrays["T"], arrays["RH"]
        if a.shape != b.shape:
            if a.shape[-1] != b.shape[-1] or (a.ndim == 2 and b.ndim == 2):
                raise InputError(
                    f"{func}: T and RH must have the same shape, (hours,) or (draws, "
                    f"hours); got T {a.shape} and RH {b.shape}"
                )
            shape = a.shape if a.ndim == 2 else b.shape
            arrays = {k: np.broadcast_to(v, shape) for k, v in arrays.items()}
    ndim = max(v.ndim for v in arrays.values())
    arrays = {k: np.atleast_2d(v) for k, v in arrays.items()}
    out = Hourly(T=arrays.get("T"), RH=arrays.get("RH"), index=index, ndim=ndim)
    if min_hours is not None and out.n_hours < min_hours:
        raise InputError(
            f"{func}: {what or 'this indicator'} needs at least one year of hourly data "
            f"({min_hours} h); got {out.n_hours} h"
        )
    return out


def pointwise(func: str, **inputs):
    """Validate pointwise inputs (any broadcastable shapes, scalars allowed).

    Returns ``(arrays, wrap)``: the broadcast float arrays in the order given, and a
    function that puts a result of the broadcast shape back into the caller's type
    (float for scalars, Series when a Series came in, else ndarray).
    """
    arrays = []
    index = None
    for label, x in inputs.items():
        arr, idx = _to_array(x, label, func)
        if idx is not None:
            if index is not None and not idx.equals(index):
                raise InputError(
                    f"{func}: T and RH are Series with different indices; align them "
                    f"first, e.g. T, RH = T.align(RH, join='inner')"
                )
            index = idx
        (validate_T if label == "T" else validate_RH)(arr, func, label)
        arrays.append(arr)
    try:
        arrays = np.broadcast_arrays(*arrays)
    except ValueError:
        shapes = " and ".join(f"{k} {np.shape(a)}" for k, a in zip(inputs, arrays, strict=True))
        raise InputError(f"{func}: inputs must have matching shapes; got {shapes}") from None

    def wrap(result, name=None):
        result = np.asarray(result, dtype=float)
        if result.ndim == 0:
            return float(result)
        if index is not None and result.shape == (len(index),):
            return pd.Series(result, index=index, name=name)
        return result

    return arrays, wrap


def centred_mean(x: np.ndarray, half: int, edges: str, nan_policy: str) -> np.ndarray:
    """Centred moving average over ``2*half + 1`` samples along the last axis.

    Vectorised over the leading (draws) axis with cumulative sums. NaN values are left
    out of each window's mean (``omit``) or make the window NaN (``propagate``).
    ``edges="shrink"``: windows are truncated at the ends of the series (mean of the
    samples available); ``"wrap"``: the series is treated as periodic.
    """
    d, n = x.shape
    valid = np.isfinite(x)
    complete = bool(valid.all())
    xv = x if complete else np.where(valid, x, 0.0)
    if edges == "wrap":
        xv = np.concatenate([xv[:, n - half :], xv, xv[:, :half]], axis=1)
        cnt = np.concatenate([valid[:, n - half :], valid, valid[:, :half]], axis=1)
        lo = np.arange(n)
        hi = lo + 2 * half + 1
    else:
        cnt = valid
        i = np.arange(n)
        lo = np.maximum(i - half, 0)
        hi = np.minimum(i + half + 1, n)
    cs = np.zeros((d, xv.shape[1] + 1))
    np.cumsum(xv, axis=1, out=cs[:, 1:])
    s = cs[:, hi] - cs[:, lo]
    if complete:
        return s / (hi - lo)
    cc = np.zeros((d, xv.shape[1] + 1))
    np.cumsum(cnt, axis=1, out=cc[:, 1:])
    c = cc[:, hi] - cc[:, lo]
    with np.errstate(invalid="ignore", divide="ignore"):
        mean = s / c
    if nan_policy == "propagate":
        mean[c < (hi - lo)] = np.nan
    else:
        mean[c == 0] = np.nan
    return mean


def harmonic_mean(x: np.ndarray, nan_policy: str) -> np.ndarray:
    """Harmonic mean along the last axis (``omit``: over the finite values only)."""
    with np.errstate(divide="ignore"):
        inv = 1.0 / x
    if nan_policy == "omit":
        valid = ~np.isnan(x)
        n = valid.sum(axis=-1)
        s = np.where(valid, inv, 0.0).sum(axis=-1)
    else:
        n = x.shape[-1]
        s = inv.sum(axis=-1)
    with np.errstate(divide="ignore", invalid="ignore"):
        return np.where(n > 0, n / s, np.nan)


def share_percent(mask: np.ndarray, valid: np.ndarray, nan_policy: str) -> np.ndarray:
    """100 × (hours where ``mask`` among valid hours) / (valid hours), per draw."""
    n = np.count_nonzero(valid, axis=-1)
    k = np.count_nonzero(mask & valid, axis=-1)
    with np.errstate(invalid="ignore", divide="ignore"):
        out = np.where(n > 0, 100.0 * k / n, np.nan)
    if nan_policy == "propagate":
        out = np.where(n < valid.shape[-1], np.nan, out)
    return out
