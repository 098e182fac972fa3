"""``arzsumo evaluate`` with and without the shared warm-up: wall times and the speed-up.

    .venv/bin/python benchmarks/bench_evaluate.py [--seeds 4] [--workers 2]
        [--controllers open,alinea,pi-alinea,backstepping,etc] [--horizon S] [--warmup S]

The default scenario as shipped unless ``--horizon`` / ``--warmup`` (s) shorten it. The
two evaluations run one after the other into fresh directories (nothing skipped): first
every run with its own warm-up, then the runs of each seed continuing one warm-up
(:mod:`arzsumo.sweep.groups`). Wall times include the worker processes' start and the
report; the kernels are solved before either. The script also checks that both gave the
same whole-demand time spent, run by run, and prints the goal of the shared warm-up (a
speed-up of at least 1.6).
"""

from __future__ import annotations

import argparse
import shutil
import tempfile
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
DEFAULT = ROOT / "scenarios" / "default.toml"
CONTROLLERS = "open,alinea,pi-alinea,backstepping,etc"
KEY = "network_whole_demand.time_spent_s.total"


def timed(controllers: list[str], seeds: int, args: argparse.Namespace, share: bool,
          tmp: Path):
    from arzsumo.sweep.evaluate import run_evaluation

    out = Path(tempfile.mkdtemp(dir=tmp)) / "out"
    t0 = time.perf_counter()
    res = run_evaluation(DEFAULT, controllers, list(range(1, seeds + 1)), out=out,
                         horizon=args.horizon, warmup=args.warmup, workers=args.workers,
                         share_warmup=share, progress=False, plots=False)
    wall = time.perf_counter() - t0
    n = len(controllers) * seeds
    assert res.sweep.statuses == {"ok": n}, res.sweep.statuses
    runs = res.runs.set_index("run_id")[KEY].sort_index()
    shutil.rmtree(out.parent)
    return wall, runs


def warm_kernel_cache() -> None:
    """Solve the default's kernels before timing, so that neither evaluation pays it."""
    from arzsumo.kernel_cache import cached_kernels
    from arzsumo.model.characteristic import linearize
    from arzsumo.scenario import load_scenario

    sc = load_scenario(DEFAULT)
    cached_kernels(linearize(sc.equilibrium).system, sc.run.kernel_cells)


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--seeds", type=int, default=4)
    ap.add_argument("--workers", type=int, default=2)
    ap.add_argument("--controllers", default=CONTROLLERS)
    ap.add_argument("--horizon", type=float, default=None)
    ap.add_argument("--warmup", type=float, default=None)
    args = ap.parse_args()
    controllers = args.controllers.split(",")
    warm_kernel_cache()
    tmp = Path(tempfile.mkdtemp(prefix="bench_evaluate."))
    try:
        plain, a = timed(controllers, args.seeds, args, False, tmp)
        shared, b = timed(controllers, args.seeds, args, True, tmp)
    finally:
        shutil.rmtree(tmp, ignore_errors=True)
    n = len(controllers) * args.seeds
    same = a.index.equals(b.index) and bool((a == b).all())
    print(f"evaluate default: {len(controllers)} controllers x {args.seeds} seeds = {n} runs, "
          f"{args.workers} local processes, warm-up {args.warmup or 'as shipped'}, "
          f"horizon {args.horizon or 'as shipped'}")
    print(f"own warm-up per run      {plain:8.1f} s   ({plain / n:.1f} s per run)")
    print(f"shared warm-up per seed  {shared:8.1f} s   ({shared / n:.1f} s per run)")
    print(f"speed-up                 {plain / shared:8.2f}   (goal >= 1.6)")
    print(f"whole-demand time spent equal run by run: {same}")


if __name__ == "__main__":
    main()
