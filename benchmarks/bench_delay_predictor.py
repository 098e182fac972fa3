"""Continuous backstepping with a delayed input on the linear plant, with and without the
delay predictor (:mod:`arzsumo.control.predictor`).

For each model (the paper_base preset and ``scenarios/default.toml``'s identified model at
its equilibrium) and each input delay, the law control_law drives the linear plant
(clpsys1-clpsys4, :class:`~arzsumo.control.plant.LinearPlant`, 100 cells) from the same
smooth initial state; its command reaches the outlet ``delay`` s later. Prints the L2
norm of w-bar at t_f and 2 t_f relative to the initial norm (t_f: the finite
convergence time L / min lambda+ + L / Lambda-), and the ratio of the norm at 2 t_f
with the predictor to that without it (< 1: the predictor helps).

Usage::

    PYTHONPATH=src python benchmarks/bench_delay_predictor.py --delays 0 1 3 6 12 20
"""

from __future__ import annotations

import argparse
import sys
from pathlib import Path

import numpy as np

from arzsumo.control.kernels import solve_kernels
from arzsumo.control.plant import LinearPlant
from arzsumo.control.predictor import committed, predict_riemann
from arzsumo.control.transform import BacksteppingLaw
from arzsumo.model import PRESETS, Linearization, equilibrium_from_densities, linearize
from arzsumo.scenario import load_scenario

ROOT = Path(__file__).resolve().parents[1]


def initial(lin: Linearization, x: np.ndarray) -> np.ndarray:
    """Smooth bumps in every scaled Riemann variable, consistent with the boundaries."""
    s = lin.system
    w = np.vstack([0.3 * np.sin(np.pi * (k + 1) * x / s.length)
                   + 0.2 * np.cos(2 * np.pi * x / s.length) for k in range(s.n + 1)])
    w[: s.n, 0] = s.Q * w[s.n, 0]
    w[s.n, -1] = s.R @ w[: s.n, -1]
    return w


def closed_loop(lin: Linearization, law: BacksteppingLaw, delay: float, predict: bool
                ) -> tuple[float, float]:
    """Norm at t_f and 2 t_f relative to the initial norm."""
    s = lin.system
    plant = LinearPlant(s, 100)
    plant.reset(initial(lin, plant.x))
    issued_t: list[float] = []
    issued_u: list[float] = []

    def u_bar(t: float, w: np.ndarray) -> float:
        if predict and delay > 0:
            w = predict_riemann(s, plant.x, w, delay,
                                committed(np.array(issued_t), np.array(issued_u), t, delay))
        issued_t.append(t)
        issued_u.append(law.u_bar(w))
        k = int(np.searchsorted(issued_t, t - delay, side="right")) - 1
        return issued_u[k] if k >= 0 else 0.0

    h = plant.run(2 * s.t_f, u_bar, sample_every=1.0)
    at = np.interp([s.t_f, 2 * s.t_f], h.t, h.norm) / h.norm[0]
    return float(at[0]), float(at[1])


def main(argv: list[str] | None = None) -> int:
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--delays", type=float, nargs="+", default=[0, 1, 3, 6, 12, 20])
    args = p.parse_args(argv)
    base = PRESETS["paper_base"]
    models = {"paper_base": linearize(equilibrium_from_densities(base.params, base.rho_h,
                                                                  base.rho_a)),
              "default": linearize(load_scenario(ROOT / "scenarios/default.toml").equilibrium)}
    print("| model | t_f s | delay s | law on w(t): norm at t_f, 2 t_f | "
          "on predicted w(t + delay) | ratio at 2 t_f |\n|---|---|---|---|---|---|")
    for name, lin in models.items():
        law = BacksteppingLaw(lin.system, solve_kernels(lin.system, 100))
        for d in args.delays:
            plain = closed_loop(lin, law, d, False)
            pred = closed_loop(lin, law, d, True) if d > 0 else plain
            print(f"| {name} | {lin.system.t_f:.0f} | {d:g} | {plain[0]:.3g}, {plain[1]:.3g} | "
                  f"{pred[0]:.3g}, {pred[1]:.3g} | {pred[1] / plain[1]:.3g} |", flush=True)
    return 0


if __name__ == "__main__":
    sys.exit(main())
