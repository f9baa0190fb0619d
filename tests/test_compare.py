"""Model comparison (issue 13): arviz conventions of a run, blocked LOO, validation ELPD,
identifiability measures, the recommendation, `hbayes compare` and `hbayes models NAME`.

A module-scoped fixture runs `hbayes compare` on a tiny virtual monument (thermal_1c and
thermal_2c, 10 + 5 days, 600 sampler steps: seconds, not converged) once.
"""

from __future__ import annotations

import io
import json
import math

import numpy as np
import pytest
import xarray as xr
import yaml

from heritage_bayes._arviz import az
from heritage_bayes.calibration.selection import choose, decide
from heritage_bayes.cli import main
from heritage_bayes.compare import (
    _block_se,
    _practical_rank,
    blocked_loo_data,
    elpd_validation,
    load_inference,
    recommend,
)
from heritage_bayes.config.sampler import SamplerSettings
from heritage_bayes.inference.predictive import PREDICTIVE_DRAWS
from heritage_bayes.report._browser import PHONE_OVERFLOW_JS, find_chromium, open_page

TINY = {
    "name": "tiny",
    "building": "Virtual <b>monument</b>",
    "seed": 3,
    "data": {"demo": {"seed": 7, "gap": ["2019-02-05", "2019-02-06"]}},
    "periods": {
        "calibration": {"start": "2019-02-01", "end": "2019-02-11"},
        "validation": {"start": "2019-02-11", "end": "2019-02-16"},
        "warmup": "2d",
        "init_window": "2d",
    },
    "room_volume": 400,
    # Gw exists in thermal_2c only: the thermal_1c candidate runs without it
    "thermal": {"model": "thermal_2c", "priors": {"Gw": {"lower": 1.0, "upper": 1.0e4}}},
    "hygric": {"model": "hygric_1c"},
    "sampler": {"max_steps": 600, "check_every": 200},
    "optimizer": {"maxiter": 20, "starts": 2, "popsize": 4},
}
MODELS = ("thermal_1c", "thermal_2c")


@pytest.fixture(scope="module")
def cfg_path(tmp_path_factory):
    p = tmp_path_factory.mktemp("cmpcfg") / "tiny.yaml"
    p.write_text(yaml.safe_dump(TINY))
    return p


@pytest.fixture(scope="module")
def compared(cfg_path, tmp_path_factory):
    out = tmp_path_factory.mktemp("compare") / "cmp"
    args = ["compare", str(cfg_path), "--models", ",".join(MODELS), "--out", str(out)]
    # two at a time: thermal_2c in this process, thermal_1c in a worker process
    assert main([*args, "--quiet", "--no-report", "--workers", "2"]) == 0
    return out, json.loads((out / "comparison.json").read_text())


def test_the_screen_is_recorded(compared):
    """Every candidate's MAP screened before sampling: its row (free parameters, FIT,
    score) in comparison.json; two candidates are both sampled (a comparison needs two),
    each chain started at its screened MAP."""
    out, res = compared
    screen = res["screen"]
    assert screen["sampled"] == list(MODELS) and res["screened_out"] == {}
    assert [r["model"] for r in screen["rows"]] == list(MODELS)
    for r in screen["rows"]:
        assert {"n_params", "fit", "score", "map_seconds"} <= set(r), r
        assert r["score"] == pytest.approx(r["fit"]["validation"]["Ti"]["FIT"])
    assert "the simplest within 2 points of the best is chosen" in screen["rule"]
    # the same rule as model: auto: the screen's choice from the same rows, recorded
    sel = res["selection"]
    assert sel["choice"] == choose([r for r in screen["rows"] if "error" not in r])["choice"]
    assert sel["rule"] == screen["rule"]
    rec = res["recommendation"]
    assert rec["screen_choice"] == sel["choice"] and rec["model"] == sel["model"]
    if sel["decided_by"] == "screen":  # the ELPD did not (reliably) break a tie
        assert rec["model"] == sel["choice"] and rec["agrees_with_screen"]


