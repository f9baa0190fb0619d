"""Parameters, bounded priors and the transform to an unconstrained sampling space.

Why one module (about 850 lines): the prior families, the transform of each kind of
parameter and the :class:`ParameterSet` that applies them are one contract (the prior's
bounds are the transform's walls and its log-density carries the Jacobian); splitting
them would put one formula on either side of a module boundary.

Every estimated quantity (each C, G, solar aperture, split fraction, constant boundary,
and the noise parameters) is a :class:`Parameter` with a name, unit, kind and a bounded
:class:`Prior`. Sampling happens in a transformed space ``x``:

- positive parameters with *log-scale* priors (``loguniform``, ``lognormal``):
  :math:`x = \\log\\theta` (unbounded for positivity), the prior bounds as hard walls;
- *linear* priors (``uniform``, ``normal``): :math:`x = \\theta`, the bounds as walls;
- fractions and the AR(1) coefficient: :math:`\\theta = l + (u-l)\\,\\sigma(x)` (logit).

Log rather than logit for C, G and apertures matters: RC posteriors have ridges that are
exactly straight in log space (scaling all C and G together leaves the output unchanged),
and a logit of each parameter's own range would bend them into thin curved bananas,
which ensemble samplers explore badly (measured: τ ≈ 1750 vs a few hundred steps).

The log-prior in ``x`` includes the log-Jacobian :math:`\\log|d\\theta/dx|`, so the
posterior is the same distribution whatever the transform (lmfit's bounded-parameter
idea, made Bayesian).

Default priors per kind are weakly informative and physically plausible (see
:func:`default_prior`); knowledge users actually have enters as a log-normal prior, e.g.
the room volume on the air-node capacity (:func:`air_capacity_prior`).
"""

from __future__ import annotations

import math
from collections.abc import Mapping, Sequence
from dataclasses import dataclass, field

import numpy as np
from scipy.special import expit, logit

from heritage_bayes.errors import ConfigError
from heritage_bayes.rc.catalog import roles_of

__all__ = [
    "RHO_CP_AIR",
    "Parameter",
    "ParameterSet",
    "Prior",
    "air_capacity_prior",
    "aperture_prior",
    "default_prior",
    "interior_prior",
    "parameters_for",
    "roof_aperture_prior",
    "ventilation_prior",
]

#: Volumetric heat capacity of air at room conditions [J/(m³·K)] (1.2 kg/m³ × 1005 J/(kg·K)).
RHO_CP_AIR = 1.2 * 1005.0
#: Hygric capacity of air per volume [kg/(Pa·m³)] at 15 °C: 1 / (R_v T).
HYG_CAP_AIR = 1.0 / (461.52 * 288.15)

_DISTS = ("uniform", "loguniform", "normal", "lognormal")
#: Parameter kinds sampled through a logit (bounded on both sides by nature).
_LOGIT_KINDS = ("fraction", "phi", "saturation")


