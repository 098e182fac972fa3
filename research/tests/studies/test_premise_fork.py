"""A seed's premise runs share one warm-up by fork, bit for bit what separate runs give,
and a child that dies is run again alone, leaving nothing behind (real SUMO, short)."""

from __future__ import annotations

import json
import os
import signal

import pytest
from arzsumo_studies.common import shipped_scenario
from arzsumo_studies.premise import runs as pr

from arzsumo.sumo import fork

pytestmark = [pytest.mark.sumo, pytest.mark.slow]

OPTS = pr.PremiseOptions(window=20.0, pulse=5.0, level=5.0, levels=2)


def _runs():
    return pr.premise_runs(shipped_scenario("legacy_default.toml"), [5], 20.0, OPTS)


def _without_wall(row: dict) -> str:
    """The row but its wall times, as text (NaN speeds of empty cells compare equal)."""
    times = ("wall_s", "warmup_wall_s", "rerun")
    return json.dumps({k: v for k, v in row.items() if k not in times}, sort_keys=True)


def _children() -> set[int]:
    """This process's child processes (Linux: /proc), zombies included."""
    from pathlib import Path

    found: set[int] = set()
    for task in Path(f"/proc/{os.getpid()}/task").iterdir():
        text = (task / "children").read_text().split()
        found.update(int(p) for p in text)
    return found


@pytest.fixture(scope="module")
def plain():
    return [pr.run_premise_task(r) for r in _runs()]


def test_a_forked_group_equals_the_runs_made_alone(plain, monkeypatch, tmp_path):
    monkeypatch.setenv("ARZSUMO_SCRATCH_DIR", str(tmp_path))
    monkeypatch.setattr(fork, "can_fork", lambda: True)   # see the next test
    group = pr.run_premise_group(pr.grouped(_runs())[0])["rows"]
    assert [r["kind"] for r in group] == list(pr.KINDS)
    assert not any(r.get("rerun") for r in group)
    assert len(plain[0]["t_s"]) == 20 and plain[0]["main_vehicles"][-1] > 20
    for a, b in zip(group, plain, strict=True):
        assert _without_wall(a) == _without_wall(b)
    # the pulse moved the stream: the comparison is not between identical runs
    assert plain[1]["v_hv"] != plain[0]["v_hv"]
    assert list(tmp_path.iterdir()) == []


def test_a_killed_child_runs_again_alone_and_nothing_is_left(plain, monkeypatch, tmp_path):
    monkeypatch.setenv("ARZSUMO_SCRATCH_DIR", str(tmp_path))
    parent, branch = os.getpid(), pr._branch

    def dies_in_the_pulse_child(sc, plant, t0, opt, warm_s):
        if os.getpid() != parent and opt["kind"] == "pulse":
            os.kill(os.getpid(), signal.SIGKILL)
        return branch(sc, plant, t0, opt, warm_s)

    monkeypatch.setattr(pr, "_branch", dies_in_the_pulse_child)
    # an earlier test in this process may have left an idle thread (Dask's offload
    # thread), which makes can_fork refuse; this test is about the re-run, so fork anyway
    monkeypatch.setattr(fork, "can_fork", lambda: True)
    before = _children()
    group = pr.run_premise_group(pr.grouped(_runs())[0])["rows"]
    assert [bool(r.get("rerun")) for r in group] == [False, True, False]
    for a, b in zip(group, plain, strict=True):
        assert _without_wall(a) == _without_wall(b)
    assert _children() == before                 # every child was reaped
    assert list(tmp_path.iterdir()) == []


def _parent_with_a_branch(tmp_path, setup: str = "", call: str = "run_branches([branch])\n"):
    """A process that runs one branch sleeping 60 s, and the branch's pid once it runs."""
    import subprocess
    import sys
    import time

    flag = tmp_path / "child.pid"
    code = ("import os, signal, time\n"
            "from arzsumo.sumo.fork import run_branches\n" + setup
            + f"def branch():\n    open({str(flag)!r}, 'w').write(str(os.getpid()))\n"
            "    time.sleep(60)\n" + call)
    parent = subprocess.Popen([sys.executable, "-c", code])
    for _ in range(200):
        if flag.exists() and flag.read_text():
            break
        time.sleep(0.05)
    return parent, int(flag.read_text())


def test_a_branch_dies_with_its_parent(tmp_path):
    """A process that runs branches and is killed from outside leaves no child running."""
    import time

    parent, child = _parent_with_a_branch(tmp_path)
    parent.kill()
    parent.wait()
    for _ in range(100):
        try:
            os.kill(child, 0)
        except ProcessLookupError:
            break
        time.sleep(0.05)
    with pytest.raises(ProcessLookupError):
        os.kill(child, 0)


def test_a_parent_that_unwinds_ends_its_branch_at_once(tmp_path):
    """An exception in the waiting parent (a dying parent's SIGTERM raises one in a pool
    worker) ends the branch's child instead of waiting for its whole run."""
    import time

    parent, child = _parent_with_a_branch(
        tmp_path, setup="def stop(signum, frame):\n    raise RuntimeError('unwind')\n"
                        "signal.signal(signal.SIGTERM, stop)\n",
        call="try:\n    run_branches([branch])\nexcept RuntimeError:\n    raise SystemExit(7)\n")
    t0 = time.monotonic()
    parent.send_signal(signal.SIGTERM)
    assert parent.wait(timeout=20) == 7          # unwound, not after the branch's 60 s
    assert time.monotonic() - t0 < 10
    with pytest.raises(ProcessLookupError):      # reaped by the parent's waitpid
        os.kill(child, 0)
