"""The drain: after the control window, the run goes on until every loaded vehicle has left.

Every controller hands the meter to the same *drain policy*, the queue override held on,
until the network is empty, at most ``[sumo] drain_max_s``. No controller, sensor or twin
runs; fuel and CO2 are summed every step (SUMO's emissions device cannot be read while
running), so the window's measures stay the window's. Teleports are off, so vehicles at the merge
can wait for each other for good (measured: 1 drain in 5 on the default); a drain with no
arrival for :data:`STALL_S` while vehicles remain ends as ``gridlock``. docs/whole_demand.md.
"""

from __future__ import annotations

from dataclasses import dataclass, replace

import pandas as pd

from arzsumo.bridge.run_progress import DRAIN
from arzsumo.progress import RunProgress
from arzsumo.sumo.network import NetworkSpec
from arzsumo.sumo.network_measures import ramp_waits, whole_demand_summary
from arzsumo.sumo.plant import SumoPlant
from arzsumo.sumo.window import NetworkMeasures, WindowEnd

#: a drain with no arrival for this long while vehicles remain is a gridlock, s
STALL_S = 300.0


@dataclass(frozen=True)
class Drained:
    """What the drain left: the window's end (its values then), the drain's length and
    limit (s), and whether it ended on a gridlock (no arrival for :data:`STALL_S`)."""

    end: WindowEnd
    duration_s: float
    max_s: float
    gridlock: bool = False


def drain(plant: SumoPlant, limit: float, bar: RunProgress | None = None) -> Drained:
    """Step ``plant`` after the control window under the drain policy (module docstring)
    until no vehicle is in the system or expected, at most ``limit`` seconds; ``bar``
    counts the vehicles that have left."""
    sim = plant.sim
    t_end = sim.time
    plant.end_window()
    arrived, last_arrival, gridlock = sim.arrived, t_end, False
    left = plant.expected()
    if bar is not None:
        bar.enter(DRAIN, work=left)
    while sim.time - t_end < limit - 1e-9 and left > 0:
        plant.step()
        left = plant.expected()
        if bar is not None:
            bar.update(bar.timer.phase.work - left)
        if sim.arrived > arrived:
            arrived, last_arrival = sim.arrived, sim.time
        elif sim.time - last_arrival >= STALL_S:
            gridlock = True
            break
    return Drained(plant.sensor.window_end_values(), sim.time - t_end, limit, gridlock)


def whole_demand(network: NetworkMeasures, trips: pd.DataFrame, plant: SumoPlant,
                 drained: Drained) -> NetworkMeasures:
    """``network`` with its ``whole_demand`` block
    (:func:`~arzsumo.sumo.network_measures.whole_demand_summary`): the whole run after the
    drain, the per-step integral of vehicles in the system and the ramp vehicles' waits at
    the meter."""
    spec, sim = NetworkSpec(), plant.sim
    road = sim.cfg.layout
    free = spec.ramp_length / spec.ramp_speed if road is None else road.ramp_free_time
    waits = ramp_waits(trips, plant.sensor.stop_line.crossings, sim.cfg.step_length, free)
    block = whole_demand_summary(network.whole_run, waits, sim.in_system_s,
                                 drained.duration_s, drained.max_s, drained.gridlock)
    return replace(network, whole_demand=block)
