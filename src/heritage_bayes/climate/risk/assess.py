"""Every indicator at once: :func:`assess`, :func:`assess_batch`, :func:`summarize`.

Reads the indicator families of :mod:`~heritage_bayes.climate.risk.indicators` (each
holds its options, its numpy computation and its registry entries): it resolves the
selected groups and each family's options (defaults are the keyword defaults of the
target functions), computes all selected indicators per draw, and returns tidy tables
with units and IPI-style ratings.
"""

from __future__ import annotations

import math

import numpy as np
import pandas as pd

from heritage_bayes.climate.risk._inputs import (
    MIN_YEAR_HOURS,
    Hourly,
    centred_mean,
    hourly,
)
from heritage_bayes.climate.risk.indicators import FAMILIES, shared_seasonal
from heritage_bayes.climate.risk.registry import (
    INDICATOR_GROUPS,
    complete_year_hours,
    indicator_info,
    resolve_options,
)
from heritage_bayes.climate.risk.standards import _window_half
from heritage_bayes.errors import InputError


def _resolve_groups(func, indicators):
    if indicators is None:
        return tuple(INDICATOR_GROUPS)
    if isinstance(indicators, str):
        indicators = (indicators,)
    groups = tuple(indicators)
    unknown = [g for g in groups if g not in INDICATOR_GROUPS]
    if unknown or not groups:
        raise InputError(
            f"{func}: indicators must be a non-empty selection of {list(INDICATOR_GROUPS)}; "
            f"got {list(groups)}"
        )
    return groups


def _check_year(func, groups, n):
    yearly = [g for g in groups if INDICATOR_GROUPS[g]]
    if yearly and n < MIN_YEAR_HOURS:
        short = [g for g in groups if not INDICATOR_GROUPS[g]] or ["mechanical"]
        raise InputError(
            f"{func}: the indicators {yearly} need at least one year of hourly data "
            f"({MIN_YEAR_HOURS} h); got {n} h. For a shorter series pass "
            f"indicators={short}"
        )


def _assess_core(h: Hourly, groups, opts, nan_policy) -> dict[str, np.ndarray]:
    """All indicators of the selected families, one value per draw."""
    seasonal = None
    if shared_seasonal(groups, opts):
        a = opts["ashrae"]
        half = _window_half("assess", a["window_days"], h.n_hours)
        seasonal = centred_mean(h.RH, half, a["edges"], nan_policy)
    out: dict[str, np.ndarray] = {}
    for fam in FAMILIES:
        if fam.name in groups:
            out.update(fam.compute(h, opts, nan_policy, seasonal))
    return out


def _unit(name: str) -> str:
    return indicator_info(name).unit


def _rating(name: str, v) -> str:
    """Rating of one indicator value on its published scale ('' where none applies)."""
    if v is None or (isinstance(v, float) and math.isnan(v)):
        return ""
    rate = indicator_info(name).rating
    return "" if rate is None else rate(v)


def _prepare_assess(func, T, RH, indicators, nan_policy, options):
    """Checked series (cut to their complete years), groups and options.

    A series of a year or more is cut to its complete years
    (:func:`~heritage_bayes.climate.risk.registry.complete_year_hours`): the hours after
    the last complete year are not used (``Hourly.dropped`` counts them).
    """
    groups = _resolve_groups(func, indicators)
    opts = resolve_options(func, options)
    h = hourly(func, T=T, RH=RH, nan_policy=nan_policy)
    _check_year(func, groups, h.n_hours)
    n = complete_year_hours(h.n_hours)
    if n < h.n_hours:
        index = None if h.index is None else h.index[:n]
        h = Hourly(T=h.T[:, :n], RH=h.RH[:, :n], index=index, ndim=h.ndim, dropped=h.n_hours - n)
    return h, groups, opts


