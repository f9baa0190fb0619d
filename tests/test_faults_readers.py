"""Fault campaign of the readers: damaged run directories, ranges at the config
boundary, hostile text and odd terminals (issue 44, the readers' half).

Every case checks what a user sees and what is left on disk: the exit code (2 for a
user error), a message naming the file, key, column or option, no traceback, and every
file that existed in the case's folder before byte for byte the same after (nothing
created or removed either). The commands run in this process through
:func:`heritage_bayes.cli.main`, except where the process itself is the subject (a
closed pipe, the terminal's encoding, an unwritable home): those run as subprocesses.

One tiny calibration (``test_faults.TINY``: three weeks of the demo, ``thermal_1c``,
300 steps, about 10 s) is made once; each run-directory case damages a copy of it.
"""

from __future__ import annotations

import json
import os
import re
import shutil
import subprocess
import sys
from pathlib import Path

import h5py
import numpy as np
import pytest
import yaml

from heritage_bayes.calibration.calibrate import run_calibration
from heritage_bayes.cli import main
from heritage_bayes.config import parse_config
from heritage_bayes.errors import InputError, quoted, shorten
from test_faults import _PROJ, _SHADOW, TINY, _csv_config, _csv_files, _env, _tree


@pytest.fixture(scope="module")
def tiny_run(tmp_path_factory) -> Path:
    out = tmp_path_factory.mktemp("readers") / "run"
    run_calibration(parse_config(TINY), out_dir=out, report=False, quiet=True)
    return out


def _clean(err: str) -> bool:
    return "Traceback" not in err and "internal error" not in err and len(err) < 4000


def _run_case(d: Path, argv: list, capsys) -> tuple[int, str]:
    """``hbayes argv`` in this process; asserts the folder's files are unchanged."""
    capsys.readouterr()
    before = _tree(d)
    rc = main([str(a) for a in argv])
    err = capsys.readouterr().err
    after = _tree(d)
    assert after == before, f"changed: {sorted(set(after) ^ set(before))}"
    return rc, err


# ------------------------------------------------------- damaged run directories
def _truncate(name: str, keep: int):
    def damage(run: Path):
        data = (run / name).read_bytes()
        (run / name).write_bytes(data[:keep])

    return damage


def _replace(name: str, content: bytes):
    def damage(run: Path):
        (run / name).write_bytes(content)

    return damage


def _remove(name: str):
    def damage(run: Path):
        (run / name).unlink()

    return damage


def _summary_edit(**changes):
    def damage(run: Path):
        s = json.loads((run / "summary.json").read_text(encoding="utf-8"))
        for k, v in changes.items():
            if v is None:
                s.pop(k, None)
            else:
                s[k] = v
        (run / "summary.json").write_text(json.dumps(s), encoding="utf-8")

    return damage


def _summary_is_a_folder(run: Path):
    (run / "summary.json").unlink()
    (run / "summary.json").mkdir()


def _posterior_without_group(run: Path):
    (run / "posterior.nc").unlink()
    with h5py.File(run / "posterior.nc", "w") as f:
        f.create_dataset("x", data=np.arange(3))


def _posterior_of_other_variables(run: Path):
    import xarray as xr

    (run / "posterior.nc").unlink()
    ds = xr.Dataset({"other.a": (("chain", "draw"), np.zeros((2, 3)))})
    ds.to_netcdf(run / "posterior.nc", group="posterior", engine="h5netcdf")


def _old_run_foreign_config(run: Path):
    """A run written before the provenance existed: config.yaml is what it reads."""
    _summary_edit(provenance=None)(run)
    (run / "config.yaml").write_text(_SHADOW, encoding="utf-8")


