"""Branches of one SUMO run: several continuations of one simulated state.

A child process forked from a process that holds an open libsumo simulation continues
SUMO bit for bit (all its state is in the inherited memory;
``tests/sumo/test_warm_start.py``), where SUMO's saveState/loadState does not.
:func:`run_branches` runs each branch in a child of its own, one after the other, from the
caller's state, and sends its (picklable) result back through a pipe; a child that dies
or raises comes back as a :class:`BranchFailed` (the caller re-runs it alone). A child
ends with ``os._exit``, running no cleanup of the parent's; one that lets SUMO write its
outputs calls :func:`own_files` first, since it inherits the parent's open files, offsets
included. Forking is POSIX-only: :func:`can_fork` says whether this process may.
"""

from __future__ import annotations

import contextlib
import os
import pickle
import shutil
import signal
import threading
import traceback
from collections.abc import Callable, Iterator, Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import Any

from arzsumo.interrupts import die_with_parent

#: where Linux lists a process's open files and their offsets and flags
PROC_FD, PROC_FDINFO = Path("/proc/self/fd"), Path("/proc/self/fdinfo")


@dataclass(frozen=True)
class BranchFailed:
    """A branch that gave no result: its child's exit status and what it said."""

    index: int
    status: int
    reason: str


def can_fork() -> bool:
    """Whether branches may fork here: a Linux process with one thread (forking a
    threaded process, such as a Dask worker's, may leave a lock held in the child;
    :func:`own_files` reads ``/proc``)."""
    return hasattr(os, "fork") and threading.active_count() == 1 and PROC_FD.is_dir()


@dataclass(frozen=True)
class OpenFile:
    """A file this process holds open: descriptor, path, open flags and offset."""

    fd: int
    path: Path
    flags: int
    offset: int

    @property
    def writable(self) -> bool:
        return self.flags & os.O_ACCMODE != os.O_RDONLY


def open_files(under: Path) -> Iterator[OpenFile]:
    """The regular files under ``under`` that this process holds open (Linux ``/proc``)."""
    root = Path(under).resolve()
    for entry in PROC_FD.iterdir():
        try:
            fd, path = int(entry.name), Path(os.readlink(entry))
            info = dict(line.split(":", 1) for line in
                        (PROC_FDINFO / entry.name).read_text().splitlines() if ":" in line)
        except (OSError, ValueError):   # closed meanwhile, or not a file
            continue
        if path.is_relative_to(root) and path.is_file():
            yield OpenFile(fd, path, int(info["flags"], 8), int(info["pos"]))


def own_files(src: Path, dst: Path) -> list[Path]:
    """In a forked child: make the files it inherited open under ``src`` its own.

    A forked child shares each open file's offset with its parent, so its reads and
    writes would move the parent's. Each file open for writing is copied as it stands
    into ``dst`` (same relative path) and the child's descriptor now points at the copy,
    at the same offset: what the child writes from now on (the bytes still in its
    buffers included) goes there, after what the parent had written. Each file open for
    reading only is opened again, at the same offset. Return the copies' paths.
    """
    copies = []
    for f in list(open_files(src)):
        if f.writable:
            target = Path(dst) / f.path.relative_to(Path(src).resolve())
            target.parent.mkdir(parents=True, exist_ok=True)
            shutil.copyfile(f.path, target)
            new = os.open(target, f.flags & (os.O_ACCMODE | os.O_APPEND))
            copies.append(target)
        else:
            new = os.open(f.path, os.O_RDONLY)
        try:
            os.lseek(new, f.offset, os.SEEK_SET)
            os.dup2(new, f.fd, inheritable=False)
        finally:
            os.close(new)
    return copies


def _child(fn: Callable[[], Any], write_fd: int) -> None:
    """In the child: run ``fn`` and send ("ok", result) or ("error", text); never return."""
    try:
        die_with_parent(signal.SIGKILL)   # a group killed from outside leaves no SUMO
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
        except BaseException:
            # this process unwinds (Ctrl-C, a dying parent's SIGTERM): end the branch now,
            # or the wait below would wait for its whole run (it dies only with us)
            with contextlib.suppress(ProcessLookupError):
                os.kill(pid, signal.SIGKILL)
            raise
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
