"""The thermo-hygric coupled model beside today's linear hygric model, in one run.

``hygric_2c_sorption`` (a sorbing buffer whose surface vapour pressure follows the indoor
temperature: an exact 2x2 recursion per step, :mod:`heritage_bayes.rc.sorption`) against
``hygric_2c`` (the paper's model 3, constant modal form), with the first-order hold of
``Pe`` (the default for files):

1. 100 years hourly (876,600 steps), one parameter set: simulation (``RCModel.forward``,
   the saturation series of Ti included) (target <= 50 ms for the coupled model);
2. the same record, the log-likelihood with the initial state integrated out (noise
   ``ar1_white``), one parameter set (target: coupled <= 2x linear);
3. one year hourly, a batch of 32 parameter sets (an emcee ensemble): the log-likelihood.

Beside them, ``hygric_2c_sorption`` with ``noise: kalman`` (a Kalman filter over the
per-step transitions, :mod:`heritage_bayes.inference.coupled_kalman`; initial state
from its prior inside the filter): its log-likelihood's ratio to ``hygric_2c``'s (with
``ar1_white``) in the same run.

The same for ``hygric_2c_sorption`` with ``isotherm: gab`` (a capacity that follows the
buffer's humidity, its transitions computed per step from the state:
:mod:`heritage_bayes.rc.isotherm`), its ratio to the linear-isotherm coupled model and
to ``hygric_2c``. Its log-likelihood takes two passes (the start's quadratic form about
the trajectory from the prior mean, then about the one from the conditional mean it
gives, :meth:`LogPosterior._marginal`), the first ending where the start's free
responses have died (here, a buffer of τ about 60 h, within the first months; the
steps it ran are printed): the row ``gab, pass 1 whole`` is the cost where they last the
whole record (a slow wall over a short record: the SBC cellars), both passes in full.

Wall and CPU times, best of 7 with the two models' repeats interleaved (a change of the
machine's load falls on both sides of a ratio), BLAS single-threaded; the ratios beside
the targets. Last, the log-likelihood of one parameter set per step over 10 and 100
years: a cost per step that grows with the record is a stall (a dying free response
stuck at a subnormal number was one).

    python benchmarks/coupled_hygric.py
    python benchmarks/coupled_hygric.py --second-pass 12,8,0

``--second-pass REPS``: instead, what the second pass changes, on the SBC cellars
(``benchmarks/sbc_coupled.py``'s rooms, seed 2049, 60 days, the fit with ``isotherm:
gab``): at the truth (noise sigma 8 Pa, phi 0.9, measurement 3 Pa) and at 120 parameter
sets about it (unconstrained coordinates spread by sd 0.05, 0.2, 0.5, 1: 30 each), the
log-likelihood with the start's quadratic form taken twice minus once, the
Gauss-Newton step on the wall's start, its squared size in the start's posterior sd
(z², all nodes) and the wall's capacity change between the two starts (r = |C(φ at the
conditional mean) / C(φ at the prior mean) - 1|).
"""

from __future__ import annotations

import os
import sys

os.environ.setdefault("OPENBLAS_NUM_THREADS", "1")
os.environ.setdefault("OMP_NUM_THREADS", "1")

import time

import numpy as np

import heritage_bayes as hb
from heritage_bayes.inference.coupled import coupled_filter_stats
from heritage_bayes.inference.likelihoods import get_noise_model
from heritage_bayes.inference.parameters import parameters_for
from heritage_bayes.inference.posterior import LogPosterior
from heritage_bayes.rc.sorption import P_REF

N100 = 100 * 8760
#: A 190 m³ attic at 0.5 ACH with a buffer of 40 kg per unit RH (τ about 60 h).
SORPTION = dict(Cm=40.0, Ci=1.4e-3, Gi=1.2e-7, Gfast=2.5e-7)
LINEAR = dict(Cw=40.0 / P_REF, Ci=1.4e-3, Gw=1e-9, Gi=1.2e-7, Gfast=2.5e-7)
NOISE = (40.0, 0.8, 5.0)  # sigma_Pi [Pa], phi_Pi [-], sigma_meas_Pi [Pa]
KALMAN = (5.0, 3.0, 40.0)  # sigma_Pi [Pa], q_Pw, q_Pi [Pa/√h]


