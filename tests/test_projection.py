"""Climate-change projections (issue 12): ``hbayes project`` end to end on a tiny run,
the physics of the projected change, predictive noise, and bad input.

A module-scoped fixture calibrates the tiny virtual monument (thermal_1c + hygric_1c,
as the report tests; a few seconds, not converged: enough posterior draws to project).
The demo weather is a TMY3 year: 8759 hours on the UTC grid.
"""

from __future__ import annotations

import json
import shutil
from pathlib import Path

import numpy as np
import pytest
import yaml

from heritage_bayes.calibration.calibrate import run_calibration
from heritage_bayes.cli import main
from heritage_bayes.config import parse_config
from heritage_bayes.errors import ConfigError, DataError, InputError
from heritage_bayes.projection import parse_projection_config, project
from heritage_bayes.report._browser import BROKEN_WORDS, PHONE_OVERFLOW_JS, find_chromium, open_page
from test_report import TINY

DRAWS = 24
SHIFT = 2.0  # [K] uniform warming of the "warm" scenario


def _morph(name, horizon, dT, **kw):
    return {"scenario": name, "horizon": horizon, "method": "shift", "deltas": {"Te": [dT] * 12}}


PROJ = {
    "name": "tiny_projection",
    "draws": DRAWS,
    "seed": 5,
    "morphing": [_morph("warm", 2050, SHIFT), _morph("mild", 2050, 1.0)],
    "risk": {"chunk_draws": 10},
}


@pytest.fixture(scope="module")
def run_dir(tmp_path_factory) -> Path:
    out = tmp_path_factory.mktemp("proj") / "run"
    run_calibration(parse_config(TINY), out_dir=out, report=False, quiet=True)
    return out


@pytest.fixture(scope="module")
def proj(run_dir, tmp_path_factory):
    out = tmp_path_factory.mktemp("proj_out") / "p"
    return project(run_dir, PROJ, out=out), out


def test_outputs_written(proj):
    p, out = proj
    assert sorted(x.name for x in out.iterdir()) == [
        ".hbayes-run.json",  # the marker: the folder and the four files are the package's
        "projection.csv",
        "projection.html",
        "projection.json",
        "projection.nc",
    ]
    from heritage_bayes.rundir.marker import read_marker

    marker = read_marker(out)
    assert marker.kind == "projection"
    assert marker.files == tuple(f"projection.{x}" for x in ("csv", "html", "json", "nc"))
    import xarray as xr

    ds = xr.open_dataset(out / "projection.nc", engine="h5netcdf")
    assert list(ds["case"].values) == ["baseline", "warm 2050", "mild 2050"]
    assert ds.sizes["draw"] == DRAWS and ds.sizes["month"] == 12
    for v in ("twpi", "vtt_mould_index_max", "emc_range", "en15757_outside", "Ti_monthly"):
        assert v in ds
    assert "twpi_parametric" in ds and "en15757_outside_baseline" in ds
    assert ds["twpi_per_year"].dims == ("case", "draw", "year")
    s = json.loads((out / "projection.json").read_text())
    assert s["draws"] == DRAWS and len(s["cases"]) == 3
    assert s["cases"][0]["hours"] == 8759  # a TMY year on the UTC grid: not refused
    stmts = {r["indicator"] for r in s["probabilities"]}
    assert {"vtt_mould_index_max", "twpi"} <= stmts
    for r in s["probabilities"]:
        for c in r["cases"].values():
            assert 0.0 <= c["p"] <= 1.0
    assert set(s["uncertainty_split"]) == {"baseline", "2050"}
    assert s["indicator_registry"]["time_of_wetness"]["source"].startswith("ISO 9223")
    import pandas as pd

    csv = pd.read_csv(out / "projection.csv")
    assert set(csv["case"]) == {"baseline", "warm 2050", "mild 2050"}
    row = csv[(csv.indicator == "twpi") & (csv.case == "baseline")].iloc[0]
    assert row["name"] == "Time-weighted preservation index" and row["unit"] == "years"
    assert row["q50"] == pytest.approx(s["indicators"]["twpi"]["cases"]["baseline"]["q50"])


