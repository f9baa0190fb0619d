"""Fault campaign of the writers (issue 44): every file the package writes, written one
way — resolved, never through a symbolic link, staged, renamed.

Each case builds a user's folder tree, hashes every entry in it (files by content,
symlinks by target, folders by presence), runs ``hbayes`` and checks the exit code,
the message, that every pre-existing entry is byte-identical afterwards except the
one output the command was asked to write, and that nothing was created outside that
output:

- ``hbayes init`` (in process): a symbolic link at ``-o`` (to a user's file, to a
  folder, dangling; with and without ``--force``), a dangling link among the folders
  of ``-o``, hostile folder and file names (a newline and a YAML key in a data
  folder's name: the config gains no key, the path reads back as written);
- the output folders of ``calibrate``, ``project`` and ``compare``: dangling links,
  symlinked staging folders, another run holding the lock while it creates its
  staging folder (said to be another run, never "remove it");
- signals (subprocesses, the signal sent by the process itself at a chosen point, so
  that the point is exact): SIGTERM and Ctrl-C while ``hbayes project`` writes each of
  its four files over an earlier projection (exit 130, the earlier projection whole),
  in the swap (the new projection whole), while numba compiles at start-up (exit 130).
"""

from __future__ import annotations

import hashlib
import json
import os
import re
import shutil
import signal
import subprocess
import sys
from pathlib import Path

import pytest
import yaml

from heritage_bayes.cli import main
from test_faults import TINY as TINY_CFG
from test_faults import _clean, _env, _hourly_csv
from test_paths import snapshot as tree  # every entry: files by content, links by target


# ----------------------------------------------------------------------------- helpers
def changes(before: dict, after: dict) -> tuple[set, set, set]:
    """(changed, created, removed) relative paths."""
    changed = {k for k in before.keys() & after.keys() if before[k] != after[k]}
    return changed, set(after) - set(before), set(before) - set(after)


def assert_only(root: Path, before: dict, outputs: tuple[str, ...] = ()) -> None:
    """Nothing under ``root`` changed, created or removed but ``outputs`` (relative
    paths: the entry itself and anything below it)."""
    changed, created, removed = changes(before, tree(root))

    def allowed(rel: str) -> bool:
        return any(rel == o or rel.startswith(o + os.sep) for o in outputs)

    bad = sorted(x for x in changed | created | removed if not allowed(x))
    assert not bad, f"touched outside the output: {bad}"


def run_cli(argv, capsys) -> tuple[int, str]:
    rc = main([str(a) for a in argv])
    return rc, capsys.readouterr().err


@pytest.fixture
def box(tmp_path, monkeypatch):
    """A user's tree: ``box/home/work`` (the current folder) with ``data/logger.csv``,
    ``data/weather.csv``, ``mine.txt`` (a user's file) and ``elsewhere/`` (a folder of
    the user's). HOME is outside the tree (the libraries' caches are not the writers')."""
    root = tmp_path / "box"
    work = root / "home" / "work"
    (work / "data").mkdir(parents=True)
    (work / "elsewhere").mkdir()
    _hourly_csv(work / "data" / "logger.csv", ("T", "RH"), 15.0)
    _hourly_csv(work / "data" / "weather.csv", ("Te", "RHe"), 5.0)
    (work / "mine.txt").write_text("the user's own file\n", encoding="utf-8")
    (work / "elsewhere" / "thesis.docx").write_bytes(b"PK\x03\x04 thesis")
    (tmp_path / "home").mkdir()
    monkeypatch.setenv("HOME", str(tmp_path / "home"))
    monkeypatch.chdir(work)
    return root


# ------------------------------------------------------------------------ hbayes init
def _init_argv(work: Path, out, *extra, data="data") -> list:
    return [
        "init",
        work / data / "logger.csv",
        "--weather",
        work / data / "weather.csv",
        "--latitude",
        "52",
        "--longitude",
        "5",
        "-o",
        out,
        *extra,
    ]


def _link(target, at: Path) -> None:
    at.parent.mkdir(parents=True, exist_ok=True)
    os.symlink(target, at)


