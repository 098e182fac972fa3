"""Co-simulation wall time with each estimator: none, smoothing, enkf (32).

``scenarios/legacy_default.toml`` (150 s warm-up; ``--scenario`` another, e.g. the
default with its 600 s fill, ``--warmup`` to override), a short control horizon (120 s by
default), the ETC: ``none`` on today's sensor (the full probe's cells), ``smoothing``
and ``enkf`` on loops every 250 m and every AV as a probe (the sensors are loaded in all
three so the ratio is the estimator's alone; loading the loops moves no vehicle,
``tests/bridge/test_estimation_loop.py``). Runs alternate, best of ``--repeats``. Prints
each wall time, its ratio to ``none``, and the estimator's time per control period.
The estimators also run over the warm-up's records (the EnKF and the ASM need a
history), which is in the wall time but not in the per-period figure.

BLAS runs single-threaded (``OPENBLAS_NUM_THREADS=1``, set here before numpy loads):
on a busy 2-core machine a multi-threaded BLAS made the EnKF's small matrix products up
to 25 times slower (``benchmarks/bench_estimate.py``). threadpoolctl is not installed,
so the limit is the environment variable.

Run: ``.venv/bin/python benchmarks/bench_estimation_cost.py [--horizon 120] [--repeats 2]``
"""

from __future__ import annotations

import os

for _var in ("OPENBLAS_NUM_THREADS", "OMP_NUM_THREADS", "MKL_NUM_THREADS"):
    os.environ.setdefault(_var, "1")

import argparse  # noqa: E402
import time  # noqa: E402
from pathlib import Path  # noqa: E402

from arzsumo.bridge.cosim import run_cosimulation  # noqa: E402
from arzsumo.bridge.prepared import PreparedRun  # noqa: E402
from arzsumo.bridge.session import prepare_run  # noqa: E402
from arzsumo.scenario import Scenario, load_scenario  # noqa: E402

LEGACY = Path(__file__).resolve().parents[1] / "scenarios" / "legacy_default.toml"
SENSORS = {"sensing.kinds": ["probe", "loops", "av_probes"], "sensing.loop_spacing_m": 250}
METHODS = {"none": {}, "smoothing": {"estimation.method": "smoothing"},
           "enkf (32)": {"estimation.method": "enkf", "estimation.members": 32}}


def main() -> None:
    ap = argparse.ArgumentParser()
    ap.add_argument("--horizon", type=float, default=120.0)
    ap.add_argument("--repeats", type=int, default=2)
    ap.add_argument("--controller", default="etc")
    ap.add_argument("--scenario", type=Path, default=LEGACY)
    ap.add_argument("--warmup", type=float, default=None, help="s (default: the scenario's)")
    args = ap.parse_args()
    base = load_scenario(args.scenario).with_(SENSORS)
    def prepared(sc: Scenario, horizon: float) -> PreparedRun:
        return prepare_run(sc, controller=args.controller, horizon=horizon,
                           warmup=args.warmup)

    runs = {name: prepared(base.with_(ch) if ch else base, args.horizon)
            for name, ch in METHODS.items()}
    run_cosimulation(prepared(base, 5.0))  # kernels cached
    wall: dict[str, list[float]] = {name: [] for name in runs}
    per_period: dict[str, float] = {}
    for _ in range(args.repeats):
        for name, run in runs.items():
            t0 = time.perf_counter()
            res = run_cosimulation(run)
            wall[name].append(time.perf_counter() - t0)
            per_period[name] = res.timings["estimator"] / max(1, res.t.size)
    ref = min(wall["none"])
    warmup = runs["none"].settings.warmup
    print(f"scenario {base.name}, controller {args.controller}, warm-up "
          f"{warmup:g} s + {args.horizon:g} s control, loops every 250 m + AV "
          f"probes, best of {args.repeats}, OPENBLAS_NUM_THREADS="
          f"{os.environ['OPENBLAS_NUM_THREADS']}")
    print(f"{'method':<10} {'wall s':>8} {'ratio':>7} {'estimator ms/period':>20}")
    for name in runs:
        w = min(wall[name])
        print(f"{name:<10} {w:8.2f} {w / ref:7.3f} {1e3 * per_period[name]:20.2f}")


if __name__ == "__main__":
    main()
