"""Priors from a building survey: what a description of the room knows (its volume,
floor, envelope and interior areas, windows, roof, the ground behind a fixed node) as
log-normal priors or bounds on the parameters of the matching role.

:func:`heritage_bayes.inference.parameters.parameters_for` attaches them by the
parameter's role in the catalogue (:data:`heritage_bayes.rc.catalog.ROLES`) through
:data:`ROLE_PRIORS`, and to the solar apertures by surface. Each prior pins a direction
hourly temperatures leave free (the overall scale of C and G, see
:mod:`heritage_bayes.rc.identify`) or cuts a ridge to physically possible values.
"""

from __future__ import annotations

import math
from collections.abc import Callable, Mapping
from dataclasses import dataclass, field

from heritage_bayes.errors import ConfigError
from heritage_bayes.inference.priors import Prior, default_prior

__all__ = [
    "APERTURE_PER_GLAZING",
    "C_BUFFER_MAX",
    "C_ENVELOPE_MAX",
    "DELTA_AIR",
    "G_VAPOUR_MAX",
    "G_VAPOUR_MIN",
    "HYG_CAP_AIR",
    "H_EXTERIOR",
    "H_INTERIOR",
    "RHO_CP_AIR",
    "RH_FIXED_NODE",
    "ROLE_PRIORS",
    "ROOF_APERTURE_PER_AREA",
    "SD_FLOOR",
    "SIGMA_FIXED_NODE",
    "U_ENVELOPE_MIN",
    "U_GROUND",
    "Survey",
    "air_capacity_prior",
    "aperture_prior",
    "envelope_priors",
    "fixed_vapour_pressure_prior",
    "ground_prior",
    "interior_prior",
    "roof_aperture_prior",
    "vapour_ground_prior",
    "ventilation_prior",
]

#: Volumetric heat capacity of air at room conditions [J/(m³·K)] (1.2 kg/m³ × 1005 J/(kg·K)).
RHO_CP_AIR = 1.2 * 1005.0
#: Hygric capacity of air per volume [kg/(Pa·m³)] at 15 °C: 1 / (R_v T).
HYG_CAP_AIR = 1.0 / (461.52 * 288.15)


def _lognormal(median: float, sigma: float) -> Prior:
    """The log-normal prior of a survey quantity: ``median``, sd of log ``sigma``, bounded
    at ±5 sd (the sampler's walls, where the density is e^-12.5 of its peak)."""
    return Prior(
        "lognormal", median * math.exp(-5 * sigma), median * math.exp(5 * sigma), median, sigma
    )


def _per_area(key: str, area: float, per_m2: float, sigma: float) -> Prior:
    """:func:`_lognormal` with median ``per_m2 × area`` for a survey's area [m²] given
    as the config key ``key`` (an area ≤ 0 is a ConfigError naming it)."""
    if not area > 0:
        raise ConfigError(f"{key} must be > 0 m² (got {area})")
    return _lognormal(per_m2 * area, sigma)


def air_capacity_prior(
    domain: str, volume: float, *, factor: float | None = None, sigma: float | None = None
) -> Prior:
    """Log-normal prior on the air-node capacity ``Ci`` from the room volume [m³].

    Thermal: median ``factor × ρc_air × V`` with ρc_air = 1206 J/(m³·K), default
    factor 5 (air plus the fast-responding surface layers and light contents lumped in
    the air node), σ_log = 1.0 (2σ range 0.7–37 × the air alone).
    Hygric: median ``factor × V/(R_v T)`` (7.5e-6 kg/(Pa·m³)), default factor 10, σ_log
    1.5, since fast hygroscopic surfaces buffer far more than the air.

    This pins the otherwise unidentifiable overall scale of all C and G (see
    :mod:`heritage_bayes.rc.identify`).
    """
    if not volume > 0:
        raise ConfigError(f"room volume must be > 0 m³ (got {volume})")
    if domain == "thermal":
        base, factor, sigma = RHO_CP_AIR * volume, factor or 5.0, sigma or 1.0
    else:
        base, factor, sigma = HYG_CAP_AIR * volume, factor or 10.0, sigma or 1.5
    median = base * factor
    lo = max(base * 0.5, median * math.exp(-5 * sigma))
    return Prior("lognormal", lo, median * math.exp(5 * sigma), median, sigma)