def test_results_do_not_depend_on_where_a_candidate_ran(compared, cfg_path, tmp_path):
    """The parent calibrates the largest candidate itself, a worker the other (issue 28):
    each candidate's chain is its seed's, so one after the other in this process gives
    the very same draws and comparison."""
    out, res = compared
    one = tmp_path / "one"
    args = ["compare", str(cfg_path), "--models", ",".join(MODELS), "--out", str(one)]
    assert main([*args, "--quiet", "--no-report", "--workers", "1"]) == 0
    for m in MODELS:
        a = az.from_netcdf(out / m / "posterior.nc").posterior
        b = az.from_netcdf(one / m / "posterior.nc").posterior
        assert set(a.data_vars) == set(b.data_vars)
        for v in a.data_vars:
            np.testing.assert_array_equal(a[v].values, b[v].values, err_msg=f"{m}: {v}")
    again = json.loads((one / "comparison.json").read_text())
    assert again["recommendation"] == res["recommendation"]


def test_run_groups_share_draws_and_loglik_has_only_observed_hours(compared):
    out, _ = compared
    idata = load_inference([out / "thermal_2c"])["thermal_2c"]
    post = idata.posterior
    ds = idata["log_likelihood"]
    np.testing.assert_array_equal(ds["chain"].values, post["chain"].values)
    np.testing.assert_array_equal(ds["draw"].values, post["draw"].values)
    # the predictive: about PREDICTIVE_DRAWS of the same draws (labels kept), and bands
    # over all of them
    pp = idata.posterior_predictive
    np.testing.assert_array_equal(pp["chain"].values, post["chain"].values)
    assert set(pp["draw"].values) <= set(post["draw"].values)
    n_pp = pp.sizes["chain"] * pp.sizes["draw"]
    n_post = post.sizes["chain"] * post.sizes["draw"]
    assert n_pp == n_post or PREDICTIVE_DRAWS <= n_pp < PREDICTIVE_DRAWS + pp.sizes["chain"]
    assert idata["predictive_bands"]["thermal.Ti"].sizes["quantile"] == 5
    ll = idata.log_likelihood["thermal.Ti"]
    assert np.all(np.isfinite(ll.values))
    # warm-up (2 days) and the one-day gap are not in the likelihood: 10 - 2 - 1 days
    assert ll.shape[-1] == (10 - 2 - 1) * 24
    # the validation hours: one log predictive density each, not the terms per draw
    assert "log_likelihood_validation" not in idata.groups()
    lv = idata["log_predictive_density_validation"]["thermal.Ti"]
    assert lv.shape == (5 * 24,) and np.all(np.isfinite(lv.values))
    # every group holds sampler.n_predictive draws (its default), or all retained ones
    summ = json.loads((out / "thermal_2c" / "summary.json").read_text())
    per_walker = summ["models"]["thermal"]["chain"]["draws_per_walker"]
    n_saved = SamplerSettings().n_predictive
    assert post.sizes["draw"] == min(per_walker, math.ceil(n_saved / post.sizes["chain"]))


def test_az_loo_and_compare_on_run_directories_are_finite(compared):
    out, _ = compared
    runs = load_inference({m: out / m for m in MODELS})
    for d in runs.values():
        loo = az.loo(d)  # one output per run: no var_name needed
        assert math.isfinite(float(loo.elpd_loo)) and math.isfinite(float(loo.se))
    table = az.compare(runs)
    assert set(table.index) == set(MODELS)
    assert np.all(np.isfinite(table[["elpd_loo", "se", "dse", "weight"]].to_numpy(float)))
    blocked = {m: blocked_loo_data(d) for m, d in runs.items()}
    assert blocked["thermal_2c"].log_likelihood["thermal.Ti"].shape[-1] == 7  # daily blocks
    table = az.compare(blocked)
    assert np.all(np.isfinite(table[["elpd_loo", "se", "dse"]].to_numpy(float)))
    # the blocked terms are sums of the hourly ones: the full-data lpd is unchanged
    h = runs["thermal_2c"].log_likelihood["thermal.Ti"].values.astype(float).sum(axis=-1)
    b = blocked["thermal_2c"].log_likelihood["thermal.Ti"].values.sum(axis=-1)
    np.testing.assert_allclose(h, b, rtol=1e-10)