@dataclass(frozen=True)
class Prior:
    """A bounded prior.

    Parameters
    ----------
    dist : {"uniform", "loguniform", "normal", "lognormal"}
    lower, upper : float
        Bounds (the support; ``normal``/``lognormal`` are truncated to them).
    mu, sigma : float, optional
        ``normal``: mean and standard deviation (parameter units);
        ``lognormal``: median and the standard deviation of the natural log
        (``mu`` is the *median* in parameter units).
    """

    dist: str
    lower: float
    upper: float
    mu: float | None = None
    sigma: float | None = None

    def __post_init__(self):
        where = "prior"
        if self.dist not in _DISTS:
            raise ConfigError(f"{where}.dist: must be one of {list(_DISTS)} (got {self.dist!r})")
        lo, up = float(self.lower), float(self.upper)
        if not (math.isfinite(lo) and math.isfinite(up)):
            raise ConfigError(f"{where}: bounds must be finite (got [{lo}, {up}])")
        if not lo < up:
            raise ConfigError(f"{where}.lower: must be < upper (got {lo:g} >= {up:g})")
        if self.log_scale and lo <= 0:
            raise ConfigError(f"{where}.lower: a {self.dist} prior needs lower > 0 (got {lo:g})")
        if self.dist in ("normal", "lognormal"):
            if self.mu is None or self.sigma is None or not self.sigma > 0:
                raise ConfigError(
                    f"{where}: a {self.dist} prior needs mu (the "
                    f"{'median' if self.dist == 'lognormal' else 'mean'}) "
                    f"and sigma > 0 (got mu={self.mu}, sigma={self.sigma})"
                )
            if self.dist == "lognormal" and not self.mu > 0:
                raise ConfigError(
                    f"{where}.mu: the median of a lognormal prior must be > 0 (got {self.mu:g})"
                )

    @property
    def log_scale(self) -> bool:
        return self.dist in ("loguniform", "lognormal")

    @classmethod
    def from_spec(
        cls, spec: Mapping, *, where: str = "prior", default: Prior | None = None
    ) -> Prior:
        """Build from a config mapping, naming ``where`` (the key path) in errors.

        Keys: ``dist``, ``lower``, ``upper``, ``median`` (lognormal) or ``mean``
        (normal), ``sigma``. Missing bounds are taken from ``default``; for a lognormal
        without bounds: median × exp(±5 sigma); for a normal: mean ± 6 sigma.
        """
        allowed = {"dist", "lower", "upper", "median", "mean", "sigma"}
        unknown = sorted(set(spec) - allowed)
        if unknown:
            raise ConfigError(
                f"{where}: unknown key(s) {unknown}; allowed: {sorted(allowed)} (or 'fixed: value')"
            )
        dist = spec.get("dist", default.dist if default else None)
        if dist is None:
            raise ConfigError(f"{where}.dist: required, one of {list(_DISTS)}")
        if dist not in _DISTS:
            raise ConfigError(f"{where}.dist: must be one of {list(_DISTS)} (got {dist!r})")
        mu = spec.get("median") if dist == "lognormal" else spec.get("mean")
        sigma = spec.get("sigma")
        for key, v, positive in (("median", mu, dist == "lognormal"), ("sigma", sigma, True)):
            if v is None:
                continue
            if isinstance(v, bool) or not isinstance(v, int | float) or not math.isfinite(v):
                raise ConfigError(f"{where}.{key}: expected a finite number (got {v!r})")
            if positive and not v > 0:
                what = "the median of a lognormal prior" if key == "median" else "sigma"
                raise ConfigError(f"{where}.{key}: {what} must be > 0 (got {v:g})")
        lo, up = spec.get("lower"), spec.get("upper")
        if dist == "lognormal" and mu is not None and sigma is not None:
            lo = lo if lo is not None else float(mu) * math.exp(-5 * float(sigma))
            up = up if up is not None else float(mu) * math.exp(5 * float(sigma))
        if dist == "normal" and mu is not None and sigma is not None:
            lo = lo if lo is not None else float(mu) - 6 * float(sigma)
            up = up if up is not None else float(mu) + 6 * float(sigma)
        if default is not None:
            lo = default.lower if lo is None else lo
            up = default.upper if up is None else up
        if lo is None or up is None:
            raise ConfigError(f"{where}: lower and upper bounds are required for a {dist} prior")
        try:
            return cls(
                dist,
                float(lo),
                float(up),
                None if mu is None else float(mu),
                None if sigma is None else float(sigma),
            )
        except ConfigError as exc:
            raise ConfigError(str(exc).replace("prior", where, 1)) from None
        except (TypeError, ValueError):
            raise ConfigError(
                f"{where}: bounds, median/mean and sigma must be numbers (got {dict(spec)})"
            ) from None

    def to_dict(self) -> dict:
        d = {"dist": self.dist, "lower": self.lower, "upper": self.upper}
        if self.dist == "lognormal":
            d.update(median=self.mu, sigma=self.sigma)
        elif self.dist == "normal":
            d.update(mean=self.mu, sigma=self.sigma)
        return d

    def describe(self) -> str:
        """Short human-readable form, e.g. ``loguniform[1e+04, 1e+12]``."""
        b = f"[{self.lower:.3g}, {self.upper:.3g}]"
        if self.dist == "lognormal":
            return f"lognormal(median {self.mu:.3g}, σ_log {self.sigma:.3g}) on {b}"
        if self.dist == "normal":
            return f"normal({self.mu:.3g}, {self.sigma:.3g}) on {b}"
        return f"{self.dist}{b}"

    # -- numerics on arrays ------------------------------------------------------
    def logpdf(self, theta: np.ndarray) -> np.ndarray:
        """Unnormalised log density in parameter units (bounds not checked)."""
        if self.dist == "uniform":
            return np.zeros_like(theta)
        if self.dist == "loguniform":
            return -np.log(theta)
        if self.dist == "normal":
            return -0.5 * ((theta - self.mu) / self.sigma) ** 2
        lt = np.log(theta)
        return -lt - 0.5 * ((lt - math.log(self.mu)) / self.sigma) ** 2

    def _ab(self) -> tuple[float, float]:
        if self.log_scale:
            return math.log(self.lower), math.log(self.upper)
        return self.lower, self.upper

    def from_unconstrained(self, x: np.ndarray, mode: str = "direct"):
        """θ(x) and log|dθ/dx| (``-inf`` outside the bounds in ``direct`` mode).

        ``direct``: x = log θ (log-scale priors) or θ, the bounds hard walls;
        ``logit``: x = logit of the position between the bounds.
        """
        a, b = self._ab()
        if mode == "direct":
            x = np.asarray(x, dtype=float)
            logj = np.where((x >= a) & (x <= b), 0.0, -np.inf)
            if self.log_scale:
                return np.exp(np.clip(x, -700, 700)), logj + x
            return x, logj
        s = expit(x)
        y = a + (b - a) * s
        # log σ(x) + log(1 - σ(x)) = -softplus(-x) - softplus(x), stable for large |x|
        logj = math.log(b - a) - np.logaddexp(0.0, -x) - np.logaddexp(0.0, x)
        if self.log_scale:
            return np.exp(y), logj + y
        return y, logj

    def to_unconstrained(self, theta: np.ndarray, mode: str = "direct") -> np.ndarray:
        a, b = self._ab()
        y = np.log(theta) if self.log_scale else np.asarray(theta, dtype=float)
        if mode == "direct":
            return y
        s = np.clip((y - a) / (b - a), 1e-12, 1 - 1e-12)
        return logit(s)

    def sample(self, rng: np.random.Generator, size: int) -> np.ndarray:
        """Draws from the (truncated) prior."""
        a, b = self._ab()
        if self.dist in ("uniform", "loguniform"):
            y = rng.uniform(a, b, size)
        else:
            from scipy.stats import truncnorm

            m = math.log(self.mu) if self.dist == "lognormal" else self.mu
            lo, hi = (a - m) / self.sigma, (b - m) / self.sigma
            y = truncnorm.rvs(lo, hi, loc=m, scale=self.sigma, size=size, random_state=rng)
        return np.exp(y) if self.log_scale else y


