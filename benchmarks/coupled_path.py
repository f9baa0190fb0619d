"""The cellar's slow quantities on the record's own path of the wall (``sbc_coupled --path``).

With a capacity that follows the wall's humidity, ``tau1_h`` and ``buffer_hours`` of
:func:`coupled_rooms.network_quantities` depend on where on the isotherm the capacity is
taken. ``sbc_coupled`` ranks them at one point (the record's mean indoor vapour pressure);
here they are taken where the record's wall actually was: at the **harmonic mean of the
capacity along the wall's trajectory over the calibration period**, the one constant
capacity a linear wall needs to follow a varying one to first order (its RH's rate is
``J / C_w(φ)``: the time mean of ``1/C_w``; :mod:`coupled_rooms`'s docstring).

- the truth: the generator's ``M u'(φ_w(t))`` along its own wall's RH, harmonic mean over
  the calibration hours (``capacity_means["harmonic"]``), over ``p_sat`` at the wall;
- each posterior draw: ``C_w g(K φ(t))/g(K φ_ref)`` along that draw's own wall state
  ``φ(t) = P_w(t)/p_sat(15 °C)``, simulated by the fitted model's recursion from the
  draw's conditional posterior mean start state (the one the likelihood integrates out),
  harmonic mean over the same hours.

The ranks are appended to a copy of the log (``tau1_path_h``, ``buffer_hours_path``), so
that ``--table`` and ``--paired`` read them as any other quantity.
"""

from __future__ import annotations

from collections.abc import Iterator

import numpy as np

import coupled_rooms as rooms

#: the quantities this module adds, and the ones they stand for
PATH_QUANTITIES = {"tau1_path_h": "tau1_h", "buffer_hours_path": "buffer_hours"}


def wall_paths(model, P: np.ndarray, U: np.ndarray, x0: np.ndarray) -> np.ndarray:
    """(K, N) the buffer's state [Pa] at the start of every step of ``U`` (N, m) for
    parameter sets ``P`` (K, n) from ``x0`` (K, 2), by the model's own compiled
    recursion one step at a time (the state is what the recursion leaves in ``x``;
    each call restarts the GAB capacity's extrapolation from the present state, a
    second-order difference in the step's change). A cellar's model takes no ``Ti``:
    each step needs its own input row only."""
    P = np.atleast_2d(P)
    kp = model.kernel_parameters(P)
    x = np.ascontiguousarray(x0, dtype=float).copy()
    out = np.empty((P.shape[0], 1))
    path = np.empty((P.shape[0], U.shape[0]))
    U = np.ascontiguousarray(U, dtype=float)
    for k in range(U.shape[0]):
        path[:, k] = x[:, 0]
        model._recursion(P, kp, U[k : k + 1], 3600.0, x, out)
    return path


def rank(d: np.ndarray, t: float) -> dict:
    """The rank entry of ``bench_sbc.fit_and_rank`` for draws ``d`` and truth ``t``."""
    lo90, lo50, hi50, hi90 = np.quantile(d, [0.05, 0.25, 0.75, 0.95])
    return {
        "in50": bool(lo50 <= t <= hi50),
        "in90": bool(lo90 <= t <= hi90),
        "rank": float(np.mean(d < t)),
        "median": float(np.median(d)),
        "sd": float(np.std(d)),
    }


