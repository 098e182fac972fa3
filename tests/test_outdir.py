"""The output policy of :mod:`arzsumo.outdir`: what may be written, replaced, removed."""

from __future__ import annotations

import hashlib
import json
import os
import subprocess
import sys
from pathlib import Path

import pytest

from arzsumo.outdir import (
    MARKER,
    SCRATCH_ENV,
    OutputDir,
    OutputError,
    atomic_dir,
    marker_kind,
    remove_leftovers,
    resumable_dir,
    write_marker,
)
from arzsumo.sumo.paths import scratch_dir


def checksums(root: Path) -> dict[str, str]:
    """SHA-256 of every file under ``root`` (or of ``root`` itself), by relative path."""
    if root.is_file():
        return {".": hashlib.sha256(root.read_bytes()).hexdigest()}
    return {str(p.relative_to(root)): hashlib.sha256(p.read_bytes()).hexdigest()
            for p in sorted(root.rglob("*")) if p.is_file()}


def result(path: Path, kind: str, text: str = "old") -> Path:
    path.mkdir(parents=True)
    write_marker(path, kind)
    (path / "summary.json").write_text(text)
    return path


def dead_pid() -> int:
    proc = subprocess.run([sys.executable, "-c", "import os; print(os.getpid())"],
                          capture_output=True, text=True, check=True)
    return int(proc.stdout)


def test_new_target_gets_files_and_marker(tmp_path):
    with atomic_dir(tmp_path / "a" / "b", "twin") as tmp:
        (tmp / "x.txt").write_text("1")
    out = tmp_path / "a" / "b"
    assert (out / "x.txt").read_text() == "1"
    assert json.loads((out / MARKER).read_text())["kind"] == "twin"
    assert sorted(p.name for p in (tmp_path / "a").iterdir()) == ["b"]  # nothing beside it


def test_empty_directory_is_written(tmp_path):
    (tmp_path / "e").mkdir()
    with atomic_dir(tmp_path / "e", "run") as tmp:
        (tmp / "x").write_text("1")
    assert marker_kind(tmp_path / "e") == "run" and (tmp_path / "e" / "x").is_file()


@pytest.mark.parametrize(("make", "message"), [
    (lambda p: (p.mkdir(), (p / "thesis.txt").write_text("notes")), "non-empty directory"),
    (lambda p: p.write_text("notes"), "is a file"),
    (lambda p: result(p, "twin"), "holds an arzsumo twin result, not a run result"),
])
@pytest.mark.parametrize("overwrite", [False, True])
def test_foreign_targets_are_refused_untouched(tmp_path, make, message, overwrite):
    target = tmp_path / "out"
    make(target)
    before = checksums(target)
    with pytest.raises(OutputError, match=message):
        OutputDir(target, "run", overwrite=overwrite)
    assert checksums(target) == before
    assert sorted(p.name for p in tmp_path.iterdir()) == ["out"]


def test_same_kind_needs_overwrite_then_is_replaced(tmp_path):
    target = result(tmp_path / "out", "run")
    (target / "stale.txt").write_text("from the old run")
    with pytest.raises(OutputError, match=r"previous arzsumo run result; allowed: --overwrite"):
        OutputDir(target, "run")
    assert (target / "stale.txt").is_file()
    with atomic_dir(target, "run", overwrite=True) as tmp:
        (tmp / "summary.json").write_text("new")
    assert (target / "summary.json").read_text() == "new"
    assert not (target / "stale.txt").exists()
    assert sorted(p.name for p in tmp_path.iterdir()) == ["out"]


def test_dot_resolves_to_the_cwd_and_is_judged(tmp_path, monkeypatch):
    (tmp_path / "mine.txt").write_text("x")
    monkeypatch.chdir(tmp_path)
    with pytest.raises(OutputError, match=rf"--out = '\.' \({tmp_path}\) is a non-empty"):
        OutputDir(".", "twin")


@pytest.mark.parametrize("path", ["/", "/proc/arzsumo-nope/out", "{tmp}/file/sub"])
def test_impossible_targets_are_refused_and_leave_nothing(tmp_path, path):
    (tmp_path / "file").write_text("x")
    with pytest.raises(OutputError, match=r"has no name|cannot be created"):
        OutputDir(path.format(tmp=tmp_path), "run")
    assert sorted(p.name for p in tmp_path.iterdir()) == ["file"]


def test_error_inside_removes_partial_and_created_parents(tmp_path):
    with pytest.raises(RuntimeError), OutputDir(tmp_path / "new" / "deep" / "out", "run"):
        assert len(list((tmp_path / "new" / "deep").glob(".out.partial.*"))) == 1
        raise RuntimeError("boom")
    assert list(tmp_path.iterdir()) == []


def test_scratch_dir_lives_in_the_partial_dir_while_open(tmp_path, monkeypatch):
    monkeypatch.delenv(SCRATCH_ENV, raising=False)
    with OutputDir(tmp_path / "out", "run") as od:
        s = scratch_dir()
        assert s is not None and s.parent == od.tmp
        (s / "route.xml").write_text("x")
        od.commit()
    assert scratch_dir() is None
    assert sorted(p.name for p in (tmp_path / "out").iterdir()) == [MARKER]


def test_leftovers_of_dead_runs_are_removed_only_when_ours(tmp_path):
    target = tmp_path / "out"
    dead = dead_pid()
    ours = tmp_path / f".out.partial.{dead}.abc"
    ours.mkdir()
    write_marker(ours, "run")
    (ours / ".scratch").mkdir()
    old = result(tmp_path / ".out.old", "run")
    alive = tmp_path / f".out.partial.{os.getppid()}.abc"  # a live process: in use
    alive.mkdir()
    write_marker(alive, "run")
    foreign = tmp_path / f".out.partial.{dead}.mine"       # no marker, not empty
    foreign.mkdir()
    (foreign / "notes.txt").write_text("keep")
    other = result(tmp_path / ".other.old", "run")         # another target's
    assert set(remove_leftovers(target)) == {ours, old}
    assert alive.is_dir() and (foreign / "notes.txt").is_file() and other.is_dir()


def test_resumable_dir_continues_its_own_kind_and_refuses_others(tmp_path, monkeypatch):
    monkeypatch.delenv(SCRATCH_ENV, raising=False)
    with resumable_dir(tmp_path / "sw", "sweep") as out:
        (out / "runs").mkdir()
        assert scratch_dir() is not None and scratch_dir().parent == out
    with resumable_dir(tmp_path / "sw", "sweep") as out:  # no --overwrite needed
        assert (out / "runs").is_dir()
    assert sorted(p.name for p in (tmp_path / "sw").iterdir()) == [MARKER, "runs"]
    result(tmp_path / "tw", "twin")
    (tmp_path / "f").write_text("x")
    for bad, message in (("tw", "twin result, not a sweep"), ("f", "is a file")):
        with pytest.raises(OutputError, match=message), resumable_dir(tmp_path / bad, "sweep"):
            pass
    assert (tmp_path / "f").read_text() == "x"
