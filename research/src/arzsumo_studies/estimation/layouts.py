"""Estimation error against sensor layout, per estimator, over seeds
(``arzsumo study estimation-layouts``).

Per seed ONE open-loop SUMO run of the scenario (default: the former default lateral_files, its fill
as warm-up + its control horizon) records the sensor data of a superset of sensors (loop
stations every 50 m with both boundaries, every AV a probe) and the truth (the full
probe's cells): :func:`arzsumo_studies.estimation.sensor_record.record_run`, cached as ``.npz`` in
``$ARZSUMO_CACHE/estimation-runs`` (:func:`record`). Every layout x estimator is then an
offline pass over the recorded observations
(:func:`~arzsumo_studies.estimation.sensor_record.replay_estimation`), with the numbers
the estimator gives inside the closed loop. ``interpolation`` is linear interpolation between the
layout's loop stations (speeds filled with Ve), the baseline; with the full probe the
controller acts on the truth itself (RMSE 0). The table gives the relative RMSE (1 = the
equilibrium value) per variable, one row per layout, method and seed; the page its means
over seeds with 95 % t half-widths. The records are shared with ``loop-speed`` and
``enkf-noise``.
"""

from __future__ import annotations

import hashlib
import json
import os
import time
from collections.abc import Mapping
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np
import pandas as pd
from scipy import stats

from arzsumo.outdir import resumable_dir
from arzsumo.sweep.driver import default_workers
from arzsumo_studies import checks
from arzsumo_studies.common import (
    FORMER_DEFAULT,
    RESULTS_DIR,
    file_stem,
    seed_text,
    shipped_scenario,
    study_spec,
)
from arzsumo_studies.design import StudyRun, design_runs
from arzsumo_studies.outputs.pages import publish, write_csv

NAME = "estimation-layouts"
#: the results page this study keeps a block of
PAGE = "estimation_layouts"
VARS = ("rho_h", "v_h", "rho_a", "v_a")
#: layout name -> [sensing] keys ({}: the full probe)
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


def design(scenario: Path, seeds: list[int], warmup: float | None = None,
           horizon: float | None = None) -> list[StudyRun]:
    """One recorded open-loop run per seed (``warmup``, ``horizon`` s: instead of the
    scenario's)."""
    fixed: dict[str, Any] = {"run.controller": "open"}
    if warmup is not None:
        fixed["run.warmup_s"] = warmup
    if horizon is not None:
        fixed["sumo.horizon_s"] = horizon
    return design_runs(study_spec(NAME, scenario, seeds=list(seeds), set=fixed))


def cache_path(run: StudyRun) -> Path:
    """Where the record of ``run`` lives: a hash of its scenario and the package
    version, under ``$ARZSUMO_CACHE/estimation-runs``."""
    from arzsumo.version import __version__

    text = json.dumps([run.scenario, __version__], sort_keys=True, default=str)
    key = hashlib.sha256(text.encode()).hexdigest()[:24]
    root = Path(os.environ.get("ARZSUMO_CACHE", Path.home() / ".cache" / "arzsumo"))
    stem = file_stem(run.scenario.get("name", "run"))
    return root / "estimation-runs" / f"{stem}-{run.run_id}-{key}.npz"


def record(run: StudyRun) -> dict[str, Any]:
    """The cached record of ``run`` (one SUMO run if missing): ``{"path": ...}``."""
    from arzsumo.scenario import scenario_from_dict
    from arzsumo_studies.estimation.sensor_record import record_run

    path = cache_path(run)
    if not path.exists():
        sc = scenario_from_dict(run.scenario, run.source)
        rec, info = record_run(sc, sc.sumo.seed, sc.run.warmup, sc.sumo.horizon)
        rec.save(path, info)
    return {"path": str(path)}


def offline(rec: Any, sc: Any, layout: str, method: str,
            extra: Mapping[str, Any] | None = None) -> dict[str, Any]:
    """The estimation scores of one layout and method on a record (``extra``: more
    scenario keys, e.g. EnKF settings)."""
    from arzsumo.bridge.estimators import estimation_scores
    from arzsumo_studies.estimation.sensor_record import replay_estimation

    if not LAYOUTS[layout]:
        return {v: {"relative": 0.0} for v in VARS} | {"spread": None}
    real = "none" if method == "interpolation" else method
    s = sc.with_({**LAYOUTS[layout], "estimation.method": real, **(extra or {})})
    scores = estimation_scores(rec.truth(), replay_estimation(rec, s), s.equilibrium)
    if method == "interpolation":
        return scores["interpolation"] | {"spread": None}
    return scores


