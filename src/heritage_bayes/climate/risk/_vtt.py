"""The VTT mould-index recursion (Hukka & Viitanen 1999; Ojanen et al. 2010).

Private module, the one place the recursion is written: :func:`vtt_step` (one hour),
:func:`vtt_loop` (draws × hours, plain Python: the readable reference, also used by the
benchmark), ``vtt_kernel`` (the same loop compiled with numba) and :func:`vtt_hours`
(compiled, a block of hours of one series carrying its state; the fused pass of
:mod:`heritage_bayes.climate.risk._fused` calls it). The model:
:func:`heritage_bayes.climate.risk.vtt_mould_index`.
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit
from numba.extending import register_jitable

#: Sensitivity classes (Ojanen et al. 2010): k1 for M < 1, k1 for M >= 1, A, B, C of
#: the maximum index, RHmin [%], and the decline factor Cmat.
SENSITIVITY = {
    "VS": (1.0, 2.0, 1.0, 7.0, 2.0, 80.0, 1.0),
    "S": (0.578, 0.386, 0.3, 6.0, 1.0, 80.0, 0.5),
    "MR": (0.072, 0.097, 0.0, 5.0, 1.5, 85.0, 0.25),
    "R": (0.033, 0.014, 0.0, 3.0, 1.0, 85.0, 0.1),
}


@register_jitable
def vtt_step(Ti, Ri, M, dry, k1_lo, k1_hi, A, B, C, RH_min, C_mat, W, SQ, frozen_decline):
    """One hour of the recursion: the index ``M`` [-] and the hours ``dry`` of the current
    unfavourable period after an hour at ``Ti`` [°C], ``Ri`` [%] (both finite).

    Growth (0 < T < 50 °C and RH at or above the critical RH) follows Hukka & Viitanen
    (1999) with the maximum index and ``k1`` of Ojanen et al. (2010); otherwise the index
    declines (Cmat × 0.00133 /h for the first 6 h, none from 6 to 24 h, 0.000667 /h
    after), or holds at T <= 0 °C when not ``frozen_decline``. Plain Python when called
    from Python, compiled into the numba code that calls it (the fused pass and
    :data:`vtt_kernel`).
    """
    grow = Ti > 0.0 and Ti < 50.0
    RHc = RH_min
    if grow:
        if Ti <= 20.0:
            RHc = -0.00267 * Ti**3 + 0.160 * Ti**2 - 3.13 * Ti + 100.0
            if RHc < RH_min:
                RHc = RH_min
        grow = Ri >= RHc
    if grow:
        x = (RHc - Ri) / (RHc - 100.0)
        M_max = A + B * x - C * x * x
        k1 = k1_lo if M < 1.0 else k1_hi
        k2 = 1.0 - math.exp(2.3 * (M - M_max))
        if k2 < 0.0:
            k2 = 0.0
        # dM/dt [1/h] = k1 k2 / (24·7·exp(-0.68 lnT - 13.9 lnRH + 0.14 W - 0.33 SQ + 66.02))
        M += (
            k1
            * k2
            * math.exp(0.68 * math.log(Ti) + 13.9 * math.log(Ri) - 0.14 * W + 0.33 * SQ - 66.02)
            / 168.0
        )
        return M, 0
    if Ti <= 0.0 and not frozen_decline:
        return M, dry  # frozen: hold the index and the decline clock
    dry += 1
    if dry <= 6:
        M -= 0.00133 * C_mat
    elif dry > 24:
        M -= 0.000667 * C_mat
    if M < 0.0:
        M = 0.0
    return M, dry


def vtt_loop(T, RH, k1_lo, k1_hi, A, B, C, RH_min, C_mat, W, SQ, M0, frozen_decline, omit, out):
    """Mould index for each row of ``T``/``RH`` (draws × hours, °C and %).

    Writes the hourly index into ``out`` when it has the shape of ``T`` (pass an empty
    (0, 0) array to skip) and returns the maximum index of each row (NaN when a NaN
    input was met with ``omit=False``, or when a row has no valid hour).
    """
    d, n = T.shape
    store = out.shape[0] == d and out.shape[1] == n
    peak = np.empty(d)
    for i in range(d):
        M = M0
        dry = 0  # hours since the start of the current unfavourable period
        mx = -1.0
        broken = False
        for t in range(n):
            Ti = T[i, t]
            Ri = RH[i, t]
            if math.isnan(Ti) or math.isnan(Ri):
                if omit:
                    if store:
                        out[i, t] = math.nan
                    continue
                broken = True
                if store:
                    for u in range(t, n):
                        out[i, u] = math.nan
                break
            M, dry = vtt_step(Ti, Ri, M, dry, k1_lo, k1_hi, A, B, C, RH_min, C_mat, W, SQ,
                              frozen_decline)  # fmt: skip
            if store:
                out[i, t] = M
            if M > mx:
                mx = M
        peak[i] = math.nan if (broken or mx < 0.0) else mx
    return peak


vtt_kernel = njit(cache=True, nogil=True)(vtt_loop)


@njit(cache=True, error_model="numpy")
def vtt_hours(T, RH, m, p, frozen_decline, state):  # pragma: no cover - compiled
    """:func:`vtt_step` over the hours ``T[:m]`` [°C], ``RH[:m]`` [%] (finite) of a series,
    carrying ``state`` = [M, hours of the dry spell, max M]; ``p`` = (k1_lo, k1_hi, A,
    B, C, RH_min, C_mat, W, SQ)."""
    k1_lo, k1_hi, A, B, C = p[0], p[1], p[2], p[3], p[4]
    RH_min, C_mat, W, SQ = p[5], p[6], p[7], p[8]
    M = state[0]
    dry = np.int64(state[1])
    mx = state[2]
    for t in range(m):
        M, dry = vtt_step(T[t], RH[t], M, dry, k1_lo, k1_hi, A, B, C, RH_min, C_mat, W, SQ,
                          frozen_decline)  # fmt: skip
        if M > mx:
            mx = M
    state[0] = M
    state[1] = dry
    state[2] = mx
