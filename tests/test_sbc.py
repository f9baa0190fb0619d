"""A small seeded simulation-based calibration (the full study: benchmarks/bench_sbc.py).

Eight rooms shaped like real logs (AR(1) model error + sensor noise + rounding + a gap,
a start far from equilibrium, De Bilt weather), generated with scipy's matrix
exponential and calibrated with the package's defaults (``ar1_white``, initial state
integrated out, the thermal likelihood tempered by 2: the variant ``:T=2``, since the
benchmark fits untempered unless told) and the survey knowledge of the benchmark (room
volume, air change rate, floor area). For each identifiable quantity, the number of
truths outside the 90 % interval must not exceed the binomial 99.9 % quantile for 8
replicates at a 10 % miss rate: a calibrated posterior fails this test with probability
below 0.1 % per quantity; a posterior whose intervals cover only 50 % fails it with
probability ~ 64 %.
"""

from __future__ import annotations

import sys
from pathlib import Path

import numpy as np
import pytest
from scipy import stats

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT / "benchmarks"))

bench_sbc = pytest.importorskip("bench_sbc")

pytestmark = pytest.mark.skipif(
    not bench_sbc.KNMI.is_file(), reason="needs ../shared/data/knmi-debilt beside the checkout"
)

REPS = 8


def test_small_sbc_thermal_2c_intervals_cover_the_truth():
    from heritage_bayes.config.models import DEFAULT_LIKELIHOOD_TEMPERATURE

    variant = f"ar1_white:estimate:T={DEFAULT_LIKELIHOOD_TEMPERATURE['thermal']:g}"
    results = [
        bench_sbc.replicate(("thermal_2c", rep, [variant], 7, 4000, 28, {}, bench_sbc.FLOOR))
        for rep in range(REPS)
    ]
    limit = int(stats.binom.ppf(0.999, REPS, 0.10))
    for q in ("tau_1_h", "gain_Ti_Te", "gain_Ti_I_S"):
        ranks = [r["variants"][variant]["ranks"][q] for r in results]
        misses = sum(not x["in90"] for x in ranks)
        assert misses <= limit, f"{q}: {misses} of {REPS} truths outside the 90 % interval"
        # and the ranks are not all on one side of the posterior (a bias)
        below = sum(x["rank"] < 0.5 for x in ranks)
        assert stats.binomtest(below, REPS, 0.5).pvalue > 0.001, f"{q}: ranks one-sided"
    assert np.all([np.isfinite(r["truth"]["tau_1_h"]) for r in results])


def test_hygric_truths_of_the_fixed_node_are_drawn_from_the_fit_priors():
    """SBC is exact only where the truths come from the prior the fit uses: the fixed
    node's Pf and Gf of 200 rooms follow fixed_vapour_pressure_prior (at the record's
    mean temperature) and vapour_ground_prior (80 m²): mean of log(x / median) within 4
    standard errors of 0 (σ/√200), its sd within 4 standard errors (σ/√400) of σ."""
    import heritage_bayes as hb
    from heritage_bayes.inference.survey import (
        fixed_vapour_pressure_prior,
        vapour_ground_prior,
    )

    model = hb.model("hygric_2c_fixed")
    rng = np.random.default_rng(5)
    draws = [bench_sbc.truth(model, rng, bench_sbc.FLOOR) for _ in range(200)]
    for name, prior in (
        ("Pf", fixed_vapour_pressure_prior(bench_sbc.ground_temperature())),
        ("Gf", vapour_ground_prior(bench_sbc.FLOOR)),
    ):
        z = np.log([d[name] for d in draws]) - np.log(prior.mu)
        assert abs(z.mean()) < 4 * prior.sigma / np.sqrt(200), name
        assert abs(z.std() - prior.sigma) < 4 * prior.sigma / np.sqrt(400), name
    assert 10.0 < bench_sbc.ground_temperature() < 12.0  # De Bilt 2011-2020 [°C]
    # --flat-fixed-node: the study before these priors (Pf uniform on 900-1 400 Pa)
    flat = [bench_sbc.truth(model, rng, bench_sbc.FLOOR, True) for _ in range(20)]
    assert all(900.0 <= d["Pf"] <= 1400.0 and 2e-8 <= d["Gf"] <= 2e-7 for d in flat)


