"""A pool worker whose parent dies ends even when its task ignores the unwinding."""

from __future__ import annotations

import contextlib
import os
import subprocess
import sys
import time
from pathlib import Path

import pytest

from arzsumo.interrupts import UNWIND_GRACE_S

#: a parent whose one worker runs a task that swallows every exception, ParentGone too
#: (as a __del__ or a finaliser would), and goes on for a minute
PARENT = """
import multiprocessing, os, sys, time
from arzsumo.interrupts import guarded, worker_pool
from tests.sweep.test_interrupts import stubborn

if __name__ == "__main__":
    with worker_pool(1, multiprocessing.get_context("spawn")) as pool:
        pool.submit(guarded, stubborn, sys.argv[1]).result()
"""


def stubborn(flag: str) -> None:
    Path(flag).write_text(str(os.getpid()))
    end = time.monotonic() + 60
    while time.monotonic() < end:
        with contextlib.suppress(BaseException):   # the point: ParentGone lost
            time.sleep(0.05)


def _gone(pid: int) -> bool:
    try:
        state = Path(f"/proc/{pid}/stat").read_text().rsplit(")", 1)[1].split()[0]
    except OSError:
        return True
    return state == "Z"


@pytest.mark.skipif(not Path("/proc/self/stat").exists(), reason="needs Linux /proc")
def test_a_worker_that_swallows_the_unwinding_still_ends(tmp_path):
    flag = tmp_path / "worker.pid"
    root = Path(__file__).resolve().parents[2]
    parent = subprocess.Popen([sys.executable, "-c", PARENT, str(flag)], cwd=root,
                              env={**os.environ, "PYTHONPATH": str(root)})
    deadline = time.monotonic() + 60
    while time.monotonic() < deadline and not (flag.exists() and flag.read_text()):
        time.sleep(0.05)
    worker = int(flag.read_text())
    parent.kill()                 # the kernel sends the worker SIGTERM (PDEATHSIG)
    parent.wait()
    t0 = time.monotonic()
    while time.monotonic() - t0 < 40 and not _gone(worker):
        time.sleep(0.1)
    waited = time.monotonic() - t0
    assert _gone(worker)
    assert UNWIND_GRACE_S - 1 < waited < UNWIND_GRACE_S + 10   # the grace, not the task
