"""The compiled projection pass (issue 12's performance target) against the numpy path.

:func:`heritage_bayes.projection.engine.simulate_cases` simulates free-running models
itself, forms RH with a vectorised saturation pressure, and reduces each draw's series
in one compiled pass. Reference: what the engine did before, chunk by chunk —
``model.forward``, the noise model's ``sample`` with the generator seeded ``(seed,
chunk)``, RH capped at saturation, :func:`~heritage_bayes.climate.risk.assess_batch`
and monthly means with ``np.add.reduceat``.

Tolerances: the simulated series agree with ``model.forward`` to 1e-11 relative
(the forcing is summed over the inputs in another order than the BLAS product: ~1e-16
per step, carried by modes with poles below 1); the RH differs by ≤ 2e-14 relative (the
saturation pressure). The indicators, computed on series that differ at that level,
agree to 1e-9 relative (the EN 15757 share to the hours tied at the band edges, see
``assert_close``), and the monthly means (float32) to 1 float32 ulp (6e-8).
"""

from __future__ import annotations

from types import SimpleNamespace

import numpy as np
import pandas as pd
import pytest

import heritage_bayes as hb
from heritage_bayes.climate import risk
from heritage_bayes.demo import TRUE_HYGRIC, TRUE_THERMAL, _inputs
from heritage_bayes.errors import InputError
from heritage_bayes.inference.likelihoods import get_noise_model
from heritage_bayes.projection import engine
from heritage_bayes.projection.engine import Draws, _monthly, _relative_humidity
from heritage_bayes.rundir.summary import RunSummary

SEED = 4
CHUNK = 3


def _summaries(summary: dict) -> dict:
    """A stub run's ``summary`` (the JSON) and ``run_summary`` (typed)."""
    return {"summary": summary, "run_summary": RunSummary.from_dict(summary)}


@pytest.fixture(scope="module")
def setup():
    models = {"thermal": hb.model("thermal_2c"), "hygric": hb.model("hygric_2c")}
    run = SimpleNamespace(models=models, **_summaries({"dt": 3600.0, "init_steps": 720}), path="t")
    _, inp, _, _, _ = _inputs("greensboro_tmy3")  # 8759 h: a TMY on the UTC grid
    # two complete years (17 520 h, the third copy cut: months cut mid-way)
    two = pd.concat([inp, inp, inp], ignore_index=True).iloc[:17_520]
    two.index = pd.date_range(inp.index[0], periods=len(two), freq="h")
    warm = two.copy()
    warm[["Te", "Tf"]] += 3.0
    return run, demo_draws(models, 7), [two, warm]


def demo_draws(models, K: int) -> Draws:
    """``K`` seeded draws around the demo's true parameters, AR(1) noise."""
    rng = np.random.default_rng(0)
    truth = {"thermal": TRUE_THERMAL, "hygric": TRUE_HYGRIC}
    model, noise, nms = {}, {}, {}
    for s, m in models.items():
        jit = {p: truth[s][p] * np.exp(rng.normal(0, 0.05, K)) for p in m.parameter_names}
        model[s], _ = m.param_array(jit)
        sig = (0.3, 30.0)[s == "hygric"]
        noise[s] = np.column_stack([sig * np.exp(rng.normal(0, 0.1, K)), np.full(K, 0.9)])
        nms[s] = get_noise_model("ar1")
    return Draws(index=np.arange(K), model=model, noise=noise, noise_models=nms)