#: id -> (setup(work) -> (-o as typed, extra args), exit code, message, output written
#: (relative to work; None: nothing))
INIT = {
    "link-to-user-file": (
        lambda w: (_link("mine.txt", w / "room.yaml"), ("room.yaml",))[1],
        2,
        "room.yaml is a symbolic link (to mine.txt); hbayes never writes through a link",
        None,
    ),
    "link-to-user-file-force": (
        lambda w: (_link("mine.txt", w / "room.yaml"), ("room.yaml", "--force"))[1],
        0,
        "was a symbolic link (to mine.txt): the link is replaced",
        "room.yaml",
    ),
    "link-absolute-to-user-file-force": (
        lambda w: (_link(w / "mine.txt", w / "p" / "room.yaml"), ("p/room.yaml", "--force"))[1],
        0,
        "the file it pointed to is left as it is",
        "p/room.yaml",
    ),
    "dangling-link": (
        lambda w: (_link(w / "nowhere" / "deep" / "c.yaml", w / "room.yaml"), ("room.yaml",))[1],
        2,
        "room.yaml is a symbolic link (to",
        None,
    ),
    "dangling-link-force": (
        lambda w: (
            _link(w / "nowhere" / "deep" / "c.yaml", w / "room.yaml"),
            ("room.yaml", "--force"),
        )[1],
        0,
        "the link is replaced",
        "room.yaml",
    ),
    "dangling-folder-link": (
        lambda w: (_link(w / "nowhere" / "deep", w / "proj"), ("proj/room.yaml",))[1],
        2,
        "proj is a symbolic link to",
        None,
    ),
    "dangling-folder-link-force": (
        lambda w: (_link(w / "nowhere" / "deep", w / "proj"), ("proj/room.yaml", "--force"))[1],
        2,
        "which does not exist; hbayes creates nothing through a link",
        None,
    ),
    "dangling-folder-link-deeper": (
        lambda w: (_link("../nowhere", w / "a" / "b"), ("a/b/c/room.yaml",))[1],
        2,
        "b is a symbolic link to ../nowhere, which does not exist",
        None,
    ),
    "link-to-a-folder": (
        lambda w: (_link("elsewhere", w / "room.yaml"), ("room.yaml",))[1],
        2,
        "room.yaml is a symbolic link (to elsewhere)",
        None,
    ),
    "link-to-a-folder-force": (
        lambda w: (_link("elsewhere", w / "room.yaml"), ("room.yaml", "--force"))[1],
        0,
        "the link is replaced",
        "room.yaml",
    ),
    "link-loop": (
        lambda w: (_link("loop2", w / "loop1"), _link("loop1", w / "loop2"), ("loop1",))[2],
        2,
        "loop1 is a symbolic link (to loop2)",
        None,
    ),
    "existing-file": (
        lambda w: (("room.yaml",), (w / "room.yaml").write_text("# my notes\n"))[0],
        2,
        "room.yaml exists; choose another name or add --force",
        None,
    ),
    "existing-folder": (lambda w: ("elsewhere",), 2, "is not a regular file", None),
    "under-a-file": (lambda w: ("mine.txt/room.yaml",), 2, "mine.txt is a file", None),
    "folder-through-a-link": (
        lambda w: (_link("elsewhere", w / "alias"), ("alias/room.yaml",))[1],
        0,
        "",
        "elsewhere/room.yaml",
    ),
    "new-folders": (lambda w: ("rooms/nave/config.yaml",), 0, "", "rooms"),
    "newline-in-output-name": (
        lambda w: ("room\nname: x.yaml",),
        2,
        "name (from --output)",
        None,
    ),
    "newline-in-name": (
        lambda w: ("room.yaml", "--name", "nave\nroom_volume: 1"),
        2,
        "--name",
        None,
    ),
}


@pytest.mark.parametrize("case", sorted(INIT))
def test_init_output(box, capsys, case):
    setup, code, message, written = INIT[case]
    work = box / "home" / "work"
    out, *extra = setup(work)
    before = tree(box)
    rc, err = run_cli(_init_argv(work, out, *extra), capsys)
    assert rc == code, err
    # init's findings are long by design (each with its evidence): no traceback is the check
    assert message in err and "Traceback" not in err and "internal error" not in err, err
    if written is None:
        assert_only(box, before)
        return
    rel = str(Path("home") / "work" / written)
    assert_only(box, before, (rel,))
    target = work / (out if written == "rooms" else written)
    assert target.is_file() and not target.is_symlink()
    cfg = yaml.safe_load(target.read_text(encoding="utf-8"))
    assert cfg["data"]["measurements"]["path"].endswith("logger.csv")


