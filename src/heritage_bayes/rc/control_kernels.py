"""The compiled steps of controlled rooms: one model's controlled recursion (batched
over parameter sets, :class:`heritage_bayes.rc.control.ControlledModel`) and a thermal
and a hygric model stepped together per draw (a coupled room, the interventions of
:mod:`heritage_bayes.projection`).

Both solve the piecewise-linear system exactly for a control flow held constant within
the step: the free-running step, then the flow that brings the air node to its violated
bound, clipped at the capacity (the equations are in :mod:`heritage_bayes.rc.control`).
"""

from __future__ import annotations

import math

import numba
import numpy as np

from heritage_bayes.climate import _vecmath
from heritage_bayes.climate._vecmath import psat_water, stamp_cache

__all__ = [
    "CP_DIFF",
    "CP_H_ON",
    "CP_M_DEHUM",
    "CP_M_HUM",
    "CP_P_MAX",
    "CP_RH_CH",
    "CP_RH_HI",
    "CP_RH_LO",
    "CP_T_MAX",
    "CP_T_MODE",
    "CP_T_SET",
    "CP_T_USE",
    "N_COST",
    "N_CP",
    "control_run",
    "coupled_draw",
    "kernel_rows",
]


def kernel_rows(c: dict) -> dict:
    """Kernel keyword arguments from the controller arrays."""
    return {
        "mode": c["mode"],
        "lo0": c["lo0"],
        "lo1": c["lo1"],
        "hi1": c["hi1"],
        "qadd": c["qadd"],
        "qrem": c["qrem"],
        "rh_ch": c["rh_ch"],
        "t_max": c["t_max"],
        "sig": c["s"],
        "pv": c["pv"],
    }


@numba.njit(cache=True, nogil=True)
def _t_at_rh(pv, rh):  # pragma: no cover - compiled
    """Temperature [°C] at which vapour pressure ``pv`` [Pa] is relative humidity ``rh``
    [-] (Magnus form, Alduchov & Eskridge 1996; within 0.1 K of IAPWS for 0-40 °C)."""
    if pv <= 0.0 or rh <= 0.0:
        return -1e300
    g = math.log(pv / (rh * 610.94))
    return 243.04 * g / (17.625 - g)


@numba.njit(cache=True, nogil=True)
def control_run(
    ad, W, bd, Cz, z, Y, Q, k0, mode, lo0, lo1, hi1, qadd, qrem, rh_ch, t_max, sig, pv
):  # pragma: no cover - compiled
    """Controlled modal recursion (:mod:`heritage_bayes.rc.control`) over the rows of W, in place.

    ad, bd, z : (K, n); W : (Nb, K*n) free forcing of rows k0..k0+Nb-1 (index p*n + j);
    Cz : (K, n_out, n); Y : (K, N, n_out) outputs; Q : (K, N) control flow. mode 0
    none, 1 thermostat, 2 humidistat, 3 thermostat with conservation heating. Bounds of
    the air node at the end of step k: thermostat ``lo = lo0 + lo1 sig[k]`` (and the
    temperature at RH ``rh_ch`` of ``pv[k]``), no upper bound; humidistat
    ``lo = lo1 sig[k]``, ``hi = hi1 sig[k]`` (``sig`` = saturation pressure at the
    indoor temperature). ``sig``, ``pv``: (1, N) one signal for every walker, or
    (K, N) one per walker.
    """
    K, n = ad.shape
    s_each = sig.shape[0] > 1
    p_each = pv.shape[0] > 1
    Nb = W.shape[0]
    n_out = Cz.shape[1]
    zf = np.empty(n)
    g = np.zeros(K)
    for p in range(K):
        for j in range(n):
            g[p] += Cz[p, 0, j] * bd[p, j]
    for kb in range(Nb):  # time outer: the forcing rows are read in order
        k = k0 + kb
        for p in range(K):
            base = p * n
            ps = p if s_each else 0
            pp = p if p_each else 0
            for o in range(n_out):
                acc = 0.0
                for j in range(n):
                    acc += Cz[p, o, j] * z[p, j]
                Y[p, k, o] = acc
            yf = 0.0
            for j in range(n):
                zf[j] = ad[p, j] * z[p, j] + W[kb, base + j]
                yf += Cz[p, 0, j] * zf[j]
            q = 0.0
            if mode == 1 or mode == 3:
                lo = lo0[p] + lo1[p] * sig[ps, k]
                if mode == 3:
                    tc = _t_at_rh(pv[pp, k], rh_ch[p])
                    if tc > t_max:
                        tc = t_max
                    if tc > lo:
                        lo = tc
                if yf < lo:
                    q = (lo - yf) / g[p]
                    if q > qadd[p]:
                        q = qadd[p]
            elif mode == 2:
                lo = lo1[p] * sig[ps, k]
                hi = hi1[p] * sig[ps, k]
                if yf > hi:
                    q = (hi - yf) / g[p]
                    if q < -qrem[p]:
                        q = -qrem[p]
                elif yf < lo:
                    q = (lo - yf) / g[p]
                    if q > qadd[p]:
                        q = qadd[p]
            Q[p, k] = q
            for j in range(n):
                z[p, j] = zf[j] + bd[p, j] * q


