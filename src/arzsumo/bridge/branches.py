"""Several controllers after one warm-up: the runs of a seed share the warm-up's SUMO.

:func:`run_branched` simulates the warm-up once and forks one child per controller at its
end (:mod:`arzsumo.sumo.fork`); each continues SUMO bit for bit on its own output files and
finishes as :func:`~arzsumo.bridge.cosim.run_cosimulation` would
(``tests/bridge/test_branches.py``). Runs share a warm-up when :func:`warmup_key` agrees:
everything SUMO and the warm-up read except what acts only from the start of control. A
child returns only what ``keep`` makes of its session (picklable); one that dies comes
back as a :class:`~arzsumo.sumo.fork.BranchFailed`. docs/sweeps.md, 'One warm-up per seed'.
"""

from __future__ import annotations

import json
import shutil
import time
from collections.abc import Callable, Sequence
from dataclasses import replace
from functools import partial
from typing import Any, TypeVar

from arzsumo.bridge.cosim import OpenRun, Warmed, finish_run, open_run, warm_start
from arzsumo.bridge.prepared import PreparedRun
from arzsumo.bridge.session import SumoSession
from arzsumo.errors import ArzsumoError
from arzsumo.io import json_safe
from arzsumo.scenario.run import WINDOW_ONLY_RUN_KEYS, RunSettings
from arzsumo.sumo.fork import BranchFailed, run_branches

T = TypeVar("T")


class BranchError(ArzsumoError, ValueError):
    """Runs handed to :func:`run_branched` that do not share a warm-up."""


def warmup_key(run: PreparedRun) -> str:
    """What a run's warm-up depends on, as text: runs with equal keys share it (a
    ``[disturbance]`` acts after the warm-up, so it is left out)."""
    tables = {k: dict(v) if isinstance(v, dict) else v
              for k, v in run.scenario.tables.items()}
    for key in WINDOW_ONLY_RUN_KEYS:
        tables.get("run", {}).pop(key, None)
    tables.pop("disturbance", None)      # it acts from the start of control on
    initial = None if run.initial is None else run.initial.tolist()
    settings = replace(run.settings, controller="open",
                       constant_release=RunSettings().constant_release)
    parts = {"tables": tables, "settings": repr(settings),
             "sumo": repr(run.sumo), "initial": initial}
    return json.dumps(json_safe(parts), sort_keys=True, default=repr)


def run_branched(runs: Sequence[PreparedRun], keep: Callable[[SumoSession], T]
                 ) -> list[T | BranchFailed]:
    """``keep`` of each run's session, the runs continuing one warm-up in forked children
    (module docstring); a :class:`~arzsumo.sumo.fork.BranchFailed` where a child died or
    raised. Runs that do not share a warm-up are refused (:class:`BranchError`)."""
    if not runs:
        return []
    keys = {warmup_key(r) for r in runs}
    if len(keys) > 1:
        raise BranchError(f"{len(runs)} runs with {len(keys)} different warm-ups; allowed: "
                          "runs that differ in [run] controller only")
    first = runs[0]
    with open_run(first) as run:
        warmed = warm_start(run.sim, first, run.bar)
        warm_wall = time.perf_counter() - run.wall0
        return run_branches([partial(_branch, run, warmed, warm_wall, r, i, keep)
                             for i, r in enumerate(runs)])


def _branch(run: OpenRun, warmed: Warmed, warm_wall: float, prepared: PreparedRun,
            index: int, keep: Callable[[SumoSession], Any]) -> Any:
    """In the child: own files, finish the run, return ``keep`` of its session. Its wall
    time is the shared warm-up's plus its own (what a plain run of it costs)."""
    out_dir = run.out_dir / f"branch-{index}"    # under the parent's scratch directory
    run.sim.branch_off(out_dir)
    mine = replace(run, out_dir=out_dir, files=run.files.copy(under=out_dir),
                   wall0=time.perf_counter() - warm_wall)
    try:
        result = finish_run(mine, warmed, prepared)
        return keep(SumoSession(result, prepared.settings, prepared.sumo))
    finally:
        mine.files.remove()
        shutil.rmtree(out_dir, ignore_errors=True)
