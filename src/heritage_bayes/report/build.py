"""``RUN_DIR/report.html``: the self-contained HTML report of a calibration run.

Reads only the run directory (``posterior.nc``, ``summary.json``, ``config.yaml`` and
the chain files ``chain_<model>.h5``), draws the figures with matplotlib and ``corner``
(PNG, embedded as ``data:`` URIs), and renders ``templates/report.html`` with jinja2
(autoescaping on: building, room and notes are untrusted text). The page needs no
script, no font and no network: it opens from a USB stick. A Content-Security-Policy
in the page forbids scripts and every external load as a second line of defence.

Sections, in the order a reader needs them: 1 header with the convergence verdict,
2 data, 3 fit, 4 metrics (the paper's Table 2), 5 parameters, 6 identifiability,
7 diagnostics, 8 reproducibility.
"""

from __future__ import annotations

import json
import math
import os
import re
import time
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from heritage_bayes._version import __version__
from heritage_bayes.errors import InputError

__all__ = ["REQUIRED_FILES", "SECTIONS", "convergence_verdict", "write_report"]

#: Files a run directory must hold for a report.
REQUIRED_FILES = ("posterior.nc", "summary.json", "config.yaml")

#: (id, title) of the report's sections, in order.
SECTIONS = (
    ("summary", "1. Summary"),
    ("data", "2. Data"),
    ("fit", "3. Fit"),
    ("metrics", "4. Fit metrics"),
    ("parameters", "5. Parameters"),
    ("identifiability", "6. Identifiability"),
    ("diagnostics", "7. Sampler diagnostics"),
    ("reproducibility", "8. Reproducibility"),
)

#: "Close to converged" (amber) thresholds; green uses the run's own criteria.
AMBER = {"max_rhat": 1.05, "min_ess_bulk": 100.0}

_OUT_UNITS = {"Ti": "°C", "Pi": "Pa", "RHi": "%"}
_OUT_WORDS = {
    "Ti": "indoor temperature",
    "Pi": "indoor vapour pressure",
    "RHi": "indoor relative humidity",
}
_VERSIONS = (
    "numpy",
    "scipy",
    "pandas",
    "xarray",
    "emcee",
    "arviz",
    "matplotlib",
    "corner",
    "pvlib",
    "numba",
    "h5py",
    "jinja2",
)
_TRACE_POINTS = 400  # thinned steps per walker in trace plots
_CORNER_MAX = 3000  # posterior samples in a corner plot


# ------------------------------------------------------------------------ formatting
_SUP = str.maketrans("-0123456789", "⁻⁰¹²³⁴⁵⁶⁷⁸⁹")


def fmt(x, digits: int = 3) -> str:
    """A number for people: 3 significant digits, ``2.41×10⁶`` for large/small ones."""
    if x is None:
        return "—"
    try:
        v = float(x)
    except (TypeError, ValueError):
        return str(x)
    if not math.isfinite(v):
        return "—" if math.isnan(v) else ("∞" if v > 0 else "−∞")
    if v == 0:
        return "0"
    if 1e-3 <= abs(v) < 1e5:
        s = f"{v:.{digits}g}"
        if "e" in s:  # e.g. 1e+03 from .3g
            s = f"{v:.0f}"
        return s.replace("-", "−")
    m, e = f"{v:.{digits - 1}e}".split("e")
    m = m.rstrip("0").rstrip(".") if "." in m else m
    return f"{m}×10{str(int(e)).translate(_SUP)}".replace("-", "−", 1)


def fmt_int(x) -> str:
    if x is None:
        return "—"
    try:
        v = float(x)
    except (TypeError, ValueError):
        return str(x)
    if not math.isfinite(v):
        return "—"
    return f"{round(v):,}".replace(",", " ")


def fmt_pct(x, digits: int = 0) -> str:
    if x is None or not math.isfinite(float(x)):
        return "—"
    return f"{100 * float(x):.{digits}f} %"


def fmt_time(text: str | None) -> str:
    """ISO time -> ``2019-01-02 00:00 UTC``."""
    if not text:
        return "—"
    import pandas as pd

    try:
        ts = pd.Timestamp(text)
    except (TypeError, ValueError):
        return str(text)
    ts = ts.tz_convert("UTC") if ts.tzinfo is not None else ts
    return f"{ts:%Y-%m-%d %H:%M} UTC"


_SCI = re.compile(r"(?<![\w.])[-+]?\d+(?:\.\d+)?e[-+]?\d+")


def prior_text(prior: str | None) -> str:
    """``loguniform[1e+04, 1e+12]`` -> ``loguniform[10⁴, 10¹²]`` (numbers for people)."""
    if not prior:
        return "—"

    def num(m):
        v = float(m.group(0))
        text = fmt(v)
        return text[2:] if text.startswith("1×10") else text

    return _SCI.sub(num, str(prior))


def _grade(ok: bool, close: bool) -> str:
    return "ok" if ok else ("warn" if close else "bad")


def _is_log(prior: str | None) -> bool:
    return bool(prior) and str(prior).startswith(("loguniform", "lognormal"))


# ---------------------------------------------------------------------------- loading
@dataclass
class _RunData:
    path: Path
    run: object  # heritage_bayes.run.Run
    summary: dict
    config_text: str

    @property
    def cfg(self):
        return self.run.config

    @property
    def idata(self):
        return self.run.idata


def _load(run_dir) -> _RunData:
    p = Path(run_dir)
    if not p.is_dir():
        raise InputError(f"{p}: run directory not found; run `hbayes calibrate` first")
    missing = [n for n in REQUIRED_FILES if not (p / n).is_file()]
    if missing:
        raise InputError(
            f"{p}: not a complete run directory ({', '.join(missing)} "
            f"{'is' if len(missing) == 1 else 'are'} missing); run "
            "`hbayes calibrate` first"
        )
    try:
        json.loads((p / "summary.json").read_text(encoding="utf-8"))
    except (json.JSONDecodeError, UnicodeDecodeError) as exc:
        raise InputError(
            f"{p / 'summary.json'}: not valid JSON ({exc}); the run "
            "directory is damaged, run `hbayes calibrate` again"
        ) from None
    from heritage_bayes.run import load_run

    try:
        run = load_run(p)
    except InputError:
        raise
    except (OSError, ValueError, KeyError) as exc:
        raise InputError(
            f"{p / 'posterior.nc'}: cannot be read ({exc}); the run "
            "directory is damaged, run `hbayes calibrate` again"
        ) from None
    text = (p / "config.yaml").read_text(encoding="utf-8")
    return _RunData(path=p, run=run, summary=run.summary, config_text=text)