def assess(
    T,
    RH,
    *,
    indicators=None,
    nan_policy="raise",
    lm=None,
    emc=None,
    vtt=None,
    isopleth=None,
    ashrae=None,
    en15757=None,
    **more,
):
    r"""All conservation-risk indicators of one hourly series, as a tidy table.

    Parameters
    ----------
    T : array_like or pandas.Series
        Hourly air temperature, shape (hours,). [°C]
    RH : array_like or pandas.Series
        Hourly relative humidity, shape (hours,). [%]
    indicators : iterable of str, optional
        Groups to compute, any of ``"chemical"`` (lifetime multipliers, TWPI, time of
        wetness), ``"mechanical"`` (EMC, dimensional change), ``"mould"`` (VTT index,
        hours above LIM), ``"ashrae"``, ``"en15757"``; default all. All but
        ``mechanical`` need at least a year (8736 h: a year less a day, so that an
        8759-hour typical year counts): their values depend on the season covered.
    nan_policy : {"raise", "omit", "propagate"}, default "raise"
        Missing hours: an error naming the count (default), the indicators computed
        on the valid hours (the table's ``hours`` column gives their number), or NaN
        results.
    lm : dict, optional
        Options of :func:`twlm`; ``Ea`` is a dict label → activation energy [J/mol],
        default ``{"paper": 100e3, "varnish": 70e3}`` (one row each).
    emc : dict, optional
        Options of :func:`dimensional_change` (``coefficient``).
    vtt : dict, optional
        Options of :func:`vtt_mould_index` (``sensitivity``, ``species``, ``surface``,
        ``M0``, ``frozen``).
    isopleth : dict, optional
        Options of :func:`hours_above_isopleth` (``growth_rate``).
    ashrae : dict, optional
        Options of :func:`ashrae_classes`.
    en15757 : dict, optional
        Options of :func:`en15757_band`.
    **more : dict, optional
        Options of a family added with
        :func:`~heritage_bayes.climate.risk.registry.register`, by its option keyword.

    Returns
    -------
    pandas.DataFrame
        One row per indicator, columns ``indicator``, ``value``, ``unit``, ``rating``:

        * ``lifetime_multiplier[<label>]`` — :func:`twlm` [-];
        * ``twpi`` — :func:`twpi` [years], rated good (≥ 75) / OK (≥ 45) / risk;
        * ``emc_min``, ``emc_max`` [% MC] — rated OK/risk against 5 and 12.5 %;
          ``emc_range`` [% MC]; ``dimensional_change`` [%] (:func:`dimensional_change`);
        * ``time_of_wetness`` — hours with RH > 80 % and T > 0 °C [h/year] (ISO 9223),
          rated with its category τ1-τ5;
        * ``vtt_mould_index_max`` — maximum of :func:`vtt_mould_index` [-], rated good
          (< 1) / risk;
        * ``hours_above_LIM0`` — :func:`hours_above_isopleth` [h/year];
        * ``ashrae_AA`` … ``ashrae_D`` — share of hours per class [% of hours];
          ``ashrae_best_class`` — share of the best class, whose name is the rating
          ("none" if no class reaches the threshold);
        * ``en15757_outside`` [% of hours], ``en15757_lower_offset``,
          ``en15757_upper_offset`` [%RH] (:func:`en15757_band`).

        Ratings are empty where the field has no published scale. ``hours``: the
        valid hours the value is computed from. A series of a year or more is cut to
        its complete years (the first ⌊n / 8760⌋ × 8760 hours): ``table.attrs
        ["hours_dropped"]`` counts the hours left out. Definitions, sources and periods
        of every indicator: :data:`heritage_bayes.climate.risk.registry.INDICATORS`.

    Raises
    ------
    heritage_bayes.errors.InputError
        Bad input (RH as a fraction, mismatched shapes, irregular index, a series shorter
        than a year for the yearly groups, unknown option names or values).

    See Also
    --------
    assess_batch : the same for many series at once (draws × hours).

    Notes
    -----
    The equations are in the functions named above. Unknown option keys are rejected,
    never ignored.

    References
    ----------
    .. [1] S. Michalski (2002), ICOM-CC 13th Triennial Meeting, Rio de Janeiro, 66-72
       (lifetime multiplier, :func:`lifetime_multiplier`).
    .. [2] D. K. Sebera (1994), "Isoperms"; J. M. Reilly et al. (1995), "New Tools for
       Preservation", Commission on Preservation and Access (PI, TWPI).
    .. [3] A. J. Hailwood and S. Horrobin (1946), doi:10.1039/TF946420B084; Wood
       Handbook FPL-GTR-190 (2010), doi:10.2737/FPL-GTR-190 (EMC, dimensional change).
    .. [4] A. Hukka and H. A. Viitanen (1999), doi:10.1007/s002260050131; T. Ojanen et
       al. (2010), Buildings XI (VTT mould index).
    .. [5] L. Zeng et al. (2023), doi:10.1177/01436244221137846 (lowest isopleth).
    .. [6] ASHRAE Handbook — HVAC Applications, museums chapter (climate classes).
    .. [7] EN 15757:2010; D. Camuffo et al. (2022), doi:10.3390/atmos13091344.

    Examples
    --------
    >>> import numpy as np
    >>> t = np.arange(8760)
    >>> T = 12 + 6 * np.sin(2 * np.pi * t / 8760)
    >>> RH = 60 + 8 * np.sin(2 * np.pi * t / 24)
    >>> table = assess(T, RH)
    >>> table.set_index("indicator").loc["ashrae_best_class", "rating"]
    'B'
    """
    func = "assess"
    options = dict(
        lm=lm, emc=emc, vtt=vtt, isopleth=isopleth, ashrae=ashrae, en15757=en15757, **more
    )
    h, groups, opts = _prepare_assess(func, T, RH, indicators, nan_policy, options)
    if h.ndim != 1:
        raise InputError(
            f"{func}: expected one hourly series (1-D); got shape "
            f"{(h.T.shape[0], h.n_hours)}. Use assess_batch for draws × hours"
        )
    res = _assess_core(h, groups, opts, nan_policy)
    valid = int((np.isfinite(h.T) & np.isfinite(h.RH)).sum())
    rows = []
    for name, v in res.items():
        if name == "ashrae_best_class":
            best = v[0]
            value = float(res[f"ashrae_{best}"][0]) if best != "none" else math.nan
            rows.append((name, value, _unit(name), best, valid))
            continue
        value = float(v[0])
        rows.append((name, value, _unit(name), _rating(name, value), valid))
    table = pd.DataFrame(rows, columns=["indicator", "value", "unit", "rating", "hours"])
    table.attrs["hours_dropped"] = int(h.dropped)
    return table


