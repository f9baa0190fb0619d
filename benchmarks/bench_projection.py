"""Projection benchmark (issue 12): posterior draws × 30 years hourly × 4 scenarios ×
2 models (thermal_2c, hygric_2c), noise draws and every risk indicator included.

The streamed engine (:func:`heritage_bayes.projection.engine.simulate_case`: chunks of
draws, each chunk simulated over the whole series, noise added, RH capped, reduced at
once to indicators and monthly means) against a naive loop in the same run: one draw
at a time (``model.forward`` for one parameter set, the noise model's ``sample`` for
one draw, ``risk.assess`` twice: predictive and noise-free), timed on a few draws and
scaled. Both produce the same per-draw indicators (checked).

The weather is the demo's TMY3 year (Greensboro, NC) repeated; the scenarios add 1–4 K
to Te and Tf at constant outdoor RH. Target of the issue: 1000 draws in ≤ 60 s and
≤ 2 GB. The engine's time is linear in draws × hours, so it is measured at ``--draws``
(default 100) and extrapolated to 1000; run with ``--draws 1000`` for the full size.

Run from the repository root: ``python benchmarks/bench_projection.py [--draws N]
[--years Y]``. Prints wall and CPU time (user+sys of this process) and the peak RSS.
"""

from __future__ import annotations

import argparse
import resource
import time
from types import SimpleNamespace

import numpy as np
import pandas as pd

import heritage_bayes as hb
from heritage_bayes.climate import risk
from heritage_bayes.climate.psychro import saturation_vapour_pressure
from heritage_bayes.demo import TRUE_HYGRIC, TRUE_THERMAL, _inputs
from heritage_bayes.inference.likelihoods import get_noise_model
from heritage_bayes.projection.engine import Draws, _relative_humidity, simulate_case

SCENARIOS = (1.0, 2.0, 3.0, 4.0)  # [K] warming of Te and Tf
NAIVE_DRAWS = 3


def _inputs_years(years: int) -> pd.DataFrame:
    _, inp, _, _, _ = _inputs("greensboro_tmy3")
    n = len(inp)
    reps = pd.concat([inp] * years, ignore_index=True)
    reps.index = pd.date_range(inp.index[0], periods=n * years, freq="h")
    return reps


def _scenario(inp: pd.DataFrame, dT: float) -> pd.DataFrame:
    out = inp.copy()
    ratio = saturation_vapour_pressure(inp["Te"] + dT) / saturation_vapour_pressure(inp["Te"])
    out["Te"] = inp["Te"] + dT
    out["Tf"] = inp["Tf"] + dT
    out["Pe"] = inp["Pe"] * ratio  # constant outdoor RH
    return out


def _draws(models, K: int, seed: int = 0) -> Draws:
    rng = np.random.default_rng(seed)
    truth = {"thermal": TRUE_THERMAL, "hygric": TRUE_HYGRIC}
    noise = {"thermal": (0.3, 0.9), "hygric": (30.0, 0.9)}
    model, nz, nms = {}, {}, {}
    for s, m in models.items():
        base = {p: truth[s][p] for p in m.parameter_names}
        jit = {p: v * np.exp(rng.normal(0, 0.05, K)) for p, v in base.items()}
        model[s], _ = m.param_array(jit)
        sig, phi = noise[s]
        nz[s] = np.column_stack([sig * np.exp(rng.normal(0, 0.1, K)), np.full(K, phi)])
        nms[s] = get_noise_model("ar1")
    return Draws(index=np.arange(K), model=model, noise=nz, noise_models=nms)


