"""Branches of one SUMO run: several continuations of one simulated state.

A child process forked from a process that holds an open libsumo simulation continues
SUMO bit for bit (every vehicle, lane-change model and random number generator is in the
inherited memory; ``tests/sumo/test_warm_start.py``), where SUMO's saveState/loadState
does not. :func:`run_branches` uses this to share a warm-up: the caller warms up once,
then each branch runs in its own child, one after the other, from that same state, and
sends its (picklable) result back through a pipe.

A child ends with ``os._exit``: it runs no cleanup of the parent's (temporary files,
SUMO's own outputs), so the parent's simulation and files stay as they were. A branch
whose child dies or raises comes back as a :class:`BranchFailed`; the caller re-runs it
alone. Forking is POSIX-only: :func:`can_fork` says whether this process may.
"""

from __future__ import annotations

import os
import pickle
import signal
import threading
import traceback
from collections.abc import Callable, Sequence
from dataclasses import dataclass
from typing import Any

#: prctl option: the signal a child gets when its parent dies (linux/prctl.h)
PR_SET_PDEATHSIG = 1


@dataclass(frozen=True)
class BranchFailed:
    """A branch that gave no result: its child's exit status and what it said."""

    index: int
    status: int
    reason: str


def can_fork() -> bool:
    """Whether branches may fork here: a POSIX process with one thread (forking a
    threaded process, such as a Dask worker's, may leave a lock held in the child)."""
    return hasattr(os, "fork") and threading.active_count() == 1


def _die_with_parent() -> None:
    """Linux: have the kernel kill this child when its parent dies (a group's process
    killed from outside leaves no SUMO running); elsewhere nothing."""
    try:
        import ctypes

        libc = ctypes.CDLL(None, use_errno=True)
        libc.prctl(PR_SET_PDEATHSIG, signal.SIGKILL)
    except (OSError, AttributeError):   # not Linux: the parent's waitpid still reaps it
        pass


def _child(fn: Callable[[], Any], write_fd: int) -> None:
    """In the child: run ``fn`` and send ("ok", result) or ("error", text); never return."""
    try:
        _die_with_parent()
        try:
            payload = pickle.dumps(("ok", fn()))
        except BaseException as exc:   # everything goes back to the parent
            payload = pickle.dumps(("error", "".join(
                traceback.format_exception_only(type(exc), exc)).strip()))
        with os.fdopen(write_fd, "wb") as pipe:
            pipe.write(payload)
    finally:
        os._exit(0)


def run_branches(branches: Sequence[Callable[[], Any]]) -> list[Any]:
    """The result of each branch, each run in a child forked from this process's present
    state (one after the other); a :class:`BranchFailed` where a child died or raised."""
    out: list[Any] = []
    for index, fn in enumerate(branches):
        read_fd, write_fd = os.pipe()
        pid = os.fork()
        if pid == 0:
            os.close(read_fd)
            _child(fn, write_fd)
        os.close(write_fd)
        try:
            with os.fdopen(read_fd, "rb") as pipe:
                data = pipe.read()
        finally:
            _, status = os.waitpid(pid, 0)
        out.append(_result(index, status, data))
    return out


def _result(index: int, status: int, data: bytes) -> Any:
    if not data:
        return BranchFailed(index, status, "the child died before it sent a result")
    try:
        kind, value = pickle.loads(data)
    except Exception:   # a truncated pipe
        return BranchFailed(index, status, "the child's result was cut short")
    return value if kind == "ok" else BranchFailed(index, status, str(value))
