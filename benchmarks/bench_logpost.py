"""Log-posterior benchmark (calibration engine).

1 year hourly of ``thermal_4a`` (4 facades) with the AR(1) noise model, a batch of 32
parameter sets (an emcee ensemble): log-posterior evaluations per second on one core
(BLAS limited to one thread; target >= 20,000/s), against a naive log-posterior that
loops over the walkers and simulates each with ``scipy.signal.lsim`` (the reference,
measured in the same run on a subset and scaled).
"""

from __future__ import annotations

import os

os.environ.setdefault("OPENBLAS_NUM_THREADS", "1")
os.environ.setdefault("OMP_NUM_THREADS", "1")
os.environ.setdefault("MKL_NUM_THREADS", "1")

import numpy as np
from scipy import signal

import heritage_bayes as hb
from _common import best_of, report
from heritage_bayes.inference.likelihoods import get_noise_model
from heritage_bayes.inference.parameters import parameters_for
from heritage_bayes.inference.posterior import LogPosterior

TRUTH = dict(
    Cw=2e8,
    Ci=2.4e6,
    Cint=5e7,
    Gw=400.0,
    Gi=1600.0,
    Gint=400.0,
    Gfast=130.0,
    Gf=25.0,
    fI_N=0.5,
    fI_E=2.0,
    fI_S=4.0,
    fI_W=2.0,
    fsol=0.7,
    sigma_Ti=0.25,
    phi_Ti=0.8,
    sigma_meas_Ti=0.1,
    q_Tw=0.05,
    q_Ti=0.05,
    q_Tint=0.05,
)

#: (noise model, initial state) variants timed against the AR(1) steady-state path
VARIANTS = [
    ("ar1", "estimate"),
    ("ar1_white", "steady"),
    ("ar1_white", "estimate"),
    ("iid", "estimate"),
    ("kalman", "estimate"),
]


def problem(n: int = 8760, seed: int = 0) -> LogPosterior:
    rng = np.random.default_rng(seed)
    m = hb.model("thermal_4a")
    t = np.arange(n)
    te = 10 + 8 * np.sin(2 * np.pi * t / 8766) + 4 * np.sin(2 * np.pi * (t - 14) / 24)
    sol = np.clip(400 * np.sin(2 * np.pi * (t - 6) / 24), 0, None)[:, None] * rng.uniform(
        0.3, 1.0, (n, 4)
    )
    U = np.column_stack([te + rng.normal(0, 1, n), sol, np.full(n, 10.0)])
    y = hb.simulate(m, {k: v for k, v in TRUTH.items() if k in m.parameter_names}, U)
    y = y + rng.normal(0, 0.25, y.shape)
    noise = get_noise_model("ar1")
    return LogPosterior(m, parameters_for(m, noise, room_volume=400), noise, U, y)


def naive_logpost(lp: LogPosterior, X: np.ndarray) -> np.ndarray:
    """The same log-posterior, one walker at a time, simulated with scipy.signal.lsim."""
    theta, logprior = lp.params.transform(X)
    out = np.empty(len(X))
    t = np.arange(lp.inputs.shape[0]) * lp.dt
    obs = lp.observed[:, 0]
    for k in range(len(X)):
        p = dict(zip(lp.model.parameter_names, theta[k, : lp.n_model], strict=True))
        A, B, C, D = lp.model.state_space(p)
        x0 = np.linalg.solve(-A, B @ lp.u_init)
        _, y, _ = signal.lsim((A, B, C, D), lp.inputs, t, X0=x0, interp=False)
        r = obs - y
        sigma, phi = theta[k, lp.n_model :]
        ok = np.isfinite(r)
        rr = r[ok]
        e = rr[1:] - phi * rr[:-1]
        v1 = sigma**2 * (1 - phi**2)
        ll = -0.5 * (np.log(2 * np.pi * sigma**2) + rr[0] ** 2 / sigma**2) - 0.5 * np.sum(
            np.log(2 * np.pi * v1) + e**2 / v1
        )
        out[k] = logprior[k] + ll
    return out


def main() -> None:
    lp = problem()
    rng = np.random.default_rng(1)
    x0 = lp.params.to_unconstrained(np.array([[TRUTH[n] for n in lp.params.names]]))
    X = x0 + 0.05 * rng.standard_normal((32, lp.ndim))
    lp(X)  # compile
    t = best_of(lambda: lp(X), repeat=20, number=5)
    report("log-posterior, batch of 32, 1 year hourly thermal_4a + AR(1)", t)
    print(f"{'evaluations per second':<58s} {32 / t:9.0f} /s  (target >= 20,000/s)")
    sub = X[:4]
    t_ref = best_of(lambda: naive_logpost(lp, sub), repeat=2) * 32 / 4
    report("naive per-walker scipy.signal.lsim log-posterior (x32)", t_ref)
    print(f"{'ratio naive / vectorised':<58s} {t_ref / t:9.1f} x")
    diff = np.abs(naive_logpost(lp, sub) - lp(sub)).max()
    print(f"{'max |difference| of the two log-posteriors':<58s} {diff:9.2e}")
    print("\nnoise model and initial state (same problem and batch; ratio to AR(1), steady):")
    for name, init in VARIANTS:
        noise = get_noise_model(name)
        v = LogPosterior(
            lp.model,
            parameters_for(lp.model, noise, room_volume=400),
            noise,
            lp.inputs,
            lp.observed,
            initial_state=init,
        )
        xv = v.params.to_unconstrained(np.array([[TRUTH[n] for n in v.params.names]]))
        Xv = xv + 0.05 * np.random.default_rng(1).standard_normal((32, v.ndim))
        v(Xv)  # compile
        tv = best_of(lambda v=v, Xv=Xv: v(Xv), repeat=20, number=5)
        label = f"  {name}, initial state {init}"
        print(f"{label:<58s} {32 / tv:9.0f} /s  ({t / tv:.2f} x)")


if __name__ == "__main__":
    main()