def _naive(run, draws: Draws, inputs: pd.DataFrame, k: int, seed: int):
    """One draw at a time: the model, one noise draw, ``risk.assess`` twice."""
    rows = []
    rng = np.random.default_rng([seed, k])
    out = {}
    for s, m in run.models.items():
        U = inputs[list(m.input_names)].to_numpy(float)
        u0 = U[:720].mean(axis=0)  # the same initial state as the engine
        y = m.forward(draws.model[s][k : k + 1], U, 3600.0, u_init=u0)[0][0, :, 0]
        e = draws.noise_models[s].sample(rng, draws.noise[s][k : k + 1], len(U), 1)[0, :, 0]
        out[s] = (y, e)
    Ts, Ps = out["thermal"][0], out["hygric"][0]
    T, P = Ts + out["thermal"][1], Ps + out["hygric"][1]
    for TT, PP in ((T, P), (Ts, Ps)):
        rows.append(risk.assess(TT, _relative_humidity(TT, PP)))
    return rows


def main() -> int:
    ap = argparse.ArgumentParser()
    ap.add_argument("--draws", type=int, default=100)
    ap.add_argument("--years", type=int, default=30)
    ap.add_argument("--chunk", type=int, default=20)
    args = ap.parse_args()
    models = {"thermal": hb.model("thermal_2c"), "hygric": hb.model("hygric_2c")}
    run = SimpleNamespace(models=models, summary={"dt": 3600.0, "init_steps": 720}, path="bench")
    base = _inputs_years(args.years)
    cases = [base] + [_scenario(base, d) for d in SCENARIOS]
    N = len(base)
    K = args.draws
    draws = _draws(models, K)
    print(
        f"projection: {K} draws × {N} h ({args.years} years) × {len(cases)} cases "
        f"(baseline + {len(SCENARIOS)} scenarios) × 2 models, noise + all risk indicators "
        f"(predictive and noise-free); shared 2-core machine"
    )
    # streamed engine
    t0, c0 = time.perf_counter(), time.process_time()
    secs = {"simulate": 0.0, "noise": 0.0, "risk": 0.0}
    results = []
    for inp in cases:
        r = simulate_case(run, draws, inp, seed=1, chunk=args.chunk)
        results.append(r)
        for key in secs:
            secs[key] += r.seconds[key]
    wall, cpu = time.perf_counter() - t0, time.process_time() - c0
    peak = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024**2
    scale = 1000 / K
    print(
        f"  streamed engine   : wall {wall:7.1f} s, CPU {cpu:7.1f} s  (simulate "
        f"{secs['simulate']:.1f} s, noise {secs['noise']:.1f} s, risk {secs['risk']:.1f} s); "
        f"peak RSS {peak:.2f} GB"
    )
    print(
        f"    -> 1000 draws (linear): wall {wall * scale:7.0f} s, CPU {cpu * scale:7.0f} s "
        f"(target <= 60 s, <= 2 GB: {'ok' if wall * scale <= 60 else 'NOT MET'})"
    )
    # naive loop, a few draws of the first scenario, scaled
    n_naive = min(NAIVE_DRAWS, K)
    t0, c0 = time.perf_counter(), time.process_time()
    for k in range(n_naive):
        rows = _naive(run, draws, cases[1], k, seed=1)
    wall_n, cpu_n = time.perf_counter() - t0, time.process_time() - c0
    per = wall_n / n_naive * len(cases)
    print(
        f"  naive loop        : {n_naive} draws × 1 case in wall {wall_n:.1f} s, CPU "
        f"{cpu_n:.1f} s -> {per:.1f} s per draw for all cases; {K} draws: {per * K:.0f} s; "
        f"1000 draws: {per * 1000:.0f} s"
    )
    per_cpu = cpu_n / n_naive * len(cases)
    print(f"  speed-up          : wall {per * K / wall:.2f}x, CPU {per_cpu * K / cpu:.2f}x")
    # same indicators: noise-free ones (the noise streams are seeded per chunk in the
    # engine and per draw in the loop, so only the noise-free series coincide)
    last = rows[1].set_index("indicator")["value"]
    eng = results[1].parametric.iloc[n_naive - 1]
    for name in ("twpi", "emc_range", "vtt_mould_index_max"):
        a, b = float(last[name]), float(eng[name])
        assert abs(a - b) <= 1e-6 * max(1.0, abs(a)), (name, a, b)
    print("  check: naive and streamed noise-free indicators agree (twpi, emc_range, vtt)")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
