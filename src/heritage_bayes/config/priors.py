"""Priors of one calibrated model (``thermal.priors``, ``hygric.priors``): per parameter
a prior of a registered family or a fixed value, typed and checked here, on its own.

Which names exist, a fixed value's physical range (by the parameter's kind) and the keys
a spec leaves to the parameter's default prior are checked where the model is known
(:func:`heritage_bayes.inference.parameters.parameters_for`), before any data are read.
"""

from __future__ import annotations

import math
from collections.abc import Mapping
from typing import Annotated, Any

from pydantic import BeforeValidator, model_serializer, model_validator

from heritage_bayes.config._base import Choices, _Strict, key
from heritage_bayes.errors import ConfigError
from heritage_bayes.names import PRIOR_DISTRIBUTIONS

__all__ = ["PriorSpec", "prior_specs"]


def _number(v: Any) -> Any:
    """A number as written (an integer stays one: the config written back is the same
    text); numeric text such as YAML 1.1's ``1e4`` (read as a string) becomes a float."""
    if isinstance(v, bool):
        raise ValueError(f"expected a number (got {v!r})")
    if isinstance(v, str):
        try:
            v = float(v)
        except ValueError:
            raise ValueError(f"expected a number (got {v!r})") from None
    if isinstance(v, float) and not math.isfinite(v):
        raise ValueError(f"expected a finite number (got {v})")
    return v


class _FamilyOrNone(Choices):
    """A prior family's name, or None (the parameter's default family)."""

    def _check(self, value: Any) -> str | None:
        return None if value is None else super()._check(value)


#: A finite number in the parameter's unit.
Number = Annotated[int | float, BeforeValidator(_number)]


class PriorSpec(_Strict):
    """A parameter's prior, e.g. ``Gw: {dist: lognormal, median: 1.4e-8, sigma: 1}``, or
    its fixed value, ``Gf: {fixed: 0}``, in the parameter's units (``hbayes models
    NAME`` lists the names, units and default priors). Keys left out keep the default
    prior's: its family, and its bounds when the family is the same."""

    dist: Annotated[str | None, _FamilyOrNone(PRIOR_DISTRIBUTIONS)] = key(
        None,
        unit=None,
        description="the family: "
        + "; ".join(f"{k}, {v.description}" for k, v in PRIOR_DISTRIBUTIONS.items())
        + " (default: the parameter's default prior's)",
    )
    lower: Number | None = key(
        None,
        unit="SI",
        description="lower bound, in the parameter's unit (default: the default prior's, "
        "or the centre − span × sigma for a normal or lognormal)",
    )
    upper: Number | None = key(
        None,
        unit="SI",
        description="upper bound, in the parameter's unit (default: the default prior's, "
        "or the centre + span × sigma)",
    )
    median: Number | None = key(
        None, unit="SI", description="a lognormal's median, in the parameter's unit (> 0)"
    )
    mean: Number | None = key(
        None, unit="SI", description="a normal's mean, in the parameter's unit"
    )
    sigma: Number | None = key(
        None,
        unit="SI",
        description="a normal's sd (the parameter's unit) or a lognormal's sd of the natural "
        "log (-); > 0",
    )
    fixed: Number | None = key(
        None,
        unit="SI",
        description="hold the parameter at this value (not sampled); alone in its entry",
    )

    @model_validator(mode="before")
    @classmethod
    def _mapping(cls, v: Any) -> Any:
        if not isinstance(v, Mapping | PriorSpec):
            raise ValueError(
                "expected a mapping such as {dist: loguniform, lower: 1, upper: 100} or "
                f"{{fixed: 50}} (got {v!r})"
            )
        return v

    @model_validator(mode="after")
    def _check(self) -> PriorSpec:
        given = [k for k in type(self).model_fields if getattr(self, k) is not None]
        if self.fixed is not None and len(given) > 1:
            others = sorted(set(given) - {"fixed"})
            raise ValueError(
                f"fixed: cannot be combined with {others} (a fixed value has no prior)"
            )
        lo, up = self.lower, self.upper
        if lo is not None and up is not None and not lo < up:
            raise ValueError(f"lower: must be < upper (got {lo:g} >= {up:g})")
        if self.sigma is not None and not self.sigma > 0:
            raise ValueError(f"sigma: must be > 0 (got {self.sigma:g})")
        if self.median is not None and not self.median > 0:
            raise ValueError(
                f"median: the median of a lognormal prior must be > 0 (got {self.median:g})"
            )
        if self.dist is not None:
            self._check_family(given)
        return self

    def _check_family(self, given: list[str]) -> None:
        """The keys fit the family ``dist`` names."""
        info = PRIOR_DISTRIBUTIONS[self.dist]
        takes = {info.centre, "sigma"} if info.centre else set()
        for k in ("median", "mean", "sigma"):
            if k in given and k not in takes:
                has = f"its centre is its {info.centre}" if info.centre else "it is flat"
                raise ValueError(f"{k}: a {self.dist} prior has no {k} ({has})")
        if info.centre and (getattr(self, info.centre) is None or self.sigma is None):
            raise ValueError(
                f"a {self.dist} prior needs {info.centre} and sigma "
                f"(got {info.centre}={getattr(self, info.centre)}, sigma={self.sigma})"
            )
        if info.log_scale and self.lower is not None and not self.lower > 0:
            raise ValueError(f"lower: a {self.dist} prior needs lower > 0 (got {self.lower:g})")

    @model_serializer(mode="plain")
    def _as_written(self) -> dict[str, Any]:
        """The keys given, in the schema's order (the form the config file holds)."""
        return {k: v for k in type(self).model_fields if (v := getattr(self, k)) is not None}


def prior_specs(priors: Mapping[str, Any], where: str = "priors") -> dict[str, PriorSpec]:
    """Parameter name -> :class:`PriorSpec` from plain mappings, as the config loader
    checks them (for calls of :func:`heritage_bayes.inference.parameters.parameters_for`
    from Python).

    Examples
    --------
    >>> prior_specs({"Gf": {"fixed": 0}, "Gw": {"dist": "loguniform", "upper": 1e3}})["Gf"]
    PriorSpec(dist=None, lower=None, upper=None, median=None, mean=None, sigma=None, fixed=0)

    Raises
    ------
    ConfigError
        One line per wrong key, naming its path below ``where`` (``priors.Gw.lower``).
    """
    from pydantic import TypeAdapter, ValidationError

    from heritage_bayes.config._messages import join_errors

    raw = dict(priors)
    try:
        return TypeAdapter(dict[str, PriorSpec]).validate_python(raw)
    except ValidationError as exc:
        lines = join_errors(exc.errors(), raw, PriorSpec)
        raise ConfigError("\n".join(f"{where}.{line}" for line in lines)) from None
