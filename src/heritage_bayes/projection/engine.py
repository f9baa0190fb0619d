"""Predictive simulation of posterior draws on each weather, streamed, with risk.

For each chunk of posterior draws and each case (the baseline, every scenario), the
thermal and hygric models are simulated over the whole weather, a draw of each section's
noise model is added (so bands are predictive, not only parametric), the indoor RH is
formed from the coupled ``Ti`` and ``Pi`` and capped at saturation, and each draw is
reduced at once to what is kept: the risk indicators (of the predictive series and of
the noise-free one, for the uncertainty split) and monthly means of ``Ti`` and ``RHi``.

The per-draw work is one compiled pass (:mod:`heritage_bayes.projection._stream`, numba,
draws in parallel over the threads): the modal recursion of a free-running model, the
RH, and every indicator of :func:`~heritage_bayes.climate.risk.assess_batch` by
:mod:`heritage_bayes.climate.risk.fused` (the same values, to rounding; a series that
function rejects or with a missing hour is handed to it). A selected family without a
compiled pass (registered at run time) is computed by its numpy ``compute`` on the
series the compiled pass keeps for it (:class:`~heritage_bayes.climate.risk.fused.NumpyPass`:
per chunk, over the whole weather and per complete year). Peak memory is the noise of
two chunks (two arrays of ``chunk × hours`` doubles each: the next chunk's is drawn
while this one is reduced) and nine arrays of the series length per thread, whatever
the number of draws; with a family without a compiled pass, four more arrays of
``chunk × hours`` (the kept series) and that family's numpy temporaries.

The same parameter draws and the same noise realisations (seeded per chunk, drawn once
per chunk and used for every case of the same length) are used for every case:
differences between scenarios are then paired, not blurred by noise. A controlled room
(thermostat, humidistat) is simulated by its ``model.forward`` and keeps its calibrated
control.
"""

from __future__ import annotations

import time
from concurrent.futures import ThreadPoolExecutor

import numpy as np
import pandas as pd

from heritage_bayes.climate.psychro import saturation_vapour_pressure
from heritage_bayes.errors import ConfigError, InputError
from heritage_bayes.projection._modal import (
    _HOURS_YEAR,
    _NO_MODAL,
    _controlled,
    _coupled_series,
    _modal_arrays,
    _modal_form,
    _noise,
    _work,
    case_inputs,
    coupled_pair,
)
from heritage_bayes.projection.cases import Case, CaseOut, CaseResult, Draws, init_window
from heritage_bayes.rc.control_kernels import N_CP


def select_draws(run, n: int | None, seed: int) -> Draws:
    """``n`` posterior draws (random without replacement, seeded; all if None).

    Raises
    ------
    InputError
        ``n`` larger than the posterior holds.
    """
    from heritage_bayes.inference.likelihoods import get_noise_model

    post = run.idata.posterior
    total = int(post.sizes["chain"] * post.sizes["draw"])
    if n is not None and n > total:
        raise InputError(
            f"draws: {n} requested, but the posterior of {run.path} holds {total} draws "
            f"(chains × draws); ask for at most {total}"
        )
    idx = np.arange(total)
    if n is not None and n < total:
        idx = np.sort(np.random.default_rng(seed).choice(total, size=n, replace=False))
    model, noise, nms = {}, {}, {}
    for section, m in run.models.items():
        params = run.draws(section)  # all draws, in the flattened posterior order
        P, _ = m.param_array({k: v[idx] for k, v in params.items()})
        model[section] = P
        nm = get_noise_model(getattr(run.config, section).noise)
        # the bands' error model where it replaced the posterior's (for every output:
        # the free-run error's model, whose columns are all set from the fit below)
        info = run.run_summary.models.get(section)
        pred = {} if info is None else info.predictive_noise
        if pred and set(pred) >= set(m.output_names):
            nm = nm.free_run_model()
        names = [f"{section}.{n}" for n, _, _ in nm.parameter_specs(m.output_names, m.state_names)]
        cols = [post[n].values.reshape(-1)[idx] if n in post else np.zeros(idx.size) for n in names]
        noise[section] = np.column_stack(cols) if cols else np.zeros((len(idx), 0))
        kinds = nm.free_run_model().kinds  # the free-run error's parameters
        for out, fit in pred.items():
            for kind in kinds:
                name = f"{section}.{kind}_{out}"
                if name in names:
                    noise[section][:, names.index(name)] = getattr(fit, kind)
        nms[section] = nm
    return Draws(index=idx, model=model, noise=noise, noise_models=nms)