def ventilation_prior(
    domain: str, volume: float, air_change_rate: float, *, sigma: float = 1.0
) -> Prior:
    """Log-normal prior on the fast conductance ``Gfast`` from an air change rate.

    Thermal: median ``ρc_air × V × n / 3600`` [W/K]; in model 4a ``Gfast`` also carries
    other fast paths (glazing), which the default width σ_log = 1.0 (a factor 2.7)
    admits. Hygric: median ``V × n / (3600 R_v T)`` [kg/(s·Pa)] (ventilation only).
    ``air_change_rate`` n in [1/h], ``volume`` V in [m³]. Sharing n between the thermal
    and hygric models is the physical link between them, and it pins the overall scale
    of C and G that hourly temperatures alone leave free (the air node's own capacity
    ``Ci`` cannot, since its time constant is usually shorter than the time step).
    """
    if not volume > 0:
        raise ConfigError(f"room_volume must be > 0 m³ (got {volume})")
    if not air_change_rate > 0:
        raise ConfigError(f"air_change_rate must be > 0 per hour (got {air_change_rate})")
    flow = volume * air_change_rate / 3600.0  # [m³/s]
    median = flow * (RHO_CP_AIR if domain == "thermal" else HYG_CAP_AIR)
    return _lognormal(median, sigma)


#: Typical thermal transmittance of a large ground floor to the deep ground [W/(m²·K)]
#: (EN ISO 13370: about 0.2 for large insulated slabs to about 1 for small uninsulated
#: ones; historic halls on the ground: 0.3-0.6).
U_GROUND = 0.4


def ground_prior(floor_area: float, *, u_value: float = U_GROUND, sigma: float = 1.0) -> Prior:
    """Log-normal prior on the ground conductance ``Gf`` [W/K] from the floor area.

    Median ``u_value × floor_area``, width σ_log = 1 (a factor 2.7: U from 0.15 to 1.1
    W/(m²·K) within one σ). Why: with a constant ground temperature ``Tf`` the data see
    ``Gf`` only through the mean level, which a slow envelope mode and the start also
    move, so the default log-uniform prior (seven decades) lets ``Gf`` drift to zero and
    the gain from ``Te`` to one (measured: docs/science/sbc.md, "Figures behind the
    code's choices"), while a floor area is in every building survey.

    Parameters
    ----------
    floor_area : float
        Floor area on the ground [m²].
    u_value : float
        Median ground-floor transmittance [W/(m²·K)].
    sigma : float
        sd of log(Gf).
    """
    return _per_area("floor_area", floor_area, u_value, sigma)


#: Heat transfer coefficient between the interior mass and the room air [W/(m²·K)]:
#: the convective part of the interior surface coefficient, h_c ≈ 2.5 W/(m²·K) for walls
#: (EN ISO 6946:2017, Annex C; 5 upward, 0.7 downward), plus the share of the radiative
#: exchange h_r ≈ 5 W/(m²·K) (R_si 0.13 m²K/W in all, Table 7) that a lumped air node
#: carries, since the surfaces the interior mass sees in radiation belong to the air
#: node's side of the network: between 2.5 and 7.7; the median of
#: :func:`interior_prior`.
H_INTERIOR = 5.0


def interior_prior(interior_area: float, *, h: float = H_INTERIOR, sigma: float = 0.7) -> Prior:
    """Log-normal prior on the conductance ``Gint`` [W/K] between the room air and the
    interior mass (model 4a's ``Cint``: inner walls and floors, vaults, furniture) from
    the area [m²] of those surfaces.

    Median ``h × interior_area`` (:data:`H_INTERIOR`, 5 W/(m²·K)), width σ_log = 0.7 (a
    factor 2: 2.5-10 W/(m²·K) within one σ). Why: what couples a mass to the air is its
    surface, and a building survey knows the surface while hourly temperatures do not.
    With the default log-uniform prior over seven decades a posterior can hold an arm in
    which the interior mass is decoupled (a few tenths of a square metre of surface),
    which the chain crosses only in rare long excursions (measured:
    docs/science/benchmarks.md, "The interior area and several optima").

    Parameters
    ----------
    interior_area : float
        Area of the interior constructions and contents in contact with the room air
        [m²]: floor, inner walls, vaults, the contents' surfaces.
    h : float
        Median surface heat transfer coefficient [W/(m²·K)].
    sigma : float
        sd of log(Gint).
    """
    return _per_area("interior_area", interior_area, h, sigma)


