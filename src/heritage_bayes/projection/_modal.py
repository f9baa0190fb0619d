"""Modal arrays of the compiled projection pass (:mod:`heritage_bayes.projection._stream`).

The arrays one draw of a free-running model hands to the compiled pass (its modal
recursion as ``RCModel.forward`` sets it up), the pass's work arrays, and the noise-free
series of a measure's controllers stepped on the free-running network
(:func:`heritage_bayes.rc.control_kernels.coupled_draw`, the same arithmetic as the pass).
The noise of a chunk and the reference path of a controlled measure are here too.
Split from :mod:`heritage_bayes.projection.engine`, which calls them.
"""

from __future__ import annotations

from typing import TYPE_CHECKING

import numpy as np

from heritage_bayes.rc.control_kernels import N_COST

if TYPE_CHECKING:
    from heritage_bayes.projection.cases import Case, CaseOut, Draws

_HOURS_YEAR = 8760


def _modal_form(m, P: np.ndarray, dt: float, free: bool = False):
    """The modal form of a free-running model (None for a controlled one: it is
    simulated by its own ``forward``); ``free``: of the model's network whatever it is
    (a measure's controllers are stepped on it)."""
    from heritage_bayes.rc.discretize import modal_form
    from heritage_bayes.rc.model import RCModel

    if m.n_states > _MAX_MODES or (type(m).forward is not RCModel.forward and not free):
        return None
    return modal_form(m, P, dt)


def _modal_arrays(mf, u0: np.ndarray, source=None) -> tuple:
    """(ad, Bdz, edz, Cz of the first output, z0) as ``RCModel.forward`` sets them up;
    ``source``: (forcing, steady-state shift) of a constant source, added to ``edz`` and
    ``z0`` as ``ControlledModel.forward`` does."""
    with np.errstate(divide="ignore", invalid="ignore"):
        z0 = mf.steady_state_modal(u0)
    z0 = np.where(np.isfinite(z0), z0, 0.0)
    z0 = np.ascontiguousarray(np.broadcast_to(z0, mf.lam.shape))
    c = np.ascontiguousarray
    edz = mf.edz
    if source is not None:
        edz, z0 = edz + source[0], c(z0 + source[1])
    return c(mf.ad), c(mf.Bdz), c(edz), c(mf.Cz[:, 0, :]), z0


_MAX_MODES = 64
_NO_MODAL = (np.zeros((0, 1)), np.zeros((0, 1, 1)), np.zeros((0, 1)), np.zeros((0, 1)),
             np.zeros((0, 1)))  # fmt: skip


def _work(plan, slots: int, N: int) -> tuple:
    """Work arrays of the compiled pass: the plan's, four series and the modal state
    and forcing of each slot."""
    from heritage_bayes.climate.risk._fused import BLOCK

    return (
        *plan.workspace(slots),
        np.empty((slots, 4, N)),
        np.empty((slots, _MAX_MODES)),
        np.empty((slots, _MAX_MODES, BLOCK)),
    )


def _coupled_series(c: Case, modal: dict, ctrl: tuple, sig, rows, w: int, cost=None):
    """Noise-free ``Ti``, ``Pi`` (section -> (k, N)) of the chunk's draws ``rows``
    (positions in the chunk) with a measure's controllers
    (:func:`heritage_bayes.rc.control_kernels.coupled_draw`, the compiled pass's arithmetic)."""
    from heritage_bayes.rc.control_kernels import coupled_draw

    ctl, bdT, bdP, spin, src = ctrl
    mT = _modal_arrays(modal["thermal"], c.U["thermal"][: max(1, w)].mean(axis=0),
                       src.get("thermal"))  # fmt: skip
    mP = _modal_arrays(modal["hygric"], c.U["hygric"][: max(1, w)].mean(axis=0),
                       src.get("hygric"))  # fmt: skip
    Y = {"thermal": np.empty((len(rows), c.N)), "hygric": np.empty((len(rows), c.N))}
    for j, i in enumerate(rows):
        nT, nP = mT[0].shape[1], mP[0].shape[1]
        acc = np.zeros(N_COST) if cost is None else cost[i]
        coupled_draw(
            *(x[i] for x in mT), c.Ut["thermal"], *(x[i] for x in mP), c.Ut["hygric"],
            bdT[i], bdP[i], ctl[i], sig, spin, Y["thermal"][j], Y["hygric"][j], acc,
            np.empty(nT), np.empty(nP), np.empty(nT), np.empty(nP),
        )  # fmt: skip
    return Y


