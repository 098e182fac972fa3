"""Open-loop runs that record ALINEA's loop: the samples of its flow-occupancy curve.

:func:`record_downstream_loop` runs the open loop from t = 0, fill included (where the
loop sees the free branch of the curve), and returns the occupancy and flow of the E1
loop on ``down`` per control period (:class:`~arzsumo.sumo.loops.DownstreamLoop`). The
math on top (period means, triangular fit, target) is
:mod:`arzsumo.evaluation.critical_occupancy`.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from arzsumo.model.params import ModelParameters
from arzsumo.sumo.config import SumoConfig
from arzsumo.sumo.green_share import DEFAULT_CURVE, GreenShareCurve
from arzsumo.sumo.period_reads import OpenLoopPeriod, OpenLoopReads
from arzsumo.sumo.plant import SumoPlant
from arzsumo.sumo.simulation import open_simulation


@dataclass(frozen=True)
class LoopSeries:
    """The loop's record of one run: period ends ``t`` (s from SUMO start), occupancy
    (fraction) and flow (veh/s) per control period of ``dt`` s; the SUMO ``seed``."""

    t: np.ndarray
    occupancy: np.ndarray
    flow: np.ndarray
    dt: float
    seed: int


def record_downstream_loop(params: ModelParameters, cfg: SumoConfig, distance: float,
                           curve: GreenShareCurve = DEFAULT_CURVE) -> LoopSeries:
    """Run ``cfg.horizon`` s of open loop (nominal meter; ``curve`` for a fixed-cycle
    meter); the series of the loop ``distance`` m past the merge nose."""
    t_out, occ, flow = [], [], []

    def keep(p: OpenLoopPeriod) -> None:
        if p.loop is not None:
            t_out.append(p.t)
            occ.append(p.loop[0])
            flow.append(p.loop[1])

    with open_simulation(params, cfg, downstream_loop=distance) as sim:
        # the meter's reading only: the mainline cells are not needed here, the loop is
        plant = SumoPlant(sim, params.length, cfg, curve, measure=False)
        plant.run_open_loop(on_period=keep, until=cfg.horizon,
                            reads=OpenLoopReads(downstream_loop=True))
    return LoopSeries(np.asarray(t_out), np.asarray(occ), np.asarray(flow),
                      cfg.control_period, cfg.seed)
