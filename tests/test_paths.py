"""The output-path policy, run markers, staging, locks and tamper evidence.

Every case runs in a sandbox folder holding a user's files (a home folder, data, a
config, notes, symlinks). It asserts that every pre-existing entry is byte-identical
afterwards (files by content, symlinks by target, folders by presence) and that nothing
was created outside the folder the command resolved as its output.
"""

from __future__ import annotations

import os
from pathlib import Path

import pytest

from heritage_bayes.errors import InputError
from heritage_bayes.rundir import check_name, resolve_output, write_new_file


# ------------------------------------------------------------------ the sandbox
def snapshot(root: Path) -> dict[str, tuple]:
    """Every entry under ``root`` (symlinks not followed): relative path -> identity."""
    out: dict[str, tuple] = {}
    for dirpath, dirnames, filenames in os.walk(root, followlinks=False):
        for name in dirnames + filenames:
            p = Path(dirpath) / name
            rel = str(p.relative_to(root))
            if p.is_symlink():
                out[rel] = ("link", os.readlink(p))
            elif p.is_dir():
                out[rel] = ("dir",)
            else:
                out[rel] = ("file", p.read_bytes())
    return out


class Sandbox:
    """A user's folder tree: ``home/`` (HOME and the current folder's parent),
    ``home/work`` (the current folder) with ``config.yaml``, ``data/indoor.csv``,
    ``notes.txt`` and ``results/`` holding ``thesis.docx``; a symlink ``alias`` ->
    ``results``."""

    def __init__(self, root: Path):
        self.root = root
        self.home = root / "home"
        self.cwd = self.home / "work"
        (self.cwd / "data").mkdir(parents=True)
        (self.cwd / "results").mkdir()
        (self.cwd / "config.yaml").write_text("name: nave\n", encoding="utf-8")
        (self.cwd / "data" / "indoor.csv").write_text("time,T\n2020-01-01,5.0\n")
        (self.cwd / "notes.txt").write_text("my notes\n")
        (self.cwd / "results" / "thesis.docx").write_bytes(b"\x50\x4b\x03\x04 thesis")
        (self.home / "private.txt").write_text("do not touch\n")
        os.symlink("results", self.cwd / "alias")
        self.before = snapshot(root)

    @property
    def protect(self) -> list[Path]:
        return [self.cwd / "config.yaml", self.cwd / "data" / "indoor.csv"]

    def forget_run(self, out: Path) -> None:
        """Take the run's own files (those its marker lists, and the marker) out of the
        snapshot: a re-run may replace them."""
        from heritage_bayes.rundir.marker import MARKER, read_marker

        for name in (*read_marker(out).files, MARKER):
            self.before.pop(str((out / name).relative_to(self.root)), None)

    def check(self, *allowed: Path) -> None:
        """Pre-existing entries unchanged; new entries only under ``allowed`` folders
        (resolved) or equal to an allowed file."""
        after = snapshot(self.root)
        for rel, ident in self.before.items():
            assert after.get(rel) == ident, f"{rel} was changed or removed"
        allowed_r = [a.resolve() for a in allowed]
        for rel in sorted(set(after) - set(self.before)):
            p = (
                (self.root / rel).resolve()
                if not (self.root / rel).is_symlink()
                else (self.root / rel)
            )
            assert any(p == a or a in p.parents for a in allowed_r), f"{rel} was created"


@pytest.fixture
def box(tmp_path, monkeypatch) -> Sandbox:
    sb = Sandbox(tmp_path)
    monkeypatch.setenv("HOME", str(sb.home))
    monkeypatch.chdir(sb.cwd)
    return sb


# ------------------------------------------------------------------ plain names
@pytest.mark.parametrize(
    "bad",
    ["..", ".", "../x", "../../x", "/abs", "a/b", "a\\b", "", ".hidden", " pad", "a\nb", "x" * 101],
)
def test_names_must_be_plain(box, bad):
    with pytest.raises(InputError, match=r"name: .* not a plain name"):
        check_name(bad)
    box.check()


