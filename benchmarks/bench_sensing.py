"""Cost of reading loop stations and AV probes per control period, against bare SUMO.

Runs a scenario's SUMO set-up (default ``scenarios/legacy_default.toml``: vehicles enter
at x = 0, so ``main`` fills from the start) bare, then with E1 stations every
``--spacings`` m loaded, and times per control period:

* ``step``: SUMO's ``simulationStep`` (with loops loaded, SUMO's own detector work is in it);
* ``cells``: today's probe (:class:`~arzsumo.sumo.measure.MainlineSensor`, every step);
* ``loops``: :class:`~arzsumo.sumo.loops.LoopSensor` (``getVehicleData`` of every station
  every step, one record per period);
* ``interval``: SUMO's interval getters once per period instead (vehicle ids, occupancy,
  mean speed per station; not used: they count a vehicle in two periods, see loops.py);
* ``av_probes``: :class:`~arzsumo.sumo.probes.AvProbes` from the cells' last sample
  (``observe``) or read alone from libsumo (``read``), once per period.

Prints milliseconds per period and each as a ratio to the bare step's cost per period.

    .venv/bin/python benchmarks/bench_sensing.py [--horizon 300] [--spacings 250,100]
"""

from __future__ import annotations

import argparse
import time
from collections import defaultdict

from arzsumo.scenario import load_scenario
from arzsumo.sumo.loops import LoopSensor, loop_ids
from arzsumo.sumo.measure import MainlineSensor
from arzsumo.sumo.probes import AvProbes
from arzsumo.sumo.sensing import SensorLayout
from arzsumo.sumo.simulation import open_simulation


def _interval(lib, ids: list[str]) -> None:
    il = lib.inductionloop
    for d in ids:
        il.getLastIntervalVehicleIDs(d)
        il.getLastIntervalOccupancy(d)
        il.getLastIntervalMeanSpeed(d)


def run(sc, horizon: float, spacing: float | None) -> tuple[dict[str, float], int]:
    """Seconds spent per component over a run, and the number of periods."""
    params, cfg = sc.params, sc.sumo.with_(horizon=horizon)
    xs = SensorLayout(("loops",), loop_spacing=spacing).loop_x(params.length) \
        if spacing else ()
    spent: dict[str, float] = defaultdict(float)
    clock, periods = time.perf_counter, 0
    with open_simulation(params, cfg, loops=xs) as sim:
        lib = sim.lib
        cells = MainlineSensor(lib, params.length, cfg.cell_length, cfg.step_length,
                               cfg.steps_per_period)
        loops = LoopSensor(lib, xs, params.length, cfg.step_length,
                           cfg.steps_per_period) if xs else None
        probes, alone = AvProbes(0.5, 1), AvProbes(0.5, 1)
        while sim.time < cfg.horizon - 1e-9:
            a = clock()
            t = sim.step()
            b = clock()
            spent["step"] += b - a
            if spacing is None:
                continue
            done = cells.collect(t) is not None
            c = clock()
            spent["cells"] += c - b
            if loops is not None:
                loops.observe(t)
            d = clock()
            spent["loops"] += d - c
            if not done:
                continue
            periods += 1
            if loops is not None:
                _interval(lib, loop_ids(len(xs)))
            e = clock()
            spent["interval"] += e - d
            probes.observe(t, cells.last_ids, cells.last_pos, cells.last_speed, cells.last_av)
            f = clock()
            spent["av_probes observe"] += f - e
            alone.read(lib, t)
            spent["av_probes read"] += clock() - f
    return spent, periods or round(horizon / cfg.control_period)


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--scenario", default="scenarios/legacy_default.toml")
    ap.add_argument("--horizon", type=float, default=300.0, help="run length, s")
    ap.add_argument("--spacings", default="250,100", help="loop spacings, m")
    args = ap.parse_args()
    sc = load_scenario(args.scenario)
    bare, n = run(sc, args.horizon, None)
    base = bare["step"] / n * 1e3
    print(f"{sc.name}: {args.horizon:g} s, step {sc.sumo.step_length:g} s, period "
          f"{sc.sumo.control_period:g} s; bare SUMO {base:.3f} ms per period")
    print(f"{'spacing':>8} {'stations':>8}  {'component':18} {'ms/period':>10} "
          f"{'ratio to bare step':>10}")
    for spacing in (float(s) for s in args.spacings.split(",")):
        spent, n = run(sc, args.horizon, spacing)
        k = len(SensorLayout(("loops",), loop_spacing=spacing).loop_x(sc.params.length))
        for name, sec in spent.items():
            ms = sec / n * 1e3
            print(f"{spacing:8g} {k:8d}  {name:18} {ms:10.3f} {ms / base:10.3f}")


if __name__ == "__main__":
    main()
