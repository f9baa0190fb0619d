"""Is the timber's heat of sorption what the attic's thermal model misses?

On the tuning attics (R2, R4, R6; the held-out ones are refused), init's config, the
residual of ``thermal_1c``'s MAP (measured - simulated Ti [K], ``attic_physics.py``'s
``wind``: the package) against proxies of the net vapour uptake of the attic's
materials, whose heat of sorption (:data:`HEAT_OF_SORPTION`, the latent heat plus a
differential heat) would warm the air while they take up vapour and cool it while they
give it back:

- ``RHe``: the outdoor relative humidity [%] (the signal "The attics' autumn" found);
- ``dP``: the measured outdoor minus attic vapour pressure :math:`P_e - P_i` [Pa]
  (FMI's and the logger's T/RH: a ventilated attic's air takes vapour in when
  :math:`P_e > P_i`, which its materials must store);
- ``Q``: the heat of the moisture the buffer of init's hygric model
  (``hygric_2c_sorption``) takes up, :math:`L\\,C_m\\,\\dot P_w / p_{sat}(T_{ref})` [W]
  (:mod:`heritage_bayes.rc.sorption`: the buffer's state :math:`P_w = \\varphi_w
  p_{sat}(T_{ref})`, its moisture :math:`C_m \\varphi_w`), at the hygric MAP with the
  buffer at the measured Ti; ``Qm``, ``Qe``: the same with the buffer at the simulated
  Ti of the thermal MAP with measured radiation, estimated (no measured indoor
  quantity in the validation).

Printed: the correlation of the daily mean (local days with at least 20 hours) and of
the hourly residual with each, calibration and validation, and of ``Qm``, ``Qe`` with
the rate of change of the simulated Ti they follow. ``--fit``: the MAP of
``thermal_1c`` with ``Qm`` (``Qe``) over its standard deviation in the calibration as a known
input into the air node, its gain ``kq`` [W] estimated (uniform 0-10 kW: the heat of
one standard deviation of uptake; the hygric model's own magnitude is no guide: the
scale of its capacities and conductances is not identified by Pi, only their
ratios); validation and calibration FIT of Ti [%], measured radiation and estimated,
and the log-likelihood's change with ``kq`` at :data:`PROFILE`, the rest at the MAP;
``--negative``: the same with the heat's sign turned (the physics' opposite).

Usage (from the repository root)::

    python benchmarks/attic_sorption.py [ROOM ...] [--fit]
"""

from __future__ import annotations

import argparse
import sys
import tempfile
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT / "benchmarks"))

import numpy as np  # noqa: E402
import pandas as pd  # noqa: E402

import attic_physics as ap  # noqa: E402
from _common import config_map  # noqa: E402
from real_rooms import run_init  # noqa: E402

TUNING = ["R2", "R4", "R6"]
LOCAL = pd.Timedelta(hours=2)  # FMI's and the loggers' clock, UTC+2
#: Heat released per kg of vapour adsorbed [J/kg]: the latent heat of vaporisation
#: (2.45 MJ/kg near 20 °C) plus a differential heat of sorption of wood at mid RH.
HEAT_OF_SORPTION = 2.6e6
#: The gain's steady warming [K] per standard deviation of the uptake (``kq`` over the
#: air node's conductances) at which the log-likelihood is printed, the rest at the MAP.
PROFILE = np.array([0.0, 0.02, 0.05, 0.1, 0.2])
KQ_PRIOR = {"kq": {"dist": "uniform", "lower": 0.0, "upper": 1e4}}  # [W]


def buffer_path(m, theta, U, dt, x0) -> tuple[np.ndarray, np.ndarray]:
    """The states ``Pw``, ``Pi`` [Pa] (N,) of a coupled hygric model from ``x0`` (2,)
    over the inputs ``U`` (N, m): the package's compiled step coefficients
    (:func:`heritage_bayes.rc.sorption.coupled_block`) with both states kept."""
    from heritage_bayes.rc import sorption as so

    kp = m.kernel_parameters(np.atleast_2d(theta))[0]
    cols = m.input_columns()
    U = np.ascontiguousarray(U, dtype=float)
    n = U.shape[0]
    mf, sb = np.empty((6, so.BLOCK)), np.empty((so.N_SERIES, so.BLOCK))
    pw, pi = np.empty(n), np.empty(n)
    xw, xi = float(x0[0]), float(x0[1])
    for k0 in range(0, n, so.BLOCK):
        b = min(so.BLOCK, n - k0)
        so.fill_series(U, cols, k0, b, sb)
        so.coupled_block(kp, sb, float(dt), bool(cols[1] >= 0), 0, b, mf)
        for j in range(b):
            pw[k0 + j], pi[k0 + j] = xw, xi
            xw, xi = (mf[0, j] * xw + mf[1, j] * xi + mf[4, j],
                      mf[2, j] * xw + mf[3, j] * xi + mf[5, j])  # fmt: skip
    return pw, pi