@pytest.mark.parametrize("good", ["nave_2019", "Ørholm kirke", "room-1.v2"])
def test_plain_names_pass(box, good):
    assert check_name(good) == good
    box.check()


# ------------------------------------------------------------------ resolve_output
@pytest.mark.parametrize(
    ("typed", "rule"),
    [
        ("/", "filesystem root"),
        (".", "current folder"),
        ("results/..", "current folder"),
        ("..", "home folder"),
        ("~", "home folder"),
        ("../..", "ancestor of the home folder"),
        ("data", "holds an input file"),
        ("data/indoor.csv", "input file of this command"),
        ("notes.txt", "is a file, not a folder"),
    ],
)
def test_dangerous_output_folders_are_refused(box, typed, rule):
    with pytest.raises(InputError, match=rule):
        resolve_output(typed, protect=box.protect)
    box.check()


def test_output_folder_through_a_symlink_is_resolved(box):
    p = resolve_output("alias/run1", protect=box.protect)
    assert p == (box.cwd / "results" / "run1").resolve()
    assert not p.exists()  # nothing created
    box.check()


def test_symlink_to_the_current_folder_is_refused(box):
    os.symlink(".", box.cwd / "here")
    box.before = snapshot(box.root)
    with pytest.raises(InputError, match=r"here \(resolved: .*current folder"):
        resolve_output("here", protect=box.protect)
    box.check()


def test_symlink_loop_is_refused(box):
    os.symlink("loop2", box.cwd / "loop1")
    os.symlink("loop1", box.cwd / "loop2")
    box.before = snapshot(box.root)
    with pytest.raises(InputError, match="cannot be resolved"):
        resolve_output("loop1/run", protect=box.protect)
    box.check()


def test_output_file_may_not_be_an_input(box):
    with pytest.raises(InputError, match="input file of this command"):
        resolve_output("config.yaml", kind="file", protect=box.protect)
    with pytest.raises(InputError, match="not a regular file"):
        resolve_output("results", kind="file", protect=box.protect)
    box.check()


def test_output_file_in_the_current_folder_is_fine(box):
    assert resolve_output("new.yaml", kind="file", protect=box.protect) == box.cwd / "new.yaml"
    box.check()


# ------------------------------------------------------------------ write_new_file
def test_write_new_file_refuses_an_existing_file(box):
    with pytest.raises(InputError, match=r"notes.txt exists; .*--force"):
        write_new_file(box.cwd / "notes.txt", "replaced")
    box.check()


def test_write_new_file_refuses_a_dangling_symlink(box):
    os.symlink(box.home / "created-through-link", box.cwd / "dangling.yaml")
    box.before = snapshot(box.root)
    with pytest.raises(InputError, match=r"dangling\.yaml is a symbolic link"):
        write_new_file(box.cwd / "dangling.yaml", "x")
    box.check()


def test_write_new_file_force_replaces_the_link_not_its_target(box):
    os.symlink(box.home / "private.txt", box.cwd / "link.yaml")
    box.before = snapshot(box.root)
    write_new_file(box.cwd / "link.yaml", "new", force=True)
    assert (box.cwd / "link.yaml").read_text() == "new"
    assert not (box.cwd / "link.yaml").is_symlink()
    del box.before["home/work/link.yaml"]  # the one file the call was asked to replace
    box.check(box.cwd / "link.yaml")


def test_write_new_file_writes_atomically_and_leaves_no_temporary(box):
    p = write_new_file(box.cwd / "out" / "init.yaml", "name: x\n")
    assert p.read_text() == "name: x\n"
    assert sorted(q.name for q in p.parent.iterdir()) == ["init.yaml"]
    box.check(box.cwd / "out")


