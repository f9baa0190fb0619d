"""heritage_bayes: Bayesian calibration of RC models of the indoor climate of monuments.

The forward models follow Kramer, van Schijndel & Schellen, "Inverse modeling of climate
responses of monumental buildings" (thermal model 4a, hygric model 3).
"""

from heritage_bayes import climate, io
from heritage_bayes._version import __version__
from heritage_bayes.errors import ConfigError, DataError, InputError
from heritage_bayes.rc import (
    Network,
    RCModel,
    available_models,
    discretize,
    model,
    simulate,
    structural_identifiability,
)


def __getattr__(name):
    # heavier entry points, imported on first use (no side effects at import)
    if name == "load_run":
        from heritage_bayes.run import load_run

        return load_run
    if name == "run_calibration":
        from heritage_bayes.calibrate import run_calibration

        return run_calibration
    raise AttributeError(f"module 'heritage_bayes' has no attribute {name!r}")


__all__ = [
    "ConfigError",
    "DataError",
    "InputError",
    "Network",
    "RCModel",
    "__version__",
    "available_models",
    "climate",
    "discretize",
    "io",
    "load_run",
    "model",
    "run_calibration",
    "simulate",
    "structural_identifiability",
]
