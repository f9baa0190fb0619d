"""Where a slow parameter sits and what it is tied to, from a chain of
``bench_coordinates.py --save-chain`` (issue 28: is thermal_4a's ``fsol`` piled on a
bound, on a curved ridge, or tied to the interior node?).

For the second half of the chain (all walkers; the log coordinates of the sampler:
log θ for log-scale priors, logit for fractions on [0, 1]) it prints the parameter's
quantiles (as a value for a logit coordinate), its correlation with every other
coordinate and with the log time constant of a node ``log C - log G``, the share of
its variance explained by a linear and by a quadratic regression on the other
coordinates (near 1 for linear: a straight ridge, which affine-invariant moves follow
at no cost; a gain from quadratic: curvature), and τ [steps] along the extreme
principal directions of the correlation matrix.

    python benchmarks/bench_coordinates.py demo_4a --only node_tau --moves de_snooker \\
        --max-steps 20000 --save-chain /tmp/chain
    python benchmarks/chain_geometry.py /tmp/chain_demo_4a_node_tau.npz fsol \\
        --node Cint:Gint --node Cw:Gw+Gi
"""

from __future__ import annotations

import argparse

import emcee
import numpy as np
from scipy.special import expit


def _r2(X: np.ndarray, v: np.ndarray) -> float:
    """Share of the variance of v explained by least squares on the columns of X."""
    A = np.column_stack([X, np.ones(len(v))])
    r = v - A @ np.linalg.lstsq(A, v, rcond=None)[0]
    return float(1 - r.var() / v.var())


def main() -> None:
    ap = argparse.ArgumentParser()
    ap.add_argument("chain", help="an .npz of bench_coordinates.py --save-chain")
    ap.add_argument("parameter")
    ap.add_argument(
        "--node",
        action="append",
        default=[],
        help="C:G1+G2..., a node's log time constant log C - log ΣG (repeatable), "
        "e.g. Cint:Gint, Cw:Gw+Gi",
    )
    ap.add_argument("--logit", action="store_true", help="the coordinate is a logit")
    args = ap.parse_args()
    data = np.load(args.chain)
    chain, names = data["chain"], [str(n) for n in data["names"]]
    half = chain[chain.shape[0] // 2 :]
    H = half.reshape(-1, chain.shape[2])
    k = names.index(args.parameter)
    v = H[:, k]
    q = [1, 5, 25, 50, 75, 95, 99]
    value = expit(v) if args.parameter.startswith("fsol") or args.logit else v
    print(f"{chain.shape[0]} steps × {chain.shape[1]} walkers; second half")
    print(
        f"{args.parameter} quantiles {q} %: "
        + " ".join(f"{x:.3g}" for x in np.percentile(value, q))
    )
    C = np.corrcoef(H.T)
    print(
        "correlation with "
        + ", ".join(f"{n} {C[k, j]:+.2f}" for j, n in enumerate(names) if j != k)
    )
    for node in args.node:
        c, gs = node.split(":")
        gs = gs.split("+")
        lt = H[:, names.index(c)] - np.log(sum(np.exp(H[:, names.index(g)]) for g in gs))
        print(
            f"log {c}/({'+'.join(gs)}) [log s]: median {np.median(lt):.2f} (sd {lt.std():.2f}); "
            f"correlation {np.corrcoef(v, lt)[0, 1]:+.2f}; log {gs[0]} 1-99 %: "
            + " ".join(f"{x:.2f}" for x in np.percentile(H[:, names.index(gs[0])], [1, 99]))
        )
        if value is not v:  # a fraction: which of its transforms is linear in lt?
            for label, t in (
                ("logit f", v),
                ("f", value),
                ("log f", np.log(value)),
                ("log(1 - f)", np.log1p(-value)),
            ):
                print(
                    f"  R² of {label} on it: linear {_r2(lt[:, None], t):.4f}, "
                    f"quadratic {_r2(np.column_stack([lt, lt**2]), t):.4f}"
                )
    others = np.delete(H, k, axis=1)
    print(
        f"R² of {args.parameter} on the other coordinates: linear {_r2(others, v):.3f}, "
        f"quadratic {_r2(np.column_stack([others, others**2]), v):.3f}"
    )
    z = (H - H.mean(0)) / H.std(0)
    w, V = np.linalg.eigh(np.cov(z.T))
    for i in (0, -1):
        p = ((half - H.mean(0)) / H.std(0)) @ V[:, i]
        tau = emcee.autocorr.integrated_time(p[:, :, None], quiet=True)[0]
        print(
            f"principal direction {i}: eigenvalue {w[i]:.4g}, τ {tau:.0f}, "
            f"loading of {args.parameter} {V[k, i]:+.2f}"
        )


if __name__ == "__main__":
    main()