#: Default prior bounds per (domain, kind). Documented in the user guide.
_DEFAULTS: dict[tuple[str, str], Prior] = {
    # thermal capacities: from a few m³ of air (1e4 J/K) to a cathedral's masonry (1e12)
    ("thermal", "capacity"): Prior("loguniform", 1e4, 1e12),
    # thermal conductances: a cupboard's leak (0.01 W/K) to a hall with open doors (1e5)
    ("thermal", "conductance"): Prior("loguniform", 1e-2, 1e5),
    # effective solar apertures (window area × transmittance) [m²]
    ("thermal", "gain"): Prior("loguniform", 1e-3, 200.0),
    ("thermal", "fraction"): Prior("uniform", 0.0, 1.0),
    ("thermal", "constant"): Prior("uniform", -20.0, 40.0),
    # hygric capacities [kg/Pa]: air of 1 m³ is 7.5e-6 kg/Pa; buffering contents far more
    ("hygric", "capacity"): Prior("loguniform", 1e-6, 1e3),
    # hygric conductances [kg/(s·Pa)]: 0.1 ACH in 10 m³ ~ 2e-9; 5 ACH in 1e4 m³ ~ 1e-4
    ("hygric", "conductance"): Prior("loguniform", 1e-12, 1e-3),
    ("hygric", "gain"): Prior("loguniform", 1e-6, 1e3),
    ("hygric", "fraction"): Prior("uniform", 0.0, 1.0),
    # fixed vapour pressure [Pa]: 0 to saturation at ~33 °C
    ("hygric", "constant"): Prior("uniform", 0.0, 5000.0),
    # moisture capacity of a sorbing buffer per unit surface RH [kg]: a few kg of a
    # small room's wooden surface layer (100 m² × 1 mm × 450 kg/m³ × ξ 0.15) to a
    # church's plaster and timber (1e6)
    ("hygric", "sorption_capacity"): Prior("loguniform", 1e-2, 1e6),
    # relative humidity of a vapour sink at a temperature [-]: soil and wet walls sit
    # near saturation
    ("hygric", "saturation"): Prior("uniform", 0.7, 1.0),
    # control of the air node (heritage_bayes.rc.control): heating set-points [°C] from
    # frost protection to a warm church; heating power [W] from a radiator (1 kW) to a
    # cathedral's plant (10 MW); RH limits [-]; humidistat capacities [kg/s] from a
    # small dehumidifier (1e-6 kg/s = 0.1 L/day) to a plant (1 kg/s); constant sources:
    # heat [W] (0.01 W to 10 MW) and moisture [kg/s] (a few people emit 1e-5 kg/s)
    ("thermal", "setpoint"): Prior("uniform", 0.0, 30.0),
    ("thermal", "power"): Prior("loguniform", 1.0, 1e7),
    ("thermal", "rh"): Prior("uniform", 0.3, 0.95),
    ("thermal", "source"): Prior("loguniform", 1e-2, 1e7),
    ("hygric", "rh"): Prior("uniform", 0.05, 0.98),
    ("hygric", "moisture_capacity"): Prior("loguniform", 1e-7, 1.0),
    ("hygric", "source"): Prior("loguniform", 1e-9, 1e-1),
    # noise: σ [K] or [Pa], AR(1) coefficient φ [-]
    ("thermal", "sigma"): Prior("loguniform", 1e-3, 10.0),
    ("hygric", "sigma"): Prior("loguniform", 1e-1, 1e3),
    ("thermal", "phi"): Prior("uniform", 0.0, 0.999),
    ("hygric", "phi"): Prior("uniform", 0.0, 0.999),
    # white measurement noise of noise: ar1_white: sensor noise and rounding
    ("thermal", "sigma_meas"): Prior("loguniform", 1e-3, 10.0),
    ("hygric", "sigma_meas"): Prior("loguniform", 1e-1, 1e3),
    # process-noise diffusion of a node (noise: kalman) [K/√h], [Pa/√h]
    ("thermal", "diffusion"): Prior("loguniform", 1e-4, 10.0),
    ("hygric", "diffusion"): Prior("loguniform", 1e-2, 1e3),
}


