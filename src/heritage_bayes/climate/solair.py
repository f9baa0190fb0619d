"""The sun's heat through an opaque roof, weighted by the wind on its outer surface.

The sun absorbed by a roof's cover (tiles, boards, sheet metal) leaves it two ways:
outwards, to the outdoor air and the sky, through the exterior surface coefficient
:math:`h_e` [W/(m² K)], and inwards, to the attic, through the cover's conductance to
the attic :math:`U_r` [W/(m² K)] (the boards and the radiation and convection of their
underside). The share that reaches the attic is :math:`U_r / (h_e + U_r)`: the sol-air
temperature's excess :math:`\\alpha I / h_e` acting through :math:`U_r` (Duffie and
Beckman [1]_, section 6.4). The convective part of :math:`h_e` grows with the wind
(ISO 6946 [2]_, annex C: :math:`h_c = 4 + 4 v`), so the same sun heats an attic about
three times as much on a calm day as in a gale.

An RC model multiplies each solar surface's irradiance by an effective aperture
(:math:`\\propto \\alpha A U_r / (h_e + U_r)`); with :math:`h_e` varying, the weight
:func:`roof_wind_weight` applied to the irradiance keeps the model linear (a known,
time-varying input) and adds no parameter: the aperture is then the one at ISO 6946's
standard exterior resistance :math:`R_{se} = 0.04` m² K/W (:data:`REFERENCE_WIND`),
and the weight is 1 when no wind speed is known.

Glazing's transmitted sun does not depend on the wind; the weight is for opaque roof
planes only.

References
----------
.. [1] J. A. Duffie and W. A. Beckman, "Solar Engineering of Thermal Processes", 4th ed.,
   Wiley (2013), sections 3.15 (wind heat transfer coefficients) and 6.4.
.. [2] ISO 6946:2017, "Building components and building elements - Thermal resistance and
   thermal transmittance - Calculation methods", annex C (surface resistances:
   :math:`h_c = 4 + 4 v`, :math:`h_r = \\varepsilon h_{r0}`, :math:`h_{r0} = 4 \\sigma
   T_m^3` = 4.6 W/(m² K) at 0 °C; :math:`R_{se} = 0.04` at :math:`v` = 4 m/s).
"""

from __future__ import annotations

import numpy as np

from heritage_bayes.errors import InputError

__all__ = [
    "REFERENCE_WIND",
    "ROOF_INNER_CONDUCTANCE",
    "exterior_surface_coefficient",
    "roof_wind_weight",
]

#: Wind speed [m/s] of ISO 6946's standard exterior surface resistance (0.04 m² K/W).
REFERENCE_WIND = 4.0
#: Conductance of a roof's cover to the attic [W/(m² K)], :math:`U_r`: boarding or
#: sarking (about 0.1 m² K/W) with the underside's surface resistance (0.10, ISO 6946
#: upward flow) and the cover's contact, about 5 W/(m² K); of 0, 5 and 12 the value
#: that fitted the attics it was tuned on best (``docs/science/real_rooms.md``, "The wind
#: on the roof").
ROOF_INNER_CONDUCTANCE = 5.0
#: Long-wave emissivity of the roof's outer surface [-] (tile, slate, painted metal).
_EMISSIVITY = 0.9
#: :math:`h_{r0}` at 0 °C [W/(m² K)] (ISO 6946 table C.1).
_HR0 = 4.6


def exterior_surface_coefficient(wind_speed) -> np.ndarray:
    """Exterior surface coefficient [W/(m² K)] at wind speed ``wind_speed`` [m/s]:
    :math:`h_e = \\varepsilon h_{r0} + 4 + 4 v` (ISO 6946 annex C, :math:`\\varepsilon`
    0.9), 24.1 at 4 m/s (:math:`R_{se}` 0.04 m² K/W).

    Raises
    ------
    heritage_bayes.errors.InputError
        A negative or non-finite wind speed.
    """
    v = np.asarray(wind_speed, dtype=float)
    if not np.isfinite(v).all() or (v < 0).any():
        bad = v[~(np.isfinite(v) & (v >= 0))]
        raise InputError(f"wind speed: finite values >= 0 m/s expected (found {bad[:3].tolist()})")
    return _EMISSIVITY * _HR0 + 4.0 + 4.0 * v


def roof_wind_weight(wind_speed, inner_conductance: float = ROOF_INNER_CONDUCTANCE):
    """Weight [-] of a roof plane's irradiance for the share of its absorbed sun that
    reaches the attic, relative to the standard exterior resistance.

    Parameters
    ----------
    wind_speed : array_like
        Wind speed [m/s] (a weather station's, 10 m above the ground).
    inner_conductance : float, default :data:`ROOF_INNER_CONDUCTANCE`
        :math:`U_r` [W/(m² K)], the cover's conductance to the attic.

    Returns
    -------
    numpy.ndarray
        :math:`w(v) = (h_e(v_{ref}) + U_r) / (h_e(v) + U_r)`, :math:`v_{ref}` =
        :data:`REFERENCE_WIND`: 1 at 4 m/s, 2.2 in calm air, 0.65 at 8 m/s (with the
        default :math:`U_r`).
    """
    u = float(inner_conductance)
    if not np.isfinite(u) or u < 0:
        raise InputError(f"inner_conductance: a conductance >= 0 W/(m² K) (got {u!r})")
    ref = exterior_surface_coefficient(REFERENCE_WIND)
    return (ref + u) / (exterior_surface_coefficient(wind_speed) + u)