def test_thermal_truth_priors_are_the_distributions_the_truths_come_from():
    """``--truth-priors`` on thermal_2c: each drawn parameter's prior is the distribution
    its truths follow (log-uniform ranges, log-normal around the survey's medians); 300
    truths checked against each prior's support and, for the log-normal ones, mean and
    sd of log(x / median) within 4 standard errors."""
    import heritage_bayes as hb

    model = hb.model("thermal_2c", surfaces=("S",))
    priors = bench_sbc.truth_priors(model, bench_sbc.FLOOR)
    assert set(priors) == {"Gw", "Gi", "fI_S", "Gf", "Ci", "Gfast"}  # Cw: solved for τ1
    rng = np.random.default_rng(11)
    draws = [bench_sbc.truth(model, rng, bench_sbc.FLOOR) for _ in range(300)]
    for name, spec in priors.items():
        x = np.array([d[name] for d in draws])
        if spec["dist"] == "loguniform":
            assert spec["lower"] <= x.min() and x.max() <= spec["upper"], name
            # and they fill the range: a quarter of the log-range at each end is used
            span = np.log(spec["upper"] / spec["lower"])
            assert np.log(x.min() / spec["lower"]) < span / 4, name
            assert np.log(spec["upper"] / x.max()) < span / 4, name
        else:
            z = np.log(x / spec["median"])
            assert abs(z.mean()) < 4 * spec["sigma"] / np.sqrt(300), name
            assert abs(z.std() - spec["sigma"]) < 4 * spec["sigma"] / np.sqrt(600), name


def test_likelihood_ratio_at_the_truth_tells_the_truth_from_a_wrong_room():
    """``--lr``: 2Δ of the true parameters is of the size χ²_6 gives (below its 99.9 %
    quantile), and of a room whose solar aperture is taken twice the truth far above it
    (the same data: the diagnostic sees the difference)."""
    task = ("thermal_2c", 0, [], 7, 0, 28, {}, bench_sbc.FLOOR, (None, ()), bench_sbc.ENVELOPE)
    room = bench_sbc.room_data(task)
    res = room["result"]
    nt = res["noise_truth"]
    start = dict(res["truth_parameters"])
    start.update(
        sigma_Ti=nt["sd"], phi_Ti=nt["phi"], sigma_meas_Ti=float(np.hypot(nt["sensor"], 0.029))
    )
    out = bench_sbc.likelihood_at_truth(room, {"map": start}, bench_sbc.FLOOR, bench_sbc.ENVELOPE)
    assert out["df"] == 6
    assert -0.1 < out["lr"] < stats.chi2.ppf(0.999, 6)
    res["truth_parameters"] = {**res["truth_parameters"], "fI_S": 2 * start["fI_S"]}
    wrong = bench_sbc.likelihood_at_truth(room, {"map": start}, bench_sbc.FLOOR, bench_sbc.ENVELOPE)
    assert wrong["lr"] > 10 * stats.chi2.ppf(0.999, 6)


