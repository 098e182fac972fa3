"""Run every experiment of section 5 on the twin: the library behind ``arzsumo reproduce``.

The experiments are the scenario files of one directory (``scenarios/paper/`` by
default); a file with a ``[sweep]`` table stands for one ETC run per value, and files
that differ only in their controller and its design share one open loop
(``docs/twin.md``, 'Reproducing section 5'). The paper's numbers and the comparison live
in :mod:`.values` and :mod:`.compare`; this module writes nothing (see :mod:`.report`).
Runs are deterministic: with ``workers > 1`` (the sweep engine's process pool,
:func:`arzsumo.sweep.driver.map_runs`) the results are identical and in the same order.
"""

from __future__ import annotations

import logging
import math
import time
from collections.abc import Mapping, Sequence
from dataclasses import dataclass, field, replace
from pathlib import Path
from typing import Any

import numpy as np

from arzsumo.control.events import lyapunov_convergence_time
from arzsumo.engines.twin import TwinRun, compare_to_open_loop, run_twin
from arzsumo.errors import ScenarioError
from arzsumo.io import json_safe
from arzsumo.pde.metrics import Performance
from arzsumo.scenario import Scenario, load_scenario
from arzsumo.sweep.driver import map_runs

log = logging.getLogger(__name__)

#: Default directory of the section 5 scenario files (relative to the working directory).
DEFAULT_DIR = Path("scenarios") / "paper"

#: ``--quick``: a short horizon on a coarse grid, for smoke tests (not for the numbers).
QUICK_TWIN = {"cells": 40, "horizon_s": 40.0, "kernel_cells": 40}

#: Lyapunov convergence time: first time after which V stays below this fraction of V(0).
LYAPUNOV_FRACTION = 0.01

@dataclass(frozen=True)
class RunRecord:
    """What the report needs of one run (light enough to cross process boundaries).

    ``summary`` is :meth:`arzsumo.pde.run.TwinRun.summary` (SI, JSON-ready);
    ``event_times`` the check times (s) at which the applied control was updated;
    ``lyapunov_time`` the Lyapunov convergence time (s; ``inf`` if V never stays below
    :data:`LYAPUNOV_FRACTION` V(0), ``nan`` for controllers without V).
    """

    name: str
    scenario: str
    controller: str
    summary: dict[str, Any]
    event_times: np.ndarray
    lyapunov_time: float
    sweep: tuple[str, float] | None = None

    @property
    def triggers(self) -> int:
        """Number of control updates."""
        return int(self.summary["triggers"])

    @property
    def release_time(self) -> float:
        """Total release time, s."""
        return float(self.summary["release_time"])

    def relative(self, part: str, key: str) -> float:
        """Change of index ``key`` of ``part`` (h, a, total) against the open loop, %."""
        rel = self.summary["relative_to_open_loop_percent"]
        if rel is None:
            return math.nan
        value = rel[part][key]
        return math.nan if value is None else float(value)


@dataclass(frozen=True)
class Reproduction:
    """All runs of a reproduction, in a deterministic order."""

    records: tuple[RunRecord, ...]
    open_loops: int
    quick: bool
    wall_time: float
    source: str
    workers: int = 1
    scenarios: tuple[str, ...] = field(default_factory=tuple)
    overrides: dict[str, Any] = field(default_factory=dict)

    def get(self, name: str) -> RunRecord | None:
        """The record called ``name`` (a scenario name, or ``name[parameter=value]``)."""
        return next((r for r in self.records if r.name == name), None)

    def sweep(self, parameter: str) -> list[RunRecord]:
        """The records of the sweep over ``parameter``, by increasing value."""
        rows = [r for r in self.records if r.sweep is not None and r.sweep[0] == parameter]
        return sorted(rows, key=lambda r: r.sweep[1] if r.sweep else 0.0)


@dataclass(frozen=True)
class _Task:
    scenario: Scenario
    sweep: tuple[str, float] | None
    group: int


def _with(sc: Scenario, **tables: Mapping[str, Any]) -> Scenario:
    """``sc`` with some keys of some tables changed (validated again)."""
    return sc.with_({f"{name}.{key}": value for name, changes in tables.items()
                     for key, value in changes.items()})


def _baseline_key(sc: Scenario) -> str:
    """What decides the open loop: model, equilibrium, solver options (U range aside: the
    open loop applies U = 0) and the initial fields; not the controller nor its design."""
    solver = replace(sc.twin.solver, u_min=None, u_max=None)
    return repr((sc.params, sc.equilibrium, solver, sc.twin.initial))


def load_experiments(directory: str | Path = DEFAULT_DIR) -> list[Scenario]:
    """Every ``*.toml`` scenario of ``directory``, sorted by file name."""
    path = Path(directory)
    if not path.is_dir():
        raise ScenarioError(f"scenarios = {str(path)!r} is not a directory; allowed: a "
                            "directory of scenario files such as scenarios/paper")
    files = sorted(path.glob("*.toml"))
    if not files:
        raise ScenarioError(f"scenarios = {str(path)!r} holds no *.toml scenario files")
    return [load_scenario(f) for f in files]


