"""Worker functions for the crash test; importable by spawned worker processes."""

from __future__ import annotations

import os

from arzsumo.sweep.worker import RunOutcome, RunTask, execute


def die_on_crash_run(task: RunTask) -> RunOutcome:
    """Kill the worker process (as a crash in SUMO would) for runs marked ``crash``."""
    if task.scenario.get("description") == "crash":
        os._exit(9)
    return execute(task)