def reference(run, draws, inputs, noise=True):
    """The numpy path, chunk by chunk (the engine before the compiled pass)."""
    K, N = draws.index.size, len(inputs)
    starts, _ = engine._month_starts(inputs.index)
    par, pred, tm, rm, series = [], [], [], [], []
    for i, s0 in enumerate(range(0, K, CHUNK)):
        sl = slice(s0, min(s0 + CHUNK, K))
        rng = np.random.default_rng([SEED, i])
        out = {}
        for s, m in run.models.items():
            U = inputs[list(m.input_names)].to_numpy(float)
            y = m.forward(draws.model[s][sl], U, 3600.0, u_init=U[:720].mean(axis=0))[0][..., 0]
            e = draws.noise_models[s].sample(rng, draws.noise[s][sl], N, 1)[..., 0]
            out[s] = (y, e if noise else 0.0 * y)
        Ts, Ps = out["thermal"][0], out["hygric"][0]
        par.append(risk.assess_batch(Ts, _relative_humidity(Ts, Ps)))
        T = Ts + out["thermal"][1]
        RH = _relative_humidity(T, Ps + out["hygric"][1])
        pred.append(risk.assess_batch(T, RH))
        tm.append(_monthly(T, starts))
        rm.append(_monthly(RH, starts))
        series.append((Ts, Ps))
    cat = lambda parts: pd.concat(parts, ignore_index=True)  # noqa: E731
    return cat(par), cat(pred), np.concatenate(tm), np.concatenate(rm), series


def assert_close(ref: pd.DataFrame, got: pd.DataFrame):
    """1e-9 relative; the EN 15757 share to 4 hours: the weather repeats one year, so
    past the start-up the noise-free climate is periodic and the band edges (order
    statistics) are tied by one hour per year; whether those hours lie outside is decided
    by the last bit of the series (two edges × two years)."""
    assert [c for c in got.columns if c != "en15757_outside_baseline"] == list(ref.columns)
    n = 17_520
    for c in ref.columns:
        if c == "en15757_outside":
            np.testing.assert_allclose(got[c], ref[c], rtol=0, atol=4 * 100 / n, err_msg=c)
        elif pd.api.types.is_float_dtype(ref[c]):
            np.testing.assert_allclose(got[c], ref[c], rtol=1e-9, atol=1e-12, err_msg=c)
        else:
            assert (got[c].astype(str) == ref[c].astype(str)).all(), c


def test_simulated_series_equal_model_forward(setup):
    run, draws, (two, _) = setup
    from heritage_bayes.projection._stream import _modal

    for s, m in run.models.items():
        U = np.ascontiguousarray(two[list(m.input_names)].to_numpy(float))
        u0 = U[:720].mean(axis=0)
        ref = m.forward(draws.model[s], U, 3600.0, u_init=u0)[0][..., 0]
        ad, B, e, C, z0 = engine._modal_arrays(engine._modal_form(m, draws.model[s], 3600.0), u0)
        y = np.empty(len(U))
        for k in range(ref.shape[0]):
            _modal(ad[k], B[k], e[k], C[k], z0[k], np.ascontiguousarray(U.T), y,
                   np.empty(64), np.empty((64, 512)))  # fmt: skip
            np.testing.assert_allclose(y, ref[k], rtol=1e-11, atol=1e-11 * np.abs(ref[k]).max())


def test_cases_equal_the_numpy_path(setup):
    run, draws, cases = setup
    got = engine.simulate_cases(run, draws, cases, seed=SEED, chunk=CHUNK)
    for inp, g in zip(cases, got, strict=True):
        par, pred, tm, rm, _ = reference(run, draws, inp)
        assert_close(par, g.parametric)
        assert_close(pred, g.predictive)
        np.testing.assert_allclose(g.Ti_month, tm, rtol=6e-8)
        np.testing.assert_allclose(g.RHi_month, rm, rtol=6e-8)
        units = dict(g.predictive.attrs["units"])
        assert units.pop("en15757_outside_baseline") == "% of hours"
        assert units == pred.attrs["units"]
        assert set(g.seconds) == {"simulate", "noise", "risk"}
    # paired: the same noise in every case of the same length; one case alone is the same
    # (alone, the warm case is its own baseline: the baseline-band share differs)
    one = engine.simulate_case(run, draws, cases[1], seed=SEED, chunk=CHUNK)
    col = "en15757_outside_baseline"
    pd.testing.assert_frame_equal(one.predictive.drop(columns=col),
                                  got[1].predictive.drop(columns=col))  # fmt: skip


def test_noise_free(setup):
    run, draws, (two, _) = setup
    got = engine.simulate_case(run, draws, two, seed=SEED, noise=False, chunk=CHUNK)
    par, _, tm, rm, _ = reference(run, draws, two, noise=False)
    assert_close(par, got.parametric)
    pd.testing.assert_frame_equal(got.parametric, got.predictive)
    np.testing.assert_allclose(got.Ti_month, tm, rtol=6e-8)


