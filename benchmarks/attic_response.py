"""How fast the attic answers the outdoor air and the sun, and what bounds its validation.

Cheap checks on the tuning attics R2, R4, R6 (the held-out ones are refused), from the
``thermal_1c`` MAP of init's config with measured radiation (as ``attic_physics.py``:
100 generations, 2 starts, seed 1); printed as tables for
``docs/science/real_rooms.md`` ("The attic's response to the sun, checked"):

- **Which path is faster.** Three least-squares fits of the measured Ti's simulation
  (not the MAP's likelihood: the simulation error, which the FIT measures) on the
  prepared inputs (``Te``, the roof planes' columns ``I_roof_*``), each with an offset
  [K], over April-August and September-December 2011 (each season its own fit):
  ``1c``, one first-order response of time constant τ to ``Te`` plus the planes'
  sun times a gain each (``thermal_1c`` with ``Gf`` at its floor, as its MAPs have it);
  ``split``, ``Te`` through τ and the sun through its own τ_s (two parallel paths);
  ``cascade``, the sun through a store of τ_s before it joins ``Te`` in the air's τ
  (a roof deck that the sun heats and that passes its heat to the air). Their FIT
  over the season fitted and the time constants [h].
- **The validation's ceiling.** The same ``1c`` and ``cascade`` and a ``1c`` whose
  ``Te`` gain is free (a warm boundary: the house below, the ground) fitted on the
  validation period itself: the best FIT such a structure can give there, whatever
  the calibration.
- **Where the validation's error is.** The MAP's validation residual split into its
  daily means and the within-day rest: their shares of the squared error, and the FIT
  the MAP would have with either part removed.

Usage (from the repository root)::

    python benchmarks/attic_response.py [ROOM ...]
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
from scipy.optimize import least_squares  # noqa: E402
from scipy.signal import lfilter  # noqa: E402

TUNING = ["R2", "R4", "R6"]
#: structure -> starting point: log τ [ln h], gains of the two planes [K per kW/m²],
#: offset [K], then log τ_s or the Te gain
STARTS = {
    "1c": [0.4, 10.0, 5.0, 0.0],
    "split": [0.4, 10.0, 5.0, 0.0, 0.5],
    "cascade": [0.4, 10.0, 5.0, 0.0, 0.5],
    "1c_te_gain": [0.4, 10.0, 5.0, 0.0, 1.0],
}


def lag(x: np.ndarray, tau_hours: float) -> np.ndarray:
    """``x`` (hourly) through a first-order store of time constant ``tau_hours`` [h],
    unit steady gain, starting steady at ``x[0]``."""
    a = np.exp(-1.0 / tau_hours)
    return lfilter([1 - a], [1, -a], x, zi=[a * x[0]])[0]


def simulate(p, kind: str, te: np.ndarray, sun: np.ndarray) -> np.ndarray:
    """Ti [°C] of a structure (module docstring) at parameters ``p``."""
    tau, c = np.exp(p[0]), p[3]
    s = sun @ np.asarray(p[1:3]) / 1000.0
    if kind == "1c":
        return lag(te + s, tau) + c
    if kind == "1c_te_gain":
        return lag(p[4] * te + s, tau) + c
    if kind == "split":
        return lag(te, tau) + lag(s, np.exp(p[4])) + c
    return lag(te + lag(s, np.exp(p[4])), tau) + c  # cascade


def fit_pct(obs: np.ndarray, sim: np.ndarray) -> float:
    """FIT [%] of ``sim`` on the finite ``obs``."""
    m = np.isfinite(obs)
    o, s = obs[m], sim[m]
    return 100.0 * (1.0 - np.linalg.norm(o - s) / np.linalg.norm(o - o.mean()))


def best(kind, te, sun, obs, mask):
    """Least-squares parameters of a structure over ``mask`` and the FIT there."""
    res = least_squares(lambda p: (simulate(p, kind, te, sun) - obs)[mask], STARTS[kind])
    sim = simulate(res.x, kind, te, sun)
    return res.x, fit_pct(np.where(mask, obs, np.nan), sim)


def room_map(room: str, data: Path, work: Path):
    """Inputs, observed and MAP-simulated Ti, and the periods of a room's thermal_1c MAP."""
    import attic_physics as ap
    from _common import config_map

    w = work / room
    (w / "wx").mkdir(parents=True, exist_ok=True)
    cfg = ap._config(room, "wind", "thermal_1c", False, data, w)
    prep, m, lp, mp = config_map(cfg, "thermal")
    u = prep.model_inputs("thermal", m)
    y = lp.simulate_frame(mp.theta[None], u, prep.calibration.start)[0][0][:, 0]
    names = list(m.network.inputs)
    sun = np.column_stack([u[:, i] for i, n in enumerate(names) if n.startswith("I_")])
    obs = prep.observed("thermal", m)[:, 0]
    return prep.frame.index, u[:, names.index("Te")], sun, obs, y, prep.validation


def report(room: str, data: Path, work: Path) -> None:
    idx, te, sun, obs, y, val = room_map(room, data, work)
    month = idx.month
    seasons = {
        "Apr-Aug": (idx.year == 2011) & (month >= 4) & (month <= 8),
        "Sep-Dec": (idx.year == 2011) & (month >= 9),
    }
    for label, sel in seasons.items():
        for kind in ("1c", "split", "cascade"):
            p, f = best(kind, te, sun, obs, sel & np.isfinite(obs))
            taus = f"τ {np.exp(p[0]):.2f} h" + (f", τ_s {np.exp(p[4]):.2f} h" if len(p) > 4 else "")
            print(f"| {room} | {label} | {kind} | {f:.1f} | {taus} |")
    vmask = np.zeros(len(obs), bool)
    vmask[val] = True
    vmask &= np.isfinite(obs)
    ceil = {k: best(k, te, sun, obs, vmask) for k in ("1c", "cascade", "1c_te_gain")}
    e = pd.Series(obs[val] - y[val], idx[val]).dropna()
    o = pd.Series(obs[val], idx[val]).dropna()
    daily = e.groupby(e.index.floor("D")).transform("mean")
    rest, den = e - daily, ((o - o.mean()) ** 2).sum()
    share = (daily**2).sum() / (e**2).sum()
    print(
        f"| {room} | validation | MAP {fit_pct(obs[val], y[val]):.1f} | ceiling 1c "
        f"{ceil['1c'][1]:.1f}, cascade {ceil['cascade'][1]:.1f}, Te gain "
        f"{ceil['1c_te_gain'][1]:.1f} ({ceil['1c_te_gain'][0][4]:.2f}) | daily means "
        f"{100 * share:.0f} % of the squared error; FIT without them "
        f"{100 * (1 - np.sqrt((rest**2).sum() / den)):.1f}, without the within-day rest "
        f"{100 * (1 - np.sqrt((daily**2).sum() / den)):.1f} |",
        flush=True,
    )


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("rooms", nargs="*", default=TUNING)
    ap.add_argument("--data", type=Path, default=ROOT.parent / "shared" / "data")
    args = ap.parse_args(argv)
    if set(args.rooms) - set(TUNING):
        ap.error(f"tuning attics only: {TUNING} (the others are held out)")
    work = Path(tempfile.mkdtemp(prefix="attic_response_"))
    print("| room | season | structure | FIT [%] | time constants |")
    for room in args.rooms:
        report(room, args.data, work)
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