@pytest.mark.parametrize(
    "folder",
    [
        "x\nroom_volume: 1",
        "x\r\nroom_volume: 1",
        "x\u2028room_volume: 1",
        "x\x85room_volume: 1",
        "# x: 1",
        "x' # \"\nseed: 9",
    ],
)
def test_init_hostile_data_folder_adds_no_key(box, capsys, folder):
    """A data folder's name ends no comment and no value: the config has the keys init
    writes, and the data paths read back as the files' paths."""
    work = box / "home" / "work"
    data = work / folder
    data.mkdir()
    _hourly_csv(data / "logger.csv", ("T", "RH"), 15.0)
    _hourly_csv(data / "weather.csv", ("Te", "RHe"), 5.0)
    before = tree(box)
    rc, err = run_cli(_init_argv(work, "room.yaml", data=folder), capsys)
    assert rc == 0, err
    assert_only(box, before, (str(Path("home") / "work" / "room.yaml"),))
    text = (work / "room.yaml").read_text(encoding="utf-8")
    cfg = yaml.safe_load(text)
    assert "room_volume" not in cfg and cfg["seed"] == 1
    assert set(cfg) <= {"name", "building", "room", "seed", "site", "data", "periods",
                        "thermal", "hygric", "sampler", "questions"}  # fmt: skip
    for key, name in (("measurements", "logger.csv"), ("weather", "weather.csv")):
        assert (work / cfg["data"][key]["path"]).resolve() == (data / name).resolve()


# ---------------------------------------------------------------- output folders
PROJ = {
    "draws": 6,
    "seed": 5,
    "morphing": [
        {"scenario": "warm", "horizon": 2050, "method": "shift", "deltas": {"Te": [1.0] * 12}}
    ],
    "risk": {"chunk_draws": 6},
}


def _cfg(work: Path) -> Path:
    p = work / "c.yaml"
    p.write_text(yaml.safe_dump(TINY_CFG), encoding="utf-8")
    return p


def _held(out: Path):
    """The lock of ``out`` held as another run holds it (flock on its own open file)."""
    from heritage_bayes.rundir.lock import FolderLock

    return FolderLock(out).acquire()


def _staging_being_made(work: Path, out: str) -> list:
    """Another run holds the lock and has just made its staging folder (no marker yet)."""
    (work / f".{out}.partial").mkdir()
    return [_held(work / out)]


#: id -> (setup(work) -> argv, message, kept objects (locks) while it runs)
FOLDERS = {
    "calibrate-out-dangling-link": (
        lambda w: (_link(w / "nowhere" / "run", w / "run"), ["calibrate", _cfg(w), "--out", "run"])[
            1
        ],
        "run is a symbolic link to",
    ),
    "calibrate-out-under-dangling-link": (
        lambda w: (_link(w / "nowhere", w / "runs"), ["calibrate", _cfg(w), "--out", "runs/a"])[1],
        "which does not exist; hbayes creates nothing through a link",
    ),
    "calibrate-staging-symlink": (
        lambda w: (
            _link(w / "elsewhere", w / ".run.partial"),
            ["calibrate", _cfg(w), "--out", "run"],
        )[1],
        "staging folder of an unfinished run is a symlink",
    ),
    "calibrate-staging-symlink-resume": (
        lambda w: (
            _link(w / "elsewhere", w / ".run.partial"),
            ["calibrate", _cfg(w), "--out", "run", "--resume"],
        )[1],
        "it is not followed nor removed",
    ),
    "calibrate-old-symlink": (
        lambda w: (_link(w / "elsewhere", w / ".run.old"), ["calibrate", _cfg(w), "--out", "run"])[
            1
        ],
        "interrupted swap is a symlink",
    ),
    "calibrate-while-another-makes-its-staging": (
        lambda w: (["calibrate", _cfg(w), "--out", "run"], _staging_being_made(w, "run")),
        "another hbayes run is writing it (pid",
    ),
    "calibrate-while-another-runs": (
        lambda w: (["calibrate", _cfg(w), "--out", "run"], [_held(w / "run")]),
        "another hbayes run is writing it (pid",
    ),
    "calibrate-staging-of-a-stranger": (
        lambda w: (
            (w / ".run.partial").mkdir(),
            (w / ".run.partial" / "x.txt").write_text("x"),
            ["calibrate", _cfg(w), "--out", "run"],
        )[2],
        "has no valid .hbayes-run.json",
    ),
    "compare-out-dangling-link": (
        lambda w: (
            _link(w / "nowhere" / "cmp", w / "cmp"),
            ["compare", _cfg(w), "--models", "thermal_1c,thermal_2c", "--out", "cmp"],
        )[1],
        "cmp is a symbolic link to",
    ),
    "compare-while-another-makes-its-folder": (
        lambda w: (
            (w / "cmp").mkdir(),
            (w / "cmp" / ".hbayes-run.json.x1.tmp").write_text("{"),
            ["compare", _cfg(w), "--models", "thermal_1c,thermal_2c", "--out", "cmp"],
            [_held(w / "cmp")],
        )[2:],
        "another hbayes run is writing it (pid",
    ),
}


