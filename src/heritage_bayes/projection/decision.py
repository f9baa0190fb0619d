"""The decision table of the interventions: measures ranked by the change they make to
one risk, beside one running energy per year and, with tariffs, its cost and CO₂.

For the most severe case (:func:`severe_case`: the future of highest mean outdoor
temperature, the baseline when there is no future) and every measure:

* the paired change of the ranking indicator against doing nothing (same parameter
  draw, noise realisation and weather), its 5/50/95 % quantiles over the draws and
  ``p_better``, the share of draws in which the measure is strictly better (the
  registry's direction, :mod:`heritage_bayes.climate.risk.registry`);
* the running energy [kWh/a]: per draw the sum of the measure's energy terms
  (:data:`heritage_bayes.projection.interventions.ENERGY`: heat delivered to the
  air, electric energy of dehumidifier and humidifier), then its quantiles; 0 for a
  measure without a unit (ventilation);
* with ``tariffs``: per draw ``heat × heating energy + electricity × (dehumidifier +
  humidifier energy)`` [EUR/a], and the same with the CO₂ factors [kg/a].

Measures are ranked by the median change in the better direction (most improvement
first), ties by the median energy (least first). The ranking indicator defaults to the
first of :data:`DEFAULT_RANK_BY` that the projection computes and that varies between
the draws or measures (a risk that is the same with every measure ranks nothing).
"""

from __future__ import annotations

import numpy as np

from heritage_bayes.projection.interventions import _q

#: Default ranking indicators, first computed and varying wins: mould (hours above the
#: lowest isopleth, then the VTT index), then chemical decay (TWPI), then wetness.
DEFAULT_RANK_BY = ("hours_above_LIM0", "vtt_mould_index_max", "twpi", "time_of_wetness")
#: Electric energy terms of :data:`heritage_bayes.projection.interventions.COSTS` [kWh/a].
ELECTRIC = ("dehumidifier_energy", "humidifier_energy")


def severe_case(summary: dict) -> str:
    """The label of the most severe case: the future of highest mean outdoor
    temperature (``summary["cases"][i]["mean_Te"]``), the baseline without a future."""
    cases = summary["cases"]
    futures = cases[1:] or cases
    return max(futures, key=lambda c: c["mean_Te"])["label"]


def _varies(name: str, r0, per_case: list) -> bool:
    from heritage_bayes.projection.summary import is_degenerate

    v = np.concatenate([r.predictive[name].to_numpy(float) for r in (r0, *per_case)])
    return bool(np.isfinite(v).any()) and not is_degenerate(v)


def rank_indicator(requested: str | None, r0, per_case: list) -> str | None:
    """The indicator the measures are ranked by: ``requested`` if given, else the
    first of :data:`DEFAULT_RANK_BY` computed and varying (None if none is)."""
    if requested is not None:
        return requested
    cols = set(r0.predictive.columns)
    for n in DEFAULT_RANK_BY:
        if n in cols and _varies(n, r0, per_case):
            return n
    return next((n for n in DEFAULT_RANK_BY if n in cols), None)


def energy_per_draw(costs, K: int) -> dict:
    """Per draw [kWh/a]: ``total`` (every energy term), ``heat`` (heating energy) and
    ``electric`` (dehumidifier and humidifier); zeros where the measure has none."""
    from heritage_bayes.projection.interventions import ENERGY

    def col(c):
        if costs is None or c not in costs.columns:
            return np.zeros(K)
        return costs[c].to_numpy(float)

    heat = col("heating_energy")
    electric = sum((col(c) for c in ELECTRIC), np.zeros(K))
    total = sum((col(c) for c in ENERGY), np.zeros(K))
    return {"total": total, "heat": heat, "electric": electric}


def decision_table(labels, nothing, per_measure: dict, summary: dict, rank_by, tariffs) -> dict:
    """The JSON-ready decision table (see the module docstring).

    Parameters
    ----------
    labels : list of str
        Case labels, the baseline first.
    nothing : list of CaseResult
        Doing nothing per case.
    per_measure : dict
        Measure name -> list of CaseResult (per case, paired with ``nothing``).
    summary : dict
        The projection summary (its ``cases`` give the most severe case).
    rank_by : str or None
        The ranking indicator (None: the default of :func:`rank_indicator`).
    tariffs : Tariffs or None
        Prices [EUR/kWh] and emission factors [kg CO₂/kWh]; None: energy only.

    Returns
    -------
    dict
        ``case``, ``rank_by`` (indicator key), ``unit``, ``tariffs`` (dict or None) and
        ``measures``: a list, best first, of ``{"name", "change" (quantiles and
        p_better), "energy_kwh" (quantiles of the per-draw total [kWh/a]),
        "has_energy" (the measure has an energy term), "energy_missing" (units that move
        water without an energy per kg given: their energy is not in the total),
        "cost_eur" [EUR/a], "co2_kg" [kg/a]}`` (quantiles, None without tariffs).
    """
    from heritage_bayes.climate.risk.registry import indicator_info
    from heritage_bayes.projection.interventions import ENERGY

    if not per_measure:
        return {}
    case = severe_case(summary)
    i = labels.index(case)
    r0 = nothing[i]
    n = rank_indicator(rank_by, r0, [rs[i] for rs in per_measure.values()])
    info = indicator_info(n) if n else None
    K = len(r0.predictive)
    rows = []
    for name, rs in per_measure.items():
        r = rs[i]
        change = None
        if n is not None:
            d = r.predictive[n].to_numpy(float) - r0.predictive[n].to_numpy(float)
            ok = np.isfinite(d)
            change = _q(d) | {"p_better": float(np.mean(info.worse * d[ok] < 0))}
        e = energy_per_draw(r.costs, K)
        cols = set(r.costs.columns) if r.costs is not None else set()
        missing = [u for u, w, c in (("dehumidifier", "water_removed", "dehumidifier_energy"),
                                     ("humidifier", "water_added", "humidifier_energy"))
                   if w in cols and c not in cols]  # fmt: skip
        row = {"name": name, "change": change, "energy_kwh": _q(e["total"]),
               "has_energy": bool(cols & set(ENERGY)), "energy_missing": missing,
               "cost_eur": None, "co2_kg": None}  # fmt: skip
        if tariffs is not None:
            row["cost_eur"] = _q(
                tariffs.heat_eur_per_kwh * e["heat"]
                + tariffs.electricity_eur_per_kwh * e["electric"]
            )
            if tariffs.has_co2():
                row["co2_kg"] = _q(
                    tariffs.heat_co2_kg_per_kwh * e["heat"]
                    + tariffs.electricity_co2_kg_per_kwh * e["electric"]
                )
        rows.append(row)

    def key(row):
        c = row["change"]
        better = -info.worse * c["q50"] if c and c["q50"] is not None else -np.inf
        return (-better, row["energy_kwh"]["q50"] or 0.0)

    rows.sort(key=key)
    return {
        "case": case,
        "rank_by": n,
        "unit": info.unit if info else None,
        "tariffs": tariffs.model_dump() if tariffs is not None else None,
        "measures": rows,
    }
