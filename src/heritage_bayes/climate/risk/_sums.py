"""Sums, minima and maxima for the compiled risk passes: numpy's pairwise summation bit
for bit (:func:`pairwise_sum`), and block sums and extrema that vectorise.

Private module; callers: :mod:`heritage_bayes.climate.risk._fused` and
:mod:`heritage_bayes.projection._stream` (which stamp their numba cache with this file,
:func:`heritage_bayes.climate._vecmath.stamp_cache`).
"""

from __future__ import annotations

import numpy as np
from numba import njit


@njit(cache=True, error_model="numpy")
def _pairwise_leaf(a, lo, n):  # pragma: no cover - compiled
    """numpy's pairwise summation of ``a[lo:lo + n]`` for ``n <= 128`` (no split)."""
    if n < 8:
        res = 0.0
        for i in range(n):
            res += a[lo + i]
        return res
    r0, r1, r2, r3 = a[lo], a[lo + 1], a[lo + 2], a[lo + 3]
    r4, r5, r6, r7 = a[lo + 4], a[lo + 5], a[lo + 6], a[lo + 7]
    i = 8
    while i < n - (n % 8):
        r0 += a[lo + i]
        r1 += a[lo + i + 1]
        r2 += a[lo + i + 2]
        r3 += a[lo + i + 3]
        r4 += a[lo + i + 4]
        r5 += a[lo + i + 5]
        r6 += a[lo + i + 6]
        r7 += a[lo + i + 7]
        i += 8
    res = ((r0 + r1) + (r2 + r3)) + ((r4 + r5) + (r6 + r7))
    while i < n:
        res += a[lo + i]
        i += 1
    return res


@njit(cache=True, error_model="numpy")
def pairwise_sum(a, lo, n):  # pragma: no cover - compiled
    """numpy's pairwise summation of ``a[lo:lo + n]`` (the same result, bit for bit).

    numpy splits a sum of more than 128 terms at ``n2 = n // 2 - (n // 2) % 8`` and adds
    the two halves; the recursion is unrolled here onto an explicit stack (a cached
    numba function that calls a recursive one does not load from the cache).
    """
    if n <= 128:
        return _pairwise_leaf(a, lo, n)
    depth = 64
    s_lo = np.empty(depth, np.int64)
    s_n = np.empty(depth, np.int64)
    s_phase = np.zeros(depth, np.int64)  # 0: not split yet, 1: left pending, 2: right
    s_left = np.empty(depth)
    sp = 0
    s_lo[0] = lo
    s_n[0] = n
    while True:
        cn = s_n[sp]
        if cn > 128 and s_phase[sp] == 0:
            n2 = cn // 2
            n2 -= n2 % 8
            s_phase[sp] = 1
            sp += 1
            s_lo[sp] = s_lo[sp - 1]
            s_n[sp] = n2
            s_phase[sp] = 0
            continue
        r = _pairwise_leaf(a, s_lo[sp], cn)
        sp -= 1
        while sp >= 0:  # hand the result to the parents
            if s_phase[sp] == 1:
                s_left[sp] = r
                s_phase[sp] = 2
                pn = s_n[sp]
                n2 = pn // 2
                n2 -= n2 % 8
                sp += 1
                s_lo[sp] = s_lo[sp - 1] + n2
                s_n[sp] = pn - n2
                s_phase[sp] = 0
                break
            r = s_left[sp] + r
            sp -= 1
        if sp < 0:
            return r


@njit(cache=True, fastmath={"reassoc", "nsz"})
def _bsum(a, m):  # pragma: no cover - compiled
    """Sum of ``a[:m]`` (vectorised: the order of the additions is the compiler's)."""
    s = 0.0
    for t in range(m):
        s += a[t]
    return s


@njit(cache=True, fastmath={"nnan", "nsz"})
def _bminmax(a, m, lo, hi):  # pragma: no cover - compiled
    """(min, max) of ``a[:m]`` and the running ``lo``, ``hi`` (finite values: exact)."""
    for t in range(m):
        v = a[t]
        lo = v if v < lo else lo
        hi = v if v > hi else hi
    return lo, hi