def test_warming_reaches_the_room(proj):
    """A uniform +2 K on Te (and so on the annual-mean ground temperature) raises the
    simulated Ti by 2 K exactly in every draw: the thermal models' static gains from Te
    and Tf sum to 1, solar gains are unchanged, and the noise draw is the same (paired)."""
    p, _ = proj
    ti = p.dataset["Ti_monthly"]
    d = (ti.sel(case="warm 2050") - ti.sel(case="baseline")).values
    np.testing.assert_allclose(d.mean(axis=1), SHIFT, atol=1e-3)
    # warmer at constant outdoor RH: TWPI (chemical lifetime) falls in every draw
    tw = p.dataset["twpi"]
    assert (tw.sel(case="warm 2050") < tw.sel(case="baseline")).all()
    assert (tw.sel(case="warm 2050") < tw.sel(case="mild 2050")).all()
    assert p.summary["indicators"]["twpi"]["change"]["warm 2050"]["p_worse"] == 1.0


def test_noise_draw_widens_the_bands(proj):
    """Each draw adds a draw of its noise model: the predictive spread of the monthly
    Ti exceeds the spread of the parameters alone, and the split names model error."""
    p, _ = proj
    ds = p.dataset
    rh = ds["RHi_monthly"].values
    assert np.nanmax(rh) <= 100.0 and np.nanmin(rh) >= 0.0
    split = p.summary["uncertainty_split"]["2050"]["indicators"]["twpi"]
    assert split["variance"]["noise"] > 0
    assert split["variance"]["scenario"] > 0
    assert split["variance"]["weather_year"] is None  # one year of weather: none
    assert abs(sum(v for v in split["share"].values() if v is not None) - 1) < 1e-9


def test_noise_free_projection_is_parametric(run_dir):
    p = project(run_dir, {**PROJ, "noise": False, "draws": 6}, write=False)
    ds = p.dataset
    np.testing.assert_allclose(ds["twpi"].values, ds["twpi_parametric"].values)
    assert p.summary["noise"] is None


def test_probability_table(proj):
    p, _ = proj
    t = p.probability_table()
    assert list(t.columns) == p.labels
    assert any(i.startswith("P(Highest VTT mould index > 1") for i in t.index)


def test_cli_project(run_dir, tmp_path, capsys):
    cfg = tmp_path / "p.yaml"
    cfg.write_text(yaml.safe_dump(PROJ))
    out = tmp_path / "out"
    # the tiny run is not converged: written, with a warning and exit status 3
    assert main(["project", str(run_dir), str(cfg), "--out", str(out), "--draws", "8"]) == 3
    cap = capsys.readouterr()
    assert "P(Time-weighted preservation index < 45 years)" in cap.out and "warm 2050" in cap.out
    assert "calibration did not converge" in cap.err and "exit code 3" in cap.err
    html = (out / "projection.html").read_text()
    assert "id='unconverged'" in html and "Calibration not converged" in html
    assert json.loads((out / "projection.json").read_text())["draws"] == 8


# ---------------------------------------------------------------------- bad input
def _fails(args, capsys, *needles):
    assert main(args) == 2
    err = capsys.readouterr().err
    assert "Traceback" not in err
    for n in needles:
        assert n in err, err
    return err


def test_bad_scenario_and_horizon(run_dir, tmp_path, capsys):
    cfg = tmp_path / "p.yaml"
    cfg.write_text(yaml.safe_dump({"knmi14": {"tables": "x", "scenarios": ["WX"]}}))
    out = tmp_path / "out"
    _fails(["project", str(run_dir), str(cfg), "--out", str(out)], capsys, "knmi14.scenarios[0]")
    cfg.write_text(yaml.safe_dump({"knmi14": {"tables": "x", "horizons": [2070]}}))
    _fails(["project", str(run_dir), str(cfg), "--out", str(out)], capsys, "knmi14.horizons[0]")
    assert not out.exists()


def test_more_draws_than_the_posterior(run_dir, tmp_path, capsys):
    cfg = tmp_path / "p.yaml"
    cfg.write_text(yaml.safe_dump(PROJ))
    out = tmp_path / "out"
    _fails(
        ["project", str(run_dir), str(cfg), "--out", str(out), "--draws", "10000000"],
        capsys,
        "draws: 10000000 requested",
        "holds",
    )
    assert not out.exists()