# ---------------------------------------------------------------------- coupled rooms
#: Columns of the per-draw controller array of :func:`coupled_draw` (``cp``).
CP_T_MODE, CP_T_SET, CP_T_USE, CP_P_MAX, CP_RH_CH, CP_T_MAX = 0, 1, 2, 3, 4, 5
CP_H_ON, CP_RH_LO, CP_RH_HI, CP_M_DEHUM, CP_M_HUM, CP_DIFF = 6, 7, 8, 9, 10, 11
N_CP = 12
#: Columns of the per-draw running-cost sums of :func:`coupled_draw` (``cost``): heat
#: [W·steps], peak heat [W], water removed [kg/s·steps], peak removal [kg/s], water
#: added [kg/s·steps], peak addition [kg/s].
N_COST = 6


@numba.njit(inline="always", cache=True, nogil=True, error_model="numpy")
def _free_step(ad, Bdz, edz, Cz, U, k, z, zf):  # pragma: no cover - compiled
    """The free-running modal step ``zf = ad z + Bdz u[k] + edz``; returns ``Cz·zf``."""
    y = 0.0
    for j in range(ad.size):
        w = edz[j]
        for q in range(U.shape[0]):
            w += Bdz[j, q] * U[q, k]
        zf[j] = ad[j] * z[j] + w
        y += Cz[j] * zf[j]
    return y


@numba.njit(cache=True, nogil=True, error_model="numpy")
def _coupled_steps(
    adT, BdzT, edzT, CzT, UT, adP, BdzP, edzP, CzP, UP, bdT, gT, bdP, gP, cp, sig,
    zT, zP, k1, control, Ts, Ps, cost, store,
):  # fmt: skip  # pragma: no cover - compiled
    """Steps ``0 .. k1-1`` of :func:`coupled_draw` from the states ``zT``, ``zP`` (in
    place); outputs stored when ``store``, running costs summed into ``cost``."""
    nT = adT.size
    nP = adP.size
    zfT = np.empty(nT)
    zfP = np.empty(nP)
    t_mode = int(cp[CP_T_MODE]) if control else 0
    h_on = cp[CP_H_ON] != 0.0 and control
    diff = cp[CP_DIFF]
    on_d = False  # the humidistat's switches (hysteresis)
    on_h = False
    for k in range(k1):
        yT = 0.0
        for j in range(nT):
            yT += CzT[j] * zT[j]
        yP = 0.0
        for j in range(nP):
            yP += CzP[j] * zP[j]
        if store:
            Ts[k] = yT
            Ps[k] = yP
        # thermal: the free step, then the heating that meets the bound at its end
        yf = _free_step(adT, BdzT, edzT, CzT, UT, k, zT, zfT)
        q = 0.0
        if t_mode != 0:
            lo = cp[CP_T_SET] + cp[CP_T_USE] * sig[k]
            if t_mode == 3:  # conservation heating: the T at which Pi has RH_ch
                tc = _t_at_rh(yP, cp[CP_RH_CH])
                tc = cp[CP_T_MAX] if tc > cp[CP_T_MAX] else tc
                lo = tc if tc > lo else lo
            if yf < lo:
                q = (lo - yf) / gT
                q = cp[CP_P_MAX] if q > cp[CP_P_MAX] else q
        for j in range(nT):
            zT[j] = zfT[j] + bdT[j] * q
        if store and q > 0.0:
            cost[0] += q
            cost[1] = q if q > cost[1] else cost[1]
        # hygric: the free step, then the humidistat (RH at the sensed temperature yT)
        yf = _free_step(adP, BdzP, edzP, CzP, UP, k, zP, zfP)
        m = 0.0
        if h_on:
            ps = psat_water(yT)
            hi = cp[CP_RH_HI] * ps
            lo = cp[CP_RH_LO] * ps
            off_d = (cp[CP_RH_HI] - diff) * ps  # where a running unit switches off
            off_h = (cp[CP_RH_LO] + diff) * ps
            if on_d and yf <= off_d:
                on_d = False
            if on_h and yf >= off_h:
                on_h = False
            if not on_d and yf > hi:
                on_d = True
                on_h = False
            if not on_d and not on_h and yf < lo:
                on_h = True
            if on_d:  # runs (at most its capacity) until the RH is down to RH_hi - diff
                m = (off_d - yf) / gP
                m = -cp[CP_M_DEHUM] if m < -cp[CP_M_DEHUM] else m
                on_d = yf + gP * m > off_d * (1.0 + 1e-12)
            elif on_h:  # runs until the RH is up to RH_lo + diff
                m = (off_h - yf) / gP
                m = cp[CP_M_HUM] if m > cp[CP_M_HUM] else m
                on_h = yf + gP * m < off_h * (1.0 - 1e-12)
        for j in range(nP):
            zP[j] = zfP[j] + bdP[j] * m
        if store and m != 0.0:
            if m < 0.0:
                cost[2] -= m
                cost[3] = -m if -m > cost[3] else cost[3]
            else:
                cost[4] += m
                cost[5] = m if m > cost[5] else cost[5]


