"""Issue 17, point 1c: the green-share -> mainline-outflow map from step responses in SUMO.

Each run is one open-loop SUMO run of ``scenarios/default.toml`` (2.5 km approach, fill
then hold): the nominal plan (green share 0.5) through the fill and warm-up (``--warmup``
s), ``--base`` s more at 0.5, then a sequence of green-share steps (``--greens``, each
held ``--hold`` s) that drive the meter directly (:meth:`RampMeter.set_green_share`; a new
plan takes effect at the next 6 s cycle start). Every second it records, exactly:

* ``g_req``: the requested green share; ``g_run``: the green share of the running plan
  (after the cycle quantisation);
* ``out_h``, ``out_a``: vehicles that left ``main`` at x = L in the second (the section's
  mainline outflow, :class:`~arzsumo.sumo.measure.MainlineSensor`, exact crossings);
* ``in_h``, ``in_a``: vehicles that entered ``main`` at x = 0;
* ``ramp``: ramp vehicles that passed the meter (entered ``ramp_dn``) in the second;
* ``n_main``: vehicles on ``main`` at the end of the second; ``ramp_queue`` (veh).

The series (one CSV row per second and seed) goes to ``--series``; :mod:`study_meter_fit`
fits the first-order-plus-dead-time model per step and writes the table, CSV and figure.

Usage (2 runs in parallel at most; the machine is shared)::

    PYTHONPATH=src python benchmarks/study_meter_steps.py --seeds 1 2 3 --jobs 2 \\
        --series docs/results/meter_dynamics/meter_steps_series.csv
    PYTHONPATH=src python benchmarks/study_meter_fit.py \\
        docs/results/meter_dynamics/meter_steps_series.csv
"""

from __future__ import annotations

import argparse
import csv
import multiprocessing as mp
import sys
import time
from concurrent.futures import ProcessPoolExecutor, as_completed
from pathlib import Path
from typing import Any

ROOT = Path(__file__).resolve().parents[1]
SCENARIO = ROOT / "scenarios" / "default.toml"
COLUMNS = ["seed", "t_s", "g_req", "g_run", "out_h_veh", "out_a_veh", "in_h_veh",
           "in_a_veh", "ramp_veh", "n_main_veh", "ramp_queue_veh"]


def schedule(warmup: float, base: float, greens: list[float], hold: float
             ) -> list[tuple[float, float]]:
    """(start s, green share) of each segment: 0.5 from 0, then the steps."""
    out = [(0.0, 0.5)]
    t = warmup + base
    for g in greens:
        out.append((t, g))
        t += hold
    return out


def run_seed(seed: int, warmup: float, base: float, greens: list[float], hold: float
             ) -> tuple[list[dict[str, Any]], dict[str, Any]]:
    """One open-loop run with the green-share steps; the per-second rows after
    ``warmup - base`` s and the run's report (wall time, collisions, inserted)."""
    from arzsumo.scenario import load_scenario
    from arzsumo.sumo.meter import RampMeter
    from arzsumo.sumo.network import RAMP_DN
    from arzsumo.sumo.sensor import SumoSensor
    from arzsumo.sumo.simulation import open_simulation

    t0 = time.perf_counter()
    sc = load_scenario(SCENARIO)
    end = warmup + base + hold * len(greens)
    cfg = sc.sumo.with_(seed=seed, horizon=end, control_period=1.0)
    plan = schedule(warmup, base, greens, hold)
    rows: list[dict[str, Any]] = []
    with open_simulation(sc.params, cfg) as sim:
        meter = RampMeter(sim.lib, cfg)
        sensor = SumoSensor(sim.lib, sc.params.length, cfg)
        prev_dn: set[str] = set()
        ramp = 0
        g_req = 0.5
        while sim.time < end - 1e-9:
            for start, g in plan:    # asked half a cycle early: runs from ``start``
                if abs(sim.time - (start - cfg.meter_cycle / 2)) < cfg.step_length / 2:
                    g_req = g
                    meter.set_green_share(g)
            got = sensor.observe(sim.step())
            meter.step(sensor.queue)
            dn = set(sim.lib.edge.getLastStepVehicleIDs(RAMP_DN))
            ramp += len(dn - prev_dn)
            prev_dn = dn
            if got is None:
                continue
            c = got.cells
            if c.t > warmup - 120 + 1e-9:
                rows.append({"seed": seed, "t_s": round(c.t, 3), "g_req": g_req,
                             "g_run": meter.green_share,
                             "out_h_veh": round(c.outflow_h * c.window),
                             "out_a_veh": round(c.outflow_a * c.window),
                             "in_h_veh": round(c.inflow_h * c.window),
                             "in_a_veh": round(c.inflow_a * c.window), "ramp_veh": ramp,
                             "n_main_veh": sim.lib.edge.getLastStepVehicleNumber("main"),
                             "ramp_queue_veh": got.ramp_queue})
            ramp = 0
    rep = sim.report
    info = {"seed": seed, "wall_s": time.perf_counter() - t0,
            "collisions": rep.collisions, "emergency_stops": rep.emergency_stops,
            "inserted_main": rep.delivered_main}
    return rows, info


def main(argv: list[str] | None = None) -> int:
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--seeds", type=int, nargs="+", default=[1, 2, 3])
    p.add_argument("--warmup", type=float, default=600.0, help="fill and warm-up, s")
    p.add_argument("--base", type=float, default=60.0, help="extra s at 0.5 before the steps")
    p.add_argument("--greens", type=float, nargs="+",
                   default=[0.2, 0.5, 0.8, 0.5, 0.2, 0.5, 0.8, 0.5])
    p.add_argument("--hold", type=float, default=102.0, help="s per step (17 cycles)")
    p.add_argument("--jobs", type=int, default=2)
    p.add_argument("--series", default="docs/results/meter_dynamics/meter_steps_series.csv")
    args = p.parse_args(argv)
    out = Path(args.series)
    new = not out.is_file()
    with out.open("a", newline="") as f, ProcessPoolExecutor(
            args.jobs, mp_context=mp.get_context("spawn"), max_tasks_per_child=1) as pool:
        w = csv.DictWriter(f, COLUMNS)
        if new:
            w.writeheader()
        futs = [pool.submit(run_seed, s, args.warmup, args.base, args.greens, args.hold)
                for s in args.seeds]
        for fut in as_completed(futs):
            rows, info = fut.result()
            w.writerows(rows)
            f.flush()
            print(", ".join(f"{k}={v:.4g}" if isinstance(v, float) else f"{k}={v}"
                            for k, v in info.items()), flush=True)
    return 0


if __name__ == "__main__":
    sys.exit(main())
