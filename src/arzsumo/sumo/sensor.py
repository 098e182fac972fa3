"""The sensing stage of the closed loop: every libsumo read of a control period.

One :class:`SumoSensor` per run. After each SUMO step :meth:`SumoSensor.observe` samples

* the vehicles on ``main`` (Edie aggregates per class and cell, class flows at the
  section boundaries, :class:`~arzsumo.sumo.measure.MainlineSensor`),
* the lane occupancy downstream of the merge (ALINEA's measurement), and
* the ramp queue (halted vehicles on ``ramp_up`` plus ramp vehicles still waiting to be
  inserted), which the meter's spillback override needs every step,

and when a control period is complete returns one :class:`PeriodMeasurement`. Nothing
else in the closed loop reads SUMO; the meter only writes the traffic light.
"""

from __future__ import annotations

from dataclasses import dataclass
from types import ModuleType

from arzsumo.sumo.config import SumoConfig
from arzsumo.sumo.measure import CellData, MainlineSensor
from arzsumo.sumo.network import DOWN, RAMP_UP

#: the lane whose occupancy ALINEA regulates (downstream of the merge)
OCCUPANCY_LANE = f"{DOWN}_0"


def ramp_queue(lib: ModuleType) -> int:
    """Halted vehicles on ``ramp_up`` plus ramp vehicles still waiting to be inserted."""
    waiting = sum(1 for v in lib.simulation.getPendingVehicles() if v.startswith("ramp"))
    return int(lib.edge.getLastStepHaltingNumber(RAMP_UP)) + waiting


@dataclass(frozen=True)
class PeriodMeasurement:
    """What the sensor read over one control period ending at ``cells.t`` (SI).

    ``cells`` are the Edie aggregates of the mainline; ``occupancy_out`` the mean lane
    occupancy downstream of the merge over the period (fraction, SUMO's definition);
    ``ramp_queue`` the ramp queue at the period's last step, vehicles.
    """

    cells: CellData
    occupancy_out: float
    ramp_queue: int

    @property
    def t(self) -> float:
        """End of the period, s of simulation time."""
        return self.cells.t


class SumoSensor:
    """Reads an open libsumo run every step; yields one measurement per control period.

    Parameters
    ----------
    lib : module
        The libsumo module of the open run.
    length : float
        Length L of the measured section, m.
    cfg : SumoConfig
        Cell length, step length and control period.
    """

    def __init__(self, lib: ModuleType, length: float, cfg: SumoConfig) -> None:
        self.lib = lib
        self.mainline = MainlineSensor(lib, length, cfg.cell_length, cfg.step_length,
                                       cfg.steps_per_period)
        self.queue = 0
        self._occupancy_sum, self._steps = 0.0, 0

    def observe(self, t: float) -> PeriodMeasurement | None:
        """Sample the step that ended at ``t`` (s); return the period's measurement when
        the period is complete, else None. :attr:`queue` is the ramp queue now."""
        self.queue = ramp_queue(self.lib)
        self._occupancy_sum += self.lib.lane.getLastStepOccupancy(OCCUPANCY_LANE)
        self._steps += 1
        cells = self.mainline.collect(t)
        if cells is None:
            return None
        occupancy = self._occupancy_sum / self._steps
        self._occupancy_sum, self._steps = 0.0, 0
        return PeriodMeasurement(cells, occupancy, self.queue)
