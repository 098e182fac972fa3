"""Issue 16: estimation error against sensor layout, per estimator, over seeds.

Per seed ONE open-loop SUMO run of the scenario (default: ``scenarios/default.toml``,
its 600 s fill as warm-up + 450 s) records the sensor data of a superset of sensors
(loop stations every 50 m with both boundaries, every AV a probe) and the truth (the full
probe's cells): :func:`arzsumo.bridge.sensor_record.record_run`, cached as ``.npz`` in
``$ARZSUMO_CACHE/estimation-runs``. Every layout x estimator is then an offline pass over
the recorded observations (:func:`~arzsumo.bridge.sensor_record.replay_estimation`), with
the numbers the estimator gives inside the closed loop (``tests/bridge/
test_sensor_record.py``). ``interpolation`` is linear interpolation between the layout's
loop stations (speeds filled with Ve), the baseline; with the full probe the controller
acts on the truth itself (RMSE 0). Prints means over seeds with 95 % t half-widths and
writes one row per layout, method and seed to ``--out``::

    PYTHONPATH=src python benchmarks/bench_estimation_layouts.py --seeds 1 2 3 4 5 \\
        --workers 2 --out docs/results/estimation_layouts/estimation_layouts_default.csv
"""

from __future__ import annotations

import argparse
import csv
import hashlib
import json
import multiprocessing as mp
import os
import sys
import time
from concurrent.futures import ProcessPoolExecutor
from pathlib import Path
from typing import Any

import numpy as np
from scipy import stats

ROOT = Path(__file__).resolve().parents[1]
SCENARIO = ROOT / "scenarios" / "default.toml"
VARS = ("rho_h", "v_h", "rho_a", "v_a")
#: layout name -> [sensing] keys ({} : the full probe)
LAYOUTS: dict[str, dict[str, Any]] = {
    "full probe": {},
    "loops 100 m": {"sensing.kinds": ["loops"], "sensing.loop_spacing_m": 100},
    "loops 250 m": {"sensing.kinds": ["loops"], "sensing.loop_spacing_m": 250},
    "loops 500 m": {"sensing.kinds": ["loops"], "sensing.loop_spacing_m": 500},
    "boundary loops + AV probes": {"sensing.kinds": ["loops", "av_probes"]},
    "loops 250 m + AV probes": {"sensing.kinds": ["loops", "av_probes"],
                                "sensing.loop_spacing_m": 250},
}
METHODS = ("interpolation", "smoothing", "enkf")


def cache_path(scenario: Path, seed: int, warmup: float, horizon: float) -> Path:
    """Where the record of one run lives: a hash of the scenario text, seed, times and
    the package version."""
    from arzsumo import __version__

    text = json.dumps([scenario.read_text(encoding="utf-8"), seed, warmup, horizon,
                       __version__])
    key = hashlib.sha256(text.encode()).hexdigest()[:24]
    root = Path(os.environ.get("ARZSUMO_CACHE", Path.home() / ".cache" / "arzsumo"))
    return root / "estimation-runs" / f"{scenario.stem}-seed{seed}-{key}.npz"


def record(job: tuple[str, int, float, float]) -> str:
    """The cached record of one seed (made by one SUMO run if missing); its path."""
    from arzsumo.bridge.sensor_record import record_run
    from arzsumo.scenario import load_scenario

    scenario, seed, warmup, horizon = job
    path = cache_path(Path(scenario), seed, warmup, horizon)
    if not path.exists():
        rec, info = record_run(load_scenario(Path(scenario)), seed, warmup, horizon)
        rec.save(path, info)
        print(f"seed {seed}: recorded in {info['wall_time_s']:.0f} s", flush=True)
    return str(path)