def _relative_humidity(T: np.ndarray, P: np.ndarray) -> np.ndarray:
    """RH [%] from T [°C] and vapour pressure [Pa], capped to 0–100 % (saturation)."""
    return np.clip(100.0 * P / saturation_vapour_pressure(T), 0.0, 100.0)


def _month_starts(index: pd.DatetimeIndex) -> tuple[np.ndarray, pd.DatetimeIndex]:
    per = index.tz_convert("UTC").tz_localize(None).to_period("M")
    codes = per.asi8
    starts = np.flatnonzero(np.r_[True, codes[1:] != codes[:-1]])
    return starts, per[starts].to_timestamp().tz_localize("UTC")


def _monthly(x: np.ndarray, starts: np.ndarray) -> np.ndarray:
    sums = np.add.reduceat(x, starts, axis=1)
    counts = np.diff(np.r_[starts, x.shape[1]])
    return (sums / counts).astype(np.float32)


def simulate_case(
    run,
    draws: Draws,
    inputs: pd.DataFrame,
    *,
    seed: int,
    noise: bool = True,
    chunk: int = 50,
    init_steps: int | None = None,
    risk_options: dict | None = None,
) -> CaseResult:
    """Predictive simulation and risk of every draw on one weather.

    :func:`simulate_cases` for one case (see there for the parameters).

    Returns
    -------
    CaseResult
    """
    return simulate_cases(
        run,
        draws,
        [inputs],
        seed=seed,
        noise=noise,
        chunk=chunk,
        init_steps=init_steps,
        risk_options=risk_options,
    )[0]


def simulate_cases(
    run,
    draws: Draws,
    inputs: list[pd.DataFrame],
    *,
    seed: int,
    noise: bool = True,
    chunk: int = 50,
    init_steps: int | None = None,
    risk_options: dict | None = None,
    progress=None,
    baseline: bool = True,
    measure=None,
    compiled: bool = True,
) -> list[CaseResult]:
    """Predictive simulation and risk of every draw on each weather (streamed by chunks).

    Parameters
    ----------
    run : heritage_bayes.run.Run
    draws : Draws
    inputs : list of pandas.DataFrame
        Model inputs of each case on an hourly grid
        (:func:`heritage_bayes.projection.weather.model_inputs`); only their complete
        years are simulated (:func:`~heritage_bayes.climate.risk.registry.complete_year_hours`).
    seed : int
        Seed of the noise draws: chunk ``i`` uses ``(seed, i)``, for every case (cases
        of the same length share the very same draws: paired differences).
    noise : bool
        Add a draw of each section's noise model (predictive); False: noise-free only.
    chunk : int
        Draws per chunk: the noise of a chunk (two arrays of ``chunk × hours`` doubles)
        is drawn once and used for every case; the work arrays are nine series per
        thread, whatever the chunk.
    init_steps : int, optional
        Rows averaged for the steady-state initial state (default the calibration's).
    risk_options : dict, optional
        Keywords of :func:`heritage_bayes.climate.risk.assess_batch` (any registered
        family's group and options).
    progress : callable, optional
        Called with one line of text per chunk.
    baseline : bool
        ``inputs[0]`` is the baseline: each draw's EN 15757 band is taken from its
        baseline simulation and every case is judged against it
        (``en15757_outside_baseline``, :func:`heritage_bayes.projection._stream.annual_values`).
    measure : Measure, optional
        An intervention (:class:`~heritage_bayes.projection.interventions.Measure`)
        applied to every draw (:func:`simulate_measures` runs doing nothing and several
        measures in one pass).
    compiled : bool
        A measure's controllers stepped in the compiled pass
        (:func:`heritage_bayes.rc.control_kernels.coupled_draw`); False: through
        :meth:`~heritage_bayes.projection.interventions.Measure.simulate`
        (``ControlledModel.forward``, each controller against the other model's
        free-running series; the previous implementation, kept as the reference the
        tests and ``benchmarks/bench_interventions.py`` compare with).

    Returns
    -------
    list of CaseResult
        In the order of ``inputs``, with the per-complete-year values of
        :data:`heritage_bayes.climate.risk.registry.ANNUAL` and of the ``per_year``
        columns of the families without a compiled pass (``annual_*``) and, when the
        EN 15757 group is computed and ``baseline``, the column
        ``en15757_outside_baseline`` (mean over the years). ``seconds``: ``simulate``
        (modal forms, and
        ``model.forward`` of controlled models), ``noise`` (the noise draws, shared
        equally by the cases that use them) and ``risk`` (the compiled pass: simulation
        of free-running models, RH, indicators, monthly means).

    Notes
    -----
    The compiled pass (:mod:`heritage_bayes.projection._stream`) gives, per draw, the
    indicators of :func:`~heritage_bayes.climate.risk.assess_batch` on the same series
    (to rounding, see :mod:`heritage_bayes.climate.risk.fused`); a draw whose series
    that function would reject or that has a missing hour is recomputed with it.
    """
    return _simulate(
        run, draws, inputs, [measure], seed=seed, noise=noise, chunk=chunk,
        init_steps=init_steps, risk_options=risk_options, progress=progress,
        baseline=baseline, compiled=compiled,
    )[0]  # fmt: skip


