"""What one control period of the closed loop leaves behind: a typed record per period.

Record k pairs the check at ``t`` (s from the start of control) with the SUMO period that
followed it under that check's command (docs/outputs.md, ``periods.parquet``).
"""

from __future__ import annotations

from dataclasses import dataclass, field, fields

import numpy as np

from arzsumo.bridge.actuator import Actuation
from arzsumo.control.base import Command
from arzsumo.sumo.measure import CellData
from arzsumo.sumo.meter import MeterState
from arzsumo.sumo.sensor import PeriodMeasurement


@dataclass(frozen=True)
class PeriodRecord:
    """One control period (SI; flows veh/s, counts since the start of control; flags 1.0 or
    0.0): the check at ``t`` and the period that followed. The columns of
    ``periods.parquet``, each described in :data:`arzsumo.schema.PERIODS` (docs/outputs.md).
    """

    t: float
    u: float
    u_continuous: float
    triggered: float
    green_commanded: float
    green_running: float
    light_changes: float
    plan_changes: float
    queue: float
    max_queue: float
    inflow_h: float
    inflow_a: float
    outflow_h: float
    outflow_a: float
    occupancy_out: float
    u_reference: float
    controller_s: float
    u_raw: float = float("nan")
    u_applied: float = float("nan")
    saturated: float = 0.0
    rate_limited: float = 0.0
    flow_out_loop: float = float("nan")
    release_rate: float = float("nan")
    override: float = 0.0
    speed_limit: float = float("nan")

    @classmethod
    def of(cls, t: float, command: Command, act: Actuation, u_reference: float,
           controller_s: float, m: PeriodMeasurement, meter: MeterState) -> PeriodRecord:
        """The record of the check at ``t`` (s from the start of control) and of the period
        that followed (the sensor's measurement, the meter at its end); times in s."""
        c = m.cells
        return cls(t=t, u=act.u_applied, u_continuous=command.u_continuous,
                   triggered=float(command.triggered), green_commanded=act.green,
                   green_running=meter.green_share, light_changes=meter.light_changes,
                   plan_changes=meter.plan_changes, queue=meter.queue,
                   max_queue=meter.max_queue, inflow_h=c.inflow_h, inflow_a=c.inflow_a,
                   outflow_h=c.outflow_h, outflow_a=c.outflow_a,
                   occupancy_out=m.occupancy_out, u_reference=u_reference,
                   controller_s=controller_s, u_raw=command.u, u_applied=act.u_applied,
                   saturated=float(act.saturated), rate_limited=float(act.rate_limited),
                   flow_out_loop=m.flow_out_loop, release_rate=act.release_rate,
                   override=float(meter.override), speed_limit=act.speed_limit)


def columns(records: list[PeriodRecord]) -> dict[str, np.ndarray]:
    """The records as one float array per field (the ``periods`` table's columns)."""
    return {f.name: np.array([getattr(r, f.name) for r in records], float)
            for f in fields(PeriodRecord)}


def micro_fields(c: CellData) -> np.ndarray:
    """Edie cells as (rho_h, v_h, rho_a, v_a) rows (4, cells), SI; NaN speed where empty."""
    return np.vstack([c.rho_h, c.v_h, c.rho_a, c.v_a])


@dataclass
class Trace:
    """The control window as it happened: records and fields per period."""

    x: np.ndarray
    start: np.ndarray
    records: list[PeriodRecord] = field(default_factory=list)
    t: list[float] = field(default_factory=list)
    micro: list[np.ndarray] = field(default_factory=list)
    replay: list[np.ndarray] = field(default_factory=list)
    reference: list[np.ndarray] = field(default_factory=list)