# ------------------------------------------- the independent generator (issue 31)
def test_independent_generator_machinery():
    """One thermal room of ``bench_sbc_independent`` (the full study: 50 replicates per
    model, its coverage table in the benchmark README): the generator's 10-minute
    weather is sampled at the hour for the fit, the fit's inputs are the package's
    (align, Erbs + Perez facade), every listed quantity is ranked, and the mean solar
    warming's truth uses the generator's own irradiance. The machinery, not the
    coverage (one replicate cannot say anything about coverage)."""
    bench = pytest.importorskip("bench_sbc_independent")
    gw = bench.generator_weather(3)
    fine, hourly = gw["fine"], gw["hourly"]
    # the station's hourly readings are the 10-minute series at the full hour
    np.testing.assert_array_equal(hourly["Te"].to_numpy()[:-1], fine["Te"][:: bench.SUB])
    frame = bench.fit_inputs(hourly)
    assert frame.index[0] == gw["t0"] and len(frame) == fine["Te"].size // bench.SUB
    # align: an instantaneous column's row k is the mean of the readings k and k+1
    te = hourly["Te"].to_numpy()
    np.testing.assert_allclose(frame["Te"].to_numpy(), 0.5 * (te[:-1] + te[1:]), atol=1e-9)
    # another sky model, not another sun: the hourly means agree within 25 %
    i_gen = fine["I_S"].reshape(-1, bench.SUB).mean(axis=1)
    ratio = frame["I_S"].sum() / i_gen.sum()
    assert 0.75 < ratio < 1.25 and abs(ratio - 1) > 1e-3
    # the fit holds the readings exactly, as hbayes calibrate does: slope columns from
    # align (the change of each reading over the hour), zeros for the hour-ending
    # irradiance means
    import heritage_bayes as hb

    m = hb.model("thermal_2c", surfaces=("S",))
    fit_model = m.with_slopes(m.network.inputs)
    frame = bench.fit_inputs(hourly, [fit_model])
    np.testing.assert_allclose(frame["Te_slope"].to_numpy(), np.diff(te), atol=1e-9)
    assert (frame["I_S_slope"] == 0).all() and frame.attrs["input_hold"] == "exact"
    r = bench.replicate(("thermal_2c", 0, ["ar1_white:estimate"], 11, 600, 28))
    assert r["input_hold"] == "exact"
    ranks = r["variants"]["ar1_white:estimate"]["ranks"]
    assert set(bench.QUANTITIES["thermal_2c"]) <= set(ranks)
    for x in ranks.values():
        assert 0.0 <= x["rank"] <= 1.0 and x["sd"] > 0
    t = r["truth"]
    assert t["solar_warming_K"] == pytest.approx(
        t["gain_Ti_I_S"] * r["irradiance_mean"]["generator"]
    )
    assert t["gain_Ti_Te"] + t["gain_Ti_Tf"] == pytest.approx(1.0)


