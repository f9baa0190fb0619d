"""Every shipped config's numbers do not move: a guard for changes that should change no
result (refactorings above all).

What is compared with the values recorded in ``reference_outputs.json`` (beside this
file):

- **Each calibration config** in ``configs/`` and each room of
  ``configs/portfolio_demo.yaml`` (its defaults and overrides merged): the data are
  prepared as ``hbayes calibrate`` prepares them, and for each section the model's name,
  the parameter names, the checksums of the model inputs and observations over the whole
  prepared frame (a plain and a position-weighted sum: a moved row or a swapped column
  shows), the log-likelihood, the log-posterior (priors, time-constant prior, tempering)
  and the estimated initial state at one fixed parameter vector: every free parameter at
  its prior's centre (the median of a log-normal, the mean of a normal, the geometric
  mean of a log-uniform's bounds, the middle of a uniform's), fixed ones at their value.
  The vector itself is recorded too, so that a moved prior shows by name.
- **A tiny calibration run** of the virtual monument (``thermal_1c`` + ``hygric_1c``
  on ten days, a 10-generation MAP search and 100 sampler steps, no ladder): the sums of
  every numeric variable of ``posterior.nc`` and the whole of ``summary.json`` but for
  what differs between two runs of one tree (times, versions, the creation date) and the
  config's provenance and hash (a settings refactoring may reorder the recorded
  config). The whole path (MAP search, sampler, run outputs) runs, so a change in any
  of them shows.
- **The projection configs** ``projection_demo.yaml``, ``projection_interventions.yaml``
  and ``projection_knmi.yaml`` projected from that run with 4 draws: the sums of every
  numeric variable of the projection's dataset (every case, indicator, measure and
  cost). ``projection_knmi.yaml`` is written for a run on De Bilt weather, whose KNMI
  station gives the KNMI'14 region; the tiny run's demo weather is no station file, so
  it is projected with the region of De Bilt's station (:data:`KNMI_STATION`) given,
  its one year of baseline weather under the file's eight futures (a De Bilt run of its
  own would cost a second calibration and ten years of weather).

Floats agree to 12 significant digits: the same arithmetic gives the same bits, and the
margin only admits a numpy or BLAS that sums in another order. The configs' numbers
(one likelihood evaluation each) hold on every machine. The tiny run and the
projections from it do not: the MAP search and the sampler amplify a last-bit rounding
difference into other draws, and the last bits depend on the *numerical platform*:
the processor's vector instructions that numpy dispatches to (its exp and log differ by
an ulp between AVX2 and AVX-512 code), the BLAS kernel, the processor numba compiles
for, and the numerical libraries' versions (:func:`platform_fingerprint`). Their
values are therefore recorded per platform (``platforms`` in the record): on a platform
with a record they must agree to 12 digits; on one without, the test checks what no
rounding moves (every key, group, parameter name and list length, the value types) and
says that the values were not compared. Configs that read ``../shared/data`` skip,
saying so, when it is not beside the checkout.

Re-recording: ``PYTHONPATH=src python tests/test_reference_outputs.py`` rewrites
``reference_outputs.json`` from the current tree, keeping the tiny run's values for this
platform only (the other platforms' would be stale). That is legitimate only in a commit
that means to change a result (a fix in the physics or the data reading, a new default,
a shipped config edited) and that says in its message which numbers moved and why.
``--add-platform`` records this platform's tiny run beside the others and leaves every
other entry as it is: for a machine or a dependency version the record has not seen,
after checking that the configs' numbers hold (they are the platform-free guard). A
refactoring re-records nothing: if this test fails after one, the refactoring changed
behaviour. The values were first recorded on commit 212f59b.

Cost: the nine configs' preparations and two likelihood evaluations each, the tiny run
and three projections: 21 s of CPU for the module alone (imports and numba compilation
included, which the full suite pays once anyway).
"""

from __future__ import annotations

import json
import math
import re
import sys
from functools import cache
from pathlib import Path

import numpy as np
import pytest

from _platform import NUMERICAL_LIBRARIES, platform_fingerprint, platform_info

ROOT = Path(__file__).resolve().parents[1]
CONFIGS = ROOT / "configs"
RECORD = Path(__file__).with_name("reference_outputs.json")
SHARED_DATA = ROOT.parent / "shared" / "data"