#: id -> (damage(run), the file the message must name, a text it must contain)
DAMAGED = {
    "summary-truncated": (_truncate("summary.json", 100), "summary.json", "not valid JSON"),
    "summary-a-list": (_replace("summary.json", b"[1, 2, 3]"), "summary.json", "found a list"),
    "summary-a-number": (_replace("summary.json", b"42"), "summary.json", "found a number"),
    "summary-not-utf8": (_replace("summary.json", b'{"a": "\xff\xfe"}'), "summary.json", "UTF-8"),
    "summary-empty-file": (_replace("summary.json", b""), "summary.json", "not valid JSON"),
    "summary-foreign-object": (
        _replace("summary.json", b'{"hello": "world"}'),
        "summary.json",
        "not the summary of a calibration",
    ),
    "summary-models-a-list": (_summary_edit(models=[1, 2]), "summary.json", "key 'models'"),
    "summary-converged-a-text": (
        _summary_edit(converged="yes"),
        "summary.json",
        "key 'converged'",
    ),
    "summary-provenance-a-list": (
        _summary_edit(provenance=[1]),
        "summary.json",
        "key 'provenance'",
    ),
    "summary-missing": (_remove("summary.json"), "summary.json", "is missing"),
    "summary-a-folder": (_summary_is_a_folder, "summary.json", "is missing"),
    "posterior-truncated": (_truncate("posterior.nc", 5000), "posterior.nc", "cannot be read"),
    "posterior-empty": (_replace("posterior.nc", b""), "posterior.nc", "not a NetCDF-4/HDF5"),
    "posterior-a-text-file": (
        _replace("posterior.nc", _SHADOW.encode()),
        "posterior.nc",
        "not a NetCDF-4/HDF5",
    ),
    "posterior-hdf5-without-posterior": (
        _posterior_without_group,
        "posterior.nc",
        "no 'posterior' group",
    ),
    "posterior-of-other-variables": (
        _posterior_of_other_variables,
        "posterior.nc",
        "not this run's posterior",
    ),
    "posterior-missing": (_remove("posterior.nc"), "posterior.nc", "is missing"),
    "config-missing": (_remove("config.yaml"), "config.yaml", "is missing"),
    "config-foreign-in-an-old-run": (_old_run_foreign_config, "config.yaml", "not a"),
}


def _damaged_copy(tiny_run: Path, d: Path, damage) -> Path:
    run = d / "run"
    shutil.copytree(tiny_run, run)
    damage(run)
    return run


@pytest.mark.parametrize("command", ["report", "project"])
@pytest.mark.parametrize("case", sorted(DAMAGED))
def test_a_damaged_run_directory_is_exit_2_naming_the_file(
    tiny_run, tmp_path, capsys, case, command
):
    damage, name, text = DAMAGED[case]
    run = _damaged_copy(tiny_run, tmp_path, damage)
    if command == "report":
        argv = ["report", run]
    else:
        proj = tmp_path / "proj.yaml"
        proj.write_text(_PROJ, encoding="utf-8")
        argv = ["project", run, proj]
    rc, err = _run_case(tmp_path, argv, capsys)
    assert rc == 2, err
    assert name in err and text in err, err
    assert _clean(err), err
    assert "SECRET" not in err  # a foreign file's content is never shown


@pytest.mark.parametrize("case", sorted(DAMAGED))
def test_load_run_names_the_damaged_file(tiny_run, tmp_path, case):
    from heritage_bayes import load_run

    damage, name, text = DAMAGED[case]
    run = _damaged_copy(tiny_run, tmp_path, damage)
    before = _tree(tmp_path)
    with pytest.raises(InputError) as exc:
        load_run(run)
    assert name in str(exc.value) and text in str(exc.value)
    assert _tree(tmp_path) == before


@pytest.mark.parametrize(
    "case", ["summary-a-list", "posterior-a-text-file", "posterior-of-other-variables"]
)
def test_compare_and_batch_readers_name_the_damaged_file(tiny_run, tmp_path, case):
    """The comparison (``compare_runs``) and the portfolio's row of a room
    (``room_row``) read through the same checks."""
    from heritage_bayes.compare import compare_runs
    from heritage_bayes.portfolio.rooms import room_row

    damage, name, text = DAMAGED[case]
    run = _damaged_copy(tiny_run, tmp_path, damage)
    before = _tree(tmp_path)
    with pytest.raises(InputError) as exc:
        compare_runs({"a": run}, "thermal")
    assert name in str(exc.value) and text in str(exc.value)
    if name == "summary.json":
        with pytest.raises(InputError) as exc:
            room_row(run)
        assert name in str(exc.value)
    assert _tree(tmp_path) == before