def simulate_measures(
    run, draws: Draws, inputs: list[pd.DataFrame], measures: list, *, seed: int, **options
) -> tuple[list[CaseResult], dict]:
    """Doing nothing and every measure, in one streamed pass (paired by construction).

    Parameters are those of :func:`simulate_cases` (``options``: its keywords ``noise``,
    ``chunk``, ``init_steps``, ``risk_options``, ``progress``, ``baseline``);
    ``measures`` a list of :class:`~heritage_bayes.projection.interventions.Measure`.
    Per chunk of draws the noise is drawn once and each case's weather prepared once
    for doing nothing and every measure; a measure with a controller steps both models
    together
    (:func:`heritage_bayes.rc.control_kernels.coupled_draw`) in the compiled pass, draws in
    parallel over the threads, and only its predictive indicators are computed (a
    measure is compared predictive with predictive; its ``parametric`` frame is NaN
    when ``noise``).

    Returns
    -------
    nothing : list of CaseResult
        Doing nothing, per case (as :func:`simulate_cases`).
    per_measure : dict
        Measure name -> list of CaseResult (per case), with ``costs``.
    """
    res = _simulate(run, draws, inputs, [None, *measures], seed=seed, **options)
    return res[0], {m.name: r for m, r in zip(measures, res[1:], strict=True)}


