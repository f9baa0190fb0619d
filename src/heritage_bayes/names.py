"""The name lists a user chooses from, declared once: noise models, sampler moves,
prior families and the controls of a room's air.

Layer 0, imported by the settings (the choices of ``noise:`` and ``sampler.moves``,
:class:`heritage_bayes.config._base.Choices`), by the command line (``hbayes models
--noise``'s choices, without importing the numerics), by the generated references and
by the report; the implementations register under a declared name
(:func:`heritage_bayes.inference.likelihoods.register_noise`,
:data:`heritage_bayes.inference.monitor.MOVES`), and a name declared here without an
implementation, or the other way round, fails the tests.

The catalogue of RC models is :data:`heritage_bayes.rc.catalog.CATALOG` (one entry
per model, its ladder position and solar capability included).
"""

from __future__ import annotations

from typing import NamedTuple

__all__ = [
    "CONTROLS",
    "DEFAULT_NOISE",
    "HUMIDISTAT_MODES",
    "MOVES",
    "NOISE_MODELS",
    "PRIOR_DISTRIBUTIONS",
    "DistributionName",
    "NoiseName",
    "declare_noise",
    "noise_traits",
]


class NoiseName(NamedTuple):
    """What the package knows of a noise model without importing its numerics."""

    #: One line for the references.
    description: str
    #: Its model error is an AR(1) process with coefficient ``phi_<output>``: the
    #: report shows the error's correlation time.
    ar1: bool = False
    #: Besides the AR(1) error, white sensor noise ``sigma_meas_<output>``.
    white: bool = False
    #: ``phi`` has a cap per time (the prior's upper bound from the time step): a
    #: ``phi`` at its cap is a finding, not a prior bound.
    capped_phi: bool = False
    #: A state-space model (a Kalman filter on the stochastic RC model): the fit
    #: figure shows its one-step-ahead band.
    state_space: bool = False


#: ``noise:`` choices, the default first.
NOISE_MODELS: dict[str, NoiseName] = {}
#: The noise model of a section that does not choose one.
DEFAULT_NOISE = "ar1_white"


def declare_noise(name: str, entry: NoiseName) -> NoiseName:
    """Declare a noise model's name (then its class registers under it).

    Raises
    ------
    ValueError
        The name is taken or not a lowercase identifier.
    """
    if name in NOISE_MODELS or not name.isidentifier() or name != name.lower():
        raise ValueError(f"noise model name {name!r}: taken, or not a lowercase identifier")
    NOISE_MODELS[name] = entry
    return entry


def noise_traits(name: str | None) -> NoiseName:
    """The declaration of a noise model by name; a name not declared (a run written by
    another version) has none of the traits."""
    return NOISE_MODELS.get(name or "", NoiseName(""))


declare_noise(
    "ar1_white",
    NoiseName("AR(1) model error + white sensor noise", ar1=True, white=True, capped_phi=True),
)
declare_noise("ar1", NoiseName("a single AR(1) error", ar1=True))
declare_noise("iid", NoiseName("independent errors"))
declare_noise("kalman", NoiseName("a Kalman filter on the stochastic RC model", state_space=True))

#: ``sampler.moves`` choices, the default first (name -> description); the emcee
#: mixtures are :data:`heritage_bayes.inference.monitor.MOVES`.
MOVES: dict[str, str] = {
    "de_snooker": "differential evolution 80 %, snooker 20 %",
    "de_snooker_50": "differential evolution 50 %, snooker 50 %",
    "de": "differential evolution",
    "stretch": "the affine-invariant stretch move",
    "de_global": "de_snooker whose DE part is replaced, for a walker in ten, by an "
    "independent draw from a Student-t fitted to the chain so far",
    "dime": "DE with those independent draws, no snooker",
}


class DistributionName(NamedTuple):
    """What the package knows of a prior family (``priors.<name>.dist``) without
    importing its numerics (:class:`heritage_bayes.inference.priors.Prior`)."""

    #: One line for the references.
    description: str
    #: Sampled in log θ: the parameter must be positive (``lower > 0``).
    log_scale: bool = False
    #: The config key of its centre besides ``sigma`` (``median`` or ``mean``), in the
    #: parameter's units; None for a flat family.
    centre: str | None = None
    #: Without bounds, the support is the centre ± ``span`` × ``sigma`` (in log θ for a
    #: log-scale family).
    span: float = 0.0


#: ``priors.<name>.dist`` choices: the bounded prior families.
PRIOR_DISTRIBUTIONS: dict[str, DistributionName] = {
    "uniform": DistributionName("flat between lower and upper"),
    "loguniform": DistributionName(
        "flat in log θ between lower and upper (density ∝ 1/θ)", log_scale=True
    ),
    "normal": DistributionName(
        "normal of mean and sd sigma, truncated to the bounds (default: mean ± 6 sigma)",
        centre="mean",
        span=6.0,
    ),
    "lognormal": DistributionName(
        "log-normal of median and sd of log sigma, truncated to the bounds (default: "
        "median × exp(±5 sigma))",
        log_scale=True,
        centre="median",
        span=5.0,
    ),
}


#: Controls of a room's air (``<section>.options``, :mod:`heritage_bayes.rc.control`):
#: name -> the domain of the model it acts on (None: either).
CONTROLS: dict[str, str | None] = {"thermostat": "thermal", "humidistat": "hygric", "source": None}
#: Modes of a humidistat: the air's RH held within ``[RH_lo, RH_hi]``, below ``RH_hi``,
#: above ``RH_lo``, at ``RH_set``.
HUMIDISTAT_MODES = ("band", "dehumidifier", "humidifier", "setpoint")
