"""Fault injection at the level of the ``hbayes`` process (issue 15).

Every case runs ``python -m heritage_bayes.cli`` as a subprocess, as a user would, and
checks what the user sees (exit code, one clear message, no traceback) and what is left
on disk:

- user errors (config, data, ``--out``, run directory; batch, project and compare
  configs through the same strict loader; names and output paths that would reach
  outside the output folder; the time budget spent in the MAP search): exit 2 naming
  the key or file, every file in the case's folder unchanged (symlinks included);
- SIGINT/SIGTERM at seeded random instants while the data are prepared, during the MAP
  search, during sampling and while the outputs are written: exit 130, then ``--resume``
  gives the chain of an uninterrupted run, bit for bit;
- damaged checkpoints (rows beyond the commit, no random state, a corrupt chunk,
  truncated, not HDF5, made for other data): resumed from the valid prefix with a
  warning, or exit 2 explaining what is wrong;
- two runs into one ``--out``, a failed re-run over a finished run, a full disk (a tiny
  tmpfs; skipped where mounting is not permitted).

The runs are tiny (three weeks of the demo, ``thermal_1c``, 300 steps, no ladder, no
report) and run two at a time: the machine has two cores.
"""

from __future__ import annotations

import json
import os
import random
import shutil
import signal
import subprocess
import sys
import threading
import time
from concurrent.futures import ThreadPoolExecutor
from pathlib import Path

import h5py
import numpy as np
import pandas as pd
import pytest
import yaml

SRC = Path(__file__).resolve().parents[1] / "src"
STEPS = 300
#: The tiny runs stop at STEPS before converging: a finished, unconverged run (exit 3).
DONE = 3

TINY = {
    "name": "faults",
    "seed": 3,
    "data": {"demo": {}},
    "room_volume": 400,
    "periods": {
        "calibration": {"start": "2019-01-02", "end": "2019-01-16"},
        "validation": {"start": "2019-01-16", "end": "2019-01-21"},
        "warmup": "2D",
        "init_window": "2D",
    },
    "thermal": {"model": "thermal_1c", "noise": "ar1"},
    "sampler": {"max_steps": STEPS, "check_every": 50, "max_draws": 200, "n_predictive": 20},
    "optimizer": {"maxiter": 10, "starts": 1},
    "ladder": False,
    "report": False,
}


def _env() -> dict:
    env = dict(os.environ)
    env["PYTHONPATH"] = os.pathsep.join([str(SRC), env.get("PYTHONPATH", "")]).rstrip(os.pathsep)
    env["PYTHONFAULTHANDLER"] = "1"  # a crash would print where
    return env


#: ``hbayes`` as started from a terminal: Ctrl-C (SIGINT) delivered, even when the test
#: runs as a background job, whose children inherit SIGINT ignored
_MAIN = (
    "import signal, sys; signal.signal(signal.SIGINT, signal.default_int_handler); "
    "from heritage_bayes.cli import main; sys.exit(main(sys.argv[1:]))"
)


def _cmd(*args) -> list[str]:
    return [sys.executable, "-c", _MAIN, *map(str, args)]


def _hbayes(*args, cwd=None) -> tuple[int, str]:
    p = subprocess.run(
        _cmd(*args), capture_output=True, text=True, env=_env(), cwd=cwd, check=False
    )
    return p.returncode, p.stderr


def _write(path: Path, cfg) -> Path:
    path.parent.mkdir(parents=True, exist_ok=True)
    if isinstance(cfg, bytes):
        path.write_bytes(cfg)
    elif isinstance(cfg, str):
        path.write_text(cfg, encoding="utf-8")
    else:
        path.write_text(yaml.safe_dump(cfg, sort_keys=False), encoding="utf-8")
    return path


def _tiny(**changes) -> dict:
    cfg = json.loads(json.dumps(TINY))
    for key, value in changes.items():
        node = cfg
        *head, last = key.split(".")
        for k in head:
            node = node[k]
        node[last] = value
    return cfg


def _committed(path: Path) -> np.ndarray:
    """The committed chain of a checkpoint (rows up to the commit)."""
    with h5py.File(path, "r") as f:
        n = json.loads(f.attrs["commit"])["iteration"]
        return f["chain"][:n]


def _clean(err: str) -> bool:
    return "Traceback" not in err and "emcee: Exception" not in err and len(err) < 4000


# ----------------------------------------------------------------- user errors: exit 2
def _csv_files(
    d: Path, *, rh_scale=1.0, ti_offset=0.0, ti_scale=1.0, logger_rows=None, observed=None
) -> None:
    """Three weeks of hourly weather and logger tables (January 2019, UTC); the logger
    with ``logger_rows`` rows, and readings only in its first ``observed`` rows."""
    t = np.arange(24 * 21)
    time_ = [f"2019-01-{1 + h // 24:02d} {h % 24:02d}:00" for h in t]
    te = 5 + 4 * np.sin(2 * np.pi * t / 24)
    ti = 10 + 1.5 * np.sin(2 * np.pi * (t - 4) / 24)
    rh = 70 + 5 * np.cos(2 * np.pi * t / 24)
    weather = "time,Te,RHe\n" + "".join(
        f"{a},{b:.2f},{c:.1f}\n" for a, b, c in zip(time_, te, rh, strict=True)
    )
    logger = "time,T,RH\n" + "".join(
        f"{a},{b * ti_scale + ti_offset:.2f},{c * rh_scale:.3f}\n"
        if observed is None or i < observed
        else f"{a},,\n"
        for i, (a, b, c) in enumerate(zip(time_, ti, rh, strict=True))
        if logger_rows is None or i < logger_rows
    )
    (d / "weather.csv").write_text(weather, encoding="utf-8")
    (d / "logger.csv").write_text(logger, encoding="utf-8")


