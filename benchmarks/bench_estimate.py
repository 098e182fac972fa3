"""Cost of the estimators per control period, on the default 1 km grid.

The default scenario's model at its congested equilibrium with a 5 % stop-and-go wave;
loops every 250 m (both boundaries) and every AV as a probe, 1 s periods. Prints the wall
time per period of: the causal ASM (loops; loops and probes), the EnKF with 8, 32 and 64
members (batched first-order twins, 20 cells = the controller's 50 m cells, and 100
cells = the twin grid of scenarios/default.toml), and 32 single first-order twins
(TwinStepper) advanced one period each on the same grid, with the ratios.

Run: ``.venv/bin/python benchmarks/bench_estimate.py [--periods N]``. On a busy machine
run it with ``OPENBLAS_NUM_THREADS=1``: the EnKF analysis multiplies small matrices,
and a multi-threaded BLAS competing for the cores made it up to 25 times slower here
(32 members on 100 cells: 35 ms per period against 8 ms single-threaded).
"""

from __future__ import annotations

import argparse
import time
from pathlib import Path

import numpy as np

from arzsumo.estimate.enkf import BoundaryInput, EnkfOptions, EnsembleKalmanFilter
from arzsumo.estimate.observations import LoopNoise, ProbeNoise
from arzsumo.estimate.smoothing import CausalSmoother
from arzsumo.estimate.synthetic import sample_loops, sample_probes
from arzsumo.pde import InitialCondition, SolverOptions, TwinStepper, initial_fields
from arzsumo.pde.state import cell_centres
from arzsumo.scenario import load_scenario

ROOT = Path(__file__).resolve().parents[1]


def _data(eq, cells: int, periods: int):
    x = cell_centres(eq.params.length, cells)
    fields = initial_fields(InitialCondition("sinusoid", amplitude=0.05), eq, x)
    rng = np.random.default_rng(0)
    xl = np.arange(0.0, 1001.0, 250.0)
    loops = [sample_loops(x, fields, xl, float(k), 1.0, LoopNoise(), rng)
             for k in range(1, periods + 1)]
    probes = [sample_probes(x, fields, "a", 1.0, float(k), ProbeNoise(), rng)
              for k in range(1, periods + 1)]
    return fields, loops, probes


def per_period(run, periods: int) -> float:
    """Wall seconds per period of ``run(k)`` for k = 1..periods (after 5 warm-up calls)."""
    for k in range(1, 6):
        run(k)
    start = time.perf_counter()
    for k in range(6, periods + 6):
        run(k)
    return (time.perf_counter() - start) / periods


def bench_grid(eq, cells: int, periods: int) -> None:
    p = eq.params
    fields, loops, probes = _data(eq, cells, periods + 6)
    rows: list[tuple[str, float]] = []
    for use in (False, True):
        sm = CausalSmoother(cell_centres(p.length, cells))

        def asm(k, sm=sm, use=use):
            sm.add([loops[k - 1]], [probes[k - 1]] if use else [])
            sm.estimate(float(k))
        rows.append((f"ASM, loops{' + AV probes' if use else ''}", per_period(asm, periods)))
    singles = [TwinStepper(eq, fields, SolverOptions(cells=cells, scheme="first"))
               for _ in range(32)]

    def single(k):
        for s in singles:
            s.advance(float(k), 0.0)
    t_single = per_period(single, periods)
    for m in (8, 32, 64):
        f = EnsembleKalmanFilter(p, fields, EnkfOptions(members=m, cells=cells))

        def enkf(k, f=f):
            f.step(float(k), BoundaryInput.from_loops(p, loops[k - 1]), [loops[k - 1]],
                   [probes[k - 1]])
        rows.append((f"EnKF {m} members (forecast + analysis)", per_period(enkf, periods)))
        g = EnsembleKalmanFilter(p, fields, EnkfOptions(members=m, cells=cells))
        rows.append((f"  forecast only, {m} members batched", per_period(
            lambda k, g=g: g.forecast(float(k), BoundaryInput.from_loops(p, loops[k - 1])),
            periods)))
    rows.append(("32 single twins (TwinStepper, first order)", t_single))
    print(f"\n{cells} cells ({p.length / cells:g} m), {periods} periods of 1 s")
    print(f"{'estimator':<44} {'ms/period':>10} {'ratio to 32 singles':>13}")
    for name, sec in rows:
        print(f"{name:<44} {sec * 1e3:10.2f} {sec / t_single:13.2f}")


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--periods", type=int, default=200)
    args = ap.parse_args()
    eq = load_scenario(ROOT / "scenarios" / "default.toml").equilibrium
    for cells in (20, 100):
        bench_grid(eq, cells, args.periods)


if __name__ == "__main__":
    main()