def assess_batch(
    T,
    RH,
    *,
    indicators=None,
    nan_policy="propagate",
    chunk_size=128,
    lm=None,
    emc=None,
    vtt=None,
    isopleth=None,
    ashrae=None,
    en15757=None,
    **more,
):
    r"""All indicators for many series at once (posterior draws × hours).

    Parameters
    ----------
    T : array_like
        Hourly air temperature, shape (draws, hours), or (hours,) shared by all draws of
        ``RH``. [°C]
    RH : array_like
        Hourly relative humidity, shape (draws, hours), or (hours,) shared. [%]
    indicators, nan_policy, lm, emc, vtt, isopleth, ashrae, en15757, **more
        As in :func:`assess`.
    chunk_size : int, default 128
        Draws processed together (bounds the memory of the temporaries). [-]

    Returns
    -------
    pandas.DataFrame
        One row per draw (index ``draw``), one column per indicator of :func:`assess`
        (same names and units; ``df.attrs["units"]`` maps column → unit). The column
        ``ashrae_best_class`` holds the class name ("none" if none is reached). Use
        :func:`summarize` for quantiles and ratings.

    Notes
    -----
    Vectorised over draws: moving averages by cumulative sums along the hours axis,
    the VTT recursion compiled with numba (timed by ``benchmarks/bench_risk.py``).
    Row *i* equals ``assess(T[i], RH[i])``. :func:`~heritage_bayes.climate.risk.assess_fused`
    returns the same indicators from one compiled pass per series (the projection's
    path, ``benchmarks/bench_projection.py``).

    References
    ----------
    See :func:`assess`.
    """
    func = "assess_batch"
    options = dict(
        lm=lm, emc=emc, vtt=vtt, isopleth=isopleth, ashrae=ashrae, en15757=en15757, **more
    )
    h, groups, opts = _prepare_assess(func, T, RH, indicators, nan_policy, options)
    bad = isinstance(chunk_size, bool) or not isinstance(chunk_size, int | np.integer)
    if bad or chunk_size < 1:
        raise InputError(f"{func}: chunk_size must be a positive integer; got {chunk_size!r}")
    d = h.T.shape[0]
    parts: list[dict[str, np.ndarray]] = []
    for start in range(0, d, int(chunk_size)):
        sl = slice(start, start + int(chunk_size))
        hc = Hourly(T=h.T[sl], RH=h.RH[sl], index=None, ndim=2)
        parts.append(_assess_core(hc, groups, opts, nan_policy))
    cols = {k: np.concatenate([p[k] for p in parts]) for k in parts[0]}
    df = pd.DataFrame(cols, index=pd.RangeIndex(d, name="draw"))
    df.attrs["units"] = {k: _unit(k) for k in cols}
    df.attrs["hours_dropped"] = int(h.dropped)
    return df


