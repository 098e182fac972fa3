"""Where results go, through the CLI: refusals before any work, --overwrite, Ctrl-C and
killed runs (real SUMO, subprocesses)."""

from __future__ import annotations

import json
import os
import signal
import subprocess
import sys
import time
from pathlib import Path

import pytest

from arzsumo.outdir import MARKER, write_marker
from tests.test_outdir import checksums, result

ROOT = Path(__file__).resolve().parents[2]
TWIN = str(ROOT / "scenarios" / "paper_base.toml")
# a short warm-up: these tests are about where results go, not about the fill phase
RUN = ("run", "--warmup", "30", "--allow-short-warmup", "--horizon", "60", "--no-plots",
       "--quiet")


def cli_cmd(*args: str) -> list[str]:
    return [sys.executable, "-m", "arzsumo.cli", *args]


def env_with_tmp(tmpdir: Path) -> dict[str, str]:
    tmpdir.mkdir(exist_ok=True)
    return {**os.environ, "TMPDIR": str(tmpdir)}


def cli(*args: str, cwd: Path, tmpdir: Path) -> tuple[subprocess.CompletedProcess, float]:
    t0 = time.perf_counter()
    proc = subprocess.run(cli_cmd(*args), capture_output=True, text=True, timeout=300,
                          cwd=cwd, env=env_with_tmp(tmpdir))
    return proc, time.perf_counter() - t0


@pytest.fixture(scope="module")
def startup() -> float:
    """Seconds to start the CLI (interpreter and imports; ``--version``). The machine is
    shared and its load varies: a refusal must take under 5 s beyond starting (twice this,
    for the variation), far less than a SUMO run (a warm-up alone takes over 10 s)."""
    t0 = time.perf_counter()
    subprocess.run(cli_cmd("--version"), capture_output=True, check=True, timeout=120)
    return time.perf_counter() - t0


def sweep_file(path: Path) -> Path:
    path.write_text(f"""name = "small"
base = "{ROOT / 'scenarios' / 'paper' / 'penetration_44_etc.toml'}"
engine = "twin"
seeds = [1]
[set]
twin.cells = 40
twin.horizon_s = 30
twin.kernel_cells = 40
[[axis]]
field = "equilibrium.penetration"
values = [0.44]
""")
    return path


def one_error_line(proc: subprocess.CompletedProcess, *parts: str) -> None:
    assert proc.returncode == 2, proc.stderr
    lines = proc.stderr.strip().splitlines()
    assert len(lines) == 1, proc.stderr
    assert lines[0].startswith("arzsumo: error: --out = ")
    for part in parts:
        assert part in lines[0]


def commands(tmp_path: Path) -> dict[str, tuple[str, ...]]:
    return {"run": RUN, "twin": ("twin", TWIN, "--no-plots", "--no-baseline"),
            "reproduce": ("reproduce", "--quick", "--no-plots"),
            "sweep": ("sweep", str(sweep_file(tmp_path / "s.toml")), "--quiet", "--no-plots",
                      "--workers", "1")}


@pytest.mark.parametrize("command", ["run", "twin", "reproduce", "sweep"])
@pytest.mark.parametrize("kind", ["dir", "file"])
def test_foreign_out_is_refused_fast_and_untouched(tmp_path, command, kind, startup):
    target = tmp_path / "mine"
    if kind == "dir":
        (target / "sub").mkdir(parents=True)
        (target / "thesis.txt").write_text("notes")
        (target / "sub" / "data.csv").write_text("1,2\n")
    else:
        target.write_text("notes")
    args = commands(tmp_path)[command]
    before, listing = checksums(target), sorted(p.name for p in tmp_path.iterdir())
    proc, elapsed = cli(*args, "--out", "mine", cwd=tmp_path, tmpdir=tmp_path / "tmp")
    one_error_line(proc, "'mine'", "a new or empty directory",
                   "is a file" if kind == "file" else "non-empty directory")
    assert elapsed < 5.0 + 2 * startup  # refused before any simulation
    assert checksums(target) == before
    assert sorted(p.name for p in tmp_path.iterdir()) == sorted({*listing, "tmp"})
    assert list((tmp_path / "tmp").iterdir()) == []


@pytest.mark.parametrize("out", ["/proc/arzsumo-nope/out", "afile/out", "."])
def test_impossible_out_is_refused_before_sumo(tmp_path, out, startup):
    (tmp_path / "afile").write_text("x")
    proc, elapsed = cli(*RUN, "--out", out, cwd=tmp_path, tmpdir=tmp_path / "tmp")
    one_error_line(proc, repr(out))
    assert elapsed < 5.0 + 2 * startup
    assert (tmp_path / "afile").read_text() == "x"
    assert sorted(p.name for p in tmp_path.iterdir()) == ["afile", "tmp"]


def test_default_run_name_has_the_horizon_and_follows_the_rules(tmp_path, startup):
    # a foreign directory at the default name: refused before SUMO, naming that path
    mine = tmp_path / "results" / "default-etc-seed7-h60s-w30s"
    mine.mkdir(parents=True)
    (mine / "notes.txt").write_text("x")
    proc, elapsed = cli(*RUN, "--seed", "7", cwd=tmp_path, tmpdir=tmp_path / "tmp")
    one_error_line(proc, "results/default-etc-seed7-h60s-w30s")
    assert elapsed < 5.0 + 2 * startup and (mine / "notes.txt").read_text() == "x"