#: Effective solar aperture per m² of glazing [-]: EN ISO 13790:2008, 11.3.3,
#: A_sol = F_sh × g × (1 − F_F) × A_w, with g ≈ 0.77 for old single glazing (0.85 at normal
#: incidence × 0.9 for the angles of the day), a frame share F_F ≈ 0.3 and shading by
#: reveals and surroundings F_sh ≈ 0.75: 0.77 × 0.7 × 0.75 ≈ 0.4.
APERTURE_PER_GLAZING = 0.4


def aperture_prior(
    glazing_area: float, *, factor: float = APERTURE_PER_GLAZING, sigma: float = 0.7
) -> Prior:
    """Log-normal prior on a surface's effective solar aperture ``fI_<surface>`` [m²]
    from the glazed area of its windows [m²].

    Median ``factor × glazing_area`` (:data:`APERTURE_PER_GLAZING`, EN ISO 13790's
    collecting area of a window), width σ_log = 0.7 (a factor 2: g-value, frame and
    shading, and the sun the opaque wall passes on, all uncertain). Why: with the
    default log-uniform prior over five decades a facade whose sun is mostly diffuse
    (north) is hardly told from the others, and the prior's volume pulls its aperture
    towards zero (measured over logger-noise seeds, with the commands:
    docs/science/sbc.md, "The demo's solar apertures"); a window
    count is in every building survey.

    Parameters
    ----------
    glazing_area : float
        Glazed area of the surface's windows [m²] (> 0).
    factor : float
        Median effective aperture per m² of glazing [-].
    sigma : float
        sd of log(fI).
    """
    if not (isinstance(glazing_area, (int, float)) and glazing_area > 0):
        raise ConfigError(f"glazing_area must be > 0 m² (got {glazing_area!r})")
    median = factor * glazing_area
    return _lognormal(median, sigma)


#: Effective solar aperture per m² of a ventilated roof's slope [-]: the share of the sun
#: on the covering that reaches the attic air, EN ISO 13790:2008 11.3.4 for an opaque
#: element, A_sol = α × R_se × U × A: α ≈ 0.65 (red clay tile; 0.3-0.9 from light to
#: dark sheet), R_se = 0.04 m²K/W (EN ISO 6946, Table 7), U ≈ 2.6 W/(m²·K) from the
#: covering to the attic air (radiation across the ventilated gap, 4.7 W/(m²·K) for
#: emissivities 0.9, EN ISO 6946 Annex D, in series with R_si = 0.17 m²K/W, heat flow
#: downward): 0.65 × 0.04 × 2.6 ≈ 0.07.
ROOF_APERTURE_PER_AREA = 0.07


def roof_aperture_prior(
    plane_area: float, *, factor: float = ROOF_APERTURE_PER_AREA, sigma: float = 0.7
) -> Prior:
    """Log-normal prior on a roof slope's effective solar aperture ``fI_roof_<...>``
    [m²] from the slope's area [m²].

    Median ``factor × plane_area`` (:data:`ROOF_APERTURE_PER_AREA`: absorbed fraction ×
    the share of the absorbed heat that reaches the attic air, EN ISO 13790's opaque
    element [1]_), width σ_log = 0.7 (a factor 2: the covering's absorptance, the gap's
    ventilation and the wind, all uncertain).

    Parameters
    ----------
    plane_area : float
        Area of the slope [m²] (> 0), along the slope.
    factor : float
        Median effective aperture per m² of slope [-].
    sigma : float
        sd of log(fI).

    References
    ----------
    .. [1] EN ISO 13790:2008, Energy performance of buildings - Calculation of energy
       use for space heating and cooling, 11.3.4 (the effective collecting area of
       opaque building parts).
    """
    if not (isinstance(plane_area, (int, float)) and plane_area > 0):
        raise ConfigError(f"roof area must be > 0 m² (got {plane_area!r})")
    return _lognormal(factor * plane_area, sigma)


#: Exterior surface heat transfer coefficient [W/(m²·K)]: 1 / R_se, R_se = 0.04 m²K/W
#: (EN ISO 6946:2017, Table 7): nothing outside the envelope node couples it to the
#: outdoor air better than the film on its outer face.
H_EXTERIOR = 25.0
#: Best-insulated envelope per m² of its surface [W/(m²·K)]: U = 0.1, a passive-house
#: wall (EN ISO 6946 gives U; masonry of monuments is 1-3): the envelope node's Gw, its
#: conductance to the outdoor air through the outer part of the wall, is at least U × area.
U_ENVELOPE_MIN = 0.1
#: Heaviest envelope per m² of its surface [J/(m²·K)]: 3 m of granite or dense
#: stone at ρc ≈ 2.5 MJ/(m³·K) (EN ISO 10456: granite 2 500 kg/m³ × 1 000 J/(kg·K)).
C_ENVELOPE_MAX = 3.0 * 2.5e6


