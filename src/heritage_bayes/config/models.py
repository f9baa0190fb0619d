"""Settings of one calibrated model (``thermal:``, ``hygric:``): the catalogue model and
its options, the noise model, the initial state and the priors
(:class:`~heritage_bayes.config.priors.PriorSpec`, typed here).

The options are typed here (:mod:`heritage_bayes.config.options`); the model names,
which catalogue model takes which option, and the prior keys are checked where the
catalogue is known (:func:`heritage_bayes.models.build_model`,
:func:`heritage_bayes.inference.parameters.parameters_for`), before any data are read.
"""

from __future__ import annotations

import math
from typing import Annotated, Any, Literal

import pandas as pd
from pydantic import PlainSerializer, PlainValidator, WithJsonSchema, model_validator

from heritage_bayes.config._base import DURATION_UNIT, Choices, _duration, _Strict, key
from heritage_bayes.config.options import ModelOptions
from heritage_bayes.config.priors import PriorSpec
from heritage_bayes.convert import format_timedelta
from heritage_bayes.names import DEFAULT_NOISE, NOISE_MODELS

__all__ = [
    "DEFAULT_LIKELIHOOD_TEMPERATURE",
    "FILTERED_SINK_LIKELIHOOD_TEMPERATURE",
    "FILTERED_SINK_MODELS",
    "FILTERED_SINK_NOISE",
    "SINK_LIKELIHOOD_TEMPERATURE",
    "SORPTION_LIKELIHOOD_TEMPERATURE",
    "TEMPERED_MAX_NODES",
    "DurationOrNone",
    "ModelSection",
]

#: ``likelihood_temperature`` where a section does not set it, by model domain:
#: measured by simulation-based calibration on rooms the package did not generate
#: (docs/science/sbc.md, "A tempered likelihood"); 1 for a domain not listed, and for
#: networks of more than :data:`TEMPERED_MAX_NODES` capacity nodes.
DEFAULT_LIKELIHOOD_TEMPERATURE = {"thermal": 2.0, "hygric": 1.0}
#: The default temperature applies to networks of at most this many capacity nodes
#: (1c, 2c: where it was measured). Richer ones (thermal_4a) keep 1: the directions
#: their data leave to the priors widen with it and the chain slows (measured:
#: docs/science/sbc.md, "A tempered likelihood").
TEMPERED_MAX_NODES = 2
#: ``likelihood_temperature`` of a hygric model whose buffer sorbs at the materials'
#: temperature (``hygric_2c_sorption``) where the section does not set it: its slow
#: quantities sit about one posterior sd from the truth on attics the package did not
#: generate (the isotherm's curvature, the hourly weather), which the innovations do
#: not show (docs/science/sbc.md, the coupled hygric models).
SORPTION_LIKELIHOOD_TEMPERATURE = 2.0
#: ``likelihood_temperature`` of a hygric model with a vapour sink at a temperature
#: (``sink: temperature``, a cellar's or a crawlspace's ground) whose buffer does not
#: sorb at the materials' temperature, where the section does not set it: an
#: unmodelled moisture source at the air node is stored in the buffer and released on
#: its slow time constant (days), an error the AR(1) model error counts as many
#: independent ones, so the slow quantities' intervals are too narrow by a factor that
#: varies from room to room (docs/science/sbc.md, the coupled hygric models).
SINK_LIKELIHOOD_TEMPERATURE = 3.0
#: The noise model of a section that does not choose one, for the catalogue models
#: whose linear buffer (``isotherm: linear``, the default) exchanges with a vapour sink
#: at a temperature (``sink: temperature``) and that no humidistat controls: a Kalman
#: filter over the coupled model's own per-step transitions, whose process noise at the
#: nodes carries an unmodelled moisture source stored in the buffer and returned over
#: days (:mod:`heritage_bayes.inference.coupled_kalman`). Its intervals on simulated
#: cellars meet the coverage target at :data:`FILTERED_SINK_LIKELIHOOD_TEMPERATURE`,
#: ``ar1_white``'s at 3 do not (docs/science/sbc.md, "The cellars' default"). The GAB
#: buffer and the controlled rooms, which the filter does not take, keep ``ar1_white``.
FILTERED_SINK_NOISE = "kalman"
#: The catalogue models :data:`FILTERED_SINK_NOISE` is the default of (with the sink).
FILTERED_SINK_MODELS = ("hygric_2c_fixed", "hygric_2c_sorption")
#: ``likelihood_temperature`` of a hygric model with a vapour sink at a temperature
#: under :data:`FILTERED_SINK_NOISE`, where the section does not set it: the filter
#: describes the source's return through the buffer, and what it leaves (the linear
#: buffer against a GAB one) asks a temperature of 2, not 3 (docs/science/sbc.md).
FILTERED_SINK_LIKELIHOOD_TEMPERATURE = 2.0