def _simulate(
    run, draws: Draws, inputs: list, variants: list, *, seed: int, noise: bool = True,
    chunk: int = 50, init_steps: int | None = None, risk_options: dict | None = None,
    progress=None, baseline: bool = True, compiled: bool = True,
) -> list[list[CaseResult]]:  # fmt: skip
    """:func:`simulate_measures` for ``variants`` (None: doing nothing, or a Measure):
    per variant, the list of CaseResult. Each variant's EN 15757 band is built from its
    own baseline case (all cases of a variant are reduced before the next variant)."""
    import numba

    from heritage_bayes.climate.risk.fused import projection_plan

    if set(run.models) != {"thermal", "hygric"}:
        raise ConfigError(
            f"run {run.path}: a projection of risk needs both the thermal and the hygric "
            f"model (indoor T and RH); the run has {sorted(run.models)}"
        )
    dt = run.run_summary.dt
    if dt != 3600.0:
        raise ConfigError(
            f"run {run.path}: data.step is {dt:g} s; the risk indicators need an hourly grid"
        )
    w = int(init_steps or init_window(run))
    params = []  # each variant's parameter draws (a measure's change applied)
    for v in variants:
        if v is not None:
            v.check(run)
        params.append(draws.model if v is None else v.params(run, draws.model))
    opts = dict(risk_options or {})
    plan_opts = {k: v for k, v in opts.items() if k not in ("nan_policy", "chunk_size")}
    nan_policy = opts.get("nan_policy", "propagate")
    from heritage_bayes.climate.risk.registry import complete_year_hours

    cases = []
    for inp in inputs:
        inp = inp.iloc[: complete_year_hours(len(inp))]  # the indicators' complete years
        U = case_inputs(run, inp)  # a column simulated by another model: NaN here
        starts, months = _month_starts(inp.index)
        plan, numpy = projection_plan(len(inp), nan_policy=nan_policy, **plan_opts)
        Ut = {s: np.ascontiguousarray(u.T) for s, u in U.items()}
        mode = (1 if not cases else 2) if baseline else 0
        hoy = hour_of_year(inp.index)
        cases.append(Case(U, Ut, starts, months, plan, len(inp), hoy, mode, inp.index,
                          numpy or None))  # fmt: skip
    K = draws.index.size
    out = [[CaseOut.empty(c, K) for c in cases] for _ in variants]
    sigs = [[_hours_of_use(v, c) for c in cases] for v in variants]
    slots = max(1, min(numba.get_num_threads(), chunk, K))
    from heritage_bayes.projection._stream import HOY

    n_max = max(c.N for c in cases)
    bands = (np.empty((min(chunk, K), HOY + 2)), np.empty((min(chunk, K), HOY + 2)))
    annual_work = (np.empty((slots, n_max)), np.empty((slots, HOY)))
    work: dict = {}
    lengths = sorted({c.N for c in cases})
    chunks = [slice(s0, min(s0 + chunk, K)) for s0 in range(0, K, chunk)]

    def draw_noise(i: int) -> tuple[dict, float]:
        t0 = time.perf_counter()
        e = (
            {N: _noise(draws, chunks[i], N, seed, i, run.models, dt) for N in lengths}
            if noise
            else {}
        )
        return e, time.perf_counter() - t0

    # the noise of the next chunk is drawn while this one is reduced (numpy's generator
    # and the compiled pass release the GIL): two chunks of noise in memory at most
    with ThreadPoolExecutor(max_workers=1) as pool:
        ahead = pool.submit(draw_noise, 0)
        for i, sl in enumerate(chunks):
            t_chunk = time.perf_counter()
            e_all, t_noise = ahead.result()
            if i + 1 < len(chunks):
                ahead = pool.submit(draw_noise, i + 1)
            for v, Pv, outs, sv in zip(variants, params, out, sigs, strict=True):
                t0 = time.perf_counter()
                ctl = v is not None and v.controlled and v.stepped_together(run)
                free = {"free": True} if ctl and compiled else {}  # the measure's networks
                modal = {s: _modal_form(m, Pv[s][sl], dt, **free) for s, m in run.models.items()}
                ctrl = None
                if ctl and compiled:
                    P_sl = {s: Pv[s][sl] for s in run.models}
                    ctrl = v.controller_arrays(sl.stop - sl.start, modal, run, P_sl)
                t_modal = (time.perf_counter() - t0) / len(cases)
                for c, o, sig in zip(cases, outs, sv, strict=True):
                    if v is variants[0]:  # drawn once, for every variant
                        o.seconds["noise"] += t_noise / sum(cc.N == c.N for cc in cases)
                    key = (c.N, c.plan.pad)
                    if key not in work:
                        work[key] = _work(c.plan, slots, c.N)
                    e = e_all.get(c.N) if noise else None
                    aw = (bands, annual_work)
                    _run_chunk(
                        run, Pv, c, o, sl, modal, e, dt, w, work[key], aw, t_modal, opts, v,
                        ctrl, sig,
                    )  # fmt: skip
            del e_all
            if progress is not None:
                n_m = sum(v is not None for v in variants)
                what = "" if not n_m else f", {n_m} measure(s)"
                what += ", doing nothing" if n_m and None in variants else ""
                progress(
                    f"draws {sl.start + 1}-{sl.stop} of {K}: {len(cases)} case(s){what} in "
                    f"{time.perf_counter() - t_chunk:.1f} s"
                )
    years = [c.N / _HOURS_YEAR for c in cases]
    return [
        [o.result(c, v, dt, y) for c, o, y in zip(cases, outs, years, strict=True)]
        for v, outs in zip(variants, out, strict=True)
    ]


