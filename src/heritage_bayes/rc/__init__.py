"""Layer 1: RC networks, exact discretization and the fast simulator (pure numpy/scipy).

See :mod:`heritage_bayes.rc.catalog` for the paper's models. Its :func:`model` takes
typed options (the network's keywords and a :class:`Control`);
:func:`heritage_bayes.model` takes them as a config section writes them.
"""

from heritage_bayes.rc.catalog import CATALOG, available_models, model
from heritage_bayes.rc.control_spec import Control
from heritage_bayes.rc.derived import (
    constant_contributions,
    derived_quantities,
    derived_units,
    static_gains,
    time_constants,
)
from heritage_bayes.rc.discretize import (
    ModalForm,
    discretize,
    discretize_foh,
    foh_weights,
    modal_form,
)
from heritage_bayes.rc.identify import structural_identifiability
from heritage_bayes.rc.identify_result import IdentifiabilityResult, NullDirection
from heritage_bayes.rc.model import RCModel
from heritage_bayes.rc.network import Link, Network, Node, ParameterInfo, Source
from heritage_bayes.rc.simulate import iter_simulate, simulate

__all__ = [
    "CATALOG",
    "Control",
    "IdentifiabilityResult",
    "Link",
    "ModalForm",
    "Network",
    "Node",
    "NullDirection",
    "ParameterInfo",
    "RCModel",
    "Source",
    "available_models",
    "constant_contributions",
    "derived_quantities",
    "derived_units",
    "discretize",
    "discretize_foh",
    "foh_weights",
    "iter_simulate",
    "modal_form",
    "model",
    "simulate",
    "static_gains",
    "structural_identifiability",
    "time_constants",
]