def test_controlled_models_use_their_forward(setup, monkeypatch):
    """A model with its own ``forward`` (thermostat, humidistat) is not simulated by the
    compiled pass: its outputs are taken from ``forward``, with the same results."""
    run, draws, (two, _) = setup
    calls = []

    def no_modal(m, P, dt):
        calls.append(m.name)
        return None

    monkeypatch.setattr(engine, "_modal_form", no_modal)
    got = engine.simulate_case(run, draws, two, seed=SEED, chunk=CHUNK)
    par, pred, *_ = reference(run, draws, two)
    assert_close(par, got.parametric)
    assert_close(pred, got.predictive)
    assert calls


def test_series_the_indicators_reject_are_handed_to_assess_batch(setup):
    """A draw whose indoor T leaves −100…100 °C: the numpy path raises, as before."""
    run, draws, (two, _) = setup
    hot = two.copy()
    hot["Te"] = hot["Te"] + 150.0
    hot["Tf"] = hot["Tf"] + 150.0
    with pytest.raises(InputError, match="within -100…100"):
        engine.simulate_case(run, draws, hot, seed=SEED, chunk=CHUNK)


def test_risk_options_reach_the_plan(setup):
    run, draws, (two, _) = setup
    got = engine.simulate_case(
        run, draws, two, seed=SEED, chunk=CHUNK, risk_options={"indicators": ["chemical"]}
    )
    assert list(got.predictive.columns) == [
        "lifetime_multiplier[paper]",
        "lifetime_multiplier[varnish]",
        "twpi",
        "time_of_wetness",
    ]
    with pytest.raises(InputError, match="indicators must be"):
        engine.simulate_case(run, draws, two, seed=SEED, risk_options={"indicators": ["x"]})


def _numpy_annual(T, RH, hoy, base_RH=None):
    """Per-year TWPI, time of wetness and baseline-band share with numpy (reference of
    the compiled pass): the band from ``base_RH`` (default ``RH``) as EN 15757 defines
    it, its seasonal cycle averaged by hour of the year."""
    from heritage_bayes.climate.risk._inputs import centred_mean

    base = RH if base_RH is None else base_RH
    ma = centred_mean(base, 360, "shrink", "propagate")
    band = np.array([np.bincount(hoy, m, 8760) / np.bincount(hoy, None, 8760) for m in ma])
    res = risk.en15757_band(base)
    lo = np.atleast_1d(res.lower_offset)[:, None]
    hi = np.atleast_1d(res.upper_offset)[:, None]
    out = (RH < band[:, hoy] + lo) | (RH > band[:, hoy] + hi)
    years = T.shape[1] // 8760
    rows = []
    for y in range(years):
        sl = slice(y * 8760, (y + 1) * 8760)
        rows.append(
            [
                risk.twpi(T[:, sl], RH[:, sl]),
                8760 * np.mean((RH[:, sl] > 80) & (T[:, sl] > 0), axis=1),
                100 * out[:, sl].mean(axis=1),
            ]
        )
    return np.array(rows).transpose(2, 0, 1)  # draws, years, 3


