"""The calibration config: the top level of the schema (the building, the scale priors,
the outputs) and the one entry from YAML to typed settings, :func:`load_config`.
"""

from __future__ import annotations

import hashlib
import json
from pathlib import Path
from typing import Any

from pydantic import PrivateAttr, field_validator, model_validator

from heritage_bayes.config._base import MAX_SEED, _Strict, key
from heritage_bayes.config._messages import validate
from heritage_bayes.config.data import Data
from heritage_bayes.config.loader import read_yaml
from heritage_bayes.config.models import ModelSection
from heritage_bayes.config.periods import Periods
from heritage_bayes.config.sampler import OptimizerSettings, SamplerSettings
from heritage_bayes.config.sources import Site

__all__ = ["CalibrationConfig", "chain_tag", "config_hash", "load_config", "parse_config"]


class CalibrationConfig(_Strict):
    """What ``hbayes calibrate`` reads: one room, its data, periods, models, sampler and
    outputs (see ``configs/demo.yaml`` for a complete, commented example)."""

    name: str | None = key(
        None, unit=None, description="run name (default: the config file's stem)"
    )
    building: str = key("", unit=None, description="free text, shown in the report")
    room: str = key("", unit=None, description="free text, shown in the report")
    notes: str = key("", unit=None, description="free text, shown in the report")
    seed: int = key(
        1,
        unit=None,
        description="seed of the MAP search and the sampler: the same seed gives the same "
        "posterior",
        ge=0,
        le=MAX_SEED,
    )
    site: Site | None = key(
        None,
        unit=None,
        description="latitude, longitude, altitude: needed for solar input unless the "
        "weather file (epw, tmy3) carries them",
    )
    room_volume: float | None = key(
        None, unit="m³", description="air volume: log-normal prior on each model's Ci", gt=0
    )
    air_change_rate: float | None = key(
        None,
        unit="1/h",
        description="ventilation rate: log-normal prior on Gfast of both models",
        gt=0,
    )
    air_change_sigma: float = key(
        1.0, unit="-", description="sd of log(air change rate)", gt=0, le=5
    )
    floor_area: float | None = key(
        None,
        unit="m²",
        description="floor on the ground: log-normal prior on Gf, the thermal ground "
        "coupling and hygric_2c_fixed's vapour conductance to its fixed node",
        gt=0,
    )
    fixed_node_temperature: float | None = key(
        None,
        unit="°C",
        description="temperature of the ground, water or crypt behind hygric_2c_fixed's "
        "fixed vapour-pressure node: a log-normal prior on Pf, median 0.9 × its saturation "
        "vapour pressure, sd of log 0.25; default: the ground temperature (the thermal "
        "model's Tf, else data.ground_temperature's constant, else the annual mean outdoor "
        "temperature), its mean over the calibration period, recorded in the run's "
        "config.yaml",
        ge=-40,
        le=40,
    )
    envelope_area: float | None = key(
        None,
        unit="m²",
        description="exterior area of walls and roof: bounds on the envelope node's Gw "
        "and Cw (thermal) and on the moisture buffer's Gw and Cw (hygric)",
        gt=0,
    )
    interior_area: float | None = key(
        None,
        unit="m²",
        description="area of the interior constructions and contents in contact with the "
        "room air (floor, inner walls, vaults, furniture): a log-normal prior on the "
        "interior-mass conductance Gint of thermal_4a (and any model with an interior mass "
        "node), median 5 W/(m²K) × the area, sd of log 0.7",
        gt=0,
    )
    glazing_area: dict[str, float] | None = key(
        None,
        unit="m²",
        description="glazed area of the windows per solar surface (the names of "
        "data.surfaces), e.g. {S: 8, E: 4}: a log-normal prior on each listed surface's "
        "effective aperture fI, median 0.4 × the area (EN ISO 13790), sd of log 0.7; "
        "the other surfaces keep the wide default",
    )
    data: Data = key(unit=None, description="weather and logger files (or the demo)")
    periods: Periods = key(
        unit=None,
        description="calibration and validation periods, warm-up",
        default_factory=Periods,
    )
    thermal: ModelSection | None = key(
        None, unit=None, description="the thermal model (indoor temperature)"
    )
    hygric: ModelSection | None = key(
        None, unit=None, description="the hygric model (indoor vapour pressure)"
    )
    sampler: SamplerSettings = key(
        unit=None, description="emcee and its budget", default_factory=SamplerSettings
    )
    optimizer: OptimizerSettings = key(
        unit=None, description="the MAP search", default_factory=OptimizerSettings
    )
    report: bool = key(True, unit=None, description="write report.html")
    ladder: bool = key(
        True,
        unit=None,
        description="MAP fits of the neighbouring model orders for the "
        "accuracy-vs-identifiability comparison",
    )
    base_dir: str | None = key(
        None, unit=None, description="the config file's folder (set by load_config)"
    )
    _source_text: str | None = PrivateAttr(default=None)

    @property
    def source_text(self) -> str | None:
        """The YAML text the config was read from (set by :func:`load_config`)."""
        return self._source_text

    @field_validator("thermal", "hygric")
    @classmethod
    def _control_of_its_domain(cls, sec, info):
        bad = sec.options.misplaced_control(info.field_name) if sec is not None else None
        if bad:
            other = "hygric" if info.field_name == "thermal" else "thermal"
            raise ValueError(
                f"options.{bad}: a {bad} controls the air of a {other} model; give it "
                f"under {other}.options"
            )
        return sec

    @model_validator(mode="after")
    def _needs_models(self):
        if self.thermal is None and self.hygric is None:
            raise ValueError("give at least one of 'thermal' and 'hygric'")
        if self.data.demo is not None and self.site is not None:
            raise ValueError(
                "site: the demo uses the site of its weather file (Greensboro, NC; De Bilt "
                "for debilt_knmi); remove 'site'"
            )
        site_in_file = self.data.weather is not None and self.data.weather.format in (
            "epw",
            "tmy3",
        )
        if self.glazing_area is not None:
            bad = {k: v for k, v in self.glazing_area.items() if not v > 0}
            if bad:
                raise ValueError(
                    f"glazing_area: every area must be > 0 m² (got {bad}); leave a surface "
                    "without windows out to keep its wide default prior"
                )
            if self.data.irradiance == "none":
                raise ValueError(
                    "glazing_area: given, but data.irradiance is 'none' (no solar input); "
                    "remove 'glazing_area' or set data.irradiance"
                )
            roof = self.data.roof.plane_areas() if self.data.roof else {}
            both = sorted(set(self.glazing_area) & set(roof))
            if both:
                raise ValueError(
                    f"glazing_area: {both} are roof slopes whose aperture prior comes from "
                    "data.roof.area; give one of the two"
                )
            stray = sorted(set(self.glazing_area) - set(self.data.surfaces))
            if stray:
                raise ValueError(
                    f"glazing_area: surface(s) {stray} are not in data.surfaces "
                    f"{sorted(self.data.surfaces)}"
                )
        needs_sun = self.data.irradiance != "none" and self.data.demo is None
        if needs_sun and self.site is None and not site_in_file:
            raise ValueError(
                "site: required (latitude, longitude) to compute solar "
                "irradiance on the surfaces; or set data.irradiance: none"
            )
        return self

    def resolved(self) -> dict:
        """The config with defaults filled in (what ``config.yaml`` in a run holds)."""
        return self.model_dump(mode="json", exclude={"base_dir"})

    def portable(self) -> dict:
        """:meth:`resolved` with absolute data paths: re-runs from any folder."""
        d = self.resolved()
        data = d["data"]
        sources = [data.get("weather"), *(data.get("measurements") or [])]
        sources.append((data.get("ground_temperature") or {}).get("source"))
        demo = data.get("demo") or {}
        for holder, k in [(s, "path") for s in sources if s] + [(demo, "weather_path")]:
            p = holder.get(k)
            if p is not None:
                absolute = [
                    str(self.path(q).absolute()) for q in ([p] if isinstance(p, str) else p)
                ]
                holder[k] = absolute[0] if isinstance(p, str) else absolute
        return d

    def path(self, p: str) -> Path:
        """A data path resolved against the config file's folder."""
        q = Path(p).expanduser()
        return q if q.is_absolute() or self.base_dir is None else Path(self.base_dir) / q


