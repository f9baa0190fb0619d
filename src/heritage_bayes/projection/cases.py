"""What the projection's engine carries: the posterior draws, one case (a weather's
inputs and its indicator plan), the arrays a case fills chunk by chunk, and what is kept
of it.

:mod:`heritage_bayes.projection.engine` builds and fills them;
:mod:`heritage_bayes.projection._modal` reads them.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np
import pandas as pd

from heritage_bayes.rc.control_kernels import N_COST

__all__ = ["Case", "CaseOut", "CaseResult", "Draws", "init_window"]

#: [steps] the initial-state window (``periods.init_window``) of a run that did not
#: record its own
DEFAULT_INIT_STEPS = 720


def init_window(run) -> int:
    """[steps] the initial-state window the run was calibrated with
    (:attr:`~heritage_bayes.rundir.summary.RunSummary.init_steps`;
    :data:`DEFAULT_INIT_STEPS` where the run did not record it)."""
    steps = run.run_summary.init_steps
    return DEFAULT_INIT_STEPS if steps is None else int(steps)


@dataclass
class Draws:
    """Posterior draws used by the projection: model and noise parameters per section."""

    index: np.ndarray  # (K,) positions in the flattened (chain, draw) posterior
    model: dict  # section -> (K, p) model parameter array [SI]
    noise: dict  # section -> (K, q) noise parameters in the noise model's order
    noise_models: dict  # section -> NoiseModel


@dataclass
class CaseResult:
    """What is kept of one case."""

    predictive: pd.DataFrame  # draws × indicators (with the noise draw)
    parametric: pd.DataFrame  # draws × indicators (noise-free: parameter uncertainty only)
    months: pd.DatetimeIndex
    Ti_month: np.ndarray  # (K, n_months) [°C]
    RHi_month: np.ndarray  # (K, n_months) [%]
    seconds: dict
    #: (K, years, len(annual_names)) per-complete-year values, predictive and noise-free
    annual_predictive: np.ndarray | None = None
    annual_parametric: np.ndarray | None = None
    annual_names: tuple = ()
    #: draws × running costs of an intervention
    #: (:data:`heritage_bayes.projection.interventions.COSTS`), empty for doing nothing
    costs: pd.DataFrame | None = None


@dataclass
class Case:
    """One weather (the baseline or a scenario) over ``N`` hours: each section's inputs,
    the months, the hour of the year and the indicator plan."""

    U: dict  # section -> (hours, inputs)
    Ut: dict  # section -> (inputs, hours)
    starts: np.ndarray
    months: pd.DatetimeIndex
    plan: object
    N: int
    hoy: np.ndarray  # (N,) hour of the year of each hour
    mode: int  # 1: the baseline (builds each draw's EN 15757 band), 2: judged by it, 0: none
    index: pd.DatetimeIndex | None = None  # time of each hour (an intervention's calendar)
    numpy: object = None  # the families without a compiled pass (fused.NumpyPass)

    def en_params(self) -> tuple[np.ndarray, int]:
        """(en, en_col) of :func:`heritage_bayes.projection._stream.chunk_kernel`."""
        from heritage_bayes.climate.risk.indicators import LAYOUT as L

        _, fpar, ipar, _, _ = self.plan.arrays
        cols = self.plan.columns
        en_col = cols.index("en15757_lower_offset") if "en15757_lower_offset" in cols else -1
        fam = "ashrae" if ipar[L.i("en15757.shared")] != 0 else "en15757"
        half, wrap = ipar[L.i(f"{fam}.half")], ipar[L.i(f"{fam}.wrap")]
        limc = fpar[L.f("mould.lim_c")] if ipar[L.i("mould")] else np.nan
        return np.array([self.mode, half, wrap, 0.0, 0.0, limc], float), en_col


@dataclass
class CaseOut:
    """The per-draw values of one case, filled chunk by chunk: indicators (noise-free and
    predictive), monthly means, per-year values and running costs."""

    par: np.ndarray
    pred: np.ndarray
    Tm: np.ndarray
    RHm: np.ndarray
    seconds: dict
    apar: np.ndarray
    apred: np.ndarray
    cost: np.ndarray  # (K, N_COST) running-cost sums of a measure's controllers
    #: column -> (K,) values of the families without a compiled pass (predictive, noise-free)
    xpred: dict = field(default_factory=dict)
    xpar: dict = field(default_factory=dict)

    def put_numpy(self, c: Case, sl, kept: np.ndarray, measured: bool, noise: bool) -> None:
        """The families without a compiled pass on the series the compiled pass kept
        (``kept``: noise-free ``T``, ``RH``, then predictive), draws ``sl``: their
        columns and per-year values (after the compiled ones). ``measured`` with
        ``noise``: no noise-free values (NaN, as the compiled pass)."""
        n0 = self.apar.shape[2] - len(c.numpy.annual_columns)
        for which, (T, RH), store, ann in (
            ("par", (kept[0], kept[1]), self.xpar, self.apar),
            ("pred", (kept[2], kept[3]) if noise else (kept[0], kept[1]), self.xpred, self.apred),
        ):  # fmt: skip
            skip = which == "par" and measured and noise
            vals = {k: np.full(len(T), np.nan) for k in c.numpy.columns} if skip else None
            for key, v in (vals or c.numpy.values(T, RH)).items():
                v = np.asarray(v)
                if key not in store:
                    store[key] = np.full(self.par.shape[0], np.nan, v.dtype if v.dtype.kind
                                         in "fO" else float)  # fmt: skip
                store[key][sl] = v
            ann[sl, :, n0:] = np.nan if skip else c.numpy.annual(T, RH)

    @classmethod
    def empty(cls, c: Case, K: int) -> CaseOut:
        from heritage_bayes.climate.risk.registry import years_of
        from heritage_bayes.projection._stream import ANNUAL

        nm = c.starts.size
        ny = years_of(c.N)
        na = len(ANNUAL) + (len(c.numpy.annual_columns) if c.numpy else 0)
        return cls(
            par=np.empty((K, c.plan.width)),
            pred=np.empty((K, c.plan.width)),
            Tm=np.empty((K, nm), np.float32),
            RHm=np.empty((K, nm), np.float32),
            seconds={"simulate": 0.0, "noise": 0.0, "risk": 0.0},
            apar=np.empty((K, ny, na)),
            apred=np.empty((K, ny, na)),
            cost=np.zeros((K, N_COST)),
        )

    def result(self, c: Case, measure=None, dt: float = 3600.0, years: float = 1.0) -> CaseResult:
        from heritage_bayes.climate.risk.registry import indicator_info
        from heritage_bayes.projection._stream import A_BAND, ANNUAL

        extra = c.numpy.columns if c.numpy else ()
        names = tuple(ANNUAL) + (c.numpy.annual_columns if c.numpy else ())
        # the isopleth's per-year column takes its own name; without the mould family
        # there is no isopleth, and no column
        lim = [n for n in c.plan.columns if n.startswith("hours_above_LIM")]
        keep = [j for j, n in enumerate(names) if n != "hours_above_LIM" or lim]
        names = tuple(lim[0] if names[j] == "hours_above_LIM" else names[j] for j in keep)
        frames = []
        for vals, ann, xs in (
            (self.pred, self.apred, self.xpred),
            (self.par, self.apar, self.xpar),
        ):
            df = c.plan.frame(vals)
            if c.mode and "en15757_lower_offset" in df.columns:
                pos = list(df.columns).index("en15757_upper_offset") + 1
                df.insert(pos, "en15757_outside_baseline", ann[:, :, A_BAND].mean(axis=1))
                df.attrs["units"]["en15757_outside_baseline"] = "% of hours"
            for key in extra:  # the families without a compiled pass, after the others
                df[key] = xs[key]
                df.attrs["units"][key] = indicator_info(key).unit
            frames.append(df)
        return CaseResult(
            predictive=frames[0],
            parametric=frames[1],
            months=c.months,
            Ti_month=self.Tm,
            RHi_month=self.RHm,
            seconds=self.seconds,
            annual_predictive=self.apred[..., keep],
            annual_parametric=self.apar[..., keep],
            annual_names=names,
            costs=pd.DataFrame(
                {} if measure is None else measure.costs(self.cost, dt, years),
                index=pd.RangeIndex(self.par.shape[0]),
            ),
        )