def test_run_dir_missing_files(run_dir, tmp_path, capsys):
    broken = tmp_path / "run"
    shutil.copytree(run_dir, broken)
    (broken / "posterior.nc").unlink()
    cfg = tmp_path / "p.yaml"
    cfg.write_text(yaml.safe_dump(PROJ))
    _fails(["project", str(broken), str(cfg)], capsys, "posterior.nc is missing")
    assert not (broken / "projection").exists()


def test_baseline_shorter_than_a_year(run_dir, tmp_path):
    csv = tmp_path / "short.csv"
    idx = np.arange(24 * 100)
    te = 10 + 5 * np.sin(2 * np.pi * idx / 24)
    lines = ["time,Te,RHe,ghi"] + [
        f"2020-01-01T00:00Z,{t:.2f},70,0".replace("2020-01-01T00:00Z", str(ts))
        for t, ts in zip(
            te, np.datetime64("2020-01-01T00:00") + idx.astype("timedelta64[h]"), strict=True
        )
    ]
    csv.write_text("\n".join(lines))
    bad = {
        **PROJ,
        "baseline": {"format": "csv", "path": str(csv), "time_column": "time", "timezone": "UTC"},
    }
    with pytest.raises(DataError, match=r"baseline: the weather covers 2400 h.*at least a year"):
        project(run_dir, bad, out=tmp_path / "o")
    assert not (tmp_path / "o").exists()


def test_future_file_on_another_site(run_dir, tmp_path, shared_data):
    epw = shared_data / "epw"
    path = sorted(epw.glob("*.epw"))[0]
    bad = {
        **PROJ,
        "morphing": [],
        "files": [
            {"scenario": "x", "horizon": 2080, "weather": {"format": "epw", "path": str(path)}}
        ],
    }
    with pytest.raises(
        InputError,
        match=r"files\[0\]\.weather: the file is for another site.* km from.*"
        r"within 50 km.*allow_other_site: true",
    ):
        project(run_dir, bad, out=tmp_path / "o")
    assert not (tmp_path / "o").exists()
    # the baseline too
    bad = {**PROJ, "baseline": {"format": "epw", "path": str(path)}}
    with pytest.raises(InputError, match=r"^baseline: the file is for another site"):
        project(run_dir, bad, out=tmp_path / "o")
    assert not (tmp_path / "o").exists()
    # said explicitly: accepted
    ok = project(run_dir, {**bad, "allow_other_site": True, "draws": 4}, write=False)
    assert ok.summary["cases"][0]["weather"]["from"] == "projection file (baseline)"


def test_unknown_threshold_indicator_is_refused(run_dir, tmp_path, capsys):
    cfg = tmp_path / "p.yaml"
    cfg.write_text(yaml.safe_dump({**PROJ, "thresholds": [{"indicator": "twpi", "below": 4},
                                                         {"indicator": "metal_corrosion",
                                                          "above": 9}]}))  # fmt: skip
    out = tmp_path / "out"
    _fails(["project", str(run_dir), str(cfg), "--out", str(out)], capsys,
           "thresholds[1].indicator: unknown indicator 'metal_corrosion'", "time_of_wetness",
           "en15757_outside_baseline")  # fmt: skip
    assert not out.exists()


def test_schema_errors_name_keys():
    with pytest.raises(ConfigError, match=r"morphing\[0\]\.method"):
        parse_projection_config({"morphing": [{**_morph("a", 2050, 1), "method": "warp"}]})
    with pytest.raises(ConfigError, match="give at least one future"):
        parse_projection_config({"draws": 5})
    with pytest.raises(ConfigError, match=r"draws"):
        parse_projection_config({**PROJ, "draws": 0})
    with pytest.raises(ConfigError, match="given twice"):
        parse_projection_config({"morphing": [_morph("a", 2050, 1), _morph("a", 2050, 2)]})