def test_validation_elpd_is_the_log_mean_density(compared):
    out, _ = compared
    d = load_inference([out / "thermal_1c"])["thermal_1c"]
    ev = elpd_validation(d)
    lv = d["log_predictive_density_validation"]["thermal.Ti"]
    assert ev["n"] == 120
    np.testing.assert_allclose(ev["elpd"], lv.values.sum(), rtol=1e-12)
    np.testing.assert_array_equal(ev["times"], lv["time.thermal.Ti"].values)
    assert ev["se"] > 0


def test_validation_elpd_of_stored_densities_equals_that_of_terms_per_draw():
    """A run written before issue 28 (terms per draw) and one written now (the log mean
    density per hour, :func:`_validation_lpd`) give the same ELPD and standard error;
    ``log_mean_exp`` is the naive formula where that does not overflow, and stable
    where it would."""
    from heritage_bayes.calibration.outputs import _validation_lpd
    from heritage_bayes.inference.interop import log_mean_exp

    rng = np.random.default_rng(3)
    t = np.arange(96).astype("datetime64[h]").astype("datetime64[ns]")
    terms = xr.DataArray(
        rng.normal(-1.0, 0.3, (4, 25, 96)),
        dims=("chain", "draw", "time.thermal.Ti"),
        coords={"chain": np.arange(4), "draw": np.arange(25), "time.thermal.Ti": t},
    )
    naive = np.log(np.mean(np.exp(terms.values.reshape(100, 96)), axis=0))
    np.testing.assert_allclose(log_mean_exp(terms.values), naive, rtol=1e-13)
    np.testing.assert_allclose(log_mean_exp(terms.values - 1000.0), naive - 1000.0, rtol=1e-13)
    old = az.InferenceData(log_likelihood_validation=xr.Dataset({"thermal.Ti": terms}))
    new = az.InferenceData(
        log_predictive_density_validation=xr.Dataset({"thermal.Ti": _validation_lpd(terms, 100)})
    )
    a, b = elpd_validation(old), elpd_validation(new)
    np.testing.assert_allclose(a["elpd"], b["elpd"], rtol=1e-13)
    np.testing.assert_allclose(a["se"], b["se"], rtol=1e-12)
    np.testing.assert_array_equal(a["times"], b["times"])


def test_comparison_json(compared):
    out, res = compared
    assert set(res["models"]) == set(MODELS)
    for m in MODELS:
        info = res["models"][m]
        assert (out / m / "posterior.nc").is_file() and info["model"] == m
        a = info["accuracy"]
        assert {"FIT", "MSE", "MAE"} <= set(a["validation"])
        for k in ("elpd_validation", "loo_blocked"):
            assert math.isfinite(a[k]["elpd"]) and math.isfinite(a[k]["diff_to_best"])
        i = info["identifiability"]
        assert i["structural_rank"] <= i["structural_n_params"]
        assert 0 <= i["practical_rank"] <= i["n_free_physical"]
        lo, hi = i["practical_rank_band"]
        assert lo <= i["practical_rank"] <= hi
        assert i["widest_interval"]["decades"] > 0
        assert "tau_1_h" in i["derived"]
        for e in list(i["parameters"].values()) + list(i["derived"].values()):
            if not e.get("fixed") and e.get("contraction") is not None:
                assert e["contraction"] <= 1.0
    # the configured priors reach the candidates that have the parameter
    p2 = res["models"]["thermal_2c"]["identifiability"]["parameters"]
    assert 1.0 <= p2["Gw"]["q05"] and p2["Gw"]["q95"] <= 1.0e4
    assert "Gw" not in res["models"]["thermal_1c"]["identifiability"]["parameters"]
    rec = res["recommendation"]
    assert rec["model"] in MODELS and rec["reason"].startswith(f"`{rec['model']}`:")
    assert rec["best_accuracy"] in MODELS
    assert (out / "comparison.html").is_file()