def test_the_undamaged_run_loads(tiny_run):
    """The campaign's baseline: the same run, undamaged, loads."""
    from heritage_bayes import load_run

    assert load_run(tiny_run).sections == ("thermal",)


# ------------------------------------------------------- ranges at the config boundary
def _projection(tmp_path: Path, extra: str) -> Path:
    return _write(tmp_path / "proj.yaml", _PROJ + extra)


def _write(path: Path, text) -> Path:
    path.parent.mkdir(parents=True, exist_ok=True)
    path.write_text(text if isinstance(text, str) else yaml.safe_dump(text), encoding="utf-8")
    return path


#: id -> (projection file text after _PROJ, texts the message must contain)
PROJECTION_RANGES = {
    "t_set-minus-300": (
        "interventions:\n  - {name: h, heating: {t_set: -300}}\n",
        ["interventions[0].heating.t_set", "[-20, 40] °C", "(got -300)"],
    ),
    "t_set-200": (
        "interventions:\n  - {name: h, heating: {t_set: 200}}\n",
        ["interventions[0].heating.t_set", "[-20, 40] °C", "(got 200)"],
    ),
    "t_max-conservation-heating": (
        "interventions:\n  - {name: c, conservation_heating: {rh_max: 60, t_max: 90}}\n",
        ["conservation_heating.t_max", "°C"],
    ),
    "capacity-5000": (
        "interventions:\n  - {name: d, dehumidification: {rh_max: 60, capacity: 5000}}\n",
        ["dehumidification.capacity", "[0, 1000] kg/h"],
    ),
    "rh_max-160": (
        "interventions:\n  - {name: d, dehumidification: {rh_max: 160, capacity: 1}}\n",
        ["dehumidification.rh_max", "(0, 100] %"],
    ),
    "power-negative": (
        "interventions:\n  - {name: h, heating: {t_set: 10, power_max: -5}}\n",
        ["heating.power_max", "W"],
    ),
    "seed-negative-in-the-file": ("seed: -3\n", ["seed", "0..2147483647"]),
}


@pytest.mark.parametrize("case", sorted(PROJECTION_RANGES))
def test_a_physical_input_out_of_range_names_the_key_and_range(tmp_path, capsys, case):
    extra, texts = PROJECTION_RANGES[case]
    proj = _projection(tmp_path, extra)
    rc, err = _run_case(tmp_path, ["project", tmp_path / "no-run", proj], capsys)
    assert rc == 2, err
    for t in texts:
        assert t in err, (t, err)
    assert _clean(err)


@pytest.mark.parametrize(
    ("argv", "option"),
    [
        (["project", "{run}", "{proj}", "--seed", "-1"], "--seed"),
        (["project", "{run}", "{proj}", "--seed", str(2**31)], "--seed"),
        (["compare", "{cfg}", "--seed", "-1"], "--seed"),
        (["compare", "{cfg}", "--models", ""], "--models"),
        (["compare", "{cfg}", "--models", "thermal_1c,,thermal_2c"], "--models"),
        (["init", "{cfg}", "--weather", "{cfg}", "--longitude", "400"], "--longitude"),
        (["init", "{cfg}", "--weather", "{cfg}", "--latitude", "-91"], "--latitude"),
    ],
    ids=["project-seed-1", "project-seed-2**31", "compare-seed-1", "compare-models-empty",
         "compare-models-empty-entry", "init-longitude-400", "init-latitude-91"],
)  # fmt: skip
def test_a_command_line_value_out_of_range_is_exit_2(tiny_run, tmp_path, capsys, argv, option):
    run = tmp_path / "run"
    shutil.copytree(tiny_run, run)
    names = {
        "run": run,
        "proj": _projection(tmp_path, ""),
        "cfg": _write(tmp_path / "c.yaml", TINY),
    }
    argv = [a.format(**{k: str(v) for k, v in names.items()}) for a in argv]
    rc, err = _run_case(tmp_path, argv, capsys)
    assert rc == 2, err
    assert f"hbayes: error: {option}:" in err, err
    assert _clean(err)