@pytest.mark.parametrize("case", sorted(FOLDERS))
def test_output_folder(box, capsys, case):
    setup, message = FOLDERS[case]
    work = box / "home" / "work"
    made = setup(work)
    argv, keep = made if isinstance(made, tuple) else (made, [])
    before = tree(box)
    try:
        rc, err = run_cli(argv, capsys)
    finally:
        for lock in keep:
            lock.release()
    lock_file = [k for k in changes(before, tree(box))[2] if k.endswith(".lock")]
    assert rc == 2 and message in err, err
    if "another hbayes run" in message:  # a live run's folder is never to be removed
        assert "remove or rename" not in err, err
    assert "hbayes: error: " in err and _clean(err), err
    before = {k: v for k, v in before.items() if k not in lock_file}  # the holder's own
    assert_only(box, before)


# ------------------------------------------------------------------------- projection
@pytest.fixture(scope="module")
def run_dir(tmp_path_factory) -> Path:
    """A tiny finished calibration (thermal_1c and hygric_1c, 300 steps: unconverged,
    enough draws)."""
    from heritage_bayes.calibration.calibrate import run_calibration
    from heritage_bayes.config import parse_config

    out = tmp_path_factory.mktemp("writers") / "run"
    cfg = TINY_CFG | {"hygric": {"model": "hygric_1c", "noise": "ar1"}}
    run_calibration(parse_config(cfg), out_dir=out, report=False, quiet=True)
    return out


@pytest.fixture(scope="module")
def earlier(run_dir, tmp_path_factory) -> Path:
    """An earlier projection (seed 5), with a user's note beside its files."""
    from heritage_bayes.projection import project

    out = tmp_path_factory.mktemp("earlier") / "proj"
    project(run_dir, PROJ, out=out)
    (out / "notes.txt").write_text("my reading of it\n", encoding="utf-8")
    return out


_MAIN = """
import os, signal, sys
signal.signal(signal.SIGINT, signal.default_int_handler)
SIG = signal.{sig}
{patch}
from heritage_bayes.cli import main
sys.exit(main(sys.argv[1:]))
"""

#: the signal after the k-th of the four files is written into the staging folder
_AFTER_WRITE = """
import heritage_bayes.projection.output as _o
_n = [0]
def _wrap(f):
    def g(*a, **k):
        r = f(*a, **k)
        _n[0] += 1
        if _n[0] == {k}:
            os.kill(os.getpid(), SIG)
        return r
    return g
_o.atomic_write = _wrap(_o.atomic_write)
_o.atomic_write_text = _wrap(_o.atomic_write_text)
"""

#: the signal as the swap starts (the marker of the staging folder is written first)
_IN_SWAP = """
import heritage_bayes.rundir.writer as _w
_calls = [0]
_orig = _w.write_marker
def _wm(*a, **k):
    _calls[0] += 1
    if _calls[0] == 2:  # the first is the staging folder's, the second the commit's
        os.kill(os.getpid(), SIG)
    return _orig(*a, **k)
_w.write_marker = _wm
"""

#: the signal just before the swap
_BEFORE_SWAP = """
import heritage_bayes.rundir.writer as _w
_orig = _w.StagedFolder.commit
def _commit(self):
    os.kill(os.getpid(), SIG)
    return _orig(self)
_w.StagedFolder.commit = _commit
"""