@numba.njit(cache=True, nogil=True, error_model="numpy")
def coupled_draw(
    adT, BdzT, edzT, CzT, z0T, UT, adP, BdzP, edzP, CzP, z0P, UP, bdT, bdP, cp, sig, spin,
    Ts, Ps, cost, zT, zP, zfT, zfP,
):  # fmt: skip  # pragma: no cover - compiled
    """One parameter draw of a thermal and a hygric model stepped together, each with
    its optional controller: noise-free ``Ti`` [°C] into ``Ts`` and ``Pi`` [Pa] into
    ``Ps`` (N,), running-cost sums (:data:`N_COST`) into ``cost``.

    Parameters
    ----------
    adT, BdzT, edzT, CzT, z0T : arrays
        Modal recursion of the thermal model (:func:`heritage_bayes.rc.discretize.modal_form`:
        ``ad`` (n,), ``Bdz`` (n, m), ``edz`` (n,), the air row of ``Cz`` (n,), initial
        modal state (n,)); ``UT`` (m, N) its inputs by column.
    adP, BdzP, edzP, CzP, z0P, UP : arrays
        The same for the hygric model.
    bdT, bdP : (n,) arrays
        Modal state change of a unit flow into the air node held over one step (1 W,
        1 kg/s): ``phi * s[air] * V[air, :]`` of the modal form.
    cp : (N_CP,) array
        Controllers (columns ``CP_*``): thermostat mode (0 none, 1 set-point ``T_SET``
        [°C] plus ``T_USE`` [K] × ``sig``, 3 the same with conservation heating to
        ``RH_CH`` [-] capped at ``T_MAX`` [°C]), heating power ``P_MAX`` [W];
        humidistat on/off, its band ``RH_LO``..``RH_HI`` [-], dehumidifier and
        humidifier capacities [kg/s], switching differential ``DIFF`` [-].
    sig : (N,) array
        Hours of use (1 in use, 0 not, fractions allowed) [-].
    spin : int
        Steps of the periodic spin-up: the state change that ``spin`` controlled steps
        make against free-running ones, added to ``z0T``, ``z0P``.
    Ts, Ps, cost : arrays
        Outputs.
    zT, zP, zfT, zfP : arrays
        Work arrays (n,).

    Notes
    -----
    The step is :class:`~heritage_bayes.rc.control.ControlledModel`'s (the exact
    solution of the piecewise-linear system for a flow constant within the step), the
    sensors read the air at the start
    of the step: the conservation-heating bound uses ``Pi[k]`` and the humidistat the
    saturation pressure at ``Ti[k]``, each model's controlled value, so a heating and
    a humidistat act on one coupled room. The humidistat is an on/off controller with
    a switching differential (hysteresis) ``d``: the dehumidifier switches on when the
    RH would exceed ``RH_HI`` and runs (at most its capacity) until the RH is down to
    ``RH_HI - d``; the humidifier switches on below ``RH_LO`` and runs until
    ``RH_LO + d``; ``d = 0`` holds the RH at the limit (a modulating unit).
    """
    N = Ts.size
    for j in range(zT.size):
        zT[j] = z0T[j]
        zfT[j] = z0T[j]
    for j in range(zP.size):
        zP[j] = z0P[j]
        zfP[j] = z0P[j]
    gT = 0.0
    for j in range(zT.size):
        gT += CzT[j] * bdT[j]
    gP = 0.0
    for j in range(zP.size):
        gP += CzP[j] * bdP[j]
    n0 = spin if spin < N else N
    if n0 > 0:
        args = (adT, BdzT, edzT, CzT, UT, adP, BdzP, edzP, CzP, UP, bdT, gT, bdP, gP, cp, sig)
        _coupled_steps(*args, zT, zP, n0, True, Ts, Ps, cost, False)
        _coupled_steps(*args, zfT, zfP, n0, False, Ts, Ps, cost, False)
        for j in range(zT.size):
            zT[j] = z0T[j] + zT[j] - zfT[j]
        for j in range(zP.size):
            zP[j] = z0P[j] + zP[j] - zfP[j]
    _coupled_steps(
        adT, BdzT, edzT, CzT, UT, adP, BdzP, edzP, CzP, UP, bdT, gT, bdP, gP, cp, sig,
        zT, zP, N, True, Ts, Ps, cost, True,
    )  # fmt: skip


stamp_cache(globals(), _vecmath)