def summarize(per_draw: pd.DataFrame, quantiles=(0.05, 0.5, 0.95)) -> pd.DataFrame:
    r"""Distribution of each indicator over draws, as a tidy table.

    Parameters
    ----------
    per_draw : pandas.DataFrame
        Output of :func:`assess_batch` (one row per draw; units in ``attrs["units"]``).
    quantiles : sequence of float, default (0.05, 0.5, 0.95)
        Quantiles to report, each in [0, 1]. [-]

    Returns
    -------
    pandas.DataFrame
        Columns ``indicator``, ``unit``, ``mean``, one column per quantile (``q5``,
        ``q50``, ``q95`` …) and ``rating``: the rating of the median for rated
        indicators; for ``ashrae_best_class``, the share of draws per best class
        (e.g. ``"B 80 %, C 20 %"``). NaN draws are left out. Values in the unit of
        each indicator (``per_draw.attrs["units"]``).

    Notes
    -----
    Quantiles by linear interpolation (:func:`numpy.quantile`); the rating of the
    median uses the same scales as :func:`assess`.
    """
    func = "summarize"
    if not isinstance(per_draw, pd.DataFrame):
        raise InputError(
            f"{func}: expected the DataFrame of assess_batch; got {type(per_draw).__name__}"
        )
    try:
        qs = [float(q) for q in quantiles]
    except (TypeError, ValueError):
        raise InputError(
            f"{func}: quantiles must be numbers in [0, 1]; got {quantiles!r}"
        ) from None
    if not qs or not all(0.0 <= q <= 1.0 for q in qs):
        raise InputError(f"{func}: quantiles must be numbers in [0, 1]; got {quantiles!r}")
    qcols = [f"q{100 * q:g}" for q in qs]
    units = per_draw.attrs.get("units", {})
    rows = []
    for name in per_draw.columns:
        col = per_draw[name]
        if name == "ashrae_best_class":
            freq = col.astype(str).value_counts(normalize=True)
            rating = ", ".join(f"{k} {100 * v:.0f} %" for k, v in freq.items())
            rows.append([name, "", math.nan, *([math.nan] * len(qs)), rating])
            continue
        x = col.to_numpy(dtype=float)
        x = x[~np.isnan(x)]
        if x.size:
            qv = np.quantile(x, qs)
            mean = float(x.mean())
            med = float(np.median(x))
        else:
            qv, mean, med = [math.nan] * len(qs), math.nan, math.nan
        rows.append([name, units.get(name, ""), mean, *map(float, qv), _rating(name, med)])
    return pd.DataFrame(rows, columns=["indicator", "unit", "mean", *qcols, "rating"])
