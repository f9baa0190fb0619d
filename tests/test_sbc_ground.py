"""The simulation-based calibration of the ground at an estimated depth, in small (the
study: ``benchmarks/sbc_ground.py``, its table in docs/science/sbc.md).

The generator (``benchmarks/ground_rooms.py``) must share no code with the package and
agree with it where their physics is the same; the runner must rank every quantity, and
a deliberately wrong truth must fall outside its interval.
"""

from __future__ import annotations

import math
import re
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

ROOT = Path(__file__).resolve().parents[1]
BENCH = ROOT / "benchmarks"
sys.path.insert(0, str(BENCH))

rooms = pytest.importorskip("ground_rooms")
sbc = pytest.importorskip("sbc_ground")

QUIET = ("anomaly", "gain", "noise", "outage", "synoptic")


def test_generator_imports_nothing_of_the_package():
    code = (
        f"import sys; sys.path.insert(0, {str(BENCH)!r}); import ground_rooms as r; "
        "r.generate(3, cal_days=30); "
        "bad = [m for m in sys.modules if m.startswith('heritage_bayes')]; "
        "assert not bad, bad"
    )
    subprocess.run([sys.executable, "-c", code], check=True)
    src = (BENCH / "ground_rooms.py").read_text()
    assert not re.search(r"^\s*(from|import)\s+(heritage_bayes|bench_sbc|sbc_)", src, re.M)


def test_soil_column_damps_and_delays_a_surface_wave_as_conduction_does():
    """The finite-difference column of the surface's departures carries a 30-day wave
    to 0.4 m damped by exp(-z/D) and late by z/(D ω), D = sqrt(2α/ω) (Carslaw and
    Jaeger's periodic solution), within a few per cent."""
    days, period, alpha, z = 240, 30.0, 0.5e-6, 0.4
    t = np.arange(days * rooms.PER_DAY) / rooms.PER_DAY
    wave = np.sin(2 * math.pi * t / period)
    w = {"Te": 10.0 + wave, "season": np.full(t.size, 10.0), "day": t}
    w.update(T_m=10.0, A=0.0, t_min=0.0)
    got = rooms.soil_temperature(w, z, alpha) - 10.0
    omega = 2 * math.pi / (period * 86400.0)
    d = math.sqrt(2 * alpha / omega)
    want = math.exp(-z / d) * np.sin(2 * math.pi * t / period - z / d)
    late = t > 120  # the column's start has died out
    # the column takes daily means (a 1-day box filter) applied at the day's end
    lag = np.interp(t - 0.5, t, want)
    assert np.abs(got[late] - lag[late]).max() < 0.05 * math.exp(-z / d) + 0.01


def test_generator_and_package_agree_where_their_physics_is_the_same():
    """Without the soil's departures, the heat gain, the synoptic weather and the
    logger, the package's thermal_1c with the ground at the true equivalent depth (the
    cycle it fits to the station's year) follows the generator's room within 0.02 K on
    average; the ground at twice the depth (0.1 K colder in this room, whose ground
    takes 5 % of the balance) does not."""
    from heritage_bayes import simulate

    room = rooms.generate([sbc.SEED, 5], cal_days=30, without=QUIET)
    model = sbc.fit_model()
    U, y, te = sbc.fit_inputs(room, model)
    truth = {**room["truth"], "dTf": sbc.climate_offset(room, te)}
    assert abs(truth["dTf"]) < 0.1  # without the synoptic weather: the year's mean
    rows = room["rows"]
    x0 = np.array([room["hourly"]["Ti_true"][0]])

    def err(zf):
        sim = simulate(model, {**truth, "zf": zf}, U, 3600.0, x0)[:, 0]
        return (sim - room["hourly"]["Ti_true"][: sim.size])[rows]

    good, bad = err(truth["zf"]), err(2.0 * truth["zf"])
    # what is left: the weather within the hour, which the hourly readings do not see
    assert abs(good.mean()) < 0.02 and good.std() < 0.1, (good.mean(), good.std())
    assert abs(bad.mean()) > 0.08, bad.mean()