#: the signal at the k-th compilation of a numba function (a cold cache: start-up)
_AT_COMPILE = """
from numba.core import event as _ev
class _L(_ev.Listener):
    n = 0
    def on_start(self, ev):
        _L.n += 1
        if _L.n == {k}:
            os.kill(os.getpid(), SIG)
    def on_end(self, ev):
        pass
_ev.register("numba:compile", _L())
"""


def _spawn(patch: str, sig: str, *argv, env=None) -> tuple[int, str]:
    code = _MAIN.format(sig=sig, patch=patch)
    p = subprocess.run(
        [sys.executable, "-c", code, *map(str, argv)],
        capture_output=True,
        text=True,
        env=env or _env(),
        check=False,
    )
    return p.returncode, p.stderr


def _projection_files(out: Path) -> dict[str, str]:
    return {
        n: hashlib.sha256((out / n).read_bytes()).hexdigest()
        for n in ("projection.nc", "projection.json", "projection.csv", "projection.html")
    }


SIGNAL_CASES = {
    **{
        f"after-file-{k}-SIGTERM": (_AFTER_WRITE.format(k=k), "SIGTERM", "old") for k in range(1, 5)
    },
    "after-file-2-SIGINT": (_AFTER_WRITE.format(k=2), "SIGINT", "old"),
    "before-swap-SIGTERM": (_BEFORE_SWAP, "SIGTERM", "old"),
    "in-swap-SIGTERM": (_IN_SWAP, "SIGTERM", "new"),
    "in-swap-SIGINT": (_IN_SWAP, "SIGINT", "new"),
}


@pytest.mark.parametrize("case", sorted(SIGNAL_CASES))
def test_interrupted_projection_is_never_a_mix(run_dir, earlier, tmp_path, case):
    """A re-projection (seed 9) over an earlier one (seed 5), interrupted: exit 130 and
    the folder holds one projection whole — the earlier one, or the new one when the
    signal came inside the swap — with the user's note; no staging folder, no lock."""
    patch, sig, expect = SIGNAL_CASES[case]
    root = tmp_path / "box"
    out = root / "proj"
    shutil.copytree(earlier, out)
    proj_file = root / "p.yaml"
    proj_file.write_text(yaml.safe_dump(PROJ), encoding="utf-8")
    before, old = tree(root), _projection_files(out)
    rc, err = _spawn(patch, sig, "project", run_dir, proj_file, "--out", out, "--seed", 9)
    assert rc == 130, err
    assert ("terminated (SIGTERM)" if sig == "SIGTERM" else "interrupted") in err
    assert _clean(err), err
    now = _projection_files(out)
    seed = json.loads((out / "projection.json").read_text(encoding="utf-8"))["seed"]
    if expect == "old":
        assert now == old and seed == 5
        assert f"{out} is unchanged" in err
        assert_only(root, before)
    else:
        assert all(now[n] != old[n] for n in now) and seed == 9, "a mix of two projections"
        assert "written in full before the interrupt" in err
        import xarray as xr

        with xr.open_dataset(out / "projection.nc", engine="h5netcdf") as ds:
            assert int(ds.attrs["seed"]) == 9
        assert_only(root, before, ("proj",))
    assert (out / "notes.txt").read_text(encoding="utf-8") == "my reading of it\n"
    assert sorted(p.name for p in root.iterdir()) == ["p.yaml", "proj"]


def test_reprojection_replaces_the_four_files_and_keeps_the_users(run_dir, earlier, tmp_path):
    out = tmp_path / "proj"
    shutil.copytree(earlier, out)
    old = _projection_files(out)
    from heritage_bayes.projection import project

    p = project(run_dir, PROJ | {"seed": 9}, out=out)
    assert all(p.paths[k].parent == out.resolve() for k in p.paths)
    now = _projection_files(out)
    assert all(now[n] != old[n] for n in now)
    assert (out / "notes.txt").read_text(encoding="utf-8") == "my reading of it\n"
    assert sorted(x.name for x in tmp_path.iterdir()) == ["proj"]