def _csv_config(**source) -> dict:
    cfg = {k: v for k, v in TINY.items() if k not in ("data", "room_volume")}
    cfg["data"] = {
        "weather": {"format": "csv", "path": "weather.csv", "time_column": "time",
                    "timezone": "UTC", "columns": {"Te": "Te", "RHe": "RHe"}},
        "measurements": {"format": "csv", "path": "logger.csv", "time_column": "time",
                         "timezone": "UTC", "columns": {"Ti": "T", "RHi": "RH"}},
        "irradiance": "none",
        "ground_temperature": {"mode": "constant", "value": 8},
    }  # fmt: skip
    cfg["data"]["measurements"].update(source)
    return cfg


def _bomb() -> str:
    lines = ['a0: &a0 ["x", "x", "x", "x", "x", "x", "x", "x", "x", "x"]']
    for i in range(1, 7):
        lines.append(f"a{i}: &a{i} [" + ", ".join([f"*a{i - 1}"] * 10) + "]")
    return "\n".join(lines) + "\nnotes: *a6\n" + yaml.safe_dump(TINY)


def _case_config(text):
    def setup(d: Path):
        return ["calibrate", _write(d / "c.yaml", text), "--out", d / "run"]

    return setup


def _case_data(cfg, **files):
    def setup(d: Path):
        _csv_files(d, **files)
        return ["calibrate", _write(d / "c.yaml", cfg), "--out", d / "run"]

    return setup


