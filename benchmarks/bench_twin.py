"""Benchmark of the nonlinear PDE twin: speed-up over real time and grid refinement.

1. Speed: a 450 s run of ``paper_base`` (open loop, 2 % stop-and-go) at 200 cells, per
   scheme; prints the speed-up over real time (goal: at least 500x).
2. Refinement: a smooth, boundary-compatible bump (1 %) run for 40 s, so that its waves
   reach both boundaries; L1 relative error against a 6400-cell MUSCL reference and the
   observed order per scheme.

Run: ``.venv/bin/python benchmarks/bench_twin.py [--quick]``.
"""

from __future__ import annotations

import argparse
import time

import numpy as np

from arzsumo.model import PRESETS, equilibrium_from_densities
from arzsumo.pde import InitialCondition, SolverOptions, initial_fields, simulate
from arzsumo.pde.metrics import deviation_norm
from arzsumo.pde.state import cell_centres

GOAL = 500.0


def speed(eq, scheme: str, repeats: int) -> tuple[float, float, int]:
    """Best wall time of ``repeats`` 450 s runs at 200 cells; also the final norm ratio."""
    x = cell_centres(eq.params.length, 200)
    init = initial_fields(InitialCondition(amplitude=(0.02, -0.02, 0.02, -0.02)), eq, x)
    best, ratio, steps = np.inf, np.nan, 0
    for _ in range(repeats):
        start = time.perf_counter()
        res = simulate(eq, init, options=SolverOptions(cells=200, scheme=scheme))
        best = min(best, time.perf_counter() - start)
        norm = deviation_norm(eq, res.x, res.fields)
        ratio, steps = float(norm[-1] / norm[0]), res.steps
    return best, ratio, steps


def bump_run(eq, cells: int, scheme: str, horizon: float = 40.0) -> np.ndarray:
    star = np.array([eq.rho_h, eq.v_h, eq.rho_a, eq.v_a])[:, None]
    x = cell_centres(eq.params.length, cells)
    s = np.clip((x - 300.0) / 400.0, 0.0, 1.0)
    shape = np.array([1.0, -1.0, 1.0, -0.5])[:, None] * (np.sin(np.pi * s) ** 4)[None, :]
    ic = InitialCondition("array", fields=tuple(star * (1.0 + 0.01 * shape)))
    res = simulate(eq, initial_fields(ic, eq, x),
                   options=SolverOptions(cells=cells, scheme=scheme, horizon=horizon,
                                         output_period=horizon, cfl=0.8))
    return res.fields[-1]


def refinement(eq, grids: list[int], ref_cells: int) -> None:
    star = np.array([eq.rho_h, eq.v_h, eq.rho_a, eq.v_a])[:, None]
    ref = bump_run(eq, ref_cells, "muscl")
    print(f"\nrefinement: 1 % bump, t = 40 s, L1 relative error vs {ref_cells}-cell MUSCL")
    print(f"{'cells':>7} | {'first':>10} {'order':>6} | {'muscl':>10} {'order':>6}")
    prev: dict[str, float] = {}
    for n in grids:
        row = [f"{n:7d}"]
        for scheme in ("first", "muscl"):
            coarse_ref = ref.reshape(4, n, ref_cells // n).mean(axis=2)
            err = float(np.mean(np.abs((bump_run(eq, n, scheme) - coarse_ref) / star)))
            order = f"{np.log2(prev[scheme] / err):6.2f}" if scheme in prev else " " * 6
            prev[scheme] = err
            row.append(f"{err:10.3e} {order}")
        print(" | ".join(row))


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--quick", action="store_true", help="smaller refinement table")
    args = parser.parse_args()
    p = PRESETS["paper_base"]
    eq = equilibrium_from_densities(p.params, p.rho_h, p.rho_a)
    print("speed: paper_base, 450 s, 200 cells, open loop, 2 % sinusoid")
    for scheme in ("first", "muscl"):
        wall, ratio, steps = speed(eq, scheme, repeats=3)
        flag = "meets" if 450.0 / wall >= GOAL else "BELOW"
        print(f"  {scheme:<6} {wall:6.3f} s wall, {steps} steps, {450.0 / wall:7.0f}x real time "
              f"({flag} the {GOAL:.0f}x goal); open-loop norm ratio at 450 s {ratio:.2f}")
    if args.quick:
        refinement(eq, [50, 100, 200, 400], 1600)
    else:
        refinement(eq, [50, 100, 200, 400, 800], 6400)


if __name__ == "__main__":
    main()
