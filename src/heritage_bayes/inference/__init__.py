"""Layer 2: priors, noise models, the vectorised log-posterior, MAP and emcee.

Importing the package registers every noise model of the package in
:data:`heritage_bayes.names.NOISE_MODELS` (the registry's ``home``): each noise model's
module registers its classes where it defines them, and is imported here. ``statespace``
(``kalman``) imports ``likelihoods`` (``ar1_white``, ``ar1``, ``iid``), so importing it
registers both.
"""

from heritage_bayes.inference import statespace as _statespace  # noqa: F401
