"""Run a kept SUMO configuration through libsumo, stepping to its end in one call.

The `sumo` binary of the eclipse-sumo wheel is stripped, so a profiler sees only addresses
in it. libsumo's shared library keeps its symbol table, and stepping it to the end in one
`simulationStep` runs the same simulation loop as the binary (the same vehicles, within a
few per cent of its CPU time), so profiling this script names SUMO's functions.

    python libsumo_run.py RUN_DIR/run.sumocfg [--end 400] [-- EXTRA SUMO OPTIONS]

Prints the simulated end time and the number of vehicles still running.
"""

from __future__ import annotations

import argparse

import libsumo


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("config", help="a run.sumocfg that `arzsumo run` kept")
    parser.add_argument("--end", type=float, default=400.0, help="simulated end time, s")
    parser.add_argument("extra", nargs="*", help="further sumo options (after --)")
    args = parser.parse_args()
    libsumo.start(
        ["sumo", "-c", args.config, "--end", str(args.end), "--no-step-log", "--no-warnings",
         *args.extra]
    )
    libsumo.simulationStep(args.end)
    print(
        f"t = {libsumo.simulation.getTime():.1f} s, vehicles running {libsumo.vehicle.getIDCount()}"
    )
    libsumo.close()


if __name__ == "__main__":
    main()
