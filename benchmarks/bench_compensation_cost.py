"""Cost of the delay predictor per control check, against the plain check.

Times ``check`` of backstepping and the ETC, plain and wrapped in
:class:`~arzsumo.control.compensation.DelayCompensated` (prediction theta s ahead with the
committed commands), on ``scenarios/default.toml``'s identified model and kernel grid, on
the same sequence of states; prints microseconds per check and the ratio. The check runs
once per control period (1 s of SUMO, about 290 ms of CPU on the default), so its share is
what matters.

    PYTHONPATH=src python benchmarks/bench_compensation_cost.py --theta 14 --checks 2000
"""

from __future__ import annotations

import argparse
import sys
import time
from pathlib import Path

import numpy as np

from arzsumo.control.backstepping import Backstepping
from arzsumo.control.base import MacroState
from arzsumo.control.compensation import DelayCompensated
from arzsumo.control.etc import EventTriggered
from arzsumo.control.kernels import solve_kernels
from arzsumo.model.characteristic import linearize
from arzsumo.scenario import load_scenario

DEFAULT = Path(__file__).resolve().parents[1] / "scenarios" / "default.toml"


def states(ctrl: Backstepping | EventTriggered, n: int, seed: int) -> list[MacroState]:
    """``n`` states: the reference plus smooth random deviations (5 % of it)."""
    rng = np.random.default_rng(seed)
    sm = ctrl.state_map
    base = np.asarray(sm.reference)
    out = []
    for k in range(n):
        dev = 0.05 * base * np.sin(np.outer(rng.uniform(1, 4, 4), sm.x / sm.x[-1] * np.pi))
        out.append(MacroState(float(k), sm.x, *(base + dev)))
    return out


def time_checks(ctrl, seq: list[MacroState]) -> float:
    """Seconds per check over ``seq`` (the applied U fed back as the closed loop does)."""
    t0 = time.perf_counter()
    for s in seq:
        ctrl.actuated(ctrl.check(s))
    return (time.perf_counter() - t0) / len(seq)


def main() -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--theta", type=float, default=14.0, help="prediction horizon, s")
    ap.add_argument("--checks", type=int, default=2000)
    ap.add_argument("--repeats", type=int, default=3)
    args = ap.parse_args()
    sc = load_scenario(DEFAULT)
    lin = linearize(sc.equilibrium)
    kernels = solve_kernels(lin.system, sc.run.kernel_cells)
    for cls in (Backstepping, EventTriggered):
        seq = states(cls(lin, kernels), args.checks, seed=1)
        best = {}
        for name, make in (("plain", lambda c=cls: c(lin, kernels)),
                           ("compensated", lambda c=cls: DelayCompensated(c(lin, kernels),
                                                                          args.theta))):
            best[name] = min(time_checks(make(), seq) for _ in range(args.repeats))
        print(f"{cls.__name__:15s} plain {best['plain'] * 1e6:7.1f} us/check, compensated "
              f"(theta {args.theta:g} s) {best['compensated'] * 1e6:7.1f} us/check, ratio "
              f"x{best['compensated'] / best['plain']:.2f}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