def offline(rec: Any, sc: Any, layout: str, method: str,
            extra: dict[str, Any] | None = None) -> dict[str, Any]:
    """The estimation scores of one layout and method on a record (``extra``: more
    scenario keys, e.g. EnKF settings)."""
    from arzsumo.bridge.sensor_record import estimation_scores, replay_estimation

    if not LAYOUTS[layout]:
        return {v: {"relative": 0.0} for v in VARS} | {"spread": None}
    real = "none" if method == "interpolation" else method
    s = sc.with_({**LAYOUTS[layout], "estimation.method": real, **(extra or {})})
    scores = estimation_scores(rec.truth(), replay_estimation(rec, s), s.equilibrium)
    if method == "interpolation":
        return scores["interpolation"] | {"spread": None}
    return scores


def rows_of(path: str, scenario: str, seed: int) -> list[dict[str, Any]]:
    """Every layout x method on one record."""
    from arzsumo.bridge.sensor_record import SensorRecord
    from arzsumo.scenario import load_scenario

    rec, _ = SensorRecord.load(Path(path))
    sc = load_scenario(Path(scenario))
    out = []
    for layout in LAYOUTS:
        for method in METHODS if LAYOUTS[layout] else ("none",):
            t0 = time.perf_counter()
            s = offline(rec, sc, layout, method)
            row: dict[str, Any] = {"layout": layout, "method": method, "seed": seed}
            for v in VARS:
                row[f"{v}_rel"] = s[v]["relative"]
                row[f"{v}_spread_rel"] = (s["spread"][v]["relative"] if s["spread"]
                                          else np.nan)
            row["offline_s"] = time.perf_counter() - t0
            out.append(row)
    return out


def mean_ci(x: np.ndarray) -> str:
    """'mean +- 95 % t half-width' of the finite values."""
    x = x[np.isfinite(x)]
    half = (stats.t.ppf(0.975, x.size - 1) * x.std(ddof=1) / np.sqrt(x.size)
            if x.size > 1 else np.nan)
    return f"{x.mean():.3f} +- {half:.3f}"


def table(rows: list[dict[str, Any]]) -> str:
    """Means over seeds with 95 % t half-widths, per layout and method."""
    out = ["| layout | method | " + " | ".join(VARS) + " |", "|---|---|" + "---|" * len(VARS)]
    for layout in LAYOUTS:
        for method in ("none", *METHODS):
            sel = [r for r in rows if r["layout"] == layout and r["method"] == method]
            if sel:
                cells = [mean_ci(np.array([r[f"{v}_rel"] for r in sel], float))
                         for v in VARS]
                out.append(f"| {layout} | {method} | " + " | ".join(cells) + " |")
    return "\n".join(out)


def main(argv: list[str] | None = None) -> int:
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--scenario", type=Path, default=SCENARIO)
    p.add_argument("--seeds", type=int, nargs="+", default=[1, 2, 3, 4, 5])
    p.add_argument("--warmup", type=float, default=None, help="default: the scenario's")
    p.add_argument("--horizon", type=float, default=None, help="default: the scenario's")
    p.add_argument("--workers", type=int, default=2, help="SUMO runs at once")
    p.add_argument("--out", default="estimation_layouts.csv")
    args = p.parse_args(argv)
    from arzsumo.scenario import load_scenario

    sc = load_scenario(args.scenario)
    warmup = args.warmup if args.warmup is not None else sc.run.warmup
    horizon = args.horizon if args.horizon is not None else sc.sumo.horizon
    jobs = [(str(args.scenario), s, warmup, horizon) for s in args.seeds]
    with ProcessPoolExecutor(args.workers, mp_context=mp.get_context("spawn")) as pool:
        paths = list(pool.map(record, jobs))
        parts = pool.map(rows_of, paths, [str(args.scenario)] * len(paths), args.seeds)
        rows = [r for part in parts for r in part]
    with open(args.out, "w", newline="") as f:
        w = csv.DictWriter(f, list(rows[0]))
        w.writeheader()
        w.writerows(rows)
    print(f"relative RMSE of the estimate (1 = the equilibrium value), mean over seeds "
          f"{args.seeds}, {warmup:g} s warm-up + {horizon:g} s, open loop, "
          f"{args.scenario.name}")
    print(table(rows))
    return 0


if __name__ == "__main__":
    sys.exit(main())