# ------------------------------------------------------------------------ browser
_LAYOUT_JS = """(() => {
  const out = {tables: [], scrolls: [], width: window.innerWidth};
  for (const t of document.querySelectorAll('table')) {
    const c = t.parentElement;
    out.tables.push({w: t.getBoundingClientRect().width, cw: c.clientWidth,
                     right: t.getBoundingClientRect().right});
  }
  for (const d of document.querySelectorAll('div.scroll'))
    out.scrolls.push({sw: d.scrollWidth, cw: d.clientWidth});
  out.text = document.body.innerText;
  out.docw = document.documentElement.scrollWidth;
  out.right = Math.max(...[...document.querySelectorAll('nav.toc a, h1, h2, p, figure img')]
                           .map(e => e.getBoundingClientRect().right));
  out.broken = BROKEN;
  return out;
})()""".replace("BROKEN", BROKEN_WORDS)


@pytest.mark.browser
@pytest.mark.parametrize("size", [(1280, 800), (1920, 1080)])
def test_projection_page_in_headless_chromium(proj, size):
    """At 1280 × 800 and 1920 × 1080: no table wider than its container (nothing cut
    or scrolled sideways), the three figures, no percentage above 100 %."""
    chromium = find_chromium()
    if chromium is None:
        pytest.skip("chromium not installed: the page was not opened in a real browser")
    _, out = proj
    path = out / "projection.html"
    res = open_page(path, chromium=chromium, width=size[0], height=size[1], extra_js=_LAYOUT_JS)
    assert res.errors == [], res.errors
    external = [u for u in res.requests[1:] if not u.startswith("data:")]
    assert external == [], external
    dom = res.dom
    assert dom["sections"] == [
        "assumptions",
        "decision",
        "probabilities",
        "climate",
        "risk",
        "uncertainty",
        "indicators",
        "weather",
    ]
    assert dom["figures"] == ["fig-seasonal", "fig-risk", "fig-split"]
    assert dom["scripts"] == 0
    assert all(i["complete"] and i["w"] > 400 and i["h"] > 200 for i in dom["images"])
    lay = dom["extra"]
    assert len(lay["tables"]) >= 5
    for t in lay["tables"]:
        assert t["w"] <= t["cw"] + 0.5 and t["right"] <= lay["width"], t
    for d in lay["scrolls"]:
        assert d["sw"] <= d["cw"], d
    assert lay["docw"] <= lay["width"] and lay["right"] <= lay["width"], lay["right"]
    assert lay["broken"] == [], lay["broken"]  # no number or word cut by a line break
    _no_percentage_above_100(lay["text"])


@pytest.mark.browser
def test_projection_page_on_a_phone_has_no_horizontal_scroll(proj):
    """At 390 px nothing but the sideways-scrolling tables is wider than the screen."""
    chromium = find_chromium()
    if chromium is None:
        pytest.skip("chromium not installed: the page was not opened in a real browser")
    _, out = proj
    res = open_page(
        out / "projection.html", chromium=chromium, width=390, height=844,
        extra_js=PHONE_OVERFLOW_JS,
    )  # fmt: skip
    assert res.errors == [], res.errors
    lay = res.dom["extra"]
    assert lay["docw"] <= lay["W"] <= 390 and lay["wide"] == [], lay
    assert lay["broken"] == [], lay["broken"]


def _no_percentage_above_100(text: str) -> None:
    import re

    found = [float(m) for m in re.findall(r"(-?\d+(?:\.\d+)?)\s?%", text)]
    assert found, "no percentage on the page"
    assert max(found) <= 100.0, sorted(found)[-5:]


def test_a_morphing_run_speaks_of_its_own_weather_not_knmi14(proj):
    """The uncertainty section says what the scenario share leaves out for the weather
    this projection used: morphing deltas here, never the KNMI'14 tables."""
    import html as html_mod
    import re

    from heritage_bayes.projection.page import _scenario_caveat

    _, out = proj
    text = html_mod.unescape(re.sub(r"<[^>]+>", " ", (out / "projection.html").read_text()))
    assert "KNMI'14" not in text and "KNMI’14" not in text
    assert "each morphing case applies one set of monthly changes" in " ".join(text.lower().split())

    def caveat(*methods):
        cases = [{"weather": {"method": m}} for m in methods]
        return _scenario_caveat(type("P", (), {"summary": {"cases": cases}})())

    knmi = "KNMI'14 time-series transformation (Bakker 2015, TR-349)"
    assert caveat(knmi).startswith("The KNMI'14 tables give one change per scenario, so")
    both = caveat(knmi, "user-supplied future weather file")
    assert "KNMI'14" in both and "each future weather file is one realisation" in both
    assert caveat("") == ""