# ------------------------------------------------------------------------- verdict
def convergence_verdict(summary: dict) -> dict:
    """The plain-words convergence verdict of a run's ``summary.json``.

    Returns
    -------
    dict
        ``level`` (``"green"``: converged — τ criterion met, max R-hat and min bulk ESS
        within the run's criteria; ``"amber"``: close — max R-hat ≤ 1.05 and min bulk
        ESS ≥ 100; ``"red"``: not converged), ``title``, ``text``, ``models`` (one
        plain-words line per model) and ``advice``.
    """
    crit = summary.get("criteria") or {}
    r_ok = float(crit.get("max_rhat", 1.01))
    e_ok = float(crit.get("min_ess_bulk", 400.0))
    tf = float(crit.get("tau_factor", 50.0))
    params = summary.get("parameters") or {}
    lines = []
    for m, info in (summary.get("models") or {}).items():
        pr = {
            k.split(".", 1)[1]: v
            for k, v in params.items()
            if k.startswith(f"{m}.") and v.get("r_hat") is not None
        }
        ch = info.get("chain") or {}
        problems = []
        steps, tmax = ch.get("steps"), ch.get("tau_max")
        if not ch.get("converged_tau", False):
            if steps is not None and tmax is not None and math.isfinite(tmax):
                problems.append(
                    f"the chains ran {fmt_int(steps)} steps but need at least "
                    f"{tf:g} × τ = {fmt_int(tf * tmax)} steps (τ ≈ {fmt_int(tmax)}) with a "
                    "stable τ"
                )
            else:
                problems.append("the autocorrelation-time (τ) criterion was not met")
        if pr:
            worst_r = max(pr, key=lambda k: _nan_low(pr[k].get("r_hat")))
            worst_e = min(pr, key=lambda k: _nan_high(pr[k].get("ess_bulk")))
            rmax = _nan_low(pr[worst_r].get("r_hat"))
            emin = _nan_high(pr[worst_e].get("ess_bulk"))
            if not rmax <= r_ok:
                problems.append(
                    f"the walkers disagree: R-hat up to {rmax:.3f} for "
                    f"{worst_r} (should be ≤ {r_ok:g})"
                )
            if not emin >= e_ok:
                problems.append(
                    f"too few independent samples: bulk ESS down to "
                    f"{fmt_int(emin)} for {worst_e} (should be ≥ {e_ok:g})"
                )
        name = f"{m} ({info.get('model', '?')})"
        if problems:
            lines.append(f"{name}: " + "; ".join(problems) + ".")
        else:
            lines.append(f"{name}: all criteria met.")
    max_rhat = _nan_low(summary.get("max_rhat"))
    min_ess = _nan_high(summary.get("min_ess_bulk"))
    stats = (
        f"max R-hat {max_rhat:.3f} (target ≤ {r_ok:g}), min bulk ESS "
        f"{fmt_int(min_ess)} (target ≥ {e_ok:g}), chain length ≥ {tf:g} τ: "
        f"{'yes' if summary.get('converged_tau') else 'no'}"
    )
    green = (
        bool(summary.get("converged"))
        and bool(summary.get("converged_tau"))
        and max_rhat <= r_ok
        and min_ess >= e_ok
    )
    if green:
        level, title = "green", "Converged"
        text = (
            "The sampler met every convergence criterion: the posterior summaries, "
            "intervals and predictive bands in this report are reliable, within the "
            "assumptions of the model."
        )
        advice = ""
    elif max_rhat <= AMBER["max_rhat"] and min_ess >= AMBER["min_ess_bulk"]:
        level, title = "amber", "Nearly converged — use with care"
        text = (
            "The chains are close to, but do not meet, the convergence criteria. "
            "Medians are usable; treat the intervals, bands and tail values as "
            "approximate."
        )
        advice = (
            "Run the sampler longer before relying on the intervals: raise "
            "sampler.max_steps in the config and run `hbayes calibrate CONFIG --out "
            "RUN_DIR --resume`, which continues the saved chains."
        )
    else:
        level, title = "red", "NOT CONVERGED — do not use these results yet"
        text = (
            "The sampler did not reach a stable posterior. The parameter values, "
            "intervals and predictive bands below may be wrong."
        )
        advice = (
            "Run the sampler longer: raise sampler.max_steps in the config and run "
            "`hbayes calibrate CONFIG --out RUN_DIR --resume`, which continues the saved "
            "chains; if it still does not converge, the model may be over-parameterised "
            "for the data (see the identifiability section and the model-order ladder)."
        )
    if level != "green" and any(
        (i.get("identifiability") or {}).get("n_null", 0)
        for i in (summary.get("models") or {}).values()
    ):
        advice += (
            " Parameter combinations that the data cannot identify (section 6) "
            "slow the sampler down: pinning them with prior knowledge, e.g. the "
            "room volume (room_volume), usually helps."
        )
    return {
        "level": level,
        "title": title,
        "text": text,
        "stats": stats,
        "models": lines,
        "advice": advice.strip(),
    }


def _nan_low(v) -> float:
    """NaN/None -> +inf (counts as worst for 'max must be small')."""
    try:
        f = float(v)
    except (TypeError, ValueError):
        return math.inf
    return f if math.isfinite(f) else math.inf


def _nan_high(v) -> float:
    try:
        f = float(v)
    except (TypeError, ValueError):
        return -math.inf
    return f if math.isfinite(f) else -math.inf


# -------------------------------------------------------------------------- helpers
def _times(ds) -> np.ndarray:
    return np.asarray(ds["time"].values).astype("datetime64[ns]")


def _utc64(text: str) -> np.datetime64:
    import pandas as pd

    ts = pd.Timestamp(text)
    if ts.tzinfo is not None:
        ts = ts.tz_convert("UTC").tz_localize(None)
    return np.datetime64(ts.to_datetime64(), "ns")


def _flat(da) -> np.ndarray:
    """(chain, draw, time) DataArray -> (chain·draw, time) float array."""
    v = np.asarray(da.values, dtype=float)
    return v.reshape(-1, v.shape[-1])


def _model_label(summary: dict, m: str) -> str:
    if m == "combined":
        models = summary.get("models") or {}
        return " + ".join(str(models[k].get("model", k)) for k in models)
    return str((summary.get("models") or {}).get(m, {}).get("model", m))


def _section_params(summary: dict, m: str) -> dict:
    return {
        k.split(".", 1)[1]: v
        for k, v in (summary.get("parameters") or {}).items()
        if k.startswith(f"{m}.")
    }