def path_ranks(r: dict, theta: np.ndarray, fit_inputs, models: dict) -> tuple[dict, dict]:
    """Ranks of :data:`PATH_QUANTITIES` for one logged cellar ``r`` whose posterior
    draws are ``theta`` (model then noise parameters), and their truths."""
    import heritage_bayes as hb
    from bench_sbc import log_posterior
    from heritage_bayes.inference.likelihoods import get_noise_model
    from heritage_bayes.rc.isotherm import gab_capacity_factor
    from heritage_bayes.rc.sorption import P_REF
    from sbc_coupled import fit_of

    without = tuple(r["without"])
    room = rooms.generate("cellar", [r["seed"], rooms.ROOMS.index("cellar"), r["rep"]],
                          r.get("cal_days", 60), without=without)  # fmt: skip
    name, opts = models["cellar"]
    model = hb.model(name, **{**opts, "isotherm": r["isotherm"]}).with_slopes(("Pe",))
    U, y = fit_inputs(room, model)
    rows = room["rows"]
    noise_name, init = r.get("variant", "ar1_white:estimate").split(":")[:2]
    _, lp = log_posterior(model, get_noise_model(noise_name), U[rows], y[rows], {},
                          rooms.FLOOR, rooms.ENVELOPE, init)  # fmt: skip
    x0 = lp.initial_states(theta)
    n = lp.n_model
    P = theta[:, :n]
    pw = wall_paths(model, P, U[rows], x0)
    p = {nm: P[:, j] for j, nm in enumerate(model.parameter_names)}
    k_gab = p.get("K_gab", np.zeros(P.shape[0]))
    factor = gab_capacity_factor(pw / P_REF, k_gab[:, None])
    p["Cw"] = p["Cw"] / np.mean(1.0 / factor, axis=1)  # the harmonic mean along the path
    tf = float(np.mean(U[rows, model.input_names.index("Tf")]))
    q = rooms.network_quantities("cellar", p, tf)
    t = dict(r["truth_parameters"])
    t["Cw"] = room["capacity_means"]["harmonic"] / room["wall_psat"]
    qt = rooms.network_quantities("cellar", t, room["Tf_mean"])
    ranks, truths = {}, {}
    for new, old in PATH_QUANTITIES.items():
        truths[new] = float(qt[old])
        ranks[new] = rank(np.asarray(q[old], float), truths[new])
    assert fit_of(r)["ranks"], "a logged fit without ranks"
    return ranks, truths


def gab_cellar(rep: int, seed: int, cal_days: int, fit_inputs, models: dict, gab_truth):
    """One SBC cellar (its ``truth`` under the fit's names) and the log-posterior of its
    fit with a GAB wall (``hbayes calibrate``'s defaults, ``noise: ar1_white``, the start
    estimated): ``(room, model, LogPosterior)``."""
    import heritage_bayes as hb
    from bench_sbc import log_posterior
    from heritage_bayes.inference.likelihoods import get_noise_model

    room = rooms.generate("cellar", [seed, rooms.ROOMS.index("cellar"), rep], cal_days)
    room["truth"] = gab_truth(room)
    name, opts = models["cellar"]
    m = hb.model(name, **opts, isotherm="gab").with_slopes(("Pe",))
    U, y = fit_inputs(room, m)
    rows = room["rows"]
    _, lp = log_posterior(m, get_noise_model("ar1_white"), U[rows], y[rows], {},
                          rooms.FLOOR, rooms.ENVELOPE, "estimate")  # fmt: skip
    return room, m, lp


def start_lines(reps, seed: int, cal_days: int, fit_inputs, models: dict, gab_truth) -> list[str]:
    """``sbc_coupled --start``: per cellar (GAB wall, no fit) the wall's highest K·RH
    over the calibration (the GAB slope's cap acts above 0.97) and, at the true
    parameters with the noise's at their maximum, the start's prior mean, its
    conditional mean and the log-likelihood with the start's quadratic form taken once
    (about the prior mean's trajectory) and twice (then about the conditional mean's)."""
    from scipy.optimize import minimize

    lines = ["cellar: K*RH max; prior mean, start once / twice [Pa]; log L once / twice; "
             "sigma_Pi once / twice"]  # fmt: skip
    for rep in reps:
        room, m, lp = gab_cellar(rep, seed, cal_days, fit_inputs, models, gab_truth)
        kx = room["generator"]["K"] * room["phi_w_range"][1]
        tm = np.array([room["truth"][n] for n in m.parameter_names])

        def theta(v, _tm=tm):
            return np.concatenate([_tm, np.exp(v[:1]), np.tanh(v[1:2]), np.exp(v[2:])])[None]

        out = []
        for twice in (False, True):
            lp._relinearise = twice

            def nll(v, _lp=lp):
                r = _lp.log_likelihood(theta(v))[0]
                return -r if np.isfinite(r) else 1e12

            starts = ([np.log(10.0), 1.5, np.log(3.0)], [np.log(5.0), 0.5, 0.0])
            fits = [
                minimize(nll, s, method="Nelder-Mead", options={"maxiter": 400}) for s in starts
            ]
            best = min(fits, key=lambda r: r.fun)
            th = theta(best.x)
            out.append((-best.fun, lp.initial_states(th)[0, 0], th[0, lp.n_model]))
        xm = lp._x0_mean(lp._form(th[:, : lp.n_model]))[0, 0]
        (l1, s1, g1), (l2, s2, g2) = out
        lines.append(f"{rep:3d}: {kx:.2f}; {xm:.0f}, {s1:.0f} / {s2:.0f}; {l1:.1f} / {l2:.1f}; "
                     f"{g1:.1f} / {g2:.1f}")  # fmt: skip
    return lines


