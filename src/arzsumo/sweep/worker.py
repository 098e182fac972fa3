"""The worker function of a sweep: one run, in whatever process or machine it lands on.

:func:`execute` takes a picklable :class:`RunTask` and returns a :class:`RunOutcome`. It
writes no files (workers need no shared file system: the driver writes what comes back)
and never raises for a bad run: a user error is status ``invalid``, anything else
``failed``, each with its message.
"""

from __future__ import annotations

import contextlib
import functools
import importlib.metadata
import io
import logging
import os
import socket
import time
import traceback
import uuid
from collections.abc import Iterator
from dataclasses import dataclass, field
from typing import Any

import pyarrow as pa
import pyarrow.parquet as pq

from arzsumo.errors import ArzsumoError
from arzsumo.io import dump_toml, json_safe

#: the statuses of a finished run (``incomplete``: the twin left the physical domain and
#: stopped early, partial summary kept); ``invalid``, ``failed``, ``crashed`` record an error
FINISHED = ("ok", "incomplete")


@dataclass(frozen=True)
class RunTask:
    """Everything a worker needs for one run (picklable, no file paths)."""

    run_id: str
    engine: str
    scenario: dict[str, Any]
    source: str
    baseline: bool
    sha256: str


@dataclass(frozen=True)
class RunOutcome:
    """What a worker returns: summary or error, resolved scenario, tables, execution."""

    run_id: str
    status: str
    summary: dict[str, Any] | None
    error: str | None
    scenario_toml: str
    tables: dict[str, bytes] = field(default_factory=dict)
    execution: dict[str, Any] = field(default_factory=dict)
    warnings: list[str] = field(default_factory=list)


class _Collect(logging.Handler):
    def __init__(self) -> None:
        super().__init__(logging.WARNING)
        self.messages: list[str] = []

    def emit(self, record: logging.LogRecord) -> None:
        self.messages.append(f"{record.name}: {record.getMessage()}")


@contextlib.contextmanager
def collected_warnings() -> Iterator[list[str]]:
    """The warnings arzsumo logs during a run, for its outcome, kept off the sweep's terminal
    (a hundred workers would bury the progress bar); a child forked inside adds its own."""
    logger = logging.getLogger("arzsumo")
    handler, propagate = _Collect(), logger.propagate
    logger.addHandler(handler)
    logger.propagate = False
    try:
        yield handler.messages
    finally:
        logger.removeHandler(handler)
        logger.propagate = propagate


def _parquet(table: pa.Table) -> bytes:
    sink = io.BytesIO()
    pq.write_table(table, sink)
    return sink.getvalue()


def _run_twin(task: RunTask) -> tuple[str, dict[str, Any], dict[str, bytes]]:
    from arzsumo.engines.twin import run_twin
    from arzsumo.outputs.twin import control_table
    from arzsumo.scenario import scenario_from_dict

    sc = scenario_from_dict(task.scenario, task.source)
    run = run_twin(sc, baseline=task.baseline)
    status = "ok" if run.result.complete else "incomplete"
    return status, json_safe(run.summary()), {"control.parquet": _parquet(control_table(run))}


def _run_sumo(task: RunTask) -> tuple[str, dict[str, Any], dict[str, bytes]]:
    from arzsumo.bridge.session import run_in_sumo
    from arzsumo.scenario import scenario_from_dict

    return sumo_outcome(run_in_sumo(scenario_from_dict(task.scenario, task.source)))


def sumo_outcome(session: Any) -> tuple[str, dict[str, Any], dict[str, bytes]]:
    """Status, summary and tables of a finished SUMO session (a plain run or a branch)."""
    from arzsumo.outputs.bridge import cells_table, periods_table, summary

    summ = json_safe(summary(session.result).to_dict())
    summ["settings_resolved"] = session.resolved_comment()
    # the cells (about 0.1 MB a run) let a reading of the field, such as what a boundary
    # can reach, be made from a sweep's runs without running them again
    return "ok", summ, {"periods.parquet": _parquet(periods_table(session.result)),
                        "cells.parquet": _parquet(cells_table(session.result))}


ENGINES = {"twin": _run_twin, "sumo": _run_sumo}


def execute(task: RunTask) -> RunOutcome:
    """Run ``task`` and report; never raises for a bad run (module docstring)."""
    t0, c0 = time.perf_counter(), time.process_time()
    execution = execution_record()
    text = dump_toml(task.scenario)
    with collected_warnings() as warnings:
        status, summ, tables, error = classified(lambda: ENGINES[task.engine](task))
    # CPU time of this process (libsumo's SUMO included): a cost that other load on the
    # machine hardly moves, where the wall time doubles
    execution["wall_s"] = time.perf_counter() - t0
    execution["cpu_s"] = time.process_time() - c0
    return RunOutcome(task.run_id, status, summ, error, text, tables, execution,
                      list(warnings))


def classified(fn: Any) -> tuple[str, dict[str, Any] | None, dict[str, bytes], str | None]:
    """``fn()``'s (status, summary, tables) with no error, or the error classified: a
    user's error is ``invalid``, anything else ``failed`` (with the last frames)."""
    try:
        status, summ, tables = fn()
        return status, summ, tables, None
    except ArzsumoError as exc:
        return "invalid", None, {}, f"{type(exc).__name__}: {exc}"
    except Exception as exc:
        tb = traceback.format_exc(limit=-4)
        return "failed", None, {}, f"{type(exc).__name__}: {exc}\n{tb}"


@functools.cache
def sumo_version() -> str | None:
    """The installed SUMO's version (the ``eclipse-sumo`` distribution), or None."""
    try:
        return importlib.metadata.version("eclipse-sumo")
    except importlib.metadata.PackageNotFoundError:
        return None


def execution_record(**extra: Any) -> dict[str, Any]:
    """Where and when an execution ran, and with which SUMO (``wall_s`` added when it
    ends): a run reproduces bit for bit only on the same SUMO version."""
    return {"id": uuid.uuid4().hex, "host": socket.gethostname(), "pid": os.getpid(),
            "started": time.time(), "sumo": sumo_version(), **extra}


def crashed(task: RunTask, why: str) -> RunOutcome:
    """The outcome of a run whose worker process died (no summary, no tables)."""
    return RunOutcome(task.run_id, "crashed", None, why, dump_toml(task.scenario), {},
                      {"id": uuid.uuid4().hex, "started": time.time(), "wall_s": None})
