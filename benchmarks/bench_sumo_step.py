"""What SUMO's own step costs on this road, and how far it is from the same road without
sublanes.

Runs the `sumo` binary on the configuration an open-loop `arzsumo run` keeps (default
scenario, fixed seed, the meter's nominal plan as a static program, the run's step, lateral
resolution and collision options; no outputs but a per-step summary to count vehicles), over
a simulated span (default 400 s), and the same files with the sublane model off
(`--lateral-resolution 0` on the command line: the kept run.sumocfg turns sublanes on with
`<lateral-resolution value="0.5"/>`, and SUMO's own default is 0, no sublanes). The two run
interleaved, shipped / no-sublane / shipped / ..., REPS times each. A run's CPU time is the
user + system time of the finished child process (os.wait4), so load from other processes
on a shared machine moves it little; wall times are not compared.

Prints, for each variant, the median CPU seconds (min and max), the vehicles inserted, the
vehicle updates (vehicles on the network summed over the steps, from SUMO's summary output)
and the vehicle updates per CPU second; then the ratio shipped / no-sublane (median of the
pairwise ratios): the distance from today's step to the limit of this road on this machine.
Without sublanes fewer vehicles enter (a different stream), so the ratio of updates per CPU
second is printed as well: that one compares the cost of one vehicle's step.

    .venv/bin/python benchmarks/bench_sumo_step.py                 # 400 s, 3 repetitions
    .venv/bin/python benchmarks/bench_sumo_step.py --quick         # 100 s, 2 repetitions
    .venv/bin/python benchmarks/bench_sumo_step.py --span 1050 --reps 5 --run-dir /tmp/kept

The kept configuration comes from one open-loop `arzsumo run` of the span (its co-simulation
costs about as much as one shipped run of the span); --run-dir keeps it for the next call.
"""

from __future__ import annotations

import argparse
import os
import shutil
import statistics
import subprocess
import sys
import tempfile
import xml.etree.ElementTree as ET
from pathlib import Path

import sumo

ROOT = Path(__file__).resolve().parents[1]
SUMO = Path(sumo.SUMO_HOME) / "bin" / "sumo"
ARZSUMO = Path(sys.executable).with_name("arzsumo")
FILL_S = 600.0   # the default scenario's fill phase; a warm-up shorter than it is allowed here


def keep_config(run_dir: Path, scenario: str, seed: int, span: float) -> Path:
    """RUN_DIR/run.sumocfg, made by an open-loop run whose demand covers [0, SPAN] s."""
    cfg = run_dir / "run.sumocfg"
    if cfg.is_file():
        return cfg
    warmup = min(span, FILL_S)
    horizon = max(span - warmup, 60.0)
    cmd = [str(ARZSUMO), "run", scenario, "--controller", "open", "--seed", str(seed),
           "--warmup", f"{warmup:g}", "--horizon", f"{horizon:g}", "--out", str(run_dir),
           "--overwrite", "--no-plots", "--quiet"]
    if warmup < FILL_S:
        cmd.append("--allow-short-warmup")
    print(f"keeping the run configuration: {' '.join(cmd[1:])}", flush=True)
    subprocess.run(cmd, check=True, stdout=subprocess.DEVNULL)
    return cfg


def run_once(cfg: Path, span: float, options: list[str], summary: Path) -> tuple[float, int, int]:
    """CPU seconds of one `sumo` run, vehicles inserted, vehicle updates (summed over steps)."""
    cmd = [str(SUMO), "-c", str(cfg), "--end", f"{span:g}", "--no-step-log", "true",
           "--no-warnings", "true", "--duration-log.disable", "true",
           "--summary-output", str(summary), *options]
    proc = subprocess.Popen(cmd, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
    _, status, usage = os.wait4(proc.pid, 0)
    if os.waitstatus_to_exitcode(status) != 0:
        raise SystemExit(f"sumo failed: {' '.join(cmd)}")
    steps = ET.parse(summary).getroot().findall("step")
    updates = sum(int(s.get("running")) for s in steps)
    inserted = int(steps[-1].get("inserted")) if steps else 0
    return usage.ru_utime + usage.ru_stime, inserted, updates


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--span", type=float, default=400.0, help="simulated span, s (400)")
    parser.add_argument("--reps", type=int, default=3, help="runs of each variant (3)")
    parser.add_argument("--seed", type=int, default=213, help="SUMO seed (213)")
    parser.add_argument("--scenario", default="default", help="scenario name or file (default)")
    parser.add_argument("--run-dir", type=Path, default=None,
                        help="where the kept configuration is made, or reused if there")
    parser.add_argument("--quick", action="store_true",
                        help="100 s simulated, 2 repetitions (about a minute)")
    args = parser.parse_args()
    if args.quick:
        args.span, args.reps = 100.0, 2
    tmp = Path(tempfile.mkdtemp(prefix="bench_sumo_step_"))
    try:
        run_dir = (args.run_dir or tmp / "run").resolve()
        cfg = keep_config(run_dir, args.scenario, args.seed, args.span)
        variants = {"shipped (sublane 0.5 m)": [],
                    "no sublane (lat.-res. 0)": ["--lateral-resolution", "0"]}
        results: dict[str, list[tuple[float, int, int]]] = {name: [] for name in variants}
        for rep in range(args.reps):
            for name, options in variants.items():
                results[name].append(run_once(cfg, args.span, options, tmp / "summary.xml"))
            print(f"  repetition {rep + 1}/{args.reps} done", file=sys.stderr, flush=True)
        version = subprocess.run([str(SUMO), "--version"], capture_output=True, text=True)
        print(f"\n{args.scenario}, open loop, seed {args.seed}, {args.span:g} s simulated, "
              f"{args.reps} interleaved runs each ({version.stdout.splitlines()[0]})")
        print(f"{'':26s} {'CPU s (median, min-max)':>24s} {'inserted':>9s} {'updates':>9s} "
              f"{'updates/CPU s':>14s}")
        ups = {}
        for name, rows in results.items():
            cpu = [r[0] for r in rows]
            med = statistics.median(cpu)
            ups[name] = statistics.median(r[2] / r[0] for r in rows)
            print(f"{name:26s} {med:9.2f} ({min(cpu):6.2f}-{max(cpu):6.2f}) {rows[0][1]:9d} "
                  f"{rows[0][2]:9d} {ups[name]:14.0f}")
        ship, bare = (results[name] for name in variants)
        ratio = statistics.median(a[0] / b[0] for a, b in zip(ship, bare, strict=True))
        print(f"ratio shipped / no sublane, CPU time:             {ratio:7.2f}")
        names = list(variants)
        print(f"ratio of updates per CPU second (no sublane / shipped): "
              f"{ups[names[1]] / ups[names[0]]:7.2f}")
    finally:
        shutil.rmtree(tmp, ignore_errors=True)


if __name__ == "__main__":
    main()
