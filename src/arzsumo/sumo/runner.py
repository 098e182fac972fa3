"""A SUMO run with per-step measurement and the ramp meter at a fixed plan.

The closed loop with the PDE controllers lives in the bridge; this module runs the
open-loop experiments that calibration, tests and the benchmark need.
"""

from __future__ import annotations

import logging
from collections.abc import Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import Any

from arzsumo.model.params import ModelParameters
from arzsumo.sumo.config import SumoConfig
from arzsumo.sumo.demand import InitialVehicle
from arzsumo.sumo.green_share import DEFAULT_CURVE, GreenShareCurve
from arzsumo.sumo.measure import MeasurementLog
from arzsumo.sumo.network import RAMP_UP
from arzsumo.sumo.paths import SumoError
from arzsumo.sumo.period_reads import OpenLoopPeriod
from arzsumo.sumo.plant import SumoPlant
from arzsumo.sumo.simulation import RunReport, open_simulation

log = logging.getLogger(__name__)


@dataclass(frozen=True)
class RunResult:
    """Measurements (per control period), vehicle accounting and meter counts of a run."""

    cfg: SumoConfig
    green_share: float
    measurements: MeasurementLog
    report: RunReport
    meter: dict[str, Any]
    ramp_passed: int


def run_fixed_meter(params: ModelParameters, cfg: SumoConfig, green_share: float | None = None,
                    *, initial: Sequence[InitialVehicle] = (), net_dir: Path | None = None,
                    measure: bool = True, curve: GreenShareCurve = DEFAULT_CURVE) -> RunResult:
    """Run ``cfg.horizon`` seconds with the meter at ``green_share`` (default: nominal).

    ``green_share`` in [0, 1] (0: always red, 1: always green); ``cfg.control_period`` is
    the measurement window; ``initial``: vehicles placed at t = 0; ``measure``: collect
    Edie aggregates every step (False: only the meter acts).
    """
    g = cfg.green_share if green_share is None else green_share
    cfg = cfg.with_(green_share=g)
    measurements = MeasurementLog()

    def keep(p: OpenLoopPeriod) -> None:
        if p.measurement is not None:
            measurements.append(p.measurement.cells)

    with open_simulation(params, cfg, initial=initial, net_dir=net_dir) as sim:
        plant = SumoPlant(sim, params.length, cfg, curve, measure=measure)
        plant.run_open_loop(on_period=keep, until=cfg.horizon)
        # ramp vehicles past the meter: inserted minus those still upstream of it
        ramp = cfg.layout.ramp_edge if cfg.layout is not None else RAMP_UP
        ramp_passed = sim.inserted_ramp - int(sim.lib.edge.getLastStepVehicleNumber(ramp))
    if sim.report is None:  # pragma: no cover - close() failed to read SUMO's counts
        raise SumoError("SUMO closed without a final report")
    log.info("%s", sim.report.summary())
    return RunResult(cfg, g, measurements, sim.report, plant.meter_summary(), ramp_passed)