#: Most vapour-open envelope per m² [kg/(m²·s·Pa)]: a layer of equivalent air
#: thickness s_d = 0.1 m (δ_air ≈ 2e-10 kg/(m·s·Pa), EN ISO 12572; a thin open board;
#: masonry walls have s_d of metres, EN ISO 10456). Air leaks are Gfast's.
G_VAPOUR_MAX = 2e-9
#: Most vapour-tight envelope per m² [kg/(m²·s·Pa)] that a buffer linked to the outdoor
#: air (a model's ``Gw``) stands for: s_d = 100 m (δ_air 2e-10 / 100; a metre of dense
#: masonry, μ ≈ 100, EN ISO 10456; brick walls of monuments have s_d of 2-20 m): the
#: hygric ``Gw``'s lower bound, as ``U_ENVELOPE_MIN`` is the thermal one's. A tighter
#: envelope (a membrane, a metal roof) is a buffer linked to nothing but the air: a
#: model without ``Gw``.
G_VAPOUR_MIN = 2e-12
#: Largest moisture buffer per m² of envelope [kg/(m²·Pa)]: 10 cm of wood (moisture
#: capacity dw/dφ ≈ 250 kg/m³ at high RH) in equilibrium at 0 °C (p_sat 611 Pa):
#: 0.1 × 250 / 611 ≈ 0.04, generous enough to include the interior's contents.
C_BUFFER_MAX = 0.04


def envelope_priors(envelope_area: float, domain: str = "thermal") -> dict[str, Prior]:
    """Bounds on an envelope node (thermal) or a moisture buffer (hygric) from the
    exterior surface area.

    ``Gw`` (envelope node - outdoor air) [W/K] at most ``H_EXTERIOR × area`` and
    ``Cw`` [J/K] at most ``C_ENVELOPE_MAX × area``; the log-uniform family and Cw's
    lower bound stay the defaults' (Gw's lower bound: below). Why: without them a 2c or 4a posterior
    can hold a ridge running to an envelope node clamped to the outdoor air (Gw at the
    default's 1e5 W/K) that keeps its slow mode with a capacity of 1e11 J/K: a low-pass
    filtered outdoor temperature, physically a wall tens of metres thick. Along the
    ridge the solar gain moves (measured: docs/science/sbc.md, "Figures behind the
    code's choices").

    And ``Gw`` at least ``U_ENVELOPE_MIN × area``: an envelope node nearly detached
    from the outdoor air (Gw 0.01-0.3 W/K for a 259 m² envelope) is the trap of the
    Kalman likelihoods, whose process noise then makes the detached node a random walk
    that carries the slow response (``noise: kalman``; docs/science/noise.md, "Two
    traps, and the bounds that close them").

    Hygric models (``domain="hygric"``): the buffer node's ``Gw`` (buffer - outdoor)
    [kg/(s·Pa)] at most ``G_VAPOUR_MAX × area`` and ``Cw`` [kg/Pa] at most
    ``C_BUFFER_MAX × area``. Without them hygric_2c_fixed holds the same kind of ridge:
    a buffer welded to the outdoor air (Gw at the default's 1e-3) with a capacity of
    1e3 kg/Pa (a tonne of water per pascal), a low-pass filtered Pe that trades the
    gain from Pe against the fixed node's offset (measured: docs/science/noise.md, "Two
    traps, and the bounds that close them"). And the
    hygric ``Gw`` at least ``G_VAPOUR_MIN × area`` (an envelope no tighter than
    s_d = 100 m): a wall's exchange with outdoors that relaxes over months to years is
    barely seen in a few months of data, and the default's log-uniform prior, down to
    1e-12, then holds most of its volume in envelopes tighter than any masonry
    (docs/science/sbc.md, "The coupled hygric models").

    Parameters
    ----------
    envelope_area : float
        Exterior surface area of walls and roof [m²] (not the floor on the ground).
    domain : str
        ``"thermal"`` or ``"hygric"``.

    Returns
    -------
    dict
        ``{"conductance": prior of Gw, "capacity": prior of Cw}``: by the parameter's
        kind, the two parameters of the ``envelope`` role.
    """
    out = {}
    limits = (H_EXTERIOR, C_ENVELOPE_MAX) if domain == "thermal" else (G_VAPOUR_MAX, C_BUFFER_MAX)
    for kind, limit in (
        ("conductance", limits[0] * envelope_area),
        ("capacity", limits[1] * envelope_area),
    ):
        d = default_prior(domain, kind)
        if not limit > d.lower:
            raise ConfigError(
                f"envelope_area: {envelope_area:g} m² bounds the envelope's {kind} at "
                f"{limit:.3g}, below its default lower bound {d.lower:g}; expected the "
                "exterior area of walls and roof in m² (tens to thousands)"
            )
        lower = d.lower
        if kind == "conductance":
            floor = U_ENVELOPE_MIN if domain == "thermal" else G_VAPOUR_MIN
            lower = max(lower, floor * envelope_area)
        out[kind] = Prior(d.dist, lower, limit)
    return out