def plan(scenarios: Sequence[Scenario], *, quick: bool = False,
         only: Sequence[str] | None = None,
         twin: Mapping[str, Any] | None = None) -> list[_Task]:
    """Expand sweeps, apply ``quick`` and ``twin`` overrides, group tasks by open loop."""
    if only is not None:
        names = {sc.name for sc in scenarios}
        missing = sorted(set(only) - names)
        if missing:
            raise ScenarioError(f"only = {missing!r} is not allowed: scenario names are "
                                f"{', '.join(sorted(names))}")
        scenarios = [sc for sc in scenarios if sc.name in set(only)]
    tasks: list[_Task] = []
    groups: dict[str, int] = {}
    for sc in scenarios:
        changes = {**(QUICK_TWIN if quick else {}), **(twin or {})}
        if changes:
            sc = _with(sc, twin=changes)
        sweep = sc.sweep
        items = ([(sc, None)] if sweep is None else
                 [(_with(sc, design={sweep.parameter: v}), (sweep.parameter, v))
                  for v in sweep.values])
        for item, sw in items:
            group = groups.setdefault(_baseline_key(item), len(groups))
            tasks.append(_Task(item, sw, group))
    return tasks


def _record(run: TwinRun, sweep: tuple[str, float] | None) -> RunRecord:
    res = run.result
    ctrl_log = res.controller.log
    V = ctrl_log.extra.get("V")
    lyap = (lyapunov_convergence_time(np.asarray(ctrl_log.t), np.asarray(V),
                                      LYAPUNOV_FRACTION) if V else math.nan)
    name = run.scenario.name if sweep is None else f"{run.scenario.name}[{sweep[0]}={sweep[1]:g}]"
    return RunRecord(name, run.scenario.name, res.controller.name, json_safe(run.summary()),
                     res.control_t[run.events.astype(bool)].copy(), float(lyap), sweep)


def _open_loop(task: _Task) -> tuple[Performance, bool, str, RunRecord | None]:
    """The open loop of a task's group; its record too when the task is the open loop."""
    cfg = task.scenario.twin
    run = run_twin(task.scenario, replace(cfg, controller="open"), baseline=False)
    own = _record(run, task.sweep) if cfg.controller == "open" else None
    return run.performance, run.result.complete, run.result.status, own


def _controlled(item: tuple[_Task, tuple[Performance, bool, str]]) -> RunRecord:
    """A task's run, compared with the open loop of its group (``baseline``)."""
    task, baseline = item
    run = run_twin(task.scenario, baseline=False)
    if run.result.controller.name != "open":
        run = compare_to_open_loop(run, *baseline)
    return _record(run, task.sweep)


def _map(fn: Any, items: list[Any], workers: int, scheduler: str | None) -> list[Any]:
    """``fn`` over ``items`` through the sweep engine (:func:`arzsumo.sweep.driver.map_runs`),
    in this process when there is one worker or one item (and no scheduler)."""
    here = scheduler is None and (workers <= 1 or len(items) <= 1)
    return map_runs(fn, items, workers=workers, scheduler=scheduler, in_process=here)


def reproduce(directory: str | Path = DEFAULT_DIR, *, quick: bool = False,
              only: Sequence[str] | None = None, workers: int | None = None,
              twin: Mapping[str, Any] | None = None,
              scheduler: str | None = None) -> Reproduction:
    """Run every experiment of ``directory`` (one open loop per group of controllers).

    Parameters
    ----------
    directory : path
        Directory of scenario files (default ``scenarios/paper``).
    quick : bool
        Override every ``[twin]`` with :data:`QUICK_TWIN` (smoke test; numbers not
        meaningful).
    only : sequence of str, optional
        Scenario names to run (all by default).
    twin : mapping, optional
        ``[twin]`` keys (scenario-file names and units, e.g. ``{"scheme": "muscl"}``)
        set in every scenario; validated like the files.
    workers : int, optional
        Processes (default 1: faster for runs of about 1 s, ``docs/twin.md``, 'Speed').
        Results do not depend on it.
    scheduler : str, optional
        Address of a Dask scheduler to run on instead (``tcp://host:8786``).
    """
    start = time.perf_counter()
    scenarios = load_experiments(directory)
    tasks = plan(scenarios, quick=quick, only=only, twin=twin)
    workers = 1 if workers is None else max(1, int(workers))
    first: dict[int, int] = {}                 # group -> index of its first task
    for i, task in enumerate(tasks):
        first.setdefault(task.group, i)
    opens = dict(zip(first, _map(_open_loop, [tasks[i] for i in first.values()],
                                  workers, scheduler),
                     strict=True))
    log.debug("%d open loops for %d runs", len(opens), len(tasks))   # the summary says it
    reused = {i for g, i in first.items() if opens[g][3] is not None}
    todo = [i for i in range(len(tasks)) if i not in reused]
    done = _map(_controlled, [(tasks[i], opens[tasks[i].group][:3]) for i in todo],
                workers, scheduler)
    records = dict(zip(todo, done, strict=True)) | {i: opens[g][3] for g, i in first.items()
                                                   if i in reused}
    return Reproduction(tuple(records[i] for i in range(len(tasks))), len(opens), quick,
                        time.perf_counter() - start, str(directory), workers,
                        tuple(sc.name for sc in scenarios), dict(twin or {}))
