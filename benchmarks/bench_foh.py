"""First-order hold vs zero-order hold of the interval mean, on real hourly readings.

An outdoor temperature read at the hour is linear between readings (the convention of
:func:`heritage_bayes.io.align` for instantaneous columns). The aligned frame holds the
hour's mean, which the simulator holds over the hour (ZOH); the exact step for a
linear input is the first-order hold (:func:`heritage_bayes.rc.discretize_foh`). This
prints the RMS and largest error of the indoor node of a thermal_2c room against a
1-minute simulation of the linear input, for both, over 90 days of De Bilt readings
(``../shared/data/knmi-debilt``), for a fast air node (τ ≈ 5 min) and a slower one
(τ ≈ 1 h).

    python benchmarks/bench_foh.py
"""

from __future__ import annotations

import sys
from pathlib import Path

import numpy as np
from scipy.linalg import expm

sys.path.insert(0, str(Path(__file__).resolve().parent))

import heritage_bayes as hb
from bench_sbc import KNMI, _knmi_cache

ROOMS = {
    "fast air node": dict(Cw=5e7, Ci=3e5, Gw=200.0, Gi=800.0, Gfast=150.0, Gf=20.0, fI_S=3.0),
    "air node ~1 h": dict(Cw=5e7, Ci=2.0e6, Gw=200.0, Gi=400.0, Gfast=150.0, Gf=20.0, fI_S=3.0),
}
SUB = 60  # 1-minute reference steps


def main() -> int:
    te = _knmi_cache()["Te"].interpolate().to_numpy()[: 24 * 90 + 1]
    m = hb.model("thermal_2c", surfaces=("S",))
    U = np.zeros((te.size, m.n_inputs))
    U[:, m.input_names.index("Te")] = te
    U[:, m.input_names.index("Tf")] = te.mean()
    o = m.state_names.index("Ti")
    for label, p in ROOMS.items():
        Ad, B0, B1, _ = hb.rc.discretize_foh(m, p, 3600.0)
        _, Bd, _, _, _ = hb.discretize(m, p, 3600.0)
        A, B, _, _ = m.state_space(p)
        Af = expm(A * 3600.0 / SUB)
        Bf = np.linalg.solve(A, Af - np.eye(len(A))) @ B
        x_foh = x_zoh = x_ref = np.linalg.solve(-A, B @ U[0])
        e_foh, e_zoh = [], []
        for k in range(te.size - 1):
            x_foh = Ad @ x_foh + B0 @ U[k] + B1 @ U[k + 1]
            x_zoh = Ad @ x_zoh + Bd @ (0.5 * (U[k] + U[k + 1]))
            for j in range(SUB):
                x_ref = Af @ x_ref + Bf @ (U[k] + (j + 0.5) / SUB * (U[k + 1] - U[k]))
            e_foh.append(x_foh[o] - x_ref[o])
            e_zoh.append(x_zoh[o] - x_ref[o])
        tau = np.sort(1.0 / np.linalg.eigvals(-A).real / 3600.0)[::-1]
        rms = [float(np.sqrt(np.mean(np.square(e)))) for e in (e_foh, e_zoh)]
        print(
            f"{label} (τ {tau[0]:.1f} h, {tau[1]:.2f} h): Ti error vs {SUB}-substep linear input "
            f"RMS FOH {rms[0]:.1e} K, ZOH of the hour mean {rms[1]:.3f} K "
            f"(largest {np.max(np.abs(e_zoh)):.3f} K)"
        )
    return 0


if __name__ == "__main__":
    if not KNMI.is_file():
        sys.exit(f"needs {KNMI}")
    sys.exit(main())