#: Relative humidity of the air or water surface behind a fixed vapour-pressure node
#: [-]: soil air and a wet wall (Kramer et al.'s canal) are at or near saturation, a
#: crypt or cellar at 80-100 % RH; the median of :func:`fixed_vapour_pressure_prior`.
RH_FIXED_NODE = 0.9
#: sd of log(Pf) [-]: the source's RH (0.75-1.0, sd 0.08 in log), its temperature
#: against the annual mean outdoor one (± 2 K at 6.8 %/K near 10 °C: sd 0.14), and
#: room for what the node also lumps (a moisture source the model lacks).
SIGMA_FIXED_NODE = 0.25
#: Equivalent air-layer thickness s_d [m] of a ground floor laid on soil, the median of
#: :func:`vapour_ground_prior` (brick or stone on sand with open joints, no membrane:
#: 0.2-1.5 m within one sd; EN ISO 10456 gives mu of 5-10 for brick, 50-100 for dense
#: stone, whose joints short-circuit it).
SD_FLOOR = 0.5
#: Vapour permeability of still air [kg/(m·s·Pa)] (EN ISO 12572, ~20 °C).
DELTA_AIR = 2e-10


def fixed_vapour_pressure_prior(
    temperature: float, *, rh: float = RH_FIXED_NODE, sigma: float = SIGMA_FIXED_NODE
) -> Prior:
    """Log-normal prior on the fixed node's vapour pressure ``Pf`` [Pa] of
    ``hygric_2c_fixed`` from the temperature of what lies behind it.

    Median ``rh × p_sat(temperature)``, width ``sigma``, bounds median × exp(±5 σ).
    Kramer, van Schijndel & Schellen introduce the node for a basement wall in contact
    with a canal, "analogous to the thermal situation with ground contact": ground,
    water or crypt air at the ground temperature (the annual mean outdoor temperature),
    near saturation: soil air below the surface layer and air over water are close to
    100 % RH (ground-contact constructions: Hens, *Building Physics: Heat, Air and
    Moisture*, 2nd ed., Ernst & Sohn, 2012).

    Why: the gain from ``Pe`` and the node's offset ``Gf/(ΣG) × Pf`` trade along a ridge
    three months of data barely resolve; the former default (uniform on 0-5 000 Pa) gives
    the weak-node, high-``Pf`` end of the ridge most of its volume, so the posterior
    leant there (measured: docs/science/sbc.md, "The fixed vapour-pressure node").

    Parameters
    ----------
    temperature : float
        Temperature of the ground, water or space behind the node [°C].
    rh : float
        Median relative humidity there [-].
    sigma : float
        sd of log(Pf) [-].
    """
    from heritage_bayes.climate.psychro import saturation_vapour_pressure

    if not (math.isfinite(temperature) and -40.0 <= temperature <= 40.0):
        raise ConfigError(
            f"fixed_node_temperature: expected a ground temperature in -40..40 °C "
            f"(got {temperature!r})"
        )
    median = rh * float(saturation_vapour_pressure(temperature))
    return _lognormal(median, sigma)


def vapour_ground_prior(floor_area: float, *, s_d: float = SD_FLOOR, sigma: float = 1.0) -> Prior:
    """Log-normal prior on the vapour conductance ``Gf`` [kg/(s·Pa)] between indoor
    air and a fixed vapour-pressure node under the floor, from the floor area [m²].

    Median ``DELTA_AIR / s_d × floor_area`` (diffusion through a floor of equivalent
    air-layer thickness ``s_d`` [m]; 1.6e-8 kg/(s·Pa) for 80 m² at s_d 0.5 m),
    σ_log = 1 (s_d 0.18-1.4 m within one σ). The hygric counterpart of
    :func:`ground_prior`: the default log-uniform prior over nine decades puts most of
    its volume on a node too weak to matter (gain from Pe → 1), the end of the
    gain-offset ridge the posterior leant to (:func:`fixed_vapour_pressure_prior`).
    """
    if not floor_area > 0:
        raise ConfigError(f"floor_area must be > 0 m² (got {floor_area})")
    median = DELTA_AIR / s_d * floor_area
    return _lognormal(median, sigma)


