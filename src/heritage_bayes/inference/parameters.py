"""Parameters and the transform to an unconstrained sampling space.

Every estimated quantity (each C, G, solar aperture, split fraction, constant boundary,
and the noise parameters) is a :class:`Parameter` with a name, unit, kind and a bounded
:class:`~heritage_bayes.inference.priors.Prior`. Sampling happens in a transformed
space ``x``:

- positive parameters with *log-scale* priors (``loguniform``, ``lognormal``):
  :math:`x = \\log\\theta` (unbounded for positivity), the prior bounds as hard walls;
- *linear* priors (``uniform``, ``normal``): :math:`x = \\theta`, the bounds as walls;
- fractions and the AR(1) coefficient: :math:`\\theta = l + (u-l)\\,\\sigma(x)` (logit).

Log rather than logit for C, G and apertures matters: RC posteriors have ridges that are
exactly straight in log space (scaling all C and G together leaves the output unchanged),
and a logit of each parameter's own range would bend them into thin curved bananas,
which ensemble samplers explore badly (docs/science/benchmarks.md, "Figures behind the
code's choices").

The log-prior in ``x`` includes the log-Jacobian :math:`\\log|d\\theta/dx|`, so the
posterior is the same distribution whatever the transform (lmfit's bounded-parameter
idea, made Bayesian).

:func:`parameters_for` gives a model and its noise model their parameters: the default
prior of each kind (:func:`~heritage_bayes.inference.priors.default_prior`), the
survey's priors by the parameter's role in the catalogue
(:data:`~heritage_bayes.inference.survey.ROLE_PRIORS`), then the configured ones
(:func:`~heritage_bayes.inference.priors.configured_prior`).
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from dataclasses import dataclass, field

import numpy as np
from scipy.special import expit

from heritage_bayes.errors import ConfigError
from heritage_bayes.inference.priors import (
    LOGIT_KINDS,
    Prior,
    PriorOverride,
    check_fixed,
    configured_prior,
    default_prior,
)
from heritage_bayes.inference.survey import ROLE_PRIORS, Survey
from heritage_bayes.rc.catalog import roles_of, solar_apertures

__all__ = ["Parameter", "ParameterSet", "owned_priors", "parameters_for"]


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
        self._mu = np.array([p.centre for p in priors])
        self._sig = np.array([p.sigma or 1.0 for p in priors])
        # the free columns of each prior family not flat in its sampling coordinate
        # (DistributionName.ylogpdf None), with their centres and sigmas
        fams = [p.family for p in priors]
        self._families = []
        for fam in dict.fromkeys(fams):
            cols = np.array([k for k, f in enumerate(fams) if f is fam])
            m, s = self._mu[cols], self._sig[cols]
            if fam.ylogpdf(m[None, :], m, s) is not None:
                self._families.append((fam, cols, m, s))
        # logit for quantities bounded on both sides by nature (fractions, AR(1) phi);
        # log θ (or θ) with the bounds as hard walls for the rest, so that the exactly
        # linear log-space ridges of RC models (the overall scale) stay straight lines,
        # which affine-invariant ensemble moves follow at no cost
        self._logit = np.array([self.parameters[j].kind in LOGIT_KINDS for j in self._free_idx])
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
        # y is log θ for log-scale priors: the Jacobian gains dθ/dy = θ, which each
        # family's density in y holds (loguniform's 1/θ cancels it)
        logp = self._add_log_density_y(y, logj)
        theta[:, self._free_idx] = th
        return theta, logp.sum(axis=1)

    def log_density_y(self, y: np.ndarray) -> np.ndarray:
        """(K, d) unnormalised log prior density of each free parameter in its sampling
        coordinate ``y`` (log θ or θ; bounds not checked), asked of each family
        (:meth:`heritage_bayes.names.DistributionName.ylogpdf`); 0 where flat."""
        return self._add_log_density_y(y, np.zeros_like(y))

    def _add_log_density_y(self, y: np.ndarray, out: np.ndarray) -> np.ndarray:
        """``out`` (K, d) plus :meth:`log_density_y` of ``y``, in place."""
        for fam, cols, m, s in self._families:
            out[:, cols] += fam.ylogpdf(y[:, cols], m, s)
        return out

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
    priors: Mapping[str, PriorOverride] | None = None,
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
    priors : mapping name -> PriorOverride, optional
        Overrides per parameter, typed and checked when the settings were loaded
        (:class:`heritage_bayes.config.PriorSpec`; :func:`heritage_bayes.config.prior_specs`
        makes them from plain mappings): ``fixed``, or a prior whose missing keys keep
        the default's (:func:`~heritage_bayes.inference.priors.configured_prior`).
        Unknown names are rejected.
    room_volume : float, optional
        Room air volume [m³]: sets a log-normal prior on the air capacity (role
        ``air_capacity``, ``Ci``; see :func:`~heritage_bayes.inference.survey.air_capacity_prior`)
        unless ``priors`` sets it.
    air_change_rate : float, optional
        Air changes per hour [1/h] (needs ``room_volume``): a log-normal prior of width
        ``air_change_sigma`` on the ventilation conductance (role ``ventilation``,
        ``Gfast``; :func:`~heritage_bayes.inference.survey.ventilation_prior`).
    floor_area : float, optional
        Floor area on the ground [m²]: a log-normal prior on the ground coupling (role
        ``ground``, ``Gf``) of a thermal model
        (:func:`~heritage_bayes.inference.survey.ground_prior`) or the fixed
        vapour-pressure node's of a hygric one
        (:func:`~heritage_bayes.inference.survey.vapour_ground_prior`).
    envelope_area : float, optional
        Exterior surface area of walls and roof [m²]: bounds on the envelope node
        (role ``envelope``, ``Gw`` and ``Cw``;
        :func:`~heritage_bayes.inference.survey.envelope_priors`).
    interior_area : float, optional
        Area of the interior constructions and contents in contact with the room air
        [m²]: a log-normal prior on the interior-mass conductance (role
        ``interior_mass``, ``Gint``) of a thermal model that has one
        (:func:`~heritage_bayes.inference.survey.interior_prior`); ignored by the others.
    glazing_area : mapping surface -> float, optional
        Glazed area of the windows [m²] of solar surfaces: a log-normal prior on each
        listed surface's aperture ``fI_<surface>``
        (:func:`~heritage_bayes.inference.survey.aperture_prior`); the other surfaces
        keep the default. Ignored by a model without solar inputs; a surface the model
        does not have is an error.
    roof_area : mapping surface -> float, optional
        Area [m²] of each roof slope (``data.roof``'s planes): a log-normal prior on its
        aperture (:func:`~heritage_bayes.inference.survey.roof_aperture_prior`). A model
        without the surface ignores it.
    fixed_node_temperature : float, optional
        Temperature [°C] of the ground or space behind a fixed vapour-pressure node: a
        log-normal prior on its pressure (role ``fixed_potential``, ``Pf``;
        :func:`~heritage_bayes.inference.survey.fixed_vapour_pressure_prior`).
    where : str
        Key path used in error messages.

    Raises
    ------
    ConfigError
        Naming the key path: an unknown parameter, a glazed surface the model does not
        have, a fixed value outside its kind's physical range, a configured prior that
        does not fit its parameter, or a survey value out of range.
    """
    survey = Survey(
        room_volume=room_volume,
        air_change_rate=air_change_rate,
        air_change_sigma=air_change_sigma,
        floor_area=floor_area,
        envelope_area=envelope_area,
        interior_area=interior_area,
        glazing_area=dict(glazing_area or {}),
        roof_area=dict(roof_area or {}),
        fixed_node_temperature=fixed_node_temperature,
    )
    priors = dict(priors or {})
    noise_specs = noise.parameter_specs(model.output_names, model.state_names)
    _check_names(model, noise, priors, noise_specs, where)
    apertures = solar_apertures(model.parameter_names)
    if apertures:
        _check_glazing(model, set(apertures.values()), survey.glazing_area)
    domain = model.domain
    noise_priors = noise.priors_for(dt)
    roles = roles_of(model.name)
    params = []
    for name, kind, unit, desc, is_noise in _entries(model, noise, noise_specs):
        if is_noise and (domain, kind) in noise_priors:
            prior = noise_priors[(domain, kind)]
        else:
            prior = default_prior(domain, kind)
        if not is_noise:
            role = ROLE_PRIORS.get(roles.get(name, ""))
            prior = (role(survey, domain, kind) if role else None) or prior
            if name in apertures and kind == "gain":
                prior = survey.aperture(apertures[name]) or prior
        spec = priors.get(name)
        params.append(_parameter(name, kind, unit, desc, prior, spec, f"{where}.{name}"))
    return ParameterSet(params)


