"""The overall scale of a room without a measured heat input, measured on a config's
section: is the likelihood exactly constant along the scale direction, what the
log-posterior's Hessian at the MAP looks like, and a short chain in the log coordinates
against one along the scale line (:mod:`heritage_bayes.inference.scale`).

    hbayes init oerholm-indoor-climate-data_2009-2021.csv \\
        --weather DMI_outdoor-climate-data_2009-2021.csv --latitude 55.79 \\
        --longitude 12.50 --timezone UTC+1 -o /tmp/orh/config.yaml
    python benchmarks/orholm_chain.py /tmp/orh/config.yaml --model thermal_2c --steps 6000
"""

from __future__ import annotations

import argparse
import time

import numpy as np
from threadpoolctl import threadpool_limits

from _common import config_map
from heritage_bayes.config import load_config
from heritage_bayes.inference.coordinates import default_coordinates
from heritage_bayes.inference.sampler import run_sampler
from heritage_bayes.inference.scale import scale_direction, scale_line


def hessian(lp, x: np.ndarray, h: float = 1e-3) -> np.ndarray:
    """Minus the central-difference Hessian of the log-posterior at ``x``."""
    d = x.size
    E = np.eye(d) * h
    pts = [
        x + si * E[i] + sj * E[j]
        for i in range(d)
        for j in range(d)
        for si, sj in ((1, 1), (1, -1), (-1, 1), (-1, -1))
    ]
    v = lp(np.array(pts)).reshape(d, d, 4)
    H = (v[..., 0] - v[..., 1] - v[..., 2] + v[..., 3]) / (4 * h * h)
    return -0.5 * (H + H.T)


def main() -> None:
    ap = argparse.ArgumentParser()
    ap.add_argument("config")
    ap.add_argument("--model", default="thermal_2c")
    ap.add_argument("--steps", type=int, default=6000)
    ap.add_argument("--seed", type=int, default=1)
    args = ap.parse_args()
    cfg = load_config(args.config)
    cfg = cfg.model_copy(update={"thermal": cfg.thermal.model_copy(update={"model": args.model})})
    prep, m, lp, mp = config_map(cfg, "thermal")
    names = lp.params.free_names
    x = mp.x
    print("MAP:", ", ".join(f"{n} {v:.3f}" for n, v in zip(names, x, strict=True)))
    s = scale_direction(lp)
    print("scale direction on:", [n for n, v in zip(names, s, strict=True) if v])
    ts = np.linspace(-3, 3, 7)
    X = x + ts[:, None] * s
    th, lpr = lp.params.transform(X)
    ll = lp.log_likelihood(th)
    for t, a, b in zip(ts, ll - ll[3], lpr, strict=True):
        print(f"  t {t:+.1f}: log-likelihood change {a:+.2e}, log-prior {b:.3f}")
    lo, hi = lp.params.bounds
    on = s == 1
    print(
        f"  prior support along the line: t in [{np.max(lo[on] - x[on]):.2f}, "
        f"{np.min(hi[on] - x[on]):.2f}]"
    )
    H = hessian(lp, x)
    w, V = np.linalg.eigh(H)
    np.set_printoptions(precision=3, suppress=True, linewidth=160)
    print("Hessian eigenvalues (minus log-posterior) and vectors over", names)
    for i in range(len(w)):
        print(f"  {w[i]:+.3e}", V[:, i])
    inner = default_coordinates(lp)
    for label, coords in (("log", inner), ("scale line", scale_line(lp, inner, x))):
        c0 = time.process_time()
        with threadpool_limits(limits=1, user_api="blas"):
            ch = run_sampler(
                lp,
                x,
                seed=args.seed,
                max_steps=args.steps,
                coordinates=coords,
                bounds=lp.params.bounds,
                max_rhat=None,
                min_ess=None,
            )
        tau = ch.tau
        print(
            f"{label}: {ch.steps} steps, {time.process_time() - c0:.0f} s CPU, acceptance "
            f"{np.mean(ch.accepted) / ch.steps:.3f}, tau "
            + ", ".join(f"{n} {t:.0f}" for n, t in zip(names, tau, strict=True))
        )
        H2 = ch.chain[ch.chain.shape[0] // 2 :].reshape(-1, len(names))
        print(
            "  second half, sd of log coordinates:",
            dict(zip(names, H2.std(0).round(3), strict=True)),
        )


if __name__ == "__main__":
    main()
