"""arviz, imported without its one-off notice about the arviz 1.x refactor.

arviz 0.23 prints a multi-line FutureWarning at import; it is about arviz's own future
API, not about anything a user of heritage_bayes can act on, so it is silenced here (and
only that message).
"""

import warnings

with warnings.catch_warnings():
    warnings.filterwarnings(
        "ignore", message=r"\s*ArviZ is undergoing a major refactor", category=FutureWarning
    )
    import arviz as az

__all__ = ["az"]