# ------------------------------------------------------------------ run directories
from heritage_bayes.rundir.folder import OutputFolder  # noqa: E402
from heritage_bayes.rundir.lock import FolderLock  # noqa: E402
from heritage_bayes.rundir.marker import MARKER, new_marker, read_marker, write_marker  # noqa: E402
from heritage_bayes.rundir.writer import RunWriter, is_run_directory, saved_chains  # noqa: E402

RUN = {"config.yaml": "name: nave\n", "summary.json": "{}", "chain_thermal.h5": "chain"}


def fake_run(out, files=RUN, **kw) -> Path:
    """What ``hbayes calibrate`` does to the folders: write ``files`` into the staging
    folder of a RunWriter, then commit."""
    with RunWriter(out, **kw) as w:
        for name, text in files.items():
            (w.staging / name).write_text(text)
        w.commit()
    return w.out


def test_a_new_run_directory_has_a_marker_listing_its_files(box):
    out = fake_run("results/run1", protect=box.protect)
    m = read_marker(out)
    assert m.kind == "calibration" and m.files == tuple(sorted(RUN))
    assert len(m.run_id) == 32 and is_run_directory(out)
    assert sorted(p.name for p in out.iterdir()) == sorted([*RUN, MARKER])
    box.check(out)


def test_rerun_keeps_the_users_files_in_a_run_directory(box):
    out = fake_run("results/run1", protect=box.protect)
    (out / "notes.txt").write_text("my notes on the run\n")
    (out / "projection").mkdir()
    (out / "projection" / "p.html").write_text("kept")
    box.before = snapshot(box.root)
    box.forget_run(out)
    fake_run("results/run1", {"config.yaml": "new", "summary.json": "{1}"}, protect=box.protect)
    assert (out / "summary.json").read_text() == "{1}"
    assert not (out / "chain_thermal.h5").exists()  # listed by the old marker: the run's
    box.check(out)
    assert read_marker(out).files == ("config.yaml", "summary.json")


def test_a_folder_with_a_chain_file_but_no_marker_is_not_a_run(box):
    d = box.cwd / "results"
    (d / "chain_old.h5").write_bytes(b"not mine to replace")
    box.before = snapshot(box.root)
    assert not is_run_directory(d)
    with pytest.raises(InputError, match="not a run directory of hbayes"):
        fake_run("results", protect=box.protect)
    box.check()


def test_force_writes_beside_the_users_files_never_over_them(box):
    out = fake_run("results", protect=box.protect, force=True)
    assert read_marker(out).files == tuple(sorted(RUN))  # thesis.docx not listed
    box.check(out)
    # a second --force run: still only the listed files are replaced
    box.before = snapshot(box.root)
    box.forget_run(out)
    fake_run("results", {"summary.json": "{2}"}, protect=box.protect, force=True)
    box.check(out)


def test_force_refuses_a_user_file_named_like_an_output(box):
    (box.cwd / "results" / "summary.json").write_text("my own summary")
    box.before = snapshot(box.root)
    with pytest.raises(InputError, match=r"holds summary\.json, named like the run.s files"):
        fake_run("results", protect=box.protect, force=True)
    box.check()


def test_an_empty_folder_becomes_the_run(box):
    (box.cwd / "empty").mkdir()
    box.before = snapshot(box.root)
    out = fake_run("empty", protect=box.protect)
    assert is_run_directory(out)
    box.check(out)


@pytest.mark.parametrize(
    ("content", "why"),
    [
        ("{not json", "not JSON"),
        ('{"format": "other"}', "format is not"),
        (
            '{"format": "hbayes-run", "version": 99, "kind": "calibration"}',
            "version 99",
        ),
        (
            '{"format": "hbayes-run", "version": 1, "kind": "calibration", "run_id": '
            '"0123456789abcdef0123456789abcdef", "created": "x", "files": ["../thesis.docx"]}',
            "not a plain file name",
        ),
    ],
)
def test_an_invalid_or_tampered_marker_is_refused(box, content, why):
    d = box.cwd / "results"
    (d / MARKER).write_text(content)
    box.before = snapshot(box.root)
    with pytest.raises(InputError, match=why):
        fake_run("results", protect=box.protect, force=True)
    box.check()


