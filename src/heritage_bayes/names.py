"""The name lists a user chooses from: noise models, sampler moves, prior families (each
with its numerics, which import numpy only when called) and the controls of a room's air.

Layer 0, imported by the settings (the choices of ``noise:`` and ``sampler.moves``,
:class:`heritage_bayes.config._base.Choices`), by the command line (``hbayes models
--noise``'s choices), by the generated references and by the report.

The noise models and the moves are listed nowhere by hand: :data:`NOISE_MODELS` and
:data:`MOVES` are each a :class:`Registry` that each implementation fills where it is
defined (:func:`heritage_bayes.inference.likelihoods.register_noise` beside a noise
model's class, :func:`heritage_bayes.inference.monitor.register_move` with a move
mixture's description), read from here by the layers below the numerics.

The catalogue of RC models is :data:`heritage_bayes.rc.catalog.CATALOG` (one entry
per model, its ladder position and solar capability included).
"""

from __future__ import annotations

import importlib
import math
from collections.abc import Iterator, Mapping
from typing import Any, TypeVar

_T = TypeVar("_T")

__all__ = [
    "CONTROLS",
    "DEFAULT_MOVE",
    "DEFAULT_NOISE",
    "HUMIDISTAT_MODES",
    "MOVES",
    "NOISE_MODELS",
    "PRIOR_DISTRIBUTIONS",
    "DistributionName",
    "Registry",
]


class Registry(Mapping[str, _T]):
    """A name list a user chooses from (name -> entry), filled by the implementations
    themselves: each registers under its name where it is defined, and nothing else
    lists the names.

    The settings and the command line sit below the implementations and read the list
    through this object. Its first read imports ``home``, the module whose import
    registers the package's own entries, so that every name is known whoever asks
    first (the numerics are imported then, not when the settings module is). The
    entries keep the order of their registration.
    """

    def __init__(self, what: str, home: str):
        #: What an entry is, for messages (``"noise model"``).
        self.what = what
        #: The module whose import registers the package's own entries.
        self.home = home
        self._entries: dict[str, _T] = {}
        self._loaded = False

    def _load(self) -> dict[str, _T]:
        if not self._loaded:  # a read during home's import gets the entries so far
            importlib.import_module(self.home)
            self._loaded = True
        return self._entries

    def register(self, name: str, entry: _T) -> _T:
        """Add ``entry`` under ``name``.

        Raises
        ------
        ValueError
            The name is taken or not a lowercase identifier.
        """
        if name in self._load() or not name.isidentifier() or name != name.lower():
            raise ValueError(f"{self.what} {name!r}: registered once, under a lowercase identifier")
        self._entries[name] = entry
        return entry

    def unregister(self, name: str) -> _T:
        """Remove the entry of ``name`` (a test's or an example's) and return it."""
        return self._load().pop(name)

    def __getitem__(self, name: str) -> _T:
        return self._load()[name]

    def __iter__(self) -> Iterator[str]:
        return iter(self._load())

    def __len__(self) -> int:
        return len(self._load())

    def __repr__(self) -> str:
        return f"Registry({self.what!r}, {list(self)!r})"


#: ``noise:`` choices (name -> its class, a
#: :class:`heritage_bayes.inference.likelihoods.NoiseModel`, registered by
#: :func:`heritage_bayes.inference.likelihoods.register_noise` beside its definition).
NOISE_MODELS: Registry[Any] = Registry("noise model", "heritage_bayes.inference")
#: The noise model of a section that does not choose one.
DEFAULT_NOISE = "ar1_white"

#: ``sampler.moves`` choices, the default first (name -> its emcee move mixture, a
#: :class:`heritage_bayes.inference.monitor.Mixture`, registered by
#: :func:`heritage_bayes.inference.monitor.register_move` with its description).
MOVES: Registry[Any] = Registry("sampler move", "heritage_bayes.inference.monitor")
#: The moves of a sampler that does not choose them.
DEFAULT_MOVE = "de_snooker"


