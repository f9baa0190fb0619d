"""Layer 2: priors, noise models, the vectorised log-posterior, MAP and emcee."""
