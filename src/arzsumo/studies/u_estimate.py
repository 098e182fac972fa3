"""The control law's U on raw cells beside U on an estimate, same seed
(``arzsumo study u-estimate``).

Backstepping on ``legacy_default.toml`` (seed 42, 150 s warm-up + 120 s by default), once
on the full probe's raw 50 m x 1 s cells (``[estimation] method = "none"``) and once per
estimator on loops every 250 m plus AV probes: a sweep built in code (axis ``estimator``)
run by :func:`arzsumo.sweep.driver.run_sweep` into ``OUT/sweep``. The table gives per run
the plan changes, the range of U and its median step per period (veh/h); the figure U
over time.
"""

from __future__ import annotations

import argparse
from pathlib import Path

import numpy as np
import pandas as pd

from arzsumo.outdir import resumable_dir
from arzsumo.outputs.studies import (
    markdown_table,
    publish,
    remove_stale_figures,
    write_csv,
)
from arzsumo.studies.common import (
    EXIT_SOME_FAILED,
    add_output,
    add_runs,
    plots_wanted,
    positive_float,
    print_list,
    shipped_scenario,
    study_spec,
)
from arzsumo.sweep.spec import SweepSpec
from arzsumo.sweep.table import run_dir
from arzsumo.sweep.worker import FINISHED
from arzsumo.units import veh_s_to_veh_h

NAME = "u-estimate"
#: the results page this study keeps a block of
PAGE = "u_on_estimate"
SENSORS = {"sensing.kinds": ["loops", "av_probes"], "sensing.loop_spacing_m": 250}
#: estimator -> (scenario keys, label)
ESTIMATORS = {
    "none": ({"estimation.method": "none"}, "raw cells (full probe)"),
    "smoothing": ({"estimation.method": "smoothing", **SENSORS},
                  "ASM on loops 250 m + AV probes"),
    "enkf": ({"estimation.method": "enkf", **SENSORS}, "EnKF on loops 250 m + AV probes"),
}


def design(seeds: list[int], warmup: float = 150.0, horizon: float = 120.0,
           controller: str = "backstepping") -> SweepSpec:
    """The sweep: estimator x seed on ``legacy_default.toml``."""
    return study_spec(NAME, shipped_scenario("legacy_default.toml"), seeds=list(seeds),
                      set={"run.controller": controller, "run.warmup_s": warmup,
                           "sumo.horizon_s": horizon},
                      axis=[{"name": "estimator", "values": list(ESTIMATORS),
                             "set": [keys for keys, _ in ESTIMATORS.values()]}])


def series(spec: SweepSpec, out: Path) -> pd.DataFrame:
    """U (veh/h) per control check of every finished run: estimator, seed, t_s, u_veh_h."""
    parts = []
    for run in spec.runs():
        path = run_dir(out, run) / "periods.parquet"
        if path.is_file():
            p = pd.read_parquet(path, columns=["t_s", "u_continuous"])
            parts.append(pd.DataFrame({"estimator": run.columns["estimator"],
                                       "seed": run.columns["seed"], "t_s": p["t_s"],
                                       "u_veh_h": veh_s_to_veh_h(p["u_continuous"])}))
    return pd.concat(parts, ignore_index=True) if parts else pd.DataFrame(
        columns=["estimator", "seed", "t_s", "u_veh_h"])


def statistics(u: pd.DataFrame, runs: pd.DataFrame) -> pd.DataFrame:
    """Per run: plan changes, U range and median |dU| per period (veh/h)."""
    rows = []
    for (est, seed), g in u.groupby(["estimator", "seed"], sort=False):
        steps = np.abs(np.diff(g["u_veh_h"].to_numpy(float)))
        plan = runs[(runs["estimator"] == est) & (runs["seed"] == seed)]["plan_changes"]
        rows.append({"estimator": est, "seed": seed,
                     "plan_changes": int(plan.iloc[0]) if len(plan) else np.nan,
                     "u_min_veh_h": g["u_veh_h"].min(), "u_max_veh_h": g["u_veh_h"].max(),
                     "median_step_veh_h": float(np.nanmedian(steps)) if steps.size else np.nan})
    return pd.DataFrame(rows)


def add_arguments(parser: argparse.ArgumentParser) -> None:
    """The study's options."""
    add_runs(parser, seeds="42")
    parser.add_argument("--warmup", type=positive_float, default=150.0, help="s")
    parser.add_argument("--horizon", type=positive_float, default=120.0,
                        help="control horizon, s")
    parser.add_argument("--controller", default="backstepping",
                        help="the law (a controller with a continuous U)")
    add_output(parser, NAME, PAGE)


def run(args: argparse.Namespace) -> int:
    """Run the sweep (resumable), then write the table and the figure."""
    from arzsumo.sweep.driver import run_sweep

    spec = design(args.seeds, args.warmup, args.horizon, args.controller)
    if args.list:
        return print_list([r.run_id for r in spec.runs()])
    with resumable_dir(args.out, f"study-{NAME}") as out:
        rep = run_sweep(spec, out / "sweep", workers=args.workers, scheduler=args.scheduler,
                        progress=not args.quiet, plots=False)
        u = series(spec, rep.out)
        stats = statistics(u, rep.table)
        files = [write_csv(stats, out / "u_estimate.csv"), write_csv(u, out / "u_series.csv")]
        if plots_wanted(args):
            from arzsumo.outputs.study_figures import write_u_series

            lines = [(f"{ESTIMATORS[r.estimator][1]}, seed {r.seed}: {r.plan_changes} plan "
                      "changes", g["t_s"].to_numpy(), g["u_veh_h"].to_numpy())
                     for r, (_, g) in zip(stats.itertuples(),
                                          u.groupby(["estimator", "seed"], sort=False),
                                          strict=True)]
            files.append(write_u_series(lines, f"{args.controller} on legacy_default: the "
                                        "law on raw cells and on estimates", out / "u.png"))
        else:
            remove_stale_figures(out / "u.png")
        text = markdown_table(stats, ".0f")
        if args.docs is not None:
            publish(args.docs, PAGE, NAME, "The control law on raw cells and on estimates",
                    f"`arzsumo study {NAME}`. Table: [{PAGE}.csv]({PAGE}/{PAGE}.csv)."
                    f"\n\n{text}" + (f"\n\n![U]({PAGE}/{PAGE}.png)" if plots_wanted(args)
                                     else ""),
                    [(p, f"{PAGE}{p.suffix}" if p.name != "u_series.csv" else
                      f"{PAGE}_series.csv") for p in files])
    print(text)
    ok = rep.table["status"].isin(FINISHED).all()
    return 0 if ok else EXIT_SOME_FAILED