def _case_damaged_gz(kind):
    def setup(d: Path):
        import gzip

        _csv_files(d)
        blob = gzip.compress((d / "weather.csv").read_bytes())
        blob = blob[: len(blob) // 2] if kind == "truncated" else blob[:30] + b"\xff" * 40
        (d / "weather.csv.gz").write_bytes(blob)
        cfg = _csv_config()
        cfg["data"]["weather"]["path"] = "weather.csv.gz"
        return ["calibrate", _write(d / "c.yaml", cfg), "--out", d / "run"]

    return setup


def _case_out(kind):
    def setup(d: Path):
        cfg = _write(d / "c.yaml", TINY)
        (d / "afile").write_text("x", encoding="utf-8")
        if kind == "file":
            return ["calibrate", cfg, "--out", d / "afile"]
        if kind == "under_file":
            return ["calibrate", cfg, "--out", d / "afile" / "run"]
        (d / "mine").mkdir()  # a user's folder, not a run directory
        for name in ("config.yaml", "summary.json", "report.html"):
            (d / "mine" / name).write_text(f"my own {name}", encoding="utf-8")
        return ["calibrate", cfg, "--out", d / "mine"]

    return setup


def _case_report_bad_config(d: Path):
    run = d / "run"
    run.mkdir()
    for name in ("posterior.nc", "summary.json"):
        (run / name).write_text("{}", encoding="utf-8")
    (run / "config.yaml").write_text("name: [unclosed\n", encoding="utf-8")
    return ["report", run]


def _case_seed_arg(d: Path):
    return ["calibrate", _write(d / "c.yaml", TINY), "--out", d / "run", "--seed", "-5"]


def _case_portfolio(text, *extra, room_config=None):
    """``hbayes batch`` on a portfolio file ``text`` (a room config ``c.yaml`` beside)."""

    def setup(d: Path):
        _write(d / "c.yaml", TINY if room_config is None else room_config)
        return ["batch", _write(d / "p.yaml", text), "--out", d / "out", *extra]

    return setup


_SHADOW = "root:$6$SECRET1:19000:0:99999:7:::\ndaemon:*:SECRET2:0:99999:7:::\n"
_ROOMS = "rooms:\n  - {name: nave, config: c.yaml}\n"
_PROJ = (
    "draws: 5\nmorphing:\n  - {scenario: warm, horizon: 2050, method: shift, "
    f"deltas: {{Te: {[1.0] * 12}}}}}\n"
)


def _case_projection(text, *extra):
    """``hbayes project`` with projection file ``text`` (its checks come first)."""

    def setup(d: Path):
        proj = _write(d / "proj.yaml", text)
        return ["project", d / "run", proj, *(a.format(d=d) for a in extra)]

    return setup


def _case_compare(cfg, *extra):
    def setup(d: Path):
        c = _write(d / "c.yaml", cfg)
        return ["compare", c, "--models", "thermal_1c,thermal_2c", *extra]

    return setup


def _hourly_csv(path: Path, names: tuple[str, str], mean: float) -> Path:
    """Twenty days of hourly readings with a daily cycle (a small logger/weather export)."""
    h = np.arange(24 * 20)
    t = pd.Timestamp("2020-01-01") + pd.to_timedelta(h, unit="h")
    day = np.sin(2 * np.pi * h / 24)
    pd.DataFrame(
        {"time": t.strftime("%Y-%m-%d %H:%M"), names[0]: mean + 3 * day, names[1]: 70 + 5 * day}
    ).to_csv(path, index=False, float_format="%.2f")
    return path


def _case_init(kind):
    """``hbayes init`` on a logger and a weather export (issue 30) given carelessly."""

    def setup(d: Path):
        data = d / "data"  # init writes no config among the data it reads
        data.mkdir()
        logger = _hourly_csv(data / "logger.csv", ("T", "RH"), 15.0)
        weather = _hourly_csv(data / "weather.csv", ("Te", "RHe"), 5.0)
        out = d / "room.yaml"
        if kind == "missing-logger":
            logger = data / "nope.csv"
        elif kind == "not-a-logger":
            logger = data / "shadow.csv"
            logger.write_text(_SHADOW)
        elif kind == "output-exists":
            out.write_text("# my own notes\n")
        elif kind == "output-root":
            out = Path("/")
        elif kind == "output-is-the-logger":
            out = data / "sub" / ".." / "logger.csv"
        elif kind == "output-in-the-data-folder":
            out = data / "sub" / "room.yaml"
        return ["init", logger, "--weather", weather, "-o", out]

    return setup


def _case_paths(kind):
    """Output paths a careless or unlucky user gives (cwd is the case's folder)."""

    def setup(d: Path):
        cfg = _write(d / "c.yaml", TINY)
        if kind == "dotdot":
            return ["calibrate", cfg, "--out", "run/.."]
        if kind == "root":
            return ["calibrate", cfg, "--out", "/"]
        if kind == "config-folder":
            cfg = _write(d / "cfg" / "c.yaml", TINY)
            return ["calibrate", cfg, "--out", d / "cfg"]
        if kind == "symlink-staging":
            (d / "elsewhere").mkdir()
            (d / "elsewhere" / "chain_thermal.h5").write_text("someone else's")
            os.symlink(d / "elsewhere", d / ".run.partial")
            return ["calibrate", cfg, "--out", d / "run", "--resume"]
        if kind == "chain-file":
            (d / "mine").mkdir()
            (d / "mine" / "chain_old.h5").write_text("a user's file named like a chain")
            (d / "mine" / "thesis.docx").write_text("the user's thesis")
            return ["calibrate", cfg, "--out", d / "mine"]
        (d / "mine").mkdir()  # "force-clash"
        (d / "mine" / "summary.json").write_text("my own summary")
        return ["calibrate", cfg, "--out", d / "mine", "--force"]

    return setup


_CUSTOM = {
    "name": "custom",
    "domain": "thermal",
    "nodes": {"Ti": "C/i"},
    "links": [["Ti", "Te", "Ge"]],
    "inputs": ["Te"],
    "outputs": ["Ti"],
}

#: id -> (setup(dir) -> argv, text the message must contain)
USER_ERRORS = {
    "duplicate-key": (_case_config(yaml.safe_dump(TINY) + "seed: 4\n"), "duplicate key 'seed'"),
    "deep-nesting": (
        _case_config("notes: " + "[" * 5000 + "]" * 5000 + "\n" + yaml.safe_dump(TINY)),
        "nested more than",
    ),
    "anchor-bomb": (_case_config(_bomb()), "after expanding YAML anchors"),
    "nul-bytes-config": (_case_config(b"\x00" * 4096), "not valid YAML"),
    "latin-1-config": (
        _case_config(("building: Ch\xe2teau\n" + yaml.safe_dump(TINY)).encode("latin-1")),
        "not UTF-8",
    ),
    "seed-negative": (_case_config(_tiny(seed=-1)), "seed:"),
    "seed-huge": (_case_config(_tiny(seed=10**30)), "seed:"),
    "seed-argument": (_case_seed_arg, "--seed"),
    "walkers-huge": (_case_config(_tiny(**{"sampler.walkers": 10**9})), "sampler.walkers"),
    "fixed-negative-capacity": (
        _case_config(_tiny(**{"thermal.priors": {"Ci": {"fixed": -1e6}}})),
        "thermal.priors.Ci.fixed",
    ),
    "room-volume-inf": (
        _case_config(yaml.safe_dump(TINY).replace("room_volume: 400", "room_volume: .inf")),
        "room_volume",
    ),
    "lognormal-median-negative": (
        _case_config(
            _tiny(**{"thermal.priors": {"Ci": {"dist": "lognormal", "median": -5, "sigma": 1}}})
        ),
        "thermal.priors.Ci.median",
    ),
    "misspelt-dist": (
        _case_config(
            _tiny(**{"thermal.priors": {"Ci": {"dist": "log-normal", "median": 5, "sigma": 1}}})
        ),
        "thermal.priors.Ci.dist",
    ),
    "unknown-model": (_case_config(_tiny(**{"thermal.model": "thermal_9z"})), "thermal.model"),
    "model-wrong-type": (_case_config(_tiny(**{"thermal.model": 5})), "thermal.model:"),
    "custom-parameter-name": (
        _case_config(_tiny(**{"thermal.model": _CUSTOM})),
        "parameter name 'C/i'",
    ),
    "custom-network-options": (
        _case_config(
            _tiny(
                thermal={"model": {**_CUSTOM, "nodes": {"Ti": "Ci"}}, "options": {"ground": False}}
            )
        ),
        "thermal.options.ground: a custom network",
    ),
    "impossible-date": (
        _case_config(yaml.safe_dump(TINY).replace("end: '2019-01-16'", "end: 2019-13-02", 1)),
        "periods.calibration",
    ),
    "time-format": (_case_data(_csv_config(time_format="%Q")), "time_format"),
    "sep-empty": (_case_data(_csv_config(sep="")), "sep"),
    "sep-regex": (_case_data(_csv_config(sep="((")), "sep"),
    "gz-truncated": (_case_damaged_gz("truncated"), "weather.csv.gz"),
    "gz-corrupt": (_case_damaged_gz("corrupt"), "weather.csv.gz"),
    "header-only-file": (_case_data(_csv_config(), logger_rows=0), "logger.csv"),
    "one-row-file": (_case_data(_csv_config(), logger_rows=1), "logger.csv"),
    "rh-as-fraction": (_case_data(_csv_config(), rh_scale=0.01), "'RH'"),
    "fahrenheit-indoors": (_case_data(_csv_config(), ti_scale=1.8, ti_offset=32), "'T'"),
    "kelvin-indoors": (_case_data(_csv_config(), ti_offset=273.15), "Kelvin"),
    # calibration from 2 January with 2 days of warm-up: readings end 4 January 02:00
    "two-observed-hours": (
        _case_data(_csv_config(), observed=24 * 3 + 2),
        "only 2 Ti observations in the calibration",
    ),
    "out-is-a-file": (_case_out("file"), "is a file"),
    "out-under-a-file": (_case_out("under_file"), "is a file"),
    "out-not-a-run-directory": (_case_out("mine"), "not a run directory"),
    "report-bad-config-yaml": (_case_report_bad_config, "config.yaml"),
    # -- names and output paths (issue 25): nothing outside the output folder is touched
    "name-dotdot": (_case_config(_tiny(name="..")), "name: '..' is not a plain name"),
    "name-traversal": (_case_config(_tiny(name="../../x")), "not a plain name"),
    "name-absolute": (_case_config(_tiny(name="/tmp/x")), "not a plain name"),
    "out-dotdot-is-cwd": (_case_paths("dotdot"), "is the current folder"),
    "out-root": (_case_paths("root"), "is the filesystem root"),
    "out-holds-the-config": (_case_paths("config-folder"), "holds an input file"),
    "out-symlinked-staging": (_case_paths("symlink-staging"), "is a symlink"),
    "out-chain-file-is-not-a-run": (_case_paths("chain-file"), "not a run directory of hbayes"),
    "out-force-never-replaces": (_case_paths("force-clash"), "named like the run's files"),
    "map-search-time-budget": (
        _case_config(_tiny(**{"sampler.max_time": "3s", "optimizer.popsize": 10_000})),
        "sampler.max_time = 3s (1 section(s) left",
    ),
    # -- batch, project, compare configs through the same strict loader
    "batch-duplicate-key": (_case_portfolio("name: a\nname: b\n" + _ROOMS), "duplicate key 'name'"),
    "batch-anchor-bomb": (
        _case_portfolio(_bomb().split("\nnotes: *a6")[0] + "\nnotes: *a6\n" + _ROOMS),
        "after expanding YAML anchors",
    ),
    "batch-python-tag": (
        _case_portfolio("name: !!python/object/apply:os.system ['true']\n" + _ROOMS),
        "not valid YAML",
    ),
    "batch-wrongly-nested": (
        _case_portfolio("rooms:\n  nave: {config: c.yaml}\n"),
        "rooms: expected a non-empty list",
    ),
    "batch-room-config-duplicate-key": (
        _case_portfolio(_ROOMS, room_config=yaml.safe_dump(TINY) + "seed: 4\n"),
        "rooms[0] (nave).config",
    ),
    "batch-room-name-dotdot": (
        _case_portfolio("rooms:\n  - {name: '..', config: c.yaml}\n"),
        "rooms[0] (..).name: expected letters",
    ),
    "batch-workers-beyond-cpus": (
        _case_portfolio(_ROOMS, "--workers", "100000"),
        "--workers-unbounded",
    ),
    "batch-out-root": (_case_portfolio(_ROOMS, "--out", "/"), "is the filesystem root"),
    "project-duplicate-key": (_case_projection("draws: 5\ndraws: 6\n"), "duplicate key 'draws'"),
    "project-anchor-bomb": (
        _case_projection(_bomb().split("\nnotes: *a6")[0] + "\nname: *a6\n"),
        "after expanding YAML anchors",
    ),
    "project-out-root": (_case_projection(_PROJ, "--out", "/"), "is the filesystem root"),
    "project-out-into-the-run": (
        _case_projection(_PROJ, "--out", "{d}/run"),
        "holds an input file",
    ),
    "compare-duplicate-key": (_case_compare(yaml.safe_dump(TINY) + "seed: 4\n"), "duplicate key"),
    "compare-name-traversal": (_case_compare(_tiny(name="../../etc")), "not a plain name"),
    "compare-out-cwd": (_case_compare(TINY, "--out", "."), "is the current folder"),
    # -- hbayes init: named errors, nothing written over the user's files
    "init-missing-logger": (_case_init("missing-logger"), "nope.csv: file not found"),
    "init-not-a-logger": (_case_init("not-a-logger"), "a logger file needs a header and data"),
    "init-output-exists": (_case_init("output-exists"), "exists; choose another name"),
    "init-output-root": (_case_init("output-root"), "is the filesystem root"),
    "init-output-is-the-logger": (_case_init("output-is-the-logger"), "is an input file"),
    "init-output-in-the-data-folder": (
        _case_init("output-in-the-data-folder"),
        "is in the folder of INDOOR_FILE",
    ),
    # -- a file that is not a config: named, its lines never echoed
    "shadow-as-config": (_case_config(_SHADOW), "not a configuration: none of its 2"),
    "shadow-as-portfolio": (_case_portfolio(_SHADOW), "not a portfolio file"),
    "shadow-as-projection": (_case_projection(_SHADOW), "not a projection file"),
}


#: Wall time of each user-error case [s] (printed by -s; never asserted: a busy machine)
SECONDS: dict[str, float] = {}


def _tree(d: Path) -> dict:
    """Every entry under ``d``, symlinks not followed: files by content, links by target."""
    out = {}
    for dirpath, dirnames, filenames in os.walk(d):
        for n in dirnames + filenames:
            p = Path(dirpath) / n
            out[p] = (
                ("link", os.readlink(p))
                if p.is_symlink()
                else ("dir",)
                if p.is_dir()
                else ("file", p.read_bytes())
            )
    return out


@pytest.fixture(scope="module")
def user_errors(tmp_path_factory):
    """Run every user-error case, two processes at a time."""
    root = tmp_path_factory.mktemp("user_errors")

    def one(item):
        name, (setup, _) = item
        d = root / name
        d.mkdir()
        argv = setup(d)
        before = _tree(d)
        t0 = time.perf_counter()
        rc, err = _hbayes(*argv, cwd=d)
        SECONDS[name] = time.perf_counter() - t0
        return name, (rc, err, before == _tree(d))

    with ThreadPoolExecutor(2) as pool:
        res = dict(pool.map(one, USER_ERRORS.items()))
    slow = sorted(SECONDS.items(), key=lambda kv: -kv[1])[:5]
    print("slowest user-error cases [s]:", ", ".join(f"{k} {v:.1f}" for k, v in slow))
    return res


@pytest.mark.parametrize("case", sorted(USER_ERRORS))
def test_user_error_is_a_clean_exit_2(user_errors, case):
    rc, err, untouched = user_errors[case]
    assert rc == 2, err
    assert USER_ERRORS[case][1] in err, err
    assert "hbayes: error: " in err and _clean(err), err
    assert untouched, "the user's files were changed"


@pytest.mark.parametrize(
    "case",
    ["shadow-as-config", "shadow-as-portfolio", "shadow-as-projection", "init-not-a-logger"],
)
def test_a_file_that_is_not_a_config_is_not_quoted(user_errors, case):
    rc, err, _ = user_errors[case]
    assert rc == 2 and "SECRET" not in err, err


# ----------------------------------------------------------- interrupts, then --resume
#: id -> (marker on stderr after which the signal comes, signal, seed of the delay)
INTERRUPTS = {
    "prepare-SIGTERM": ("calibrating", signal.SIGTERM, 1),
    "map-SIGTERM": ("MAP search", signal.SIGTERM, 2),
    "map-SIGINT": ("MAP search", signal.SIGINT, 3),
    "sampling-SIGINT": ("emcee 150 steps", signal.SIGINT, 4),
    "sampling-SIGTERM": ("emcee 50 steps", signal.SIGTERM, 5),
    "writing-SIGINT": (f"{STEPS} steps, τmax", signal.SIGINT, 6),
}


def _interrupt(cfg: Path, out: Path, marker: str, sig, seed: int) -> tuple[int, str, float]:
    """Start a run, send ``sig`` a seeded random time after ``marker`` appears."""
    proc = subprocess.Popen(
        _cmd("calibrate", cfg, "--out", out),
        stderr=subprocess.PIPE,
        stdout=subprocess.DEVNULL,
        text=True,
        env=_env(),
    )
    delay = random.Random(seed).uniform(0.0, 0.3)
    lines: list[str] = []
    sent = threading.Event()

    def fire():
        time.sleep(delay)
        if proc.poll() is None:
            proc.send_signal(sig)
            sent.set()

    for line in proc.stderr:
        lines.append(line)
        if marker in line and not sent.is_set() and not any(marker in x for x in lines[:-1]):
            threading.Thread(target=fire, daemon=True).start()
    proc.wait()
    return proc.returncode, "".join(lines), delay


@pytest.fixture(scope="module")
def runs(tmp_path_factory):
    """The reference run, the interrupted runs and their resumptions, the damaged
    checkpoints and the run-directory cases; two processes at a time."""
    root = tmp_path_factory.mktemp("runs")
    cfg = _write(root / "tiny.yaml", TINY)
    # runs to interrupt sample until the signal comes, however late (a busy machine);
    # max_steps is not part of the chain's identity, so the tiny config resumes them
    endless = _write(root / "endless.yaml", _tiny(**{"sampler.max_steps": 10**6}))
    res: dict = {"root": root, "cfg": cfg}

    def reference():
        res["ref"] = _hbayes("calibrate", cfg, "--out", root / "ref" / "run")

    def interrupted(name):
        marker, sig, seed = INTERRUPTS[name]
        out = root / name / "run"
        rc, err, delay = _interrupt(cfg if "writing" in name else endless, out, marker, sig, seed)
        staged = out.parent / ".run.partial"
        snap = root / name / "snapshot"
        if staged.is_dir():
            shutil.copytree(staged, snap)
        lock_left = (out.parent / ".run.lock").exists()
        rc2, err2 = _hbayes("calibrate", cfg, "--out", out, "--resume")
        res[name] = {"rc": rc, "err": err, "delay": delay, "snap": snap, "lock": lock_left,
                     "rc_resume": rc2, "err_resume": err2, "out": out}  # fmt: skip

    def concurrent():
        out = root / "concurrent" / "run"
        first = subprocess.Popen(
            _cmd("calibrate", cfg, "--out", out), stderr=subprocess.PIPE, text=True, env=_env()
        )
        for line in first.stderr:  # the first holds the lock once it says so
            if "calibrating" in line:
                break
        res["concurrent"] = {"second": _hbayes("calibrate", cfg, "--out", out)}
        first.stderr.read()
        res["concurrent"]["first"] = first.wait()

    with ThreadPoolExecutor(2) as pool:
        jobs = [pool.submit(reference), pool.submit(concurrent)]
        jobs += [pool.submit(interrupted, n) for n in INTERRUPTS]
        for j in jobs:
            j.result()
    res["ref_chain"] = _committed(root / "ref" / "run" / "chain_thermal.h5")

    # damaged copies of the checkpoint saved by an interrupt during sampling
    snap = res["sampling-SIGINT"]["snap"]

    # damaged before any thread forks: HDF5 locks the file it opens (flock), and a
    # child forked by another thread holds that lock until it closes its inherited
    # descriptors, so opening it again for writing in that window fails (EAGAIN)
    prefixes = {}
    for name in DAMAGE:
        path = root / f"damaged-{name}" / ".run.partial" / "chain_thermal.h5"
        shutil.copytree(snap, path.parent)
        prefixes[name] = _committed(path)
        DAMAGE[name](path)

    def damaged(name):
        d = root / f"damaged-{name}"
        prefix = prefixes[name]
        c = cfg
        if name == "other-data":
            c = _write(d / "other.yaml", _tiny(**{"data.demo": {"seed": 8}}))
        rc, err = _hbayes("calibrate", c, "--out", d / "run", "--resume")
        chain = _committed(d / "run" / "chain_thermal.h5") if rc == DONE else None
        res[f"damaged-{name}"] = {"rc": rc, "err": err, "prefix": prefix, "chain": chain, "d": d}

    def fresh_resume():
        out = root / "fresh" / "run"
        res["fresh"] = _hbayes("calibrate", cfg, "--out", out, "--resume")

    def rerun_saved_config():
        saved = root / "ref" / "run" / "config.yaml"
        res["rerun"] = _hbayes("calibrate", saved, "--out", root / "rerun" / "run", cwd=root)

    def failed_rerun():
        keep = root / "keep" / "run"
        shutil.copytree(root / "ref" / "run", keep)
        before = {p.name: p.read_bytes() for p in keep.iterdir()}
        # valid, but the logger gap covers the calibration period: fails on the data
        bad = _tiny(
            building="Another house", **{"data.demo": {"gap": ["2019-01-01", "2019-01-30"]}}
        )
        rc, err = _hbayes("calibrate", _write(root / "keep" / "bad.yaml", bad), "--out", keep)
        after = {p.name: p.read_bytes() for p in keep.iterdir()}
        res["failed_rerun"] = {"rc": rc, "err": err, "same": before == after}

    with ThreadPoolExecutor(2) as pool:
        jobs = [pool.submit(damaged, n) for n in DAMAGE]
        jobs += [pool.submit(f) for f in (fresh_resume, rerun_saved_config, failed_rerun)]
        for j in jobs:
            j.result()
    return res


def test_reference_run_and_its_directory(runs):
    rc, err = runs["ref"]
    assert rc == DONE and _clean(err), err
    run = runs["root"] / "ref" / "run"
    summary = json.loads((run / "summary.json").read_text(encoding="utf-8"))
    assert summary["versions"]["numpy"] == np.__version__  # the library versions
    assert runs["ref_chain"].shape[0] == STEPS
    # a log (not a terminal): one plain line per progress update, no carriage returns
    assert "\r" not in err
    assert sum("emcee " in line for line in err.splitlines()) == STEPS // 50
    # the user's file beside the resolved one; nothing but the run left in the parent
    assert (run / "config.original.yaml").read_text(encoding="utf-8") == runs["cfg"].read_text(
        encoding="utf-8"
    )
    assert sorted(p.name for p in run.parent.iterdir()) == ["run"]


@pytest.mark.parametrize("case", sorted(INTERRUPTS))
def test_interrupt_then_resume_loses_nothing(runs, case):
    r = runs[case]
    assert r["rc"] in (130, DONE), r["err"]  # DONE: the run ended before the signal came
    assert _clean(r["err"]), r["err"]
    if r["rc"] == 130:
        assert "hbayes: interrupted" in r["err"] or "hbayes: terminated" in r["err"]
        assert "--resume" in r["err"] and "unchanged" not in r["err"]  # no previous run
        assert not r["lock"], "the lock outlived the run"
        if r["snap"].is_dir() and (r["snap"] / "chain_thermal.h5").exists():
            saved = _committed(r["snap"] / "chain_thermal.h5")[:STEPS]
            np.testing.assert_array_equal(saved, runs["ref_chain"][: len(saved)])
    assert r["rc_resume"] == DONE, r["err_resume"]
    # as if never interrupted (a late signal may have let the chain pass STEPS steps)
    final = _committed(r["out"] / "chain_thermal.h5")
    assert final.shape[0] >= STEPS
    np.testing.assert_array_equal(final[:STEPS], runs["ref_chain"])
    assert not (r["out"].parent / ".run.partial").exists()


def _extra_rows(path: Path) -> None:
    """As if a crash came between writing rows and committing them."""
    with h5py.File(path, "a") as f:
        n = f["chain"].shape[0]
        for name in ("chain", "log_prob"):
            f[name].resize(n + 37, axis=0)
            f[name][n:] = 1e300


def _no_rng(path: Path) -> None:
    """A checkpoint of the first format without its random state."""
    with h5py.File(path, "a") as f:
        c = json.loads(f.attrs["commit"])
        del f.attrs["commit"]
        f.attrs["iteration"] = c["iteration"]


def _corrupt_chunk(path: Path) -> None:
    """Overwrite bytes inside the second stored chunk of the chain (rows 64..127)."""
    with h5py.File(path, "r") as f:
        info = f["chain"].id.get_chunk_info_by_coord((64, 0, 0))
    with open(path, "r+b") as fh:
        fh.seek(info.byte_offset + 100)
        fh.write(b"\x55" * 64)


def _truncate(path: Path) -> None:
    data = path.read_bytes()
    path.write_bytes(data[: len(data) // 2])


def _garbage(path: Path) -> None:
    path.write_bytes(np.random.default_rng(0).bytes(20000))


def _edit_row(path: Path) -> None:
    """A hand edit of one committed row (h5py recomputes the Fletcher-32 checksum)."""
    with h5py.File(path, "a") as f:
        f["chain"][10, 0, 0] += 0.25


DAMAGE = {
    "edited-row": _edit_row,
    "extra-rows": _extra_rows,
    "no-random-state": _no_rng,
    "corrupt-chunk": _corrupt_chunk,
    "truncated": _truncate,
    "not-hdf5": _garbage,
    "other-data": lambda path: None,  # resumed with the demo's data of another seed
}


def test_rows_beyond_the_commit_are_ignored(runs):
    r = runs["damaged-extra-rows"]
    assert r["rc"] == DONE and _clean(r["err"]), r["err"]
    np.testing.assert_array_equal(r["chain"][:STEPS], runs["ref_chain"])


def test_missing_random_state_is_explained_and_the_chain_kept(runs):
    r = runs["damaged-no-random-state"]
    assert r["rc"] == DONE and _clean(r["err"]), r["err"]
    assert "no random-number state" in r["err"]
    n = len(r["prefix"])
    np.testing.assert_array_equal(r["chain"][:n], r["prefix"])
    assert r["chain"].shape[0] == max(n, STEPS)


def test_corrupt_chunk_keeps_the_valid_prefix(runs):
    r = runs["damaged-corrupt-chunk"]
    assert r["rc"] == DONE and _clean(r["err"]), r["err"]
    assert "damaged" in r["err"] and "kept the 64 valid steps" in r["err"], r["err"]
    np.testing.assert_array_equal(r["chain"][:64], r["prefix"][:64])
    assert r["chain"].shape[0] == STEPS  # 64 kept, the rest sampled again
    assert (r["d"] / "run" / "chain_thermal.h5.damaged").exists()  # kept for inspection


@pytest.mark.parametrize(
    ("case", "message"),
    [
        ("truncated", "checkpoint is damaged"),
        ("not-hdf5", "checkpoint is damaged"),
        ("other-data", "different configuration, model or data"),
        ("edited-row", "block 1 (steps 1 to 50) does not match its checksum"),
    ],
)
def test_unusable_checkpoint_is_a_clean_exit_2(runs, case, message):
    r = runs[f"damaged-{case}"]
    assert r["rc"] == 2 and message in r["err"] and _clean(r["err"]), r["err"]
    assert "without --resume" in r["err"]
    # the unfinished run is left for inspection, nothing half-written in its place
    assert not (r["d"] / "run").exists()
    assert (r["d"] / ".run.partial" / "chain_thermal.h5").exists()


def test_resume_without_a_checkpoint_says_so(runs):
    rc, err = runs["fresh"]
    assert rc == DONE and "no checkpoint" in err and _clean(err), err


def test_saved_config_reruns_as_it_is(runs):
    rc, err = runs["rerun"]
    assert rc == DONE and _clean(err), err
    chain = _committed(runs["root"] / "rerun" / "run" / "chain_thermal.h5")
    np.testing.assert_array_equal(chain, runs["ref_chain"])


def test_failed_rerun_leaves_the_finished_run_intact(runs):
    r = runs["failed_rerun"]
    assert r["rc"] == 2 and _clean(r["err"]), r["err"]
    assert "is unchanged" in r["err"]
    assert r["same"], "the finished run directory was changed by a failed re-run"


def test_concurrent_runs_into_one_out(runs):
    rc, err = runs["concurrent"]["second"]
    assert rc == 2 and "another hbayes run is writing it (pid" in err and _clean(err), err
    assert runs["concurrent"]["first"] == DONE


@pytest.fixture
def tiny_fs(tmp_path):
    """A 2 MiB tmpfs (root only); skipped where mounting is not permitted."""
    mnt = tmp_path / "tiny_fs"
    mnt.mkdir()
    if not shutil.which("mount") or os.geteuid() != 0:
        pytest.skip("mounting a tiny tmpfs needs root")
    p = subprocess.run(
        ["mount", "-t", "tmpfs", "-o", "size=2m", "tmpfs", str(mnt)],
        capture_output=True,
        text=True,
        check=False,
    )
    if p.returncode != 0:
        pytest.skip(f"cannot mount a tmpfs here: {p.stderr.strip()}")
    try:
        yield mnt
    finally:
        subprocess.run(["umount", str(mnt)], check=False)


def test_disk_full_is_a_clean_exit_2(tiny_fs, tmp_path):
    cfg = _write(tmp_path / "tiny.yaml", TINY)
    rc, err = _hbayes("calibrate", cfg, "--out", tiny_fs / "run")
    assert rc == 2, err  # not a traceback, not a crash at exit
    assert "not enough free disk space" in err and _clean(err), err


def test_a_projection_that_fills_the_disk_is_a_clean_exit_2(tiny_fs, tmp_path):
    """A projection whose files do not fit (the user's own file takes most of the
    disk): exit 2 naming the folder and what to do, no traceback and no crash at exit
    (HDF5 segfaulted when the disk filled inside its write), the user's file
    byte-identical and nothing left on the disk (the staged projection is removed)."""
    import hashlib

    filler = tiny_fs / "photos.bin"
    filler.write_bytes(np.random.default_rng(0).bytes(2 * 2**20 - 64 * 2**10))
    digest = hashlib.sha256(filler.read_bytes()).hexdigest()
    proj = _write(
        tmp_path / "p.yaml",
        {"name": "p", "draws": 16, "seed": 5, "morphing": [
            {"scenario": "warm", "horizon": 2050, "method": "shift", "deltas": {"Te": [2.0] * 12}}
        ]},
    )  # fmt: skip
    # a run with both models (a projection of risk needs indoor T and RH)
    cfg = _write(tmp_path / "tiny.yaml", _tiny(hygric={"model": "hygric_1c", "noise": "ar1"}))
    rc, err = _hbayes("calibrate", cfg, "--out", tmp_path / "run")
    assert rc in (0, 3), err  # finished (STEPS: usually not converged)
    rc, err = _hbayes("project", tmp_path / "run", proj, "--out", tiny_fs / "p")
    assert rc == 2 and _clean(err), err
    # checked before the HDF5 write (a full disk inside one crashed the interpreter)
    assert "not enough free disk space to write projection.nc" in err, err
    assert str(tiny_fs) in err and "choose another --out" in err, err
    assert sorted(x.name for x in tiny_fs.iterdir()) == ["photos.bin"]
    assert hashlib.sha256(filler.read_bytes()).hexdigest() == digest


def test_a_reader_of_the_chain_file_does_not_end_the_run(tmp_path):
    """HDF5 locks the file: a user reading the running chain (h5py, another process)
    made the next append fail with BlockingIOError and ended a 4-minute run; the
    append now waits for the reader."""
    from heritage_bayes.inference.backend import _Checkpoint

    path = tmp_path / "chain_thermal.h5"
    ck = _Checkpoint(path, "tag")
    ck.create(4, 2)
    reader = subprocess.Popen(
        [
            sys.executable,
            "-c",
            f"import h5py, time, sys; f = h5py.File({str(path)!r}, 'r'); "
            "print('open', flush=True); time.sleep(2.0)",
        ],
        stdout=subprocess.PIPE,
        text=True,
    )
    assert reader.stdout.readline().strip() == "open"  # the reader holds the lock
    rng = np.random.default_rng(0)
    state = ("MT19937", np.zeros(624, dtype=np.uint32), 0, 0, 0.0)
    ck.append(rng.normal(size=(5, 4, 2)), rng.normal(size=(5, 4)), np.zeros(4), state, [])
    assert reader.wait(timeout=30) == 0
    with h5py.File(path, "r") as f:
        assert f["chain"].shape == (5, 4, 2)
        assert json.loads(f.attrs["commit"])["iteration"] == 5
