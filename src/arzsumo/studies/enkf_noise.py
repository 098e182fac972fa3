"""The EnKF's model-error noise and inflation, chosen offline on SUMO records
(``arzsumo study enkf-noise``).

On SUMO data the EnKF with a perfect-model ensemble is over-confident (spread about a
tenth of its error). This study chooses the additive model-error noise per forecast
(``[estimation] model_sd_*``) on the records of ``--tune-seeds`` (the open-loop records
of :mod:`arzsumo.studies.estimation_layouts`, made when missing) for one layout
(``--layout``), then reports on ``--report-seeds`` the normalised error RMSE / mean
spread per variable (target near 1) and the RMSE, for every EnKF layout, without and
with the chosen noise (both at ``--inflation``).

Calibration: starting from ``--start``, each round runs the filter offline on the tuning
seeds and scales each variable's sd by its normalised error (pooled over seeds, clipped
to [1/4, 4]) to the power ``--gain``; ``--rounds`` rounds, the result rounded to two
significant digits. Inflation-only settings (no model noise) are reported beside it.
"""

from __future__ import annotations

import argparse
from collections.abc import Sequence
from pathlib import Path
from typing import Any

import numpy as np
import pandas as pd

from arzsumo.outdir import resumable_dir
from arzsumo.outputs.studies import publish, write_csv, write_text
from arzsumo.studies import estimation_layouts as layouts
from arzsumo.studies.common import (
    FORMER_DEFAULT,
    StudyError,
    add_output,
    file_stem,
    non_negative_int,
    number_list,
    positive_float,
    positive_int,
    seed_list,
    shipped_scenario,
)
from arzsumo.sweep.driver import default_workers, map_runs

NAME = "enkf-noise"
#: the results page this study keeps a block of
PAGE = "enkf_noise"
VARS = layouts.VARS
#: scenario keys of the model-error sd, in VARS order (user units: veh/km, km/h)
KEYS = ("estimation.model_sd_rho_h_veh_km", "estimation.model_sd_v_h_kmh",
        "estimation.model_sd_rho_a_veh_km", "estimation.model_sd_v_a_kmh")
#: a job: (record path, scenario tables, seed, layout, extra scenario keys)
Job = tuple[str, dict[str, Any], int, str, dict[str, Any]]


def settings(sd: Sequence[float], inflation: float, length: float = 150.0) -> dict[str, Any]:
    """Scenario keys of one setting (sd in veh/km and km/h, correlation length m)."""
    return {**{k: float(v) for k, v in zip(KEYS, sd, strict=True)},
            "estimation.inflation": float(inflation), "estimation.model_length_m": length}


def score(job: Job) -> dict[str, Any]:
    """RMSE and mean spread (relative) per variable of one record, layout and setting."""
    from arzsumo.bridge.sensor_record import SensorRecord
    from arzsumo.scenario import scenario_from_dict

    path, tables, seed, layout, extra = job
    rec, _ = SensorRecord.load(Path(path))
    s = layouts.offline(rec, scenario_from_dict(tables), layout, "enkf", extra)
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


def next_sd(sd: np.ndarray, rows: list[dict[str, Any]], gain: float) -> np.ndarray:
    """One calibration round: each sd scaled by its clipped normalised error ** gain."""
    return sd * np.clip(normalised(rows), 0.25, 4.0) ** gain


def fmt(rows: list[dict[str, Any]], label: str) -> str:
    """One table line: normalised error and mean RMSE per variable."""
    nerr = normalised(rows)
    rmse = [np.mean([r[f"{v}_rel"] for r in rows]) for v in VARS]
    return (f"| {label} | " + " | ".join(f"{n:.2f}" for n in nerr) + " | "
            + " | ".join(f"{e:.3f}" for e in rmse) + " |")


class Tuner:
    """Scores settings on the records of some seeds through the sweep engine."""

    def __init__(self, records: dict[int, tuple[str, dict[str, Any]]], workers: int) -> None:
        self.records, self.workers = records, workers

    def rows(self, seeds: Sequence[int], layout: str, extra: dict[str, Any]
             ) -> list[dict[str, Any]]:
        """The scores of ``layout`` with the keys ``extra`` on the records of ``seeds``."""
        jobs = [(*self.records[s], s, layout, extra) for s in seeds]
        return map_runs(score, jobs, workers=self.workers)


def tune(tuner: Tuner, args: argparse.Namespace) -> tuple[np.ndarray, list[str]]:
    """The inflation-only lines and the calibration rounds on the tuning seeds; the
    chosen sd (veh/km, km/h)."""
    lines = []
    for infl in args.inflation_only:
        rows = tuner.rows(args.tune_seeds, args.layout, settings(np.zeros(4), infl))
        lines.append(fmt(rows, f"tune: no model noise, inflation {infl:g}"))
    sd = np.array(args.start, float)
    for k in range(args.rounds):
        rows = tuner.rows(args.tune_seeds, args.layout,
                          settings(sd, args.inflation, args.length))
        lines.append(fmt(rows, f"tune round {k}: sd " + ", ".join(f"{v:.3g}" for v in sd)))
        sd = next_sd(sd, rows, args.gain)
    if args.rounds:
        sd = np.array([float(f"{v:.2g}") for v in sd])
    return sd, lines


