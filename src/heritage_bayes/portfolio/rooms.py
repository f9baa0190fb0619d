"""One room as a Dask task, and its row of the portfolio table."""

from __future__ import annotations

import time
import traceback
from collections.abc import Mapping
from pathlib import Path
from typing import Any

import numpy as np
import pandas as pd

from heritage_bayes.errors import InputError
from heritage_bayes.portfolio.spec import RoomSpec
from heritage_bayes.rundir.summary import STATUSES, RunSummary

__all__ = ["STATUSES", "measured_risk", "report_status", "room_row"]


def _is_done(run_dir: Path, chash: str) -> bool:
    """A finished run of the same config: a run directory (valid marker) whose
    summary.json has the same config hash."""
    from heritage_bayes.rundir.reader import read_summary
    from heritage_bayes.rundir.writer import is_run_directory

    if not is_run_directory(run_dir):
        return False
    try:
        s = read_summary(run_dir)
    except InputError:  # damaged: calibrated again
        return False
    return s.get("config_hash") == chash


def _room_task(spec: RoomSpec, out_dir: str, resume: bool) -> dict:
    """Calibrate one room in a worker; never raises (the row carries the failure)."""
    from heritage_bayes.config import config_hash, parse_config

    t0, c0 = time.perf_counter(), time.process_time()
    run_dir = Path(out_dir) / spec.name
    row: dict[str, Any] = {"room": spec.name, "config": str(spec.config_path)}
    try:
        cfg = parse_config(spec.raw, source=str(spec.config_path), base_dir=spec.base_dir)
        if resume and _is_done(run_dir, config_hash(cfg)):
            row["status"] = "skipped"
            row["message"] = "done in an earlier run (--resume)"
        else:
            from heritage_bayes.calibration.calibrate import run_calibration
            from heritage_bayes.run import saved_chains

            has_chain = bool(saved_chains(run_dir))
            run_calibration(cfg, run_dir, resume=resume and has_chain, quiet=True)
            row["status"] = "done"
            row["message"] = "resumed the saved chains" if resume and has_chain else ""
        row.update(room_row(run_dir))
        if spec.projection is not None:
            row.update(_project_room(run_dir, spec.projection, resume))
    except InputError as exc:
        row["status"] = "failed"
        row["message"] = str(exc)
    except KeyboardInterrupt:
        raise
    except Exception as exc:  # an internal error in one room must not stop the others
        row["status"] = "error"
        row["message"] = f"internal error: {type(exc).__name__}: {exc}\n" + "".join(
            traceback.format_exception(exc)[-6:]
        )
    row["task_seconds"] = time.perf_counter() - t0
    row["task_cpu_seconds"] = time.process_time() - c0
    row["worker_peak_rss_mb"] = _peak_rss_mb()
    return row


def _peak_rss_mb() -> float:
    try:
        import resource

        return resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024.0
    except (ImportError, OSError):  # pragma: no cover - not on POSIX
        return float("nan")


#: Indicators whose projected change the portfolio table carries (median and P(worse)).
PROJECTED = ("twpi", "vtt_mould_index_max", "en15757_outside_baseline", "emc_range")


def _project_room(run_dir: Path, projection: Path, resume: bool) -> dict:
    """Run the room's projection (``hbayes project``) into ``<run>/projection`` and keep
    its headline numbers for the table.

    The columns describe the *most severe* case of the projection: the scenario and
    horizon with the warmest mean outdoor temperature. For each indicator of
    :data:`PROJECTED`: the median change relative to the baseline (paired draws, noise
    included) and the probability that it changes for the worse; the first probability
    statement of the projection file, for that case. With ``resume``, an existing
    ``projection.json`` of the same run is reused.
    """
    from heritage_bayes.projection import project
    from heritage_bayes.rundir.reader import read_json_object

    dest = run_dir / "projection"
    summary_path = dest / "projection.json"
    summary = None
    if resume and summary_path.is_file():
        try:
            summary = read_json_object(summary_path, "the object of a projection summary")
        except InputError:  # damaged: projected again
            summary = None
    if summary is None:
        summary = project(run_dir, projection, out=dest).summary
    cases = [c for c in summary.get("cases", []) if c.get("horizon") is not None]
    row: dict[str, Any] = {
        "projection": str(dest / "projection.html") if (dest / "projection.html").is_file() else ""
    }
    if not cases:
        return row
    worst = max(cases, key=lambda c: c.get("mean_Te", float("-inf")))
    label = worst["label"]
    row["proj.case"] = label
    for ind in PROJECTED:
        entry = summary.get("indicators", {}).get(ind)
        change = (entry or {}).get("change", {}).get(label)
        if change:
            row[f"proj.{ind}.change"] = change.get("q50", change.get("median", float("nan")))
            row[f"proj.{ind}.p_worse"] = change.get("p_worse", float("nan"))
    probs = summary.get("probabilities") or []
    if probs:
        p0 = probs[0]
        # the indicator's name as the projection page prints it, not its key
        what = p0.get("name") or p0["indicator"]
        unit = f" {p0['unit']}" if p0.get("unit") else ""
        row["proj.statement"] = f"P({what} {p0['op']} {p0['value']:g}{unit})"
        row["proj.statement_text"] = _statement_text(p0)
        row["proj.probability"] = p0["cases"].get(label, {}).get("p", float("nan"))
    return row