def test_a_marker_that_is_a_symlink_is_refused(box):
    os.symlink(box.home / "private.txt", box.cwd / "results" / MARKER)
    box.before = snapshot(box.root)
    with pytest.raises(InputError, match="a symlink or not a regular file"):
        fake_run("results", protect=box.protect, force=True)
    box.check()


def test_a_marker_of_another_kind_is_refused(box):
    (box.cwd / "cmp").mkdir()
    write_marker(box.cwd / "cmp", new_marker("comparison"))
    box.before = snapshot(box.root)
    with pytest.raises(InputError, match="holds a comparison of hbayes, not a run directory"):
        fake_run("cmp", protect=box.protect)
    box.check()


@pytest.mark.parametrize("resume", [False, True])
def test_a_staging_folder_that_is_a_symlink_is_not_followed(box, resume):
    (box.home / "elsewhere").mkdir()
    (box.home / "elsewhere" / "chain_thermal.h5").write_text("someone else's")
    os.symlink(box.home / "elsewhere", box.cwd / ".run1.partial")
    box.before = snapshot(box.root)
    with pytest.raises(InputError, match="staging folder of an unfinished run is a symlink"):
        fake_run("run1", protect=box.protect, resume=resume)
    assert saved_chains(box.cwd / "run1") == []
    box.check()


def test_a_staging_folder_hbayes_did_not_make_is_left_alone(box):
    (box.cwd / ".run1.partial").mkdir()
    (box.cwd / ".run1.partial" / "chain_thermal.h5").write_text("not ours")
    box.before = snapshot(box.root)
    with pytest.raises(InputError, match=f"has no valid {MARKER}"):
        fake_run("run1", protect=box.protect)
    box.check()


def test_an_old_folder_that_is_a_symlink_is_refused(box):
    os.symlink(box.home, box.cwd / ".run1.old")
    box.before = snapshot(box.root)
    with pytest.raises(InputError, match="interrupted swap is a symlink"):
        fake_run("run1", protect=box.protect)
    box.check()


def test_an_interrupted_swap_is_undone(box):
    out = fake_run("results/run1", protect=box.protect)
    os.rename(out, out.parent / ".run1.old")  # killed between the two renames
    fake_run("results/run1", {"summary.json": "{3}"}, protect=box.protect)
    assert (out / "summary.json").read_text() == "{3}"
    assert sorted(p.name for p in out.parent.iterdir()) == ["run1", "thesis.docx"]


def test_an_interrupted_commit_puts_the_users_files_back(box, monkeypatch):
    out = fake_run("results/run1", protect=box.protect)
    (out / "notes.txt").write_text("mine")
    box.before = snapshot(box.root)
    box.forget_run(out)
    real_rename = os.rename

    def dies(src, dst):
        if Path(src) == out:  # after the user's file moved into staging
            raise KeyboardInterrupt
        return real_rename(src, dst)

    monkeypatch.setattr(os, "rename", dies)
    with pytest.raises(KeyboardInterrupt):
        fake_run("results/run1", protect=box.protect)
    monkeypatch.setattr(os, "rename", real_rename)
    assert not (out / "notes.txt").exists()  # in the staging folder, with a journal
    fake_run("results/run1", protect=box.protect)
    box.check(out)


def test_a_failed_run_leaves_the_previous_run_and_no_staging(box):
    out = fake_run("results/run1", protect=box.protect)
    box.before = snapshot(box.root)
    with pytest.raises(RuntimeError), RunWriter("results/run1", protect=box.protect) as w:
        (w.staging / "config.yaml").write_text("half")
        raise RuntimeError("the data were bad")
    assert not w.staging.exists()
    box.check(out)