def test_page_and_outputs_have_no_share_above_100(proj):
    import html as html_mod
    import re

    p, out = proj
    text = html_mod.unescape(re.sub(r"<[^>]+>", " ", (out / "projection.html").read_text()))
    text = re.sub(r"data:image/png;base64,\S+", "", text)
    _no_percentage_above_100(text)
    s = json.loads((out / "projection.json").read_text())
    for r in s["probabilities"]:
        assert all(0 <= c["p"] <= 1 for c in r["cases"].values())
    for cls in s["ashrae_best_class"].values():
        assert abs(sum(cls.values()) - 1) < 1e-9
    for n, e in s["indicators"].items():
        if e["unit"] == "% of hours":
            for c in e["cases"].values():
                assert c["q95"] is None or 0 <= c["q95"] <= 100, n


def test_decomposition_sums_to_100(proj):
    """Shares of the decomposition sum to 100 % ± 0.1 for every indicator and group."""
    p, _ = proj
    checked = 0
    for block in p.summary["uncertainty_split"].values():
        for n, e in block["indicators"].items():
            if e["total"]:
                total = sum(v for v in e["share"].values() if v is not None)
                assert abs(100 * total - 100) <= 0.1, (n, e)
                checked += 1
    assert checked > 10


def test_decompose_components_by_construction():
    """decompose() on data built from known parts: the scenario, parameter, noise and
    weather-year variances come back (large samples), and the shares add up to 1."""
    from heritage_bayes.projection.summary import decompose

    rng = np.random.default_rng(3)
    S, K, Y = 4, 4000, 30
    scen = np.array([0.0, 1.0, 2.0, 3.0])[:, None, None]  # variance 1.25
    par = rng.normal(0, 2.0, (1, K, 1))  # parameter variance 4
    year = rng.normal(0, 1.5, (1, 1, Y))  # weather-year variance 2.25
    noise = rng.normal(0, 0.5, (S, K, 1))  # noise variance 0.25 (draw level)
    x = scen + par + year + 0 * noise
    y = x + noise
    d = decompose(y, x)
    v = d["variance"]
    # tolerances: 4 standard errors of each sample variance. Scenario: the noise means
    # per scenario (SE 0.5/√K) move Var_s by 2 Cov_s, SE 2·0.5/√K·√5/4 = 0.0088;
    # parameter: 4·√(2/K) = 9 % relative; noise (S·K values): 4·0.25·√(2/(S K)) = 0.011
    assert v["scenario"] == pytest.approx(1.25, abs=0.035)
    assert v["parameter"] == pytest.approx(4.0, rel=0.09)
    assert v["weather_year"] == pytest.approx(year.var(), rel=1e-9)  # exact: no noise
    assert v["noise"] == pytest.approx(0.25, abs=0.012)
    assert d["total"] == pytest.approx(y.var(), rel=1e-12)
    assert sum(d["share"].values()) == pytest.approx(1.0, abs=1e-12)
    # one scenario, no years: scenario 0, no weather-year share
    d1 = decompose(y[:1, :, 0], x[:1, :, 0])
    assert d1["variance"]["scenario"] == 0 and d1["share"]["weather_year"] is None
    assert sum(v for v in d1["share"].values() if v is not None) == pytest.approx(1.0)


def test_figure_legends_do_not_cover_the_data(proj, monkeypatch):
    """Every legend of the page's figures lies outside every axes."""
    from matplotlib.backends.backend_agg import FigureCanvasAgg

    from heritage_bayes.projection import page

    p, _ = proj
    figs = []
    monkeypatch.setattr(page, "to_png_uri", lambda fig: figs.append(fig) or "data:,")
    page._fig_seasonal(p), page._fig_risk(p), page._fig_split(p)
    assert len(figs) == 3
    for fig in figs:
        FigureCanvasAgg(fig).draw()
        r = fig.canvas.get_renderer()
        legends = list(fig.legends) + [a.get_legend() for a in fig.axes if a.get_legend()]
        for leg in legends:
            lb = leg.get_window_extent(r)
            for ax in fig.axes:
                if ax.get_visible():
                    assert not lb.overlaps(ax.get_window_extent(r)), fig


