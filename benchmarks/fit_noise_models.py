"""MAP fits of one config under different noise models: does the simulation keep the signal?

For each model of a section and each noise model, the MAP (the config's optimiser
settings and seed) and the paper's FIT of the noise-free MAP simulation on the
calibration and validation periods, the noise parameters and which parameters sit on a
prior bound. The reference is ``iid`` (the paper's MSE criterion) measured in the same
run: a noise model that lets the noise process carry the slow response shows a FIT far
below it. ``ar1_white:0.999`` is ``ar1_white`` with the cap on phi lifted.

    python benchmarks/fit_noise_models.py configs/orholm.yaml thermal thermal_2c,thermal_1c
    python benchmarks/fit_noise_models.py configs/orholm.yaml hygric hygric_2c,hygric_2c_fixed
"""

from __future__ import annotations

import argparse
import time

import numpy as np

from _common import config_map
from heritage_bayes.config import load_config
from heritage_bayes.inference.results import fit_metrics


def _acf(r: np.ndarray, lag: int) -> float:
    """Autocorrelation of a residual series with gaps at ``lag`` steps."""
    r = r - np.nanmean(r)
    a, b = r[lag:], r[:-lag]
    ok = np.isfinite(a) & np.isfinite(b)
    return float(np.sum(a[ok] * b[ok]) / np.sqrt(np.sum(a[ok] ** 2) * np.sum(b[ok] ** 2)))


def fit(cfg, section: str, model: str, noise: str) -> dict:
    name, _, cap = noise.partition(":")
    sec = getattr(cfg, section)
    priors = dict(sec.priors)
    if cap:
        out = "Ti" if section == "thermal" else "Pi"
        priors[f"phi_{out}"] = {"dist": "uniform", "lower": 0.0, "upper": float(cap)}
    other = "hygric" if section == "thermal" else "thermal"
    sec = sec.model_copy(update={"noise": name, "model": model, "priors": priors})
    cfg = cfg.model_copy(update={section: sec, other: None})
    t0 = time.process_time()
    prep, m, lp, mp = config_map(cfg, section)
    y = lp.simulate_frame(mp.theta[None], prep.model_inputs(section, m), prep.calibration.start)
    y = y[0][0]
    obs = prep.observed(section, m)
    fits = []
    cal = prep.calibration
    r = (
        obs[cal.start + prep.warmup_steps : cal.stop, 0]
        - y[cal.start + prep.warmup_steps : cal.stop, 0]
    )
    acf = {lag: _acf(r, lag) for lag in (24, 168)}
    for period in ("calibration", "validation"):
        sl = getattr(prep, period)
        if sl is None:
            continue
        start = sl.start + (prep.warmup_steps if period == "calibration" else 0)
        fits.append(fit_metrics(obs[start : sl.stop, 0], y[start : sl.stop, 0])["FIT"])
    noise_vals = dict(zip(lp.params.names[lp.n_model :], mp.theta[lp.n_model :], strict=True))
    return {
        "fit": fits,
        "noise": noise_vals,
        "at_bound": lp.params.at_bound(mp.x),
        "loglik": float(lp.log_likelihood(mp.theta[None])[0]),
        "acf": acf,
        "cpu": time.process_time() - t0,
    }


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("config")
    ap.add_argument("section", choices=["thermal", "hygric"])
    ap.add_argument("models", help="comma-separated catalogue models")
    ap.add_argument("--noise", default="iid,ar1,ar1_white:0.999,ar1_white")
    args = ap.parse_args()
    cfg = load_config(args.config)
    print(f"{args.config} [{args.section}]: MAP simulation FIT cal / val [%]")
    for model in args.models.split(","):
        for noise in args.noise.split(","):
            r = fit(cfg, args.section, model, noise)
            fits = " / ".join(f"{f:.1f}" for f in r["fit"])
            nz = ", ".join(f"{k} {v:.3g}" for k, v in r["noise"].items())
            bound = ", ".join(f"{n} ({side})" for n, side in r["at_bound"]) or "none"
            print(
                f"  {model:16s} {noise:16s} FIT {fits:13s} {nz}; at a bound: {bound}; "
                f"log-lik {r['loglik']:.1f}; residual ACF 24 h {r['acf'][24]:.2f}, "
                f"168 h {r['acf'][168]:.2f}; {r['cpu']:.0f} s CPU"
            )


if __name__ == "__main__":
    np.seterr(all="ignore")
    main()