def owned_priors(priors: Mapping[str, PriorOverride], model, noise) -> dict:
    """The configured priors whose parameters ``model`` or its noise model has: the
    model's parameter names and those the noise model names for the model's outputs and
    nodes (:meth:`~heritage_bayes.inference.likelihoods.NoiseModel.parameter_specs`), so
    that a model of a ladder keeps the section's priors that fit it."""
    own = set(model.parameter_names)
    own |= {n for n, _, _ in noise.parameter_specs(model.output_names, model.state_names)}
    return {k: v for k, v in priors.items() if k in own}


def _check_names(model, noise, priors: Mapping, noise_specs, where: str) -> None:
    """Every configured prior names a parameter of the model or its noise model."""
    known = set(model.parameter_names) | {n for n, _, _ in noise_specs}
    unknown = sorted(set(priors) - known)
    if unknown:
        raise ConfigError(
            f"{where}: unknown parameter(s) {unknown} for model "
            f"{model.name!r} with noise {noise.name!r}; parameters are "
            f"{sorted(known)}"
        )


def _check_glazing(model, surfaces: set[str], glazing: Mapping[str, float]) -> None:
    """Every glazed surface is a solar surface of the model."""
    stray = sorted(set(glazing) - surfaces)
    if stray:
        raise ConfigError(
            f"glazing_area: surface(s) {stray} are not solar surfaces of model "
            f"{model.name!r}; its surfaces are {sorted(surfaces)} (data.surfaces)"
        )


