"""MAP fits of one config under different noise models: does the simulation keep the signal?

For each model of a section and each noise model, the MAP (the config's optimiser
settings and seed) and the paper's FIT of the noise-free MAP simulation on the
calibration and validation periods, the noise parameters and which parameters sit on a
prior bound. The reference is ``iid`` (the paper's MSE criterion) measured in the same
run: a noise model that lets the noise process carry the slow response shows a FIT far
below it. ``ar1_white:0.999`` is ``ar1_white`` with the cap on phi lifted, and
``ar1_white:tau1`` the experiment of a cap that moves with the parameters (correlation
time no longer than the model's slowest time constant). Also printed:
the residual's autocorrelation at 24 h and 168 h and the range of its monthly means
(a slow misfit: what the noise model's correlation time has to carry or leave out).
``--clear-sky NAME=TILT,AZ`` replaces a config's ``irradiance: none`` by a clear-sky
proxy on one surface (is the slow misfit a missing solar input?).

    python benchmarks/fit_noise_models.py configs/orholm.yaml thermal thermal_2c,thermal_1c
    python benchmarks/fit_noise_models.py configs/orholm.yaml thermal thermal_2c \
        --clear-sky H=0,0
    python benchmarks/fit_noise_models.py configs/orholm.yaml hygric hygric_2c,hygric_2c_fixed
"""

from __future__ import annotations

import argparse
import contextlib
import time

import numpy as np
import pandas as pd

from _common import config_map
from heritage_bayes.config import load_config
from heritage_bayes.inference.results import fit_metrics
from heritage_bayes.rc.derived import time_constants


def _acf(r: np.ndarray, lag: int) -> float:
    """Autocorrelation of a residual series with gaps at ``lag`` steps."""
    r = r - np.nanmean(r)
    a, b = r[lag:], r[:-lag]
    ok = np.isfinite(a) & np.isfinite(b)
    return float(np.sum(a[ok] * b[ok]) / np.sqrt(np.sum(a[ok] ** 2) * np.sum(b[ok] ** 2)))


@contextlib.contextmanager
def _error_faster_than_model(out: str):
    """The experiment ``ar1_white:tau1``: the model error's correlation time
    -dt/ln(phi) no longer than the model's own slowest time constant (a cap that moves
    with the parameters), imposed on the log-likelihood the MAP maximises."""
    from heritage_bayes.inference.posterior import LogPosterior

    plain = LogPosterior.log_likelihood

    def constrained(self, theta):
        theta = np.atleast_2d(theta)
        tau1 = time_constants(self.model, theta[:, : self.n_model])[:, 0]  # [s], NaN: invalid
        phi = theta[:, self.params.names.index(f"phi_{out}")]
        return np.where(-self.dt / np.log(phi) <= tau1, plain(self, theta), -np.inf)

    LogPosterior.log_likelihood = constrained
    try:
        yield
    finally:
        LogPosterior.log_likelihood = plain


def _sun_proxy_correlation(r: pd.Series, te: pd.Series) -> dict[str, float]:
    """Correlation of the daily mean residual (minus its 30-day running mean) with a
    sunshine proxy, the outdoor daily temperature range (smoothed over a week: the
    room's response), per half-year. Clear days have wide ranges."""
    d = pd.DataFrame(
        {"r": r.resample("D").mean(), "rng": te.resample("D").max() - te.resample("D").min()}
    )
    d["r"] = d["r"] - d["r"].rolling(30, center=True, min_periods=5).mean()
    d["rng"] = d["rng"].ewm(span=7).mean()
    d = d.dropna()
    summer = d.index.month.isin([4, 5, 6, 7, 8, 9])
    return {
        h: float(np.corrcoef(q["r"], q["rng"])[0, 1])
        for h, q in (("Apr-Sep", d[summer]), ("Oct-Mar", d[~summer]))
    }


def fit(cfg, section: str, model: str, noise: str) -> dict:
    name, _, cap = noise.partition(":")
    sec = getattr(cfg, section)
    priors = dict(sec.priors)
    out = "Ti" if section == "thermal" else "Pi"
    if cap and cap != "tau1":
        priors[f"phi_{out}"] = {"dist": "uniform", "lower": 0.0, "upper": float(cap)}
    elif cap:
        priors[f"phi_{out}"] = {"dist": "uniform", "lower": 0.0, "upper": 0.999}
    other = "hygric" if section == "thermal" else "thermal"
    sec = sec.model_copy(update={"noise": name, "model": model, "priors": priors})
    cfg = cfg.model_copy(update={section: sec, other: None})
    t0 = time.process_time()
    with _error_faster_than_model(out) if cap == "tau1" else contextlib.nullcontext():
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
    frame = prep.frame.iloc[cal.start + prep.warmup_steps : cal.stop]
    monthly = pd.Series(r, index=frame.index).resample("MS").mean().dropna()
    sun = (
        _sun_proxy_correlation(pd.Series(r, index=frame.index), frame["Te"])
        if "Te" in frame
        else {}
    )
    tau = time_constants(m, mp.theta[: lp.n_model]) / 3600.0  # slowest first
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
        "monthly": (float(monthly.min()), float(monthly.max())),
        "sun": sun,
        "tau_h": tau,
        "cpu": time.process_time() - t0,
    }


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("config")
    ap.add_argument("section", choices=["thermal", "hygric"])
    ap.add_argument("models", help="comma-separated catalogue models")
    ap.add_argument("--noise", default="iid,ar1,ar1_white:0.999,ar1_white")
    ap.add_argument(
        "--clear-sky",
        metavar="NAME=TILT,AZ",
        help="a clear-sky irradiance proxy on one surface (tilt, azimuth [°]) instead of "
        "the config's irradiance: none",
    )
    args = ap.parse_args()
    cfg = load_config(args.config)
    if args.clear_sky:
        name, _, angles = args.clear_sky.partition("=")
        tilt, az = (float(v) for v in angles.split(","))
        data = cfg.data.model_copy(
            update={"irradiance": "clear_sky", "surfaces": {name: (tilt, az)}}
        )
        cfg = cfg.model_copy(update={"data": data})
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
                f"168 h {r['acf'][168]:.2f}; monthly mean residual {r['monthly'][0]:+.2f} "
                f"to {r['monthly'][1]:+.2f}; "
                + "".join(
                    f"its correlation with a sunshine proxy {h} {v:+.2f}; "
                    for h, v in r["sun"].items()
                )
                + "model tau [h] "
                + ", ".join(f"{t:.3g}" for t in r["tau_h"])
                + f"; {r['cpu']:.0f} s CPU"
            )


if __name__ == "__main__":
    np.seterr(all="ignore")
    main()