#: Physical range of a fixed value by parameter kind: (lowest, highest, inclusive?).
_FIXED_RANGE = {
    "capacity": (0.0, math.inf, False),  # [J/K], [kg/Pa]: > 0
    "conductance": (0.0, math.inf, True),  # [W/K], [kg/(s·Pa)]: ≥ 0 (0 = no path)
    "gain": (0.0, math.inf, True),
    "fraction": (0.0, 1.0, True),
    "sorption_capacity": (0.0, math.inf, False),
    "saturation": (0.0, 1.5, True),
    "sigma": (0.0, math.inf, False),
    "sigma_meas": (0.0, math.inf, False),
    "phi": (-1.0, 1.0, False),
}

#: What the noise parameters are, by kind (for descriptions and units).
_NOISE_DESCRIPTION = {
    "sigma": "marginal sd of the model error of",
    "phi": "AR(1) coefficient (per time step) of the model error of",
    "sigma_meas": "sd of the white measurement noise of",
    "diffusion": "process-noise diffusion (per square root of an hour) of node",
}


def _check_fixed(where: str, kind: str, value: float) -> None:
    """A fixed value within the physical range of its kind (else :class:`ConfigError`)."""
    if kind not in _FIXED_RANGE:
        return
    lo, hi, inclusive = _FIXED_RANGE[kind]
    ok = (lo <= value <= hi) if inclusive else (lo < value < hi)
    if not ok:
        rng = f"[{lo:g}, {hi:g}]" if inclusive else f"({lo:g}, {hi:g})"
        raise ConfigError(f"{where}: a {kind} must be within {rng} (got {value:g})")


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


