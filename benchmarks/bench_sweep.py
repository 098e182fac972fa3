"""Throughput of a twin sweep on 1 and 2 local processes, and the overhead per run of the
Dask path (a LocalCluster on loopback) against the local pool.

    .venv/bin/python benchmarks/bench_sweep.py [--runs 32] [--horizon 450]

Each sweep runs into a fresh directory (nothing skipped) with a warm kernel cache (the
kernels of every penetration are solved once before timing). Wall times include starting
the worker processes (local pool) or connecting to the running cluster (Dask); the cluster
itself is started before timing. The overhead per run is measured twice: on the real
runs, and on near-empty runs (1 s horizon) where scheduling is all there is.
"""

from __future__ import annotations

import argparse
import os
import shutil
import tempfile
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]


def spec(n_runs: int, horizon: float, cells: int):
    from arzsumo.sweep import sweep_from_dict

    pens = [0.44, 0.47, 0.50, 0.53]
    seeds = list(range(1, max(1, n_runs // len(pens)) + 1))
    data = {"name": "bench", "base": "scenarios/paper/penetration_44_etc.toml",
            "engine": "twin", "seeds": seeds,
            "set": {"initial": {"kind": "random"},
                    "twin": {"cells": cells, "horizon_s": horizon, "kernel_cells": 100}},
            "axis": [{"field": "equilibrium.penetration", "values": pens}]}
    return sweep_from_dict(data, "bench.toml", root=ROOT)


def timed(sp, tmp: Path, **kw) -> float:
    from arzsumo.sweep import run_sweep

    out = Path(tempfile.mkdtemp(dir=tmp))
    t0 = time.perf_counter()
    rep = run_sweep(sp, out, progress=False, plots=False, **kw)
    wall = time.perf_counter() - t0
    assert rep.executed == len(sp.runs()) and set(rep.statuses) <= {"ok", "incomplete"}
    shutil.rmtree(out)
    return wall


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--runs", type=int, default=32)
    ap.add_argument("--horizon", type=float, default=450.0)
    ap.add_argument("--cells", type=int, default=200)
    args = ap.parse_args()
    tmp = Path(tempfile.mkdtemp(prefix="bench_sweep."))
    os.environ["ARZSUMO_CACHE"] = str(tmp / "kernels")
    from distributed import LocalCluster

    real = spec(args.runs, args.horizon, args.cells)
    empty = spec(args.runs, 1.0, 20)
    n = len(real.runs())
    timed(spec(4, 1.0, 20), tmp, workers=1)          # warm the kernel cache
    one = timed(real, tmp, workers=1)
    two = timed(real, tmp, workers=2)
    print(f"twin sweep, {n} runs of {args.horizon:g} s at {args.cells} cells (first order)")
    print(f"  1 process : {one:7.2f} s  {n / one:6.2f} runs/s")
    print(f"  2 processes: {two:7.2f} s  {n / two:6.2f} runs/s")
    print(f"  throughput ratio 2 / 1 processes: {one / two:.2f} (goal >= 1.8)")
    with LocalCluster(n_workers=2, threads_per_worker=1, processes=True, host="127.0.0.1",
                      dashboard_address=None) as cluster:
        addr = cluster.scheduler_address
        timed(empty, tmp, scheduler=addr)                 # workers import arzsumo once
        dask_real = timed(real, tmp, scheduler=addr)
        dask_empty = timed(empty, tmp, scheduler=addr)
    local_empty = timed(empty, tmp, workers=2)
    print("Dask LocalCluster (2 workers x 1 thread, loopback) vs local pool (2 processes)")
    print(f"  real runs : Dask {dask_real:7.2f} s, local {two:7.2f} s; overhead per run "
          f"{(dask_real - two) / n * 1e3:+8.1f} ms")
    print(f"  empty runs: Dask {dask_empty:7.2f} s, local {local_empty:7.2f} s; per run "
          f"Dask {dask_empty / n * 1e3:6.1f} ms, local {local_empty / n * 1e3:6.1f} ms "
          "(local includes starting 2 processes)")
    shutil.rmtree(tmp, ignore_errors=True)


if __name__ == "__main__":
    main()
