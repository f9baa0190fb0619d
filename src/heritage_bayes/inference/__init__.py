"""Layer 2: priors, noise models, the vectorised log-posterior, MAP and emcee."""

# registers noise: kalman in likelihoods.NOISE_MODELS (statespace imports likelihoods,
# not the other way round)
from heritage_bayes.inference import statespace as _statespace  # noqa: F401