def test_annual_values_and_the_baseline_band(setup):
    """The per-year values equal numpy's; a future equal to the baseline is outside the
    baseline band exactly as often as the baseline; a warmer room (lower RH) and a
    wetter one (higher vapour pressure outside) leave it more often."""
    run, draws, (two, warm) = setup
    wet = two.copy()
    wet["Pe"] *= 1.25
    got = engine.simulate_cases(run, draws, [two, two.copy(), warm, wet], seed=SEED,
                                chunk=CHUNK, noise=False)  # fmt: skip
    base, same, hot, damp = got
    assert base.annual_names[:2] == ("twpi", "time_of_wetness")
    assert base.annual_names[2].startswith("hours_above_LIM")
    hoy = engine.hour_of_year(two.index)
    _, _, _, _, series = reference(run, draws, two, noise=False)
    Ts = np.concatenate([t for t, _ in series])
    RHs = _relative_humidity(Ts, np.concatenate([p for _, p in series]))
    ref = _numpy_annual(Ts, RHs, hoy)
    a = base.annual_parametric
    np.testing.assert_allclose(a[..., 0], ref[..., 0], rtol=1e-9)  # TWPI per year
    np.testing.assert_allclose(a[..., 1], ref[..., 1], rtol=1e-12)  # time of wetness
    # the band share: the moving averages are summed in another order (ties at the edges)
    np.testing.assert_allclose(a[..., 3], ref[..., 2], atol=2 * 100 / 8760)
    # the whole-period TWPI is the harmonic mean of the years'
    np.testing.assert_allclose(base.parametric["twpi"], 1 / np.mean(1 / a[..., 0], axis=1),
                               rtol=1e-9)  # fmt: skip
    col = "en15757_outside_baseline"
    np.testing.assert_array_equal(same.parametric[col], base.parametric[col])
    assert (hot.parametric[col] > base.parametric[col] + 5).all()
    assert (damp.parametric[col] > base.parametric[col] + 5).all()
    # the self-referenced share cannot see the change: at most 7 % + 7 % of the hours
    # by construction (less where the minimum band widens it), whatever the climate
    for g in (base, hot, damp):
        assert (g.parametric["en15757_outside"] <= 14.0 + 2 * 100 / 17_520).all()


def test_no_baseline_no_band(setup):
    run, draws, (two, warm) = setup
    got = engine.simulate_cases(run, draws, [two, warm], seed=SEED, chunk=CHUNK,
                                noise=False, baseline=False)  # fmt: skip
    assert "en15757_outside_baseline" not in got[1].parametric.columns
    assert np.isnan(got[1].annual_parametric[..., 3]).all()


def test_kalman_noise_in_projections_carries_the_process_noise():
    """A ``noise: kalman`` run's projection noise is its process noise propagated through
    each draw's modes plus the measurement noise (as the calibration's bands), not the
    measurement noise alone (which made its projected bands too narrow)."""
    from heritage_bayes.inference.statespace import KalmanNoise
    from heritage_bayes.projection._modal import _noise
    from heritage_bayes.projection.engine import Draws
    from heritage_bayes.rc.catalog import model as catalog_model
    from heritage_bayes.rc.discretize import modal_form

    m = catalog_model("thermal_1c")
    # Ci 5e6 J/K, Ge 100 W/K, Gf 20 W/K: tau = Ci/(Ge+Gf) = 11.6 h
    P = np.tile([5e6, 100.0, 20.0, 0.5, 0.5, 0.5, 0.5], (4, 1))
    sigma, q = 0.05, 0.3  # [K], [K/sqrt(h)]
    noise = np.tile([sigma, q], (4, 1))
    draws = Draws(np.arange(4), {"thermal": P}, {"thermal": noise}, {"thermal": KalmanNoise()})
    N = 20000
    e = _noise(draws, slice(0, 4), N, 7, 0, {"thermal": m}, 3600.0)["thermal"]
    # the same stream as the calibration's free-run noise
    rng = np.random.default_rng([7, 0])
    ref = KalmanNoise().sample_statespace(rng, modal_form(m, P, 3600.0), noise, N, 1)[..., 0]
    np.testing.assert_array_equal(e, ref)
    # stationary variance of the node: q^2 tau / 2 (q per sqrt(h), tau in h) + sigma^2
    tau_h = 5e6 / 120.0 / 3600.0
    expected = q**2 * tau_h / 2 + sigma**2
    var = e[:, 2000:].var(axis=1)
    # 18 000 hours with a correlation time of 11.6 h: ~780 independent values per draw,
    # the variance estimate's relative sd sqrt(2/780) = 5 %; 4 draws pooled: 2.5 %
    assert abs(var.mean() / expected - 1) < 0.1
    assert var.mean() > 10 * sigma**2
    # without the models the state-space noise cannot be drawn: a clear error
    with pytest.raises(ValueError, match="state-space"):
        _noise(draws, slice(0, 4), 10, 7, 0)


