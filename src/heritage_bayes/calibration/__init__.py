"""The calibration: data → posterior → run directory, and the choice of the model.

``hbayes calibrate`` (:func:`heritage_bayes.calibration.calibrate.run_calibration`)
prepares the data, chooses each section's model where the config says ``model: auto``,
finds the MAP, samples the posterior and writes the run directory, whose
``summary.json`` every consumer reads typed
(:class:`heritage_bayes.rundir.summary.RunSummary`). The numerics it drives stay in
:mod:`heritage_bayes.inference` (priors, noise models, log-posterior, MAP, sampler);
the run directory's format in :mod:`heritage_bayes.run` and :mod:`heritage_bayes.rundir`.

- :mod:`~heritage_bayes.calibration.calibrate` — the orchestration of a run;
- :mod:`~heritage_bayes.calibration.selection` and
  :mod:`~heritage_bayes.calibration.selection_rule` — ``model: auto``'s screen of the
  model ladder and the one selection rule ``hbayes compare`` shares;
- :mod:`~heritage_bayes.calibration.ladder` — one rung of the model-order ladder (its
  log-posterior and MAP row);
- :mod:`~heritage_bayes.calibration.chains` — the sections' chains in one time budget:
  the sampler's call, a chain out of its share continued with the time later sections
  left, the draws the sections share;
- :mod:`~heritage_bayes.calibration.findings` — what the MAP shows before sampling;
- :mod:`~heritage_bayes.calibration.outputs` and
  :mod:`~heritage_bayes.calibration.runinfo` — the run's InferenceData and the summary
  built from the sampled sections;
- :mod:`~heritage_bayes.calibration.convergence` — whether the run converged, why not,
  and the exit status that says so.

Nothing is imported here: ``hbayes``'s quick paths import the one module they need.
"""