def uptake_heat(pw: np.ndarray, cm: float, dt: float) -> np.ndarray:
    """Heat [W] of the buffer's moisture uptake, :math:`L\\,C_m\\,\\dot P_w/p_{sat}(T_{ref})`,
    by central differences of its state ``pw`` [Pa] at steps ``dt`` [s] (one-sided at
    the ends; NaN where the state is)."""
    from heritage_bayes.rc.sorption import P_REF

    return HEAT_OF_SORPTION * cm / P_REF * np.gradient(pw, dt)


def hygric(room: str, data: Path, work: Path, ti_sim: dict[str, np.ndarray]):
    """init's hygric MAP (100 generations, 2 starts) and the frame's ``Pe - Pi`` [Pa]
    and the buffer's uptake heat [W] with the buffer at the measured Ti (``Q``) and at
    each simulated Ti of ``ti_sim`` (``Q<key>``), from the calibration's start."""
    from heritage_bayes.config import load_config

    cfg = load_config(run_init(room, data, work / room / "hyg")[0])
    opt = cfg.optimizer.model_copy(update={"maxiter": 100, "starts": 2})
    cfg = cfg.model_copy(update={"optimizer": opt, "thermal": None})
    prep, m, lp, mp = config_map(cfg, "hygric")
    if not hasattr(m, "sorption") or not m.sorption:
        raise SystemExit(f"{room}: init's hygric model {m!r} has no sorbing buffer")
    s = prep.calibration.start
    U = prep.model_inputs("hygric", m)
    names = list(m.input_names)
    x0 = lp.initial_states(mp.theta[None])[0]
    cm = float(mp.theta[list(lp.params.names).index("Cm")])
    pw, pi = buffer_path(m, mp.theta[: lp.n_model], U[s:], lp.dt, x0)
    ref = lp.simulate_frame(mp.theta[None], U, s)[0][0][s:, 0]
    assert np.nanmax(np.abs(pi - ref)) < 1e-6 * np.nanmax(np.abs(ref)), "recursion differs"
    obs = prep.observed("hygric", m)[:, 0]
    out = pd.DataFrame(index=prep.frame.index)
    out["dP"] = U[:, names.index("Pe")] - obs
    out["Q"] = np.nan
    out.iloc[s:, out.columns.get_loc("Q")] = uptake_heat(pw, cm, lp.dt)
    for key, ti in ti_sim.items():
        Us = U.copy()
        Us[:, names.index("Ti")] = ti
        pws = buffer_path(m, mp.theta[: lp.n_model], Us[s:], lp.dt, x0)[0]
        out[f"Q{key}"] = np.nan
        out.iloc[s:, out.columns.get_loc(f"Q{key}")] = uptake_heat(pws, cm, lp.dt)
    theta = dict(zip(lp.params.names, mp.theta, strict=True))
    print(f"{room}: {m.network.name} MAP " + " ".join(f"{k}={v:.3g}" for k, v in theta.items()))
    return out


def correlations(room, label, e, wx, rows) -> None:
    """Print the correlation of the residual ``e`` (daily mean, hourly) with each
    column of ``wx`` over ``rows`` (a boolean mask of the frame)."""
    df = wx[rows].assign(e=e[rows])
    df.index = df.index + LOCAL
    g = df.dropna(subset=["e"]).groupby(df.dropna(subset=["e"]).index.floor("D"))
    daily = g.mean()[g.size() >= 20]
    cols = [c for c in wx.columns]
    rd = [daily[["e", c]].dropna().corr().iloc[0, 1] for c in cols]
    rh = [df[["e", c]].dropna().corr().iloc[0, 1] for c in cols]
    cells = " | ".join(f"{a:+.2f} / {b:+.2f}" for a, b in zip(rd, rh, strict=True))
    print(f"| {room} | {label} | {len(daily)} | {cells} |", flush=True)