def test_same_kind_needs_overwrite_other_kind_never(tmp_path, startup):
    twin = ("twin", TWIN, "--no-plots", "--no-baseline")
    tmpdir = tmp_path / "tmp"
    first, _ = cli(*twin, "--out", "t", cwd=tmp_path, tmpdir=tmpdir)
    assert first.returncode == 0, first.stderr
    assert json.loads((tmp_path / "t" / MARKER).read_text())["kind"] == "twin"
    (tmp_path / "t" / "extra.txt").write_text("from before")
    before = checksums(tmp_path / "t")
    again, _ = cli(*twin, "--out", "t", cwd=tmp_path, tmpdir=tmpdir)
    one_error_line(again, "previous arzsumo twin result", "--overwrite")
    other, elapsed = cli(*RUN, "--out", "t", "--overwrite", cwd=tmp_path, tmpdir=tmpdir)
    one_error_line(other, "holds an arzsumo twin result, not a run result")
    assert elapsed < 5.0 + 2 * startup and checksums(tmp_path / "t") == before
    replaced, _ = cli(*twin, "--out", "t", "--overwrite", cwd=tmp_path, tmpdir=tmpdir)
    assert replaced.returncode == 0, replaced.stderr
    assert not (tmp_path / "t" / "extra.txt").exists()
    assert (tmp_path / "t" / "summary.json").is_file()
    assert sorted(p.name for p in tmp_path.iterdir()) == ["t", "tmp"]
    assert list(tmpdir.iterdir()) == []


def wait_for(cond, timeout: float) -> bool:
    end = time.monotonic() + timeout
    while time.monotonic() < end:
        if cond():
            return True
        time.sleep(0.1)
    return False


def start_run(tmp_path: Path, tmpdir: Path) -> subprocess.Popen:
    proc = subprocess.Popen(cli_cmd(*RUN, "--out", "r"), cwd=tmp_path,
                            env=env_with_tmp(tmpdir), stdout=subprocess.PIPE,
                            stderr=subprocess.PIPE, text=True)
    # SUMO is running once its route file is in the scratch dir of the partial output
    assert wait_for(lambda: any(tmp_path.glob(".r.partial.*/.scratch/arzsumo-*/*.xml")), 30)
    time.sleep(1.0)
    return proc


def test_ctrl_c_ends_with_one_line_130_and_no_leftovers(tmp_path):
    tmpdir = tmp_path / "tmp"
    proc = start_run(tmp_path, tmpdir)
    proc.send_signal(signal.SIGINT)
    _, err = proc.communicate(timeout=60)
    assert proc.returncode == 130
    assert err.strip().splitlines() == ["arzsumo: interrupted"]
    assert sorted(p.name for p in tmp_path.iterdir()) == ["tmp"]  # no target, no partial
    assert list(tmpdir.iterdir()) == []


def test_next_run_clears_what_a_killed_run_left(tmp_path):
    tmpdir = tmp_path / "tmp"
    proc = start_run(tmp_path, tmpdir)
    proc.kill()
    proc.communicate(timeout=60)
    left = sorted(p.name for p in tmp_path.glob(".r.*"))
    assert len(left) == 1 and left[0].startswith(".r.partial.")  # what a kill leaves
    result(tmp_path / ".r.old", "run")  # as if killed while replacing
    result(tmp_path / "r", "run")       # a previous result, replaced with --overwrite
    done, _ = cli(*RUN, "--out", "r", "--overwrite", cwd=tmp_path, tmpdir=tmpdir)
    assert done.returncode == 0, done.stderr
    summary = json.loads((tmp_path / "r" / "summary.json").read_text())
    assert summary["horizon"] == 60 and summary["controller"] == "etc"
    assert sorted(p.name for p in tmp_path.iterdir()) == ["r", "tmp"]
    assert sorted(p.name for p in (tmp_path / "r").iterdir()) == [
        MARKER, "cells.parquet", "periods.parquet", "run.sumocfg", "scenario.toml", "summary.csv",
        "summary.json", "sumo", "tripinfo.xml.gz"]
    assert list(tmpdir.iterdir()) == []


def test_sweep_continues_its_own_directory_without_overwrite(tmp_path):
    sweep = sweep_file(tmp_path / "s.toml")
    args = ("sweep", str(sweep), "--quiet", "--no-plots", "--workers", "1", "--out", "sw")
    first, _ = cli(*args, cwd=tmp_path, tmpdir=tmp_path / "tmp")
    assert first.returncode == 0, first.stderr
    again, _ = cli(*args, cwd=tmp_path, tmpdir=tmp_path / "tmp")
    assert again.returncode == 0, again.stderr
    assert "1 already finished, 0 executed" in again.stdout
    marker = json.loads((tmp_path / "sw" / MARKER).read_text())
    assert marker["kind"] == "sweep"
    assert not list((tmp_path / "sw").glob(".scratch*"))
    write_marker(tmp_path / "sw", "twin")  # relabelled: no longer continued
    third, _ = cli(*args, cwd=tmp_path, tmpdir=tmp_path / "tmp")
    one_error_line(third, "holds an arzsumo twin result, not a sweep result")
