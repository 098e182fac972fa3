"""The small twin sweep the sweep tests share, and worker functions for the crash test
(importable by spawned worker processes)."""

from __future__ import annotations

import os
from pathlib import Path

from arzsumo.sweep import SweepSpec, sweep_from_dict
from arzsumo.sweep.worker import RunOutcome, RunTask, execute

ROOT = Path(__file__).resolve().parents[2]
PEN = "scenarios/paper/penetration_44_etc.toml"
SMALL = {"initial": {"kind": "random"}, "twin": {"cells": 40, "horizon_s": 60,
                                                 "kernel_cells": 40}}


def small_spec(values=(0.44, 0.5), seeds=(1, 2), fixed=None, **extra) -> SweepSpec:
    """A twin sweep of a few seconds: penetration x seeds on a 60 s horizon."""
    data = {"name": "small", "base": PEN, "engine": "twin", "seeds": list(seeds),
            "set": fixed or SMALL,
            "axis": [{"field": "equilibrium.penetration", "values": list(values)}], **extra}
    return sweep_from_dict(data, "small.toml", root=ROOT)


def die_on_crash_run(task: RunTask) -> RunOutcome:
    """Kill the worker process (as a crash in SUMO would) for runs marked ``crash``."""
    if task.scenario.get("description") == "crash":
        os._exit(9)
    return execute(task)