def inputs(n: int, seed: int = 0) -> dict[str, np.ndarray]:
    rng = np.random.default_rng(seed)
    t = np.arange(n)
    pe = 900 + 400 * np.sin(2 * np.pi * t / 8766) + 150 * np.sin(2 * np.pi * t / 24)
    pe = pe + rng.normal(0, 40, n)
    ti = 8 + 10 * np.sin(2 * np.pi * t / 8766) + 6 * np.sin(2 * np.pi * (t - 15) / 24)
    return {"Pe": pe, "Pe_slope": np.r_[np.diff(pe), 0.0], "Ti": ti + rng.normal(0, 0.5, n)}


def paired(fs: list, repeat: int = 7) -> list[tuple[float, float]]:
    """Best (wall, CPU) of each callable, the repeats interleaved (f0, f1, f0, f1, ...) so
    that a change of the machine's load falls on both sides of a ratio."""
    best = [[np.inf, np.inf] for _ in fs]
    for _ in range(repeat):
        for b, f in zip(best, fs, strict=True):
            w, c = time.perf_counter(), time.process_time()
            f()
            b[0] = min(b[0], time.perf_counter() - w)
            b[1] = min(b[1], time.process_time() - c)
    return [tuple(b) for b in best]


def first_pass_steps(lp: LogPosterior, theta: np.ndarray) -> np.ndarray:
    """(K,) steps the likelihood's first pass ran per parameter set before the start's
    free responses died (the record's length: they never did)."""
    tm, tn = lp.split(theta)
    mf = lp._form(tm)
    acc = coupled_filter_stats(lp.model, mf.theta, lp._series, lp._x0_mean(mf), lp.observed,
                               lp.noise, tn, basis=True, dt=lp.dt,
                               stop=lp._first_pass_stop)  # fmt: skip
    return acc[2]