def _hours_of_use(v, c) -> np.ndarray:
    """The hours of use (N,) of a measure's heating schedule on case ``c`` [-]."""
    if v is None or not v.controlled:
        return np.zeros(1)
    return v.hours_of_use(c.index, c.N)


def hour_of_year(index: pd.DatetimeIndex) -> np.ndarray:
    """Hour of the year (0-8759) of each time stamp [UTC]; 29 February counts as
    28 February (a 365-day year of hours, so that every year maps onto one cycle)."""
    idx = index.tz_convert("UTC") if index.tz is not None else index
    doy = np.asarray(idx.day_of_year) - 1
    leap = np.asarray(idx.is_leap_year) & (doy >= 59)  # 29 Feb and later
    doy = np.where(leap, doy - 1, doy)
    return np.ascontiguousarray(doy * 24 + np.asarray(idx.hour), dtype=np.int64)


def _run_chunk(
    run, P, c: Case, o: CaseOut, sl, modal, e, dt, w, work, aw, t_modal, opts, measure=None,
    ctrl=None, sig=None,
):  # fmt: skip
    from heritage_bayes.projection._stream import chunk_kernel

    t0 = time.perf_counter()
    Y, M, U = {}, {}, {}
    if ctrl is None and measure is not None and measure.controlled:  # the reference
        Y = _controlled(run, P, c, o, sl, dt, w, measure)
    Y = Y or coupled_pair(run, P, c, sl, dt, w)  # hygric sorbing at the simulated Ti
    for s, m in run.models.items():
        u0 = c.U[s][: max(1, w)].mean(axis=0)  # steady state of the first window
        if s in Y:
            Y[s] = np.ascontiguousarray(Y[s])
            M[s], U[s] = _NO_MODAL, np.zeros((1, 1))
        elif modal[s] is None:
            Y[s] = np.ascontiguousarray(m.forward(P[s][sl], c.U[s], dt, u_init=u0)[0][..., 0])
            M[s], U[s] = _NO_MODAL, np.zeros((1, 1))
        else:
            shift = None if ctrl is None else ctrl[4].get(s)  # a calibrated constant source
            Y[s], M[s], U[s] = np.zeros((0, 0)), _modal_arrays(modal[s], u0, shift), c.Ut[s]
    o.seconds["simulate"] += time.perf_counter() - t0 + t_modal
    t0 = time.perf_counter()
    k = sl.stop - sl.start
    spar = np.zeros(k, np.int64)
    spred = np.zeros(k, np.int64)
    dummy = np.zeros((0, 0))
    eT = e["thermal"] if e is not None else dummy
    eP = e["hygric"] if e is not None else dummy
    ws, tmp, btmp, hist, sbuf, zbuf, wbuf = work
    (bpar, bpred), (mabuf, cbuf) = aw
    en, en_col = c.en_params()
    if ctrl is None:
        ctl, bdT, bdP, spin, sig = np.zeros((0, N_CP)), dummy, dummy, 0, np.zeros(1)
    else:
        ctl, bdT, bdP, spin, _ = ctrl
    cost = o.cost[sl]
    kept = np.empty((4, k, c.N)) if c.numpy else np.zeros((0, 0, 0))
    chunk_kernel(
        Y["thermal"], Y["hygric"], M["thermal"], M["hygric"], U["thermal"], U["hygric"],
        eT, eP, e is not None, c.starts, *c.plan.arrays, ws, tmp, btmp, hist, sbuf, zbuf, wbuf,
        o.par[sl], o.pred[sl], spar, spred, o.Tm[sl], o.RHm[sl],
        c.hoy, c.mode, en, en_col, bpar[:k], bpred[:k], o.apar[sl], o.apred[sl], mabuf, cbuf,
        ctl, bdT, bdP, sig, spin, cost, measure is None, kept,
    )  # fmt: skip
    o.cost[sl] = cost
    bad = np.flatnonzero((spar != 0) | (spred != 0))
    if bad.size:
        _recompute(run, P, c, o, sl, bad, e, dt, w, opts, aw, modal, ctrl, sig, measure, kept)
    if c.numpy:  # the families without a compiled pass, with numpy on the same series
        o.put_numpy(c, sl, kept, measure is not None, e is not None)
    o.seconds["risk"] += time.perf_counter() - t0