def _statement_text(p: Mapping) -> str:
    """``P(TWPI < 25 years)``: a probability statement in the indicator's name and unit."""
    from heritage_bayes.climate.risk.registry import indicator_info

    try:
        info = indicator_info(p["indicator"])
    except InputError:  # an indicator this version does not know: its code
        return f"P({p['indicator']} {p['op']} {p['value']:g})"
    return f"P({info.name} {p['op']} {p['value']:g} {info.unit})".replace(" )", ")")


def room_row(run_dir: str | Path) -> dict:
    """The portfolio table's row of one finished run directory.

    Read through the typed summary (:func:`heritage_bayes.rundir.summary.load_summary`).
    Columns: convergence (``converged``: the stopping rule; ``saved_draws_ok``: the
    draws the R-hat and ESS are on (:attr:`~heritage_bayes.rundir.summary.Convergence.draws`)
    within the stated criteria; ``max_rhat``, ``min_ess_bulk``,
    ``wall_seconds``), per measured output ``<section>.<output>.FIT_cal`` /
    ``FIT_val`` [%] and ``coverage90_val`` [-], the slowest time constant and the
    outdoor-temperature gain of each section, and conservation-risk indicators of the
    *measured* indoor climate over the data period (:func:`measured_risk`), and the
    report's verdict (:func:`report_status`).
    """
    from heritage_bayes.rundir.summary import load_summary

    run_dir = Path(run_dir)
    s = load_summary(run_dir)
    conv = s.convergence
    nan = float("nan")
    row: dict[str, Any] = {
        "run_dir": str(run_dir),
        "report": str(run_dir / "report.html") if (run_dir / "report.html").is_file() else "",
        "building": s.building,
        "room_description": s.room,
        "converged": conv.converged,
        "saved_draws_ok": conv.draws_ok,
        "unconverged_reasons": "; ".join(conv.reasons),
        "max_rhat": nan if conv.max_rhat is None else conv.max_rhat,
        "min_ess_bulk": nan if conv.min_ess_bulk is None else conv.min_ess_bulk,
        "wall_seconds": nan if s.wall_seconds is None else s.wall_seconds,
    }
    for sec, out in dict.fromkeys((m.section, m.output) for m in s.metrics):
        if sec == "combined":
            continue
        cal, val = s.metric(sec, out, "calibration"), s.metric(sec, out, "validation")
        for col, v in (
            ("FIT_cal", cal and cal.FIT),
            ("FIT_val", val and val.FIT),
            ("coverage90_val", val and val.coverage90),
        ):
            row[f"{sec}.{out}.{col}"] = nan if v is None else v
    for section in ("thermal", "hygric"):
        for q, col in ((f"{section}.tau_1_h", "tau_1_h"), (f"{section}.gain_Ti_Te", "gain_Te")):
            e = s.derived.get(q)
            if e is not None:
                for suffix, v in (("", e.median), ("_q05", e.q05), ("_q95", e.q95)):
                    row[f"{section}.{col}{suffix}"] = nan if v is None else v
    row.update(report_status(s))
    row.update(measured_risk(run_dir))
    return row


def report_status(s: RunSummary) -> dict:
    """The room's status as its report's verdict gives it: ``verdict_level`` (green,
    amber, red), ``verdict_title`` (the verdict's heading) and ``verdict`` — one of
    :data:`STATUSES`: *converged* (green), *checks failed* (the sampler converged but
    the report's residual, coverage, truth or accuracy checks fail) or *not converged*.

    Read from the verdict the report recorded in ``summary.json`` when it was written
    (:attr:`~heritage_bayes.rundir.summary.RunSummary.verdict`, the one the page shows),
    so the overview never contradicts the report it links. Without one (no report
    written since the run) the run's own decision (its stopping rule) gives *converged*
    or *not converged*, and ``verdict_title`` says that no report was checked.
    """
    v = s.verdict
    if v is None:
        conv = s.convergence
        return {
            "verdict": "converged" if conv.converged and conv.converged_tau else "not converged",
            "verdict_level": "",
            "verdict_title": "no report: the residual and coverage checks were not run",
        }
    return {"verdict": v.status, "verdict_level": v.level, "verdict_title": v.title}


