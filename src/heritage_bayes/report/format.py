"""Where the formatter lived: :mod:`heritage_bayes.format` (numbers, intervals, units and
labels for every page and the CLI). Kept so that code importing it from here still runs."""

from heritage_bayes.format import *  # noqa: F403
from heritage_bayes.format import __all__  # noqa: F401