def test_resume_takes_chains_only_from_a_marked_folder(box):
    out = fake_run("results/run1", protect=box.protect)
    (out / "chain_extra.h5").write_text("a user's copy, not listed")
    box.before = snapshot(box.root)
    with RunWriter("results/run1", resume=True, protect=box.protect) as w:
        assert (w.staging / "chain_thermal.h5").read_text() == "chain"
        assert not (w.staging / "chain_extra.h5").exists()
    box.check(out, w.staging)  # the staging folder is kept: its chains, for --resume


def test_an_output_through_a_symlink_writes_the_target_and_keeps_the_link(box):
    out = fake_run("alias/run1", protect=box.protect)
    assert out == (box.cwd / "results" / "run1").resolve()
    assert (box.cwd / "alias").is_symlink()
    box.check(out)


@pytest.mark.parametrize("typed", ["alias/run1", "results/../results/run1", "data/../results/run1"])
def test_the_lock_holds_across_aliases_of_one_folder(box, typed):
    with (
        FolderLock(box.cwd / "results" / "run1"),
        pytest.raises(InputError, match="another hbayes run is writing it"),
    ):
        fake_run(typed, protect=box.protect)
    box.check()


def test_the_lock_names_the_folder_by_device_and_inode(box):
    with FolderLock("alias/run1") as lk:
        text = lk.path.read_text()
        st = os.stat(box.cwd / "results")
        assert f"{st.st_dev}:{st.st_ino}/run1" in text
    assert not lk.path.exists()


@pytest.mark.parametrize("typed", ["data", "."])
def test_a_run_into_an_input_folder_is_refused(box, typed):
    with pytest.raises(InputError, match="--out"):
        fake_run(typed, protect=box.protect)
    box.check()


# ------------------------------------------------------------------ other output folders
def test_an_output_folder_refuses_a_foreign_folder(box):
    with (
        pytest.raises(InputError, match="not made by hbayes"),
        OutputFolder("results", kind="comparison", protect=box.protect),
    ):
        pass
    box.check()


def test_an_output_folder_claims_only_new_or_listed_entries(box):
    with OutputFolder("results", kind="comparison", protect=box.protect, force=True) as f:
        (p,) = f.claim("comparison.json")
        p.write_text("{}")
        with pytest.raises(InputError, match=r"thesis\.docx exists and was not written by"):
            f.claim("thesis.docx")
        with pytest.raises(InputError, match="not a plain name"):
            f.claim("../escape")
    assert read_marker(box.cwd / "results").files == ("comparison.json",)
    box.check(box.cwd / "results")


def test_an_output_folder_of_another_kind_is_refused(box):
    fake_run("results/run1", protect=box.protect)
    box.before = snapshot(box.root)
    with pytest.raises(InputError, match="holds a calibration of hbayes, not a portfolio"):
        OutputFolder("results/run1", kind="portfolio").check()
    box.check()


# ------------------------------------------------------------------ tamper evidence
def _checkpoint(path: Path, blocks=(5, 7)):
    """A checkpoint of 4 walkers × 2 parameters appended in blocks of ``blocks`` rows."""
    import numpy as np

    from heritage_bayes.inference.backend import _Checkpoint

    ck = _Checkpoint(path, "tag")
    ck.create(4, 2)
    rng = np.random.default_rng(1)
    state = np.random.RandomState(3).get_state()
    hist = []
    for i, n in enumerate(blocks):
        hist.append((float(sum(blocks[: i + 1])), 1.0))
        ck.append(rng.normal(size=(n, 4, 2)), rng.normal(size=(n, 4)), np.ones(4), state, hist)
    return ck


def test_an_untouched_checkpoint_resumes(box):
    ck = _checkpoint(box.cwd / "results" / "chain_thermal.h5")
    saved = ck.load()
    assert saved.chain.shape == (12, 4, 2) and saved.problem is None
    box.check(box.cwd / "results" / "chain_thermal.h5")


