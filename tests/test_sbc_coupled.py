"""The simulation-based calibration of the coupled hygric models, in small (the study:
``benchmarks/sbc_coupled.py``, its table in docs/science/sbc.md).

The generator (``benchmarks/coupled_rooms.py``) must share no code with the package and
agree with it where their physics is the same; the runner must rank every quantity, and
a deliberately wrong truth must fail the coverage check.
"""

from __future__ import annotations

import re
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

ROOT = Path(__file__).resolve().parents[1]
BENCH = ROOT / "benchmarks"
sys.path.insert(0, str(BENCH))

rooms = pytest.importorskip("coupled_rooms")
sbc = pytest.importorskip("sbc_coupled")


def test_generator_imports_nothing_of_the_package():
    code = (
        f"import sys; sys.path.insert(0, {str(BENCH)!r}); import coupled_rooms as r; "
        "[r.generate(t, 3, cal_days=30, max_spin_days=7) for t in r.ROOMS]; "
        "bad = [m for m in sys.modules if m.startswith('heritage_bayes')]; "
        "assert not bad, bad"
    )
    subprocess.run([sys.executable, "-c", code], check=True)
    src = (BENCH / "coupled_rooms.py").read_text()
    assert not re.search(r"^\s*(from|import)\s+(heritage_bayes|bench_sbc|sbc_)", src, re.M)


def test_gab_isotherm_inverse_and_slope():
    phi = np.linspace(0.05, 0.95, 19)
    um, c, k = 0.06, 7.0, 0.78
    u = rooms.gab(phi, um, c, k)
    assert np.all(np.diff(u) > 0) and 0.08 < rooms.gab(0.65, um, c, k) < 0.13  # softwood
    back = [rooms.gab_inverse(x, um, c, k) for x in u]
    np.testing.assert_allclose(back, phi, rtol=1e-10)
    h = 1e-6
    num = (rooms.gab(phi + h, um, c, k) - rooms.gab(phi - h, um, c, k)) / (2 * h)
    np.testing.assert_allclose(rooms.gab_slope(phi, um, c, k), num, rtol=1e-6)
    # nonlinear: the capacity at 85 % RH is well above that at 45 %
    assert rooms.gab_slope(0.85, um, c, k) > 1.5 * rooms.gab_slope(0.45, um, c, k)


def test_true_capacity_is_the_harmonic_mean_of_the_isotherm_slope():
    """The truth of the buffer's capacity is the harmonic mean of M du/dφ over the
    calibration (the constant capacity whose rate 1/C is the buffer's mean rate): below
    the arithmetic mean where the nonlinear isotherm's slope varies, equal to it with a
    linear isotherm."""
    room = rooms.generate("attic", 7, cal_days=20, max_spin_days=7)
    m = room["capacity_means"]
    assert room["truth"]["Cm"] == m["harmonic"] < m["arithmetic"]
    lo, hi = room["phi_w_range"]
    g = room["generator"]
    slopes = g["M"] * rooms.gab_slope(np.array([lo, hi]), g["um"], g["C"], g["K"])
    assert slopes[0] < m["harmonic"] < slopes[1]
    flat = rooms.generate("attic", 7, cal_days=20, max_spin_days=7, without=("isotherm",))
    assert flat["capacity_means"]["harmonic"] == flat["capacity_means"]["arithmetic"]


@pytest.mark.parametrize("room_type", rooms.ROOMS)
def test_generator_and_package_agree_where_their_physics_is_the_same(room_type):
    """With a linear isotherm, no moisture source and the true indoor temperature as
    input, the package's model with the room's parameters follows the independent
    Runge-Kutta room within a few Pa (what is left: sub-hourly weather and the two
    p_sat formulas); a buffer twice as large does not."""
    import heritage_bayes as hb

    room = rooms.generate(room_type, 11, cal_days=30, without=("isotherm", "source", "noise"))
    name, opts = sbc.MODELS[room_type]
    model = hb.model(name, **opts).with_slopes(("Pe",))
    U, _ = sbc.fit_inputs(room, model)
    if "Ti" in model.input_names:
        U[:, model.input_names.index("Ti")] = room["hourly"]["Ti_true"][: len(U)]
    err = sbc.misfit(model, room, U)
    assert abs(err["mean"]) < 6.0 and err["sd"] < 4.0, err
    cap = "Cm" if "Cm" in room["truth"] else "Cw"
    wrong = {**room, "truth": {**room["truth"], cap: 2 * room["truth"][cap]}}
    bad = sbc.misfit(model, wrong, U)
    assert bad["sd"] > 3 * max(err["sd"], 1.0), (bad, err)


