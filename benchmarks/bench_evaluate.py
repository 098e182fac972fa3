"""Wall time of ``arzsumo evaluate`` (2 controllers x 4 seeds in SUMO) on 1 and 2 local
processes, and the ratio.

    .venv/bin/python benchmarks/bench_evaluate.py [--seeds 4] [--warmup 30] [--horizon 60]

The default scenario with a shorter warm-up (``--warmup`` s) and control horizon
(``--horizon`` s); open loop and ALINEA (no kernels to solve). Each evaluation runs into
a fresh directory (nothing skipped); wall times include starting the worker processes
and writing the report (CSV, Markdown, figure).
"""

from __future__ import annotations

import argparse
import os
import shutil
import tempfile
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]


def scenario(tmp: Path, warmup: float) -> Path:
    text = (ROOT / "scenarios" / "default.toml").read_text(encoding="utf-8")
    path = tmp / "bench_evaluate.toml"
    path.write_text(text.replace("warmup_s = 150", f"warmup_s = {warmup:g}"), encoding="utf-8")
    return path


def timed(path: Path, tmp: Path, seeds: int, horizon: float, workers: int) -> float:
    from arzsumo.sweep.evaluate import run_evaluation

    out = Path(tempfile.mkdtemp(dir=tmp)) / "out"
    t0 = time.perf_counter()
    res = run_evaluation(path, ["open", "alinea"], list(range(1, seeds + 1)), out=out,
                         horizon=horizon, workers=workers, progress=False)
    wall = time.perf_counter() - t0
    assert res.sweep.executed == 2 * seeds and res.sweep.statuses == {"ok": 2 * seeds}
    shutil.rmtree(out.parent)
    return wall


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--seeds", type=int, default=4)
    ap.add_argument("--warmup", type=float, default=30.0)
    ap.add_argument("--horizon", type=float, default=60.0)
    args = ap.parse_args()
    tmp = Path(tempfile.mkdtemp(prefix="bench_evaluate."))
    os.environ["ARZSUMO_CACHE"] = str(tmp / "kernels")
    path = scenario(tmp, args.warmup)
    n = 2 * args.seeds
    one = timed(path, tmp, args.seeds, args.horizon, 1)
    two = timed(path, tmp, args.seeds, args.horizon, 2)
    print(f"evaluate: open, alinea x {args.seeds} seeds = {n} SUMO runs of "
          f"{args.warmup:g} s warm-up + {args.horizon:g} s control")
    print(f"  1 process  : {one:7.2f} s  {one / n:6.2f} s/run")
    print(f"  2 processes: {two:7.2f} s  {two / n:6.2f} s/run")
    print(f"  speed-up 2 / 1 processes: {one / two:.2f}")
    shutil.rmtree(tmp, ignore_errors=True)


if __name__ == "__main__":
    main()