@dataclass(frozen=True)
class Survey:
    """What a description of the room gives; None (or empty) where it is not known.

    Attributes
    ----------
    room_volume : float or None
        Room air volume [m³] (role ``air_capacity``; with ``air_change_rate``,
        ``ventilation``).
    air_change_rate : float or None
        Air changes per hour [1/h] (role ``ventilation``).
    air_change_sigma : float
        sd of log of the ventilation conductance's prior [-].
    floor_area : float or None
        Floor area on the ground [m²] (role ``ground``).
    envelope_area : float or None
        Exterior area of walls and roof [m²] (role ``envelope``).
    interior_area : float or None
        Area of the interior constructions and contents [m²] (role ``interior_mass``).
    glazing_area : mapping surface -> float
        Glazed area of each solar surface's windows [m²] (its aperture).
    roof_area : mapping surface -> float
        Area of each roof slope [m²] (its aperture).
    fixed_node_temperature : float or None
        Temperature behind a fixed vapour-pressure node [°C] (role ``fixed_potential``).
    """

    room_volume: float | None = None
    air_change_rate: float | None = None
    air_change_sigma: float = 1.0
    floor_area: float | None = None
    envelope_area: float | None = None
    interior_area: float | None = None
    glazing_area: Mapping[str, float] = field(default_factory=dict)
    roof_area: Mapping[str, float] = field(default_factory=dict)
    fixed_node_temperature: float | None = None

    def aperture(self, surface: str) -> Prior | None:
        """The prior on the solar aperture of ``surface`` [m²]: from its windows'
        glazed area, else from its roof slope's area, else None (the default)."""
        if surface in self.glazing_area:
            try:
                return aperture_prior(self.glazing_area[surface])
            except ConfigError as exc:
                raise ConfigError(f"glazing_area.{surface}: {exc}") from None
        if surface in self.roof_area:
            return roof_aperture_prior(self.roof_area[surface])
        return None


def _air_capacity(s: Survey, domain: str, kind: str) -> Prior | None:
    if s.room_volume is None or kind != "capacity":
        return None
    return air_capacity_prior(domain, s.room_volume)


def _ventilation(s: Survey, domain: str, kind: str) -> Prior | None:
    if s.air_change_rate is None or kind != "conductance":
        return None
    if s.room_volume is None:
        raise ConfigError(
            "air_change_rate: needs room_volume (the ventilation "
            "conductance is volume × air change rate)"
        )
    return ventilation_prior(domain, s.room_volume, s.air_change_rate, sigma=s.air_change_sigma)


def _ground(s: Survey, domain: str, kind: str) -> Prior | None:
    if s.floor_area is None or kind != "conductance":
        return None
    return ground_prior(s.floor_area) if domain == "thermal" else vapour_ground_prior(s.floor_area)


def _interior_mass(s: Survey, domain: str, kind: str) -> Prior | None:
    if s.interior_area is None or (domain, kind) != ("thermal", "conductance"):
        return None
    return interior_prior(s.interior_area)


def _envelope(s: Survey, domain: str, kind: str) -> Prior | None:
    if s.envelope_area is None:
        return None
    return envelope_priors(s.envelope_area, domain)[
        "conductance" if kind == "conductance" else "capacity"
    ]


def _fixed_potential(s: Survey, domain: str, kind: str) -> Prior | None:
    if s.fixed_node_temperature is None or kind != "constant":
        return None
    return fixed_vapour_pressure_prior(s.fixed_node_temperature)


#: Parameter role (:data:`heritage_bayes.rc.catalog.ROLES`) -> the prior a survey sets on
#: a parameter of that role, domain and kind (None: the survey does not say; the
#: default prior stays).
ROLE_PRIORS: dict[str, Callable[[Survey, str, str], Prior | None]] = {
    "air_capacity": _air_capacity,
    "ventilation": _ventilation,
    "ground": _ground,
    "interior_mass": _interior_mass,
    "envelope": _envelope,
    "fixed_potential": _fixed_potential,
}