# ---------------------------------------------------------------------------- header
def _header(rd: _RunData) -> dict:
    s = rd.summary
    models = []
    for m, info in (s.get("models") or {}).items():
        n_free = len((s.get("correlations") or {}).get(m, {}).get("names", []))
        models.append(
            {
                "section": m,
                "model": info.get("model", "?"),
                "noise": info.get("noise", "?"),
                "n_free": n_free,
                "outputs": ", ".join(info.get("output_names", [])),
            }
        )
    periods = []
    for name, p in (s.get("periods") or {}).items():
        hours = p.get("steps", 0) * float(s.get("dt", 3600.0)) / 3600.0
        periods.append(
            {
                "name": name,
                "start": fmt_time(p.get("start")),
                "end": fmt_time(p.get("end")),
                "length": f"{hours / 24:.1f} d" if hours >= 48 else f"{hours:g} h",
            }
        )
    warmup_h = s.get("warmup_steps", 0) * float(s.get("dt", 3600.0)) / 3600.0
    return {
        "name": s.get("name") or rd.path.name,
        "building": s.get("building") or rd.cfg.building,
        "room": s.get("room") or rd.cfg.room,
        "notes": (s.get("notes") or rd.cfg.notes or "").strip(),
        "models": models,
        "periods": periods,
        "warmup": f"{warmup_h / 24:g} d" if warmup_h >= 24 else f"{warmup_h:g} h",
        "created_at": fmt_time(s.get("created_at")),
        "version": s.get("heritage_bayes_version", "?"),
        "seed": s.get("seed"),
        "config_hash": s.get("config_hash", "?"),
        "irradiance": s.get("irradiance_source", "?"),
    }


def _warnings(rd: _RunData, chains_missing: list[str]) -> list[dict]:
    s = rd.summary
    out = []
    irr = str(s.get("irradiance_source", ""))
    if "clear" in irr.lower() or rd.cfg.data.irradiance == "clear_sky":
        out.append(
            {
                "level": "amber",
                "title": "Solar radiation is a clear-sky proxy",
                "text": "The solar input was computed for a cloudless sky, not measured "
                f"(source: {irr}). The solar apertures then absorb the missing "
                "cloudiness (they are biased) and the fit is poorer on cloudy days; "
                "use measured irradiance when it is available.",
            }
        )
    bound = []
    for k, v in (s.get("parameters") or {}).items():
        if v.get("at_bound"):
            unit = v.get("unit", "")
            unit = f" {unit}" if unit and unit != "-" else ""
            bound.append(
                f"{k} (at the {v['at_bound']} end of its prior {prior_text(v.get('prior'))}{unit})"
            )
    if bound:
        out.append(
            {
                "level": "amber",
                "title": "Parameters pressed against a prior bound",
                "text": "The data push these parameters to the edge of the allowed "
                "range, so their interval is cut off by the prior: "
                + "; ".join(bound)
                + ". Check the model and data, or widen "
                "the prior if the bound is not physical.",
            }
        )
    nulls = [
        m
        for m, i in (s.get("models") or {}).items()
        if (i.get("identifiability") or {}).get("n_null", 0)
    ]
    if nulls:
        out.append(
            {
                "level": "info",
                "title": "Not every parameter is identifiable",
                "text": "For the "
                + " and ".join(nulls)
                + (" models" if len(nulls) > 1 else " model")
                + ", some parameter combinations "
                "cannot be determined from these data (section 6): read the "
                "time constants, static gains and ratios, not the absolute "
                "capacities and conductances, unless prior knowledge pins "
                "them.",
            }
        )
    if chains_missing:
        out.append(
            {
                "level": "amber",
                "title": "Chain files missing",
                "text": "Trace plots are not available: "
                + ", ".join(chains_missing)
                + " not found in the run directory.",
            }
        )
    if s.get("truth"):
        p_truth = any(v.get("truth") is not None for v in (s.get("parameters") or {}).values())
        d_truth = any(v.get("truth") is not None for v in (s.get("derived") or {}).values())
        if p_truth:
            where = "the true values are shown next to the estimates"
        elif d_truth:
            where = (
                "the calibrated model is not the generating one, so true values are shown "
                "only for the quantities both share (static gains, slowest time constant)"
            )
        else:
            where = "the calibrated model is not the generating one: no true values to compare"
        out.append(
            {
                "level": "info",
                "title": "Synthetic data",
                "text": "The measurements were generated from known parameters (the "
                f"built-in virtual monument): {where}.",
            }
        )
    return out


# ------------------------------------------------------------------------------ data
def _input_units(rd: _RunData) -> dict:
    units = {}
    for model in rd.run.models.values():
        for c in model.input_names:
            try:
                units[c] = model.network.input_unit(c)
            except (StopIteration, KeyError, AttributeError):
                units[c] = ""
    return units


def _gaps(rd: _RunData, dt: np.timedelta64, column: str | None = None) -> list[tuple]:
    """Measurement gaps as (start, end) datetime64 pairs (of one column, or of all)."""
    out = []
    for g in (rd.summary.get("alignment") or {}).get("measurement_gaps") or []:
        if column is not None and g.get("column") != column:
            continue
        try:
            out.append((_utc64(g["start"]), _utc64(g["end"]) + dt))
        except (KeyError, TypeError, ValueError):
            continue
    return sorted(set(out))


