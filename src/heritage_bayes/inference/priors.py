"""Bounded priors: the families, their numerics, the defaults per parameter kind, and a
configured prior applied to a parameter.

A :class:`Prior` is a family of :data:`heritage_bayes.names.PRIOR_DISTRIBUTIONS`
(``uniform``, ``loguniform``, ``normal``, ``lognormal``) on bounds that are also the
sampler's walls: log-scale families are sampled in :math:`x = \\log\\theta`, the others in
:math:`\\theta` (:mod:`heritage_bayes.inference.parameters`). Default priors per kind are
weakly informative and physically plausible (:func:`default_prior`); what a building
survey knows enters as a log-normal prior (:mod:`heritage_bayes.inference.survey`).

A prior the settings give (:class:`heritage_bayes.config.PriorSpec`, checked on its own
when the config is loaded) meets its parameter in :func:`configured_prior`: the family
and bounds it leaves out are the parameter's default's.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Protocol

import numpy as np
from scipy.special import expit, logit

from heritage_bayes.errors import ConfigError
from heritage_bayes.names import PRIOR_DISTRIBUTIONS, DistributionName

__all__ = [
    "FIXED_RANGE",
    "LOGIT_KINDS",
    "Prior",
    "PriorOverride",
    "check_fixed",
    "configured_prior",
    "default_prior",
]

#: Parameter kinds sampled through a logit (bounded on both sides by nature).
LOGIT_KINDS = ("fraction", "phi", "saturation")


@dataclass(frozen=True)
class Prior:
    """A bounded prior.

    Parameters
    ----------
    dist : str
        A family of :data:`heritage_bayes.names.PRIOR_DISTRIBUTIONS`: ``uniform``,
        ``loguniform``, ``normal``, ``lognormal``.
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
        if self.dist not in PRIOR_DISTRIBUTIONS:
            raise ConfigError(
                f"{where}.dist: must be one of {list(PRIOR_DISTRIBUTIONS)} (got {self.dist!r})"
            )
        lo, up = float(self.lower), float(self.upper)
        if not (math.isfinite(lo) and math.isfinite(up)):
            raise ConfigError(f"{where}: bounds must be finite (got [{lo}, {up}])")
        if not lo < up:
            raise ConfigError(f"{where}.lower: must be < upper (got {lo:g} >= {up:g})")
        if self.log_scale and lo <= 0:
            raise ConfigError(f"{where}.lower: a {self.dist} prior needs lower > 0 (got {lo:g})")
        centre = self.family.centre
        if centre is not None:
            if self.mu is None or self.sigma is None or not self.sigma > 0:
                raise ConfigError(
                    f"{where}: a {self.dist} prior needs mu (the {centre}) "
                    f"and sigma > 0 (got mu={self.mu}, sigma={self.sigma})"
                )
            if self.log_scale and not self.mu > 0:
                raise ConfigError(
                    f"{where}.mu: the median of a lognormal prior must be > 0 (got {self.mu:g})"
                )

    @property
    def family(self) -> DistributionName:
        """The family's traits and numerics (:data:`heritage_bayes.names.PRIOR_DISTRIBUTIONS`)."""
        return PRIOR_DISTRIBUTIONS[self.dist]

    @property
    def log_scale(self) -> bool:
        """Sampled in log θ (``loguniform``, ``lognormal``)."""
        return self.family.log_scale

    @property
    def centre(self) -> float:
        """The centre in the sampling coordinate: log(median) or the mean (0 if flat)."""
        if self.mu is None:
            return 0.0
        return math.log(self.mu) if self.log_scale else self.mu

    def to_dict(self) -> dict:
        d = {"dist": self.dist, "lower": self.lower, "upper": self.upper}
        centre = self.family.centre
        if centre is not None:
            d.update({centre: self.mu, "sigma": self.sigma})
        return d

    def describe(self) -> str:
        """Short human-readable form, e.g. ``loguniform[1e+04, 1e+12]``."""
        b = f"[{self.lower:.3g}, {self.upper:.3g}]"
        return self.family.describe(self.dist, b, self.mu, self.sigma)

    # -- numerics on arrays ------------------------------------------------------
    def logpdf(self, theta: np.ndarray) -> np.ndarray:
        """Unnormalised log density in parameter units (bounds not checked)."""
        return self.family.logpdf(theta, self.mu, self.sigma)

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
        y = self.family.sample(rng, a, b, self.centre, self.sigma, size)
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
    # equivalent depth [m] of the soil temperature behind a floor on the ground, in
    # clay/silt (option ground: seasonal; damping depth 2.24 m, ISO 13370): the soil
    # under a building is shielded from the surface above it and follows the outdoor
    # cycle through the ground around the perimeter, so it sits deeper than open ground
    # under the floor: median 2 m, a factor 1.65 per sd, from 0.5 m (the annual swing
    # × 0.80, 13 days late) to 6 m (× 0.07, 156 days late)
    ("thermal", "depth"): Prior("lognormal", 0.5, 6.0, 2.0, 0.5),
    # the ground's annual mean minus that of the outdoor air its cycle is fitted to [K]
    # (option ground: seasonal): one year's mean air temperature departs from the
    # climate's, which the deep soil follows, by about half a kelvin (the year-to-year
    # sd of an annual mean in north-west Europe), and the soil's mean sits above the
    # air's by up to 1-2 K (snow, radiation, a building's heat): sd 1 K about 0, ±5 K
    ("thermal", "offset"): Prior("normal", -5.0, 5.0, 0.0, 1.0),
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
    # multilayer factor K of a buffer's GAB isotherm [-] (heritage_bayes.rc.isotherm):
    # 0.6-0.9 for wood, lime plaster and brick at the material's temperature, × 1.0-2.0
    # for a vapour-pressure buffer at 5-15 °C whose humidity is expressed at 15 °C;
    # 0 is the linear isotherm
    ("hygric", "isotherm_shape"): Prior("uniform", 0.0, 2.0),
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