def report(tuner: Tuner, sd: np.ndarray, args: argparse.Namespace
           ) -> tuple[list[dict[str, Any]], list[str]]:
    """Every EnKF layout on the report seeds, without and with the chosen noise, both at
    ``--inflation`` (so the lines differ by the noise alone)."""
    out, lines = [], []
    for lay in [name for name, keys in layouts.LAYOUTS.items() if keys]:
        for label, extra in (("perfect model", settings(np.zeros(4), args.inflation)),
                             ("model noise", settings(sd, args.inflation, args.length))):
            rows = tuner.rows(args.report_seeds, lay, extra)
            lines.append(fmt(rows, f"report {lay}: {label}"))
            out += [{**r, "setting": label} for r in rows]
    return out, lines


def add_arguments(parser: argparse.ArgumentParser) -> None:
    """The EnKF noise study's options."""
    parser.add_argument("--scenario", type=Path, metavar="SCENARIO.toml",
                        help="scenario recorded (default: the former default, lateral_files)")
    parser.add_argument("--tune-seeds", type=seed_list, default=[1, 2], metavar="LIST",
                        help="seeds the noise is tuned on (default: 1,2)")
    parser.add_argument("--report-seeds", type=seed_list, default=[3, 4, 5], metavar="LIST",
                        help="held-out seeds reported on (default: 3-5)")
    parser.add_argument("--warmup", type=positive_float, help="s (default: the scenario's)")
    parser.add_argument("--horizon", type=positive_float,
                        help="control horizon, s (default: the scenario's)")
    parser.add_argument("--layout", default="loops 250 m + AV probes",
                        choices=[k for k, v in layouts.LAYOUTS.items() if v],
                        help="the layout tuned on")
    parser.add_argument("--start", type=number_list, default=[2.0, 1.0, 1.0, 1.0],
                        help="starting sd: rho_h veh/km, v_h km/h, rho_a veh/km, v_a km/h "
                             "(default: 2,1,1,1)")
    parser.add_argument("--inflation", type=positive_float, default=1.05,
                        help="the EnKF's inflation in the tuning rounds and in both "
                             "report settings (perfect model, model noise)")
    parser.add_argument("--length", type=positive_float, default=150.0,
                        help="correlation length of the model noise, m")
    parser.add_argument("--rounds", type=non_negative_int, default=6,
                        help="calibration rounds (0: report --start as it is)")
    parser.add_argument("--inflation-only", type=number_list, default=[1.05, 1.3, 2.0],
                        help="inflations tried without model noise (default: 1.05,1.3,2)")
    parser.add_argument("--gain", type=positive_float, default=1.5)
    parser.add_argument("--workers", type=positive_int, metavar="N",
                        help="local processes (default: one per core)")
    parser.add_argument("--scheduler", metavar="ADDRESS", help="record on this Dask scheduler")
    parser.add_argument("--quiet", action="store_true", help="no progress bar")
    add_output(parser, NAME, PAGE, plots=False)


def run(args: argparse.Namespace) -> int:
    """Record the missing seeds, tune, report, write the table."""
    if len(args.start) != 4:
        raise StudyError(f"--start = {args.start} is not allowed: 4 sd (rho_h veh/km, v_h "
                         "km/h, rho_a veh/km, v_a km/h)")
    seeds = sorted(set(args.tune_seeds) | set(args.report_seeds))
    runs = layouts.design(args.scenario or shipped_scenario(FORMER_DEFAULT), seeds,
                          args.warmup, args.horizon)
    workers = args.workers or default_workers()
    with resumable_dir(args.out, f"study-{NAME}") as out:
        paths = layouts.recorded(runs, args)
        tuner = Tuner({s: (p, dict(r.scenario)) for s, p, r in zip(seeds, paths, runs,
                                                                     strict=True)}, workers)
        sd, lines = tune(tuner, args)
        rows, more = report(tuner, sd, args) if args.report_seeds else ([], [])
        head = ("| setting | " + " | ".join(f"RMSE/spread {v}" for v in VARS) + " | "
                + " | ".join(f"RMSE {v}" for v in VARS) + " |\n|---|" + "---|" * 8)
        chosen = (f"Chosen model-error sd per forecast: {', '.join(f'{v:g}' for v in sd)} "
                  f"(rho_h veh/km, v_h km/h, rho_a veh/km, v_a km/h), inflation "
                  f"{args.inflation:g}; tuned on seeds {args.tune_seeds}, {args.layout}; "
                  f"reported on seeds {args.report_seeds}.")
        text = f"{chosen}\n\n{head}\n" + "\n".join(lines + more)
        files: list = [write_text(text, out / "enkf_noise.md")]
        if rows:
            csv = f"{PAGE}_{file_stem(runs[0].scenario.get('name', 'scenario'))}.csv"
            files.append((write_csv(pd.DataFrame(rows), out / "enkf_noise.csv"), csv))
        if args.docs is not None:
            publish(args.docs, PAGE, NAME, "The EnKF's model-error noise",
                    f"`arzsumo study {NAME}`. {text}", files)
    print(text)
    return 0
