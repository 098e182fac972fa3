"""A reproducible disturbance of the plant: an edge slowed for a while after control starts.

The paper's section 5 judges the laws by how they remove a perturbation of the stationary
state. In SUMO the perturbation is made downstream of the meter's reach, where no
controller acts on it: :class:`Slowdown` lowers the speed limit of one edge (``down``,
past the merge, by default) to ``speed`` for ``duration`` seconds, from ``start``
seconds after the start of control. The drop in discharge sends a queue wave upstream
through the section, the same on every controller of a seed: the edge, the times and the
speed are fixed by the scenario, and up to the start of control every run of a seed is
the same run (:mod:`arzsumo.bridge.branches`).

:class:`DisturbanceSchedule` applies it to a running SUMO (``edge.setMaxSpeed``).
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any

from arzsumo.errors import ScenarioError, require
from arzsumo.sumo.network import DOWN, MAIN, MERGE

#: edges a slowdown may act on (the section, the merge, the edge past it)
EDGES = (MAIN, MERGE, DOWN)
#: [disturbance] kinds: none, or an edge's speed limit lowered for a while
KINDS = ("none", "slowdown")


@dataclass(frozen=True)
class Slowdown:
    """The speed limit of ``edge`` lowered to ``speed`` (m/s) for ``duration`` (s) from
    ``start`` (s after the start of control); ``kind = "none"``: no disturbance."""

    kind: str = "none"
    edge: str = DOWN
    speed: float = 10.0 / 3.6
    start: float = 0.0
    duration: float = 30.0

    def __post_init__(self) -> None:
        require(self.kind in KINDS, "kind", self.kind, f"one of {', '.join(KINDS)}",
                ScenarioError)
        require(self.edge in EDGES, "edge", self.edge, f"one of {', '.join(EDGES)}",
                ScenarioError)
        require(math.isfinite(self.speed) and self.speed > 0, "speed", self.speed,
                "a speed > 0 m/s", ScenarioError)
        require(math.isfinite(self.start) and self.start >= 0, "start", self.start,
                "a time >= 0 s after the start of control", ScenarioError)
        require(math.isfinite(self.duration) and self.duration > 0, "duration",
                self.duration, "a duration > 0 s", ScenarioError)

    @property
    def active(self) -> bool:
        return self.kind != "none"


class DisturbanceSchedule:
    """``disturbance`` on the SUMO run ``lib``, its times counted from ``t0`` (s, SUMO
    time at the start of control); :attr:`applied` records what was done (SUMO times,
    m/s). Each lane's own limit is restored at the end."""

    def __init__(self, lib: Any, disturbance: Slowdown, t0: float) -> None:
        self.lib, self.disturbance = lib, disturbance
        self.begin = t0 + disturbance.start
        self.end = self.begin + disturbance.duration
        self.lanes: dict[str, float] = {}
        self.applied: dict[str, Any] = {"kind": disturbance.kind, "edge": disturbance.edge,
                                        "speed_m_s": disturbance.speed, "began_s": None,
                                        "ended_s": None, "original_speed_m_s": None}

    def due(self, t: float) -> None:
        """Apply what is due at SUMO time ``t`` (s); the plant calls it after every step
        (:meth:`arzsumo.sumo.plant.SumoPlant.step`)."""
        eps = 1e-9
        if self.applied["began_s"] is None and t >= self.begin - eps:
            edge = self.disturbance.edge
            self.lanes = {f"{edge}_{i}": float(self.lib.lane.getMaxSpeed(f"{edge}_{i}"))
                          for i in range(int(self.lib.edge.getLaneNumber(edge)))}
            self.lib.edge.setMaxSpeed(edge, self.disturbance.speed)
            self.applied.update(began_s=t, original_speed_m_s=max(self.lanes.values()))
        elif self.applied["ended_s"] is None and self.lanes and t >= self.end - eps:
            for lane, speed in self.lanes.items():
                self.lib.lane.setMaxSpeed(lane, speed)
            self.applied["ended_s"] = t