def source_lines(reps, source_seeds, seed: int, cal_days: int, fit_inputs, models: dict,
                 gab_truth, without: tuple = ()) -> Iterator[str]:  # fmt: skip
    """``sbc_coupled --source-seeds``: per cellar (GAB wall, no posterior) the MAP of the
    fit (``bench_sbc.fit_and_rank``'s search: differential evolution, the replicate as
    its seed) under several realisations of the room's moisture source, every other draw
    of the room kept (:func:`coupled_rooms.generate`'s ``source_seed``; ``own`` the room's
    own source; ``without``: parts of the generator left out, as ``--without``): τ1, the
    static gain and the buffer hours at the MAP over their truths, the AR(1) error's
    coefficient at the MAP, and the long-run variance ratio κ of the MAP's standardised
    innovations (Bartlett window of a week,
    :func:`heritage_bayes.inference.tempering.likelihood_temperature`); last, the sd of
    log τ1 at the MAP over the realisations: the spread the source alone gives the
    estimate, to set against the posterior's sd of τ1 (lines as they come)."""
    import heritage_bayes as hb
    from bench_sbc import log_posterior
    from heritage_bayes.inference.likelihoods import get_noise_model
    from heritage_bayes.inference.optimize import find_map
    from heritage_bayes.inference.tempering import likelihood_temperature
    from heritage_bayes.rc.isotherm import gab_capacity_factor
    from heritage_bayes.rc.sorption import P_REF

    name, opts = models["cellar"]
    m = hb.model(name, **opts, isotherm="gab").with_slopes(("Pe",))
    yield "cellar source: MAP / truth of tau1_h, gain_Pe, buffer_hours; phi_Pi; kappa 168 h"
    for rep in reps:
        logs = []
        for s in source_seeds:
            room = rooms.generate("cellar", [seed, rooms.ROOMS.index("cellar"), rep], cal_days,
                                  without=without, source_seed=s)  # fmt: skip
            U, y = fit_inputs(room, m)
            rows = room["rows"]
            phi_m = float(np.nanmean(y[rows])) / P_REF
            truth = rooms.network_quantities("cellar", gab_truth(room, phi_m), room["Tf_mean"])
            ps, lp = log_posterior(m, get_noise_model("ar1_white"), U[rows], y[rows], {},
                                   rooms.FLOOR, rooms.ENVELOPE, "estimate")  # fmt: skip
            mp = find_map(lp, seed=rep, method="differential_evolution", popsize=15, maxiter=200)
            p = dict(zip(ps.names, map(float, mp.theta), strict=True))
            p["Cw"] *= float(gab_capacity_factor(phi_m, p["K_gab"]))
            tf = float(np.mean(U[rows, m.input_names.index("Tf")]))
            q = rooms.network_quantities("cellar", p, tf)
            r = {k: float(q[k]) / float(truth[k]) for k in ("tau1_h", "gain_Pe", "buffer_hours")}
            logs.append(np.log(r["tau1_h"]))
            kappa = likelihood_temperature(lp, np.asarray(mp.theta), 168)
            yield (
                f"{rep:3d} {'own' if s is None else s}: {r['tau1_h']:.3f}, {r['gain_Pe']:.3f}, "
                f"{r['buffer_hours']:.3f}; {p['phi_Pi']:.2f}; {kappa:.2f}"
            )
        if len(logs) > 1:
            yield (
                f"{rep:3d}: sd of log tau1 at the MAP over the sources {np.std(logs, ddof=1):.3f}"
            )