def _data_section(rd: _RunData) -> dict:
    import pandas as pd

    from heritage_bayes.report.figures import C_MEAS, fig_data_overview

    idata = rd.idata
    const = idata.constant_data
    obs = idata.observed_data
    times = _times(const)
    codes = np.asarray(const["period"].values)
    dt = np.median(np.diff(times[:1000])) if times.size > 1 else np.timedelta64(3600, "s")
    units = _input_units(rd)
    inputs = [c for c in const.data_vars if c != "period" and not c.startswith("interpolated.")]
    flags = {
        c.split(".", 1)[1]: np.asarray(const[c].values).astype(bool)
        for c in const.data_vars
        if c.startswith("interpolated.")
    }
    used: set[str] = set()

    def series(name, label, style, source):
        used.add(name)
        return (name, f"{name} {label}", times, np.asarray(source[name].values, dtype=float), style)

    panels = []
    temp = [
        series(c, lab, st, const)
        for c, lab, st in (
            ("Te", "(outdoor)", {"color": "#7f8c8d", "lw": 0.6}),
            ("Tf", "(fixed / ground)", {"color": "#8e44ad", "lw": 1.0, "ls": "--"}),
        )
        if c in inputs
    ]
    if "Ti" in obs:
        temp.append(series("Ti", "(indoor, measured)", {"color": C_MEAS, "lw": 0.7}, obs))
    if temp:
        panels.append({"ylabel": "temperature [°C]", "series": temp})
    vap = (
        [series("Pe", "(outdoor)", {"color": "#7f8c8d", "lw": 0.6}, const)]
        if "Pe" in inputs
        else []
    )
    vap += [
        series(c, lab, st, const)
        for c, lab, st in (("Pf", "(fixed)", {"color": "#8e44ad", "lw": 1.0, "ls": "--"}),)
        if c in inputs
    ]
    if "Pi" in obs:
        vap.append(series("Pi", "(indoor, measured)", {"color": C_MEAS, "lw": 0.7}, obs))
    if vap:
        panels.append({"ylabel": "vapour pressure [Pa]", "series": vap})
    if "RHi" in obs:
        panels.append(
            {
                "ylabel": "relative humidity [%]",
                "series": [series("RHi", "(indoor, measured)", {"color": C_MEAS, "lw": 0.7}, obs)],
            }
        )
    irr = [c for c in inputs if units.get(c) == "W/m²" or c.startswith("I_")]
    if irr:
        ser = []
        for c in irr:
            daily = (
                pd.Series(np.asarray(const[c].values, dtype=float), index=pd.DatetimeIndex(times))
                .resample("1D")
                .mean()
            )
            ser.append(
                (
                    c,
                    f"{c} (daily mean)",
                    daily.index.values + np.timedelta64(12, "h"),
                    daily.to_numpy(),
                    {"lw": 1.0},
                )
            )
            used.add(c)
        panels.append({"ylabel": "solar irradiance [W/m²]", "series": ser})
    for c in inputs:
        if c not in used:
            u = units.get(c, "")
            panels.append(
                {
                    "ylabel": f"{c} [{u}]" if u else c,
                    "series": [series(c, "(input)", {"color": "#7f8c8d", "lw": 0.6}, const)],
                }
            )
    fig = fig_data_overview(times, codes, panels, _gaps(rd, dt), flags)
    al = rd.summary.get("alignment") or {}
    period = al.get("period") or {}
    rows = []
    for role, n in (al.get("rows_in") or {}).items():
        rows.append(
            {
                "role": role,
                "rows_in": fmt_int(n),
                "dropped": fmt_int((al.get("rows_dropped") or {}).get(role)),
            }
        )
    interp = [
        {
            "column": c,
            "filled": fmt_int(n),
            "flagged": fmt_int((al.get("flagged_rows") or {}).get(c)),
        }
        for c, n in (al.get("interpolated") or {}).items()
    ]
    gaps = []
    for kind, key in (
        ("input (filled by interpolation)", "input_gaps"),
        ("measurement", "measurement_gaps"),
    ):
        for g in al.get(key) or []:
            gaps.append(
                {
                    "kind": kind,
                    "column": g.get("column", "?"),
                    "start": fmt_time(g.get("start")),
                    "end": fmt_time(g.get("end")),
                    "length": g.get("length", "?"),
                    "n": fmt_int(g.get("n_missing")),
                    "filled": "yes" if g.get("filled") else "no",
                }
            )
    missing = [
        {"column": c, "n": fmt_int(n)} for c, n in (al.get("measurement_missing") or {}).items()
    ]
    sources = []
    for src in al.get("sources") or []:
        sources.append(
            {
                "role": src.get("role", ""),
                "source": src.get("source", ""),
                "columns": ", ".join(map(str, src.get("columns") or [])),
                "timezone": src.get("timezone", ""),
                "averaged": ", ".join(map(str, src.get("averaged") or [])),
            }
        )
    n_interp = sum(int(v or 0) for v in (al.get("interpolated") or {}).values())
    n_flag = sum(int(v or 0) for v in (al.get("flagged_rows") or {}).values())
    spans: dict[tuple, list[str]] = {}
    for g in al.get("measurement_gaps") or []:
        spans.setdefault((g.get("start"), g.get("end")), []).append(str(g.get("column")))
    n_gap_meas = len(spans)
    words = (
        f"The data were aligned on a {period.get('step', '?')} grid from "
        f"{fmt_time(period.get('start'))} to {fmt_time(period.get('end'))} "
        f"({fmt_int(period.get('n_rows'))} rows). "
    )
    if n_interp:
        words += (
            f"{fmt_int(n_interp)} missing input values were filled by interpolation "
            f"(gaps up to {al.get('max_gap', '?')}), affecting {fmt_int(n_flag)} "
            "rows (marked × in the figure). "
        )
    else:
        words += "No input value had to be interpolated. "
    if n_gap_meas:
        longest = max(
            (float(g.get("length_hours") or 0) for g in al.get("measurement_gaps") or []),
            default=0.0,
        )
        words += (
            f"The measurements have {n_gap_meas} "
            f"{'gap' if n_gap_meas == 1 else 'gaps'} (hatched; the longest "
            f"{longest:g} h): missing measurements are left out of the likelihood "
            "and the metrics, never filled. "
        )
    else:
        words += "The measurements have no gaps. "
    dropped = sum(int(v or 0) for v in (al.get("rows_dropped") or {}).values())
    if dropped:
        words += (
            f"{fmt_int(dropped)} rows of the input tables lie outside this period "
            "and were not used."
        )
    return {
        "figure": fig,
        "rows": rows,
        "interpolated": interp,
        "gaps": gaps,
        "missing": missing,
        "sources": sources,
        "words": words.strip(),
        "irradiance": rd.summary.get("irradiance_source", "?"),
        "ground": ((rd.summary.get("sources") or {}).get("ground_temperature") or {}).get(
            "method", ""
        ),
    }


# ------------------------------------------------------------------------------- fit
def _fit_outputs(rd: _RunData) -> list[dict]:
    """(section, output, pp var, sim var) for every predicted and measured output."""
    pp = rd.idata.posterior_predictive
    obs = rd.idata.observed_data
    out = []
    for m, info in (rd.summary.get("models") or {}).items():
        for o in info.get("output_names", []):
            if f"{m}.{o}" in pp and f"{m}.{o}_sim" in pp and o in obs:
                out.append(
                    {
                        "section": m,
                        "output": o,
                        "pp": f"{m}.{o}",
                        "sim": f"{m}.{o}_sim",
                        "model": info.get("model", m),
                    }
                )
    if "RHi" in pp and "RHi_sim" in pp and "RHi" in obs:
        out.append(
            {
                "section": "combined",
                "output": "RHi",
                "pp": "RHi",
                "sim": "RHi_sim",
                "model": _model_label(rd.summary, "combined"),
            }
        )
    return out


