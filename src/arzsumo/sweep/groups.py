"""Runs of a sweep that share a warm-up, executed as one task (docs/sweeps.md, "One
warm-up per seed"): :func:`share_warmups` groups them; :func:`execute_group` runs each
controller in a child forked at the end of the group's warm-up, in a fresh process where
this one may not fork (a threaded Dask worker).
"""

from __future__ import annotations

import json
import logging
import os
import pickle
import subprocess
import sys
import time
from collections.abc import Sequence
from dataclasses import dataclass
from typing import Any

from arzsumo.scenario.run import WINDOW_ONLY_RUN_KEYS
from arzsumo.sweep.worker import (
    RunOutcome,
    RunTask,
    collected_warnings,
    crashed,
    execute,
    execution_record,
    sumo_outcome,
)

log = logging.getLogger(__name__)
#: a fresh single-threaded Python process that runs one group (:func:`in_subprocess`)
CHILD_COMMAND = [sys.executable, "-c",
                 "from arzsumo.sweep.groups import child_main; child_main()"]


@dataclass(frozen=True)
class RunGroup:
    """Runs that share everything up to the end of the warm-up (picklable)."""

    tasks: tuple[RunTask, ...]

    @property
    def run_id(self) -> str:
        first = self.tasks[0].run_id
        return first if len(self.tasks) == 1 else f"{first} (+{len(self.tasks) - 1})"


def warmup_key(task: RunTask) -> str:
    """A task's scenario without what acts only from the start of control (the [run]
    keys of :data:`~arzsumo.scenario.run.WINDOW_ONLY_RUN_KEYS`, ``[disturbance]``), as
    text: tasks with equal keys share a warm-up."""
    data = {k: dict(v) if isinstance(v, dict) else v for k, v in task.scenario.items()}
    for key in WINDOW_ONLY_RUN_KEYS:
        data.get("run", {}).pop(key, None)
    data.pop("disturbance", None)
    return json.dumps([task.engine, data], sort_keys=True, default=repr)


def share_warmups(tasks: Sequence[RunTask], workers: int = 1) -> list[RunGroup]:
    """The tasks grouped by warm-up, in their order (twin runs stay alone: they have no
    warm-up to share). While there are fewer groups than ``workers``, the largest is
    halved, so that every worker has a group."""
    groups: dict[str, list[RunTask]] = {}
    for i, task in enumerate(tasks):
        key = warmup_key(task) if task.engine == "sumo" else f"alone {i}"
        groups.setdefault(key, []).append(task)
    out = list(groups.values())
    while len(out) < workers and max(map(len, out), default=1) > 1:
        big = max(range(len(out)), key=lambda i: len(out[i]))
        half = (len(out[big]) + 1) // 2
        out[big:big + 1] = [out[big][:half], out[big][half:]]
    return [RunGroup(tuple(g)) for g in out]


def crashed_group(group: RunGroup, why: str) -> list[RunOutcome]:
    """Every run of a group whose process died, as ``crashed``."""
    return [crashed(t, why) for t in group.tasks]


def execute_group(group: RunGroup) -> list[RunOutcome]:
    """The outcome of every run of ``group``, its warm-up shared where it can be."""
    from arzsumo.sumo.fork import can_fork

    if len(group.tasks) == 1:
        return [execute(group.tasks[0])]
    if not can_fork():
        return in_subprocess(group) or [execute(t) for t in group.tasks]
    return _forked(group)


def _prepare(task: RunTask) -> Any:
    from arzsumo.bridge.session import prepare_run
    from arzsumo.scenario import scenario_from_dict

    return prepare_run(scenario_from_dict(task.scenario, task.source))


def _forked(group: RunGroup) -> list[RunOutcome]:
    """Prepare every run (a refused one is ``invalid`` at once), share the warm-up of the
    rest, re-run alone a branch whose child died."""
    from arzsumo.bridge.branches import run_branched
    from arzsumo.io import dump_toml
    from arzsumo.sumo.fork import BranchFailed

    outcomes: dict[str, RunOutcome] = {}
    ready: list[tuple[RunTask, Any]] = []
    for task in group.tasks:
        try:
            ready.append((task, _prepare(task)))
        except Exception:   # refused before SUMO: the plain run says so, classified
            outcomes[task.run_id] = execute(task)
    started = execution_record(shared_warmup=len(ready))
    try:
        with collected_warnings() as warnings:   # the warm-up's; each child adds its own
            branches = run_branched([r for _, r in ready],
                                    lambda session: (*sumo_outcome(session),
                                                     session.result.wall_time,
                                                     list(warnings)))
    except Exception as exc:   # the shared warm-up itself failed: each run says why, alone
        log.warning("group %s: the shared warm-up failed (%s); plain runs instead",
                    group.run_id, type(exc).__name__)
        return [outcomes.get(t.run_id) or execute(t) for t in group.tasks]
    for (task, _), got in zip(ready, branches, strict=True):
        if isinstance(got, BranchFailed):
            log.warning("run %s: its branch of the shared warm-up failed (%s); running it "
                        "again alone", task.run_id, got.reason)
            again = execute(task)
            again.execution["rerun_alone"] = got.reason
            outcomes[task.run_id] = again
            continue
        status, summ, tables, wall, said = got
        execution = {**started, "wall_s": wall}
        outcomes[task.run_id] = RunOutcome(task.run_id, status, summ, None,
                                           dump_toml(task.scenario), tables, execution, said)
    return [outcomes[t.run_id] for t in group.tasks]


def in_subprocess(group: RunGroup) -> list[RunOutcome] | None:
    """:func:`execute_group` in a fresh Python process (one thread, so it may fork); None
    if that process gave no result."""
    t0 = time.perf_counter()
    done = subprocess.run(CHILD_COMMAND, input=pickle.dumps(group), capture_output=True,
                          check=False)
    try:
        out = pickle.loads(done.stdout)
    except Exception:   # it died, or printed something else
        log.warning("group %s: its process gave no result (exit %d, %.0f s); plain runs "
                    "instead", group.run_id, done.returncode, time.perf_counter() - t0)
        return None
    return out if isinstance(out, list) else None


def child_main() -> None:
    """:data:`CHILD_COMMAND`: a pickled group on stdin, its pickled outcomes on stdout."""
    group = pickle.loads(sys.stdin.buffer.read())
    result = os.dup(1)            # SUMO may print: only the outcomes go to the caller
    os.dup2(2, 1)
    out = pickle.dumps(execute_group(group))
    with os.fdopen(result, "wb") as pipe:
        pipe.write(out)