def _entries(model, noise, noise_specs) -> list[tuple[str, str, str, str, bool]]:
    """(name, kind, unit, description, is_noise) of the model's parameters, then of
    the noise model's (their units and descriptions the noise model's own: its
    ``unit`` and ``descriptions``)."""
    potential = "K" if model.domain == "thermal" else "Pa"
    out_units = {
        o: model.network.input_unit(o) if o in model.input_names else potential
        for o in model.output_names
    }
    entries = [(i.name, i.kind, i.unit, i.description, False) for i in model.parameters]
    for n, k, o in noise_specs:
        unit = noise.unit(k, out_units.get(o, potential), potential)
        entries.append((n, k, unit, f"{noise.descriptions.get(k, k)} {o}", True))
    return entries


def _parameter(
    name: str, kind: str, unit: str, desc: str, prior: Prior, spec, where: str
) -> Parameter:
    """The parameter with its prior, unless the configured ``spec`` fixes it or sets
    another prior (``where``: its key path, e.g. ``thermal.priors.Gw``)."""
    if spec is None:
        return Parameter(name, unit, kind, prior, None, desc)
    if spec.fixed is not None:
        fixed = float(spec.fixed)
        check_fixed(f"{where}.fixed", kind, fixed)
        return Parameter(name, unit, kind, prior, fixed, desc)
    return Parameter(name, unit, kind, configured_prior(spec, prior, where=where), None, desc)
