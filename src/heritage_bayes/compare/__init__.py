"""Accuracy versus identifiability of candidate models, from full posteriors.

The paper's central trade-off: a richer RC model fits the indoor climate better, but
its parameters lose their physical meaning (Kramer, van Schijndel & Schellen). Given a
config, :func:`run_compare` calibrates each candidate model of one section (each in its
own run directory, with the calibration engine's defaults) and :func:`compare_runs`
sets them side by side:

**Accuracy**

- the paper's fit criteria on the validation period (FIT [%], MSE, MAE of the
  posterior-median simulation);
- the expected log predictive density of the validation hours, ``elpd_val`` =
  :math:`\\sum_t \\log \\frac{1}{S}\\sum_s p(y_t \\mid \\theta_s, y_{t-1})`: with AR(1)
  noise each term is the one-step-ahead predictive density of the hour given the
  previous residual, from the simulation continued past (or through) the calibration (the
  ``log_predictive_density_validation`` group of ``posterior.nc`` holds each hour's
  inner term; older runs, without that group, the terms per draw,
  ``log_likelihood_validation``);
- **blocked PSIS-LOO** on the calibration period: the pointwise log-likelihood summed
  over blocks of ``block_hours`` consecutive hours (default one day), then Pareto-smoothed
  importance-sampling LOO over the blocks (``az.loo``) and ``az.compare`` across models.

Why blocked LOO and not leave-future-out: hourly observations are not exchangeable
(the diurnal cycle, and residuals correlated over hours), so hour-wise LOO rewards a
model for interpolating a left-out hour from its neighbours. Leaving out whole days
removes the diurnal dependence; the AR(1) terms already condition each hour on the
previous residual. Exact leave-future-out needs one refit per forecast origin (minutes
each), and its importance-sampling approximation (PSIS-LFO, Bürkner et al. 2020) must
still refit whenever the Pareto k exceeds 0.7, which happens often when a season is
added; the validation period is the leave-future-out check that needs no refit: one
block, the future, scored by ``elpd_val``. Standard errors of ELPD differences are
computed from daily block sums for the same reason (hourly terms are correlated).

**Identifiability**

- per parameter and derived quantity (time constants, static gains): posterior
  contraction relative to the prior, :math:`1 - \\mathrm{Var}_{post}/\\mathrm{Var}_{prior}`
  (on the log scale for positive quantities; the prior of a derived quantity is the
  push-forward of the parameter priors), and the 90 % interval as a factor
  :math:`q_{95}/q_{05}`; a quantity is *identified* when that factor is at most
  ``identified_factor`` (default 2);
- the structural rank (the Jacobian of the frequency response at the MAP,
  :mod:`heritage_bayes.rc.identify`) and the **practical rank**: the number of
  directions of the free physical parameters (log scale) along which the posterior
  variance is below ``practical_ratio`` (default 1 %) of the prior variance
  (eigenvalues of the prior-whitened posterior covariance);
- the widest 90 % interval of a physical parameter, in decades.

**Recommendation**: the one selection rule of ``model: auto``
(:func:`heritage_bayes.calibration.selection_rule.decide`). The screen ranks the candidates by the
validation FIT of their MAP's simulation and chooses the simplest within 2 points of
the best; the others within 2 points tie with it. The choice and its best tied rival
are sampled (with no tie, the best other candidate, for the comparison), and their
ELPD (validation ELPD, or blocked LOO without a validation period) breaks the tie only
when it is reliable: both chains converged (for blocked LOO, Pareto k at most 0.7),
and the rival ahead by more than 2 standard errors and 4 nats (a negligible
difference [4]_). Otherwise the screen's choice stands, and ``model: auto`` and
``hbayes compare`` recommend the same model; where the ELPD disagrees with the screen,
the recommendation says which way and why. The identifiability of the model
recommended is stated beside it.

References
----------
.. [1] A. Vehtari, A. Gelman, J. Gabry, "Practical Bayesian model evaluation using
   leave-one-out cross-validation and WAIC", Statistics and Computing 27 (2017)
   1413–1432, doi:10.1007/s11222-016-9696-4.
.. [2] P.-C. Bürkner, J. Gabry, A. Vehtari, "Approximate leave-future-out
   cross-validation for Bayesian time series models", J. Stat. Comput. Simul. 90 (2020)
   2499–2523, doi:10.1080/00949655.2020.1783262.
.. [3] R. Kramer, J. van Schijndel, H. Schellen, "Inverse modeling of simplified
   hygrothermal building models to predict and characterize indoor climates", Building
   and Environment 68 (2013) 87–99, doi:10.1016/j.buildenv.2013.06.019.
.. [4] T. Sivula, M. Magnusson, A. Vehtari, "Uncertainty in Bayesian leave-one-out
   cross-validation based model comparison", arXiv:2008.10296 (2020).
"""

from __future__ import annotations

from heritage_bayes.compare.core import (
    DEFAULT_MODELS,
    NEGLIGIBLE_ELPD,
    compare_runs,
    recommend,
)
from heritage_bayes.compare.identifiability import _practical_rank  # noqa: F401
from heritage_bayes.compare.orchestrate import run_compare
from heritage_bayes.compare.page import (
    accuracy_rows,
    fig_tradeoff,
    identifiability_rows,
    render_comparison,
    write_comparison,
)
from heritage_bayes.compare.scores import (  # noqa: F401  (_block_se: tested directly)
    _block_se,
    blocked_loo_data,
    elpd_validation,
    load_inference,
)

__all__ = [
    "DEFAULT_MODELS",
    "NEGLIGIBLE_ELPD",
    "accuracy_rows",
    "blocked_loo_data",
    "compare_runs",
    "elpd_validation",
    "fig_tradeoff",
    "identifiability_rows",
    "load_inference",
    "recommend",
    "render_comparison",
    "run_compare",
    "write_comparison",
]
