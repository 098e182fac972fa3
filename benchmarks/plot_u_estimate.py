"""Issue 16: the controller's U on raw cells beside U on an estimate, same seed.

Backstepping on ``scenarios/legacy_default.toml`` (seed 42, 150 s warm-up + 120 s), once on
the full probe's raw 50 m x 1 s cells (``[estimation] method = "none"``) and once per
estimator on loops every 250 m plus AV probes. Writes ``--out`` (PNG; U in veh/h) and
prints the plan changes and the U step statistics of each::

    PYTHONPATH=src python benchmarks/plot_u_estimate.py \\
        --out docs/results/u_on_estimate/u_on_estimate.png
"""

from __future__ import annotations

import argparse
import sys
from pathlib import Path

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt
import numpy as np

ROOT = Path(__file__).resolve().parents[1]
SCENARIO = ROOT / "scenarios" / "legacy_default.toml"
SENSORS = {"sensing.kinds": ["loops", "av_probes"], "sensing.loop_spacing_m": 250}


def control_series(method: str) -> tuple[np.ndarray, np.ndarray, int]:
    """(t s, U veh/h, plan changes) of one backstepping run on ``method``'s state."""
    from arzsumo.bridge.session import run_in_sumo
    from arzsumo.scenario import load_scenario

    changes = {"run.controller": "backstepping", "estimation.method": method}
    if method != "none":
        changes.update(SENSORS)
    sc = load_scenario(SCENARIO).with_(changes)
    res = run_in_sumo(sc, seed=42, horizon=120.0, warmup=150.0).result
    log = res.controller_log
    return (np.asarray(log.t, float), np.asarray(log.u_continuous, float) * 3600.0,
            int(res.meter["plan_changes"]))


def main(argv: list[str] | None = None) -> int:
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--out", default="u_on_estimate.png")
    args = p.parse_args(argv)
    fig, ax = plt.subplots(figsize=(9, 4))
    for method, label in (("none", "raw cells (full probe)"),
                          ("smoothing", "ASM on loops 250 m + AV probes"),
                          ("enkf", "EnKF(32) on loops 250 m + AV probes")):
        t, u, plan = control_series(method)
        steps = np.abs(np.diff(u))
        print(f"{method:9s}: plan changes {plan:3d}, U range [{u.min():.0f}, {u.max():.0f}] "
              f"veh/h, median |dU| per period {np.median(steps):.0f} veh/h")
        ax.plot(t, u, lw=1.0, label=f"{label}: {plan} plan changes")
    ax.set_xlabel("t since control start (s)")
    ax.set_ylabel("U, backstepping (veh/h)")
    ax.set_title("legacy_default, seed 42: the law on raw cells and on estimates")
    ax.legend(fontsize=8)
    fig.tight_layout()
    fig.savefig(args.out, dpi=90)
    print(f"figure: {args.out}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
