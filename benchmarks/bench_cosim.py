"""The whole co-simulation against bare SUMO on the same scenario, alternating runs.

Bare: SUMO stepped for warm-up + horizon with the same demand and nothing else.
Co-simulation: measurement every step, the controller every period, both twins, the meter.
Prints the wall-time ratio (goal <= 1.10), where the extra time goes, and the
per-period controller time (goal < 1 ms).

Run: .venv/bin/python benchmarks/bench_cosim.py [--pairs 2] [--controller etc] [--horizon 450]
"""

from __future__ import annotations

import argparse
import time
from pathlib import Path

from arzsumo.bridge.cosim import run_cosimulation
from arzsumo.bridge.session import prepare_run
from arzsumo.scenario import load_scenario
from arzsumo.sumo.simulation import open_simulation

DEFAULT = Path(__file__).resolve().parents[1] / "scenarios" / "default.toml"


def bare(sc, cfg, total: float) -> float:
    t0 = time.perf_counter()
    with open_simulation(sc.params, cfg.with_(horizon=total)) as sim:
        while sim.time < total - 1e-9:
            sim.step()
    return time.perf_counter() - t0


def main() -> None:
    ap = argparse.ArgumentParser()
    ap.add_argument("--pairs", type=int, default=2)
    ap.add_argument("--controller", default="etc")
    ap.add_argument("--horizon", type=float, default=450.0)
    args = ap.parse_args()
    sc = load_scenario(DEFAULT)
    run = prepare_run(sc, controller=args.controller, horizon=args.horizon)
    total = run.settings.warmup + args.horizon
    run_cosimulation(prepare_run(sc, controller=args.controller, horizon=10.0))  # kernels
    t_bare, t_co, last = [], [], None
    for _ in range(args.pairs):
        t_bare.append(bare(sc, run.sumo, total))
        t0 = time.perf_counter()
        last = run_cosimulation(run)
        t_co.append(time.perf_counter() - t0)
    b, c = min(t_bare), min(t_co)
    tm = last.timings
    periods = last.t.size
    print(f"scenario {sc.name}, controller {args.controller}, {total:.0f} s simulated, "
          f"{args.pairs} alternating pairs (best of each)")
    print(f"bare SUMO          {b:7.2f} s")
    print(f"co-simulation      {c:7.2f} s   ratio {c / b:.3f} (goal <= 1.10)")
    print(f"  inside SUMO steps        {tm['sumo_step']:7.2f} s")
    print(f"  measurement + meter      {tm['measure_actuate']:7.2f} s "
          f"({tm['measure_actuate'] / b:.1%} of bare)")
    print(f"  controller               {tm['controller']:7.2f} s "
          f"({tm['controller'] / periods * 1e3:.3f} ms per period, goal < 1 ms)")
    print(f"  twins (both modes, incl. the reference twin's controller) {tm['twins']:7.2f} s "
          f"({tm['twins'] / periods * 1e3:.2f} ms per period)")
    print(f"vehicles inserted {last.report.inserted if last.report else '?'}, "
          f"periods {periods}")


if __name__ == "__main__":
    main()