def rows_of(task: tuple[str, Mapping[str, Any], int]) -> list[dict[str, Any]]:
    """(record path, scenario tables, seed) -> every layout x method on that record."""
    from arzsumo.scenario import scenario_from_dict
    from arzsumo_studies.estimation.sensor_record import SensorRecord

    path, tables, seed = task
    rec, _ = SensorRecord.load(Path(path))
    sc = scenario_from_dict(tables)
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
                cells = [mean_ci(np.array([r[f"{v}_rel"] for r in sel], float)) for v in VARS]
                out.append(f"| {layout} | {method} | " + " | ".join(cells) + " |")
    return "\n".join(out)


@dataclass(frozen=True)
class LayoutsOptions(checks.Shared):
    """What the layout study records and scores, and where it writes (SI: s).

    Parameters
    ----------
    scenario : Path, optional
        The scenario recorded (None: the former default, lateral_files).
    seeds : tuple of int
        SUMO seeds, one recorded open-loop run each.
    warmup_s, horizon_s : float, optional
        Warm-up and control horizon, s (None: the scenario's).

    ``out``, ``docs``, ``workers``, ``scheduler``: as every study's
    (:data:`~arzsumo_studies.common.SHARED_FIELDS`).
    """

    scenario: Path | None = None
    seeds: tuple[int, ...] = (1, 2, 3, 4, 5)
    warmup_s: float | None = None
    horizon_s: float | None = None
    out: Path = RESULTS_DIR / NAME

    def __post_init__(self) -> None:
        super().__post_init__()
        checks.seeds(self.seeds)
        checks.positive(self.warmup_s, "warmup_s", optional=True)
        checks.positive(self.horizon_s, "horizon_s", optional=True)


@dataclass(frozen=True)
class LayoutsResult:
    """The study's outcome: the ``table`` (one row per layout, method and seed: relative
    RMSE per variable), the markdown ``text`` of its means over seeds and the ``files``
    written."""

    table: pd.DataFrame
    text: str
    files: tuple[Path, ...]


def study_runs(opts: LayoutsOptions) -> list[StudyRun]:
    """The recorded open-loop runs of the study, one per seed."""
    return design(opts.scenario or shipped_scenario(FORMER_DEFAULT), list(opts.seeds),
                  opts.warmup_s, opts.horizon_s)


def record_paths(runs: list[StudyRun], *, workers: int | None = None,
                 scheduler: str | None = None, progress: bool = True) -> list[str]:
    """The record paths of ``runs``, recording the missing ones on the sweep engine.

    Parameters
    ----------
    runs : list of StudyRun
        The recorded open-loop runs (:func:`design`).
    workers : int, optional
        Local processes (default: one per core); ignored with ``scheduler``.
    scheduler : str, optional
        A Dask scheduler's address to run on instead.
    progress : bool, optional
        Show a progress bar while recording.

    Returns
    -------
    list of str
        The ``.npz`` record of each run, in ``runs``' order.
    """
    from arzsumo.sweep.driver import map_runs

    done = map_runs(record, runs, workers=workers or default_workers(),
                    scheduler=scheduler,
                    progress=f"{NAME}: recording" if progress else None)
    return [d["path"] for d in done]


def run_layouts(opts: LayoutsOptions, *, progress: bool = True) -> LayoutsResult:
    """Record the missing seeds, score every layout and method, write the table.

    Parameters
    ----------
    opts : LayoutsOptions
        The study's options.
    progress : bool, optional
        Show progress bars while recording and scoring.

    Returns
    -------
    LayoutsResult
        The table, its means and the file written (``layouts.csv`` in ``opts.out``).
    """
    from arzsumo.sweep.driver import map_runs

    runs = study_runs(opts)
    with resumable_dir(opts.out, f"study-{NAME}") as out:
        paths = record_paths(runs, workers=opts.workers, scheduler=opts.scheduler,
                             progress=progress)
        tasks = [(p, r.scenario, r.scenario["sumo"]["seed"]) for p, r in zip(paths, runs,
                                                                             strict=True)]
        parts = map_runs(rows_of, tasks, workers=opts.workers or default_workers(),
                         scheduler=opts.scheduler,
                         progress=f"{NAME}: scoring" if progress else None)
        rows = [row for part in parts for row in part]
        df = pd.DataFrame(rows)
        path = write_csv(df, out / "layouts.csv")
        text = table(rows)
        if opts.docs is not None:
            csv = f"{PAGE}_{file_stem(runs[0].scenario.get('name', 'scenario'))}.csv"
            publish(opts.docs, PAGE, NAME, "Estimation error against sensor layout",
                    f"Relative RMSE of the estimate (1 = the equilibrium value), mean over "
                    f"seeds {seed_text(list(opts.seeds))} +- 95 % t half-width, open loop "
                    f"(`arzsumo study {NAME}`). Table: [{csv}]({PAGE}/{csv}).\n\n{text}",
                    [(path, csv)])
    return LayoutsResult(df, text, (path,))
