"""The co-simulation against bare SUMO: vehicle updates per second and the ratios.

    .venv/bin/python benchmarks/bench_sumo_speed.py [--seed 1] [--controllers open,etc]
        [--horizon S]

Bare SUMO is the ``sumo`` binary on the very configuration an open-loop run keeps
(``run.sumocfg``: the same network, routes, loops, step, seed and lateral resolution, the
meter's nominal plan as a static program) with the same outputs (tripinfo of every
vehicle with emissions, edge data, statistics), for the same simulated time; its own
``--duration-log.statistics`` gives its vehicle updates per second (UPS). Each arzsumo
run is the whole ``run_cosimulation`` of the default scenario without the drain: start,
warm-up, control window, SUMO's outputs read. Its updates are the vehicles on the
network summed over its steps. A third reference is libsumo alone: the run's network,
routes, loops and outputs opened as a run opens them, then nothing but ``simulationStep``
(what in-process SUMO costs before arzsumo reads anything). The goals: an open loop at
most 5 % slower than bare SUMO, the ETC with the ASM estimator at most 10 %.
"""

from __future__ import annotations

import argparse
import re
import subprocess
import tempfile
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
DEFAULT = ROOT / "scenarios" / "default.toml"
GOALS = {"open": 1.05, "etc": 1.10}


def cosim(sc, controller: str, seed: int, horizon: float | None, keep: Path | None):
    """Wall time (s) and vehicle updates of one run; its run.sumocfg placed in ``keep``."""
    from arzsumo.bridge.cosim import finish_run, open_run, warm_start
    from arzsumo.bridge.session import prepare_run

    run = prepare_run(sc.with_({"sumo.drain_max_s": 0}), controller=controller, seed=seed,
                      horizon=horizon)
    t0 = time.perf_counter()
    with open_run(run) as opened:
        warmed = warm_start(opened.sim, run, opened.bar)
        res = finish_run(opened, warmed, run)
        updates, end = opened.sim.vehicle_updates, opened.sim.time
    wall = time.perf_counter() - t0
    if keep is not None:
        res.files.place(keep)
    return wall, updates, end


def libsumo_alone(sc, seed: int, end: float) -> float:
    """Wall time (s) of libsumo stepping the run's network with its outputs, nothing read."""
    from arzsumo.sumo.network_measures import network_options
    from arzsumo.sumo.simulation import open_simulation

    out = Path(tempfile.mkdtemp(prefix="bench_sumo_speed.lib."))
    cfg = sc.sumo.with_(seed=seed, horizon=end)
    t0 = time.perf_counter()
    with open_simulation(sc.params, cfg, extra_args=network_options(out / "net"),
                         output_dir=out / "net", loops=sc.sensing.loop_x(sc.params.length),
                         downstream_loop=sc.alinea.loop_distance) as sim:
        lib = sim.lib
        while lib.simulation.getTime() < end - 1e-9:
            lib.simulationStep()
    return time.perf_counter() - t0


def bare(config: Path, end: float) -> tuple[float, float, int]:
    """Wall time (s), SUMO's UPS and updates of the ``sumo`` binary on ``config``."""
    from arzsumo.sumo.frontend import Frontend
    from arzsumo.sumo.network_measures import network_options

    out = Path(tempfile.mkdtemp(prefix="bench_sumo_speed."))
    cmd = [Frontend("traci").binary(), "-c", str(config), "--end", f"{end:g}",
           "--statistic-output", str(out / "statistics.xml"),
           "--duration-log.statistics", "true", "--no-step-log", "true",
           "--no-warnings", "true", *network_options(out / "net")]
    t0 = time.perf_counter()
    done = subprocess.run(cmd, capture_output=True, text=True, check=True)
    wall = time.perf_counter() - t0
    ups = float(re.search(r"UPS: ([\d.]+)", done.stdout).group(1))
    duration = float(re.search(r"Duration: ([\d.]+)s", done.stdout).group(1))
    return wall, ups, round(ups * duration)


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--seed", type=int, default=1)
    ap.add_argument("--controllers", default="open,etc")
    ap.add_argument("--horizon", type=float, default=None)
    args = ap.parse_args()
    from arzsumo.scenario import load_scenario

    sc = load_scenario(DEFAULT)
    keep = Path(tempfile.mkdtemp(prefix="bench_sumo_speed.cfg."))
    controllers = args.controllers.split(",")
    runs = {}
    for i, name in enumerate(controllers):
        runs[name] = cosim(sc, name, args.seed, args.horizon, keep if i == 0 else None)
    end = runs[controllers[0]][2]
    b_wall, b_ups, b_updates = bare(keep / "run.sumocfg", end)
    lib_wall = libsumo_alone(sc, args.seed, end)
    print(f"default scenario, seed {args.seed}, {end:.0f} s simulated "
          f"(warm-up and control window, no drain)")
    print(f"{'':22s}{'wall s':>9s}{'updates':>11s}{'updates/s':>11s}{'ratio':>8s}")
    print(f"{'bare sumo':22s}{b_wall:9.1f}{b_updates:11d}{b_updates / b_wall:11.0f}"
          f"{1.0:8.3f}   (SUMO's own UPS {b_ups:.0f})")
    print(f"{'libsumo alone':22s}{lib_wall:9.1f}{'':11s}{'':11s}{lib_wall / b_wall:8.3f}"
          "   (no reads: in-process SUMO's own cost)")
    for name, (wall, updates, _) in runs.items():
        goal = GOALS.get(name)
        note = f"   (goal <= {goal:.2f})" if goal else ""
        print(f"{'arzsumo ' + name:22s}{wall:9.1f}{updates:11d}{updates / wall:11.0f}"
              f"{wall / b_wall:8.3f}{note}   ratio to libsumo alone {wall / lib_wall:.3f}")


if __name__ == "__main__":
    main()