def _noise(draws: Draws, sl: slice, N: int, seed: int, i: int, models=None, dt=3600.0) -> dict:
    """The noise of chunk ``i`` for series of ``N`` hours, section by section.

    A state-space noise model (``noise: kalman``) carries its model error as process
    noise on the nodes: its free-run noise is that process noise propagated through each
    draw's own modes plus the measurement noise
    (:meth:`~heritage_bayes.inference.statespace.KalmanNoise.sample_statespace`, as the
    calibration's predictive bands), so ``models`` (section -> RC model) and the step
    ``dt`` [s] are needed for it; the residual noise models draw from their parameters
    alone."""
    from heritage_bayes.rc.discretize import modal_form

    rng = np.random.default_rng([seed, i])
    out = {}
    for s, nm in draws.noise_models.items():
        if nm.statespace:
            if models is None:
                raise ValueError(f"section {s!r}: a state-space noise model needs its RC model")
            with np.errstate(all="ignore"):
                mf = modal_form(models[s], draws.model[s][sl], dt)
            e = nm.sample_statespace(rng, mf, draws.noise[s][sl], N, 1)[..., 0]
        else:
            e = nm.sample(rng, draws.noise[s][sl], N, 1)[..., 0]
        out[s] = np.ascontiguousarray(e)
    return out


def _controlled(run, P, c: Case, o: CaseOut | None, rows, dt, w, measure) -> dict:
    """The reference path: noise-free ``Ti``, ``Pi`` (section -> (k, N)) of draws
    ``rows`` through :meth:`Measure.simulate`; its running costs stored as sums in ``o``
    (the compiled pass's :data:`~heritage_bayes.rc.control_kernels.N_COST` columns)."""
    u0 = {s: c.U[s][: max(1, w)].mean(axis=0) for s in run.models}
    Y, costs = measure.simulate(run, {s: P[s][rows] for s in run.models}, c.U, u0, dt,
                                index=c.index)  # fmt: skip
    if o is not None:
        o.cost[rows] = measure.cost_sums(costs, dt, c.N / _HOURS_YEAR)
    return Y


def case_inputs(run, inp) -> dict:
    """Section -> (hours, inputs) array of the run's models on one case's weather, the
    columns taken from another model's simulation
    (:func:`~heritage_bayes.projection.weather.coupled_columns`) NaN until
    :func:`coupled_pair` fills them draw by draw."""
    from heritage_bayes.projection.weather import coupled_columns

    out = {}
    for s, m in run.models.items():
        sim = set(coupled_columns(run, s)) - set(inp.columns)
        cols = [np.full(len(inp), np.nan) if c in sim else inp[c].to_numpy(dtype=float)
                for c in m.input_names]  # fmt: skip
        out[s] = np.ascontiguousarray(np.column_stack(cols))
    return out


def coupled_pair(run, P: dict, c, rows, dt: float, w: int) -> dict:
    """Noise-free ``Ti``, ``Pi`` (section -> (k, N)) of draws ``rows`` when the hygric
    model sorbs at the indoor temperature: the thermal model first (all draws at once),
    then the hygric model of each draw on its own simulated ``Ti``
    (:func:`hygric_on`), each from the steady state of the mean of its first ``w``
    rows (as the free-running pass). Empty when the hygric model takes no simulated
    column."""
    from heritage_bayes.projection.weather import coupled_columns

    if "hygric" not in run.models or not coupled_columns(run, "hygric"):
        return {}
    mT = run.models["thermal"]
    U = c.U["thermal"]
    T = mT.forward(P["thermal"][rows], U, dt, u_init=U[: max(1, w)].mean(axis=0))[0]
    T = np.ascontiguousarray(T[..., list(mT.output_names).index("Ti")])
    return {"thermal": T, "hygric": hygric_on(run, P["hygric"][rows], c.U["hygric"], T, dt, w)}


def hygric_on(run, P: np.ndarray, U: np.ndarray, T: np.ndarray, dt: float, w: int):
    """Noise-free ``Pi`` (k, N) [Pa] of the hygric draws ``P`` (k, p), draw ``j`` with
    its input ``Ti`` set to ``T[j]`` [°C] (a simulated indoor temperature), from the
    steady state of the mean of its first ``w`` rows."""
    m = run.models["hygric"]
    UH = np.array(U, dtype=float)
    ti = list(m.input_names).index("Ti")
    H = np.empty_like(T)
    for j in range(T.shape[0]):
        UH[:, ti] = T[j]
        u0 = UH[: max(1, w)].mean(axis=0)
        H[j] = m.forward(P[j : j + 1], UH, dt, u_init=u0)[0][0, :, 0]
    return H