@pytest.mark.parametrize(
    ("edit", "named"),
    [
        ("row", r"block 2 \(steps 6 to 12\)"),
        ("first-row", r"block 1 \(steps 1 to 5\)"),
        ("log_prob", r"block 2 \(steps 6 to 12\)"),
        ("rng", "the commit record"),
        ("iteration", "the commit record"),
    ],
)
def test_an_edited_checkpoint_is_refused_naming_the_block(box, edit, named):
    import json

    import h5py

    path = box.cwd / "results" / "chain_thermal.h5"
    ck = _checkpoint(path)
    with h5py.File(path, "a") as f:  # h5py recomputes Fletcher-32: storage looks fine
        if edit == "row":
            f["chain"][8, 1, 0] += 0.5
        elif edit == "first-row":
            f["chain"][0, 0, 0] = 0.0
        elif edit == "log_prob":
            f["log_prob"][11, 3] = -1.0
        else:
            c = json.loads(f.attrs["commit"])
            if edit == "rng":
                c["rng"][2] = (c["rng"][2] + 1) % 624
            else:
                c["iteration"] = 10
            f.attrs["commit"] = json.dumps(c)
    box.before = snapshot(box.root)
    with pytest.raises(InputError, match=named + r".*changed after hbayes wrote it"):
        ck.load()
    box.check()


def _tiny_run(root: Path) -> Path:
    """A real (tiny) calibration run, once per session."""
    import yaml

    from heritage_bayes.calibration.calibrate import run_calibration
    from heritage_bayes.config import load_config
    from test_faults import _tiny

    cfg = _tiny(name="tiny", **{"sampler.max_steps": 100})
    (root / "tiny.yaml").write_text(yaml.safe_dump(cfg))
    return run_calibration(load_config(root / "tiny.yaml"), root / "run", quiet=True)


@pytest.fixture(scope="module")
def tiny_run(tmp_path_factory) -> Path:
    return _tiny_run(tmp_path_factory.mktemp("tiny"))


def _copy(run: Path, box) -> Path:
    import shutil

    out = box.cwd / "results" / "run"
    shutil.copytree(run, out)
    box.before = snapshot(box.root)
    return out


def test_the_run_records_its_config_and_the_report_shows_it(tiny_run, box):
    from heritage_bayes.report import write_report
    from heritage_bayes.run import load_run

    out = _copy(tiny_run, box)
    run = load_run(out)
    assert run.notes == [] and run.summary["provenance"]["config"]["name"] == "tiny"
    write_report(out)
    assert read_marker(out).owns("report.html")
    box.forget_run(out)
    box.check(out)


def test_an_edited_config_yaml_is_flagged_and_not_used(tiny_run, box):
    from heritage_bayes.report.rundata import load_run_data

    out = _copy(tiny_run, box)
    text = (out / "config.yaml").read_text().replace("thermal_1c", "thermal_2c")
    (out / "config.yaml").write_text(text)
    box.before = snapshot(box.root)
    rd = load_run_data(out)
    assert rd.run.config.thermal.model == "thermal_1c"  # the recorded one
    assert "thermal_1c" in rd.config_text and "thermal_2c" not in rd.config_text
    assert any("config.yaml differs from the config that produced" in n for n in rd.run.notes)
    box.check()


def test_an_edited_config_snapshot_is_refused(tiny_run, box):
    import json

    from heritage_bayes.run import load_run

    out = _copy(tiny_run, box)
    s = json.loads((out / "summary.json").read_text())
    s["provenance"]["config"]["seed"] = 4
    (out / "summary.json").write_text(json.dumps(s))
    box.before = snapshot(box.root)
    with pytest.raises(InputError, match="does not match its SHA-256"):
        load_run(out)
    box.check()


def test_the_report_does_not_replace_a_users_report_html(tiny_run, box):
    from heritage_bayes.report import write_report

    out = _copy(tiny_run, box)
    (out / "report.html").write_text("<p>my own report</p>")
    box.before = snapshot(box.root)
    with pytest.raises(InputError, match=r"report\.html exists and was not written by hbayes"):
        write_report(out)
    box.check()
