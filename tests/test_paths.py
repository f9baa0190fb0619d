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
    with pytest.raises(InputError, match="exists"):
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