def default_prior(domain: str, kind: str) -> Prior:
    """The default prior of a parameter kind in a domain (``thermal``/``hygric``)."""
    try:
        return _DEFAULTS[(domain, kind)]
    except KeyError:
        raise ValueError(
            f"no default prior for a {kind!r} parameter in domain {domain!r}"
        ) from None


#: Physical range of a fixed value by parameter kind: (lowest, highest, inclusive?).
FIXED_RANGE = {
    "capacity": (0.0, math.inf, False),  # [J/K], [kg/Pa]: > 0
    "conductance": (0.0, math.inf, True),  # [W/K], [kg/(s·Pa)]: ≥ 0 (0 = no path)
    "gain": (0.0, math.inf, True),
    "fraction": (0.0, 1.0, True),
    "depth": (0.0, 20.0, True),
    "offset": (-20.0, 20.0, True),
    "sorption_capacity": (0.0, math.inf, False),
    "saturation": (0.0, 1.5, True),
    "isotherm_shape": (0.0, 2.0, True),
    "sigma": (0.0, math.inf, False),
    "sigma_meas": (0.0, math.inf, False),
    "phi": (-1.0, 1.0, False),
}


def check_fixed(where: str, kind: str, value: float) -> None:
    """A fixed value within the physical range of its kind (else :class:`ConfigError`
    naming ``where``, the range and the value)."""
    if kind not in FIXED_RANGE:
        return
    lo, hi, inclusive = FIXED_RANGE[kind]
    ok = (lo <= value <= hi) if inclusive else (lo < value < hi)
    if not ok:
        rng = f"[{lo:g}, {hi:g}]" if inclusive else f"({lo:g}, {hi:g})"
        raise ConfigError(f"{where}: a {kind} must be within {rng} (got {value:g})")


class PriorOverride(Protocol):
    """A prior the settings set on one parameter, typed and checked on its own
    (:class:`heritage_bayes.config.PriorSpec`): every key optional, in the parameter's
    units (``sigma`` of a ``lognormal``: of the natural log)."""

    dist: str | None
    lower: float | None
    upper: float | None
    median: float | None
    mean: float | None
    sigma: float | None
    fixed: float | None


def configured_prior(spec: PriorOverride, default: Prior, *, where: str) -> Prior:
    """The prior ``spec`` sets on a parameter whose default prior is ``default``.

    The family not given is the default's; bounds not given are the default's when the
    family is, else, for a centred family (``normal``, ``lognormal``), the centre ±
    its ``span`` × ``sigma`` (:data:`heritage_bayes.names.PRIOR_DISTRIBUTIONS`).

    Raises
    ------
    ConfigError
        Naming ``where`` (the key path, e.g. ``thermal.priors.Gw``): a centre or a
        ``sigma`` the family does not take, missing bounds, or bounds that do not fit
        (``lower`` not below ``upper``, not positive for a log-scale family).
    """
    dist = spec.dist or default.dist
    info = PRIOR_DISTRIBUTIONS[dist]
    takes = {info.centre, "sigma"} if info.centre else set()
    for k in ("median", "mean", "sigma"):
        if getattr(spec, k) is not None and k not in takes:
            raise ConfigError(
                f"{where}.{k}: a {dist} prior has no {k} (the parameter's default family "
                f"is {default.dist}); expected dist: "
                f"{'lognormal' if k == 'median' else 'normal'} with it"
            )
    mu = getattr(spec, info.centre) if info.centre else None
    sigma, lo, up = spec.sigma, spec.lower, spec.upper
    if mu is not None and sigma is not None:
        lo_c, up_c = info.support(float(mu), float(sigma))
        lo = lo if lo is not None else lo_c
        up = up if up is not None else up_c
    if dist == default.dist:
        lo = default.lower if lo is None else lo
        up = default.upper if up is None else up
    if lo is None or up is None:
        raise ConfigError(f"{where}: lower and upper bounds are required for a {dist} prior")
    try:
        return Prior(
            dist,
            float(lo),
            float(up),
            None if mu is None else float(mu),
            None if sigma is None else float(sigma),
        )
    except ConfigError as exc:
        raise ConfigError(str(exc).replace("prior", where, 1)) from None