def test_the_demo_seed_has_a_range(tmp_path, capsys):
    cfg = json.loads(json.dumps(TINY))
    cfg["data"]["demo"]["seed"] = -1
    rc, err = _run_case(tmp_path, ["calibrate", _write(tmp_path / "c.yaml", cfg)], capsys)
    assert rc == 2 and "data.demo.seed: outside the allowed range 0..2147483647" in err, err


def test_batch_refuses_an_invalid_projection_file_before_any_room_is_calibrated(tmp_path, capsys):
    _write(tmp_path / "c.yaml", TINY)
    _write(
        tmp_path / "bad.yaml", "draws: 5\ninterventions:\n  - {name: h, heating: {t_set: -300}}\n"
    )
    pf = _write(
        tmp_path / "p.yaml", "rooms:\n  - {name: nave, config: c.yaml, projection: bad.yaml}\n"
    )
    rc, err = _run_case(tmp_path, ["batch", pf, "--out", tmp_path / "out"], capsys)
    assert rc == 2, err
    assert "rooms[0] (nave).projection" in err and "heating.t_set" in err and "°C" in err
    assert not (tmp_path / "out").exists()


def test_batch_refuses_a_projection_of_a_room_without_hygric_model(tmp_path, capsys):
    _write(tmp_path / "c.yaml", TINY)  # thermal only: no indoor RH, no risk
    _write(tmp_path / "proj.yaml", _PROJ)
    pf = _write(
        tmp_path / "p.yaml", "rooms:\n  - {name: nave, config: c.yaml, projection: proj.yaml}\n"
    )
    rc, err = _run_case(tmp_path, ["batch", pf, "--out", tmp_path / "out"], capsys)
    assert rc == 2 and "needs both the thermal and the hygric model" in err, err


# ------------------------------------------------------- hostile text in data files
def _csv_case(tmp_path: Path, **source) -> Path:
    _csv_files(tmp_path)
    return _write(tmp_path / "c.yaml", _csv_config(**source))


def _long_cell(tmp_path: Path, where: str) -> None:
    """One line of the logger with a 1 MB cell (a value, or the time stamp)."""
    path = tmp_path / "logger.csv"
    lines = path.read_text(encoding="utf-8").splitlines()
    t, v, rh = lines[60].split(",")
    lines[60] = ",".join(
        ("X" * 1_000_000, v, rh) if where == "time" else (t, "9" * 1_000_000 + "x", rh)
    )
    path.write_text("\n".join(lines) + "\n", encoding="utf-8")


@pytest.mark.parametrize("where", ["time", "value"])
def test_a_huge_cell_is_quoted_to_100_characters(tmp_path, capsys, where):
    cfg = _csv_case(tmp_path)
    _long_cell(tmp_path, where)
    rc, err = _run_case(tmp_path, ["calibrate", cfg, "--out", tmp_path / "run"], capsys)
    assert rc == 2, err[:500]
    assert len(err) < 2000, len(err)
    assert "line 61" in err and re.search(r"\.\.\. \(100000[01] characters\)", err), err
    assert ("timestamp" in err) if where == "time" else ("column 'T'" in err)


@pytest.mark.parametrize("where", ["header", "row"])
def test_init_names_a_huge_line_without_quoting_it(tmp_path, capsys, where):
    (tmp_path / "data").mkdir()
    _csv_files(tmp_path / "data")
    path = tmp_path / "data" / "logger.csv"
    lines = path.read_text(encoding="utf-8").splitlines()
    k = 0 if where == "header" else 30
    lines[k] = lines[k].replace("T", "T" * 1_000_000, 1) if k == 0 else "Q" * 1_000_000
    path.write_text("\n".join(lines) + "\n", encoding="utf-8")
    argv = ["init", path, "--weather", tmp_path / "data" / "weather.csv", "-o", tmp_path / "r.yaml"]
    rc, err = _run_case(tmp_path, argv, capsys)
    assert rc == 2, err[:300]
    assert f"logger.csv: line {k + 1} has 100000" in err and "not shown" in err, err[:300]
    assert len(err) < 1000 and _clean(err)


