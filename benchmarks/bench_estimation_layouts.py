"""Issue 16: estimation error against sensor layout, per estimator, over seeds.

Open loop (the estimate does not act, so every layout sees the same traffic per seed) on
``scenarios/legacy_default.toml`` with a short warm-up and horizon (the default's 600 s
fill makes one run take minutes). Per run, ``summary.json["estimation"]``: the relative
RMSE of the estimate against the full-probe cells, for rho_h, v_h, rho_a, v_a, and of
linear interpolation between the loop stations. Prints a table of means over seeds with
95 % t-intervals and writes the rows to ``--out`` (CSV, units in the column names)::

    PYTHONPATH=src python benchmarks/bench_estimation_layouts.py --seeds 1 2 3 4 5 \\
        --out docs/estimation_layouts.csv
"""

from __future__ import annotations

import argparse
import csv
import multiprocessing as mp
import sys
from concurrent.futures import ProcessPoolExecutor
from pathlib import Path
from typing import Any

import numpy as np
from scipy import stats

ROOT = Path(__file__).resolve().parents[1]
SCENARIO = ROOT / "scenarios" / "legacy_default.toml"
VARS = ("rho_h", "v_h", "rho_a", "v_a")
#: layout name -> [sensing] keys
LAYOUTS: dict[str, dict[str, Any]] = {
    "loops 100 m": {"sensing.kinds": ["loops"], "sensing.loop_spacing_m": 100},
    "loops 250 m": {"sensing.kinds": ["loops"], "sensing.loop_spacing_m": 250},
    "loops 500 m": {"sensing.kinds": ["loops"], "sensing.loop_spacing_m": 500},
    "boundary loops + AV probes": {"sensing.kinds": ["loops", "av_probes"]},
    "loops 250 m + AV probes": {"sensing.kinds": ["loops", "av_probes"],
                                "sensing.loop_spacing_m": 250},
}
METHODS = ("smoothing", "enkf")


def run(job: tuple[str, str, int, float, float]) -> dict[str, Any]:
    """One open-loop run; the estimation RMSE of its summary."""
    from arzsumo.bridge.session import run_in_sumo
    from arzsumo.outputs.bridge import summary
    from arzsumo.scenario import load_scenario

    layout, method, seed, warmup, horizon = job
    sc = load_scenario(SCENARIO).with_({**LAYOUTS[layout], "estimation.method": method,
                                        "run.controller": "open"})
    s = summary(run_in_sumo(sc, seed=seed, horizon=horizon, warmup=warmup).result)
    est = s["estimation"]
    row: dict[str, Any] = {"layout": layout, "method": method, "seed": seed}
    for v in VARS:
        row[f"{v}_rel"] = est[v]["relative"]
        interp = est.get("interpolation") or {}
        row[f"{v}_interp_rel"] = interp.get(v, {}).get("relative", np.nan)
    return row


def table(rows: list[dict[str, Any]]) -> str:
    """Means over seeds with 95 % t half-widths, per layout and method."""
    out = ["| layout | method | " + " | ".join(VARS) + " | interpolation (same order) |",
           "|---|---|" + "---|" * (len(VARS) + 1)]
    for layout in LAYOUTS:
        for method in METHODS:
            sel = [r for r in rows if r["layout"] == layout and r["method"] == method]
            if not sel:
                continue
            cells = []
            for v in VARS:
                x = np.array([r[f"{v}_rel"] for r in sel], float)
                half = (stats.t.ppf(0.975, x.size - 1) * x.std(ddof=1) / np.sqrt(x.size)
                        if x.size > 1 else np.nan)
                cells.append(f"{x.mean():.3f} +- {half:.3f}")
            interp = " / ".join(f"{np.nanmean([r[f'{v}_interp_rel'] for r in sel]):.2f}"
                                for v in VARS)
            out.append(f"| {layout} | {method} | " + " | ".join(cells) + f" | {interp} |")
    return "\n".join(out)


def main(argv: list[str] | None = None) -> int:
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--seeds", type=int, nargs="+", default=[1, 2, 3, 4, 5])
    p.add_argument("--warmup", type=float, default=150.0)
    p.add_argument("--horizon", type=float, default=120.0)
    p.add_argument("--workers", type=int, default=2)
    p.add_argument("--out", default="estimation_layouts.csv")
    args = p.parse_args(argv)
    jobs = [(lay, m, s, args.warmup, args.horizon) for lay in LAYOUTS for m in METHODS
            for s in args.seeds]
    with ProcessPoolExecutor(args.workers, mp_context=mp.get_context("spawn")) as pool:
        rows = list(pool.map(run, jobs))
    with open(args.out, "w", newline="") as f:
        w = csv.DictWriter(f, list(rows[0]))
        w.writeheader()
        w.writerows(rows)
    print(f"relative RMSE of the estimate (1 = the equilibrium value), mean over seeds "
          f"{args.seeds}, {args.warmup:g} s warm-up + {args.horizon:g} s, open loop")
    print(table(rows))
    return 0


if __name__ == "__main__":
    sys.exit(main())