def test_independent_table_merges_logs(tmp_path, capsys):
    """``--table`` over several logs (a pilot with two noise models, a study extending
    one of them): one record per (model, replicate) with the variants merged, a
    replicate present in both logs counted once, and a replicate whose ranks differ
    between logs (another seed or code) refused with the file named."""
    import json

    bench = pytest.importorskip("bench_sbc_independent")

    def rec(rep, variants, **extra):
        return {
            "model": "thermal_2c",
            "rep": rep,
            "truth": {"tau_1_h": 1.2},
            "variants": variants,
            "input_hold": "exact",
            **extra,
        }

    def var(rank):
        x = {"in50": rank > 0.25, "in90": True, "rank": rank, "median": 1.0, "sd": 0.5}
        return {"ranks": {"tau_1_h": x}, "converged": True, "steps": 100, "cpu": 1.0}

    pilot, study, bad = tmp_path / "pilot.jsonl", tmp_path / "study.jsonl", tmp_path / "b.jsonl"
    pilot.write_text(
        "".join(
            json.dumps(rec(r, {"ar1_white:estimate": var(0.1), "kalman:estimate": var(0.5)})) + "\n"
            for r in (0, 1)
        )
    )
    study.write_text(
        "".join(json.dumps(rec(r, {"kalman:estimate": var(0.5)})) + "\n" for r in (1, 2, 3))
    )
    merged = bench.read_logs([str(pilot), str(study)])
    assert [r["rep"] for r in merged] == [0, 1, 2, 3]
    assert [sorted(r["variants"]) for r in merged] == [
        ["ar1_white:estimate", "kalman:estimate"],
        ["ar1_white:estimate", "kalman:estimate"],
        ["kalman:estimate"],
        ["kalman:estimate"],
    ]
    assert bench.main(["--table", str(pilot), str(study)]) == 0
    out = capsys.readouterr().out
    assert "thermal_2c [kalman:estimate]: 4 replicates" in out
    assert "thermal_2c [ar1_white:estimate]: 2 replicates" in out
    # the markdown table: every truth inside at 90 %; at 50 % those of rank 0.5 (kalman)
    # and none of rank 0.1 (ar1_white); z = (1.0 - 1.2) / 0.5 = -0.4 for each
    md = bench.markdown_table(merged, "kalman:estimate")
    assert md[2] == "| thermal_2c (4, 4) | τ1 | 4 | 1.00 | 1.00 | — | 0.40 |"
    md = bench.markdown_table(merged, "ar1_white:estimate")
    assert md[2] == "| thermal_2c (2, 2) | τ1 | 2 | 1.00 | 0.00 | — | 0.40 |"
    bad.write_text(json.dumps(rec(1, {"kalman:estimate": var(0.9)})) + "\n")
    with pytest.raises(SystemExit, match=r"b\.jsonl: thermal_2c replicate 1"):
        bench.read_logs([str(pilot), str(bad)])
    # logs of fits that held every input at its interval mean (before the first-order
    # hold; no "input_hold" key) and hygric fits without the buffer's bounds are
    # tabulated apart, not mixed with the current fits
    old = tmp_path / "old.jsonl"
    r_old = rec(1, {"kalman:estimate": var(0.9)})
    del r_old["input_hold"]
    r_hyg = {**rec(1, {"kalman:estimate": var(0.9)}), "model": "hygric_2c_fixed"}
    old.write_text(json.dumps(r_old) + "\n" + json.dumps(r_hyg) + "\n")
    merged = {(r["model"], r["rep"]): r for r in bench.read_logs([str(pilot), str(old)])}
    assert sorted(merged["thermal_2c", 1]["variants"]) == [
        "ar1_white:estimate",
        "kalman:estimate",
        "kalman:estimate@interval_mean",
    ]
    # (and, from before the fixed node's physical priors, "@flat_pf")
    assert sorted(merged["hygric_2c_fixed", 1]["variants"]) == ["kalman:estimate@unbounded@flat_pf"]
    bounded = {**r_hyg, "rep": 2, "hygric_envelope": True}
    physical = {**bounded, "rep": 3, "fixed_node_prior": "physical"}
    old.write_text(json.dumps(bounded) + "\n" + json.dumps(physical) + "\n")
    merged = {(r["model"], r["rep"]): r for r in bench.read_logs([str(old)])}
    assert list(merged["hygric_2c_fixed", 2]["variants"]) == ["kalman:estimate@flat_pf"]
    assert list(merged["hygric_2c_fixed", 3]["variants"]) == ["kalman:estimate"]


def test_solar_lines_compare_the_gain_bias_with_the_sky_models_ratio():
    """Two rooms whose fitted gain is the truth times the generator/fit irradiance ratio
    (the data fixed the solar warming exactly): the gain's ratio equals the irradiance
    ratio (correlation 1), the warming's is 1."""
    bench = pytest.importorskip("bench_sbc_independent")

    def room(rep, ratio):
        warming = 0.9 * ratio  # [K]: the true gain 0.01 K/(W/m²) × 90 W/m² × ratio
        truth = {"gain_Ti_I_S": 0.01, "solar_warming_K": warming}
        x = {"gain_Ti_I_S": {"median": 0.01 * ratio}, "solar_warming_K": {"median": warming}}
        return {
            "model": "thermal_2c",
            "rep": rep,
            "truth": truth,
            "irradiance_mean": {"generator": 90.0 * ratio, "fit": 90.0},
            "variants": {"kalman:estimate": {"ranks": x}},
        }

    (line,) = bench.solar_lines([room(0, 0.9), room(1, 0.8)], "kalman:estimate")
    assert "(2 rooms)" in line and "median 0.850 (0.800-0.900)" in line
    assert "gain_Ti_I_S 0.850 (below 1 in 2)" in line
    assert "solar_warming_K 1.000 (below 1 in 0)" in line and "irradiance ratio) 1.00" in line
    assert bench.solar_lines([room(0, 0.9)], "kalman:estimate") == []


