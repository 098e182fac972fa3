"""Cost of measuring every step and actuating the ramp meter, against bare SUMO.

Runs the default network for 450 s (medium demand, ramp 1200 veh/h) alternately bare
(only ``simulationStep``) and with the Edie sensor collecting every step plus the ramp
meter stepping every step and receiving a new outflow command every control period.
Prints each run's wall time, the ratio of total times (goal: at most 1.10) and the
vehicle counts.

    .venv/bin/python benchmarks/bench_sumo_measurement.py [--pairs 2] [--horizon 450]
"""

from __future__ import annotations

import argparse
import math
import time

from arzsumo.bridge.actuator import command_meter
from arzsumo.model import get_preset
from arzsumo.sumo.config import SumoConfig
from arzsumo.sumo.green_share import DEFAULT_CURVE
from arzsumo.sumo.plant import SumoPlant
from arzsumo.sumo.simulation import open_simulation


def run(cfg: SumoConfig, measured: bool) -> tuple[float, float, float, int, float, dict]:
    """One run: wall time s, CPU time s, time inside sensor and meter s, vehicles
    inserted, mean vehicles on the network, meter counts."""
    params = get_preset("paper_base").params
    on_net = 0.0
    steps = 0
    inside = 0.0
    meter_summary: dict = {}
    clock = time.perf_counter
    t0, c0 = clock(), time.process_time()
    with open_simulation(params, cfg) as sim:
        lib = sim.lib
        if measured:
            plant = SumoPlant(sim, params.length, cfg)
            meter = plant.meter
            q_star = DEFAULT_CURVE.outflow_at(cfg.green_share)
            while sim.time < cfg.horizon - 1e-9:
                data = plant.step()
                if data is not None:   # a controller would run here; command a varying U
                    command_meter(meter, 0.05 * math.sin(sim.time / 20.0), q_star)
                on_net += lib.vehicle.getIDCount()
                steps += 1
            inside = plant.timings["measure_actuate"]
            meter_summary = plant.meter_summary()
        else:
            while sim.time < cfg.horizon - 1e-9:
                sim.step()
                on_net += lib.vehicle.getIDCount()
                steps += 1
    wall, cpu = clock() - t0, time.process_time() - c0
    assert sim.report is not None
    return wall, cpu, inside, sim.report.inserted, on_net / max(steps, 1), meter_summary


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--pairs", type=int, default=2, help="bare/measured pairs")
    ap.add_argument("--horizon", type=float, default=450.0, help="run length, s")
    ap.add_argument("--step-length", type=float, default=0.1, help="SUMO step, s")
    args = ap.parse_args()
    cfg = SumoConfig(horizon=args.horizon, step_length=args.step_length)
    bare: list[tuple[float, float]] = []
    full: list[tuple[float, float]] = []
    inside_total = 0.0
    for k in range(args.pairs):
        for measured, store in ((False, bare), (True, full)):
            wall, cpu, inside, inserted, mean_on, meter = run(cfg, measured)
            store.append((wall, cpu))
            inside_total += inside
            label = "measured+meter" if measured else "bare"
            extra = (f", in sensor+meter {inside:.2f} s, plan changes {meter['plan_changes']}"
                     f", light changes {meter['light_changes']}, max ramp queue "
                     f"{meter['max_queue']}" if measured else "")
            print(f"pair {k + 1} {label:15s} wall {wall:7.2f} s  cpu {cpu:7.2f} s  inserted "
                  f"{inserted}, mean on network {mean_on:.0f}{extra}", flush=True)
    wall_b, cpu_b = (sum(x[i] for x in bare) for i in (0, 1))
    wall_f, cpu_f = (sum(x[i] for x in full) for i in (0, 1))
    print(f"horizon {cfg.horizon:g} s, step {cfg.step_length:g} s, {args.pairs} pairs")
    print(f"wall-time ratio measured+meter / bare = {wall_f / wall_b:.3f} (goal <= 1.10); "
          f"CPU-time ratio {cpu_f / cpu_b:.3f}")
    print(f"time inside sensor+meter: {inside_total:.2f} s of {wall_f:.2f} s, i.e. ratio "
          f"{wall_f / (wall_f - inside_total):.3f} against the same traffic without them")


if __name__ == "__main__":
    main()