def _fit_section(rd: _RunData, outputs: list[dict]) -> list[dict]:
    from heritage_bayes.report.figures import fig_fit

    pp = rd.idata.posterior_predictive
    obs = rd.idata.observed_data
    const = rd.idata.constant_data
    times_pp = _times(pp)
    codes_all = np.asarray(const["period"].values)
    t_const = _times(const)
    codes = (
        codes_all
        if np.array_equal(t_const, times_pp)
        else np.asarray(const["period"].reindex(time=times_pp, fill_value=-1).values)
    )
    dt = np.median(np.diff(times_pp[:1000])) if times_pp.size > 1 else np.timedelta64(3600, "s")
    items = []
    for o in outputs:
        gaps = _gaps(rd, dt, o["output"])
        Y = _flat(pp[o["pp"]])
        S = _flat(pp[o["sim"]])
        med = np.median(S, axis=0)
        q = np.quantile(Y, [0.05, 0.25, 0.75, 0.95], axis=0)
        y = np.asarray(obs[o["output"]].reindex(time=times_pp).values, dtype=float)
        fig = fig_fit(
            times_pp,
            y,
            med,
            (q[1], q[2]),
            (q[0], q[3]),
            codes,
            output=o["output"],
            model_name=o["model"],
            gaps=gaps,
        )
        what = _OUT_WORDS.get(o["output"], o["output"])
        items.append(
            {
                "id": f"fig-fit-{o['section']}-{o['output']}",
                "title": f"{what} ({o['output']}) — {o['model']}",
                "figure": fig,
                "caption": (
                    f"Measured {what} (black) and the model's posterior "
                    "median (blue line) with the 50 % and 90 % posterior-"
                    "predictive bands (model and noise). Shading: warm-up "
                    "(grey, simulated but not fitted), calibration (green), "
                    "validation (orange); hatched: measurement gaps. Bottom: "
                    "two-week details."
                ),
                "resid": (y - med),
                "codes": codes,
                "times": times_pp,
                **o,
            }
        )
    return items


# --------------------------------------------------------------------------- metrics
def _metrics_section(rd: _RunData) -> dict:
    metrics = rd.summary.get("metrics") or {}
    groups = []
    for m, outs in metrics.items():
        for o, per in outs.items():
            u = _OUT_UNITS.get(o, "")
            groups.append(
                {
                    "label": f"{_model_label(rd.summary, m)} — {o}",
                    "output": o,
                    "unit": u,
                    "per": per,
                }
            )
    periods = [p for p in ("calibration", "validation") if any(p in g["per"] for g in groups)]
    rows = []
    cov_rows = []
    for p in periods:
        cells, cov = [], []
        for g in groups:
            v = g["per"].get(p) or {}
            cells += [
                fmt(v.get("MSE")),
                fmt(v.get("MAE")),
                fmt(v.get("FIT"), 3)
                if v.get("FIT") is None
                else f"{v['FIT']:.1f}".replace("-", "−"),
            ]
            cov += [
                fmt_int(v.get("n")),
                _cov_cell(v.get("coverage50"), 0.5),
                _cov_cell(v.get("coverage90"), 0.9),
            ]
        rows.append({"period": p, "cells": cells})
        cov_rows.append({"period": p, "cells": cov})
    return {"groups": groups, "rows": rows, "cov_rows": cov_rows}


def _cov_cell(v, nominal: float) -> dict:
    if v is None or not math.isfinite(float(v)):
        return {"text": "—", "cls": ""}
    v = float(v)
    # within ±10 percentage points of nominal: fine; too narrow bands are the usual risk
    cls = "ok" if abs(v - nominal) <= 0.1 else "warn"
    return {"text": fmt_pct(v), "cls": cls}


# ------------------------------------------------------------------------ parameters
def _param_tables(rd: _RunData) -> list[dict]:
    s = rd.summary
    crit = s.get("criteria") or {}
    r_ok = float(crit.get("max_rhat", 1.01))
    e_ok = float(crit.get("min_ess_bulk", 400.0))
    tables = []
    for m, info in (s.get("models") or {}).items():
        ident = (info.get("identifiability") or {}).get("parameters") or {}
        params = _section_params(s, m)
        has_truth = any(v.get("truth") is not None for v in params.values())
        rows = []
        for name, v in params.items():
            fixed = v.get("fixed")
            r, e = v.get("r_hat"), v.get("ess_bulk")
            idf = ident.get(name)
            if idf is None:
                id_text = "noise" if v.get("kind") in ("sigma", "phi") else "—"
            elif idf.get("identifiable"):
                id_text = "yes"
            elif idf.get("identifiable_given_scale"):
                id_text = "if scale pinned"
            else:
                id_text = "no"
            truth = v.get("truth")
            inside = None
            if truth is not None and v.get("q05") is not None:
                inside = v["q05"] <= truth <= v["q95"]
            rows.append(
                {
                    "name": name,
                    "description": v.get("description", ""),
                    "unit": v.get("unit", ""),
                    "prior": "fixed" if fixed is not None else prior_text(v.get("prior")),
                    "map": fmt(v.get("map")),
                    "median": fmt(v.get("median")),
                    "interval": "—"
                    if fixed is not None
                    else f"{fmt(v.get('q05'))} … {fmt(v.get('q95'))}",
                    "at_bound": v.get("at_bound"),
                    "truth": fmt(truth) if truth is not None else "—",
                    "inside": inside,
                    "contraction": "—"
                    if v.get("contraction") is None
                    else fmt_pct(v["contraction"]),
                    "r_hat": "—" if r is None else f"{r:.3f}",
                    "r_cls": ""
                    if r is None
                    else _grade(_nan_low(r) <= r_ok, _nan_low(r) <= AMBER["max_rhat"]),
                    "ess_bulk": fmt_int(e),
                    "ess_tail": fmt_int(v.get("ess_tail")),
                    "e_cls": ""
                    if e is None
                    else _grade(_nan_high(e) >= e_ok, _nan_high(e) >= AMBER["min_ess_bulk"]),
                    "tau": fmt_int(v.get("tau")),
                    "ident": id_text,
                }
            )
        mp = info.get("map") or {}
        tables.append(
            {
                "section": m,
                "model": info.get("model", m),
                "noise": info.get("noise", "?"),
                "rows": rows,
                "has_truth": has_truth,
                "map_lp": fmt(mp.get("log_posterior")),
                "map_agreed": f"{mp.get('agreed', '?')} of {mp.get('starts', '?')}",
                "map_method": mp.get("method", "?"),
            }
        )
    return tables