def test_small_study_ranks_every_quantity_and_a_wrong_truth_fails():
    """Two attics and two cellars (30 days, short chains): every quantity ranked with
    finite statistics, the table printed; and the slow time constant's truth taken
    ten times too long is outside every 90 % interval, a coverage the table calls
    low beyond the binomial noise of four rooms."""
    tasks = [
        (room, rep, 5, 600, 30, (), {"tau1_h": 10.0}) for rep in range(2) for room in rooms.ROOMS
    ]
    results = [sbc.replicate(t) for t in tasks]
    for r in results:
        ranks = r["variants"][sbc.VARIANT]["ranks"]
        wanted = sbc.IDENTIFIABLE[r["room"]] + sbc.OTHERS[r["room"]]
        assert set(wanted) <= set(ranks), (r["room"], sorted(ranks))
        for q in wanted:
            assert np.isfinite(ranks[q]["median"]) and ranks[q]["sd"] > 0, q
        assert np.isfinite(r["misfit_Pa"]["sd"])
    for room in rooms.ROOMS:
        s = sbc.summary(results, room, "tau1_h")
        assert s["n"] == 2 and s["in90"] == 0, s
    pooled = [dict(r, room="attic") for r in results]  # four rooms of one kind
    s = sbc.summary(pooled, "attic", "tau1_h")
    assert s["c90"] == 0.0 and s["c90_ci"][1] < 0.85 and sbc.verdict(s) == "low"
    lines = sbc.table_lines(results, markdown=True)
    assert any("tau1_h" in line and "low" in line for line in lines)


def test_verdict_and_binomial_interval():
    lo, hi = sbc.coverage_interval(36, 40)
    assert lo < 0.9 < hi and 0.75 < lo < 0.8
    base = {"c50": 0.5, "z_mean": 0.0, "z_sd": 1.0, "rank_p": 0.5, "width": 0.1}
    assert sbc.verdict({**base, "c90": 0.9, "c90_ci": sbc.coverage_interval(36, 40)}) == "met"
    s = {**base, "c90": 32 / 40, "c90_ci": sbc.coverage_interval(32, 40)}
    assert sbc.verdict(s) == "low (within noise)"
    s = {**base, "c90": 20 / 40, "c90_ci": sbc.coverage_interval(20, 40)}
    assert sbc.verdict(s) == "low"
    s = {**base, "c90": 1.0, "c90_ci": sbc.coverage_interval(40, 40)}
    assert sbc.verdict(s) == "high (within noise)"  # 40 of 40 happens at 0.90 (p 0.015)
    s = {**base, "c90": 1.0, "c90_ci": sbc.coverage_interval(100, 100)}
    assert sbc.verdict(s) == "high"


def test_simulate_runs_a_coupled_model_through_its_recursion():
    """``hb.simulate`` of a model coupled to a temperature is its exact recursion
    (``forward``), not the constant modal form of its network at the reference
    temperature; the balance equations name the buffer's own vapour pressure."""
    import heritage_bayes as hb

    rng = np.random.default_rng(2)
    n = 96
    pe = 1000 + 50 * rng.standard_normal(n)
    ti = 15 + 8 * np.sin(2 * np.pi * np.arange(n) / 24)
    m = hb.model("hygric_2c_sorption")
    p = {"Cm": 50.0, "Ci": 0.02, "Gi": 1e-6, "Gfast": 5e-7}
    U = np.column_stack([pe, ti])
    x0 = np.array([900.0, 1000.0])
    y = hb.simulate(m, p, U, 3600.0, x0)
    P = np.array([[p[k] for k in m.parameter_names]])
    np.testing.assert_allclose(y, m.forward(P, U, 3600.0, x0=x0)[0][0], rtol=1e-12)
    flat = hb.simulate(m, p, np.column_stack([pe, np.full(n, 15.0)]), 3600.0, x0)
    assert np.abs(y - flat).max() > 10.0  # the temperature acts
    eq = hb.model("hygric_2c_fixed", sink="temperature").equations()[0]
    assert eq == "Cw·dPw/dt = Gw·(Pe − Pw) + Gi·(Pi − Pw)", eq