def parse_config(
    raw: Any, *, source: str = "config", base_dir: str | None = None, name: str | None = None
) -> CalibrationConfig:
    """Validate a parsed YAML mapping into typed settings.

    Parameters
    ----------
    raw : mapping
        The YAML content (:func:`~heritage_bayes.config.loader.read_yaml`).
    source : str
        The file, for messages.
    base_dir : str, optional
        The folder relative data paths start from.
    name : str, optional
        The run name when the config gives none.

    Raises
    ------
    ConfigError
        One line per wrong key, each naming its key path, what was expected and what was
        found (an unknown key with the nearest known one); or the open questions ``hbayes
        init`` left (values starting with ``??``, a ``questions:`` list), each named.
    """
    from heritage_bayes.questions import check_answered

    check_answered(raw, source)  # `hbayes init`'s '??' values: named before the schema
    cfg = validate(CalibrationConfig, raw, source)
    cfg.base_dir = base_dir
    if cfg.name is None:
        cfg.name = name or "run"
    return cfg


def load_config(path) -> CalibrationConfig:
    """Read and validate a YAML config file (see :func:`read_yaml` for the limits).

    Raises
    ------
    ConfigError
        Missing file, invalid YAML (with line and column), or invalid content (with
        key paths).
    """
    p = Path(path)
    raw, text = read_yaml(p)
    cfg = parse_config(raw, source=str(p), base_dir=str(p.parent.resolve()), name=p.stem)
    cfg._source_text = text
    return cfg


def chain_tag(cfg: CalibrationConfig) -> str:
    """Hash of what determines the Markov chains (data, models, priors, seed, walkers,
    moves, optimiser), leaving out run-length settings (``max_steps``, ``check_every``,
    ``tau_factor``, ...) and outputs, so that ``--resume`` may extend a run."""
    d = cfg.resolved()
    keep = {k: d["sampler"][k] for k in ("walkers", "moves", "init_ball")}
    if d["sampler"].get("coordinates", "auto") != "auto":  # (tags of earlier runs kept)
        keep["coordinates"] = d["sampler"]["coordinates"]
    if d["sampler"].get("start", "ball") != "ball":
        keep["start"] = d["sampler"]["start"]
    if d["sampler"].get("block_weight") is not None:
        keep["block_weight"] = d["sampler"]["block_weight"]
    d = {**d, "sampler": keep}
    # keys added later enter the tag only when set (tags of earlier runs kept)
    if d.get("interior_area") is None:
        d.pop("interior_area", None)
    if (d.get("optimizer") or {}).get("restarts") is None and "optimizer" in d:
        d["optimizer"] = {k: v for k, v in d["optimizer"].items() if k != "restarts"}
    for k in ("report", "ladder", "name", "building", "room", "notes"):
        d.pop(k, None)
    blob = json.dumps(d, sort_keys=True, default=str).encode()
    return hashlib.sha256(blob).hexdigest()[:16]


def config_hash(cfg: CalibrationConfig) -> str:
    """SHA-256 (first 16 hex digits) of the resolved config."""
    blob = json.dumps(cfg.resolved(), sort_keys=True, default=str).encode()
    return hashlib.sha256(blob).hexdigest()[:16]