def with_heat(room, bare, q: pd.Series, data: Path, work: Path):
    """The thermal MAP of ``x_sorption_heat``: ``thermal_1c`` with the known input ``q``
    [-] (a copy of the weather with it as column ``Qs``, read as ``Ph``) into the air
    node through the estimated gain ``kq`` [W]; returns validation and calibration FIT
    of Ti [%], ``kq`` [W] and its steady warming [K] (over the air node's conductances
    ``Ge + Gf``), and the log-likelihood's change at :data:`PROFILE`."""
    from heritage_bayes.config.options import ModelOptions
    from heritage_bayes.config.priors import PriorSpec
    from heritage_bayes.inference.results import fit_metrics

    w = work / room / ("bare" if bare else "meas") / "q"
    (w / "wx").mkdir(parents=True, exist_ok=True)
    cfg = ap._config(room, "wind", "thermal_1c", bare, data, w)
    src = Path(cfg.data.weather.path)
    src = src if src.is_absolute() else w / src
    fmi = pd.read_csv(src)
    stamp = (q.index + LOCAL).tz_localize(None).strftime("%Y-%m-%d %H:%M:%S")
    qs = pd.Series(q.to_numpy(), index=stamp).fillna(0.0)
    fmi["Qs"] = fmi["t_UTC+2"].map(qs).fillna(0.0)
    fmi.to_csv(w / "wx" / "fmi_q.csv", index=False)
    wc = cfg.data.weather
    wc = wc.model_copy(
        update={"path": w / "wx" / "fmi_q.csv", "columns": {**wc.columns, "Ph": "Qs"}}
    )
    d = cfg.data.model_copy(update={"weather": wc})
    priors = {k: PriorSpec.model_validate(v) for k, v in KQ_PRIOR.items()}
    opts = ModelOptions.model_validate({})
    th = cfg.thermal.model_copy(
        update={"model": "x_sorption_heat", "options": opts, "priors": priors}
    )
    cfg = cfg.model_copy(update={"data": d, "thermal": th})
    prep, m, lp, mp, obs, y = ap.thermal_map(cfg, room, data)
    v, cal = prep.validation, prep.fitted_rows()
    names = list(lp.params.names)
    g = sum(mp.theta[names.index(k)] for k in ("Ge", "Gf") if k in names)  # [W/K]
    th = np.repeat(mp.theta[None], len(PROFILE), axis=0)
    th[:, names.index("kq")] = np.maximum(PROFILE * g, 1e-5)
    prof = lp.log_likelihood(th) - lp.log_likelihood(mp.theta[None])[0]
    kq = mp.theta[names.index("kq")], mp.theta[names.index("kq")] / g  # [W], [K]
    return fit_metrics(obs[v], y[v])["FIT"], fit_metrics(obs[cal], y[cal])["FIT"], kq, prof


def _register() -> None:
    """``x_sorption_heat``: ``thermal_1c`` with the input ``Ph`` [W] into the air node
    through an estimated gain ``kq`` [W per unit of the input]."""
    import dataclasses

    from heritage_bayes.rc.catalog import CATALOG, CatalogModel, register
    from heritage_bayes.rc.network import Source

    if "x_sorption_heat" in CATALOG:
        return
    base = CATALOG["thermal_1c"].factory

    def build(surfaces=None, ground=True, heating=False):
        net = base(surfaces=surfaces, ground=ground, heating=True)
        src = tuple(Source("Ph", "Ti", "kq") if s.input == "Ph" else s for s in net.sources)
        return dataclasses.replace(net, name="x_sorption_heat", sources=src)

    register("x_sorption_heat", CatalogModel(build, "attic_sorption.py's candidate",
                                             "thermal", True))  # fmt: skip


def main(argv=None) -> int:
    p = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    p.add_argument("rooms", nargs="*", default=TUNING)
    p.add_argument("--data", type=Path, default=ROOT.parent / "shared" / "data")
    p.add_argument("--fit", action="store_true", help="thermal_1c with the uptake heat")
    p.add_argument("--negative", action="store_true", help="--fit with the heat's sign turned")
    args = p.parse_args(argv)
    if set(args.rooms) - set(TUNING):
        p.error(f"tuning attics only: {TUNING} (the others are held out)")
    work = Path(tempfile.mkdtemp(prefix="attic_sorption_"))
    ap._register()
    _register()
    for room in args.rooms:
        sims, res = {}, {}
        for bare in (False, True):
            _, prep, _, _, _, obs, y = ap.simulated(room, "wind", bare, args.data, work)
            key = "e" if bare else "m"
            sims[key], res[key] = y, obs - y
        wx = hygric(room, args.data, work, sims)
        raw = ap._fmi(room, args.data)
        wx.insert(0, "RHe", raw["RHe"].reindex(wx.index).to_numpy())
        cal = np.zeros(len(wx), bool)
        cal[prep.fitted_rows()] = True
        val = np.zeros(len(wx), bool)
        val[prep.validation] = True
        print("| room | section | days | " + " | ".join(f"{c} daily / hourly" for c in wx) + " |")
        for label, rows in (("calibration", cal), ("validation", val)):
            for key, irr in (("m", "measured"), ("e", "estimated")):
                correlations(room, f"{label}, {irr}", res[key], wx, rows)
        for key in ("m", "e"):  # the uptake against the simulated Ti's rate of change
            dy = np.gradient(sims[key])
            r = pd.DataFrame({"q": wx[f"Q{key}"], "dy": dy})[cal | val].corr().iloc[0, 1]
            print(f"{room}: hourly correlation of Q{key} with dTi/dt of its Ti: {r:+.2f}")
        if args.fit:
            for bare, key in ((False, "m"), (True, "e")):
                q = wx[f"Q{key}"]
                sign = -1.0 if args.negative else 1.0
                fv, fc, kq, prof = with_heat(room, bare, sign * q / q[cal].std(), args.data, work)
                irr = "estimated" if bare else "measured"
                pr = ", ".join(f"{k:g} K: {d:+.1f}" for k, d in zip(PROFILE, prof, strict=True))
                print(f"| {room} | {irr} | {fv:.1f} (cal {fc:.1f}) | kq {kq[0]:.3g} W "
                      f"({kq[1]:.3g} K) | {pr} |", flush=True)  # fmt: skip
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