#: The calibration configs: file stem, or ``portfolio_demo/<room>`` for a portfolio's room.
CALIBRATIONS = (
    "demo",
    "debilt_demo",
    "orholm",
    "annisse",
    "trh1_attic",
    "armadillo",
    "portfolio_demo/hall",
    "portfolio_demo/hall_logger2",
    "portfolio_demo/draughty_hall",
)
#: The projection configs projected from the tiny run.
PROJECTIONS = ("projection_demo", "projection_interventions", "projection_knmi")
#: The KNMI station whose region a ``knmi14`` projection of the tiny run takes: 260, De
#: Bilt, the station of ``configs/debilt_demo.yaml``'s weather, the run
#: ``projection_knmi.yaml`` is written for.
KNMI_STATION = 260
#: Draws of each projection (the files' own 100-200 cost seconds each).
PROJECTION_DRAWS = 4
#: Significant digits every float must keep.
RTOL = 1e-12


# ---------------------------------------------------------------------- the numbers
def _config(key: str):
    """The validated config of ``key`` (see :data:`CALIBRATIONS`)."""
    from heritage_bayes.config import load_config, parse_config
    from heritage_bayes.portfolio.spec import load_portfolio

    if "/" not in key:
        return load_config(CONFIGS / f"{key}.yaml")
    stem, room = key.split("/")
    spec = {r.name: r for r in load_portfolio(CONFIGS / f"{stem}.yaml").rooms}[room]
    return parse_config(spec.raw, source=str(spec.config_path), base_dir=spec.base_dir)


def _needs_shared_data(key: str) -> bool:
    return "shared/data" in (CONFIGS / f"{key.split('/')[0]}.yaml").read_text(encoding="utf-8")


def _prior_centre(p) -> float:
    """The fixed value of a parameter, else the centre of its prior."""
    if p.fixed is not None:
        return float(p.fixed)
    pr = p.prior
    if pr.dist in ("normal", "lognormal"):
        return float(pr.mu)
    if pr.dist == "loguniform":
        return math.sqrt(pr.lower * pr.upper)
    return 0.5 * (pr.lower + pr.upper)


def _checksums(a: np.ndarray) -> list[float]:
    """A plain and a position-weighted sum of a (rows, columns) array (NaN skipped)."""
    a = np.asarray(a, dtype=float).reshape(len(a), -1)
    w = np.linspace(1.0, 2.0, len(a))[:, None] * np.arange(1, a.shape[1] + 1)[None, :]
    return [float(np.nansum(a)), float(np.nansum(a * w))]


def calibration_values(key: str) -> dict:
    """section -> the recorded numbers of one calibration config."""
    from heritage_bayes.calibration.ladder import section_log_posterior
    from heritage_bayes.models import SECTIONS, build_model
    from heritage_bayes.prepare import prepare

    cfg = _config(key)
    prep = prepare(cfg)
    if (fixed := prep.sources.get("fixed_node_temperature")) is not None:
        cfg = cfg.model_copy(update={"fixed_node_temperature": fixed["value"]})  # as calibrate
    out = {}
    for section in SECTIONS:
        if getattr(cfg, section) is None:
            continue
        model = build_model(cfg, section)
        lp = section_log_posterior(cfg, prep, section, model, getattr(cfg, section).priors)
        theta = np.array([[_prior_centre(p) for p in lp.params.parameters]])
        u, y = prep.model_inputs(section, model), prep.observed(section, model)
        start = lp.initial_states(theta)
        out[section] = {
            "model": model.name,
            "names": list(lp.params.names),
            "point": [float(v) for v in theta[0]],
            "rows": len(u),
            "observed_finite": int(np.isfinite(y).sum()),
            "inputs": _checksums(u),
            "observed": _checksums(y),
            "log_likelihood": float(lp.log_likelihood(theta)[0]),
            "log_posterior": float(lp(lp.params.to_unconstrained(theta))[0]),
            "initial_state": None if start is None else [float(v) for v in start[0]],
        }
    return out


#: The tiny run: the report tests' ten days, with smaller budgets and no ladder.
def _tiny_config() -> dict:
    from test_report import TINY

    return dict(
        TINY,
        ladder=False,
        sampler={"max_steps": 100, "check_every": 100},
        optimizer={"maxiter": 10, "starts": 1, "popsize": 4},
    )


def _dataset_sums(ds) -> dict:
    """variable -> the sum of its finite values, for every numeric variable."""
    out = {}
    for name, var in sorted(ds.data_vars.items()):
        a = np.asarray(var.values)
        if a.dtype.kind in "fiub":
            out[str(name)] = float(np.nansum(a.astype(float)))
    return out


def run_values(run_dir: Path) -> dict:
    """The recorded numbers of the tiny run: ``posterior.nc``'s sums and the MAPs."""
    from heritage_bayes.run import load_run

    r = load_run(run_dir)
    groups = {g: _dataset_sums(r.idata[g]) for g in sorted(r.idata.groups())}
    summary = json.loads((run_dir / "summary.json").read_text(encoding="utf-8"))
    return {"posterior.nc": groups, "summary.json": _steady(summary)}


