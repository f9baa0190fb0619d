"""The solar surfaces ``hbayes init`` writes (:mod:`heritage_bayes.init_config`): the two
slopes of a roof for a room that looks like an attic, else one horizontal aperture.

A room looks like an attic or loft when a name says so (the logger file's, the run's:
*attic*, *loft*, *roof*, *garret* and their Dutch, German, Finnish, Swedish, French,
Italian and Polish words) or when its median daily temperature range is at least the
outdoor one (:data:`SWING_RATIO`, the ratio at which :mod:`heritage_bayes.init_model`
says the sun heats the room). Such a room gets ``data.roof`` with :data:`DEFAULT_PITCH`
and :data:`DEFAULT_RIDGE_AZIMUTH` and a comment asking for its real pitch and ridge
direction.

Why these defaults. *Pitch 45°*: the roofs of historic buildings lie between about 30°
(Nordic and Mediterranean tile roofs, 1:2 to 1:1.5) and 60° (Gothic churches, steep
northern European roofs); 45° is the middle. *Ridge east-west* (slopes facing north and
south): of the two main orientations it fitted the attics it was chosen on better
(validation FIT of Ti, ``benchmarks/roof_planes.py``, measured and estimated radiation);
the comparison, with held-out attics, is in ``docs/science/inputs.md`` ("Roofs as solar
surfaces").
"""

from __future__ import annotations

import pandas as pd

from heritage_bayes.config.data import ROOF_HORIZON
from heritage_bayes.yaml_text import wrap_comment

__all__ = [
    "ATTIC_WORDS",
    "DEFAULT_PITCH",
    "DEFAULT_RIDGE_AZIMUTH",
    "SWING_RATIO",
    "attic_evidence",
    "roof_finding",
    "solar_surface_lines",
]

#: Words in a name that say the room is under a roof (lower case, matched inside words).
ATTIC_WORDS = (
    "attic",
    "loft",
    "roof",
    "garret",
    "zolder",  # Dutch
    "dachboden",
    "dachraum",  # German
    "ullakko",
    "ylapohja",
    "yläpohja",  # Finnish
    "vindsrum",  # Swedish (Danish and Norwegian: loft)
    "grenier",
    "comble",  # French
    "soffitta",
    "sottotetto",  # Italian
    "strych",
    "poddasze",  # Polish
)
#: The median daily indoor temperature range against the outdoor one at or above which
#: the room is taken as heated by the sun on its roof.
SWING_RATIO = 1.0
#: init's roof when the room looks like an attic: pitch [°] and ridge direction [°].
DEFAULT_PITCH = 45.0
DEFAULT_RIDGE_AZIMUTH = 90.0


def _daily_range(s: pd.Series) -> float:
    """Median daily range [K] of the days with at least 20 hourly means."""
    hourly = s.resample("1h").mean()
    g = hourly.resample("1D")
    r = (g.max() - g.min())[g.count() >= 20]
    return float(r.median()) if len(r) else float("nan")


def attic_evidence(names, ti: pd.Series, te: pd.Series) -> str | None:
    """Why the room looks like an attic or loft, or None.

    Parameters
    ----------
    names : iterable of str
        Names the user gave the room or its files (the logger file's stem, the run's).
    ti, te : pandas.Series
        Indoor and outdoor air temperature [°C] on UTC, over the periods init chose.
    """
    for name in names:
        low = str(name).lower()
        hit = next((w for w in ATTIC_WORDS if w in low), None)
        if hit:
            return f"the name {name!r} says a room under the roof ({hit!r})"
    ri, re_ = _daily_range(ti), _daily_range(te)
    if re_ > 0 and ri / re_ >= SWING_RATIO:
        return (
            f"its median daily range {ri:.2f} K is at least the outdoor one ({re_:.2f} K): "
            "the sun on a roof"
        )
    return None


def roof_finding(attic: str) -> str:
    """init's finding for a room that looks like an attic (``attic`` the reason)."""
    return (
        f"roof: the room looks like an attic or loft ({attic}): data.roof with init's "
        f"default pitch {DEFAULT_PITCH:g}° and ridge {DEFAULT_RIDGE_AZIMUTH:g}° (east-west); "
        "give your roof's pitch and ridge direction there"
    )


def solar_surface_lines(attic: str | None) -> list[str]:
    """The ``data`` lines of the solar surfaces: the roof (``attic`` the reason) or one
    horizontal aperture."""
    if attic is None:
        return [
            "  # One solar aperture on the horizontal (tilt, azimuth from north) [°]: the",
            "  # sun on the building as a whole, which the data can pin. Name the facades",
            "  # or roof planes that matter when you know them (e.g. S: [90, 180], roof_E:",
            "  # [30, 90]); each adds an aperture to estimate.",
            "  surfaces: {H: [0, 0]}",
        ]
    text = (
        f"The room looks like an attic or loft: {attic}. Its roof's two slopes are the "
        "solar surfaces (roof_<direction>, an aperture each). CHECK the pitch [° from the "
        "horizontal] and the direction the ridge runs [° from north: 90 east-west, slopes "
        "facing N and S; 0 north-south, slopes facing E and W]: these are init's defaults "
        f"({DEFAULT_PITCH:g}°, an east-west ridge); give your roof's. Add area: [m², both "
        "slopes along the slope] for a prior on the apertures. A mono-pitch or flat roof, or "
        "not an attic: replace 'roof' by surfaces (e.g. {H: [0, 0]}). With a wind speed in "
        "the weather (weather.columns.wind [m/s]) the slopes' sun is weighted by the wind "
        "on the roof (a calm day's sun heats the attic more); with a precipitation "
        "(weather.columns.precip [mm]) in a climate with frost, they are taken under the "
        "snow a degree-day snowpack estimates (no sun, the daily swing damped). The slopes "
        "are shaded while the "
        f"sun is below horizon: [°] (default {ROOF_HORIZON:g}: the houses and trees around); "
        "give 0 for a roof open to the horizon."
    )
    return [
        *wrap_comment(text, "  # ", "  # "),
        f"  roof: {{pitch: {DEFAULT_PITCH:g}, ridge_azimuth: {DEFAULT_RIDGE_AZIMUTH:g}}}",
    ]
