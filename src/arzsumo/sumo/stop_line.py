"""The meter's stop-line detector: what the sensor (:class:`arzsumo.sumo.sensor.SumoSensor`)
reads for the meter every step and hands it as a :class:`MeterReading` (the ramp queue for
the queue override, the releases that end a one-vehicle green), and the safety events at
the meter (docs/sumo.md, "Meter realisation").
"""

from __future__ import annotations

from collections.abc import Callable, Sequence
from types import ModuleType
from typing import NamedTuple

from arzsumo.sumo.network import RAMP_UP

#: vehicles at the head of the ramp whose braking the stop-line detector watches
HEAD_VEHICLES = 3
#: braking beyond a vehicle type's ``decel`` by more than this counts as emergency braking
#: at the meter, m/s^2 (SUMO's own count is network-wide)
BRAKING_MARGIN = 0.1


class MeterReading(NamedTuple):
    """One step's reading for the meter: the ramp queue (vehicles) and the vehicles that
    crossed the stop line in the step."""

    queue: int
    released: int


def ramp_queue(lib: ModuleType, pending: Sequence[str] | None = None, edge: str = RAMP_UP,
               is_ramp: Callable[[str], bool] | None = None) -> int:
    """Halted vehicles on ``edge`` (``ramp_up``) plus ramp vehicles still waiting to be
    inserted (``pending``: the ids SUMO holds back this step, read here when not given;
    ``is_ramp``: which are ramp vehicles, by default ids starting with ``ramp``)."""
    if pending is None:
        pending = lib.simulation.getPendingVehicles()
    ramp = is_ramp or (lambda v: v.startswith("ramp"))
    return int(lib.edge.getLastStepHaltingNumber(edge)) + sum(1 for v in pending if ramp(v))


class StopLine:
    """The detector at the stop line of ``ramp_up`` (libsumo, read every step): a vehicle
    is *released* when its front leaves ``ramp_up``; an emergency braking episode is
    counted once per vehicle (docs/sumo.md, "Meter realisation")."""

    def __init__(self, lib: ModuleType, edge: str = RAMP_UP) -> None:
        self.lib, self.edge = lib, edge
        #: every release: (vehicle id, steps since SUMO started when its front had left)
        self.crossings: list[tuple[str, int]] = []
        self._steps = 0
        self._on: set[str] = set()
        self._braking: set[str] = set()
        self.emergency_stops = self.emergency_braking = 0

    def read(self) -> int:
        """Vehicles released since the last read; updates the safety counts."""
        ids = self.lib.edge.getLastStepVehicleIDs(self.edge)   # upstream first
        now = set(ids)
        self._steps += 1
        gone = self._on - now
        self.crossings += [(v, self._steps) for v in sorted(gone)]
        released = len(gone)
        self._on = now
        veh = self.lib.vehicle
        for v in self.lib.simulation.getEmergencyStoppingVehiclesIDList():
            self.emergency_stops += v in now
        braking = {v for v in ids[-HEAD_VEHICLES:]
                   if veh.getAcceleration(v) < -veh.getDecel(v) - BRAKING_MARGIN}
        self.emergency_braking += len(braking - self._braking)
        self._braking = braking
        return released

    def start_window(self) -> dict[str, int]:
        """The safety counts of the window that closes now; count anew."""
        closed = self.summary()
        self.emergency_stops = self.emergency_braking = 0
        return closed

    def summary(self) -> dict[str, int]:
        """Emergency stops and emergency braking episodes at the meter in the window."""
        return {"emergency_stops": self.emergency_stops,
                "emergency_braking": self.emergency_braking}