def test_recommendation_words():
    """The comparison's sentence: the rule's decision (synthetic screen and posteriors),
    the identifiability of the model recommended, the candidates not converged."""

    def model(n, elpd, taus_bad=(), converged=True, below=()):
        return {
            "converged": converged,
            "accuracy": {"elpd_validation": {"elpd": elpd}},
            "identifiability": {
                "n_free_physical": n,
                "time_constants_identified": not taus_bad,
                "time_constants_not_identified": list(taus_bad),
                "time_constants_below_step": list(below),
            },
        }

    rows = [
        {"model": m, "n_params": k, "fit": {"validation": {"Ti": {"FIT": f}}}}
        for m, k, f in (("thermal_1c", 8, 82.8), ("thermal_4a", 14, 83.8))
    ]
    models = {"thermal_1c": model(7, 0.0), "thermal_4a": model(13, 176.2, ["tau_2_h"], False)}

    def post(ms):
        se = {"thermal_1c": {"thermal_4a": 20.2}, "thermal_4a": {"thermal_1c": 20.2}}
        return {
            m: {"elpd": i["accuracy"]["elpd_validation"]["elpd"], "converged": i["converged"],
                "max_pareto_k": 0.3, "se": se[m]}
            for m, i in ms.items()
        }  # fmt: skip

    rec = recommend(decide(rows, post(models)), models, "elpd_validation")
    assert rec["model"] == "thermal_1c" and rec["agrees_with_screen"]
    assert rec["reason"].startswith("`thermal_1c`: the screen's choice, as `model: auto` chooses")
    assert "not reliable (thermal_4a's chain did not converge)" in rec["reason"]
    assert "All its time constants are identified." in rec["reason"]
    assert "so its figures are provisional: `thermal_4a`" in rec["reason"]
    assert rec["provisional"]  # longer chains may change it
    models["thermal_4a"]["converged"] = True
    rec = recommend(decide(rows, post(models)), models, "elpd_validation")
    assert rec["model"] == "thermal_4a" and rec["decided_by"] == "ELPD"
    assert not rec["agrees_with_screen"] and rec["screen_choice"] == "thermal_1c"
    assert rec["reason"].startswith(
        "`thermal_4a`: the ELPD breaks the screen's tie; the screen chose thermal_1c"
    )
    assert "Not all its time constants are identified (τ₂)" in rec["reason"]
    assert "tau_" not in rec["reason"] and "provisional" not in rec["reason"]
    assert not rec["provisional"]
    models["thermal_1c"] = model(7, 0.0, below=["tau_2_h"])
    models["thermal_4a"]["accuracy"]["elpd_validation"]["elpd"] = 1.0
    rec = recommend(decide(rows, post(models)), models, "elpd_validation")
    assert "time step are identified (τ₂ shorter than the step" in rec["reason"]


def test_block_se_and_practical_rank():
    rng = np.random.default_rng(5)
    # iid terms: the block-sum SE estimates sqrt(n) sd; with 400 blocks its relative
    # sampling error is about 1/sqrt(2 * 399) = 3.5 %, so 15 % is > 4 sd
    x = rng.standard_normal(400 * 24)
    t = np.datetime64("2020-01-01T00:00") + np.arange(x.size) * np.timedelta64(1, "h")
    assert _block_se(x, t, 24.0) == pytest.approx(math.sqrt(x.size), rel=0.15)
    # AR(1) terms with phi 0.9: the hourly SE formula underrates the sum's sd by
    # sqrt((1 + phi) / (1 - phi)) = 4.4; daily blocks recover most of it
    e = np.empty_like(x)
    e[0] = x[0]
    for k in range(1, x.size):
        e[k] = 0.9 * e[k - 1] + math.sqrt(1 - 0.81) * x[k]
    naive = math.sqrt(x.size) * np.std(e)
    assert _block_se(e, t, 24.0) > 3.0 * naive
    post = rng.standard_normal((4000, 3)) * np.array([0.01, 0.05, 0.9])
    rank, eig = _practical_rank(post, np.ones(3), 0.01)
    assert rank == 2 and len(eig) == 3