def _duration_or_none(v: Any) -> pd.Timedelta | str | None:
    if v is None:
        return None
    if isinstance(v, str) and v.strip().lower() == "none":
        return "none"
    return _duration(v, positive=True)


#: A positive duration with its unit, or ``'none'`` (no limit); null: the default.
DurationOrNone = Annotated[
    pd.Timedelta | Literal["none"] | None,
    PlainValidator(_duration_or_none),
    PlainSerializer(
        lambda v: v if v is None or v == "none" else format_timedelta(v), return_type=str | None
    ),
    WithJsonSchema({"type": "string", "format": "duration-with-unit or none"}),
]


def _seconds(v: pd.Timedelta | str) -> float:
    return math.inf if isinstance(v, str) else v.total_seconds()


class ModelSection(_Strict):
    """One calibrated model (thermal or hygric)."""

    model: str | dict[str, Any] = key(
        unit=None,
        description="a catalogue model (hbayes models lists them, e.g. thermal_2c, "
        "hygric_2c), 'auto' (the model ladder screened by MAP and validation FIT, the "
        "simplest within 2 FIT points of the best sampled) or an RC network given as a "
        "mapping",
    )
    options: ModelOptions = key(
        unit=None,
        description="the model's options: surfaces, ground, heating, sink, thermostat, "
        "humidistat, source (hbayes models)",
        default_factory=ModelOptions,
    )
    noise: Annotated[str, Choices(NOISE_MODELS, described=True)] = key(
        DEFAULT_NOISE,
        unit=None,
        description="noise model (default: kalman for hygric_2c_fixed and "
        "hygric_2c_sorption with sink: temperature, a linear isotherm, no humidistat and "
        "no prior on phi_<out> or sigma_meas_<out>, ar1_white otherwise)",
    )
    initial_state: Literal["estimate", "steady"] | dict[str, float] | None = key(
        None,
        unit="°C or Pa",
        description="'estimate' (integrated out exactly; default for linear models), "
        "'steady' (default for controlled rooms) or {node: value}",
    )
    initial_state_sd: float | None = key(
        None, unit="K or Pa", description="prior sd of the estimated initial state", gt=0
    )
    initial_state_horizon: DurationOrNone = key(
        None,
        unit=DURATION_UNIT,
        description="modes slower than this have their estimated start pulled to the "
        "steady state; 'none': no pull (default: the calibration record)",
    )
    time_constant_cap: DurationOrNone = key(
        None,
        unit=DURATION_UNIT,
        description="soft prior 1/(1 + (τ/cap)²) on every time constant; 'none': no cap "
        "(default: 365d for thermal models, none for hygric ones)",
    )
    likelihood_temperature: float | None = key(
        None,
        unit="-",
        description="divide the log-likelihood by this (a tempered likelihood: posterior "
        "sd about √T times wider); 1: none (default: 2 for thermal models of one or two "
        "capacity nodes, chosen by simulation-based calibration on rooms the package did "
        "not generate, and for hygric_2c_sorption; 3 for other hygric models with a vapour "
        "sink at a temperature (sink: temperature), 2 for those under noise: kalman; 1 for "
        "other hygric models and richer networks such as thermal_4a; docs: "
        "Simulation-based calibration)",
        ge=1,
        le=10,
    )
    priors: dict[str, PriorSpec] = key(
        unit="SI",
        description="per parameter name: a prior {dist, lower, upper, median or mean, sigma} "
        "or {fixed: value} (hbayes models NAME lists the names, units and default priors)",
        default_factory=dict,
    )
    room_volume: float | None = key(
        None, unit="m³", description="this model's air volume (default: the top-level one)", gt=0
    )

    @model_validator(mode="after")
    def _custom_network_takes_no_options(self):
        given = self.options.given() if isinstance(self.model, dict) else {}
        if given:
            raise ValueError(
                f"options.{next(iter(given))}: a custom network (a mapping under 'model') "
                "takes no options: its nodes, links, inputs and sources are the mapping "
                f"(got options {sorted(given)}); remove 'options' or name a catalogue model"
            )
        return self

    @model_validator(mode="after")
    def _default_noise(self):
        # priors on the AR(1) noise's own parameters (phi_<out>, sigma_meas_<out>) are
        # that noise model chosen: the filter has neither, and would refuse them
        ar1_priors = any(k.startswith(("phi_", "sigma_meas_")) for k in self.priors)
        if "noise" not in self.model_fields_set and self.filtered_sink and not ar1_priors:
            self.noise = FILTERED_SINK_NOISE
            # still a default, not the user's choice (a run's config.yaml, a full dump,
            # states it, and reading that back gives the same noise model)
            self.model_fields_set.discard("noise")
        return self

    @property
    def filtered_sink(self) -> bool:
        """Whether :data:`FILTERED_SINK_NOISE` is this section's default noise model: a
        catalogue model of :data:`FILTERED_SINK_MODELS` with ``sink: temperature``, a
        linear isotherm and no humidistat (``model: auto`` and networks given as a
        mapping keep :data:`~heritage_bayes.names.DEFAULT_NOISE`)."""
        o = self.options
        return (
            self.model in FILTERED_SINK_MODELS
            and o.sink == "temperature"
            and o.isotherm in (None, "linear")
            and o.humidistat is None
        )

    def cap_seconds(self, domain: str) -> float:
        """``time_constant_cap`` in seconds (``inf`` for none); the default by domain:
        a year for thermal models (no building node relaxes slower), none for hygric
        ones (deep moisture buffers can take years)."""
        if self.time_constant_cap is None:
            return 365 * 86400.0 if domain == "thermal" else math.inf
        return _seconds(self.time_constant_cap)

    def temperature(
        self, domain: str, n_nodes: int = 1, sorption: bool = False, sink: str = "none"
    ) -> float:
        """``likelihood_temperature``; the default by domain: 2 for thermal models of
        at most :data:`TEMPERED_MAX_NODES` capacity nodes (``thermal_2c``'s 90 %
        intervals on 50 rooms the package did not generate cover 0.88-0.92 with it,
        0.74-0.82 without), 1 for richer ones and for hygric models
        (``hygric_2c_fixed`` with a constant fixed node covers 0.86-0.90 untempered)
        except those whose buffer sorbs at a temperature (``sorption``:
        :data:`SORPTION_LIKELIHOOD_TEMPERATURE`) and, otherwise, those with a vapour
        sink at a temperature (``sink == "temperature"``:
        :data:`SINK_LIKELIHOOD_TEMPERATURE`, or
        :data:`FILTERED_SINK_LIKELIHOOD_TEMPERATURE` under
        :data:`FILTERED_SINK_NOISE`). ``n_nodes``: the model's capacity nodes
        (``RCModel.n_states``)."""
        if self.likelihood_temperature is None:
            if n_nodes > TEMPERED_MAX_NODES:
                return 1.0
            if domain == "hygric" and sink == "temperature" and self.noise == FILTERED_SINK_NOISE:
                return FILTERED_SINK_LIKELIHOOD_TEMPERATURE
            if sorption:
                return SORPTION_LIKELIHOOD_TEMPERATURE
            if domain == "hygric" and sink == "temperature":
                return SINK_LIKELIHOOD_TEMPERATURE
            return DEFAULT_LIKELIHOOD_TEMPERATURE.get(domain, 1.0)
        return float(self.likelihood_temperature)

    @property
    def horizon_seconds(self) -> float | None:
        """``initial_state_horizon`` in seconds: None for the calibration record's
        length, ``inf`` for ``none`` (no slow-mode shrinkage)."""
        h = self.initial_state_horizon
        return None if h is None else _seconds(h)