# ------------------------------------------------------------------- identifiability
def _identifiability(rd: _RunData) -> list[dict]:
    from heritage_bayes.report.figures import fig_corner, fig_correlation

    s = rd.summary
    post = rd.idata.posterior
    out = []
    for m, info in (s.get("models") or {}).items():
        idf = info.get("identifiability") or {}
        params = _section_params(s, m)
        nulls = [
            {
                "label": d.get("label", ""),
                "description": d.get("description", ""),
                "pinned_by": ", ".join(d.get("pinned_by") or []),
                "is_scale": bool(d.get("is_scale")),
            }
            for d in idf.get("null_directions") or []
        ]
        summ_lines = [
            ln.strip()[:1].upper() + ln.strip()[1:]
            for ln in str(idf.get("summary", "")).splitlines()[1:]
            if ln.strip() and not ln.strip().startswith("- ")
        ]
        n_params, rank = idf.get("n_params"), idf.get("rank")
        if idf:
            if idf.get("n_null", 0):
                verdict = (
                    f"{idf.get('n_null')} combination(s) of the {n_params} model "
                    f"parameters cannot be determined from these inputs and outputs "
                    f"(rank {rank} of {n_params}), whatever the data quality."
                )
            else:
                verdict = (
                    f"All {n_params} model parameters are structurally "
                    f"identifiable (rank {rank} of {n_params})."
                )
        else:
            verdict = "The structural check was not recorded for this run."
        corr = (s.get("correlations") or {}).get(m) or {}
        names = list(corr.get("names") or [])
        logs = [_is_log((params.get(n) or {}).get("prior")) for n in names]
        fig_c = None
        if len(names) > 1:
            labels = [f"log {n}" if lg else n for n, lg in zip(names, logs, strict=True)]
            fig_c = fig_correlation(
                labels,
                np.asarray(corr.get("matrix"), dtype=float),
                title=f"{m} ({info.get('model', '')}): posterior "
                "correlations (log scale where the prior is)",
            )
        fig_k = None
        has_truth = False
        cols, labels, truths = [], [], []
        for n, lg in zip(names, logs, strict=True):
            key = f"{m}.{n}"
            if key not in post:
                continue
            x = np.asarray(post[key].values, dtype=float).reshape(-1)
            unit = (params.get(n) or {}).get("unit", "")
            t = (params.get(n) or {}).get("truth")
            if lg:
                with np.errstate(divide="ignore", invalid="ignore"):
                    x = np.log10(x)
                t = math.log10(t) if t is not None and t > 0 else None
                labels.append(f"log10 {n}\n[{unit}]" if unit and unit != "-" else f"log10 {n}")
            else:
                labels.append(f"{n}\n[{unit}]" if unit and unit != "-" else f"{n}\n[-]")
            cols.append(x)
            truths.append(t)
        if len(cols) > 1:
            X = np.column_stack(cols)
            X = X[np.all(np.isfinite(X), axis=1)]
            if X.shape[0] > _CORNER_MAX:
                idx = np.linspace(0, X.shape[0] - 1, _CORNER_MAX).round().astype(int)
                X = X[idx]
            has_truth = any(t is not None for t in truths)
            if X.shape[0] > X.shape[1]:
                fig_k = fig_corner(X, labels, truths if has_truth else None)
        out.append(
            {
                "section": m,
                "model": info.get("model", m),
                "verdict": verdict,
                "nulls": nulls,
                "lines": summ_lines,
                "cond": fmt(idf.get("condition_number_identifiable")),
                "corr_fig": fig_c,
                "corner_fig": fig_k,
                "corner_truth": has_truth,
                "derived": _derived_rows(s, m, info),
            }
        )
    return out


def _derived_rows(s: dict, m: str, info: dict) -> dict:
    taus, gains = [], []
    outs = list(info.get("output_names") or [])
    for key, v in (s.get("derived") or {}).items():
        if not key.startswith(f"{m}."):
            continue
        name = key.split(".", 1)[1]
        r = v.get("r_hat")
        truth = v.get("truth")
        inside = None
        if truth is not None and v.get("q05") is not None and v.get("q95") is not None:
            inside = v["q05"] <= truth <= v["q95"]
        base = {
            "name": name,
            "r_hat": "—" if r is None else f"{r:.3f}",
            "ess": fmt_int(v.get("ess_bulk")),
            "truth": fmt(truth) if truth is not None else "—",
            "truth_d": fmt(_div(truth, 24)) if truth is not None else "—",
            "inside": inside,
        }
        if name.startswith("tau_") and name.endswith("_h"):
            k = name[4:-2]
            base.update(
                label=f"τ{k}",
                median_h=fmt(v.get("median")),
                int_h=f"{fmt(v.get('q05'))} … {fmt(v.get('q95'))}",
                median_d=fmt(_div(v.get("median"), 24)),
                int_d=f"{fmt(_div(v.get('q05'), 24))} … {fmt(_div(v.get('q95'), 24))}",
            )
            taus.append(base)
            continue
        label = name
        for prefix, words in (
            ("gain_", "static gain of {o} from {i}"),
            ("offset_", "steady-state offset of {o} from {i}"),
        ):
            if name.startswith(prefix):
                rest = name[len(prefix) :]
                o = next((o for o in outs if rest.startswith(o + "_")), None)
                if o is not None:
                    label = words.format(o=o, i=rest[len(o) + 1 :])
        base.update(
            label=label,
            unit=v.get("unit", ""),
            median=fmt(v.get("median")),
            interval=f"{fmt(v.get('q05'))} … {fmt(v.get('q95'))}",
        )
        gains.append(base)
    return {
        "taus": taus,
        "gains": gains,
        "tau_truth": any(r["inside"] is not None for r in taus),
        "gain_truth": any(r["inside"] is not None for r in gains),
    }


def _div(v, d):
    return None if v is None else float(v) / d


def ladder_metrics(fit: dict | None, period: str) -> dict[str, dict]:
    """Fit metrics of a ladder row for one period: output -> {MSE, MAE, FIT}.

    Accepts ``fit[period]`` keyed by output (``{"Ti": {"FIT": ...}}``) or flat
    (``{"FIT": ...}``, returned under the key ``""``).
    """
    per = (fit or {}).get(period) or {}
    if any(k in per for k in ("FIT", "MSE", "MAE")):
        return {"": per}
    return {str(k): v for k, v in per.items() if isinstance(v, dict)}


def _ladder_cell(metrics: dict[str, dict], key: str) -> str:
    txt = _fit_txt if key == "FIT" else fmt
    if len(metrics) <= 1:
        return txt(next(iter(metrics.values()), {}).get(key))
    return "; ".join(f"{o}: {txt(v.get(key))}" for o, v in metrics.items())


def _ladder(s: dict) -> dict | None:
    from heritage_bayes.report.figures import fig_ladder

    ladder = s.get("ladder")
    if not ladder:
        return None
    tables = []
    for domain, rows in ladder.items():
        out = []
        for r in rows or []:
            cal = ladder_metrics(r.get("fit"), "calibration")
            val = ladder_metrics(r.get("fit"), "validation")
            n_model = r.get("n_model_params")
            n_all = r.get("n_params")
            if n_model is not None and n_all is not None and n_all != n_model:
                n_text = f"{fmt_int(n_model)} + {fmt_int(n_all - n_model)} noise"
            else:
                n_text = fmt_int(n_all)
            labels = ", ".join(map(str, r.get("null_directions") or []))
            out.append(
                {
                    "model": r.get("model", "?"),
                    "n_params": n_text,
                    "rank": fmt_int(r.get("rank")),
                    "n_null": fmt_int(r.get("n_null")) + (f" ({labels})" if labels else ""),
                    "cond": fmt(r.get("condition_number_identifiable")),
                    "fit_cal": _ladder_cell(cal, "FIT"),
                    "fit_val": _ladder_cell(val, "FIT"),
                    "mse_cal": _ladder_cell(cal, "MSE"),
                    "mse_val": _ladder_cell(val, "MSE"),
                    "mae_cal": _ladder_cell(cal, "MAE"),
                    "mae_val": _ladder_cell(val, "MAE"),
                    "loglik": fmt(r.get("log_likelihood")),
                    "aic": fmt(r.get("aic")),
                    "bic": fmt(r.get("bic")),
                    "agreed": r.get("map_agreed", "—"),
                    "sampled": bool(r.get("sampled")),
                }
            )
        tables.append({"domain": domain, "rows": out})
    return {"tables": tables, "figure": fig_ladder(ladder)}