@pytest.mark.parametrize(
    ("models", "needle"),
    [
        ("thermal_1c,thermal_9z", "unknown model(s) ['thermal_9z']"),
        ("thermal_1c,hygric_2c", "['hygric_2c'] are not thermal models"),
        ("thermal_2c", "at least two models"),
        ("thermal_1c,thermal_1c", "given more than once"),
    ],
)
def test_bad_models_exit_2_naming_the_option(cfg_path, tmp_path, capsys, models, needle):
    rc = main(["compare", str(cfg_path), "--models", models, "--out", str(tmp_path / "o")])
    err = capsys.readouterr().err
    assert rc == 2 and "--models" in err and needle in err and "Traceback" not in err
    assert not (tmp_path / "o").exists()


def test_models_of_a_section_the_config_lacks(tmp_path, capsys):
    raw = {k: v for k, v in TINY.items() if k != "hygric"}
    p = tmp_path / "thermal_only.yaml"
    p.write_text(yaml.safe_dump(raw))
    rc = main(["compare", str(p), "--models", "hygric_1c,hygric_2c", "--out", str(tmp_path / "o")])
    err = capsys.readouterr().err
    assert rc == 2 and "no 'hygric' section" in err


def test_models_name_describes_the_model(capsys):
    assert main(["models", "thermal_2c"]) == 0
    out = capsys.readouterr().out
    assert "Ci·dTi/dt = Gi·(Tw − Ti) + Gfast·(Te − Ti)" in out
    for needle in ("Cw ", "[J/K]", "[W/K]", "fI_S", "[m²]", "loguniform", "sigma_Ti", "phi_Ti"):
        assert needle in out
    assert "Te " in out and "[W/m²]" in out and "Ti " in out
    assert main(["models", "hygric_2c", "--noise", "iid"]) == 0
    out = capsys.readouterr().out
    assert "[kg/Pa]" in out and "sigma_Pi" in out and "phi_Pi" not in out
    assert main(["models", "thermal_5x"]) == 2
    assert "unknown model 'thermal_5x'" in capsys.readouterr().err
    assert main(["models"]) == 0
    assert "thermal_4a" in capsys.readouterr().out


def test_the_same_posterior_prints_the_same_digits_on_every_page(compared):
    """A parameter's median and 90 % interval: comparison.json states the run's own
    summary.json values (computed from the draws posterior.nc holds), and the
    comparison page prints them with the report's formatter, so the report, the
    comparison and the JSON agree digit for digit."""
    import html as html_mod
    import re

    from heritage_bayes.format import fmt, fmt_interval

    out, res = compared
    page = html_mod.unescape((out / "comparison.html").read_text(encoding="utf-8"))
    checked = 0
    for m in MODELS:
        summary = json.loads((out / m / "summary.json").read_text())
        post = az.from_netcdf(out / m / "posterior.nc").posterior
        section = page[page.index(f'<section id="model-{m}">') :]
        rows = [re.findall(r"<td[^>]*>(.*?)</td>", r) for r in re.findall(r"<tr>.*?</tr>", section)]
        ident = res["models"][m]["identifiability"]
        for kind, table in (("parameters", ident["parameters"]), ("derived", ident["derived"])):
            label = "parameter" if kind == "parameters" else "derived"
            for name, e in table.items():
                if e.get("fixed"):
                    continue
                stated = summary[kind][f"thermal.{name}"]
                for q in ("median", "q05", "q95"):
                    assert e[q] == stated[q], (m, name, q)
                x = post[f"thermal.{name}"].values.reshape(-1)
                assert stated["median"] == np.quantile(x, 0.5)
                cells = next(c for c in rows if c[1:3] == [f"<code>{name}</code>", label])
                assert fmt(stated["median"]) in cells, (m, name, cells)
                assert fmt_interval(stated["q05"], stated["q95"]) in cells, (m, name, cells)
                checked += 1
    assert checked >= 10


