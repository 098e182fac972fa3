"""Ctrl-C with worker processes: the parent reports it, the workers just stop.

A terminal sends SIGINT to the whole process group, so every worker of a pool gets it too;
without care each prints a KeyboardInterrupt traceback, and a pool whose parent was
interrupted waits for its running tasks (whole SUMO runs) before the command can end.
:func:`worker_pool` gives workers a silent exit on SIGINT and ends them at once when the
parent is interrupted; the CLI then prints one line and removes the partial output.

Workers also end when their parent dies however it died (SIGTERM, SIGKILL, the OOM
killer): the kernel sends them SIGTERM (Linux ``PR_SET_PDEATHSIG``), and a worker in the
middle of a task unwinds it first (:class:`ParentGone`: SUMO is closed, its temporary
files removed) before it exits, within ``UNWIND_GRACE_S`` whatever the task does; an idle
one exits at once. Each worker keeps its temporary files in a scratch directory of its
own, inside its parent's, and removes it as it exits that way: a signal that lands
between a file's creation and the code that owns it leaves nothing either.
"""

from __future__ import annotations

import concurrent.futures as cf
import contextlib
import multiprocessing.context
import os
import shutil
import signal
import tempfile
from collections.abc import Callable, Iterator
from pathlib import Path
from typing import Any

from arzsumo.outdir import SCRATCH_ENV

#: exit status of a process ended by Ctrl-C (128 + SIGINT), by SIGTERM (128 + 15)
EXIT_INTERRUPTED, EXIT_TERMINATED = 130, 143
#: prctl option: the signal a child gets when its parent dies (linux/prctl.h)
PR_SET_PDEATHSIG = 1
#: seconds a worker whose parent died has to unwind its task before it exits regardless
UNWIND_GRACE_S = 10

_busy = False   # a worker's task is running (set by guarded)
_own_scratch: Path | None = None   # a worker's scratch directory (set by quiet_worker)


class ParentGone(BaseException):
    """Raised in a busy worker whose parent died: unwinds the task, then the worker exits."""


def die_with_parent(sig: int = signal.SIGKILL) -> None:
    """Linux: have the kernel send ``sig`` to this process when its parent dies;
    elsewhere nothing (the parent's own cleanup still ends its children)."""
    with contextlib.suppress(OSError, AttributeError):
        import ctypes

        ctypes.CDLL(None, use_errno=True).prctl(PR_SET_PDEATHSIG, int(sig))


def _parent_gone(signum: int, frame: object) -> None:
    if _busy:
        # the unwinding gets UNWIND_GRACE_S: a ParentGone that lands where Python ignores
        # exceptions (a __del__, a finaliser) or in the pool's own code would otherwise
        # leave the worker running its task to the end for a parent that is gone
        signal.signal(signal.SIGALRM, lambda signum, frame: _exit_terminated())
        signal.alarm(UNWIND_GRACE_S)
        raise ParentGone
    _exit_terminated()


def _exit_terminated() -> None:
    if _own_scratch is not None:
        shutil.rmtree(_own_scratch, ignore_errors=True)
    os._exit(EXIT_TERMINATED)


def quiet_worker(parent: int | None = None) -> None:
    """Initializer of worker processes: SIGINT ends the worker at once, silently (its
    parent reports the interrupt); with the ``parent`` pid, SIGTERM or the parent's
    death ends it after unwinding its task (module docstring)."""
    global _own_scratch
    signal.signal(signal.SIGINT, lambda signum, frame: os._exit(EXIT_INTERRUPTED))
    if parent is not None:
        base = os.environ.get(SCRATCH_ENV)
        if base:
            _own_scratch = Path(tempfile.mkdtemp(prefix=f"worker.{os.getpid()}.", dir=base))
            os.environ[SCRATCH_ENV] = str(_own_scratch)
        signal.signal(signal.SIGTERM, _parent_gone)
        die_with_parent(signal.SIGTERM)
        if os.getppid() != parent:    # the parent died before the line above
            _exit_terminated()


def guarded(fn: Callable[[Any], Any], task: Any) -> Any:
    """``fn(task)`` in a worker of :func:`worker_pool`, exiting once it has unwound if
    the parent died meanwhile (submit ``guarded, fn, task``)."""
    global _busy
    try:
        _busy = True    # inside the try: a ParentGone from the first instant is caught
        return fn(task)
    except ParentGone:
        _exit_terminated()
    finally:
        _busy = False


def stop_pool(pool: cf.ProcessPoolExecutor) -> None:
    """Cancel the queued tasks and end the workers now, without waiting for running ones."""
    # no public handle on the workers before Python 3.14 (terminate_workers)
    workers = list((getattr(pool, "_processes", None) or {}).values())
    pool.shutdown(wait=False, cancel_futures=True)
    for proc in workers:
        with contextlib.suppress(Exception):
            proc.terminate()


@contextlib.contextmanager
def worker_pool(workers: int, mp_context: multiprocessing.context.BaseContext | None = None
                ) -> Iterator[cf.ProcessPoolExecutor]:
    """A process pool (as ``ProcessPoolExecutor(workers, mp_context)``) whose workers exit
    silently on SIGINT and are ended at once when the caller is interrupted."""
    pool = cf.ProcessPoolExecutor(max_workers=workers, mp_context=mp_context,
                                  initializer=quiet_worker, initargs=(os.getpid(),))
    try:
        yield pool
    except KeyboardInterrupt:
        stop_pool(pool)
        raise
    finally:
        pool.shutdown(wait=True)