def _fit_txt(v) -> str:
    try:
        f = float(v)
    except (TypeError, ValueError):
        return "—"
    return f"{f:.1f}".replace("-", "−") if math.isfinite(f) else "—"


# ---------------------------------------------------------------------- diagnostics
def _parameter_set(rd: _RunData, m: str):
    """The sampler's ParameterSet of section ``m``, or None if it does not match the run."""
    from heritage_bayes.inference.likelihoods import get_noise_model
    from heritage_bayes.inference.parameters import parameters_for

    try:
        sec = getattr(rd.cfg, m)
        ps = parameters_for(
            rd.run.models[m],
            get_noise_model(sec.noise),
            sec.priors,
            room_volume=sec.room_volume or rd.cfg.room_volume,
            where=f"{m}.priors",
        )
    except (InputError, AttributeError, KeyError, ValueError):
        return None
    names = list(((rd.summary.get("correlations") or {}).get(m) or {}).get("names") or [])
    if list(ps.free_names) != names:
        return None
    params = _section_params(rd.summary, m)
    for n in names:
        if ps[n].prior.describe() != (params.get(n) or {}).get("prior"):
            return None
    return ps


def _traces(rd: _RunData, m: str, info: dict):
    import h5py

    from heritage_bayes.report.figures import fig_traces

    path = rd.path / f"chain_{m}.h5"
    if not path.is_file():
        return None
    try:
        with h5py.File(path, "r") as f:
            n = f["chain"].shape[0]
            stride = max(1, math.ceil(n / _TRACE_POINTS))
            X = f["chain"][::stride]
            lp = f["log_prob"][::stride]
    except (OSError, KeyError) as exc:
        raise InputError(f"{path}: cannot be read ({exc})") from None
    steps = np.arange(0, n, stride)[: X.shape[0]]
    names = list(((rd.summary.get("correlations") or {}).get(m) or {}).get("names") or [])
    params = _section_params(rd.summary, m)
    ps = _parameter_set(rd, m)
    S, W, d = X.shape
    if ps is not None and d == ps.ndim:
        theta = ps.values(X.reshape(-1, d))
        idx = [ps.names.index(nm) for nm in ps.free_names]
        V = theta[:, idx].reshape(S, W, d)
        labels = []
        for j, nm in enumerate(ps.free_names):
            p = ps[nm]
            unit = p.unit if p.unit and p.unit != "-" else ""
            if p.prior.log_scale:
                V[:, :, j] = np.log10(V[:, :, j])
                labels.append(f"log10 {nm}" + (f" [{unit}]" if unit else ""))
            else:
                labels.append(nm + (f" [{unit}]" if unit else " [-]"))
        coords = "parameter values (log10 where the prior is log-scale)"
    else:
        V = X
        labels = (
            [f"{nm} (sampler coordinate)" for nm in names]
            if len(names) == d
            else [f"x{j}" for j in range(d)]
        )
        coords = "the sampler's unconstrained coordinates"
    del params
    ch = info.get("chain") or {}
    fig = fig_traces(
        steps,
        V,
        labels,
        lp,
        int(ch.get("burn", 0)),
        title=f"{m} ({info.get('model', '')}): {W} walkers, every {stride}th step shown",
    )
    return {"figure": fig, "coords": coords}


def _residual_check(resid: np.ndarray, phi: float | None, dt_hours: float) -> dict:
    from heritage_bayes.report._diag import acf, cumulative_periodogram, innovations

    max_lag = max(1, round(72 / dt_hours))
    _, rho, n = acf(resid, max_lag)
    w = innovations(resid, phi or 0.0)
    _, rho_w, n_w = acf(w, max_lag)
    band = 1.96 / math.sqrt(max(n_w, 1))
    out_share = float(np.mean(np.abs(rho_w[1:]) > band)) if rho_w.size > 1 else float("nan")
    f, c, kb = cumulative_periodogram(w)
    dev = float(np.nanmax(np.abs(c - 2 * f))) if c.size else float("nan")
    adequate = out_share <= 0.10 and (not math.isfinite(dev) or dev <= kb)
    lag1 = float(rho[1]) if rho.size > 1 else float("nan")
    return {
        "lag1": lag1,
        "phi": phi,
        "out_share": out_share,
        "dev": dev,
        "band": kb,
        "adequate": adequate,
    }


