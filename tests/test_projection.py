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

from _report_browser import find_chromium, open_page
from heritage_bayes.calibrate import run_calibration
from heritage_bayes.cli import main
from heritage_bayes.config import parse_config
from heritage_bayes.errors import ConfigError, DataError, InputError
from heritage_bayes.projection import parse_projection_config, project
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
        ".hbayes-run.json",  # the marker: the folder and the three files are the package's
        "projection.html",
        "projection.json",
        "projection.nc",
    ]
    from heritage_bayes.rundir.marker import read_marker

    marker = read_marker(out)
    assert marker.kind == "projection"
    assert marker.files == ("projection.html", "projection.json", "projection.nc")
    import xarray as xr

    ds = xr.open_dataset(out / "projection.nc", engine="h5netcdf")
    assert list(ds["case"].values) == ["baseline", "warm 2050", "mild 2050"]
    assert ds.sizes["draw"] == DRAWS and ds.sizes["month"] == 12
    for v in ("twpi", "vtt_mould_index_max", "emc_range", "en15757_outside", "Ti_monthly"):
        assert v in ds
    assert "twpi_parametric" in ds
    s = json.loads((out / "projection.json").read_text())
    assert s["draws"] == DRAWS and len(s["cases"]) == 3
    assert s["cases"][0]["hours"] == 8759  # a TMY year on the UTC grid: not refused
    stmts = {r["indicator"] for r in s["probabilities"]}
    assert {"vtt_mould_index_max", "twpi"} <= stmts
    for r in s["probabilities"]:
        for c in r["cases"].values():
            assert 0.0 <= c["p"] <= 1.0
    assert set(s["uncertainty_split"]) == {"2050"}


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
    split = p.summary["uncertainty_split"]["2050"]["twpi"]
    assert split["variance"]["model_error"] > 0
    assert split["variance"]["scenario"] > 0
    assert abs(sum(split["share"].values()) - 1) < 1e-9


def test_noise_free_projection_is_parametric(run_dir):
    p = project(run_dir, {**PROJ, "noise": False, "draws": 6}, write=False)
    ds = p.dataset
    np.testing.assert_allclose(ds["twpi"].values, ds["twpi_parametric"].values)
    assert p.summary["noise"] is None


def test_probability_table(proj):
    p, _ = proj
    t = p.probability_table()
    assert list(t.columns) == p.labels
    assert any(i.startswith("P(vtt_mould_index_max > 1") for i in t.index)


def test_cli_project(run_dir, tmp_path, capsys):
    cfg = tmp_path / "p.yaml"
    cfg.write_text(yaml.safe_dump(PROJ))
    out = tmp_path / "out"
    assert main(["project", str(run_dir), str(cfg), "--out", str(out), "--draws", "8"]) == 0
    stdout = capsys.readouterr().out
    assert "P(twpi < 45 years)" in stdout and "warm 2050" in stdout
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
    with pytest.raises(InputError, match=r"files\[0\]\.weather: the file is for another site"):
        project(run_dir, bad, out=tmp_path / "o")
    assert not (tmp_path / "o").exists()


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
@pytest.mark.browser
def test_projection_page_in_headless_chromium(proj):
    chromium = find_chromium()
    if chromium is None:
        pytest.skip("chromium not installed: the page was not opened in a real browser")
    _, out = proj
    path = out / "projection.html"
    res = open_page(path, chromium=chromium, width=1280, height=1600)
    assert res.errors == [], res.errors
    external = [u for u in res.requests[1:] if not u.startswith("data:")]
    assert external == [], external
    dom = res.dom
    assert dom["sections"] == [
        "assumptions",
        "probabilities",
        "climate",
        "risk",
        "uncertainty",
        "weather",
    ]
    assert dom["figures"] == ["fig-fans", "fig-risk"]
    assert dom["scripts"] == 0
    assert all(i["complete"] and i["w"] > 400 and i["h"] > 200 for i in dom["images"])


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
