"""The VTT mould-index recursion (Hukka & Viitanen 1999; Ojanen et al. 2010).

Private module. ``vtt_loop`` is plain Python (the readable reference, also used by the
benchmark); ``vtt_kernel`` is the same function compiled with numba, looping over draws ×
hours. See :func:`heritage_bayes.climate.risk.vtt_mould_index` for the model.
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit

#: Sensitivity classes (Ojanen et al. 2010): k1 for M < 1, k1 for M >= 1, A, B, C of
#: the maximum index, RHmin [%], and the decline factor Cmat.
SENSITIVITY = {
    "VS": (1.0, 2.0, 1.0, 7.0, 2.0, 80.0, 1.0),
    "S": (0.578, 0.386, 0.3, 6.0, 1.0, 80.0, 0.5),
    "MR": (0.072, 0.097, 0.0, 5.0, 1.5, 85.0, 0.25),
    "R": (0.033, 0.014, 0.0, 3.0, 1.0, 85.0, 0.1),
}


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
                    * math.exp(
                        0.68 * math.log(Ti) + 13.9 * math.log(Ri) - 0.14 * W + 0.33 * SQ - 66.02
                    )
                    / 168.0
                )
                dry = 0
            elif Ti <= 0.0 and not frozen_decline:
                pass  # frozen: hold the index and the decline clock
            else:
                dry += 1
                if dry <= 6:
                    M -= 0.00133 * C_mat
                elif dry > 24:
                    M -= 0.000667 * C_mat
                if M < 0.0:
                    M = 0.0
            if store:
                out[i, t] = M
            if M > mx:
                mx = M
        peak[i] = math.nan if (broken or mx < 0.0) else mx
    return peak


vtt_kernel = njit(cache=True, nogil=True)(vtt_loop)
