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

Wall and CPU times, best of 7, BLAS single-threaded; the ratios in the same run, beside
the targets. Last, the log-likelihood of one parameter set per step over 10 and 100
years: a cost per step that grows with the record is a stall (a dying free response
stuck at a subnormal number was one).

    python benchmarks/coupled_hygric.py
"""

from __future__ import annotations

import os

os.environ.setdefault("OPENBLAS_NUM_THREADS", "1")
os.environ.setdefault("OMP_NUM_THREADS", "1")

import time

import numpy as np

import heritage_bayes as hb
from heritage_bayes.inference.likelihoods import get_noise_model
from heritage_bayes.inference.parameters import parameters_for
from heritage_bayes.inference.posterior import LogPosterior
from heritage_bayes.rc.sorption import P_REF

N100 = 100 * 8760
#: A 190 m³ attic at 0.5 ACH with a buffer of 40 kg per unit RH (τ about 60 h).
SORPTION = dict(Cm=40.0, Ci=1.4e-3, Gi=1.2e-7, Gfast=2.5e-7)
LINEAR = dict(Cw=40.0 / P_REF, Ci=1.4e-3, Gw=1e-9, Gi=1.2e-7, Gfast=2.5e-7)
NOISE = (40.0, 0.8, 5.0)  # sigma_Pi [Pa], phi_Pi [-], sigma_meas_Pi [Pa]


def inputs(n: int, seed: int = 0) -> dict[str, np.ndarray]:
    rng = np.random.default_rng(seed)
    t = np.arange(n)
    pe = 900 + 400 * np.sin(2 * np.pi * t / 8766) + 150 * np.sin(2 * np.pi * t / 24)
    pe = pe + rng.normal(0, 40, n)
    ti = 8 + 10 * np.sin(2 * np.pi * t / 8766) + 6 * np.sin(2 * np.pi * (t - 15) / 24)
    return {"Pe": pe, "Pe_slope": np.r_[np.diff(pe), 0.0], "Ti": ti + rng.normal(0, 0.5, n)}


def timed(f, repeat: int = 7) -> tuple[float, float]:
    best_wall, best_cpu = np.inf, np.inf
    for _ in range(repeat):
        w, c = time.perf_counter(), time.process_time()
        f()
        best_wall = min(best_wall, time.perf_counter() - w)
        best_cpu = min(best_cpu, time.process_time() - c)
    return best_wall, best_cpu


def main() -> None:
    cols = inputs(N100)
    obs = cols["Pe"] + 100.0
    nm = get_noise_model("ar1_white")
    rows = []
    for name, p in (("hygric_2c", LINEAR), ("hygric_2c_sorption", SORPTION)):
        m = hb.model(name).with_slopes(["Pe"])
        U = np.column_stack([cols[c] for c in m.input_names])
        P = np.array([[p[n] for n in m.parameter_names]])
        m.forward(P, U[:1000], 3600.0)  # compile once (numba cache)
        sim = timed(lambda m=m, P=P, U=U: m.forward(P, U, 3600.0))
        theta = np.array([[*P[0], *NOISE]])
        lp = LogPosterior(m, parameters_for(m, nm), nm, U, obs, warmup=0, init_window=720,
                          initial_state="estimate")  # fmt: skip
        lp.log_likelihood(theta)
        ll = timed(lambda lp=lp, theta=theta: lp.log_likelihood(theta))
        lp1 = LogPosterior(m, parameters_for(m, nm), nm, U[:8760], obs[:8760], warmup=0,
                           init_window=720, initial_state="estimate")  # fmt: skip
        batch = theta * np.random.default_rng(1).lognormal(0, 0.1, (32, theta.shape[1]))
        batch[:, -2] = NOISE[1]
        lp1.log_likelihood(batch)
        ens = timed(lambda lp1=lp1, batch=batch: lp1.log_likelihood(batch))
        n = N100 // 10
        lpn = LogPosterior(m, parameters_for(m, nm), nm, U[:n], obs[:n], warmup=0,
                           init_window=720, initial_state="estimate")  # fmt: skip
        lpn.log_likelihood(theta)
        ten = timed(lambda lpn=lpn, theta=theta: lpn.log_likelihood(theta))[1] / n * 1e9
        rows.append((name, sim, ll, ens, (ten, ll[1] / N100 * 1e9)))
    for what, i, target in (
        ("simulation, 100 years hourly, one parameter set", 1, "coupled <= 50 ms"),
        ("log-likelihood, 100 years hourly, one parameter set", 2, "ratio <= 2"),
        ("log-likelihood, 1 year hourly, 32 parameter sets", 3, "ratio <= 2"),
    ):
        print(f"{what} (target: {target})")
        for row in rows:
            print(f"  {row[0]:<20s} {row[i][0] * 1e3:8.1f} ms wall {row[i][1] * 1e3:8.1f} ms CPU")
        print(
            f"  ratio coupled / linear: {rows[1][i][0] / rows[0][i][0]:.2f} wall, "
            f"{rows[1][i][1] / rows[0][i][1]:.2f} CPU"
        )
    print("log-likelihood per step, one parameter set, 10 / 100 years (CPU)")
    for row in rows:
        print(f"  {row[0]:<20s} {row[4][0]:6.0f} / {row[4][1]:6.0f} ns")
    print(f"machine: {os.cpu_count()} cores, load average {os.getloadavg()[0]:.1f}")


if __name__ == "__main__":
    main()
