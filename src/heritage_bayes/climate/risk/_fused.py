"""Every indicator of :func:`~heritage_bayes.climate.risk.assess` for one hourly series,
in one compiled function (numba).

Private module; the plan (the options turned into arrays) and the Python entry points
are in :mod:`heritage_bayes.climate.risk.fused`. :func:`series_indicators` reads the
series a few times (hours in blocks of :data:`BLOCK`, so the temporaries stay in the
CPU cache) and writes one row of indicators; it is callable from other compiled code
(the projection kernel calls it twice per posterior draw).

Same arithmetic as the numpy code of the mechanism modules, with these differences, all
at the level of rounding (the aggregates agree with
:func:`~heritage_bayes.climate.risk.assess_batch` to the 1e-12 relative that
``tests/test_fused_risk.py`` asserts):

* exp, log and cosh are the vectorisable versions of :mod:`heritage_bayes.climate._vecmath`
  (within 2 ulp of the C library); the reciprocals of the lifetime multiplier and of the
  preservation index are computed as ``exp(-x)`` instead of ``1 / exp(x)``, with one
  division per hour (``log(RH_ref) − log(RH)``, products with ``1 / T``);
* the harmonic means sum the hours in blocks (numpy: pairwise summation).

Bit for bit the same as numpy: the moving averages (sequential cumulative sums, as
``np.cumsum``), the annual means (numpy's pairwise summation, re-implemented), the ASHRAE
and EN 15757 comparisons, the EMC, the VTT recursion and the percentiles (exact order
statistics found by a histogram of the values, then numpy's linear interpolation).

Layout: :func:`series_indicators` and its block helpers are one compiled algorithm over
the plan's parameter arrays, whose positions (the ``I_``/``F_`` names below) are derived
from the parameter names each family of :mod:`heritage_bayes.climate.risk.indicators`
declares (:data:`~heritage_bayes.climate.risk.indicators.LAYOUT`). The VTT recursion is
:func:`heritage_bayes.climate.risk._vtt.vtt_hours`, the sums are in ``_sums``. numba
caches a compiled function by its own source file, so this module's cache is stamped
with the files it reads (:func:`heritage_bayes.climate._vecmath.stamp_cache`).
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit

from heritage_bayes.climate import _vecmath
from heritage_bayes.climate._vecmath import stamp_cache, vcosh, vexp, vlog
from heritage_bayes.climate.risk import _sums, _vtt, indicators
from heritage_bayes.climate.risk._sums import _bminmax, _bsum, pairwise_sum
from heritage_bayes.climate.risk._vtt import vtt_hours
from heritage_bayes.climate.risk.indicators import LAYOUT

#: Hours processed together by the vectorised loops.
BLOCK = 512
#: Bins of the histogram that locates the EN 15757 percentiles.
N_BINS = 4096
_EPS = 1e-9  # as heritage_bayes.climate.risk.standards._EPS (tolerance on limits)
_T0 = 273.15

# positions in the parameter arrays, derived from the families' parameter names
_L = LAYOUT
I_CHEM, I_MECH, I_MOULD, I_ASHRAE, I_EN = (_L.i(f) for f in ("chemical", "mechanical", "mould",
                                                             "ashrae", "en15757"))  # fmt: skip
I_NEA = _L.i("chemical.nea")
I_FROZEN = _L.i("mould.frozen_decline")
I_HALF_A, I_WRAP_A, I_METHOD, I_NESTED, I_NCLS, I_HAS_TSP, I_HAS_RHSP = (
    _L.i(f"ashrae.{p}") for p in ("half", "wrap", "setpoint", "nested", "n_classes",
                                  "has_T_setpoint", "has_RH_setpoint")
)  # fmt: skip
I_HALF_E, I_WRAP_E, I_SHARED, I_EN_WIDTH = (
    _L.i(f"en15757.{p}") for p in ("half", "wrap", "shared", "width")
)
F_TREF_INV, F_RHREF, F_N = (_L.f(f"chemical.{p}") for p in ("tref_inv", "rh_ref", "n"))
F_COEF = _L.f("mechanical.coefficient")
F_VTT, F_M0, F_LIMC = _L.f("mould.k1_lo"), _L.f("mould.M0"), _L.f("mould.lim_c")
F_THR, F_TSP, F_RHSP = (_L.f(f"ashrae.{p}") for p in ("threshold", "T_setpoint", "RH_setpoint"))
F_QLO, F_QHI, F_MINBAND = (_L.f(f"en15757.{p}") for p in ("q_lo", "q_hi", "min_band"))
# columns of the class table (cls): raw ClimateClass values, NaN for None
C_TS, C_TDOWN, C_TUP, C_TSMAX, C_TMAX, C_RS, C_RDOWN, C_RUP, C_RLO, C_RHI = range(10)
N_CLS = 10
# kinds of set-point check (see standards._setpoint_ok)
K_NONE, K_MEAN, K_SEASON, K_SETPOINT = range(4)


@njit(cache=True, error_model="numpy")
def _bad_hours(T, RH, n):  # pragma: no cover - compiled
    """Hours that ``hourly()`` would reject or that are missing, and the RH ranges."""
    bad = 0
    above1 = 0
    above0 = 0
    for t in range(n):
        x = T[t]
        r = RH[t]
        bad += 0 if (x >= -100.0 and x <= 100.0 and r >= 0.0 and r <= 100.0) else 1
        above1 += 1 if r > 1.0 else 0
        above0 += 1 if r > 0.0 else 0
    return bad, above1, above0


@njit(inline="always", cache=True, error_model="numpy")
def inv_pi(inv_TK, r):  # pragma: no cover - compiled
    """1 / PI(T, RH) [1/years] of ``chemical._pi`` from ``1 / (T + 273.15)`` [1/K] and
    RH [%]: ``PI = exp(a) / 365`` inverted as ``365 exp(-a)`` (vectorised exp)."""
    return 365.0 * vexp(-((95220.0 - 134.9 * r) * (inv_TK / 8.314) + 0.0284 * r - 28.023))


@njit(inline="always", cache=True, error_model="numpy")
def wet(x, r):  # pragma: no cover - compiled
    """1 for an hour of ISO 9223 time of wetness (RH > 80 % and T > 0 °C), else 0."""
    return 1 if (r > 80.0) and (x > 0.0) else 0


@njit(inline="always", cache=True, error_model="numpy")
def lim_rh(x, c):  # pragma: no cover - compiled
    """The lowest isopleth for mould [%] at ``x`` [°C] (``biological._lim``, constant
    ``c`` of the growth rate)."""
    return 100.0 * (0.02633 * vcosh(0.10083 * (x - 30.0)) + c)


@njit(cache=True, error_model="numpy")
def _pointwise(T, RH, b0, m, fpar, ipar, ea_r, tmp, sums):  # pragma: no cover - compiled
    """Chemical and mechanical indicators and the isopleth count of one block.

    ``sums``: [1/LM per activation energy..., 1/PI, EMC min, EMC max, hours above LIM,
    wet hours].
    """
    nea = ipar[I_NEA]
    u = tmp[0]
    lr = tmp[1]
    w = tmp[2]
    Tb = T[b0 : b0 + m]  # views: the loops below index from 0 (vectorised)
    RHb = RH[b0 : b0 + m]
    if ipar[I_CHEM]:
        tref_inv = fpar[F_TREF_INV]
        rh_ref = fpar[F_RHREF]
        n_exp = fpar[F_N]
        log_ref = math.log(rh_ref)
        for t in range(m):
            x = Tb[t]
            r = RHb[t]
            inv_TK = 1.0 / (x + _T0)  # the one division (products below)
            u[t] = inv_TK - tref_inv
            lr[t] = n_exp * (log_ref - vlog(r))  # n log(RH_ref / RH)
            w[t] = inv_pi(inv_TK, r)
        sums[nea] += _bsum(w, m)
        n_wet = 0
        for t in range(m):  # ISO 9223 time of wetness
            n_wet += wet(Tb[t], RHb[t])
        sums[nea + 4] += n_wet
        for k in range(nea):
            e = ea_r[k]
            for t in range(m):
                w[t] = vexp(-(e * u[t] + lr[t]))  # 1 / LM
            sums[k] += _bsum(w, m)
    if ipar[I_MECH]:
        for t in range(m):
            x = Tb[t]
            h = RHb[t] / 100.0  # mechanical._emc, term by term
            W = 349.0 + 1.29 * x + 0.0135 * x * x
            K = 0.805 + 7.36e-4 * x - 2.73e-6 * x * x
            K1 = 6.27 - 9.38e-3 * x - 3.03e-4 * x * x
            K2 = 1.91 + 0.0407 * x - 2.93e-4 * x * x
            Kh = K * h
            KKh = K1 * Kh
            KKKh2 = K1 * K2 * Kh * Kh
            w[t] = (1800.0 / W) * (Kh / (1.0 - Kh) + (KKh + 2.0 * KKKh2) / (1.0 + KKh + KKKh2))
        lo, hi = _bminmax(w, m, sums[nea + 1], sums[nea + 2])
        sums[nea + 1] = lo
        sums[nea + 2] = hi
    if ipar[I_MOULD]:
        c = fpar[F_LIMC]
        cnt = 0
        for t in range(m):
            x = Tb[t]
            cnt += 1 if RHb[t] > lim_rh(x, c) else 0
        sums[nea + 3] += cnt


@njit(cache=True, error_model="numpy")
def _cumsum_block(x, m, cs):  # pragma: no cover - compiled
    """``cs[t + 1] = cs[t] + x[t]`` for the block (``cs[0]`` holds the running sum)."""
    s = cs[0]
    for t in range(m):
        s = s + x[t]
        cs[t + 1] = s


@njit(cache=True, error_model="numpy")
def _cumsum(x, n, half, wrap, cs):  # pragma: no cover - compiled
    """Cumulative sums of ``x`` (padded periodically by ``half`` when ``wrap``) into
    ``cs``, as ``_inputs.centred_mean`` builds them (``np.cumsum``: sequential)."""
    cs[0] = 0.0
    s = 0.0
    j = 1
    if wrap:
        for t in range(n - half, n):
            s = s + x[t]
            cs[j] = s
            j += 1
    for t in range(n):
        s = s + x[t]
        cs[j] = s
        j += 1
    if wrap:
        for t in range(half):
            s = s + x[t]
            cs[j] = s
            j += 1


@njit(cache=True, error_model="numpy")
def _centred(cs, b0, m, n, half, wrap, dst):  # pragma: no cover - compiled
    """Centred moving average of hours ``b0 … b0 + m`` from the sums ``cs``."""
    w = np.float64(2 * half + 1)
    if wrap:
        hi = cs[b0 + 2 * half + 1 : b0 + 2 * half + 1 + m]
        lo = cs[b0 : b0 + m]
        for t in range(m):
            dst[t] = (hi[t] - lo[t]) / w
        return
    # full windows for b0 + t in [half, n - half - 1]; truncated ones at the ends
    t0 = min(max(half - b0, 0), m)
    t1 = max(min(n - half - b0, m), t0)
    for t in range(t0):
        i = b0 + t
        a = max(i - half, 0)
        b = min(i + half + 1, n)
        dst[t] = (cs[b] - cs[a]) / np.float64(b - a)
    hi = cs[b0 + t0 + half + 1 : b0 + t1 + half + 1]
    lo = cs[b0 + t0 - half : b0 + t1 - half]
    d = dst[t0:t1]
    for t in range(t1 - t0):
        d[t] = (hi[t] - lo[t]) / w
    for t in range(t1, m):
        i = b0 + t
        a = max(i - half, 0)
        b = min(i + half + 1, n)
        dst[t] = (cs[b] - cs[a]) / np.float64(b - a)


@njit(cache=True, error_model="numpy")
def _var_pass(
    kind, x, s, m, mean, short, down, up, smax, vmin, vmax, below, nested
):  # pragma: no cover
    """One variable of one class over a block: ``below[t]`` becomes "hour t meets the
    class's limits on this variable" (standards._setpoint_ok and the absolute bounds
    ``[vmin, vmax]``), and also the previous content of ``below`` when ``nested``."""
    keep = not nested  # 1: ignore what ``below`` held
    lim = short + _EPS
    lo = vmin - _EPS
    hi = vmax + _EPS
    if kind == K_NONE:
        for t in range(m):
            v = x[t]
            below[t] = (v >= lo) & (v <= hi) & ((below[t] != 0) | keep)
    elif kind == K_MEAN:
        for t in range(m):
            v = x[t]
            ok = abs(v - mean) <= lim
            below[t] = ok & (v >= lo) & (v <= hi) & ((below[t] != 0) | keep)
    elif kind == K_SEASON:
        dlo = -down - _EPS
        dhi = up + _EPS
        top = smax + _EPS
        for t in range(m):
            v = x[t]
            st = s[t]
            ds = st - mean
            ok = (abs(v - st) <= lim) & (ds >= dlo) & (ds <= dhi) & (st <= top)
            below[t] = ok & (v >= lo) & (v <= hi) & ((below[t] != 0) | keep)
    else:  # set point following the season, clipped to the seasonal limits
        dlo = -down
        for t in range(m):
            v = x[t]
            sp = min(mean + min(max(s[t] - mean, dlo), up), smax)
            ok = abs(v - sp) <= lim
            below[t] = ok & (v >= lo) & (v <= hi) & ((below[t] != 0) | keep)


@njit(cache=True, error_model="numpy")
def _bounds(kind, short, down, up, smax):  # pragma: no cover - compiled
    """The decomposition check of one variable as five bounds: within them is
    ``|x − m| ≤ a``, ``|x − s| ≤ b``, ``c ≤ s − m ≤ d``, ``s ≤ e`` (unused ones infinite,
    so that they always hold; the same comparisons as standards._setpoint_ok)."""
    inf = math.inf
    if kind == K_MEAN:
        return short + _EPS, inf, -inf, inf, inf
    if kind == K_SEASON:
        return inf, short + _EPS, -down - _EPS, up + _EPS, smax + _EPS
    return inf, inf, -inf, inf, inf


@njit(cache=True, error_model="numpy")
def _ashrae_block(
    T, RH, b0, m, sT, sRH, mT, mRH, ipar, kinds, cls, btmp, counts
):  # pragma: no cover
    """Hours of the block meeting each class (T and RH, nested), added to ``counts``."""
    belowT, belowRH = btmp[0], btmp[1]
    nested = ipar[I_NESTED] != 0
    keep = not nested  # 1: a class is checked on its own limits only
    Tb = T[b0 : b0 + m]
    RHb = RH[b0 : b0 + m]
    for t in range(m):
        belowT[t] = 1
        belowRH[t] = 1
    for j in range(ipar[I_NCLS] - 1, -1, -1):  # from the most lenient class up
        if ipar[I_METHOD] != 0:  # "setpoint": one variable at a time
            _var_pass(kinds[j, 0], Tb, sT, m, mT, cls[j, C_TS], cls[j, C_TDOWN],
                      cls[j, C_TUP], cls[j, C_TSMAX], -math.inf, cls[j, C_TMAX], belowT,
                      nested)  # fmt: skip
            _var_pass(kinds[j, 1], RHb, sRH, m, mRH, cls[j, C_RS], cls[j, C_RDOWN],
                      cls[j, C_RUP], math.inf, cls[j, C_RLO], cls[j, C_RHI], belowRH,
                      nested)  # fmt: skip
            cnt = 0
            for t in range(m):
                cnt += belowT[t] & belowRH[t]
            counts[j] += cnt
            if nested and cnt == 0:
                break
            continue
        # "decomposition": both variables and the count in one vectorised loop
        ta, tb, tc, td, te = _bounds(kinds[j, 0], cls[j, C_TS], cls[j, C_TDOWN],
                                     cls[j, C_TUP], cls[j, C_TSMAX])  # fmt: skip
        ra, rb, rc, rd, re = _bounds(kinds[j, 1], cls[j, C_RS], cls[j, C_RDOWN],
                                     cls[j, C_RUP], math.inf)  # fmt: skip
        tmax = cls[j, C_TMAX] + _EPS
        rlo = cls[j, C_RLO] - _EPS
        rhi = cls[j, C_RHI] + _EPS
        cnt = 0
        for t in range(m):
            x = Tb[t]
            st = sT[t]
            ds = st - mT
            a = (abs(x - mT) <= ta) & (abs(x - st) <= tb) & (ds >= tc) & (ds <= td)
            a = a & (st <= te) & (x <= tmax) & ((belowT[t] != 0) | keep)
            r = RHb[t]
            sr = sRH[t]
            dr = sr - mRH
            b = (abs(r - mRH) <= ra) & (abs(r - sr) <= rb) & (dr >= rc) & (dr <= rd)
            b = b & (sr <= re) & (r >= rlo) & (r <= rhi) & ((belowRH[t] != 0) | keep)
            belowT[t] = a
            belowRH[t] = b
            cnt += a & b
        counts[j] += cnt
        if nested and cnt == 0:  # no hour of the block meets this class: nor a stricter one
            break


@njit(cache=True, error_model="numpy")
def _bin(v, fmin, scale):  # pragma: no cover - compiled
    b = np.int64((v - fmin) * scale)
    return b if b < N_BINS else N_BINS - 1


@njit(cache=True, error_model="numpy")
def _rank_bin(hist, r):  # pragma: no cover - compiled
    """(bin holding the value of rank ``r``, number of values in the bins before it)."""
    c = 0
    for b in range(N_BINS):
        if c + hist[b] > r:
            return b, c
        c += hist[b]
    return N_BINS - 1, c - hist[N_BINS - 1]


@njit(cache=True, error_model="numpy")
def _percentiles(f, n, q, hist, sel):  # pragma: no cover - compiled
    """``np.percentile(f[:n], 100 q)`` (method "linear") for the two values of ``q``.

    Exact order statistics: a histogram of the values on ``N_BINS`` bins (the bin index
    is monotone in the value) locates the bin of each rank; only that bin's values are
    sorted.
    """
    fmin, fmax = _bminmax(f, n, math.inf, -math.inf)
    out = np.empty(2)
    ranks = np.empty(4, np.int64)
    gam = np.empty(2)
    for k in range(2):
        v = (n - 1) * q[k]  # numpy's virtual index
        p = math.floor(v)
        gam[k] = v - p
        if v >= n - 1:
            ranks[2 * k] = n - 1
            ranks[2 * k + 1] = n - 1
        else:
            ranks[2 * k] = np.int64(p)
            ranks[2 * k + 1] = np.int64(p) + 1
    val = np.empty(4)
    scale = N_BINS / (fmax - fmin)
    if fmax == fmin:
        val[:] = fmin
    elif not math.isfinite(scale):
        s = np.sort(f[:n])
        for i in range(4):
            val[i] = s[ranks[i]]
    else:
        fv = f[:n]
        hist[:] = 0
        for t in range(n):
            hist[_bin(fv[t], fmin, scale)] += 1
        b_lo0, before0 = _rank_bin(hist, ranks[0])
        b_hi0, _ = _rank_bin(hist, ranks[1])
        b_lo1, before1 = _rank_bin(hist, ranks[2])
        b_hi1, _ = _rank_bin(hist, ranks[3])
        c0 = 0
        for b in range(b_lo0, b_hi0 + 1):
            c0 += hist[b]
        c = 0
        c1 = c0
        for t in range(n):  # the values of those bins, one region per percentile
            v = fv[t]
            b = _bin(v, fmin, scale)
            if b >= b_lo0 and b <= b_hi0:
                sel[c] = v
                c += 1
            if b >= b_lo1 and b <= b_hi1:
                sel[c1] = v
                c1 += 1
        part = sel[:c0]
        part.sort()
        val[0] = part[ranks[0] - before0]
        val[1] = part[ranks[1] - before0]
        part = sel[c0:c1]
        part.sort()
        val[2] = part[ranks[2] - before1]
        val[3] = part[ranks[3] - before1]
    for k in range(2):
        a = val[2 * k]
        b = val[2 * k + 1]
        t = gam[k]
        d = b - a  # numpy's _lerp
        out[k] = b - d * (1.0 - t) if t >= 0.5 else a + d * t
    return out[0], out[1]


@njit(cache=True, error_model="numpy")
def _first_pass_columns(out, sums, vtt, n, nea, fpar, ipar, mould):  # pragma: no cover
    """Write the columns of the first pass (chemical, mechanical, mould); return the next
    column's index. ``sums`` and ``vtt`` are that pass's accumulators."""
    col = 0
    if ipar[I_CHEM]:
        for k in range(nea + 1):  # lifetime multipliers, then TWPI: harmonic means
            out[col] = n / sums[k]
            col += 1
        out[col] = 100.0 * sums[nea + 4] / n / 100.0 * 8760.0  # time of wetness [h/year]
        col += 1
    if ipar[I_MECH]:
        lo, hi = sums[nea + 1], sums[nea + 2]
        out[col] = lo
        out[col + 1] = hi
        out[col + 2] = hi - lo
        out[col + 3] = 100.0 * fpar[F_COEF] * (hi - lo)
        col += 4
    if mould:
        out[col] = vtt[2]
        out[col + 1] = 100.0 * sums[nea + 3] / n / 100.0 * 8760.0  # share → h/year
        col += 2
    return col


@njit(cache=True, error_model="numpy")
def _en_columns(RH, n, f, hist, sel, cs, half, wrap, sE, fpar, ipar, out, col):  # pragma: no cover
    """Write the EN 15757 columns from the fluctuations ``f[:n]`` [%]: the share of hours
    outside the band [%] and the band's lower and upper limits [%] around the centred
    moving average read from the cumulative sums ``cs`` (``half``, ``wrap``); ``sE``
    (BLOCK,) is work space."""
    q = np.empty(2)
    q[0] = fpar[F_QLO]
    q[1] = fpar[F_QHI]
    p_lo, p_hi = _percentiles(f, n, q, hist, sel)
    mb = fpar[F_MINBAND]
    if ipar[I_EN_WIDTH]:
        mid = 0.5 * (p_lo + p_hi)
        narrow = (p_hi - p_lo) < mb
        lo = mid - 0.5 * mb if narrow else p_lo
        hi = mid + 0.5 * mb if narrow else p_hi
    else:
        lo = min(p_lo, -mb)
        hi = max(p_hi, mb)
    cnt = 0
    for b0 in range(0, n, BLOCK):
        m = min(BLOCK, n - b0)
        _centred(cs, b0, m, n, half, wrap, sE)
        RHb = RH[b0 : b0 + m]
        for t in range(m):
            r = RHb[t]
            cnt += 1 if (r < sE[t] + lo) or (r > sE[t] + hi) else 0
    out[col] = 100.0 * cnt / n
    out[col + 1] = lo
    out[col + 2] = hi


@njit(cache=True, error_model="numpy")
def series_indicators(
    T, RH, n, ea_r, fpar, ipar, kinds, cls, ws, tmp, btmp, hist, out
):  # pragma: no cover
    """All indicators of the plan for the series ``T[:n]`` [°C], ``RH[:n]`` [%].

    Writes ``out`` (the plan's columns; the best ASHRAE class as its index, -1 for none)
    and returns 0, or 1 when an hour is missing or outside what
    :func:`~heritage_bayes.climate.risk.assess_batch` accepts (``out`` is then not
    meaningful: the caller uses that function for this series). ``ws`` (5, n + 2 pad +
    1), ``tmp`` (3, BLOCK), ``btmp`` (4, BLOCK) uint8 and ``hist`` (N_BINS,) are work
    arrays.
    """
    nea = ipar[I_NEA]
    sums = np.zeros(nea + 5)
    sums[nea + 1] = math.inf
    sums[nea + 2] = -math.inf
    mould = ipar[I_MOULD] != 0
    frozen = ipar[I_FROZEN] != 0
    vtt = np.empty(3)  # M, dry hours, max M
    vtt[0] = fpar[F_M0]
    vtt[1] = 0.0
    vtt[2] = -1.0
    vtt_p = fpar[F_VTT : F_VTT + 9]  # k1_lo, k1_hi, A, B, C, RH_min, C_mat, W, SQ
    csT, csRH, csE, f, sel = ws[0], ws[1], ws[2], ws[3], ws[4]
    half_a, wrap_a = ipar[I_HALF_A], ipar[I_WRAP_A] != 0
    half_e, wrap_e = ipar[I_HALF_E], ipar[I_WRAP_E] != 0
    shared = ipar[I_SHARED] != 0
    ashrae = ipar[I_ASHRAE] != 0
    en = ipar[I_EN] != 0
    # cumulative sums of the truncated ("shrink") moving averages, in the same pass
    sum_T = ashrae and not wrap_a
    sum_RH = sum_T or (en and not shared and not wrap_e)
    csT[0] = 0.0
    csRH[0] = 0.0
    bad = 0
    above1 = 0
    above0 = 0
    for b0 in range(0, n, BLOCK):  # one pass: every hourly term, the recursions, the sums
        m = min(BLOCK, n - b0)
        Tb = T[b0 : b0 + m]
        RHb = RH[b0 : b0 + m]
        nb, a1, a0 = _bad_hours(Tb, RHb, m)
        bad += nb
        above1 += a1
        above0 += a0
        _pointwise(T, RH, b0, m, fpar, ipar, ea_r, tmp, sums)
        if mould:
            vtt_hours(Tb, RHb, m, vtt_p, frozen, vtt)
        if sum_T:
            _cumsum_block(Tb, m, csT[b0 : b0 + m + 1])
        if sum_RH:
            _cumsum_block(RHb, m, csRH[b0 : b0 + m + 1])
    if bad > 0 or (above1 == 0 and above0 > 0):
        return 1
    col = _first_pass_columns(out, sums, vtt, n, nea, fpar, ipar, mould)
    if not (ashrae or en):
        return 0
    sT, sRH, sE = tmp[0], tmp[1], tmp[2]
    ncls = ipar[I_NCLS]
    counts = np.zeros(max(ncls, 1), np.int64)
    if ashrae:
        if wrap_a:  # periodic padding: sums of the padded series
            _cumsum(T, n, half_a, True, csT)
            _cumsum(RH, n, half_a, True, csRH)
        mT = fpar[F_TSP] if ipar[I_HAS_TSP] else pairwise_sum(T, 0, n) / n
        mRH = fpar[F_RHSP] if ipar[I_HAS_RHSP] else pairwise_sum(RH, 0, n) / n
    if en and not shared:
        if wrap_e or (ashrae and wrap_a):
            _cumsum(RH, n, half_e, wrap_e, csE)
        else:
            csE = csRH  # the sums of the truncated windows do not depend on their width
    for b0 in range(0, n, BLOCK):
        m = min(BLOCK, n - b0)
        if ashrae:
            _centred(csT, b0, m, n, half_a, wrap_a, sT)
            _centred(csRH, b0, m, n, half_a, wrap_a, sRH)
            _ashrae_block(T, RH, b0, m, sT, sRH, mT, mRH, ipar, kinds, cls, btmp, counts)
        if en:
            if shared:
                sE[:m] = sRH[:m]
            else:
                _centred(csE, b0, m, n, half_e, wrap_e, sE)
            fb = f[b0 : b0 + m]
            RHb = RH[b0 : b0 + m]
            for t in range(m):
                fb[t] = RHb[t] - sE[t]
    if ipar[I_ASHRAE]:
        best = -1
        for j in range(ncls):
            share = 100.0 * counts[j] / n
            out[col + j] = share
            if best < 0 and share >= fpar[F_THR] - _EPS:
                best = j
        out[col + ncls] = best
        col += ncls + 1
    if ipar[I_EN]:
        cs = csE if not shared else csRH
        half, wrap = (half_e, wrap_e) if not shared else (half_a, wrap_a)
        _en_columns(RH, n, f, hist, sel, cs, half, wrap, sE, fpar, ipar, out, col)
    return 0


stamp_cache(globals(), _vecmath, _sums, _vtt, indicators)
