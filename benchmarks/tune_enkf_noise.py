"""Issue 16: the EnKF's model-error noise and inflation, chosen offline on SUMO records.

On SUMO data the EnKF with a perfect-model ensemble is over-confident (spread about a
tenth of its error). This script chooses the additive model-error noise per forecast
(``[estimation] model_sd_*``) on the records of ``--tune-seeds`` of
``bench_estimation_layouts.py`` (the same cached open-loop runs of the default scenario),
one layout (``--layout``), then reports on ``--report-seeds`` the normalised error
RMSE / mean spread per variable (target near 1) and the RMSE, for every EnKF layout.

Calibration: starting from ``--start``, each round runs the filter offline on the tuning
seeds and scales each variable's sd by its normalised error (pooled over seeds) to the
power ``--gain``; ``--rounds`` rounds. Inflation-only settings (no model noise) are
reported beside it::

    PYTHONPATH=src python benchmarks/tune_enkf_noise.py --tune-seeds 1 2 \\
        --report-seeds 3 4 5 --out docs/results/enkf_noise/enkf_noise_default.csv
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
from bench_estimation_layouts import LAYOUTS, SCENARIO, VARS, cache_path, offline

#: scenario keys of the model-error sd, in VARS order (user units: veh/km, km/h)
KEYS = ("estimation.model_sd_rho_h_veh_km", "estimation.model_sd_v_h_kmh",
        "estimation.model_sd_rho_a_veh_km", "estimation.model_sd_v_a_kmh")


def settings(sd: np.ndarray, inflation: float, length: float = 150.0) -> dict[str, Any]:
    """Scenario keys of one setting (sd in veh/km and km/h, correlation length m)."""
    return {**{k: float(v) for k, v in zip(KEYS, sd, strict=True)},
            "estimation.inflation": float(inflation), "estimation.model_length_m": length}


def score(job: tuple[str, str, int, str, dict[str, Any]]) -> dict[str, Any]:
    """RMSE and mean spread (relative) per variable of one record, layout and setting."""
    from arzsumo.bridge.sensor_record import SensorRecord
    from arzsumo.scenario import load_scenario

    path, scenario, seed, layout, extra = job
    rec, _ = SensorRecord.load(Path(path))
    s = offline(rec, load_scenario(Path(scenario)), layout, "enkf", extra)
    row: dict[str, Any] = {"seed": seed, "layout": layout}
    for v in VARS:
        row[f"{v}_rel"] = s[v]["relative"]
        row[f"{v}_spread_rel"] = s["spread"][v]["relative"]
    return row


def normalised(rows: list[dict[str, Any]]) -> np.ndarray:
    """RMSE pooled over rows (root mean square) / mean spread, per variable (4,)."""
    rmse = np.array([np.sqrt(np.mean([r[f"{v}_rel"] ** 2 for r in rows])) for v in VARS])
    spread = np.array([np.mean([r[f"{v}_spread_rel"] for r in rows]) for v in VARS])
    return rmse / spread


def evaluate(pool: Any, paths: dict[int, str], scenario: str, seeds: list[int],
             layouts: list[str], extra: dict[str, Any]) -> list[dict[str, Any]]:
    jobs = [(paths[s], scenario, s, lay, extra) for lay in layouts for s in seeds]
    return list(pool.map(score, jobs))


def fmt(rows: list[dict[str, Any]], label: str) -> str:
    """One table line: normalised error and mean RMSE per variable."""
    nerr = normalised(rows)
    rmse = [np.mean([r[f"{v}_rel"] for r in rows]) for v in VARS]
    return (f"| {label} | " + " | ".join(f"{n:.2f}" for n in nerr) + " | "
            + " | ".join(f"{e:.3f}" for e in rmse) + " |")


def main(argv: list[str] | None = None) -> int:
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--scenario", type=Path, default=SCENARIO)
    p.add_argument("--tune-seeds", type=int, nargs="+", default=[1, 2])
    p.add_argument("--report-seeds", type=int, nargs="*", default=[3, 4, 5])
    p.add_argument("--layout", default="loops 250 m + AV probes")
    p.add_argument("--start", type=float, nargs=4, default=[2.0, 1.0, 1.0, 1.0],
                   help="starting sd: rho_h veh/km, v_h km/h, rho_a veh/km, v_a km/h")
    p.add_argument("--inflation", type=float, default=1.05)
    p.add_argument("--length", type=float, default=150.0,
                   help="correlation length of the model noise, m")
    p.add_argument("--rounds", type=int, default=6, help="0: report --start as it is")
    p.add_argument("--inflation-only", type=float, nargs="*", default=[1.05, 1.3, 2.0],
                   help="inflations tried without model noise on the tuning seeds")
    p.add_argument("--gain", type=float, default=1.5)
    p.add_argument("--workers", type=int, default=2)
    p.add_argument("--out", default="enkf_noise.csv")
    args = p.parse_args(argv)
    from arzsumo.scenario import load_scenario

    sc = load_scenario(args.scenario)
    scen = str(args.scenario)
    seeds = sorted(set(args.tune_seeds + args.report_seeds))
    paths = {s: str(cache_path(args.scenario, s, sc.run.warmup, sc.sumo.horizon))
             for s in seeds}
    missing = [s for s in seeds if not Path(paths[s]).exists()]
    if missing:
        sys.exit(f"no record of seeds {missing}: run bench_estimation_layouts.py first")
    head = ("| setting | " + " | ".join(f"RMSE/spread {v}" for v in VARS) + " | "
            + " | ".join(f"RMSE {v}" for v in VARS) + " |")
    lines = [head, "|---|" + "---|" * 8]
    out_rows: list[dict[str, Any]] = []
    with ProcessPoolExecutor(args.workers, mp_context=mp.get_context("spawn")) as pool:
        for infl in args.inflation_only:                    # inflation alone
            rows = evaluate(pool, paths, scen, args.tune_seeds, [args.layout],
                            settings(np.zeros(4), infl))
            lines.append(fmt(rows, f"tune: no model noise, inflation {infl:g}"))
        sd = np.array(args.start, float)
        for k in range(args.rounds):
            rows = evaluate(pool, paths, scen, args.tune_seeds, [args.layout],
                            settings(sd, args.inflation, args.length))
            lines.append(fmt(rows, f"tune round {k}: sd " + ", ".join(f"{v:.3g}" for v in sd)))
            print(lines[-1], flush=True)
            sd = sd * np.clip(normalised(rows), 0.25, 4.0) ** args.gain
        sd = np.array([float(f"{v:.2g}") for v in sd]) if args.rounds else sd
        for lay in [name for name, keys in LAYOUTS.items() if keys and args.report_seeds]:
            for label, extra in (("perfect model", settings(np.zeros(4), 1.05)),
                                 ("model noise", settings(sd, args.inflation, args.length))):
                rows = evaluate(pool, paths, scen, args.report_seeds, [lay], extra)
                lines.append(fmt(rows, f"report {lay}: {label}"))
                out_rows += [{**r, "setting": label} for r in rows]
    print(f"chosen model-error sd per forecast: {sd.tolist()} (rho_h veh/km, v_h km/h, "
          f"rho_a veh/km, v_a km/h), inflation {args.inflation:g}; tuned on seeds "
          f"{args.tune_seeds}, {args.layout}; reported on seeds {args.report_seeds}")
    print("\n".join(lines))
    if not out_rows:
        return 0
    with open(args.out, "w", newline="") as f:
        w = csv.DictWriter(f, list(out_rows[0]))
        w.writeheader()
        w.writerows(out_rows)
    return 0


if __name__ == "__main__":
    sys.exit(main())
