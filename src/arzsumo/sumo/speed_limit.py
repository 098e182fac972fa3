"""The outlet's speed limit as an actuator: mainstream control at x = L.

:class:`OutletSpeedLimit` sets the limit of every lane of the edge past the merge
(``down``) with ``edge.setMaxSpeed``, from the next SUMO step on, and counts the changes
over a window, as the meter counts its plan changes. The mapping of a law's U to a limit
is the actuator's (:class:`arzsumo.bridge.speed_actuator.SpeedLimitActuator`;
docs/sumo.md, "The outlet's speed limit as the actuator").
"""

from __future__ import annotations

from typing import Any

from arzsumo.sumo.network import DOWN


class OutletSpeedLimit:
    """The speed limit of ``edge`` (default ``down``, past the merge) in the SUMO run
    ``lib`` (m/s)."""

    def __init__(self, lib: Any, edge: str = DOWN) -> None:
        self.lib, self.edge = lib, edge
        lanes = int(lib.edge.getLaneNumber(edge))
        #: the limit as the network holds it, m/s: the open loop's
        self.nominal = max(float(lib.lane.getMaxSpeed(f"{edge}_{i}")) for i in range(lanes))
        self.speed = self.nominal
        self.changes = 0

    def set(self, speed: float) -> None:
        """Set the limit to ``speed`` (m/s); a new value is a change."""
        if speed != self.speed:
            self.lib.edge.setMaxSpeed(self.edge, float(speed))
            self.speed = float(speed)
            self.changes += 1

    def restore(self) -> None:
        """The nominal limit again, not counted (the window's count is kept)."""
        if self.speed != self.nominal:
            self.lib.edge.setMaxSpeed(self.edge, self.nominal)
            self.speed = self.nominal

    def start_window(self) -> int:
        """The changes so far; count anew from now."""
        n, self.changes = self.changes, 0
        return n

    def summary(self) -> dict[str, Any]:
        """The window's count and the limit now (m/s)."""
        return {"speed_limit_changes": self.changes, "speed_limit_m_s": self.speed,
                "speed_limit_nominal_m_s": self.nominal}