# ------------------------------------------------------------------ shipped configs
CONFIGS = Path(__file__).resolve().parents[1] / "configs"


def test_shipped_projection_files_validate():
    from heritage_bayes.projection import load_projection_config

    demo = load_projection_config(CONFIGS / "projection_demo.yaml")
    assert [h for _, h in demo.cases()] == [2050, 2050, 2085, 2085]
    knmi = load_projection_config(CONFIGS / "projection_knmi.yaml")
    assert len(knmi.cases()) == 8 and knmi.knmi14.region is None  # from the station


def test_debilt_demo_config():
    from heritage_bayes.config import load_config

    cfg = load_config(CONFIGS / "debilt_demo.yaml")
    assert cfg.data.demo.weather == "debilt_knmi"
    raw = yaml.safe_load((CONFIGS / "debilt_demo.yaml").read_text())
    del raw["data"]["demo"]["weather_path"]
    with pytest.raises(ConfigError, match=r"data\.demo\.weather_path: required"):
        parse_config(raw)


def test_debilt_demo_weather(shared_data):
    """The De Bilt demo: KNMI hourly weather at De Bilt's coordinates, 10 years."""
    from heritage_bayes.demo import virtual_monument

    path = shared_data / "knmi-debilt" / "uurgeg_260_2011-2020.txt.gz"
    w, meas, _, info = virtual_monument(weather="debilt_knmi", weather_path=str(path))
    assert info["site"]["latitude"] == pytest.approx(52.10)
    assert w.index[0].year == 2011 and len(meas) > 8 * 8760
    assert info["station"] == "260"


def test_projection_of_a_run_with_a_weekly_calendar(tmp_path):
    """A thermostat with weekly hours of use: the projection generates ``hours_of_use``
    on its own dates (the calibrated use goes on) instead of stopping for a missing
    input."""
    import copy

    from heritage_bayes.run import load_run

    raw = copy.deepcopy(TINY)
    raw["thermal"] = {
        "model": "thermal_1c",
        "options": {"thermostat": {"schedule": {"weekly": ["Sun 08-12"], "timezone": "UTC"}}},
    }
    out = tmp_path / "run"
    run_calibration(parse_config(raw), out_dir=out, report=False, quiet=True)
    p = project(out, {**PROJ, "draws": 8}, out=tmp_path / "p")
    assert np.isfinite(p.dataset["Ti_monthly"].values).all()
    run = load_run(out)
    from heritage_bayes.projection.weather import baseline_weather, model_inputs

    pcfg = parse_projection_config({**PROJ, "draws": 8})
    weather, site, _ = baseline_weather(run, pcfg)
    U = model_inputs(run, pcfg, weather, site, "baseline")
    use = U["hours_of_use"].to_numpy()
    sunday_morning = (U.index.day_of_week == 6) & (U.index.hour >= 8) & (U.index.hour < 12)
    assert np.array_equal(use, sunday_morning.astype(float))


def test_several_baseline_years_give_a_weather_year_share(run_dir, tmp_path):
    """A two-year baseline (the demo's year twice, the second 1 K warmer): the per-year
    indicators get a weather-year share, the shares still sum to 1, and the baseline's
    own EN 15757 baseline-band share is the one a future equal to it gets."""
    import pandas as pd

    from heritage_bayes.run import load_run
    from heritage_bayes.sources import read_sources

    w = read_sources(load_run(run_dir).config).weather
    # two years and two days (the grid may lose an hour at either end)
    two = pd.concat([w, w, w], ignore_index=True).iloc[: 2 * 8760 + 48]
    two.index = pd.date_range(w.index[0], periods=len(two), freq="h")
    two.iloc[8760:, two.columns.get_loc("Te")] += 1.0
    csv = tmp_path / "two_years.csv"
    cols = [c for c in ("Te", "RHe", "ghi", "dni", "dhi") if c in two.columns]
    two[cols].rename_axis("time").to_csv(csv)
    cfg = {
        **PROJ,
        "draws": 8,
        "baseline": {"format": "csv", "path": str(csv), "time_column": "time"},
        "morphing": [_morph("same", 2050, 0.0), _morph("warm", 2050, SHIFT)],
    }
    p = project(run_dir, cfg, write=False)
    assert [c["years"] for c in p.summary["cases"]] == [2, 2, 2]
    e = p.summary["uncertainty_split"]["baseline"]["indicators"]["twpi"]
    assert e["variance"]["weather_year"] > 0 and e["basis"].startswith("one year's value")
    assert sum(e["share"].values()) == pytest.approx(1.0, abs=1e-9)
    col = "en15757_outside_baseline"
    same = p.results[1].predictive[col].to_numpy()
    np.testing.assert_array_equal(same, p.results[0].predictive[col].to_numpy())


