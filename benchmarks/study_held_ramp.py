"""Issue 17: is the `meter` step's gain feedback, or a ramp held at its least release rate?

In the ablation's `meter` step (one vehicle per green, on the default's controller side)
the PDE laws lower the network time loss, and they spend much of the window at the upper
bound of U, where the meter releases at ``release_rate_min``. This script runs the open
loop of the same scenario with the nominal release rate set to that bound (a fixed,
restrictive meter: no feedback, held from t = 0, the warm-up included) on the same seeds,
and pairs every run set of the `meter` step (its open loop and both laws) against it.
Because the held meter also holds during the warm-up, this compares two policies over the
same window; it does not separate feedback from holding within the window.

    python benchmarks/study_held_ramp.py --out ABLATION_DIR --seeds 10 --workers 2
    python benchmarks/study_held_ramp.py --out ABLATION_DIR --report   # only the table

``ABLATION_DIR`` holds the `meter` step (``benchmarks/study_ablation.py --steps meter``);
the held-ramp open loop goes to ``ABLATION_DIR/held``.
"""

from __future__ import annotations

import argparse
import subprocess
import sys
from pathlib import Path

import numpy as np
import pandas as pd

sys.path.insert(0, str(Path(__file__).resolve().parent))
import study_ablation

from arzsumo.evaluation.report import Measure, per_seed
from arzsumo.evaluation.stats import StatisticsError, paired_difference
from arzsumo.io import dump_toml

#: summary key (dotted) -> label, unit scale
MEASURES = {"network.time_loss_s.total": ("network time loss (veh h)", 1 / 3600),
            "network.time_loss_s.mainline": ("mainline time loss (veh h)", 1 / 3600),
            "network.time_loss_s.ramp": ("ramp time loss (veh h)", 1 / 3600),
            "network.throughput_veh_h.section_outlet": ("section outflow (veh/h)", 1.0),
            "section.speed_sd_kmh.h": ("HV speed sd (km/h)", 1.0),
            "section.speed_sd_kmh.a": ("AV speed sd (km/h)", 1.0),
            "max_ramp_queue": ("max ramp queue (veh)", 1.0)}


def held_scenario() -> dict:
    """The `meter` step's scenario with the nominal release rate at its lower bound."""
    data, _ = study_ablation.step_scenario("meter")
    low = data["sumo"].get("release_rate_min_veh_h", 240.0)
    data["sumo"]["release_rate_veh_h"] = low
    data["name"] = "ablation-held-ramp"
    return data


def run_held(out: Path, seeds: int, workers: int) -> int:
    path = out / "steps" / "held.toml"
    path.parent.mkdir(parents=True, exist_ok=True)
    path.write_text(dump_toml(held_scenario()), encoding="utf-8")
    cmd = [str(study_ablation.ARZSUMO), "evaluate", str(path), "--controllers", "open",
           "--seeds", str(seeds), "--workers", str(workers), "--quiet", "--out",
           str(out / "held")]
    print("+", " ".join(cmd), flush=True)
    return subprocess.call(cmd)


def per_seed_values(runs: pd.DataFrame, controller: str, key: str, scale: float,
                    seeds: int) -> np.ndarray:
    """Seeds 1..seeds of ``controller``'s measure ``key`` times ``scale`` from an
    evaluation's sweep table (``summaries.parquet``; NaN where a run is missing)."""
    wide = per_seed(runs, Measure(key, key, "", scale), [controller])
    return wide[controller].reindex(range(1, seeds + 1)).to_numpy(float)


def report(out: Path, seeds: int) -> str:
    """Markdown: per measure, each run set minus the held-ramp open loop, paired by seed
    (mean [95 % t], and in brackets the seeds lower / higher than the held ramp)."""
    meter, held = (pd.read_parquet(out / d / "summaries.parquet") for d in ("meter", "held"))
    sets = [("open loop, nominal rate", meter, "open"), ("backstepping", meter, "backstepping"),
            ("ETC", meter, "etc")]
    lines = ["| measure | held ramp (mean) | " + " | ".join(f"{n} minus held" for n, _, _ in sets)
             + " |", "|---" * (2 + len(sets)) + "|"]
    for key, (label, scale) in MEASURES.items():
        base = per_seed_values(held, "open", key, scale, seeds)
        cells = []
        for _, runs, ctrl in sets:
            try:
                d = paired_difference(per_seed_values(runs, ctrl, key, scale, seeds), base)
                cells.append(f"{d.mean_diff:+.3g} [{d.t.low:+.3g}, {d.t.high:+.3g}] "
                             f"({d.wins}/{d.losses})")
            except StatisticsError:
                cells.append("")
        lines.append(f"| {label} | {np.nanmean(base):.4g} | " + " | ".join(cells) + " |")
    return "\n".join(lines)


def main() -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--out", type=Path, required=True, help="the ablation directory")
    ap.add_argument("--seeds", type=int, default=10)
    ap.add_argument("--workers", type=int, default=2)
    ap.add_argument("--report", action="store_true", help="only the table")
    args = ap.parse_args()
    if not args.report and run_held(args.out, args.seeds, args.workers) not in (0, 4):
        return 1
    print(report(args.out, args.seeds))
    return 0


if __name__ == "__main__":
    sys.exit(main())
