"""Settings of the periods: calibration, validation, warm-up and initial-state window."""

from __future__ import annotations

from pydantic import model_validator

from heritage_bayes.config._base import (
    DURATION_UNIT,
    DateText,
    NonNegativeDuration,
    _Strict,
    check_dates,
    key,
    utc,
)
from heritage_bayes.convert import format_timedelta

__all__ = ["Period", "Periods"]


class Period(_Strict):
    """``[start, end)``; naive dates and times are UTC."""

    start: DateText = key(unit=None, description="first instant (2019-01-01; naive values are UTC)")
    end: DateText = key(unit=None, description="end instant, excluded")

    @model_validator(mode="after")
    def _order(self):
        check_dates(self.start, self.end)
        return self


class Periods(_Strict):
    """Calibration and validation periods, warm-up and initial-state window.

    Default (no periods): the common period of all data, its first 2/3 for calibration
    and the rest for validation. A period may span gaps in the data: an input gap longer
    than ``data.max_gap`` splits the calibration into segments, each with its own
    initial state, and nothing is simulated inside it.

    The validation lies before the calibration, after it, or inside it with calibration
    data on both sides (a record shorter than a year, whose seasons the calibration
    should all hold). Inside it, its hours are held out of the fit as a logger gap is:
    the model is simulated through them from the calibration's initial state, and its
    observations enter neither the likelihood nor the calibration's fit figures.

    ``warmup``: the first part of the calibration period simulated but excluded from the
    likelihood. Default: none when every model estimates its initial state
    (``initial_state: estimate``, the default of linear models), 14 days when one starts
    from the steady state (a controlled room, or ``initial_state: steady``).
    ``init_window``: the mean inputs over the first ``init_window`` give the steady state
    that is the initial state's prior mean (or the initial state itself with ``steady``);
    default 30 days.
    """

    calibration: Period | None = key(
        None,
        unit=None,
        description="{start, end} of the calibration period (default: the first 2/3 of the "
        "common period of all data)",
    )
    validation: Period | None = key(
        None,
        unit=None,
        description="{start, end} of the validation period (default: the rest): before "
        "or after the calibration period, or inside it (held out of the fit, the "
        "calibration on both sides)",
    )
    warmup: NonNegativeDuration | None = key(
        None,
        unit=DURATION_UNIT,
        description="start of the calibration period simulated but not fitted (default: "
        "none when initial states are estimated, 14d when a model starts steady)",
    )
    init_window: NonNegativeDuration = key(
        "30D",
        unit=DURATION_UNIT,
        description="the mean inputs over this first window give the steady state (the "
        "initial state's prior mean)",
        validate_default=True,
    )

    @model_validator(mode="after")
    def _check(self):
        if self.validation is not None and self.calibration is None:
            raise ValueError("calibration: required when 'validation' is given")
        if self.calibration is not None and self.validation is not None:
            cs, ce = utc(self.calibration.start), utc(self.calibration.end)
            vs, ve = utc(self.validation.start), utc(self.validation.end)
            if vs < ce and cs < ve:
                self._check_inside(cs, ce, vs, ve)
        if self.calibration is not None:
            length = utc(self.calibration.end) - utc(self.calibration.start)
            if self.warmup is not None and self.warmup >= length:
                raise ValueError(
                    f"warmup: {format_timedelta(self.warmup)} is not shorter than the "
                    f"calibration period ({self.calibration.start} to {self.calibration.end})"
                )
        return self

    def _check_inside(self, cs, ce, vs, ve) -> None:
        """A validation overlapping the calibration must lie inside it, with calibration
        data on both sides and the warm-up before it."""
        spans = (
            f"(calibration {self.calibration.start} to {self.calibration.end}, validation "
            f"{self.validation.start} to {self.validation.end})"
        )
        if not (cs < vs and ve < ce):
            edge = cs >= vs and ve >= ce
            raise ValueError(
                "validation: "
                + ("covers" if edge else "overlaps")
                + f" the calibration period {spans}; the validation lies before the "
                "calibration, after it, or inside it with calibration data on both sides"
                + ("" if edge else " (to validate at an end, let it start or end where the "
                   "calibration ends or starts)")
            )  # fmt: skip
        if self.warmup is not None and cs + self.warmup >= vs:
            raise ValueError(
                f"warmup: {format_timedelta(self.warmup)} reaches the validation inside "
                f"the calibration period {spans}; the warm-up must end before it"
            )