def test_a_huge_column_name_is_cut_in_the_list_of_columns(tmp_path, capsys):
    cfg = _csv_case(tmp_path)
    path = tmp_path / "logger.csv"
    text = path.read_text(encoding="utf-8")
    path.write_text(text.replace("time,T,RH", "time,T,RH" + "H" * 10_000, 1), encoding="utf-8")
    rc, err = _run_case(tmp_path, ["calibrate", cfg, "--out", tmp_path / "run"], capsys)
    assert rc == 2 and "column 'RH' not found" in err and len(err) < 1500, err[:900]


@pytest.mark.parametrize("what", ["measurements", "weather"])
def test_a_system_file_given_as_data_is_named_not_quoted(tmp_path, capsys, what):
    cfg = _csv_config()
    _csv_files(tmp_path)
    _write(tmp_path / "shadow", _SHADOW)
    cfg["data"][what]["path"] = "shadow"
    rc, err = _run_case(
        tmp_path, ["calibrate", _write(tmp_path / "c.yaml", cfg), "--out", tmp_path / "r"], capsys
    )
    assert rc == 2, err
    assert f"data.{what}: shadow: not a table" in err, err
    assert "SECRET" not in err and "daemon" not in err and "$6$" not in err, err


def test_the_cli_cuts_any_message_line(capsys, monkeypatch):
    """A safety net under the messages: no printed line is longer than MAX_LINE."""
    import heritage_bayes.cli as cli
    from heritage_bayes._terminal import MAX_LINE

    def boom(args):
        raise InputError("x" * 10_000_000 + "\nsecond line")

    monkeypatch.setattr(cli, "_cmd_models", boom)
    assert main(["models"]) == 2
    err = capsys.readouterr().err
    assert len(err) < MAX_LINE + 200 and "second line" in err
    assert "(10000000 characters)" in err


def test_quoting_helpers():
    assert quoted("abc") == "'abc'"
    assert quoted("A" * 500) == repr("A" * 100) + "... (500 characters)"
    assert shorten("x" * 101) == "x" * 100 + "... (101 characters)"
    assert shorten("short") == "short"


# ------------------------------------------------------- encodings and workbooks
def _hourly_rows(n: int = 24 * 20):
    import datetime as dt

    t0 = dt.datetime(2020, 1, 1)
    return [
        (t0 + dt.timedelta(hours=h), round(15 + 3 * np.sin(h / 4), 2), round(70 + np.cos(h / 4), 1))
        for h in range(n)
    ]


def test_a_utf16_export_is_read_as_text(tmp_path):
    from heritage_bayes.io import read_csv
    from heritage_bayes.io.loggers import inspect_table

    rows = _hourly_rows()
    text = "time\tT\tRH\r\n" + "".join(f"{t:%Y-%m-%d %H:%M}\t{a}\t{b}\r\n" for t, a, b in rows)
    path = tmp_path / "export.txt"
    path.write_text(text, encoding="utf-16")  # with its byte-order mark
    assert path.read_bytes()[:2] in (b"\xff\xfe", b"\xfe\xff")
    lay = inspect_table(path, what="logger file")
    assert lay.encoding == "utf-16" and lay.sep == "\t" and lay.time_column == "time"
    df = read_csv(path, time_column="time", sep="\t", timezone="UTC", columns={"Ti": "T"})
    assert len(df) == len(rows)
    np.testing.assert_allclose(df["Ti"].to_numpy(), [a for _, a, _ in rows])


def _workbook(path: Path, kind: str) -> Path:
    import openpyxl

    wb = openpyxl.Workbook()
    first = wb.active
    first.title = "Cover" if kind != "formulas" else "Data"
    if kind == "cover":
        first["A1"], first["A2"] = "Logger report", "serial 1234"
    data = wb.create_sheet("Readings") if kind != "formulas" else first
    data.append(["time", "T", "RH"])
    for i, (t, a, b) in enumerate(_hourly_rows()):
        data.append([t, f"=15+{i % 24}/10", b] if kind == "formulas" else [t, a, b])
    wb.save(path)
    return path


