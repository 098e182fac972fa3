"""Cost of SUMO's network-wide outputs (tripinfo with emissions, edge data, statistics).

Runs the default scenario's SUMO settings for 450 s (meter at its nominal plan)
alternately without and with :func:`~arzsumo.sumo.network_measures.network_options`, then
parses the outputs with :func:`~arzsumo.sumo.network_measures.network_summary`. Prints
each run's wall and CPU time, the parse time and the ratio of total times.

    .venv/bin/python benchmarks/bench_network_measures.py [--pairs 2] [--horizon 450]
"""

from __future__ import annotations

import argparse
import tempfile
import time
from pathlib import Path

from arzsumo.model import get_preset
from arzsumo.sumo.config import SumoConfig
from arzsumo.sumo.network_measures import network_options, network_summary
from arzsumo.sumo.plant import SumoPlant
from arzsumo.sumo.simulation import open_simulation


def run(cfg: SumoConfig, out: Path | None) -> tuple[float, float, float, int]:
    """One run: wall s, CPU s, parse s (0 without outputs), vehicles loaded."""
    params = get_preset("paper_base").params
    extra = network_options(out) if out is not None else []
    t0, c0 = time.perf_counter(), time.process_time()
    with open_simulation(params, cfg, extra_args=extra, output_dir=out) as sim:
        plant = SumoPlant(sim, params.length, cfg, measure=False)
        while sim.time < cfg.horizon - 1e-9:
            plant.step()
    wall, cpu = time.perf_counter() - t0, time.process_time() - c0
    assert sim.report is not None
    if out is None:
        return wall, cpu, 0.0, sim.report.inserted + sim.report.waiting
    p0 = time.perf_counter()
    net = network_summary(out, end_time=cfg.horizon)
    return wall, cpu, time.perf_counter() - p0, net["vehicles"]["loaded"]["total"]


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--pairs", type=int, default=2, help="without/with pairs")
    ap.add_argument("--horizon", type=float, default=450.0, help="run length, s")
    ap.add_argument("--step-length", type=float, default=0.1, help="SUMO step, s")
    args = ap.parse_args()
    cfg = SumoConfig(horizon=args.horizon, step_length=args.step_length)
    totals = {False: [0.0, 0.0], True: [0.0, 0.0]}
    parse_total = 0.0
    with tempfile.TemporaryDirectory(prefix="bench-network-") as tmp:
        for k in range(args.pairs):
            for with_out in (False, True):
                out = Path(tmp) / f"run{k}" if with_out else None
                wall, cpu, parse, loaded = run(cfg, out)
                totals[with_out][0] += wall
                totals[with_out][1] += cpu
                parse_total += parse
                label = "with outputs" if with_out else "without"
                print(f"pair {k + 1} {label:13s} wall {wall:7.2f} s  cpu {cpu:7.2f} s  "
                      f"parse {parse:5.2f} s  vehicles loaded {loaded}", flush=True)
    (wb, cb), (wf, cf) = totals[False], totals[True]
    print(f"horizon {cfg.horizon:g} s, step {cfg.step_length:g} s, {args.pairs} pairs")
    print(f"wall-time ratio with/without outputs = {wf / wb:.3f} (CPU {cf / cb:.3f}); "
          f"with parsing {(wf + parse_total) / wb:.3f}")


if __name__ == "__main__":
    main()