def test_select_draws_of_a_kalman_run_keeps_the_process_noise():
    """The draws a projection takes from a ``noise: kalman`` run carry ``q_<node>`` beside
    ``sigma_<out>``, in the order of the calibration's noise vector: the projection used
    to read ``sigma_Ti`` alone, so that a 1-node room's projected band held the
    measurement noise only and a 2-node room's projection failed on the missing columns."""
    import xarray as xr

    from heritage_bayes.inference.statespace import KalmanNoise

    m = hb.model("thermal_2c")
    rng = np.random.default_rng(3)
    # the demo room (time constants 104 h and 23 min), each draw 10 % apart
    params = {p: TRUE_THERMAL[p] * rng.uniform(0.9, 1.1, (2, 5)) for p in m.parameter_names}
    noise = {"sigma_Ti": np.full((2, 5), 0.05), "q_Tw": np.full((2, 5), 0.01)}
    noise["q_Ti"] = np.full((2, 5), 0.3)
    post = xr.Dataset(
        {f"thermal.{k}": (("chain", "draw"), v) for k, v in {**params, **noise}.items()}
    )
    run = SimpleNamespace(
        idata=SimpleNamespace(posterior=post),
        models={"thermal": m},
        config=SimpleNamespace(thermal=SimpleNamespace(noise="kalman")),
        **_summaries({}),
        path="t",
        draws=lambda s: {p: v.reshape(-1) for p, v in params.items()},
    )
    d = engine.select_draws(run, None, 0)
    names = [n for n, _, _ in KalmanNoise().parameter_specs(m.output_names, m.state_names)]
    assert names == ["sigma_Ti", "q_Tw", "q_Ti"]
    np.testing.assert_array_equal(
        d.noise["thermal"], np.column_stack([noise[n].reshape(-1) for n in names])
    )
    # and the projection's noise of these draws is the propagated process noise
    from heritage_bayes.projection._modal import _noise

    e = _noise(d, slice(0, 10), 500, 7, 0, run.models, 3600.0)["thermal"]
    # q_Ti 0.3 K/√h on an air node of 23 min: sd ≈ 0.3 × √(0.38/2) ≈ 0.13 K, beside the
    # 0.05 K measurement noise (the slow envelope's q is small): well above 0.05 K
    assert e.shape == (10, 500) and e[:, 100:].std() > 2 * 0.05


def test_select_draws_of_a_kalman_run_use_its_free_run_error():
    """Where the calibration replaced ``kalman``'s free-run bands by the free-run error
    (``predictive_noise`` in the summary, every output), a projection draws that error:
    AR(1) + white with the fitted parameters for every draw, as the calibration's bands."""
    import xarray as xr

    from heritage_bayes.inference.likelihoods import AR1WhiteNoise

    m = hb.model("thermal_1c")
    post = xr.Dataset(
        {f"thermal.{k}": (("chain", "draw"), np.ones((2, 3))) for k in ("sigma_Ti", "q_Ti")}
    )
    fit = {"sigma": 0.4, "phi": 0.97, "sigma_meas": 0.05, "reason": "kalman"}
    run = SimpleNamespace(
        idata=SimpleNamespace(posterior=post),
        models={"thermal": m},
        config=SimpleNamespace(thermal=SimpleNamespace(noise="kalman")),
        **_summaries({"models": {"thermal": {"predictive_noise": {"Ti": fit}}}}),
        path="t",
        draws=lambda s: {p: np.full(6, 1e6) for p in m.parameter_names},
    )
    d = engine.select_draws(run, None, 0)
    assert isinstance(d.noise_models["thermal"], AR1WhiteNoise)
    np.testing.assert_array_equal(d.noise["thermal"], np.tile([0.4, 0.97, 0.05], (6, 1)))