@pytest.mark.parametrize(
    ("kind", "texts"),
    [
        ("empty-first", ["first sheet 'Cover', the one read, holds no value", "'Readings'"]),
        ("cover", ["sheet 'Cover' (the first of 'Cover', 'Readings': only the first is read)"]),
        ("formulas", ["sheet 'Data': cell B2 holds a formula", "values are missing",
                      "save it again"]),
    ],
)  # fmt: skip
def test_a_workbook_message_names_the_sheet_read(tmp_path, capsys, kind, texts):
    (tmp_path / "data").mkdir()
    book = _workbook(tmp_path / "data" / "book.xlsx", kind)
    rows = "".join(f"{t:%Y-%m-%d %H:%M},{a - 10},{b}\n" for t, a, b in _hourly_rows())
    weather = _write(tmp_path / "data" / "weather.csv", "time,Te,RHe\n" + rows)
    argv = ["init", book, "--weather", weather, "-o", tmp_path / "room" / "config.yaml"]
    rc, err = _run_case(tmp_path, argv, capsys)
    assert rc == 2, err
    for t in texts:
        assert t in err, (t, err)
    assert _clean(err)


# ------------------------------------------------------- the process and its terminal
def _hbayes_process(*args, env_extra=None, drop=()) -> subprocess.CompletedProcess:
    env = _env()
    for k in drop:
        env.pop(k, None)
    env.update(env_extra or {})
    code = "import sys; from heritage_bayes.cli import main; sys.exit(main(sys.argv[1:]))"
    return subprocess.run(
        [sys.executable, "-c", code, *map(str, args)], capture_output=True, env=env, check=False
    )


def test_a_closed_pipe_ends_quietly():
    """``hbayes models | head -1``: the reader is gone before hbayes writes (its end of
    the pipe closed first: no race); no BrokenPipeError, the exit code of SIGPIPE."""
    read_end, write_end = os.pipe()
    os.close(read_end)
    try:
        code = "import sys; from heritage_bayes.cli import main; sys.exit(main(sys.argv[1:]))"
        p = subprocess.run(
            [sys.executable, "-c", code, "models"],
            stdout=write_end,
            stderr=subprocess.PIPE,
            env=_env(),
            check=False,
        )
    finally:
        os.close(write_end)
    assert p.returncode == 141, p.stderr
    assert p.stderr == b"", p.stderr


@pytest.mark.parametrize("encoding", ["latin-1", "ascii"])
def test_a_terminal_that_cannot_encode_gets_escapes(encoding):
    p = _hbayes_process("models", "thermal_2c", env_extra={"PYTHONIOENCODING": encoding})
    assert p.returncode == 0, p.stderr
    assert b"UnicodeEncodeError" not in p.stderr and b"models NAME" not in p.stderr
    assert b"\\u2212" in p.stdout  # the minus sign of the equations, escaped


def test_an_unknown_model_is_named_in_the_c_locale():
    p = _hbayes_process(
        "models", "thermal_9z", env_extra={"LC_ALL": "C", "PYTHONIOENCODING": "ascii"}
    )
    assert p.returncode == 2 and b"unknown model 'thermal_9z'" in p.stderr, p.stderr
    assert b"Traceback" not in p.stderr


def test_an_unwritable_home_is_not_a_damaged_run(tiny_run, tmp_path):
    """HOME a file (nothing can be created under it): arviz's and matplotlib's caches
    go to a private temporary folder; the run loads."""
    home = tmp_path / "home"
    home.write_text("not a folder", encoding="utf-8")
    code = (
        "import sys, os, heritage_bayes as hb; r = hb.load_run(sys.argv[1]); "
        "print(os.environ['XDG_CACHE_HOME'], r.sections)"
    )
    env = _env()
    for k in ("XDG_CACHE_HOME", "MPLCONFIGDIR"):
        env.pop(k, None)
    env["HOME"] = str(home)
    before = _tree(tiny_run)
    p = subprocess.run(
        [sys.executable, "-c", code, str(tiny_run)], capture_output=True, text=True, env=env
    )
    assert p.returncode == 0, p.stderr
    assert "damaged" not in p.stderr and "('thermal',)" in p.stdout
    assert not p.stdout.startswith(str(home))
    assert _tree(tiny_run) == before