def measured_risk(run_dir: str | Path) -> dict:
    """Conservation-risk indicators of the measured indoor climate of a run.

    Uses the logged ``Ti`` [°C] and ``RHi`` [%] of the run's data period (calibration
    and validation, gaps omitted) with :func:`heritage_bayes.climate.risk.assess`. The
    mechanical indicators (EMC range [% MC]) need no minimum length; the chemical ones
    (TWPI [years]), the mould index (VTT), ASHRAE classes and the EN 15757 band depend on
    the season covered, need a year of data and are left out (NaN) for shorter logs,
    with ``risk_note`` saying so (over a year: computed on the complete years).
    ``risk_flags`` counts the indicators rated "risk" by their published thresholds
    (see ``assess``); the overview sorts by it. Both temperature and RH must have been
    logged; otherwise the columns are absent.
    """
    from heritage_bayes.climate import risk
    from heritage_bayes.climate.risk._inputs import MIN_YEAR_HOURS
    from heritage_bayes.rundir.reader import read_posterior

    try:
        idata = read_posterior(run_dir)
    except InputError:
        return {}
    if "observed_data" not in idata.groups():
        return {}
    obs = idata.observed_data
    if "Ti" not in obs or "RHi" not in obs:
        return {}
    T = np.asarray(obs["Ti"].values, dtype=float)
    RH = np.asarray(obs["RHi"].values, dtype=float)
    ok = np.isfinite(T) & np.isfinite(RH)
    if ok.sum() < 24:
        return {}
    T, RH = T[ok], np.clip(RH[ok], 0.0, 100.0)
    groups = ["mechanical"]  # the others depend on the season covered: a year or more
    if ok.sum() >= MIN_YEAR_HOURS:
        groups += ["chemical", "mould", "ashrae", "en15757"]
    table = risk.assess(T, RH, indicators=groups, nan_policy="omit")
    by = table.set_index("indicator")
    out: dict[str, Any] = {"risk_hours": int(ok.sum())}
    if ok.sum() < MIN_YEAR_HOURS:
        out["risk_note"] = (
            f"{int(ok.sum())} h measured, less than a year: TWPI, mould, ASHRAE and EN 15757 "
            "not computed (they depend on the season covered)"
        )
    elif table.attrs.get("hours_dropped"):
        out["risk_note"] = (
            f"over the complete years: the last {table.attrs['hours_dropped']} h measured "
            "are not used"
        )
    for ind, col in (
        ("twpi", "twpi_years"),
        ("emc_range", "emc_range_pct"),
        ("vtt_mould_index_max", "mould_index_max"),
        ("en15757_outside", "en15757_outside_pct"),
    ):
        out[col] = float(by.loc[ind, "value"]) if ind in by.index else float("nan")
    if "ashrae_best_class" in by.index:
        out["ashrae_best_class"] = str(by.loc["ashrae_best_class", "rating"])
    ratings = table["rating"].astype(str).str.lower()
    out["risk_flags"] = int((ratings == "risk").sum())
    out["risk_flagged"] = ", ".join(table.loc[ratings == "risk", "indicator"].astype(str))
    return out


def _attention_order(df: pd.DataFrame) -> pd.DataFrame:
    """Rooms that need attention first: failed calibrations, then those not converged,
    then those whose report's checks fail (their figures cannot be trusted yet), then
    the most indicators rated "risk", then the shortest preservation index (TWPI)."""
    status_rank = df["status"].map({"failed": 0, "error": 0}).fillna(1)
    conv = df.get("converged", pd.Series(True, index=df.index)).fillna(False).astype(bool)
    if "verdict" in df:  # the report's verdict: not converged, checks failed, converged
        rank = {v: i for i, v in enumerate(STATUSES)}
        conv = df["verdict"].map(rank).fillna(conv.astype(int) * (len(STATUSES) - 1))
    flags = df.get("risk_flags", pd.Series(0, index=df.index)).fillna(0)
    twpi = df.get("twpi_years", pd.Series(np.inf, index=df.index)).fillna(np.inf)
    key = pd.DataFrame({"s": status_rank, "c": conv.astype(int), "f": -flags, "t": twpi})
    order = key.sort_values(["s", "c", "f", "t"], kind="stable").index
    out = df.loc[order].reset_index(drop=True)
    out.insert(0, "attention_rank", np.arange(1, len(out) + 1))
    return out