def test_a_link_among_the_projection_files_is_replaced_not_followed(run_dir, earlier, tmp_path):
    """A projection file replaced by a link to a user's file: the re-projection replaces
    the link; the user's file is untouched."""
    out = tmp_path / "proj"
    shutil.copytree(earlier, out)
    mine = tmp_path / "mine.html"
    mine.write_text("the user's page\n", encoding="utf-8")
    (out / "projection.html").unlink()
    os.symlink(mine, out / "projection.html")
    from heritage_bayes.projection import project

    project(run_dir, PROJ, out=out)
    assert not (out / "projection.html").is_symlink()
    assert mine.read_text(encoding="utf-8") == "the user's page\n"


@pytest.mark.parametrize(
    ("case", "message"),
    [
        ("dangling-out", "is a symbolic link to"),
        ("symlinked-staging", "staging folder of an unfinished run is a symlink"),
        ("foreign-folder", "is not a projection folder of hbayes"),
        ("run-directory", "holds a calibration of hbayes, not a projection folder"),
        ("locked", "another hbayes run is writing it (pid"),
        ("staging-being-made", "another hbayes run is writing it (pid"),
    ],
)
def test_projection_output_refused(run_dir, tmp_path, capsys, monkeypatch, case, message):
    root = tmp_path / "box"
    (root / "elsewhere").mkdir(parents=True)
    (root / "elsewhere" / "notes.txt").write_text("mine")
    proj_file = root / "p.yaml"
    proj_file.write_text(yaml.safe_dump(PROJ), encoding="utf-8")
    out = root / "proj"
    keep = []
    if case == "dangling-out":
        os.symlink(root / "nowhere" / "proj", out)
    elif case == "symlinked-staging":
        os.symlink(root / "elsewhere", root / ".proj.partial")
    elif case == "foreign-folder":
        out = root / "elsewhere"
    elif case == "run-directory":
        shutil.copytree(run_dir, root / "run2")
        out = root / "run2"
    elif case == "locked":
        keep = [_held(out)]
    else:
        keep = _staging_being_made(root, "proj")
    monkeypatch.chdir(root)
    before = tree(root)
    try:
        rc, err = run_cli(["project", run_dir, proj_file, "--out", out], capsys)
    finally:
        for lock in keep:
            lock.release()
    assert rc == 2 and message in err and _clean(err), err
    assert "remove or rename" not in err or case == "symlinked-staging", err
    lock_file = {k for k in before if k.endswith(".lock")}
    assert_only(root, {k: v for k, v in before.items() if k not in lock_file})


def test_projection_page_escapes_user_text(run_dir, tmp_path):
    """A scenario name with markup reaches the page escaped (the page's own escaping)."""
    from heritage_bayes.projection import project

    spec = json.loads(json.dumps(PROJ))
    spec["morphing"][0]["scenario"] = "<script>alert(1)</script>"
    out = tmp_path / "proj"
    project(run_dir, spec, out=out)
    html = (out / "projection.html").read_text(encoding="utf-8")
    assert "<script>alert(1)" not in html and "&lt;script&gt;alert(1)" in html


# ------------------------------------------------------------------ signals at start-up
@pytest.mark.parametrize(("k", "sig"), [(1, "SIGTERM"), (3, "SIGTERM"), (2, "SIGINT")])
def test_a_signal_while_numba_compiles_ends_the_run(tmp_path, k, sig):
    """A cold numba cache: the signal at the k-th compilation ends calibrate with 130
    (never lost, the run never goes on to sample); nothing is left."""
    work = tmp_path / "w"
    work.mkdir()
    cfg = _cfg(work)
    env = _env() | {"NUMBA_CACHE_DIR": str(tmp_path / "numba_cache")}
    before = tree(work)
    rc, err = _spawn(_AT_COMPILE.format(k=k), sig, "calibrate", cfg, "--out", work / "run", env=env)
    assert rc == 130, err
    assert "emcee" not in err and _clean(err), err
    assert_only(work, before)


# ------------------------------------------------- the lock covers the staging folder
_BLOCK_AT_STAGING = """
import heritage_bayes.rundir.writer as _w
_orig = _w.write_marker
_first = [True]
def _wm(folder, m):
    if _first[0]:  # the staging folder is made, its marker not yet written
        _first[0] = False
        print("STAGING-MADE", file=sys.stderr, flush=True)
        sys.stdin.readline()
    return _orig(folder, m)
_w.write_marker = _wm
"""


