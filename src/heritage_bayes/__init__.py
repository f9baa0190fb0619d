"""heritage_bayes: Bayesian calibration of RC models of the indoor climate of monuments.

The forward models follow Kramer, van Schijndel & Schellen, "Inverse modeling of climate
responses of monumental buildings" (thermal model 4a, hygric model 3).
"""

from heritage_bayes._env import writable_caches
from heritage_bayes._version import __version__
from heritage_bayes.errors import ConfigError, DataError, InputError

writable_caches()  # before arviz, numba or matplotlib is imported

#: public name -> module that defines it; imported on first use, so that ``hbayes
#: --version`` and config errors do not wait for numpy, scipy and pandas
_LAZY = {
    "climate": "heritage_bayes.climate",
    "io": "heritage_bayes.io",
    "Network": "heritage_bayes.rc",
    "RCModel": "heritage_bayes.rc",
    "available_models": "heritage_bayes.rc",
    "discretize": "heritage_bayes.rc",
    "model": "heritage_bayes.models",
    "simulate": "heritage_bayes.rc",
    "structural_identifiability": "heritage_bayes.rc",
    "load_run": "heritage_bayes.run",
    "project": "heritage_bayes.projection",
    "run_calibration": "heritage_bayes.calibration.calibrate",
}


def __getattr__(name):
    import importlib

    if name not in _LAZY:
        raise AttributeError(f"module 'heritage_bayes' has no attribute {name!r}")
    mod = importlib.import_module(_LAZY[name])
    value = mod if mod.__name__ == f"{__name__}.{name}" else getattr(mod, name)
    globals()[name] = value
    return value


def __dir__():
    return sorted([*globals(), *_LAZY])


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
    "project",
    "run_calibration",
    "simulate",
    "structural_identifiability",
]