def default_prior(domain: str, kind: str) -> Prior:
    """The default prior of a parameter kind in a domain (``thermal``/``hygric``)."""
    try:
        return _DEFAULTS[(domain, kind)]
    except KeyError:
        raise ValueError(
            f"no default prior for a {kind!r} parameter in domain {domain!r}"
        ) from None


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
    the gain from ``Te`` to one; measured by ``benchmarks/bench_sbc.py``: the gain from
    ``Te`` came out above the truth in most replicates (rank test p 0.01), while a floor
    area is in every building survey.

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
    With the default log-uniform prior over seven decades the demo's ``thermal_4a``
    posterior has an arm in which the interior mass is decoupled (``Gint`` 0.3-3.5 W/K,
    physically a few tenths of a square metre of surface) and the MAP lies there; the
    chain crosses between that arm and a merged mass in rare long excursions (τ of
    ``Gint`` 3 899 steps after 150 000 steps, not converged); with the demo's
    80 m² it converges in 9 500 steps (docs/science/benchmarks.md, "The interior area
    and several optima").

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
    towards zero (measured on the demo's north facade over 24 logger-noise seeds,
    with the commands: docs/science/sbc.md, "The demo's solar apertures"); a window
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
    ridge the solar gain moves by a factor 2-3. Measured by ``benchmarks/bench_sbc.py
    --room 88 --reps 24 --envelope-area 0`` (a 400 m³ hall, true Gw 87 W/K, Cw 3.4e8
    J/K): the MAPs of 24 fresh observations of the room spread from Gw 0.01 to 1e5 W/K
    (Cw up to 2e11 J/K), 22 chains had not converged after 12 000 steps and the 90 %
    interval of the solar gain covered the truth 9 times in 24; with these bounds (area
    259 m²) 16 in 24, and over 100 such rooms the solar gain's coverage rose from 0.81
    to 0.86 (README: simulation-based calibration).

    And ``Gw`` at least ``U_ENVELOPE_MIN × area``: an envelope node nearly detached
    from the outdoor air (Gw 0.01-0.3 W/K for a 259 m² envelope) is the trap of the
    Kalman likelihoods, whose process noise then makes the detached node a random walk
    that carries the slow response (``noise: kalman``, independent SBC rooms 4 and 12:
    Gw 0.27 and 0.01 W/K for truths of 92 and 369 W/K; docs/science/noise.md).

    Hygric models (``domain="hygric"``): the buffer node's ``Gw`` (buffer - outdoor)
    [kg/(s·Pa)] at most ``G_VAPOUR_MAX × area`` and ``Cw`` [kg/Pa] at most
    ``C_BUFFER_MAX × area``. Without them hygric_2c_fixed holds the same kind of ridge:
    a buffer welded to the outdoor air (Gw at the default's 1e-3) with a capacity of
    1e3 kg/Pa (a tonne of water per pascal), a low-pass filtered Pe that trades the
    gain from Pe against the fixed node's offset (measured by
    ``benchmarks/bench_sbc_independent.py`` before these bounds: the MAPs of 9 of 27 rooms
    with ``ar1_white`` and 27 of 39 with ``kalman``; docs/science/noise.md). And the
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
    """
    out = {}
    limits = (H_EXTERIOR, C_ENVELOPE_MAX) if domain == "thermal" else (G_VAPOUR_MAX, C_BUFFER_MAX)
    for name, kind, limit in (
        ("Gw", "conductance", limits[0] * envelope_area),
        ("Cw", "capacity", limits[1] * envelope_area),
    ):
        d = default_prior(domain, kind)
        if not limit > d.lower:
            raise ConfigError(
                f"envelope_area: {envelope_area:g} m² bounds {name} at {limit:.3g}, below its "
                f"default lower bound {d.lower:g}; expected the exterior area of walls and "
                "roof in m² (tens to thousands)"
            )
        lower = d.lower
        if name == "Gw":
            floor = U_ENVELOPE_MIN if domain == "thermal" else G_VAPOUR_MIN
            lower = max(lower, floor * envelope_area)
        out[name] = Prior(d.dist, lower, limit)
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
    leant there. Measured on eight rooms the fitted model generated (``python
    benchmarks/bench_sbc.py --reps 8 --models hygric_2c_fixed --noise
    ar1_white:estimate``): gain from Pe above the truth in 7 of 8 (mean z +1.36), no
    chain converged in 12 000 steps; with the fit's priors equal to the truth's
    distribution (``--truth-priors``) mean z +0.34, 7 of 8 converged (τ 55-220 steps).

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
class Parameter:
    """A named model or noise parameter (lmfit's Parameter, with a prior).

    Attributes
    ----------
    name, unit, kind, description : str
    prior : Prior
    fixed : float or None
        When set, the parameter is held at this value (not sampled).
    """

    name: str
    unit: str
    kind: str
    prior: Prior
    fixed: float | None = None
    description: str = ""

    @property
    def free(self) -> bool:
        return self.fixed is None


@dataclass
class ParameterSet:
    """An ordered collection of parameters: the model's, then the noise model's.

    Maps an unconstrained (K, d) array of the free parameters to (K, P) parameter values
    in the order of ``names`` (fixed ones filled in) and computes the log-prior including
    the Jacobian.
    """

    parameters: Sequence[Parameter]
    _free_idx: np.ndarray = field(init=False, repr=False)

    def __post_init__(self):
        self.parameters = tuple(self.parameters)
        self._free_idx = np.array([i for i, p in enumerate(self.parameters) if p.free], dtype=int)
        if self._free_idx.size == 0:
            raise ConfigError("every parameter is fixed: nothing to calibrate")
        # vectorised transform tables over the free parameters
        priors = [self.parameters[j].prior for j in self._free_idx]
        ab = np.array([p._ab() for p in priors])
        self._a, self._w = ab[:, 0], ab[:, 1] - ab[:, 0]
        self._log = np.array([p.log_scale for p in priors])
        self._code = np.array([_DISTS.index(p.dist) for p in priors])
        self._mu = np.array(
            [
                (math.log(p.mu) if p.dist == "lognormal" else p.mu) if p.mu is not None else 0.0
                for p in priors
            ]
        )
        self._sig = np.array([p.sigma or 1.0 for p in priors])
        # logit for quantities bounded on both sides by nature (fractions, AR(1) phi);
        # log θ (or θ) with the bounds as hard walls for the rest, so that the exactly
        # linear log-space ridges of RC models (the overall scale) stay straight lines,
        # which affine-invariant ensemble moves follow at no cost
        self._logit = np.array([self.parameters[j].kind in _LOGIT_KINDS for j in self._free_idx])
        self.modes = tuple("logit" if m else "direct" for m in self._logit)
        self._fixed = np.array(
            [p.fixed if p.fixed is not None else np.nan for p in self.parameters]
        )

    @property
    def names(self) -> tuple[str, ...]:
        return tuple(p.name for p in self.parameters)

    @property
    def free_names(self) -> tuple[str, ...]:
        return tuple(self.parameters[i].name for i in self._free_idx)

    @property
    def ndim(self) -> int:
        return int(self._free_idx.size)

    def __getitem__(self, name: str) -> Parameter:
        for p in self.parameters:
            if p.name == name:
                return p
        raise KeyError(name)

    @property
    def bounds(self) -> tuple[np.ndarray, np.ndarray]:
        """The support in sampling coordinates: (lo, hi), each (d,).

        log θ (log-scale priors) or θ between the prior bounds; ±inf for the logit
        coordinates, which are unbounded.
        """
        lo = np.where(self._logit, -np.inf, self._a)
        hi = np.where(self._logit, np.inf, self._a + self._w)
        return lo, hi

    def at_bound(self, X: np.ndarray, rel: float = 1e-3) -> list[tuple[str, str]]:
        """Free parameters within ``rel`` × their (sampling-coordinate) range of a bound.

        Returns ``(name, "lower" | "upper")`` pairs for the point ``X`` (d,), e.g. a MAP
        pressed against its prior. Logit coordinates count as at a bound beyond
        ``|x| > log(1/rel)`` (θ within ``rel`` of the range's end).
        """
        x = np.asarray(X, dtype=float).ravel()
        y = np.where(self._logit, expit(x) * self._w + self._a, x)
        pos = (y - self._a) / self._w
        out = []
        for k, j in enumerate(self._free_idx):
            if pos[k] <= rel:
                out.append((self.parameters[j].name, "lower"))
            elif pos[k] >= 1 - rel:
                out.append((self.parameters[j].name, "upper"))
        return out

    def transform(self, X: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """Unconstrained (K, d) -> values (K, P) and log-prior + log-Jacobian (K,)."""
        X = np.atleast_2d(X)
        theta = np.tile(self._fixed, (X.shape[0], 1))
        # logit coordinates: y = a + w σ(x), log|dy/dx| = log w + log σ(x)(1 - σ(x))
        y = np.where(self._logit, self._a + self._w * expit(X), X)
        with np.errstate(invalid="ignore"):
            inside = (y >= self._a) & (y <= self._a + self._w)
        logj = np.where(
            self._logit,
            np.log(self._w) - np.logaddexp(0.0, -X) - np.logaddexp(0.0, X),
            np.where(inside, 0.0, -np.inf),
        )
        th = np.where(self._log, np.exp(np.clip(np.where(self._log, y, 0.0), -700, 700)), y)
        # y is log θ for log-scale priors: the Jacobian gains dθ/dy = θ, and
        # loguniform (∝ 1/θ) cancels it; lognormal keeps the normal term in y
        z = (y - self._mu) / self._sig
        logp = logj - np.where((self._code == 2) | (self._code == 3), 0.5 * z * z, 0.0)
        theta[:, self._free_idx] = th
        return theta, logp.sum(axis=1)

    def values(self, X: np.ndarray) -> np.ndarray:
        """Unconstrained (K, d) -> values (K, P)."""
        return self.transform(X)[0]

    def to_unconstrained(self, theta: np.ndarray) -> np.ndarray:
        """Values (K, P) (all parameters) -> unconstrained free coordinates (K, d)."""
        theta = np.atleast_2d(theta)
        return np.column_stack(
            [
                self.parameters[j].prior.to_unconstrained(theta[:, j], mode)
                for j, mode in zip(self._free_idx, self.modes, strict=True)
            ]
        )

    def sample_prior(self, rng: np.random.Generator, size: int) -> np.ndarray:
        """Prior draws of all parameters (K, P) (fixed ones repeated)."""
        theta = np.empty((size, len(self.parameters)))
        for j, p in enumerate(self.parameters):
            theta[:, j] = p.fixed if p.fixed is not None else p.prior.sample(rng, size)
        return theta

    def to_dict(self) -> dict:
        return {
            p.name: ({"fixed": p.fixed} if p.fixed is not None else p.prior.to_dict())
            | {"unit": p.unit, "kind": p.kind}
            for p in self.parameters
        }


def parameters_for(
    model,
    noise,
    priors: Mapping[str, Mapping] | None = None,
    *,
    room_volume: float | None = None,
    air_change_rate: float | None = None,
    air_change_sigma: float = 1.0,
    floor_area: float | None = None,
    envelope_area: float | None = None,
    interior_area: float | None = None,
    glazing_area: Mapping[str, float] | None = None,
    roof_area: Mapping[str, float] | None = None,
    fixed_node_temperature: float | None = None,
    where: str = "priors",
    dt: float = 3600.0,
) -> ParameterSet:
    """The :class:`ParameterSet` of a model and its noise model (``dt`` [s]: the time
    step, for noise priors defined per time, e.g. ``ar1_white``'s cap on phi).

    Parameters
    ----------
    model : RCModel
    noise : NoiseModel
    priors : mapping name -> spec, optional
        Overrides per parameter: ``{"fixed": value}``, or a prior spec
        (``dist``, ``lower``, ``upper``, ``median``/``mean``, ``sigma``); keys missing from
        a spec keep the default's. Unknown names are rejected.
    room_volume : float, optional
        Room air volume [m³]: sets a log-normal prior on ``Ci`` (see
        :func:`air_capacity_prior`) unless ``priors`` sets ``Ci``.
    air_change_rate : float, optional
        Air changes per hour [1/h] (needs ``room_volume``): a log-normal prior of width
        ``air_change_sigma`` on ``Gfast`` (see :func:`ventilation_prior`).
    floor_area : float, optional
        Floor area on the ground [m²]: a log-normal prior on ``Gf``, the ground coupling
        of a thermal model (:func:`ground_prior`) or the fixed vapour-pressure node's of
        a hygric one (:func:`vapour_ground_prior`).
    envelope_area : float, optional
        Exterior surface area of walls and roof [m²]: upper bounds on a thermal
        model's envelope node, ``Gw`` and ``Cw`` (see :func:`envelope_priors`).
    interior_area : float, optional
        Area of the interior constructions and contents in contact with the room air
        [m²]: a log-normal prior on the interior-mass conductance ``Gint`` of a thermal
        model that has one (see :func:`interior_prior`); ignored by the others.
    glazing_area : mapping surface -> float, optional
        Glazed area of the windows [m²] of solar surfaces: a log-normal prior on each
        listed surface's aperture ``fI_<surface>`` (see :func:`aperture_prior`); the
        other surfaces keep the default. Ignored by a model without solar inputs; a
        surface the model does not have is an error.
    roof_area : mapping surface -> float, optional
        Area [m²] of each roof slope (``data.roof``'s planes): a log-normal prior on its
        aperture (see :func:`roof_aperture_prior`). A model without the surface ignores it.
    fixed_node_temperature : float, optional
        Temperature [°C] of the ground or space behind a fixed vapour-pressure node: a
        log-normal prior on ``Pf`` (see :func:`fixed_vapour_pressure_prior`).
    where : str
        Key path used in error messages.
    """
    priors = dict(priors or {})
    domain = model.domain
    specs: list[Parameter] = []
    noise_specs = noise.parameter_specs(model.output_names, model.state_names)
    known = set(model.parameter_names) | {n for n, _, _ in noise_specs}
    unknown = sorted(set(priors) - known)
    if unknown:
        raise ConfigError(
            f"{where}: unknown parameter(s) {unknown} for model "
            f"{model.name!r} with noise {noise.name!r}; parameters are "
            f"{sorted(known)}"
        )
    apertures = {n.removeprefix("fI_") for n in model.parameter_names if n.startswith("fI_")}
    glazing = dict(glazing_area or {}) if apertures else {}
    stray = sorted(set(glazing) - apertures)
    if stray:
        raise ConfigError(
            f"glazing_area: surface(s) {stray} are not solar surfaces of model "
            f"{model.name!r}; its surfaces are {sorted(apertures)} (data.surfaces)"
        )
    out_units = {
        o: model.network.input_unit(o)
        if o in model.input_names
        else ("K" if domain == "thermal" else "Pa")
        for o in model.output_names
    }
    entries = [(i.name, i.kind, i.unit, i.description) for i in model.parameters]
    entries += [
        (
            n,
            k,
            out_units[o]
            if k.startswith("sigma")
            else f"{'K' if domain == 'thermal' else 'Pa'}/√h"
            if k == "diffusion"
            else "-",
            f"{_NOISE_DESCRIPTION.get(k, k)} {o}",
        )
        for n, k, o in noise_specs
    ]
    noise_names = {n for n, _, _ in noise_specs}
    overrides = noise.priors_for(dt) if hasattr(noise, "priors_for") else {}
    roles = roles_of(model.name)
    for name, kind, unit, desc in entries:
        prior = default_prior(domain, kind)
        role = roles.get(name) if name not in noise_names else None
        if name in noise_names and (domain, kind) in overrides:
            prior = overrides[(domain, kind)]
        if role == "air_capacity" and room_volume is not None and kind == "capacity":
            prior = air_capacity_prior(domain, room_volume)
        if role == "ventilation" and air_change_rate is not None and kind == "conductance":
            if room_volume is None:
                raise ConfigError(
                    "air_change_rate: needs room_volume (the ventilation "
                    "conductance is volume × air change rate)"
                )
            prior = ventilation_prior(domain, room_volume, air_change_rate, sigma=air_change_sigma)
        if (
            role == "ground"
            and floor_area is not None
            and (domain, kind) == ("thermal", "conductance")
        ):
            prior = ground_prior(floor_area)
        if (
            role == "ground"
            and floor_area is not None
            and (domain, kind) == ("hygric", "conductance")
        ):
            prior = vapour_ground_prior(floor_area)
        if role == "fixed_potential" and fixed_node_temperature is not None and kind == "constant":
            prior = fixed_vapour_pressure_prior(fixed_node_temperature)
        if interior_area is not None and (role, domain, kind) == (
            "interior_mass",
            "thermal",
            "conductance",
        ):
            prior = interior_prior(interior_area)
        if envelope_area is not None and role == "envelope":
            prior = envelope_priors(envelope_area, domain)["Gw" if kind == "conductance" else "Cw"]
        surface = name.removeprefix("fI_")
        if surface in (roof_area or {}) and kind == "gain" and name.startswith("fI_"):
            prior = roof_aperture_prior(roof_area[surface])
        if surface in glazing and kind == "gain":
            try:
                prior = aperture_prior(glazing[surface])
            except ConfigError as exc:
                raise ConfigError(f"glazing_area.{surface}: {exc}") from None
        spec = priors.get(name)
        fixed = None
        if spec is not None:
            if not isinstance(spec, Mapping):
                raise ConfigError(
                    f"{where}.{name}: expected a mapping such as "
                    f"{{dist: loguniform, lower: 1, upper: 100}} or "
                    f"{{fixed: 50}} (got {spec!r})"
                )
            if "fixed" in spec:
                if len(spec) > 1:
                    raise ConfigError(
                        f"{where}.{name}: 'fixed' cannot be combined with "
                        f"{sorted(set(spec) - {'fixed'})}"
                    )
                try:
                    fixed = float(spec["fixed"])
                except (TypeError, ValueError):
                    raise ConfigError(
                        f"{where}.{name}.fixed: expected a number (got {spec['fixed']!r})"
                    ) from None
                if not math.isfinite(fixed):
                    raise ConfigError(f"{where}.{name}.fixed: must be finite (got {fixed})")
                _check_fixed(f"{where}.{name}.fixed", kind, fixed)
            else:
                base = prior if spec.get("dist", prior.dist) == prior.dist else None
                prior = Prior.from_spec(spec, where=f"{where}.{name}", default=base)
        specs.append(Parameter(name, unit, kind, prior, fixed, desc))
    return ParameterSet(specs)
