"""One twin run of a scenario: initial fields, controller, solver, indices, summary.

This is the library function behind ``arzsumo twin``; it writes nothing.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, replace
from typing import Any

import numpy as np

from arzsumo.control.base import Controller
from arzsumo.control.events import release_time
from arzsumo.control.registry import ControllerInputs, controller_spec
from arzsumo.kernel_cache import cached_kernels
from arzsumo.model.characteristic import Linearization, linearize
from arzsumo.pde.initial import initial_fields
from arzsumo.pde.metrics import (
    Performance,
    deviation_norm,
    events,
    performance,
    relative_change,
)
from arzsumo.pde.solver import TwinResult, simulate
from arzsumo.pde.state import cell_centres
from arzsumo.scenario import Scenario
from arzsumo.scenario.twin import TwinConfig
from arzsumo.schema import TWIN_SUMMARY, key_units
from arzsumo.version import __version__


@dataclass(frozen=True)
class TwinRun:
    """A finished (possibly incomplete) twin run with everything outputs and plots need."""

    scenario: Scenario
    config: TwinConfig
    result: TwinResult
    performance: Performance
    norm: np.ndarray
    events: np.ndarray
    baseline: Performance | None
    baseline_status: str = "not run"

    @property
    def triggers(self) -> int:
        """Number of updates of the applied control."""
        return int(self.events.sum())

    @property
    def release_time(self) -> float:
        """Total release time, s (:func:`arzsumo.control.events.release_time`)."""
        return release_time(self.result.control_t, self.events, float(self.result.t[-1]))

    def summary(self) -> dict[str, Any]:
        """JSON-ready summary; SI units (veh, s, m); ``units_by_key`` gives each key's unit."""
        r = self.result
        n0 = float(r.fields[0, [0, 2]].sum() * r.dx)
        n1 = float(r.extra["total_vehicles"])
        perf = self.performance.as_dict()
        ratio = float(self.norm[-1] / self.norm[0]) if self.norm[0] > 0 else math.nan
        summ = {
            "scenario": self.scenario.name,
            "source": self.scenario.source,
            "version": __version__,
            "seed": self.config.seed,
            "controller": r.controller.name,
            "complete": r.complete,
            "status": r.status,
            "units": "SI: veh, s, m; U in veh/s",
            "triggers": self.triggers,
            "release_time": self.release_time,
            "saturation_time": r.saturated_time,
            "outlet_limited_time": r.extra["outlet_limited_time"],
            "u_range": list(r.u_range),
            **{index: {k: v[index] for k, v in perf.items()}
               for index in ("J_fuel", "J_discom", "J_TTT", "TMT", "total_delay")},
            "relative_to_open_loop_percent": (relative_change(self.performance, self.baseline)
                                              if self.baseline is not None else None),
            "open_loop_baseline": self.baseline_status,
            "initial_norm": float(self.norm[0]),
            "final_norm": float(self.norm[-1]),
            "final_norm_ratio": ratio,
            "final_time": float(r.t[-1]),
            "equilibrium": self.scenario.equilibrium.as_dict(),
            "regime": linearize(self.scenario.equilibrium).regime,
            "config": self.config.as_dict(),
            "numerics": {"steps": r.steps, "rejected_steps": r.rejected_steps,
                         "wall_time_s": r.wall_time, "speed_up": r.speed_up},
            "conservation": {"vehicles_initial": n0, "vehicles_final": n1,
                             "inflow": r.inflow, "outflow": r.outflow,
                             "balance_error": n1 - n0 - (r.inflow - r.outflow)},
        }
        summ["units_by_key"] = key_units(summ, TWIN_SUMMARY)   # docs/outputs.md
        return summ


def twin_controller(cfg: TwinConfig, lin: Linearization) -> Controller:
    """A fresh controller of ``cfg`` (the registry's builder; kernels from the cache on
    ``cfg.kernel_cells`` cells for a PDE controller)."""
    spec = controller_spec(cfg.controller, "twin")
    kernels = cached_kernels(lin.system, cfg.kernel_cells) if spec.pde else None
    return spec.build(ControllerInputs(lin, kernels, cfg.design, cfg.constant_u))


def run_twin(scenario: Scenario, config: TwinConfig | None = None, *,
             controller: Controller | None = None, baseline: bool = True) -> TwinRun:
    """Run the twin on ``scenario``.

    ``config`` defaults to the scenario's ``[twin]``, ``[initial]`` and ``[design]``;
    ``controller`` (an instance) overrides the configured controller; ``baseline`` also
    runs the open loop of the same scenario to report relative changes (skipped when the
    controller is the open loop).
    """
    cfg = config or scenario.twin
    eq = scenario.equilibrium
    lin = linearize(eq)
    ctrl = controller or twin_controller(cfg, lin)
    x = cell_centres(eq.params.length, cfg.solver.cells)
    init = initial_fields(cfg.initial, eq, x)
    res = simulate(eq, init, controller=ctrl, options=cfg.solver)
    perf = performance(eq.params, res.t, res.x, res.fields)
    mask = events(res.control_t, res.control_u, ctrl.log.triggered if ctrl.log.t else None)
    run = TwinRun(scenario, cfg, res, perf, deviation_norm(eq, res.x, res.fields), mask, None)
    if ctrl.name == "open":
        return replace(run, baseline_status="this run is the open loop")
    if not baseline:
        return run
    open_res = simulate(eq, init, options=cfg.solver)
    open_perf = performance(eq.params, open_res.t, open_res.x, open_res.fields)
    return compare_to_open_loop(run, open_perf, open_res.complete, open_res.status)


def compare_to_open_loop(run: TwinRun, open_loop: Performance, complete: bool,
                         status: str) -> TwinRun:
    """``run`` with the indices ``open_loop`` of the open loop of the same scenario (same
    initial fields and solver options: the caller guarantees it, e.g.
    :func:`arzsumo.workflows.paper.reproduce.reproduce` sharing one open loop) as its
    baseline. ``complete``, ``status``: whether that open loop completed, and its status;
    indices over different horizons are not comparable, so an incomplete run on either
    side gives no baseline.
    """
    res = run.result
    if complete and res.complete:
        return replace(run, baseline=open_loop, baseline_status=status)
    return replace(run, baseline=None,
                   baseline_status=f"no comparison: open loop {status}; run {res.status}")