def _recompute(
    run, P, c: Case, o: CaseOut, sl, bad, e, dt, w, opts, aw, modal, ctrl, sig, measure, kept
):  # fmt: skip
    """Draws the compiled pass handed back (a missing hour, or a series that
    :func:`assess_batch` rejects): the numpy path, with its NaN policy and its errors
    (their series into ``kept`` when it holds any)."""
    from heritage_bayes.climate.risk import assess_batch

    rows = np.arange(sl.start, sl.stop)[bad]
    ys = {} if ctrl is None else _coupled_series(c, modal, ctrl, sig, bad, w)
    if ctrl is None and measure is not None and measure.controlled:
        ys = _controlled(run, P, c, None, rows, dt, w, measure)
    ys = ys or coupled_pair(run, P, c, rows, dt, w)
    for s, m in run.models.items():
        u0 = c.U[s][: max(1, w)].mean(axis=0)
        if s not in ys:
            ys[s] = m.forward(P[s][rows], c.U[s], dt, u_init=u0)[0][..., 0]
    from heritage_bayes.projection._stream import _annual_row

    (bpar, bpred), (mabuf, cbuf) = aw
    en, en_col = c.en_params()

    def annual(T, RH, vals, band, ann):
        for j, i in enumerate(bad):
            Tj, RHj = np.ascontiguousarray(T[j]), np.ascontiguousarray(RH[j])
            args = (c.hoy, c.mode, en, en_col, vals[j], band[i], ann[j], mabuf[0], cbuf[0])
            _annual_row(Tj, RHj, c.N, *args)

    Ts, Ps = ys["thermal"], ys["hygric"]
    RHs = _relative_humidity(Ts, Ps)
    if kept.shape[0]:
        kept[0, bad], kept[1, bad] = Ts, RHs
    o.par[rows] = c.plan.values(assess_batch(Ts, RHs, **opts))
    apar = o.apar[rows]
    annual(Ts, RHs, o.par[rows], bpar, apar)
    o.apar[rows] = apar
    if e is None:
        o.pred[rows] = o.par[rows]
        o.apred[rows] = o.apar[rows]
        bpred[bad] = bpar[bad]
        return
    T = Ts + e["thermal"][bad]
    RH = _relative_humidity(T, Ps + e["hygric"][bad])
    if kept.shape[0]:
        kept[2, bad], kept[3, bad] = T, RH
    o.pred[rows] = c.plan.values(assess_batch(T, RH, **opts))
    apred = o.apred[rows]
    annual(T, RH, o.pred[rows], bpred, apred)
    o.apred[rows] = apred
    o.Tm[rows] = _monthly(T, c.starts)
    o.RHm[rows] = _monthly(RH, c.starts)


def _concat(parts: list[pd.DataFrame]) -> pd.DataFrame:
    df = pd.concat(parts, ignore_index=True)
    df.index.name = "draw"
    df.attrs["units"] = dict(parts[0].attrs.get("units", {}))
    return df
