"""What the report reads from a run directory, and small helpers on it.

:func:`load_run_data` checks the directory (``REQUIRED_FILES``), loads it with
:func:`heritage_bayes.run.load_run` and returns a :class:`RunData`; the helpers turn
its ``posterior.nc`` groups and ``summary.json`` into arrays and labels.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from heritage_bayes.errors import InputError
from heritage_bayes.rundir.summary import Estimate, RunSummary

__all__ = [
    "REQUIRED_FILES",
    "RunData",
    "flat_draws",
    "load_run_data",
    "measurement_gaps",
    "model_label",
    "parameter_set",
    "predictive_quantiles",
    "section_params",
    "time_axis",
    "utc64",
]

#: Files a run directory must hold for a report.
REQUIRED_FILES = ("posterior.nc", "summary.json", "config.yaml")


@dataclass
class RunData:
    path: Path
    run: object  # heritage_bayes.run.Run
    #: ``summary.json``, typed
    summary: RunSummary
    config_text: str
    #: values computed once and shared by several sections (e.g. identifiable coordinates)
    cache: dict = field(default_factory=dict, repr=False)

    @property
    def cfg(self):
        return self.run.config

    @property
    def idata(self):
        return self.run.idata


def load_run_data(run_dir) -> RunData:
    """The run directory, checked and loaded (:func:`heritage_bayes.run.load_run`: a
    missing, truncated, mistyped or foreign file is an InputError naming it)."""
    from heritage_bayes.run import config_yaml, load_run
    from heritage_bayes.rundir.reader import check_run_files

    p = check_run_files(run_dir, REQUIRED_FILES)
    run = load_run(p)
    summary = run.run_summary
    recorded = summary.provenance.recorded
    # the config that produced the posterior (hash checked by load_run), not an edit
    text = (
        config_yaml(run.config)
        if recorded
        else (p / "config.yaml").read_text("utf-8", errors="replace")
    )
    return RunData(path=p, run=run, summary=summary, config_text=text)


def time_axis(ds) -> np.ndarray:
    return np.asarray(ds["time"].values).astype("datetime64[ns]")


def utc64(text: str) -> np.datetime64:
    import pandas as pd

    ts = pd.Timestamp(text)
    if ts.tzinfo is not None:
        ts = ts.tz_convert("UTC").tz_localize(None)
    return np.datetime64(ts.to_datetime64(), "ns")


def flat_draws(da) -> np.ndarray:
    """(chain, draw, time) DataArray -> (chain·draw, time) float array."""
    v = np.asarray(da.values, dtype=float)
    return v.reshape(-1, v.shape[-1])


def predictive_quantiles(idata, var: str, levels) -> np.ndarray:
    """(len(levels), time) quantiles of the predictive variable ``var``: from the
    ``predictive_bands`` group (computed over every saved draw when the run was
    written) when it holds them, else from the draws of ``posterior_predictive`` (runs
    written before the bands existed)."""
    levels = [float(q) for q in levels]
    if "predictive_bands" in idata.groups() and var in idata["predictive_bands"]:
        da = idata["predictive_bands"][var]
        have = np.asarray(da["quantile"].values, dtype=float)
        idx = [int(np.argmin(np.abs(have - q))) for q in levels]
        if np.allclose(have[idx], levels):
            return np.asarray(da.values, dtype=float)[idx]
    return np.quantile(flat_draws(idata.posterior_predictive[var]), levels, axis=0)


def model_label(summary: RunSummary, m: str) -> str:
    """The model of section ``m`` (``combined``: the models joined by ``+``)."""
    if m == "combined":
        return " + ".join(info.model for info in summary.models.values())
    info = summary.models.get(m)
    return m if info is None else info.model


def section_params(summary: RunSummary, m: str) -> dict[str, Estimate]:
    """The parameters of section ``m`` by name."""
    return {e.name: e for e in summary.parameters.values() if e.section == m}


def parameter_set(rd: RunData, m: str):
    """The sampler's ParameterSet of section ``m`` (the run's config through
    :func:`heritage_bayes.run.section_parameters`), or None if it does not match the run
    (other free parameters or priors than ``summary.json`` records)."""
    from heritage_bayes.run import section_parameters

    try:
        _, ps = section_parameters(rd.cfg, m, rd.run.models[m])
    except (InputError, AttributeError, KeyError, ValueError):  # ConfigError is one
        return None
    info = rd.summary.models.get(m)
    names = list(info.free_names) if info is not None else []
    if list(ps.free_names) != names:
        return None
    params = section_params(rd.summary, m)
    for n in names:
        if n not in params or ps[n].prior.describe() != params[n].prior:
            return None
    return ps


def measurement_gaps(rd: RunData, dt: np.timedelta64, column: str | None = None) -> list[tuple]:
    """Measurement gaps as (start, end) datetime64 pairs (of one column, or of all), and
    the input gaps too long to bridge (nothing is simulated there: a gap in every
    output)."""
    out = []
    al = rd.summary.alignment
    long_inputs = [g for g in al.input_gaps if g.filled is False]
    for g in (*al.measurement_gaps, *long_inputs):
        if column is not None and g.column != column and g.filled is not False:
            continue
        if g.start is None or g.end is None:
            continue
        try:
            out.append((utc64(g.start), utc64(g.end) + dt))
        except (TypeError, ValueError):
            continue
    return sorted(set(out))
