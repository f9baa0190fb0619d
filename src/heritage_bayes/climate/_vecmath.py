"""Elementary functions that the compiler can vectorise, for numba kernels.

Private module. ``math.exp``, ``math.log`` and ``math.cosh`` compile to calls of the C
library, one value at a time; a loop that calls them is never vectorised (numba has no
vector maths library here). The functions below are plain arithmetic (range reduction
by bit manipulation of the IEEE-754 double, a polynomial, the exponent put back by bit
manipulation), so a loop over an array of hours compiles to SIMD code (eight doubles
per instruction with AVX-512).

Accuracy: within 2 units in the last place of numpy's result for normal results
(``tests/test_fused_risk.py`` asserts a relative error ≤ 4.5e-16 on random arguments
over the whole normal range), with the special values of the C library
(``vexp(-inf) = 0``, ``vexp(inf) = inf``, ``vlog(0) = -inf``, ``vlog(x < 0) = nan``,
NaN propagated; subnormal arguments of ``vlog`` and subnormal results of ``vexp``
handled, the latter with the few-ulp error any subnormal result has).

``psat_water`` is :func:`heritage_bayes.climate.psychro.saturation_vapour_pressure`
(over water, Wagner & Pruß 1993) in this form: the fractional powers
:math:`\\vartheta^{1.5}, \\vartheta^{3.5}, \\vartheta^{7.5}` are products with
:math:`\\sqrt{\\vartheta}` instead of ``pow`` calls, and products with ``1 / T``: relative
difference ≤ 2e-14 from numpy (asserted by ``tests/test_fused_risk.py`` on 200 000
random temperatures, −60…99 °C).
"""

from __future__ import annotations

import hashlib
import math
from pathlib import Path

import numpy as np
from llvmlite import ir
from numba import njit, types
from numba.core.registry import CPUDispatcher
from numba.extending import intrinsic


def stamp_cache(namespace: dict, *depends) -> None:
    """Make numba's on-disk cache of every compiled function in ``namespace`` (a module's
    ``globals()``) depend on the source of the modules ``depends`` as well.

    numba re-compiles a cached function when its own file changes, not when a function
    it calls from another file does: the cached machine code would keep the old callee
    (wrong results, or a crash). Adding a hash of the callees' files to the cache's
    source stamp closes that gap. Uses numba's cache internals; if they change, the
    stamp is left as numba makes it.
    """
    h = hashlib.sha256()
    for m in depends:
        h.update(Path(m.__file__).read_bytes())
    digest = h.hexdigest()[:16]
    for obj in list(namespace.values()):
        if not isinstance(obj, CPUDispatcher) or obj.py_func.__module__ != namespace["__name__"]:
            continue
        cache_file = getattr(getattr(obj, "_cache", None), "_cache_file", None)
        stamp = getattr(cache_file, "_source_stamp", None)
        if isinstance(stamp, tuple):
            cache_file._source_stamp = (*stamp, digest)
        elif isinstance(stamp, bytes | str):  # numba >= 0.61: a hash of the source
            extra = digest.encode() if isinstance(stamp, bytes) else digest
            cache_file._source_stamp = stamp + extra


@intrinsic
def _as_double(typingctx, x):
    """Reinterpret the bits of an int64 as a float64 (no conversion)."""
    sig = types.float64(types.int64)

    def codegen(context, builder, signature, args):
        return builder.bitcast(args[0], ir.DoubleType())

    return sig, codegen


@intrinsic
def _as_int(typingctx, x):
    """Reinterpret the bits of a float64 as an int64 (no conversion)."""
    sig = types.int64(types.float64)

    def codegen(context, builder, signature, args):
        return builder.bitcast(args[0], ir.IntType(64))

    return sig, codegen


_LOG2E = 1.4426950408889634
# ln 2 split so that k * _LN2_HI is exact for |k| < 2**11 (Cody & Waite)
_LN2_HI = 6.93147180369123816490e-01
_LN2_LO = 1.90821492927058770002e-10
_SQRT2 = 1.4142135623730951
_TINY = 2.2250738585072014e-308  # smallest normal double
_TWO54 = 18014398509481984.0
_MANT = 0x000FFFFFFFFFFFFF
_ONE_BITS = 0x3FF0000000000000


