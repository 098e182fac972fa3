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

from dataclasses import dataclass
from pathlib import Path

import numpy as np
import pandas as pd

from arzsumo.outdir import resumable_dir
from arzsumo.outputs.figures import remove_stale_figures
from arzsumo.sweep.spec import SweepSpec
from arzsumo.sweep.table import run_dir
from arzsumo.sweep.worker import FINISHED
from arzsumo.units import veh_s_to_veh_h
from arzsumo_studies import checks
from arzsumo_studies.common import (
    EXIT_SOME_FAILED,
    RESULTS_DIR,
    shipped_scenario,
    study_spec,
)
from arzsumo_studies.outputs.pages import markdown_table, publish, write_csv

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


@dataclass(frozen=True)
class UEstimateOptions(checks.Shared):
    """What the study runs and where it writes (SI: s).

    Parameters
    ----------
    seeds : tuple of int
        SUMO seeds, one run per estimator each.
    warmup_s : float
        Warm-up before the law acts, s.
    horizon_s : float
        Control horizon, s.
    controller : str
        The law (a controller with a continuous U).
    plots : bool
        Draw the figure of U over time.

    ``out``, ``docs``, ``workers``, ``scheduler``: as every study's
    (:data:`~arzsumo_studies.common.SHARED_FIELDS`).
    """

    seeds: tuple[int, ...] = (42,)
    warmup_s: float = 150.0
    horizon_s: float = 120.0
    controller: str = "backstepping"
    out: Path = RESULTS_DIR / NAME
    plots: bool = True

    def __post_init__(self) -> None:
        super().__post_init__()
        checks.seeds(self.seeds)
        checks.positive(self.warmup_s, "warmup_s")
        checks.positive(self.horizon_s, "horizon_s")


@dataclass(frozen=True)
class UEstimateResult:
    """The study's outcome: the exit ``code`` (0; 4 when a run did not finish), the
    ``finished`` runs of ``runs``, the per-run ``table`` (plan changes, U's range and
    median step, veh/h), the ``series`` of U (veh/h), the markdown ``text`` and the
    ``files`` written."""

    code: int
    finished: int
    runs: int
    table: pd.DataFrame
    series: pd.DataFrame
    text: str
    files: tuple[Path, ...]


def design(opts: UEstimateOptions) -> SweepSpec:
    """The sweep: estimator x seed on ``legacy_default.toml``."""
    return study_spec(NAME, shipped_scenario("legacy_default.toml"), seeds=list(opts.seeds),
                      set={"run.controller": opts.controller, "run.warmup_s": opts.warmup_s,
                           "sumo.horizon_s": opts.horizon_s},
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


def run_u_estimate(opts: UEstimateOptions, *, progress: bool = True) -> UEstimateResult:
    """Run the sweep (resumable), then write the table and the figure.

    ``opts``: the study's :class:`UEstimateOptions`; ``progress``: draw a progress bar.

    Returns
    -------
    UEstimateResult
        The exit code (0, or 4 when a run did not finish), the tables and the files
        written (``u_estimate.csv``, ``u_series.csv``, ``u.png`` in ``opts.out``).
    """
    from arzsumo.sweep.driver import run_sweep

    spec = design(opts)
    with resumable_dir(opts.out, f"study-{NAME}") as out:
        rep = run_sweep(spec, out / "sweep", workers=opts.workers, scheduler=opts.scheduler,
                        progress=progress, plots=False)
        u = series(spec, rep.out)
        stats = statistics(u, rep.table)
        files = [write_csv(stats, out / "u_estimate.csv"), write_csv(u, out / "u_series.csv")]
        if opts.plots:
            files.append(_figure(opts.controller, stats, u, out / "u.png"))
        else:
            remove_stale_figures(out / "u.png")
        text = markdown_table(stats, ".0f")
        if opts.docs is not None:
            publish(opts.docs, PAGE, NAME, "The control law on raw cells and on estimates",
                    f"`arzsumo study {NAME}`. Table: [{PAGE}.csv]({PAGE}/{PAGE}.csv)."
                    f"\n\n{text}" + (f"\n\n![U]({PAGE}/{PAGE}.png)" if opts.plots
                                     else ""),
                    [(p, f"{PAGE}{p.suffix}" if p.name != "u_series.csv" else
                      f"{PAGE}_series.csv") for p in files])
    finished = int(rep.table["status"].isin(FINISHED).sum())
    code = 0 if finished == len(rep.table) else EXIT_SOME_FAILED
    return UEstimateResult(code, finished, len(rep.table), stats, u, text, tuple(files))


def _figure(controller: str, stats: pd.DataFrame, u: pd.DataFrame, path: Path) -> Path:
    """U over time, one line per run, labelled with its plan changes."""
    from arzsumo_studies.outputs.study_figures import write_u_series

    lines = [(f"{ESTIMATORS[r.estimator][1]}, seed {r.seed}: {r.plan_changes} plan "
              "changes", g["t_s"].to_numpy(), g["u_veh_h"].to_numpy())
             for r, (_, g) in zip(stats.itertuples(),
                                  u.groupby(["estimator", "seed"], sort=False),
                                  strict=True)]
    return write_u_series(lines, f"{controller} on legacy_default: the "
                          "law on raw cells and on estimates", path)
