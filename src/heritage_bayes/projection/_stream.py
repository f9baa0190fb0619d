"""The compiled hot path of a projection: one chunk of posterior draws on one weather.

Private module (used by :mod:`heritage_bayes.projection.engine`). For each draw of the
chunk, on one thread (numba ``prange`` over work slots, one slot per thread):

1. the noise-free indoor temperature ``Ti`` [°C] and vapour pressure ``Pi`` [Pa]:
   simulated here for a free-running model (the modal recursion of
   :func:`heritage_bayes.rc.simulate.modal_simulate`, one draw at a time), or copied from
   ``model.forward`` for a controlled one;
2. the noise-free RH [%] (capped at saturation), and every risk indicator of that
   series (:func:`heritage_bayes.climate.risk._fused.series_indicators`; the series are
   kept for the engine when a family without a compiled pass is selected);
3. with noise: ``Ti + e_T``, the RH from ``Pi + e_P``, their indicators, and the monthly
   means of ``Ti`` and ``RHi`` (numpy's pairwise summation, as ``np.add.reduceat``).

A draw's series live in four arrays of the slot (≈ 8 MB for 30 years of hours) and in
the CPU cache while they are reduced: nothing of size draws × hours is formed apart
from the noise draws, which the caller shares between cases.
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit, prange

from heritage_bayes.climate import _vecmath
from heritage_bayes.climate._vecmath import psat_water, stamp_cache
from heritage_bayes.climate.risk import _fused, _sums, _vtt, indicators
from heritage_bayes.climate.risk._fused import (
    BLOCK,
    _bsum,
    inv_pi,
    lim_rh,
    pairwise_sum,
    series_indicators,
    wet,
)
from heritage_bayes.climate.risk.registry import ANNUAL
from heritage_bayes.rc import control_kernels as _control
from heritage_bayes.rc.control_kernels import coupled_draw


@njit(cache=True, error_model="numpy")
def _modal(ad, Bdz, edz, Cz, z0, Ut, y, z, W):  # pragma: no cover - compiled
    """One draw of the modal recursion: ``y[k] = Cz·z[k]``, ``z[k+1] = ad z[k] + Bdz u[k]
    + edz``, with the inputs by column (``Ut``: inputs × hours).

    The arithmetic of :func:`heritage_bayes.rc.simulate.modal_simulate` (forcing summed
    over the inputs, plus the constant term, then the recursion), with the forcing of a
    block of hours computed first (vectorised) in ``W`` (modes × BLOCK).
    """
    n = ad.size
    m, N = Ut.shape
    for j in range(n):
        z[j] = z0[j]
    for b0 in range(0, N, BLOCK):
        nb = min(BLOCK, N - b0)
        for j in range(n):
            wj = W[j]
            for t in range(nb):
                wj[t] = 0.0
            for q in range(m):
                u = Ut[q, b0 : b0 + nb]
                bq = Bdz[j, q]
                for t in range(nb):
                    wj[t] += u[t] * bq
            e = edz[j]
            for t in range(nb):
                wj[t] += e
        yb = y[b0 : b0 + nb]
        if n == 2:  # the two-capacity models: the states in registers
            z_0, z_1 = z[0], z[1]
            a0, a1, c0, c1 = ad[0], ad[1], Cz[0], Cz[1]
            w0, w1 = W[0], W[1]
            for t in range(nb):
                yb[t] = 0.0 + c0 * z_0 + c1 * z_1
                z_0 = a0 * z_0 + w0[t]
                z_1 = a1 * z_1 + w1[t]
            z[0], z[1] = z_0, z_1
        else:
            for t in range(nb):
                acc = 0.0
                for j in range(n):
                    acc += Cz[j] * z[j]
                yb[t] = acc
                for j in range(n):
                    z[j] = ad[j] * z[j] + W[j, t]


@njit(inline="always", cache=True, error_model="numpy")
def _rh(T, P):
    """RH [%] from T [°C] and vapour pressure [Pa], capped to 0–100 % (NaN kept)."""
    r = 100.0 * P / psat_water(T)
    r = 0.0 if r < 0.0 else r
    return 100.0 if r > 100.0 else r


@njit(cache=True, error_model="numpy")
def _monthly(x, starts, out):  # pragma: no cover - compiled
    """Monthly means of ``x`` (months begin at ``starts``; the last ends at ``x.size``)."""
    nm = starts.size
    for j in range(nm):
        a = starts[j]
        b = starts[j + 1] if j + 1 < nm else x.size
        out[j] = (x[a] + pairwise_sum(x, a + 1, b - a - 1)) / (b - a)


#: Per-year columns of :func:`annual_values` (index in its ``out`` rows): the registry's
#: ``per_year`` indicators (:data:`heritage_bayes.climate.risk.registry.ANNUAL`).
A_TWPI, A_TOW, A_LIM, A_BAND = (ANNUAL.index(k) for k in ("twpi", "time_of_wetness",
                                                          "hours_above_LIM",
                                                          "en15757_outside_baseline"))  # fmt: skip
#: Hour-of-year bins of the baseline seasonal cycle (365 days × 24 h; 29 February is
#: read as 28 February).
HOY = 8760


@njit(cache=True, error_model="numpy")
def annual_values(T, RH, N, hoy, mode, en, band, out, ma, cnt):  # pragma: no cover
    """Per complete year: TWPI [years], time of wetness [h/year], hours above the
    lowest isopleth [h/year] and the share of hours outside the baseline EN 15757
    band [% of hours] of the series ``T[:N]`` [°C], ``RH[:N]`` [%].

    Years are consecutive blocks of 8760 h from the start (one block of ``N`` hours
    when ``8736 <= N < 8760``); ``out`` is (years, 4).

    ``en`` = (mode flag, half window [h], wrap, lower offset, upper offset, LIM
    constant ``c``): with ``mode == 1`` (the baseline of this draw) the seasonal cycle
    (centred moving average of ``RH``, ``2 half + 1`` hours, periodic when ``wrap``,
    else truncated at the ends as :func:`~heritage_bayes.climate.risk.en15757_band`)
    is averaged by hour of the year (``hoy``) into ``band[:8760]``, and the offsets
    are stored in ``band[8760:8762]``; with ``mode == 2`` (a future of the same draw)
    ``band`` is read. Hours outside ``band[hoy] + [lower, upper]`` are counted.
    ``mode == 0``: no band (NaN). ``ma`` (N,) and ``cnt`` (8760,) are work arrays.
    """
    L = 8760 if N >= 8760 else N
    ny = N // L
    half = int(en[1])
    wrap = en[2] != 0.0
    limc = en[5]
    if mode == 1:
        run = 0.0  # centred moving average from a running sum (np.cumsum order)
        w = 2 * half + 1
        for t in range(N):
            a = t - half
            b = t + half + 1
            if wrap:
                s = 0.0
                if t == 0:
                    for j in range(a, b):
                        s += RH[j % N]
                    run = s
                else:
                    run += RH[(b - 1) % N] - RH[(a - 1) % N]
                ma[t] = run / w
            else:
                lo = a if a > 0 else 0
                hi = b if b < N else N
                if t == 0:
                    run = 0.0
                    for j in range(lo, hi):
                        run += RH[j]
                else:
                    if b <= N:
                        run += RH[b - 1]
                    if a - 1 >= 0:
                        run -= RH[a - 1]
                ma[t] = run / (hi - lo)
        for j in range(HOY):
            band[j] = 0.0
            cnt[j] = 0.0
        for t in range(N):
            band[hoy[t]] += ma[t]
            cnt[hoy[t]] += 1.0
        first = -1
        for j in range(HOY):
            if cnt[j] > 0:
                band[j] /= cnt[j]
                if first < 0:
                    first = j
        last = band[first]  # bins the baseline never saw: the previous bin (cyclic)
        for j in range(HOY):
            jj = (first + j) % HOY
            if cnt[jj] > 0:
                last = band[jj]
            else:
                band[jj] = last
        band[HOY] = en[3]
        band[HOY + 1] = en[4]
    has_lim = limc == limc
    lo_off = band[HOY] if mode != 0 else 0.0
    hi_off = band[HOY + 1] if mode != 0 else 0.0
    w = np.empty(BLOCK)
    for y in range(ny):
        inv_pi_sum = 0.0
        n_wet = 0
        lim = 0
        out_band = 0
        for b0 in range(y * L, (y + 1) * L, BLOCK):  # blocks: the loops vectorise
            m = min(BLOCK, (y + 1) * L - b0)
            Tb = T[b0 : b0 + m]
            RHb = RH[b0 : b0 + m]
            for t in range(m):  # 1 / PI (chemical._pi), as in the fused pass
                x = Tb[t]
                r = RHb[t]
                w[t] = inv_pi(1.0 / (x + 273.15), r)
            inv_pi_sum += _bsum(w, m)
            for t in range(m):  # ISO 9223 time of wetness
                n_wet += wet(Tb[t], RHb[t])
            if has_lim:
                for t in range(m):  # lowest isopleth for mould (biological._lim)
                    lim += 1 if RHb[t] > lim_rh(Tb[t], limc) else 0
            if mode != 0:
                hb = hoy[b0 : b0 + m]
                for t in range(m):
                    c = band[hb[t]]
                    r = RHb[t]
                    out_band += 1 if (r < c + lo_off) or (r > c + hi_off) else 0
        out[y, A_TWPI] = L / inv_pi_sum
        out[y, A_TOW] = n_wet / L * 8760.0
        out[y, A_LIM] = lim / L * 8760.0 if has_lim else math.nan
        out[y, A_BAND] = 100.0 * out_band / L if mode != 0 else math.nan


@njit(cache=True, error_model="numpy")
def _annual_row(T, RH, N, hoy, mode, en, en_col, row, band, out, ma, cnt):  # pragma: no cover
    """:func:`annual_values` of one series, the band offsets taken from its indicator
    ``row`` (columns ``en_col``, ``en_col + 1``) when it is the baseline."""
    e = en.copy()
    if mode == 1:
        e[3] = row[en_col]
        e[4] = row[en_col + 1]
    annual_values(T, RH, N, hoy, mode if en_col >= 0 else 0, e, band, out, ma, cnt)


@njit(cache=True, error_model="numpy")
def _reduce(T, RH, N, ea_r, fpar, ipar, kinds, cls, ws, tmp, btmp, hist, vals, hoy, mode, en,
            en_col, band, ann, ma, cnt):  # fmt: skip  # pragma: no cover - compiled
    """One series reduced: its indicators into ``vals`` (status returned, as
    :func:`series_indicators`) and its per-year values into ``ann``
    (:func:`_annual_row`)."""
    st = series_indicators(T, RH, N, ea_r, fpar, ipar, kinds, cls, ws, tmp, btmp, hist, vals)
    _annual_row(T, RH, N, hoy, mode, en, en_col, vals, band, ann, ma, cnt)
    return st


@njit(parallel=True, cache=True, error_model="numpy")
def chunk_kernel(
    YT, YP, mT, mP, UT, UP, eT, eP, noise, starts,
    ea_r, fpar, ipar, kinds, cls, ws, tmp, btmp, hist, sbuf, zbuf, wbuf,
    par, pred, spar, spred, Tm, RHm,
    hoy, mode, en, en_col, bpar, bpred, apar, apred, mabuf, cbuf,
    ctl, bdT, bdP, sig, spin, cost, par_on, kept,
):  # fmt: skip  # pragma: no cover - compiled
    """Indicators (noise-free → ``par``, predictive → ``pred``; status 0/1 in ``spar``,
    ``spred``) and monthly means (``Tm``, ``RHm``) of every draw of the chunk.

    ``YT``/``YP``: (draws, hours) outputs of ``model.forward``, or (0, 0) to simulate
    here from the modal arrays ``mT``/``mP`` = (ad, Bdz, edz, Cz, z0) with inputs
    ``UT``/``UP`` (inputs × hours); ``eT``/``eP``: (draws, hours) noise (used when ``noise``).

    Per complete year (:func:`annual_values`, noise-free → ``apar``, predictive →
    ``apred``, (draws, years, 4)): with ``mode`` 1 (the baseline) the draw's EN 15757
    band is built into ``bpar``/``bpred`` (draws, 8762) from the offsets in the columns
    ``en_col``, ``en_col + 1`` of its indicators; with ``mode`` 2 (a future) it is read.
    ``en`` = (mode, half window, wrap, -, -, LIM constant), ``hoy`` (hours,) the hour of
    the year of each hour; ``mabuf`` (slots, hours) and ``cbuf`` (slots, 8760) work.

    An intervention (``ctl`` (draws, :data:`~heritage_bayes.rc.control_kernels.N_CP`), (0, ·)
    for none): both models are stepped together with their controllers
    (:func:`heritage_bayes.rc.control_kernels.coupled_draw`, modal arrays as above, unit-flow
    responses ``bdT``/``bdP`` (draws, n), hours of use ``sig`` (hours,), periodic
    spin-up over ``spin`` steps), running-cost sums into ``cost`` (draws,
    :data:`~heritage_bayes.rc.control_kernels.N_COST`). ``par_on`` False (with ``noise``): the
    noise-free indicators are not computed (NaN; a measure is compared predictive
    with predictive).

    ``kept`` (4, draws, hours), or (0, 0, 0) for none: the series reduced, kept for the
    families without a compiled pass (noise-free ``T``, ``RH``, then predictive).
    """
    c = par.shape[0]
    N = sbuf.shape[2]
    slots = ws.shape[0]
    simT = YT.shape[0] == 0
    simP = YP.shape[0] == 0
    keep = kept.shape[0] > 0
    for s in prange(slots):
        Ts, Ps, Tx, RHx = sbuf[s, 0], sbuf[s, 1], sbuf[s, 2], sbuf[s, 3]
        for i in range(s, c, slots):
            if ctl.shape[0] > 0:
                wb = wbuf[s]
                nT = mT[0].shape[1]
                nP = mP[0].shape[1]
                coupled_draw(
                    mT[0][i], mT[1][i], mT[2][i], mT[3][i], mT[4][i], UT,
                    mP[0][i], mP[1][i], mP[2][i], mP[3][i], mP[4][i], UP,
                    bdT[i], bdP[i], ctl[i], sig, spin, Ts, Ps, cost[i],
                    wb[0, :nT], wb[1, :nP], wb[2, :nT], wb[3, :nP],
                )  # fmt: skip
            else:
                if simT:
                    _modal(mT[0][i], mT[1][i], mT[2][i], mT[3][i], mT[4][i], UT, Ts, zbuf[s],
                           wbuf[s])  # fmt: skip
                else:
                    Ts[:] = YT[i]
                if simP:
                    _modal(mP[0][i], mP[1][i], mP[2][i], mP[3][i], mP[4][i], UP, Ps, zbuf[s],
                           wbuf[s])  # fmt: skip
                else:
                    Ps[:] = YP[i]
            if par_on or not noise:
                for t in range(N):
                    RHx[t] = _rh(Ts[t], Ps[t])
                spar[i] = _reduce(Ts, RHx, N, ea_r, fpar, ipar, kinds, cls, ws[s], tmp[s],
                                  btmp[s], hist[s], par[i], hoy, mode, en, en_col, bpar[i],
                                  apar[i], mabuf[s], cbuf[s])  # fmt: skip
                if keep:
                    kept[0, i, :] = Ts
                    kept[1, i, :] = RHx
            else:
                spar[i] = 0
                par[i, :] = math.nan
                apar[i, :, :] = math.nan
            if noise:
                ei = eT[i]
                pi = eP[i]
                for t in range(N):
                    x = Ts[t] + ei[t]
                    Tx[t] = x
                    RHx[t] = _rh(x, Ps[t] + pi[t])
                spred[i] = _reduce(Tx, RHx, N, ea_r, fpar, ipar, kinds, cls, ws[s], tmp[s],
                                   btmp[s], hist[s], pred[i], hoy, mode, en, en_col, bpred[i],
                                   apred[i], mabuf[s], cbuf[s])  # fmt: skip
                if keep:
                    kept[2, i, :] = Tx
                    kept[3, i, :] = RHx
                _monthly(Tx, starts, Tm[i])
            else:
                spred[i] = spar[i]
                pred[i, :] = par[i, :]
                bpred[i, :] = bpar[i, :]
                apred[i, :, :] = apar[i, :, :]
                _monthly(Ts, starts, Tm[i])
            _monthly(RHx, starts, RHm[i])


stamp_cache(globals(), _fused, _vecmath, _control, _sums, _vtt, indicators)
