"""Writing a projection: ``projection.nc``, ``projection.json``, ``projection.csv``,
``projection.html``.

All four are rendered in memory first and written atomically
(:func:`heritage_bayes.inference.results.atomic_write`) into the staging folder of
:func:`heritage_bayes.projection.project`, which swaps them in as one group
(:class:`~heritage_bayes.rundir.writer.StagedFolder`): bad input leaves nothing
behind, an interrupt leaves the previous projection whole.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np

from heritage_bayes.climate.risk.registry import indicator_info
from heritage_bayes.inference.results import atomic_write, atomic_write_text, ensure_free_space

#: What a projection writes into its folder.
OUTPUT_FILES = tuple(f"projection.{x}" for x in ("nc", "json", "csv", "html"))


def _climatology(x: np.ndarray, months) -> np.ndarray:
    """(K, n_months) monthly means -> (K, 12) means by calendar month (NaN if absent)."""
    m = np.asarray(months.month)
    out = np.full((x.shape[0], 12), np.nan, dtype=np.float32)
    for k in range(1, 13):
        sel = m == k
        if sel.any():
            out[:, k - 1] = x[:, sel].mean(axis=1)
    return out


def to_dataset(proj, run):
    """xarray.Dataset: dims ``case`` (coords ``scenario``, ``horizon``), ``draw``,
    ``month`` (1–12); one variable per risk indicator (predictive and, suffixed
    ``_parametric``, noise-free), ``Ti_monthly``/``RHi_monthly`` [°C, %]."""
    import xarray as xr

    from heritage_bayes._version import __version__
    from heritage_bayes.projection.summary import numeric_columns

    res = proj.results
    K = len(res[0].predictive)
    coords = {
        "case": np.array(proj.labels, dtype=str),
        "scenario": ("case", np.array([s["scenario"] for s in proj.summary["cases"]], dtype=str)),
        "horizon": ("case", np.array([h if h is not None else -1 for h in proj.horizons])),
        "draw": np.arange(K),
        "month": np.arange(1, 13),
    }
    units = res[0].predictive.attrs.get("units", {})
    data = {}
    for n in numeric_columns(res[0].predictive):
        for suffix, attr in (("", "predictive"), ("_parametric", "parametric")):
            arr = np.stack([getattr(r, attr)[n].to_numpy(float) for r in res])
            data[n + suffix] = (
                ("case", "draw"),
                arr.astype(np.float32),
                {"unit": units.get(n, ""), "kind": attr},
            )
    if "ashrae_best_class" in res[0].predictive.columns:
        arr = np.stack([r.predictive["ashrae_best_class"].astype(str).to_numpy() for r in res])
        data["ashrae_best_class"] = (("case", "draw"), arr.astype("U8"), {"unit": "class"})
    if res[0].annual_predictive is not None and res[0].annual_names:
        ny = max(r.annual_predictive.shape[1] for r in res)
        coords["year"] = np.arange(ny)
        units_a = {n: indicator_info(n).unit for n in res[0].annual_names}
        for j, n in enumerate(res[0].annual_names):
            for suffix, attr in (("", "annual_predictive"), ("_parametric", "annual_parametric")):
                arr = np.full((len(res), K, ny), np.nan, np.float32)
                for i, r in enumerate(res):
                    a = getattr(r, attr)
                    arr[i, :, : a.shape[1]] = a[:, :, j]
                data[f"{n}_per_year{suffix}"] = (
                    ("case", "draw", "year"),
                    arr,
                    {"unit": units_a[n], "description": f"{indicator_info(n).name}, per "
                     "complete year of the weather (blocks of 8760 h from its start)"},
                )  # fmt: skip
    for name, unit in (("Ti", "°C"), ("RHi", "%")):
        arr = np.stack([_climatology(getattr(r, f"{name}_month"), r.months) for r in res])
        data[f"{name}_monthly"] = (
            ("case", "draw", "month"),
            arr,
            {"unit": unit, "description": f"mean {name} by calendar month over the case's years"},
        )
    if proj.interventions:
        _measures(proj, data, coords, units)
    ds = xr.Dataset(
        {k: xr.DataArray(v[1], dims=v[0], attrs=v[2]) for k, v in data.items()}, coords=coords
    )
    ds.attrs.update(
        {
            "title": "heritage_bayes projection",
            "run": str(run.path),
            "heritage_bayes_version": __version__,
            "seed": int(proj.config.seed),
            "humidity": proj.config.humidity,
            "horizon_of_baseline": -1,
        }
    )
    return ds


def _measures(proj, data: dict, coords: dict, units: dict) -> None:
    """Per measure, case and draw: each indicator with the measure (``<name>_measure``,
    predictive, paired with ``<name>``) and each running cost (``cost_<name>``, NaN
    where the measure has none)."""
    from heritage_bayes.projection.interventions import COSTS
    from heritage_bayes.projection.summary import numeric_columns

    names = list(proj.interventions)
    coords["measure"] = np.array(names, dtype=str)
    runs = [proj.interventions[m] for m in names]
    K = len(proj.results[0].predictive)
    for n in numeric_columns(proj.results[0].predictive):
        arr = np.stack([np.stack([r.predictive[n].to_numpy(float) for r in rs]) for rs in runs])
        data[f"{n}_measure"] = (
            ("measure", "case", "draw"),
            arr.astype(np.float32),
            {"unit": units.get(n, ""), "kind": "predictive, with the measure"},
        )
    for c, (unit, desc) in COSTS.items():
        arr = np.full((len(names), len(proj.labels), K), np.nan, np.float32)
        for i, rs in enumerate(runs):
            for j, r in enumerate(rs):
                if r.costs is not None and c in r.costs.columns:
                    arr[i, j] = r.costs[c].to_numpy(float)
        if np.isfinite(arr).any():
            data[f"cost_{c}"] = (("measure", "case", "draw"), arr, {"unit": unit,
                                 "description": desc})  # fmt: skip


def indicator_table(proj):
    """pandas.DataFrame (``projection.csv``): one row per measure (``do nothing``
    first), indicator and case — the registry's name, unit, period and source, the
    quantiles over the draws, the paired change and P(worse) / P(better).

    Doing nothing's change is against the baseline (``change_vs: baseline``, P(worse));
    a measure's against doing nothing in the same case and draw (``change_vs: do
    nothing``, P(better)). A measure's running costs follow its indicators as rows
    ``cost_<name>`` (their quantiles, no change)."""
    import pandas as pd

    from heritage_bayes.projection.config import DO_NOTHING
    from heritage_bayes.projection.interventions import COSTS

    rows = []
    cases = proj.summary["cases"]

    def row(measure, n, name, unit, c, v, ch, vs, p_worse=None, p_better=None, info=None):
        return {
            "measure": measure, "indicator": n, "name": name, "unit": unit,
            "case": c["label"], "scenario": c["scenario"], "horizon": c["horizon"],
            "q05": v["q05"], "q50": v["q50"], "q95": v["q95"], "mean": v["mean"],
            "change_vs": vs, "change_q05": ch.get("q05"), "change_q50": ch.get("q50"),
            "change_q95": ch.get("q95"), "p_worse": p_worse, "p_better": p_better,
            "period": None if info is None else info.period,
            "source": None if info is None else info.source,
        }  # fmt: skip

    for n, e in proj.summary["indicators"].items():
        info = indicator_info(n)
        for c in cases:
            ch = e["change"].get(c["label"]) or {}
            vs = "baseline" if ch else None
            v = e["cases"][c["label"]]
            rows.append(row(DO_NOTHING, n, info.name, e["unit"], c, v, ch, vs, ch.get("p_worse"),
                            info=info))  # fmt: skip
    for m, me in (proj.summary.get("interventions") or {}).items():
        for n in proj.summary["indicators"]:
            info = indicator_info(n)
            for c in cases:
                d = me["cases"][c["label"]]["indicators"].get(n)
                if d is None:
                    continue
                rows.append(row(m, n, info.name, d["unit"], c, d["with_measure"], d,
                                DO_NOTHING, p_better=d["p_better"], info=info))  # fmt: skip
        for cost, (unit, desc) in COSTS.items():
            for c in cases:
                v = me["cases"][c["label"]]["costs"].get(cost)
                if v is not None:
                    rows.append(row(m, f"cost_{cost}", desc, unit, c, v, {}, None))
    return pd.DataFrame(rows)


def write_outputs(proj, run, dest: Path) -> dict:
    """Render everything, then write the four files (:data:`OUTPUT_FILES`) atomically
    into ``dest`` (an existing folder: the staging folder of the projection)."""
    from heritage_bayes.convert import to_jsonable
    from heritage_bayes.projection.page import render_projection_page

    dest = Path(dest)
    if dest.exists() and not dest.is_dir():
        from heritage_bayes.errors import InputError

        raise InputError(f"--out {dest}: is a file, not a folder")
    html = render_projection_page(proj, run)
    import json

    text = json.dumps(to_jsonable(proj.summary), indent=1, ensure_ascii=False, allow_nan=False)
    csv = indicator_table(proj).to_csv(index=False, float_format="%.6g")
    paths = {
        "nc": dest / "projection.nc",
        "json": dest / "projection.json",
        "csv": dest / "projection.csv",
        "html": dest / "projection.html",
    }
    # a full disk inside an HDF5 write can crash the interpreter at exit: check first,
    # for the four files (the NetCDF file at most its uncompressed size)
    texts = sum(len(t.encode("utf-8")) for t in (text, csv, html))
    ensure_free_space(paths["nc"], int(proj.dataset.nbytes) + texts)
    atomic_write(paths["nc"], lambda p: proj.dataset.to_netcdf(p, engine="h5netcdf"))
    atomic_write_text(paths["json"], text)
    atomic_write_text(paths["csv"], csv)
    atomic_write_text(paths["html"], html)
    return paths
