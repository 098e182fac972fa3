"""Kernel solver: grid convergence of K(L, 0), M(L, 0), solve times, and law evaluation cost.

Run: .venv/bin/python benchmarks/bench_kernels.py [--preset paper_base]
Errors are against a solve on 1600 cells; the order is log2 of successive error ratios.
A controller check (a MacroState to deviations, then the law) is timed as a ratio to the
bare law (the gains times a deviation already on the kernel grid).
"""

from __future__ import annotations

import argparse
import time
import timeit

import numpy as np

from arzsumo.control.backstepping import Backstepping
from arzsumo.control.base import MacroState
from arzsumo.control.kernels import solve_kernels
from arzsumo.model import equilibrium_from_densities, get_preset, linearize


def main() -> None:
    parser = argparse.ArgumentParser()
    parser.add_argument("--preset", default="paper_base")
    args = parser.parse_args()
    p = get_preset(args.preset)
    lin = linearize(equilibrium_from_densities(p.params, p.rho_h, p.rho_a))
    system = lin.system
    ref = solve_kernels(system, 1600)
    ref_vals = np.array([ref.K[0, -1, 0], ref.K[2, -1, 0], ref.M[-1, 0]])
    print(f"preset {args.preset}: errors of k_1(L,0), k_3(L,0), M(L,0) against 1600 cells")
    print(f"{'cells':>6} {'err k_1':>10} {'err k_3':>10} {'err M':>10} {'order':>6} {'solve s':>8}")
    prev = None
    for n in (50, 100, 200, 400, 800):
        t0 = time.perf_counter()
        k = solve_kernels(system, n)
        elapsed = time.perf_counter() - t0
        err = np.abs(np.array([k.K[0, -1, 0], k.K[2, -1, 0], k.M[-1, 0]]) - ref_vals)
        order = "" if prev is None else f"{np.log2(prev[0] / err[0]):6.2f}"
        print(f"{n:6d} {err[0]:10.2e} {err[1]:10.2e} {err[2]:10.2e} {order:>6} {elapsed:8.3f}")
        prev = err
    best = min(timeit.repeat(lambda: solve_kernels(system, 200), number=1, repeat=5))
    print(f"kernel solve at 200 cells: best of 5 = {best:.3f} s (goal < 1 s)")

    k = solve_kernels(system, 200)
    ctrl = Backstepping(lin, k)
    eq = lin.equilibrium
    x = k.x
    z = 0.01 * np.ones((4, x.size))
    state = MacroState(0.0, x, eq.rho_h + z[0], eq.v_h + z[1], eq.rho_a + z[2], eq.v_a + z[3])
    xc = np.arange(25.0, 1000.0, 50.0)
    coarse = MacroState(0.0, xc, np.full(xc.size, eq.rho_h), np.full(xc.size, eq.v_h),
                        np.full(xc.size, eq.rho_a), np.full(xc.size, eq.v_a))
    n = 20000
    t_dot = min(timeit.repeat(lambda: ctrl.u_of_z(z), number=n, repeat=5)) / n
    t_state = min(timeit.repeat(lambda: ctrl.decide(state), number=n, repeat=5)) / n
    t_coarse = min(timeit.repeat(lambda: ctrl.decide(coarse), number=n, repeat=5)) / n
    print(f"control law, gains . z on 201 nodes:       {t_dot * 1e6:7.2f} us (goal < 50 us)")
    print(f"controller check, MacroState on same grid: {t_state * 1e6:7.2f} us, ratio to the "
          f"bare law {t_state / t_dot:5.1f}")
    print(f"controller check, MacroState on 50 m grid: {t_coarse * 1e6:7.2f} us, ratio to the "
          f"bare law {t_coarse / t_dot:5.1f}")


if __name__ == "__main__":
    main()