def test_fit_leaves_out_readings_at_the_sensor_ceiling():
    """The generator's attic air passes saturation (it has no condensation) and the
    logger clips at 100 %RH: the fit's Pi is missing exactly where the reading is lost
    or at the sensor's ceiling, as ``hbayes calibrate`` derives it; the same room
    without the logger's noise keeps its outage."""
    import heritage_bayes as hb
    from heritage_bayes.io.derive import RH_SENSOR_CEILING

    room = rooms.generate("attic", [sbc.SEED, 0, 9], cal_days=30)
    model = hb.model("hygric_2c_sorption").with_slopes(("Pe",))
    _, y = sbc.fit_inputs(room, model)
    rh = room["hourly"]["RHi"][: y.size]
    assert np.sum(rh >= RH_SENSOR_CEILING) > 24
    assert np.array_equal(np.isnan(y), ~(rh < RH_SENSOR_CEILING))
    quiet = rooms.generate("attic", [sbc.SEED, 0, 9], cal_days=30, without=("noise",))
    assert quiet["gap"] == room["gap"] and quiet["truth"] == room["truth"]


def test_wall_path_steps_the_models_own_recursion():
    """``coupled_path.wall_paths``: the buffer's state one step at a time starts at the
    start and ends where one call of the recursion over the record leaves it (exactly
    for the linear wall; for the GAB wall each call restarts the capacity's
    extrapolation, a second-order difference)."""
    import coupled_path
    import heritage_bayes as hb

    rng = np.random.default_rng(1)
    n = 200
    pe = 1100 + 200 * np.sin(np.arange(n) / 24 * 2 * np.pi) + rng.normal(0, 20, n)
    U = np.column_stack([pe, np.r_[np.diff(pe), 0.0], 10 + np.zeros(n)])
    p = dict(Cw=0.3, Ci=0.03, Gw=2e-8, Gi=8e-7, Gfast=4e-7, Gf=3e-8, phi_f=0.9, K_gab=0.9)
    for iso, tol in (("linear", 1e-9), ("gab", 0.5)):
        m = hb.model("hygric_2c_fixed", sink="temperature", isotherm=iso).with_slopes(["Pe"])
        P = np.array([[p[k] for k in m.parameter_names]])
        x0 = np.array([[700.0, 1000.0]])
        path = coupled_path.wall_paths(m, P, U, x0)
        x = x0.copy()
        m._recursion(P, m.kernel_parameters(P), U, 3600.0, x, np.empty((1, n)))
        assert path[0, 0] == 700.0 and np.ptp(path) > 50.0
        full = coupled_path.wall_paths(m, P, np.vstack([U, U[-1:]]), x0)[0, -1]
        assert abs(full - x[0, 0]) < tol, (iso, full, x[0, 0])


def test_source_seed_redraws_the_source_only():
    """``source_seed`` gives the same room under another realisation of its moisture
    source: every other draw (truths, weather, the logger's noise, the outage) kept."""
    kw = {"cal_days": 30, "max_spin_days": 7}
    own = rooms.generate("cellar", 5, **kw)
    other = rooms.generate("cellar", 5, source_seed=1, **kw)
    # (the capacity's truth, a mean along the wall's path, moves with the source)
    assert other["generator"] == own["generator"] and other["gap"] == own["gap"]
    assert other["noise_truth"] == own["noise_truth"]
    np.testing.assert_array_equal(other["hourly"]["Te"], own["hourly"]["Te"])
    d = other["hourly"]["Pi_true"] - own["hourly"]["Pi_true"]
    assert 1.0 < np.std(d[own["rows"]]) < 100.0  # [Pa]: the source differs
    quiet = [rooms.generate("cellar", 5, without=("source",), source_seed=s, **kw) for s in (1, 2)]
    np.testing.assert_array_equal(quiet[0]["hourly"]["RHi"], quiet[1]["hourly"]["RHi"])