def _diagnostics(rd: _RunData, fits: list[dict]) -> dict:
    from heritage_bayes.report.figures import fig_residuals, fig_tau_history

    s = rd.summary
    dt_hours = float(s.get("dt", 3600.0)) / 3600.0
    crit = s.get("criteria") or {}
    models = []
    missing = []
    for m, info in (s.get("models") or {}).items():
        ch = info.get("chain") or {}
        tr = _traces(rd, m, info)
        if tr is None:
            missing.append(f"chain_{m}.h5")
        models.append(
            {
                "section": m,
                "model": info.get("model", m),
                "walkers": fmt_int(ch.get("walkers")),
                "steps": fmt_int(ch.get("steps")),
                "burn": fmt_int(ch.get("burn")),
                "thin": fmt_int(ch.get("thin")),
                "draws": fmt_int(ch.get("draws_per_walker")),
                "tau_max": fmt_int(ch.get("tau_max")),
                "needed": fmt_int(float(crit.get("tau_factor", 50)) * ch["tau_max"])
                if ch.get("tau_max") is not None
                else "—",
                "converged_tau": bool(ch.get("converged_tau")),
                "acceptance": fmt_pct(ch.get("acceptance_mean")),
                "resumed_from": fmt_int(ch.get("resumed_from")),
                "trace": tr,
            }
        )
    hist = {
        m: (i.get("chain") or {}).get("tau_history") or []
        for m, i in (s.get("models") or {}).items()
    }
    tau_fig = (
        fig_tau_history(hist, float(crit.get("tau_factor", 50.0)))
        if any(len(h) for h in hist.values())
        else None
    )
    residuals = []
    for fit in fits:
        if fit["section"] == "combined":
            continue  # RH is not a model output: its residuals have no noise model
        m, o = fit["section"], fit["output"]
        info = (s.get("models") or {}).get(m) or {}
        cal = fit["codes"] == 1
        if cal.sum() < 4:
            continue
        phi = None
        if info.get("noise") == "ar1":
            pv = (s.get("parameters") or {}).get(f"{m}.phi_{o}") or {}
            phi = pv.get("median")
        resid = fit["resid"][cal]
        check = _residual_check(resid, phi, dt_hours)
        fig = fig_residuals(
            fit["times"][cal],
            resid,
            output=o,
            unit=_OUT_UNITS.get(o, ""),
            phi=phi,
            dt_hours=dt_hours,
        )
        if phi is not None:
            words = (
                f"Lag-1 autocorrelation of the residuals {check['lag1']:.2f}; the "
                f"AR(1) noise model expects ≈ φ = {phi:.2f}. "
            )
            subject = "the innovations left after the AR(1) model"
        else:
            words = (
                f"Lag-1 autocorrelation of the residuals {check['lag1']:.2f}; the iid "
                "noise model expects ≈ 0. "
            )
            subject = "the residuals"
        share = fmt_pct(check["out_share"])
        if check["adequate"]:
            words += (
                f"The noise model looks adequate: {subject} are close to white "
                f"noise ({share} of the lags 1–72 h outside the 95 % band)."
            )
        else:
            words += (
                f"The noise model is not fully adequate: {subject} are not white "
                f"({share} of the lags 1–72 h outside the 95 % band"
                + (
                    ", cumulative periodogram outside its band"
                    if math.isfinite(check["dev"]) and check["dev"] > check["band"]
                    else ""
                )
                + "). Correlation the noise model misses (e.g. a daily cycle) makes "
                "the posterior intervals and predictive bands too narrow."
            )
        residuals.append(
            {
                "id": f"fig-resid-{m}-{o}",
                "section": m,
                "output": o,
                "model": fit["model"],
                "figure": fig,
                "words": words,
                "adequate": check["adequate"],
            }
        )
    return {
        "models": models,
        "tau_fig": tau_fig,
        "residuals": residuals,
        "missing": missing,
        "tau_factor": f"{float(crit.get('tau_factor', 50)):g}",
        "tau_rtol": fmt_pct(crit.get("tau_rtol"), 0),
    }


# -------------------------------------------------------------------- reproducibility
def _versions(s: dict) -> tuple[list[dict], str]:
    from importlib.metadata import PackageNotFoundError, version

    recorded = s.get("versions")
    if isinstance(recorded, dict) and recorded:
        return [{"name": k, "version": str(v)} for k, v in recorded.items()], "run"
    rows = [{"name": "heritage_bayes", "version": __version__}]
    import platform

    rows.append({"name": "python", "version": platform.python_version()})
    for name in _VERSIONS:
        try:
            rows.append({"name": name, "version": version(name)})
        except PackageNotFoundError:
            rows.append({"name": name, "version": "not installed"})
    return rows, "report"


def _timings(s: dict) -> list[dict]:
    rows = []
    for k, v in (s.get("timings") or {}).items():
        rows.append({"name": k.removesuffix("_seconds").replace("_", " "), "seconds": fmt(v)})
    if s.get("wall_seconds") is not None:
        rows.append({"name": "calibration, total", "seconds": fmt(s["wall_seconds"])})
    return rows


# ----------------------------------------------------------------------------- main
def _render_figures(obj, dpi: float | None = None):
    """Replace every Figure in a nested structure by its PNG data URI."""
    from matplotlib.figure import Figure

    from heritage_bayes.report.figures import to_png_uri

    if isinstance(obj, Figure):
        return to_png_uri(obj, dpi=dpi)
    if isinstance(obj, dict):
        return {k: _render_figures(v, dpi) for k, v in obj.items()}
    if isinstance(obj, list):
        return [_render_figures(v, dpi) for v in obj]
    return obj


def build_context(run_dir) -> dict:
    """Everything the template needs (figures as data URIs)."""
    import matplotlib

    from heritage_bayes.report.figures import RC_PARAMS

    t0 = time.perf_counter()
    rd = _load(run_dir)
    with matplotlib.rc_context(RC_PARAMS):
        fits = _fit_section(rd, _fit_outputs(rd))
        diagnostics = _diagnostics(rd, fits)
        ctx = {
            "sections": SECTIONS,
            "header": _header(rd),
            "verdict": convergence_verdict(rd.summary),
            "warnings": _warnings(rd, diagnostics["missing"]),
            "data": _data_section(rd),
            "fits": [{k: f[k] for k in ("id", "title", "figure", "caption")} for f in fits],
            "metrics": _metrics_section(rd),
            "parameters": _param_tables(rd),
            "identifiability": _identifiability(rd),
            "ladder": _ladder(rd.summary),
            "diagnostics": diagnostics,
        }
        ctx = _render_figures(ctx)
    versions, when = _versions(rd.summary)
    ctx["repro"] = {
        "config": rd.config_text,
        "versions": versions,
        "versions_from": when,
        "seed": rd.summary.get("seed"),
        "config_hash": rd.summary.get("config_hash", "?"),
        "created_at": fmt_time(rd.summary.get("created_at")),
        "timings": _timings(rd.summary),
        "files": sorted(
            p.name for p in rd.path.iterdir() if p.is_file() and not p.name.startswith(".")
        ),
    }
    ctx["generated"] = {"seconds": time.perf_counter() - t0, "version": __version__}
    return ctx


def render(ctx: dict) -> str:
    """Render the report template (autoescaping on)."""
    import jinja2

    env = jinja2.Environment(
        loader=jinja2.PackageLoader("heritage_bayes.report", "templates"),
        autoescape=True,
        undefined=jinja2.StrictUndefined,
        trim_blocks=True,
        lstrip_blocks=True,
    )
    env.filters["fmt"] = fmt
    return env.get_template("report.html").render(**ctx)


def _umask() -> int:
    """The process umask, read without changing it (Linux), else the usual 022."""
    try:
        for line in Path("/proc/self/status").read_text().splitlines():
            if line.startswith("Umask:"):
                return int(line.split()[1], 8)
    except (OSError, ValueError, IndexError):
        pass
    return 0o022


def write_report(run_dir) -> Path:
    """Write ``RUN_DIR/report.html`` (atomically) and return its path.

    Raises
    ------
    InputError
        ``run_dir`` is not a complete run directory (the message names the missing
        file) or one of its files cannot be read.
    """
    from heritage_bayes.inference.results import atomic_write

    t0 = time.perf_counter()
    ctx = build_context(run_dir)
    html_text = None

    def _write(tmp: Path) -> None:
        tmp.write_text(html_text, encoding="utf-8")
        # mkstemp creates 0600 files: make the report readable like a normal file
        os.chmod(tmp, 0o666 & ~_umask())

    ctx["generated"]["seconds"] = time.perf_counter() - t0
    html_text = render(ctx)
    return atomic_write(Path(run_dir) / "report.html", _write)
