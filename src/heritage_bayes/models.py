"""From a config section to its RC model: catalogue name (and options) or custom network.

Layer: config → **model**. Used by data preparation (a model states which inputs it
needs), by the orchestrator and by the run directory's loader; imports neither.
"""

from __future__ import annotations

import re
from collections.abc import Mapping

from heritage_bayes.config import CalibrationConfig
from heritage_bayes.errors import ConfigError
from heritage_bayes.rc.catalog import CATALOG
from heritage_bayes.rc.catalog import model as catalog_model
from heritage_bayes.rc.model import RCModel
from heritage_bayes.rc.network import Network

__all__ = ["SECTIONS", "build_model"]

SECTIONS = ("thermal", "hygric")
_SOLAR = {"thermal_1c", "thermal_2c", "thermal_4a"}


#: Names that become variable names in posterior.nc (NetCDF) and input columns.
_NAME = re.compile(r"^[A-Za-z][A-Za-z0-9_]*$")


def _check_names(m: RCModel, where: str) -> None:
    """Parameter, node and input names of a custom network: letters, digits and '_'."""
    for kind, names in (
        ("parameter", m.parameter_names),
        ("node", m.state_names),
        ("input", m.input_names),
    ):
        bad = [n for n in names if not _NAME.match(n)]
        if bad:
            raise ConfigError(
                f"{where}: {kind} name {bad[0]!r} is not allowed: use letters, digits and "
                "'_', starting with a letter (names become variables in posterior.nc)"
            )


def build_model(cfg: CalibrationConfig, section: str) -> RCModel:
    """The RC model of config section ``thermal`` or ``hygric``.

    Catalogue models get their solar surfaces from ``data.surfaces`` (none when
    ``data.irradiance: none``); a mapping under ``model:`` is a custom network
    (:meth:`heritage_bayes.rc.Network.from_dict`).
    """
    sec = getattr(cfg, section)
    where = f"{section}.model"
    try:
        if isinstance(sec.model, Mapping):
            m = Network.from_dict(sec.model, where=where).compile()
            _check_names(m, where)
        else:
            if sec.model not in CATALOG:
                raise ConfigError(
                    f"{where}: unknown model {sec.model!r}; available: {sorted(CATALOG)}"
                )
            m = catalog_model(sec.model, **_catalog_options(cfg, section, sec.model))
    except ConfigError:
        raise
    except ValueError as exc:
        msg = str(exc)
        raise ConfigError(msg if msg.startswith(f"{where}") else f"{where}: {msg}") from None
    if m.domain != section:
        raise ConfigError(f"{where}: a {m.domain} model cannot be used in the {section!r} section")
    return m


def _catalog_options(cfg: CalibrationConfig, section: str, name: str) -> dict:
    """Options of catalogue model ``name`` in a section: the configured ones, plus the
    solar surfaces from ``data.surfaces`` (none when ``data.irradiance: none``)."""
    options = dict(getattr(cfg, section).options)
    if name in _SOLAR and "surfaces" not in options:
        options["surfaces"] = tuple(cfg.data.surfaces) if cfg.data.irradiance != "none" else ()
    return options
