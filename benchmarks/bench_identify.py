"""Benchmark of the identification: cost and accuracy of the replay, the fit, the inlet.

1. Grid: SUMO-like synthetic runs (2 operating points, AO* 0.29 and 0.39, 1 s periods,
   observed as 20 cell averages of 50 m) made by a 200-cell first-order twin; the cost of
   one residual evaluation (a replay of every run) and the replay's relative RMSE against
   the data at the true parameters (its discretisation error), per grid and scheme; the
   ratio is each scheme's cost to the first-order scheme's on the same grid.
   Denser runs cannot serve as a fine reference: see 3.
2. Fit: the synthetic recovery of the 8 parameters (2 % noise, guess 19-35 % off) on
   same-grid data: wall time, evaluations, twin failures, recovery errors and sigmas.
3. Inlet boundary layer: the ghost-cell inlet (the replay's, and the SUMO bridge's)
   holds all four variables although one family (lambda_4 < 0) leaves through x = 0; in
   congestion a layer one cell thick forms in the first cell. Printed: the first cell's AO
   and the AO at x = 50 m after 25 s, per grid, for a run at AO* = 0.45.

Run: ``.venv/bin/python benchmarks/bench_identify.py [--quick]``.
"""

from __future__ import annotations

import argparse
import time

import numpy as np

from arzsumo.identify import ReplayData, ReplayOptions, identify, run_replay, validate
from arzsumo.identify.objective import DEFAULT_WHICH, Objective, ParameterSpace
from arzsumo.identify.replay import replay_grid
from arzsumo.identify.synthetic import SyntheticRun, boundary_data, synthetic_data
from arzsumo.model import ModelParameters, area_occupancy

TRUTH = ModelParameters(v_free_h=22.0, v_free_a=17.0, ao_max_h=0.8, ao_max_a=0.78,
                        gamma_h=1.6, gamma_a=2.2, tau_h=20.0, tau_a=40.0)
GUESS = TRUTH.with_(v_free_h=27.5, v_free_a=12.75, ao_max_h=0.95, ao_max_a=0.62,
                    gamma_h=2.08, gamma_a=1.54, tau_h=28.0, tau_a=26.0)
RUNS = (SyntheticRun(0.06, 0.03), SyntheticRun(0.09, 0.05, inlet_period=60.0),
        SyntheticRun(0.11, 0.07, outflow_period=50.0))


def coarse(data: ReplayData, factor: int) -> ReplayData:
    """The data observed as averages over ``factor`` adjacent cells (SUMO's Edie cells)."""
    def avg(a: np.ndarray) -> np.ndarray:
        return a.reshape(*a.shape[:-1], -1, factor).mean(axis=-1)
    return ReplayData.from_arrays(data.t, avg(data.x), avg(data.fields), avg(data.initial),
                                  data.inlet, data.outflow, scale=data.scale, name=data.name)


def grid_study(horizon: float, grids: list[int], repeats: int) -> None:
    ref = ReplayOptions(cells=200)
    ops = (RUNS[0], SyntheticRun(0.08, 0.045, inlet_period=60.0))
    runs = [coarse(synthetic_data(TRUTH, r, horizon=horizon, period=1.0, options=ref,
                                  name=f"op{i}"), 10) for i, r in enumerate(ops)]
    space = ParameterSpace.make(TRUTH, DEFAULT_WHICH)
    print(f"1. grid: 2 runs of {horizon:.0f} s, 1 s periods, 20 cells of 50 m observed; "
          "data from a 200-cell first-order twin")
    print(f"{'cells':>6} {'scheme':>7} | {'s/eval':>7} {'ratio':>6} | rel. RMSE at the truth "
          "(rho_h, v_h, rho_a, v_a)")
    for cells in grids:
        first = np.nan
        for scheme in ("first", "muscl"):
            opts = ReplayOptions(cells=cells, scheme=scheme)
            obj = Objective(space, runs, np.ones(4), opts, 10.0)
            best = np.inf
            for _ in range(repeats):
                start = time.perf_counter()
                obj(np.zeros(len(DEFAULT_WHICH)))
                best = min(best, time.perf_counter() - start)
            report = validate(TRUTH, runs, opts)
            stops = "; ".join(f"{n} stopped at {t:.0f} s" for n, t in
                              zip(report.names, report.stopped, strict=True) if t is not None)
            first = best if scheme == "first" else first
            print(f"{cells:6d} {scheme:>7} | {best:7.3f} {best / first:6.2f} | "
                  + "  ".join(f"{e:6.3f}" for e in report.pooled) + f"  {stops}")


def fit_study(horizon: float, cells: int) -> None:
    opts = ReplayOptions(cells=cells)
    runs = [synthetic_data(TRUTH, r, horizon=horizon, period=5.0, options=opts, noise=0.02,
                           seed=i, name=f"op{i}") for i, r in enumerate(RUNS)]
    res = identify(runs, GUESS, options=opts)
    print(f"\n2. fit: 8 parameters, 3 runs of {horizon:.0f} s (5 s periods), {cells} cells, "
          "2 % noise")
    print(f"wall {res.wall_time:.1f} s, scipy nfev {res.nfev}, residual evaluations "
          f"{res.evaluations} ({res.wall_time / res.evaluations:.3f} s each), twin failures "
          f"{res.failures}, {res.message}")
    print(f"{'param':>9} {'true':>8} {'guess':>8} {'fitted':>8} {'sigma':>8} {'rel.err':>8} "
          f"{'err/sig':>7}")
    for i, name in enumerate(res.which):
        true = getattr(TRUTH, name)
        print(f"{name:>9} {true:8.3f} {getattr(GUESS, name):8.3f} {res.values[i]:8.3f} "
              f"{res.sigma[i]:8.4f} {res.values[i] / true - 1:+8.4f} "
              f"{(res.values[i] - true) / res.sigma[i]:+7.2f}")
    print("training rel. RMSE (rho_h, v_h, rho_a, v_a): "
          + "  ".join(f"{e:.4f}" for e in res.training.pooled))


def inlet_layer(grids: list[int]) -> None:
    print("\n3. inlet boundary layer, run at AO* = 0.45 (0.09, 0.05 veh/m), t = 25 s")
    print(f"{'cells':>6} | {'AO cell 0':>9} {'AO 50 m':>8} | stopped")
    t = np.arange(1, 26) * 1.0
    for cells in grids:
        opts = ReplayOptions(cells=cells)
        init, inlet, outflow = boundary_data(TRUTH, RUNS[1], t, cells)
        x = replay_grid(TRUTH, opts)
        data = ReplayData.from_arrays(t, x, np.ones((t.size, 4, cells)), init, inlet, outflow)
        run = run_replay(TRUTH, data, opts)
        ao = area_occupancy(TRUTH, run.fields[-1, 0], run.fields[-1, 2])
        j = int(np.searchsorted(x, 50.0))
        print(f"{cells:6d} | {ao[0]:9.3f} {ao[j]:8.3f} | {run.reason or '-'}")


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--quick", action="store_true", help="short runs, fewer grids")
    args = ap.parse_args()
    if args.quick:
        grid_study(120.0, [25, 50], 1)
        fit_study(120.0, 30)
        inlet_layer([50, 100])
    else:
        grid_study(300.0, [20, 50, 100], 2)
        fit_study(300.0, 50)
        inlet_layer([50, 100, 200, 400])


if __name__ == "__main__":
    main()