#: ``summary.json``'s keys that differ between two runs of the same tree.
VOLATILE = {
    "created_at", "heritage_bayes_version", "versions", "timings", "wall_seconds",
    "cpu_seconds", "provenance", "config_hash", "schema_version",
}  # fmt: skip
#: The install folder in a path (of a virtual environment or a system Python).
_SITE_PACKAGES = re.compile(r"\S*[\\/](?:site|dist)-packages[\\/]")


def _steady(d):
    """``d`` without the :data:`VOLATILE` keys, at every depth, and with the install
    folder left out of file paths (``.../site-packages/pvlib/data/...`` ->
    ``pvlib/data/...``): where the package's environment lives is not an output."""
    if isinstance(d, str):
        return _SITE_PACKAGES.sub("", d)
    if isinstance(d, dict):
        return {k: _steady(v) for k, v in d.items() if k not in VOLATILE}
    if isinstance(d, list):
        return [_steady(v) for v in d]
    return d


def projection_values(run_dir: Path, name: str) -> dict:
    """The recorded numbers of one projection config on the tiny run (a ``knmi14``
    projection with the region of :data:`KNMI_STATION`)."""
    from heritage_bayes.climate.morph import knmi14_region
    from heritage_bayes.projection import project
    from heritage_bayes.projection.config import load_projection_config

    pcfg = load_projection_config(CONFIGS / f"{name}.yaml")
    if pcfg.knmi14 is not None and pcfg.knmi14.region is None:
        region = knmi14_region(pcfg.path(pcfg.knmi14.tables), KNMI_STATION)
        pcfg = pcfg.model_copy(update={"knmi14": pcfg.knmi14.model_copy(update={"region": region})})
    p = project(run_dir, pcfg, draws=PROJECTION_DRAWS, write=False)
    return {"labels": list(p.labels), "dataset": _dataset_sums(p.dataset)}


def _tiny_run(out: Path) -> Path:
    from heritage_bayes.calibration.calibrate import run_calibration
    from heritage_bayes.config import parse_config

    run_calibration(parse_config(_tiny_config()), out_dir=out, report=False, quiet=True)
    return out


# ---------------------------------------------------------------------- comparison
def _differences(got, ref, where: str = "", values: bool = True) -> list[str]:
    """Where ``got`` differs from ``ref``: the keys at every depth and the lists'
    lengths, and with ``values`` the values too (floats to :data:`RTOL`, the rest
    exactly)."""
    if isinstance(ref, dict) and isinstance(got, dict):
        if sorted(got) != sorted(ref):
            return [f"{where}: keys {sorted(set(got) ^ set(ref))} differ"]
        return [d for k in ref for d in _differences(got[k], ref[k], f"{where}/{k}", values)]
    if isinstance(ref, list) and isinstance(got, list | tuple):
        if len(got) != len(ref):
            return [f"{where}: {len(got)} items, recorded {len(ref)}"]
        pairs = enumerate(zip(got, ref, strict=True))
        return [d for i, (g, r) in pairs for d in _differences(g, r, f"{where}[{i}]", values)]
    if not values:
        return []
    if isinstance(ref, float) and isinstance(got, float | int):
        if got == ref or abs(got - ref) <= RTOL * max(abs(ref), abs(got)):
            return []
        return [f"{where}: {got!r}, recorded {ref!r}"]
    return [] if got == ref else [f"{where}: {got!r}, recorded {ref!r}"]


def _shape_differences(got, ref, where: str = "") -> list[str]:
    """Where ``got`` differs from ``ref`` in what no rounding moves: the keys at every
    depth (groups, variables, parameters, summary fields) and the lists' lengths. The
    values are not compared, strings included: a parameter on a prior bound, or not, is
    as much the chain's as its median."""
    return _differences(got, ref, where, values=False)


def _assert_platform_recorded(got, key: str, capsys) -> None:
    """``got`` against this platform's record of ``key``; on a platform without one,
    against the shape of any platform's record (and say so)."""
    platforms = _recorded().get("platforms", {})
    info = platform_info()
    mine = platforms.get(platform_fingerprint(info))
    if mine is not None:
        diffs = _differences(got, mine[key], key)
        assert not diffs, "changed from the recorded values:\n  " + "\n  ".join(diffs[:20])
        return
    assert platforms, f"{RECORD.name} holds no platform's tiny run"
    ref = next(iter(platforms.values()))[key]
    diffs = _shape_differences(got, ref, key)
    assert not diffs, "changed from the recorded shape:\n  " + "\n  ".join(diffs[:20])
    with capsys.disabled():
        print(
            f"\n{key}: no record for this numerical platform ({platform_fingerprint(info)}: "
            f"{info['machine']}, {info['numba_cpu']}, SIMD {'/'.join(info['simd'])}, "
            f"{'; '.join(info['blas'])}); its shape was checked, not its values "
            f"(record them: python tests/test_reference_outputs.py --add-platform)"
        )