def test_bias_lines_separate_bias_from_width():
    """Three rooms with z = -1, -2, -3 for the Te gain (mean -2, sd 1, none above) and
    +1, +2, +3 for the solar warming: correlation -1 between the two; the irradiance
    ratio's correlation is printed only where the ratio varies."""
    bench = pytest.importorskip("bench_sbc_independent")

    def room(rep, z, irr):
        truth = {"gain_Ti_Te": 0.8, "solar_warming_K": 1.0}
        x = {
            "gain_Ti_Te": {"median": 0.8 - 0.01 * z, "sd": 0.01},
            "solar_warming_K": {"median": 1.0 + 0.1 * z, "sd": 0.1},
        }
        return {
            "model": "thermal_2c",
            "rep": rep,
            "truth": truth,
            "irradiance_mean": {"generator": 90.0 * irr, "fit": 90.0},
            "variants": {"ar1_white:estimate": {"ranks": x}},
        }

    rooms = [room(0, 1, 0.9), room(1, 2, 0.8), room(2, 3, 1.0)]
    mean_sd, corr = bench.bias_lines(rooms, "ar1_white:estimate")
    assert "gain_Ti_Te -2.00 / 1.00 (0/3)" in mean_sd
    assert "solar_warming_K +2.00 / 1.00 (3/3)" in mean_sd
    assert "gain_Ti_Te~solar_warming_K -1.00" in corr and "irradiance ratio" in corr
    same = [room(0, 1, 1.0), room(1, 2, 1.0), room(2, 3, 1.0)]
    assert "irradiance ratio" not in bench.bias_lines(same, "ar1_white:estimate")[1]


def test_paired_lines_difference_of_z_on_the_same_rooms():
    """Two logs of the same three rooms: z of the second is z of the first minus 1 in
    every room (correlation 1, difference +1 with sd 0); a room in one log only is
    left out."""
    bench = pytest.importorskip("bench_sbc_independent")

    def room(rep, z):
        x = {"tau_1_h": {"median": 400.0 + 10.0 * z, "sd": 10.0}}
        return {
            "model": "thermal_2c",
            "rep": rep,
            "truth": {"tau_1_h": 400.0},
            "variants": {"ar1_white:estimate": {"ranks": x}},
        }

    a = [room(0, 1.0), room(1, -0.5), room(2, 2.0), room(3, 9.0)]
    b = [room(0, 0.0), room(1, -1.5), room(2, 1.0)]
    (line,) = bench.paired_lines(a, b)
    assert "(3 rooms in both)" in line
    assert "tau_1_h corr +1.00, diff +1.00 / 0.00 / 1.00" in line


def test_facade_solar_input_is_what_calibrate_computes():
    """``--solar facade``: the same weather stretch (Te, Pe unchanged) with the south
    facade of ``hbayes calibrate`` as I_S, i.e. ``bench_sbc_independent.fit_inputs``'s
    I_S for the same hourly record (row k the mean over the hour from row k)."""
    bench = pytest.importorskip("bench_sbc_independent")
    ghi, fac = bench_sbc.weather(5), bench_sbc.weather(5, "facade")
    np.testing.assert_array_equal(ghi["Te"], fac["Te"])
    np.testing.assert_array_equal(ghi["Pe"], fac["Pe"])
    assert fac["I_S"].shape == ghi["I_S"].shape and np.all(fac["I_S"] >= 0)
    w = bench_sbc._knmi_cache()
    n = ghi["Te"].size
    start = int(np.random.default_rng(5).integers(0, len(w) - n))  # as weather draws it
    hourly = w.iloc[start : start + n + 1][["Te", "RHe", "ghi"]].interpolate(limit_direction="both")
    hourly = hourly.assign(Pe=0.0)
    hourly.attrs.update(averaged=("ghi",), interval="1h", source="station")
    np.testing.assert_allclose(bench.fit_inputs(hourly)["I_S"].to_numpy(), fac["I_S"])
    # the hour-ending ghi of row k + 1 is the hour the facade's row k averages
    night = ghi["I_S"][1:] == 0
    assert np.all(fac["I_S"][:-1][night] == 0)
    with pytest.raises(ValueError, match="solar"):
        bench_sbc.weather(5, "roof")