# ------------------------------------------------------------------ decisions first
def test_degenerate_indicators_are_said_once_and_get_no_shares(run_dir, tmp_path, monkeypatch):
    """An indicator constant in every draw and case (here the EN 15757 band's offsets,
    held at a minimum band wider than the tiny room's fluctuations) is flagged, named once
    in the verdict at the top, and has no row in the decision or variance-share tables;
    decompose() gives it no shares even when rounding leaves a variance of 1e-30 (the
    "1250 %" of a 300-draw run)."""
    import html as html_mod
    import re

    from heritage_bayes.climate.risk.registry import indicator_info
    from heritage_bayes.climate.risk.standards import en15757_band
    from heritage_bayes.projection.summary import decompose

    monkeypatch.setitem(en15757_band.__kwdefaults__, "min_band", 15.0)  # the option's default
    out = tmp_path / "p"
    p = project(run_dir, PROJ, out=out)
    s = json.loads((out / "projection.json").read_text())
    const = [n for n, e in s["indicators"].items() if e["degenerate"]]
    assert const, "the fixture has constant indicators (the EN 15757 offsets)"
    for n in const:
        v = np.concatenate([r.predictive[n].to_numpy(float) for r in p.results])
        assert np.nanmax(v) == np.nanmin(v), n
        for block in s["uncertainty_split"].values():
            assert block["indicators"][n]["degenerate"]
            assert all(x is None for x in block["indicators"][n]["share"].values())
    varying = [n for n, e in s["indicators"].items() if not e["degenerate"]]
    assert varying
    html = (out / "projection.html").read_text()
    verdict = html[html.index("id='verdict'") : html.index("</div>", html.index("id='verdict'"))]
    assert html.index("id='verdict'") < html.index("<h2")  # above the first section
    assert "worse in" in verdict and "Constant in every draw" in verdict
    for n in const:
        name = html_mod.escape(indicator_info(n).name)
        assert name in verdict
        for sec in ("split", "decision'"):  # no row in the share or decision tables
            for table in re.findall(rf"<table class='{sec}.*?</table>", html, flags=re.S):
                assert f"<td>{name}</td>" not in table and f"<b>{name}</b>" not in table
    y = np.full((2, 300), 14.0) + np.random.default_rng(0).normal(0, 1e-15, (2, 300))
    d = decompose(y, np.full((2, 300), 14.0))
    assert d["degenerate"] and all(v is None for v in d["share"].values())


def test_ashrae_sentence_gives_required_share_and_closest_class():
    """ "none" in every draw is said with the required share of the hours and the class
    that comes closest (median share of hours), not as "none 100 %"."""
    from types import SimpleNamespace

    from heritage_bayes.projection.page import _ashrae_html

    def ind(q50):
        return {"cases": {"baseline": {"q05": q50 - 2, "q50": q50, "q95": q50 + 1}}}

    shares = {"AA": 5.0, "As": 10.0, "A": 20.0, "B": 60.0, "C": 87.0}
    summary = {
        "ashrae_best_class": {"baseline": {"none": 1.0}},
        "indicators": {f"ashrae_{c}": ind(v) for c, v in shares.items()},
    }
    text = _ashrae_html(SimpleNamespace(labels=["baseline"], summary=summary))
    assert "no class reaches the required 95 % of the hours in any draw" in text
    assert "closest: C with 87 %" in text
    assert "none 100 %" not in text and "B <span class='nowrap'>60<" in text
    summary["ashrae_best_class"]["baseline"] = {"none": 0.25, "C": 0.75}
    text = _ashrae_html(SimpleNamespace(labels=["baseline"], summary=summary))
    assert "best class reached: C in 75 % of the draws, none in 25 % of the draws" in text
