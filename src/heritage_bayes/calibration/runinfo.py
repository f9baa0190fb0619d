"""What a run's summary records beside the posterior: truths, periods, versions, the
share of frozen draws, the fit metrics and band coverage.

The true parameters and derived quantities of generated data (the demo), shown beside
the posterior; the calibration and validation periods; the versions of the libraries
that produced the run. Split from :mod:`heritage_bayes.calibration.outputs`, which calls them.
"""

from __future__ import annotations

import numpy as np

from heritage_bayes.format import OUT_UNITS
from heritage_bayes.inference.results import as_stored, coverage, fit_metrics
from heritage_bayes.rc.identify import derived_quantities


def _truth_for(cfg, prep, section) -> tuple[dict, dict]:
    """True parameter values and derived quantities to show beside the posterior.

    Only for generated data (the demo). Parameters are compared when the calibrated
    model is the generating one; otherwise only the model-independent properties of the
    room are: the static gains, constant-boundary offsets and the slowest time constant.
    """
    truth = (prep.truth or {}).get(section.name) or {}
    gen = (((prep.sources or {}).get("demo") or {}).get("models") or {}).get(section.name)
    if not truth or gen is None:
        return {}, {}
    from heritage_bayes.rc.catalog import CATALOG
    from heritage_bayes.rc.catalog import model as catalog_model

    if gen == section.model.name:
        gen_model = section.model
        params_truth = truth
    else:
        try:
            opts = {}
            if section.model.domain == "thermal" and gen in CATALOG and CATALOG[gen].solar:
                opts["surfaces"] = tuple(cfg.data.surfaces)
            gen_model = catalog_model(gen, **opts)
        except ValueError:
            return {}, {}
        params_truth = {}
    p = {k: v for k, v in truth.items() if k in gen_model.parameter_names}
    if len(p) != len(gen_model.parameter_names):
        return params_truth, {}
    dq = {
        k: float(np.asarray(v).reshape(-1)[0]) for k, v in derived_quantities(gen_model, p).items()
    }
    if gen != section.model.name:
        dq = {k: v for k, v in dq.items() if not k.startswith("tau_") or k == "tau_1_h"}
    return params_truth, dq


def _versions() -> dict:
    """Versions of the key libraries that produced the run."""
    from importlib.metadata import PackageNotFoundError, version

    out = {}
    for name in (
        "heritage_bayes",
        "numpy",
        "scipy",
        "pandas",
        "numba",
        "emcee",
        "arviz",
        "xarray",
        "matplotlib",
        "corner",
        "pvlib",
        "h5py",
        "pydantic",
    ):
        try:
            out[name] = version(name)
        except PackageNotFoundError:
            out[name] = None
    import platform

    out["python"] = platform.python_version()
    return out


def _periods(prep) -> dict:
    idx = prep.frame.index
    out = {}
    for name in ("calibration", "validation"):
        sl = getattr(prep, name)
        if sl is None:
            continue
        out[name] = {
            "start": idx[sl.start].isoformat(),
            "end": (idx[sl.stop - 1] + (idx[1] - idx[0])).isoformat(),
            "steps": int(sl.stop - sl.start),
        }
    return out


def _hours(seconds: float | None) -> float | None:
    """Seconds -> hours; None for none or infinity (JSON has no infinity)."""
    return None if seconds is None or not np.isfinite(seconds) else seconds / 3600.0


def _frozen_share(tau_h, lp) -> float | None:
    """Share of the draws whose slowest time constant [h] exceeds ``FROZEN_RECORDS``
    calibration records (:func:`heritage_bayes.rc.derived.frozen_time_constant`)."""
    from heritage_bayes.rc.derived import FROZEN_RECORDS

    if tau_h is None:
        return None
    record_h = lp.record_seconds / 3600.0
    return float(np.mean(np.asarray(tau_h).reshape(-1) > FROZEN_RECORDS * record_h))


def _metrics_for(prep, codes, outputs, pp_outputs, one_step=None) -> dict:
    """Fit criteria of the posterior-median simulation and band coverage per period;
    with ``one_step`` (output -> (K, N) one-step-ahead samples of a state-space noise
    model) also the coverage of the one-step bands (``coverage50_1step``,
    ``coverage90_1step``).

    The bands are taken from the draws as ``posterior.nc`` stores them
    (:func:`~heritage_bayes.inference.results.as_stored`: float32, packed to 0.01 °C,
    0.1 Pa, 0.01 %RH), so that the coverage read back from the file is the same to the
    last hour: a measurement on a band's edge would otherwise count on one side here and
    on the other in the file."""
    res: dict[str, dict] = {}
    for out in outputs:
        if out not in prep.frame:
            continue
        meas = prep.frame[out].to_numpy(dtype=float)
        ypp, ysim = pp_outputs[out]
        unit = OUT_UNITS.get(out, "")
        ypp = as_stored(ypp, unit)
        med = np.median(ysim, axis=0)
        res[out] = {}
        for pname, code in (("calibration", 1), ("validation", 2)):
            rows = codes == code
            if not rows.any():
                continue
            m = fit_metrics(meas[rows], med[rows])
            m["coverage50"] = coverage(meas[rows], ypp[:, rows], 0.5)
            m["coverage90"] = coverage(meas[rows], ypp[:, rows], 0.9)
            if one_step and out in one_step:
                y1 = as_stored(one_step[out][:, rows], unit)
                m["coverage50_1step"] = coverage(meas[rows], y1, 0.5)
                m["coverage90_1step"] = coverage(meas[rows], y1, 0.9)
            res[out][pname] = m
    return res