def test_weather_linear_between_readings_is_what_the_package_simulates():
    """With the weather linear between the station's readings and nothing rounded (the
    first-order hold's own assumption), the package's model at the truth follows the
    generator's room within a few thousandths of a kelvin: their steps, holds and
    reading instants agree."""
    from heritage_bayes import simulate

    parts = (*QUIET, "subhourly", "rounding")
    room = rooms.generate([sbc.SEED, 5], cal_days=30, without=parts)
    model = sbc.fit_model()
    U, _, te = sbc.fit_inputs(room, model)
    truth = {**room["truth"], "dTf": sbc.climate_offset(room, te)}
    sim = simulate(model, truth, U, 3600.0, np.array([room["hourly"]["Ti_true"][0]]))[:, 0]
    d = (sim - room["hourly"]["Ti_true"][: sim.size])[room["rows"]]
    assert abs(d.mean()) < 0.002 and d.std() < 0.005, (d.mean(), d.std())


def test_the_station_reads_the_weather_at_the_hour():
    """The least-squares time constant of a noise-free room (the generator's every
    weather part, no heat gain) is its truth within a minute; reading the 5-minute step
    that starts at the hour instead delays the weather by half a step, and the fit's
    time constant comes out longer by about that much."""
    model = sbc.fit_model()

    def tau_error_min(reading):
        room = rooms.generate([sbc.SEED, 6], cal_days=30, without=("gain",), reading=reading)
        f = sbc.pseudo_fit(room, model)
        return 60.0 * (f["tau_1_h"] - f["tau_1_h_true"])

    instant, step = tau_error_min("instant"), tau_error_min("step_start")
    assert abs(instant) < 1.0, instant
    assert 1.5 < step - instant < 4.0, (instant, step)


def test_the_offsets_truth_is_the_ground_the_fit_can_express():
    """The truth of ``dTf`` is the offset of the package's ground closest to the
    generator's soil over the calibration hours (``sbc.ground_truth``): the noise-free
    room's least-squares offset (its conductances, depth and offset fitted, no heat
    gain) is that truth within 0.1 K in two rooms of the study, while the generator's
    climate mean minus the fitted cycle's (the earlier truth) is more than 0.4 K off;
    where the soil follows the annual harmonic only, the two truths agree."""
    model = sbc.fit_model()
    for rep in (2, 10):
        room = rooms.generate([sbc.SEED, rep], cal_days=sbc.CAL_DAYS, without=("gain",))
        f = sbc.pseudo_fit(room, model)
        assert abs(f["dTf"] - f["dTf_true"]) < 0.1, (rep, f["dTf"], f["dTf_true"])
        assert abs(f["dTf"] - f["dTf_climate"]) > 0.4, (rep, f["dTf"], f["dTf_climate"])
    room = rooms.generate([sbc.SEED, 2], cal_days=sbc.CAL_DAYS, without=QUIET)
    U, _, te = sbc.fit_inputs(room, model)
    lsq = sbc.ground_truth(room, model, U)
    assert abs(lsq["dTf"] - sbc.climate_offset(room, te)) < 0.05, lsq
    assert abs(lsq["zf"] / room["truth"]["zf"] - 1.0) < 0.05, lsq


def test_small_study_ranks_every_quantity_and_a_wrong_truth_fails():
    """One room (30 days, a short chain): every quantity ranked with finite statistics,
    the table printed; the depth's truth taken 20 times too deep (and the time
    constant's ten times too long) outside its 90 % interval."""
    r = sbc.replicate((0, sbc.SEED, 300, 30, (), sbc.VARIANT, {"zf": 20.0, "tau_1_h": 10.0}))
    ranks = r["variants"][sbc.VARIANT]["ranks"]
    assert set(sbc.IDENTIFIABLE + sbc.OTHERS) <= set(ranks), sorted(ranks)
    for q in sbc.IDENTIFIABLE + sbc.OTHERS:
        assert np.isfinite(ranks[q]["median"]) and ranks[q]["sd"] > 0, q
    assert not ranks["zf"]["in90"] and not ranks["tau_1_h"]["in90"]
    assert r["truth"]["zf_lsq"] > 0 and r["truth"]["dTf_climate"] != r["truth"]["dTf"]
    assert math.isfinite(r["ground_error"]["tf_sd"])
    lines = sbc.table_lines([r], markdown=True) + sbc.room_lines([r])
    assert any(line.startswith("| thermal_1c") and "tau_1_h" in line for line in lines)