@njit(inline="always", cache=True, error_model="numpy")
def vexp(x):
    """exp(x) [-], vectorisable (see the module docstring)."""
    xc = min(max(x, -746.0), 710.0)
    k = math.floor(xc * _LOG2E + 0.5)
    r = xc - k * _LN2_HI - k * _LN2_LO  # |r| <= ln2 / 2
    # Taylor series to degree 13: truncation below 2e-16 relative on |r| <= 0.347
    p = 1.0 / 6227020800.0
    p = p * r + 1.0 / 479001600.0
    p = p * r + 1.0 / 39916800.0
    p = p * r + 1.0 / 3628800.0
    p = p * r + 1.0 / 362880.0
    p = p * r + 1.0 / 40320.0
    p = p * r + 1.0 / 5040.0
    p = p * r + 1.0 / 720.0
    p = p * r + 1.0 / 120.0
    p = p * r + 1.0 / 24.0
    p = p * r + 1.0 / 6.0
    p = p * r + 0.5
    p = p * r + 1.0
    p = p * r + 1.0
    ki = np.int64(k)
    k1 = ki >> 1  # 2**k in two factors: no overflow of the exponent field
    k2 = ki - k1
    y = p * _as_double((k1 + 1023) << 52) * _as_double((k2 + 1023) << 52)
    return x if x != x else y


@njit(inline="always", cache=True, error_model="numpy")
def vlog(x):
    """Natural logarithm of x, vectorisable (see the module docstring)."""
    small = x < _TINY
    xs = x * _TWO54 if small else x
    bits = _as_int(xs)
    e = (bits >> 52) - (1023 + 54 if small else 1023)
    m = _as_double((bits & _MANT) | _ONE_BITS)  # in [1, 2)
    big = m > _SQRT2
    m = m * 0.5 if big else m
    ef = np.float64(e + 1 if big else e)
    s = (m - 1.0) / (m + 1.0)  # |s| <= 0.1716
    z = s * s
    # 2 atanh(s) = 2 (s + s^3/3 + ... ): truncation below 1e-17 relative at degree 23
    p = 1.0 / 23.0
    p = p * z + 1.0 / 21.0
    p = p * z + 1.0 / 19.0
    p = p * z + 1.0 / 17.0
    p = p * z + 1.0 / 15.0
    p = p * z + 1.0 / 13.0
    p = p * z + 1.0 / 11.0
    p = p * z + 1.0 / 9.0
    p = p * z + 1.0 / 7.0
    p = p * z + 1.0 / 5.0
    p = p * z + 1.0 / 3.0
    lm = 2.0 * s + 2.0 * s * (z * p)
    y = ef * _LN2_HI + (lm + ef * _LN2_LO)
    if x == 0.0:
        y = -math.inf
    if x < 0.0 or x != x:
        y = math.nan
    if x == math.inf:
        y = math.inf
    return y


@njit(inline="always", cache=True, error_model="numpy")
def vcosh(x):
    """cosh(x), vectorisable."""
    e = vexp(abs(x))
    return 0.5 * (e + 1.0 / e)


# Wagner & Pruß (1993), as in heritage_bayes.climate.psychro
_TC = 647.096  # [K]
_PC = 22.064e6  # [Pa]
_A1, _A2, _A3, _A4, _A5, _A6 = (
    -7.85951783,
    1.84408259,
    -11.7866497,
    22.6807411,
    -15.9618719,
    1.80122502,
)


@njit(inline="always", cache=True, error_model="numpy")
def psat_water(T):
    """Saturation vapour pressure over water [Pa] at T [°C], vectorisable."""
    TK = T + 273.15
    th = 1.0 - TK * (1.0 / _TC)
    sq = math.sqrt(th)
    th3 = th * th * th
    poly = (
        _A1 * th
        + _A2 * (th * sq)
        + _A3 * th3
        + _A4 * (th3 * sq)
        + _A5 * (th3 * th)
        + _A6 * (th3 * th3 * th * sq)
    )
    return _PC * vexp(_TC * (1.0 / TK) * poly)
