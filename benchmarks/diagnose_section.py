"""Follow one open-loop run of a scenario in 30 s means per 200 m (issue 15's diagnosis).

Prints, every 30 s: HV and AV density (veh/km) and HV speed (km/h) per 200 m of the
section, class in- and outflows (veh/h), vehicles on the approach and its queue length (m),
and the ramp queue (veh). Used to find the HV blocking at the approach junction
(docs/results/sumo_fill.md)::

    PYTHONPATH=src python benchmarks/diagnose_section.py scenarios/default.toml 3 1350
"""

from __future__ import annotations

import sys

import numpy as np

from arzsumo.scenario import load_scenario
from arzsumo.sumo.meter_release import make_meter
from arzsumo.sumo.sensor import SumoSensor
from arzsumo.sumo.simulation import open_simulation

WINDOW, SEGMENTS = 30, 5


def line(t: float, cells: list, lib, approach: float, queue: int) -> str:
    def seg(a: np.ndarray) -> np.ndarray:
        return a.reshape(SEGMENTS, -1).mean(axis=1)

    rho_h = seg(np.mean([c.rho_h for c in cells], 0)) * 1000
    rho_a = seg(np.mean([c.rho_a for c in cells], 0)) * 1000
    q_h = np.sum([c.q_h for c in cells], 0)
    v_h = seg(q_h / np.maximum(np.sum([c.rho_h for c in cells], 0), 1e-9)) * 3.6
    flows = [np.mean([getattr(c, k) for c in cells]) * 3600
             for k in ("inflow_h", "inflow_a", "outflow_h", "outflow_a")]
    ids = lib.edge.getLastStepVehicleIDs("approach") if approach > 0 else []
    slow = [lib.vehicle.getLanePosition(v) for v in ids if lib.vehicle.getSpeed(v) < 10 / 3.6]
    tail = approach - min(slow) if slow else 0.0
    return (f"t={t:6.0f} rho_h={np.round(rho_h).astype(int)} rho_a={np.round(rho_a).astype(int)}"
            f" v_h={np.round(v_h).astype(int)} in={flows[0]:.0f}/{flows[1]:.0f}"
            f" out={flows[2]:.0f}/{flows[3]:.0f} approach={len(ids)} tail={tail:.0f}m"
            f" ramp_queue={queue}")


def main(argv: list[str]) -> int:
    sc = load_scenario(argv[0])
    cfg = sc.sumo.with_(seed=int(argv[1]), horizon=float(argv[2]))
    with open_simulation(sc.params, cfg) as sim:
        meter = make_meter(sim.lib, cfg)
        sensor = SumoSensor(sim.lib, sc.params.length, cfg)
        cells: list = []
        while sim.time < cfg.horizon - 1e-9:
            got = sensor.observe(sim.step())
            meter.step(sensor.queue)
            if got is not None:
                cells.append(got.cells)
            if len(cells) == WINDOW:
                print(line(sim.time, cells, sim.lib, cfg.approach_length, sensor.queue),
                      flush=True)
                cells = []
    print(sim.report)
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