def test_a_second_run_while_the_first_makes_its_staging_folder(tmp_path, capsys, monkeypatch):
    """The first run stops between making its staging folder and writing its marker;
    a second run into the same folder is told another run is writing it (never to
    remove the staging folder); the first, terminated, leaves nothing."""
    work = tmp_path / "w"
    work.mkdir()
    cfg = _cfg(work)
    code = _MAIN.format(sig="SIGTERM", patch=_BLOCK_AT_STAGING)
    first = subprocess.Popen(
        [sys.executable, "-c", code, "calibrate", str(cfg), "--out", str(work / "run")],
        stdin=subprocess.PIPE,
        stderr=subprocess.PIPE,
        text=True,
        env=_env(),
    )
    lines = []
    for line in first.stderr:
        lines.append(line)
        if "STAGING-MADE" in line:
            break
    assert (work / ".run.partial").is_dir(), "".join(lines)
    monkeypatch.chdir(work)
    rc, err = run_cli(["calibrate", cfg, "--out", work / "run"], capsys)
    first.send_signal(signal.SIGTERM)
    rest = first.communicate(timeout=120)[1]
    assert rc == 2 and "another hbayes run is writing it (pid" in err, err
    assert "remove or rename" not in err, err
    assert first.returncode == 130, "".join(lines) + rest
    assert sorted(p.name for p in work.iterdir()) == ["c.yaml"]


#: the signal once a worker samples: its chain's first checkpoint in a staging folder
_WORKERS_SAMPLE = """
import threading, time
from pathlib import Path
import heritage_bayes.compare.orchestrate as _o
_orig = _o._start_worker
def _watch(root):
    while not any(Path(root).rglob("*.partial/chain_*.h5")):
        time.sleep(0.2)
    os.kill(os.getpid(), SIG)
def _sw(ctx, name, cand, run_dir, kwargs, results):
    proc = _orig(ctx, name, cand, run_dir, kwargs, results)
    threading.Thread(target=_watch, args=(Path(run_dir).parent,), daemon=True).start()
    return proc
_o._start_worker = _sw
"""


@pytest.mark.parametrize("sig", ["SIGTERM", "SIGINT"])
def test_an_interrupted_compare_stops_its_workers(tmp_path, sig):
    """SIGTERM or SIGINT to ``hbayes compare --workers 2`` (the parent only, as ``kill
    PID`` sends it) while its workers sample ends the workers at once: exit 130, every
    worker process gone, no candidate's run, staging folder or lock left, and no
    candidate started after (the chains are set to run far longer than the test)."""
    work = tmp_path / "w"
    work.mkdir()
    cfg = work / "c.yaml"
    long = {**TINY_CFG["sampler"], "max_steps": 10**6, "max_time": "1h"}
    cfg.write_text(yaml.safe_dump({**TINY_CFG, "sampler": long}), encoding="utf-8")
    argv = ["compare", cfg, "--models", "thermal_1c,thermal_2c", "--workers", "2"]
    rc, err = _spawn(_WORKERS_SAMPLE, sig, *argv, "--out", work / "cmp")
    told = "terminated (SIGTERM)" if sig == "SIGTERM" else "interrupted"
    assert rc == 130 and told in err and _clean(err), err
    pids = [int(x) for x in re.findall(r"\(worker (\d+)\)", err)]
    assert len(pids) == 2, err  # both were sampling
    for pid in pids:
        with pytest.raises(ProcessLookupError):
            os.kill(pid, 0)
    assert not list((work / "cmp").glob("thermal_*")), sorted(work.rglob("*"))
    # a worker's staging folder keeps its chains so far (--resume), never a posterior
    assert not list(work.rglob("*.lock")) and not list(work.rglob("*.partial/posterior.nc"))


@pytest.mark.parametrize("text", ["x\nroom_volume: 1", "x\u2028seed: 9", "# x: 1\n..."])
def test_a_runs_config_yaml_is_emitted_by_yaml(text):
    """The run's ``config.yaml`` (written by the YAML emitter): user text with a line
    break reads back as itself and adds no key."""
    from heritage_bayes.config import parse_config
    from heritage_bayes.run import config_yaml

    cfg = parse_config(TINY_CFG | {"building": text, "room": text})
    back = yaml.safe_load(config_yaml(cfg))
    assert back["building"] == text and back["room"] == text
    assert back["room_volume"] == TINY_CFG["room_volume"] and back["seed"] == TINY_CFG["seed"]
