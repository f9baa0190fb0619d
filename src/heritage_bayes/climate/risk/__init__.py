r"""Conservation-risk indicators from hourly indoor temperature and relative humidity.

Conservators do not read temperatures; they read risk to the collection. This module turns
an hourly indoor climate (measured, simulated from a posterior draw, or projected) into
the indicators the heritage field uses:

* chemical decay: Michalski's lifetime multiplier (:func:`lifetime_multiplier`, time
  aggregated by :func:`twlm`), the preservation index (:func:`preservation_index`) and
  the time-weighted preservation index (:func:`twpi`);
* mechanical damage: equilibrium moisture content of wood (:func:`emc_wood`), its range
  (:func:`emc_range`) and a dimensional-change proxy (:func:`dimensional_change`);
* biological: the VTT mould index (:func:`vtt_mould_index`) and the hours above the
  lowest isopleth for mould (:func:`lowest_isopleth`, :func:`hours_above_isopleth`);
* climate specifications: ASHRAE museum classes (:func:`ashrae_classes`) and the
  EN 15757 seasonal RH band (:func:`en15757_band`);
* everything at once: :func:`assess` (one series → tidy table) and :func:`assess_batch`
  (draws × hours → one row per draw), summarised by :func:`summarize`;
  :func:`assess_fused` gives the table of :func:`assess_batch` from one compiled pass
  per series (numba, draws in parallel, no draws × hours temporaries; the same values
  to rounding; :mod:`~heritage_bayes.climate.risk.fused`).

Conventions
-----------
* Temperature ``T`` in [°C], relative humidity ``RH`` in [%] (0–100; a fraction 0–1 is
  rejected with :class:`~heritage_bayes.errors.InputError`, so is RH above 100 %).
* Pointwise functions (:func:`lifetime_multiplier`, :func:`preservation_index`,
  :func:`emc_wood`, :func:`lowest_isopleth`) accept scalars, arrays of any shape or
  Series, and return the same kind (float, array, Series).
* Series functions take a regular **hourly** series: a 1-D array or Series (hours), or a
  2-D array (draws × hours, hours along the last axis). A Series with a
  :class:`~pandas.DatetimeIndex` must advance by exactly one hour at every step. A 1-D
  input gives a float per indicator; a 2-D input gives one value per draw.
* Yearly indicators (ASHRAE classes, EN 15757, hours above the isopleth per year) need at
  least one year (8736 h: a year less a day, so that a typical year on a grid, 8759 h, counts).
* ``nan_policy`` (series functions): ``"propagate"`` (default; a NaN anywhere makes the
  aggregate NaN, and the VTT index NaN from the first gap on), ``"omit"`` (skip missing
  hours: aggregates over the valid hours, moving averages over the valid hours of each
  window, the VTT index holds its state across gaps and is NaN in them) or ``"raise"``
  (a NaN in the input raises :class:`~heritage_bayes.errors.InputError`).

Layout (one module per mechanism, :func:`assess` on top; every name below is importable
from this package): :mod:`~heritage_bayes.climate.risk.chemical`,
:mod:`~heritage_bayes.climate.risk.mechanical`, :mod:`~heritage_bayes.climate.risk.biological`,
:mod:`~heritage_bayes.climate.risk.standards` and :mod:`~heritage_bayes.climate.risk.assess`;
one object per indicator family (its registry entries, options, numpy computation and
compiled parameters) in :mod:`~heritage_bayes.climate.risk.indicators`, gathered by
:mod:`~heritage_bayes.climate.risk.registry`; input checking in ``_inputs``, the VTT
recursion (once) in ``_vtt``, the fused pass in :mod:`~heritage_bayes.climate.risk.fused`
(kernel in ``_fused``, sums in ``_sums``).

Where the formulas or limits were not read in a primary source (ASHRAE compliance
algorithm and table, EN 15757 minimum band), the function says so and the choice is a
parameter.
"""

from __future__ import annotations

from heritage_bayes.climate.risk._inputs import HOURS_PER_YEAR
from heritage_bayes.climate.risk.assess import (
    INDICATOR_GROUPS,
    assess,
    assess_batch,
    summarize,
)
from heritage_bayes.climate.risk.biological import (
    hours_above_isopleth,
    lowest_isopleth,
    vtt_mould_index,
)
from heritage_bayes.climate.risk.chemical import (
    R_GAS,
    lifetime_multiplier,
    preservation_index,
    twlm,
    twpi,
)
from heritage_bayes.climate.risk.fused import assess_fused
from heritage_bayes.climate.risk.mechanical import (
    EMCRange,
    dimensional_change,
    emc_range,
    emc_wood,
)
from heritage_bayes.climate.risk.standards import (
    ASHRAE_CLASSES,
    AshraeResult,
    ClimateClass,
    EN15757Band,
    ashrae_classes,
    en15757_band,
)

__all__ = [
    "ASHRAE_CLASSES",
    "HOURS_PER_YEAR",
    "INDICATOR_GROUPS",
    "R_GAS",
    "AshraeResult",
    "ClimateClass",
    "EMCRange",
    "EN15757Band",
    "ashrae_classes",
    "assess",
    "assess_batch",
    "assess_fused",
    "dimensional_change",
    "emc_range",
    "emc_wood",
    "en15757_band",
    "hours_above_isopleth",
    "lifetime_multiplier",
    "lowest_isopleth",
    "preservation_index",
    "summarize",
    "twlm",
    "twpi",
    "vtt_mould_index",
]