@cache
def _recorded() -> dict:
    return json.loads(RECORD.read_text(encoding="utf-8"))


def _assert_recorded(got, key: str) -> None:
    diffs = _differences(got, _recorded()[key], key)
    assert not diffs, "changed from the recorded values:\n  " + "\n  ".join(diffs[:20])


# ---------------------------------------------------------------------- the tests
@pytest.mark.parametrize("key", CALIBRATIONS)
def test_calibration_config_gives_the_recorded_numbers(key):
    if _needs_shared_data(key) and not SHARED_DATA.is_dir():
        pytest.skip(f"configs/{key}.yaml reads ../shared/data, not found at {SHARED_DATA}")
    _assert_recorded(calibration_values(key), key)


@pytest.fixture(scope="module")
def tiny_run(tmp_path_factory) -> Path:
    return _tiny_run(tmp_path_factory.mktemp("reference") / "run")


def test_tiny_run_gives_the_recorded_outputs(tiny_run, capsys):
    _assert_platform_recorded(run_values(tiny_run), "tiny_run", capsys)


@pytest.mark.parametrize("name", PROJECTIONS)
def test_projection_config_gives_the_recorded_outputs(tiny_run, name, capsys):
    if _needs_shared_data(name) and not SHARED_DATA.is_dir():
        pytest.skip(f"configs/{name}.yaml reads ../shared/data, not found at {SHARED_DATA}")
    _assert_platform_recorded(projection_values(tiny_run, name), name, capsys)


def test_the_shape_check_sees_a_missing_key_and_a_shorter_list():
    """The check that stands on a platform without a record can fail: it names a key
    that went missing and a list that changed length, and lets values move."""
    ref = {"posterior": {"a": 1.0, "b": [1.0, 2.0]}, "summary": {"model": "thermal_1c"}}
    assert _shape_differences(ref, ref) == []
    assert _shape_differences({**ref, "posterior": {"a": 3.5, "b": [9.0, 8.0]}}, ref) == []
    got = {"posterior": {"a": 1.0, "b": [1.0]}, "summary": {}}
    diffs = _shape_differences(got, ref)
    assert any("b: 1 items, recorded 2" in d for d in diffs), diffs
    assert any("keys ['model'] differ" in d for d in diffs), diffs


def test_the_platform_fingerprint_names_what_changes_the_last_bits():
    info = platform_info()
    assert set(NUMERICAL_LIBRARIES) <= set(info["versions"])
    assert info["machine"] and info["numba_cpu"]
    assert platform_fingerprint(info) == platform_fingerprint(dict(info))
    other = {**info, "versions": {**info["versions"], "numpy": "0.0.0"}}
    assert platform_fingerprint(other) != platform_fingerprint(info)


def _record(add_platform: bool = False) -> None:
    """Rewrite :data:`RECORD` from the current tree (see the module docstring); with
    ``add_platform`` only this platform's tiny-run entry is (re)written."""
    import tempfile

    values = dict(_recorded()) if add_platform else {}
    if not add_platform:
        values.update({key: calibration_values(key) for key in CALIBRATIONS})
    info = platform_info()
    entry = {"platform": info}
    with tempfile.TemporaryDirectory() as tmp:
        run_dir = _tiny_run(Path(tmp) / "run")
        entry["tiny_run"] = run_values(run_dir)
        entry.update({name: projection_values(run_dir, name) for name in PROJECTIONS})
    platforms = dict(values.get("platforms", {})) if add_platform else {}
    platforms[platform_fingerprint(info)] = entry
    values["platforms"] = platforms
    for key in ("tiny_run", *PROJECTIONS):  # the record's layout before platforms
        values.pop(key, None)
    RECORD.write_text(json.dumps(values, indent=1, ensure_ascii=False) + "\n", encoding="utf-8")
    print(f"recorded {len(values)} entries ({len(platforms)} platforms) in {RECORD}")


if __name__ == "__main__":
    sys.path.insert(0, str(Path(__file__).parent))  # test_report's TINY
    _record(add_platform="--add-platform" in sys.argv[1:])