class DistributionName:
    """A prior family (``priors.<name>.dist``): its traits, read by the settings and the
    command line without importing numpy, and its numerics, which import it when called
    (:class:`heritage_bayes.inference.priors.Prior` delegates to them).

    The package's families are flat or normal in their sampling coordinate :math:`y`
    (:math:`\\log\\theta` for a log-scale family, else :math:`\\theta`), truncated to
    the bounds. A new family, of any shape, is one subclass and one entry of
    :data:`PRIOR_DISTRIBUTIONS`: its density in parameter units (:meth:`logpdf`), the
    same density in the sampling coordinate (:meth:`ylogpdf`, which the sampler's
    vectorised log-prior :meth:`heritage_bayes.inference.parameters.ParameterSet.transform`
    and the MAP search call per family), its draws and its default support.
    """

    #: Sampled in log θ: the parameter must be positive (``lower > 0``).
    log_scale: bool = False
    #: The config key of its centre besides ``sigma`` (``median`` or ``mean``), in the
    #: parameter's units; None for a flat family.
    centre: str | None = None
    #: Without bounds, the support is the centre ± ``span`` × ``sigma`` (in log θ for a
    #: log-scale family).
    span: float = 0.0

    def __init__(self, description: str):
        #: One line for the references.
        self.description = description

    def __repr__(self) -> str:
        return f"{type(self).__name__}({self.description!r})"

    def logpdf(self, theta, mu: float | None, sigma: float | None):
        """Unnormalised log density at ``theta`` (array, parameter units; bounds not
        checked), centre ``mu`` (median or mean) and ``sigma``."""
        raise NotImplementedError

    def ylogpdf(self, y, m, s):
        """Unnormalised log density in the sampling coordinate ``y``, column-wise:
        ``y`` (K, c) the columns of this family, ``m`` and ``s`` (c,) their centres in
        ``y`` and their ``sigma`` (1 where none). Equal to :meth:`logpdf` at
        :math:`\\theta(y)` plus :math:`\\log|d\\theta/dy|` up to a constant; None for
        a family flat in ``y`` (it adds nothing)."""
        return None

    def sample(self, rng, a: float, b: float, m: float, sigma: float | None, size: int):
        """``size`` draws of the sampling coordinate y in [a, b] (flat in y; a normal
        family overrides), centre ``m`` in y."""
        return rng.uniform(a, b, size)

    def support(self, mu: float, sigma: float) -> tuple[float, float]:
        """The bounds a centred family takes when none are given: the centre ±
        ``span`` × ``sigma`` in the sampling coordinate, in parameter units."""
        if self.log_scale:
            return mu * math.exp(-self.span * sigma), mu * math.exp(self.span * sigma)
        return mu - self.span * sigma, mu + self.span * sigma

    def describe(self, name: str, bounds: str, mu: float | None, sigma: float | None) -> str:
        """Short human-readable form, e.g. ``loguniform[1e+04, 1e+12]``."""
        return f"{name}{bounds}"


class _Centred(DistributionName):
    """Normal in the sampling coordinate, truncated to the bounds."""

    def ylogpdf(self, y, m, s):
        z = (y - m) / s
        return -(0.5 * z * z)

    def sample(self, rng, a, b, m, sigma, size):
        from scipy.stats import truncnorm

        lo, hi = (a - m) / sigma, (b - m) / sigma
        return truncnorm.rvs(lo, hi, loc=m, scale=sigma, size=size, random_state=rng)


class _Uniform(DistributionName):
    def logpdf(self, theta, mu, sigma):
        import numpy as np

        return np.zeros_like(theta)


class _LogUniform(DistributionName):
    log_scale = True

    def logpdf(self, theta, mu, sigma):
        import numpy as np

        return -np.log(theta)


class _Normal(_Centred):
    centre = "mean"
    span = 6.0

    def logpdf(self, theta, mu, sigma):
        return -0.5 * ((theta - mu) / sigma) ** 2

    def describe(self, name, bounds, mu, sigma):
        return f"normal({mu:.3g}, {sigma:.3g}) on {bounds}"


class _LogNormal(_Centred):
    log_scale = True
    centre = "median"
    span = 5.0

    def logpdf(self, theta, mu, sigma):
        import numpy as np

        lt = np.log(theta)
        return -lt - 0.5 * ((lt - math.log(mu)) / sigma) ** 2

    def describe(self, name, bounds, mu, sigma):
        return f"lognormal(median {mu:.3g}, σ_log {sigma:.3g}) on {bounds}"


#: ``priors.<name>.dist`` choices: the bounded prior families.
PRIOR_DISTRIBUTIONS: dict[str, DistributionName] = {
    "uniform": _Uniform("flat between lower and upper"),
    "loguniform": _LogUniform("flat in log θ between lower and upper (density ∝ 1/θ)"),
    "normal": _Normal(
        "normal of mean and sd sigma, truncated to the bounds (default: mean ± 6 sigma)"
    ),
    "lognormal": _LogNormal(
        "log-normal of median and sd of log sigma, truncated to the bounds (default: "
        "median × exp(±5 sigma))"
    ),
}


#: Controls of a room's air (``<section>.options``, :mod:`heritage_bayes.rc.control`):
#: name -> the domain of the model it acts on (None: either).
CONTROLS: dict[str, str | None] = {"thermostat": "thermal", "humidistat": "hygric", "source": None}
#: Modes of a humidistat: the air's RH held within ``[RH_lo, RH_hi]``, below ``RH_hi``,
#: above ``RH_lo``, at ``RH_set``.
HUMIDISTAT_MODES = ("band", "dehumidifier", "humidifier", "setpoint")
