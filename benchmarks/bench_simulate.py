"""Forward-model benchmark: thermal_4a with 6 inputs.

1. 100 years hourly (876,600 steps), one parameter set (target <= 50 ms; the paper
   reports 0.45 s for a first-order model in MATLAB).
2. 10 years hourly against ``scipy.signal.dlsim`` on the same input (the reference,
   measured in the same run; expect >= 50x).
3. A batch of 64 parameter sets x 1 year hourly, discretization included
   (target <= 25 ms), against a loop of ``scipy.signal.dlsim``.
4. A controlled room: the same model with a power-limited thermostat
   (:mod:`heritage_bayes.rc.control`, a set-point the free-running room falls below
   about half of the time), 10 years hourly and the 64-set batch, against the linear
   model in the same run (target: within 3x), in CPU time, single-threaded BLAS.
"""

from __future__ import annotations

import time

import numpy as np
from scipy import signal
from threadpoolctl import threadpool_limits

import heritage_bayes as hb
from _common import best_of, report

P = dict(
    Cw=5e8,
    Ci=2e6,
    Cint=5e7,
    Gw=400.0,
    Gi=600.0,
    Gint=300.0,
    Gfast=100.0,
    Gf=20.0,
    fI_N=0.5,
    fI_E=1.0,
    fI_S=2.0,
    fI_W=1.0,
    fsol=0.5,
)


def make_inputs(n: int, seed: int = 0) -> np.ndarray:
    rng = np.random.default_rng(seed)
    t = np.arange(n)
    te = 10 + 8 * np.sin(2 * np.pi * t / 8766) + 4 * np.sin(2 * np.pi * t / 24)
    sol = np.clip(400 * np.sin(2 * np.pi * t / 24), 0, None)[:, None] * rng.uniform(
        0.3, 1.0, (n, 4)
    )
    return np.column_stack([te + rng.normal(0, 1, n), sol, np.full(n, 10.0)])


def dlsim_reference(m, params, U, dt=3600.0):
    Ad, Bd, C, D, _ = hb.discretize(m, params, dt)
    A, B, _, _ = m.state_space(params)
    x0 = np.linalg.solve(-A, B @ U[0])
    return signal.dlsim((Ad, Bd, C, D, dt), U, x0=x0)[1]


def main() -> None:
    m = hb.model("thermal_4a")
    U100 = make_inputs(876_600)
    U10 = U100[:87_660]
    U1 = U100[:8_760]
    hb.simulate(m, P, U1)  # compile the kernel once (numba cache)

    t100 = best_of(lambda: hb.simulate(m, P, U100), repeat=5)
    report("thermal_4a, 100 years hourly (876,600 steps)", t100, 0.050)

    t10 = best_of(lambda: hb.simulate(m, P, U10), repeat=7)
    t10_ref = best_of(lambda: dlsim_reference(m, P, U10), repeat=3)
    err = np.abs(hb.simulate(m, P, U10) - dlsim_reference(m, P, U10)).max()
    report("thermal_4a, 10 years hourly", t10)
    report("scipy.signal.dlsim, same 10 years (reference)", t10_ref)
    print(
        f"{'ratio dlsim / heritage_bayes (10 years)':<58s} {t10_ref / t10:9.1f} x"
        f"  (expect >= 50x; max |diff| = {err:.1e} °C)"
    )

    rng = np.random.default_rng(1)
    K = 64
    batch = {k: v * np.exp(rng.normal(0, 0.2, K)) for k, v in P.items() if k != "fsol"}
    batch["fsol"] = rng.uniform(0.2, 0.8, K)
    tb = best_of(lambda: hb.simulate(m, batch, U1), repeat=7)
    one = [{k: v[i] for k, v in batch.items()} for i in range(8)]
    tb_ref = best_of(lambda: [dlsim_reference(m, p, U1) for p in one], repeat=3) * K / 8
    report("batch 64 sets x 1 year, discretization included", tb, 0.025)
    report("loop of dlsim, 64 sets x 1 year (reference, scaled from 8)", tb_ref)
    print(f"{'ratio dlsim loop / batch':<58s} {tb_ref / tb:9.1f} x")

    mc = hb.model("thermal_4a", thermostat={"power_limit": True})
    pc = dict(P, Tset=12.0, Pmax=4000.0)
    hb.simulate(mc, pc, U1)  # compile
    y_free = hb.simulate(m, P, U10)[:, 0]
    active = float((y_free < 12.0).mean())
    batch_c = dict(batch, Tset=np.full(K, 12.0), Pmax=np.full(K, 4000.0))
    # CPU time (process_time), best of interleaved repeats: robust on a shared machine
    with threadpool_limits(limits=1):
        cases = {
            "linear 10 years": lambda: hb.simulate(m, P, U10),
            "thermostat 10 years": lambda: hb.simulate(mc, pc, U10),
            "linear batch": lambda: hb.simulate(m, batch, U1),
            "thermostat batch": lambda: hb.simulate(mc, batch_c, U1),
        }
        cpu = dict.fromkeys(cases, float("inf"))
        for _ in range(9):
            for k, fn in cases.items():
                t0 = time.process_time()
                fn()
                cpu[k] = min(cpu[k], time.process_time() - t0)
    for k, v in cpu.items():
        report(f"CPU time, {k} (single thread)", v)
    print(
        f"{'ratio thermostat / linear, 10 years (CPU)':<58s} "
        f"{cpu['thermostat 10 years'] / cpu['linear 10 years']:9.2f} x"
        f"  (target <= 3x; free-running room below the set-point {active:.0%} of hours)"
    )
    print(
        f"{'ratio thermostat / linear, batch 64 x 1 year (CPU)':<58s} "
        f"{cpu['thermostat batch'] / cpu['linear batch']:9.2f} x  (target <= 3x)"
    )


if __name__ == "__main__":
    main()