def test_comparison_page_in_headless_chromium(compared):
    out, res = compared
    text = (out / "comparison.html").read_text()
    assert "<b>monument</b>" not in text and "&lt;b&gt;monument" in text
    chromium = find_chromium()
    if chromium is None:
        pytest.skip("chromium not installed (Debian package 'chromium'; .ci/run installs it)")
    page = open_page(out / "comparison.html", chromium=chromium, width=1280, height=1400)
    assert page.errors == [], page.errors
    external = [u for u in page.requests[1:] if not u.startswith("data:")]
    assert external == [], external
    dom = page.dom
    # the screen's table (every candidate's MAP score, sampled or why not) before the
    # sampled models' own sections
    assert dom["sections"][:4] == ["summary", "accuracy", "identifiability", "screen"]
    assert [f"model-{m}" for m in MODELS] == dom["sections"][4:]
    assert dom["figures"] == ["fig-tradeoff"] and dom["scripts"] == 0
    assert all(i["complete"] and i["w"] > 400 for i in dom["images"])
    import matplotlib.image as mpimg

    img = mpimg.imread(io.BytesIO(page.screenshot), format="png")[..., :3]
    assert float(np.mean(img.mean(axis=2) < 0.9)) > 0.03, "screenshot is (almost) blank"
    assert res["recommendation"]["model"] in text
    phone = open_page(
        out / "comparison.html", chromium=chromium, width=390, height=844,
        extra_js=PHONE_OVERFLOW_JS,
    )  # fmt: skip
    lay = phone.dom["extra"]
    assert lay["docw"] <= lay["W"] <= 390 and lay["wide"] == [], lay


def test_a_candidate_folder_that_is_not_a_run_needs_force(cfg_path, tmp_path, capsys):
    out = tmp_path / "o"
    (out / "thermal_1c").mkdir(parents=True)
    (out / "thermal_1c" / "notes.txt").write_text("mine")
    args = ["compare", str(cfg_path), "--models", ",".join(MODELS), "--out", str(out)]
    assert main([*args, "--quiet", "--no-report"]) == 2
    err = capsys.readouterr().err
    assert "thermal_1c" in err and "--force" in err and "Traceback" not in err
    assert (out / "thermal_1c" / "notes.txt").read_text() == "mine"
    assert not (out / "comparison.json").exists()
    assert main([*args, "--quiet", "--no-report", "--force"]) == 0
    assert (out / "comparison.json").is_file()
    assert (out / "thermal_1c" / "summary.json").is_file()


def test_tempered_loo_matches_the_closed_form_of_a_tempered_normal_mean():
    """Draws of a tempered posterior (y_i ~ N(μ, 1), flat prior, log-likelihood / T):
    μ ~ N(ȳ, T/n), and leaving y_i out leaves N(ȳ_-i, T/(n-1)), so the exact LOO
    predictive of y_i is N(ȳ_-i, 1 + T/(n-1)). ``tempered_loo`` (weights p^(-1/T))
    reproduces its ELPD within 0.1 nat (6 sd of its Monte Carlo error over 10 seeds of
    8 000 draws: 0.016); ``az.loo``'s weights 1/p, right only for T = 1, are off by more
    than 5 nats (−14.65 against −9.15); with T = 1 the two are the same."""
    from scipy import stats

    from heritage_bayes.compare.scores import tempered_loo

    n, T = 6, 4.0
    y = np.array([-1.2, -0.3, 0.1, 0.4, 0.9, 1.6])
    exact = sum(
        stats.norm.logpdf(y[i], np.delete(y, i).mean(), np.sqrt(1 + T / (n - 1))) for i in range(n)
    )
    rng = np.random.default_rng(0)
    mu = rng.normal(y.mean(), np.sqrt(T / n), (4, 2000))
    ll = stats.norm.logpdf(y[None, None, :], mu[..., None], 1.0)
    data = az.InferenceData(
        posterior=xr.Dataset({"mu": (("chain", "draw"), mu)}),
        log_likelihood=xr.Dataset({"y": (("chain", "draw", "obs"), ll)}),
    )
    loo = tempered_loo(data, "y", T)
    assert abs(float(loo.elpd_loo) - exact) < 0.1
    assert loo.loo_i.shape == (n,) and np.all(np.asarray(loo.pareto_k) < 0.7)
    assert float(loo.p_loo) > 0
    assert abs(float(az.loo(data, var_name="y").elpd_loo) - exact) > 5.0
    one = tempered_loo(data, "y", 1.0)
    assert float(one.elpd_loo) == float(az.loo(data, var_name="y").elpd_loo)
    # az.compare takes it
    table = az.compare({"a": loo, "b": tempered_loo(data, "y", 2.0)}, ic="loo")
    assert set(table.index) == {"a", "b"}