def main() -> None:
    cols = inputs(N100)
    obs = cols["Pe"] + 100.0
    jobs = {}  # model -> {what: callable}
    cases = (
        ("hygric_2c", {}, LINEAR),
        ("hygric_2c_sorption", {}, SORPTION),
        ("hygric_2c_sorption", {"isotherm": "gab"}, {**SORPTION, "K_gab": 0.75}),
        ("hygric_2c_sorption", {"isotherm": "gab", "whole": True}, {**SORPTION, "K_gab": 0.75}),
        ("hygric_2c_sorption", {"kalman": True}, SORPTION),
    )
    runs = {}  # model -> steps the first pass ran, 100 years and each set of the batch
    for name, opts, p in cases:
        whole = opts.pop("whole", False)
        kalman = opts.pop("kalman", False)
        nm = get_noise_model("kalman" if kalman else "ar1_white")
        m = hb.model(name, **opts).with_slopes(["Pe"])
        name = f"{name} ({'gab, pass 1 whole' if whole else 'gab'})" if opts else name
        name = f"{name} (kalman)" if kalman else name
        U = np.column_stack([cols[c] for c in m.input_names])
        P = np.array([[p[n] for n in m.parameter_names]])
        theta = np.array([[*P[0], *(KALMAN if kalman else NOISE)]])
        batch = theta * np.random.default_rng(1).lognormal(0, 0.1, (32, theta.shape[1]))
        if not kalman:
            batch[:, -2] = NOISE[1]

        def lp(n, m=m, U=U, nm=nm):
            return LogPosterior(m, parameters_for(m, nm), nm, U[:n], obs[:n], warmup=0,
                                init_window=720, initial_state="estimate")  # fmt: skip

        l100, l1, l10 = lp(N100), lp(8760), lp(N100 // 10)
        for lpk in (l100, l1, l10):
            lpk._first_pass_stop = 0.0 if whole else lpk._first_pass_stop
        if opts and not whole:
            runs[name] = (first_pass_steps(l100, theta), first_pass_steps(l1, batch))
        jobs[name] = {
            "sim": lambda m=m, P=P, U=U: m.forward(P, U, 3600.0),
            "ll": lambda l100=l100, theta=theta: l100.log_likelihood(theta),
            "ens": lambda l1=l1, batch=batch: l1.log_likelihood(batch),
            "ten": lambda l10=l10, theta=theta: l10.log_likelihood(theta),
        }
        for f in jobs[name].values():
            f()  # compile once (numba cache)
    res = {what: paired([jobs[n][what] for n in jobs]) for what in ("sim", "ll", "ens", "ten")}
    names = list(jobs)
    for what, key, target in (
        ("simulation, 100 years hourly, one parameter set", "sim", "coupled <= 50 ms"),
        ("log-likelihood, 100 years hourly, one parameter set", "ll", "ratio <= 2"),
        ("log-likelihood, 1 year hourly, 32 parameter sets", "ens", "ratio <= 2"),
    ):
        print(f"{what} (target: {target})")
        for name, (w, c) in zip(names, res[key], strict=True):
            print(f"  {name:<26s} {w * 1e3:8.1f} ms wall {c * 1e3:8.1f} ms CPU")
        (w0, c0), (w1, c1), (w2, c2), (w3, c3), (w4, c4) = res[key]
        print(f"  ratio coupled / linear: {w1 / w0:.2f} wall, {c1 / c0:.2f} CPU")
        print(f"  ratio gab / coupled: {w2 / w1:.2f} wall, {c2 / c1:.2f} CPU; "
              f"gab / linear: {w2 / w0:.2f} wall, {c2 / c0:.2f} CPU")  # fmt: skip
        if key != "sim":
            print(f"  ratio gab, pass 1 whole / linear: {w3 / w0:.2f} wall, {c3 / c0:.2f} CPU")
            print(f"  ratio coupled kalman / linear: {w4 / w0:.2f} wall, {c4 / c0:.2f} CPU; "
                  f"/ coupled: {w4 / w1:.2f} wall, {c4 / c1:.2f} CPU")  # fmt: skip
    for name, (one, many) in runs.items():
        print(
            f"{name}: the first pass ran {one[0]:.0f} of {N100} steps (100 years); "
            f"{np.min(many):.0f}-{np.max(many):.0f} of 8760 (1 year, 32 sets)"
        )
    print("log-likelihood per step, one parameter set, 10 / 100 years (CPU)")
    for name, ten, hundred in zip(names, res["ten"], res["ll"], strict=True):
        print(
            f"  {name:<26s} {ten[1] / (N100 // 10) * 1e9:6.0f} / {hundred[1] / N100 * 1e9:6.0f} ns"
        )
    print(f"machine: {os.cpu_count()} cores, load average {os.getloadavg()[0]:.1f}")


def second_pass_lines(reps: list[int]) -> list[str]:
    """``--second-pass``: per cellar the change of the log-likelihood from the second
    pass and the candidate measures of the start's distance (module docstring)."""
    sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
    from coupled_path import gab_cellar
    from heritage_bayes.rc.isotherm import gab_capacity_factor
    from sbc_coupled import MODELS, fit_inputs, gab_truth

    rng = np.random.default_rng(5)
    lines = ["cellar: sets; |twice - once| < 0.01 / 0.1 / 1 nat; median; at the truth "
             "(step on Pw [Pa]); smallest z2*r where the change is >= 0.01 nat"]  # fmt: skip
    for rep in reps:
        room, m, lp = gab_cellar(rep, 2049, 60, fit_inputs, MODELS, gab_truth)
        th0 = np.r_[[room["truth"][n] for n in m.parameter_names], 8.0, 0.9, 3.0][None]
        X0 = lp.params.to_unconstrained(th0)
        X = [X0] + [X0 + s * rng.standard_normal((30, X0.shape[1])) for s in (0.05, 0.2, 0.5, 1)]
        th, lpr = lp.params.transform(np.vstack(X))
        tm, tn = lp.split(th[np.isfinite(lpr)])
        mf = lp._form(tm)
        xm = lp._x0_mean(mf)
        once, mean, cov = lp._integrate(mf, tn, xm, xm, True)
        at = xm.copy()
        at[:, lp.x0_free] = mean
        dll = lp._integrate(mf, tn, at, xm, False)[0] - once
        step = mean - xm[:, lp.x0_free]
        z2 = np.einsum("ki,kij,kj->k", step, np.linalg.inv(cov), step)
        k = tm[:, m.parameter_names.index("K_gab")]
        cap = np.abs(
            gab_capacity_factor(at[:, 0] / P_REF, k) / gab_capacity_factor(xm[:, 0] / P_REF, k) - 1
        )
        d = np.abs(dll[np.isfinite(dll)])
        far = (np.abs(dll) >= 0.01) & np.isfinite(dll)
        lines.append(f"{rep:3d}: {d.size}; {(d < 0.01).sum()} / {(d < 0.1).sum()} / "
                     f"{(d < 1).sum()}; {np.median(d):.2f}; {dll[0]:+.2f} ({step[0, 0]:+.0f}); "
                     f"{np.min(z2[far] * cap[far]):.3f}")  # fmt: skip
    return lines


if __name__ == "__main__":
    if sys.argv[1:2] == ["--second-pass"]:
        for line in second_pass_lines([int(r) for r in sys.argv[2].split(",")]):
            print(line, flush=True)
    else:
        main()
