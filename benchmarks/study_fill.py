"""Issue 15, point 1 (continued): fill-then-hold demand on the approach network.

Each point is one open-loop SUMO run (fixed meter plan) on the network with an ``approach``
buffer edge before x = 0. The mainline demand is ``--fill-h``/``--fill-a`` veh/h from
t = 0 to ``--fill`` s (above the merge's discharge: the queue fills the section from the
merge), then the hold demand of the point (HV, AV veh/h) to the end. After ``--warmup``
s, ``--measured`` s are measured on ``main`` with the statistics of
:mod:`study_approach` (trend of the section count on 30 s block means with Kendall's
test, densities, Edie speeds, speed sd, inserted fraction, approach queue, lambda_4).

Usage (one CSV row per run, appended as runs finish; existing rows are skipped)::

    PYTHONPATH=src python benchmarks/study_fill.py \\
        --out docs/results/sumo_fill/sumo_fill.csv --jobs 2 \\
        --holds 3750:850 3900:950 --seeds 1 2 3
"""

from __future__ import annotations

import argparse
import csv
import multiprocessing as mp
import sys
import time
from concurrent.futures import ProcessPoolExecutor, as_completed
from pathlib import Path
from typing import Any

import numpy as np
from study_approach import SCENARIO, open_loop, run_measures

FIELDS = ["hold_h_veh_h", "hold_a_veh_h", "fill_h_veh_h", "fill_a_veh_h", "fill_s",
          "green_share", "hv_sigma", "seed", "approach_m", "step_s", "warmup_s",
          "measured_s", "wall_s", "n_mean", "slope_veh_min", "slope_lo", "slope_hi",
          "kendall_p", "drift_rel", "stationary", "rho_h_veh_km", "rho_a_veh_km", "v_h_kmh",
          "v_a_kmh", "sd_v_h_kmh", "sd_v_a_kmh", "congested_share", "inflow_veh_h",
          "outflow_veh_h", "outflow_h_veh_h", "outflow_a_veh_h", "inserted_main",
          "approach_veh_end", "queue_m_end", "approach_slope_veh_min", "ramp_queue_end",
          "lambda4_kmh", "regime", "collisions", "emergency_stops", "ok"]
KEY = FIELDS[:12]


def run_point(p: dict[str, Any]) -> dict[str, Any]:
    """One open-loop run of point ``p`` (the KEY columns); returns the CSV row."""
    from arzsumo.scenario import load_scenario

    t0 = time.perf_counter()
    sc = load_scenario(SCENARIO)
    cfg = sc.sumo.with_(
        demand_h=p["hold_h_veh_h"] / 3600, demand_a=p["hold_a_veh_h"] / 3600,
        fill_demand_h=p["fill_h_veh_h"] / 3600, fill_demand_a=p["fill_a_veh_h"] / 3600,
        fill_duration=p["fill_s"], green_share=p["green_share"], hv_sigma=p["hv_sigma"],
        seed=int(p["seed"]), approach_length=p["approach_m"], step_length=p["step_s"],
        horizon=p["warmup_s"] + p["measured_s"])
    cells, n_app, (app_veh, queue_m), ramp_q, rep = open_loop(sc.params, cfg, p["warmup_s"])
    row = dict(p)
    row.update(run_measures(cfg, cells, n_app, (app_veh, queue_m), ramp_q, rep))
    for c in "ha":
        row[f"outflow_{c}_veh_h"] = float(np.mean([getattr(d, f"outflow_{c}") for d in cells])
                                          * 3600)
    row["ok"] = int(row["stationary"] and row["lambda4_kmh"] < 0
                    and row["inserted_main"] >= 0.98)
    row["wall_s"] = time.perf_counter() - t0
    return row


def _key(row: dict[str, Any]) -> tuple:
    return tuple(round(float(row[k]), 6) for k in KEY)


def points(args: argparse.Namespace) -> list[dict[str, Any]]:
    """The grid: hold demands x green shares x sigmas x seeds."""
    out = []
    for hold in args.holds:
        h, a = (float(v) for v in hold.split(":"))
        for g in args.greens:
            for s in args.sigmas:
                for seed in args.seeds:
                    out.append(dict(zip(KEY, (h, a, args.fill_h, args.fill_a, args.fill, g, s,
                                              seed, args.approach, args.step, args.warmup,
                                              args.measured), strict=True)))
    return out


def sweep(args: argparse.Namespace) -> None:
    """Run every missing point, appending rows to ``args.out``."""
    out = Path(args.out)
    done = set()
    if out.is_file():
        with out.open() as f:
            done = {_key(r) for r in csv.DictReader(f)}
    todo = [p for p in points(args) if _key(p) not in done]
    print(f"{len(todo)} runs to do", flush=True)
    new = not out.is_file()
    with out.open("a", newline="") as f, ProcessPoolExecutor(
            args.jobs, mp_context=mp.get_context("spawn"), max_tasks_per_child=1) as pool:
        w = csv.DictWriter(f, FIELDS)
        if new:
            w.writeheader()
        for fut in as_completed([pool.submit(run_point, p) for p in todo]):
            row = fut.result()
            w.writerow({k: (f"{v:.5g}" if isinstance(v, float) else v)
                        for k, v in row.items()})
            f.flush()
            shown = ["hold_h_veh_h", "hold_a_veh_h", "green_share", "seed", "wall_s",
                     "slope_veh_min", "kendall_p", "drift_rel", "rho_h_veh_km",
                     "rho_a_veh_km", "v_h_kmh", "v_a_kmh", "sd_v_h_kmh", "sd_v_a_kmh",
                     "outflow_h_veh_h", "outflow_a_veh_h", "inserted_main", "queue_m_end",
                     "lambda4_kmh", "ok"]
            print(", ".join(f"{k}={row[k]:.4g}" if isinstance(row[k], float) else
                            f"{k}={row[k]}" for k in shown), flush=True)


def main(argv: list[str] | None = None) -> int:
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--out", default="docs/results/sumo_fill/sumo_fill.csv")
    p.add_argument("--holds", nargs="+", default=["3750:850"],
                   help="hold demands HV:AV, veh/h")
    p.add_argument("--fill-h", type=float, default=4200.0, help="HV fill demand, veh/h")
    p.add_argument("--fill-a", type=float, default=1300.0, help="AV fill demand, veh/h")
    p.add_argument("--fill", type=float, default=600.0, help="fill phase, s")
    p.add_argument("--greens", type=float, nargs="+", default=[0.5])
    p.add_argument("--sigmas", type=float, nargs="+", default=[0.5])
    p.add_argument("--seeds", type=int, nargs="+", default=[1])
    p.add_argument("--approach", type=float, default=2500.0, help="buffer length, m")
    p.add_argument("--warmup", type=float, default=600.0)
    p.add_argument("--measured", type=float, default=450.0)
    p.add_argument("--step", type=float, default=0.1)
    p.add_argument("--jobs", type=int, default=1)
    sweep(p.parse_args(argv))
    return 0


if __name__ == "__main__":
    sys.exit(main())