def _toy_family():
    """A family without a compiled pass: the mean RH (per year too) and the warmest hour."""
    from heritage_bayes.climate.risk.indicators import Family, Indicator

    def toy(T, RH, *, offset=0.0):
        """Options of the toy family: ``offset`` added to the mean RH [%]."""

    def compute(h, opts, nan_policy, seasonal):
        return {"toy_rh_mean": h.RH.mean(axis=-1) + opts["toy"]["offset"],
                "toy_t_max": h.T.max(axis=-1)}  # fmt: skip

    return Family(
        name="toy",
        yearly=True,
        indicators=(
            Indicator(
                "toy_rh_mean",
                "Mean RH (toy)",
                "%",
                "Mean RH.",
                "-",
                "per year",
                1,
                "toy",
                per_year=True,
            ),
            Indicator("toy_t_max", "Warmest hour (toy)", "°C", "Max T.", "-", "series", 1, "toy"),
        ),
        options={"toy": toy},
        check=lambda func, opts: None,
        columns=lambda opts: ["toy_rh_mean", "toy_t_max"],
        compute=compute,
    )


def test_a_registered_family_is_projected_with_its_numpy_compute(setup):
    """A family registered at run time (no compiled pass) appears in a projection's
    indicators (after the compiled ones, as in assess_batch), in its per-year values and
    in the summary, with the values its numpy ``compute`` gives on the projected series;
    the compiled indicators are those of a projection without it."""
    from pydantic import ValidationError

    from heritage_bayes.climate.risk.registry import register, unregister
    from heritage_bayes.projection.config import RiskOptions
    from heritage_bayes.projection.summary import summarize

    run, draws, (two, warm) = setup
    plain = engine.simulate_cases(run, draws, [two, warm], seed=SEED, chunk=CHUNK)
    register(_toy_family())
    try:
        got = engine.simulate_cases(run, draws, [two, warm], seed=SEED, chunk=CHUNK)
        par, pred, _, _, series = reference(run, draws, two)  # assess_batch: toy included
        toy_only = {"indicators": ["toy"], "toy": {"offset": 1.0}}  # its options too
        only = engine.simulate_case(run, draws, two, seed=SEED, chunk=CHUNK, noise=False,
                                    risk_options=toy_only)  # fmt: skip
        summary = summarize(["now", "warm"], [None, 2050], got, "now", [], {})
        assert RiskOptions(indicators=["toy", "mould"]).indicators == ["toy", "mould"]
    finally:
        unregister("toy")
    with pytest.raises(ValidationError, match=r"unknown indicator group\(s\) \['toy'\]"):
        RiskOptions(indicators=["toy"])  # a projection file names only known families
    base = got[0]
    assert_close(par, base.parametric)
    assert_close(pred, base.predictive)
    assert list(base.predictive.columns)[-2:] == ["toy_rh_mean", "toy_t_max"]
    assert base.predictive.attrs["units"]["toy_t_max"] == "°C"
    for p, g in zip(plain, got, strict=True):  # the compiled columns: bit for bit
        pd.testing.assert_frame_equal(g.predictive.drop(columns=["toy_rh_mean", "toy_t_max"]),
                                      p.predictive, check_like=False)  # fmt: skip
        np.testing.assert_array_equal(g.annual_predictive[..., :-1], p.annual_predictive)
    assert base.annual_names[-1] == "toy_rh_mean"
    Ts = np.concatenate([t for t, _ in series])
    RHs = _relative_humidity(Ts, np.concatenate([p for _, p in series]))
    per_year = RHs.reshape(len(RHs), 2, 8760).mean(axis=-1)
    np.testing.assert_allclose(base.annual_parametric[..., -1], per_year, rtol=1e-9)
    np.testing.assert_allclose(only.parametric["toy_rh_mean"], RHs.mean(axis=1) + 1.0, rtol=1e-9)
    assert list(only.parametric.columns) == ["toy_rh_mean", "toy_t_max"]
    # without the mould family no isopleth: no per-year column left without its name (the
    # NetCDF writer reads every per-year column's unit by its name)
    assert not any(n.startswith("hours_above_LIM") for n in only.annual_names)
    assert only.annual_predictive.shape[-1] == len(only.annual_names)
    entry = summary["indicators"]["toy_rh_mean"]
    assert entry["unit"] == "%" and entry["change"]["warm"]["q50"] < 0  # warmer: drier
    split = summary["uncertainty_split"]["baseline"]["indicators"]["toy_rh_mean"]
    assert split["basis"].startswith("one year's value")
