"""Ctrl-C with worker processes: the parent reports it, the workers just stop.

A terminal sends SIGINT to the whole process group, so every worker of a pool gets it too;
without care each prints a KeyboardInterrupt traceback, and a pool whose parent was
interrupted waits for its running tasks (whole SUMO runs) before the command can end.
:func:`worker_pool` gives workers a silent exit on SIGINT and ends them at once when the
parent is interrupted; the CLI then prints one line and removes the partial output.
"""

from __future__ import annotations

import concurrent.futures as cf
import contextlib
import multiprocessing.context
import os
import signal
from collections.abc import Iterator

#: exit status of a process ended by Ctrl-C (128 + SIGINT)
EXIT_INTERRUPTED = 130


def quiet_worker() -> None:
    """Initializer of worker processes: SIGINT ends the worker at once, silently (its
    parent reports the interrupt)."""
    signal.signal(signal.SIGINT, lambda signum, frame: os._exit(EXIT_INTERRUPTED))


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
                                  initializer=quiet_worker)
    try:
        yield pool
    except KeyboardInterrupt:
        stop_pool(pool)
        raise
    finally:
        pool.shutdown(wait=True)