def test_zscore_table_and_noise_lines():
    """``--table``'s mean / sd of z and the noise posteriors against their truths."""

    def room(rep, z, phi_med, sig_med):
        v = {
            "ranks": {"tau_1_h": {"median": 400.0 + 10.0 * z, "sd": 10.0}},
            "posterior": {
                "phi_Ti": {"median": phi_med, "sd": 0.01},
                "sigma_Ti": {"median": sig_med, "sd": 0.01},
            },
            "corr_gain_Ti_I_S": {"phi_Ti": 0.5, "tau_1_h": -0.5 + rep},
        }
        return {
            "model": "thermal_2c",
            "rep": rep,
            "truth": {"tau_1_h": 400.0},
            "noise_truth": {"phi": 0.9, "sd": 0.2, "sensor": 0.1},
            "variants": {"ar1_white:estimate": v},
        }

    rs = [room(0, 1.0, 0.92, 0.3), room(1, -1.0, 0.94, 0.1)]
    (line,) = bench_sbc.zscore_table(rs, "ar1_white:estimate")
    assert "tau_1_h +0.00 / 1.41 (1/2)" in line
    noise, corr = bench_sbc.noise_lines(rs, "ar1_white:estimate")
    assert "sigma_Ti median / truth 1.000" in noise and "phi_Ti median - truth +0.030" in noise
    assert "phi_Ti +0.50 (+0.50..+0.50)" in corr and "tau_1_h +0.00 (-0.50..+0.50)" in corr


def test_error_lines_rank_a_gains_miss_with_each_parameters_error():
    """``--table``'s Spearman of the solar gain's z with each parameter's error: +1 for
    a parameter whose error follows the gain's z, -1 for one against it."""

    def room(rep, z):
        v = {
            "ranks": {"gain_Ti_I_S": {"median": 0.01 + 0.001 * z, "sd": 0.001}},
            "posterior": {
                "Gw": {"median": 100.0 + 10.0 * z, "sd": 10.0},
                "Cw": {"median": 4e8 - 1e7 * z**3, "sd": 1e7},
            },
        }
        return {
            "model": "thermal_2c",
            "rep": rep,
            "truth": {"gain_Ti_I_S": 0.01},
            "truth_parameters": {"Gw": 100.0, "Cw": 4e8},
            "variants": {"ar1_white:estimate": v},
        }

    rs = [room(k, z) for k, z in enumerate((-2.0, -0.5, 0.1, 0.7, 1.5, 3.0))]
    (line,) = bench_sbc.error_lines(rs, "ar1_white:estimate")
    assert "over 6 rooms: Gw +1.00, Cw -1.00" in line


def test_independent_generator_with_ghi_as_the_solar_input():
    """``bench_sbc_independent --without sky --solar ghi``: the fit's I_S is the hourly
    ghi aligned as an hour-ending mean (row k the hour ending at row k + 1), which the
    generator holds over each hour; Te and Pe are those of the facade rooms."""
    bench = pytest.importorskip("bench_sbc_independent")
    fac = bench.generator_weather(3, ("sky",))
    gw = bench.generator_weather(3, ("sky",), "ghi")
    np.testing.assert_array_equal(gw["fine"]["Te"], fac["fine"]["Te"])
    frame = bench.fit_inputs(gw["hourly"], solar="ghi")
    np.testing.assert_allclose(frame["I_S"].to_numpy(), gw["hourly"]["ghi"].to_numpy()[1:])
    np.testing.assert_allclose(gw["fine"]["I_S"], np.repeat(frame["I_S"].to_numpy(), bench.SUB))
    with pytest.raises(ValueError, match="sky"):
        bench.generator_weather(3, (), "ghi")
