"""The ASM estimate's offset with time-mean against harmonic loop speeds
(``arzsumo study loop-speed``).

ONE open-loop SUMO run of the scenario (default: the former default lateral_files, its fill as
warm-up + ``--horizon`` s) records the superset of sensors and the truth, cached like the
records of :mod:`arzsumo_studies.estimation.layouts`. The record holds both loop speeds,
so each ``[sensing] loop_speed`` is an offline pass of the same estimator over the same
traffic (loops every 250 m + AV probes, ``--method``). Per variable (rho_h, v_h, rho_a,
v_a; veh/km and km/h over the control periods and cells): the mean of the truth, the mean
offset of the estimate from the truth (cells where both are finite), the mean offset of
the estimate from the scenario's equilibrium, and the RMSE relative to the equilibrium;
and per class the loops' mean speeds against the truth's cell speeds at the stations.
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np
import pandas as pd

from arzsumo.outdir import resumable_dir
from arzsumo.units import KMH_PER_MS, VEH_KM_PER_VEH_M, ms_to_kmh
from arzsumo_studies import checks
from arzsumo_studies.common import FORMER_DEFAULT, RESULTS_DIR, shipped_scenario
from arzsumo_studies.design import StudyRun
from arzsumo_studies.estimation import layouts as estimation_layouts
from arzsumo_studies.outputs.pages import markdown_table, publish, write_csv, write_text

NAME = "loop-speed"
#: the results page this study keeps a block of
PAGE = "estimation_layouts"
VARS = estimation_layouts.VARS
#: SI -> report units: veh/m -> veh/km, m/s -> km/h
FACTOR = (VEH_KM_PER_VEH_M, KMH_PER_MS, VEH_KM_PER_VEH_M, KMH_PER_MS)
LAYOUT = estimation_layouts.LAYOUTS["loops 250 m + AV probes"]
LOOP_SPEEDS = ("time_mean", "harmonic")
#: the estimators replayed (``method``)
METHODS = ("smoothing", "enkf")


def offsets(rec: Any, sc: Any, loop_speed: str, method: str) -> list[dict[str, Any]]:
    """Per variable (report units): truth mean, estimate - truth, estimate - equilibrium,
    relative RMSE."""
    from arzsumo.bridge.estimators import estimation_scores
    from arzsumo_studies.estimation.sensor_record import replay_estimation

    s = sc.with_({**LAYOUT, "sensing.loop_speed": loop_speed, "estimation.method": method})
    est = replay_estimation(rec, s)
    truth = rec.truth()
    fields = np.asarray(est.fields[1:])
    scores = estimation_scores(truth, est, s.equilibrium)
    eq = s.equilibrium
    ref = (eq.rho_h, eq.v_h, eq.rho_a, eq.v_a)
    rows = []
    for k, name in enumerate(VARS):
        ok = np.isfinite(truth[:, k]) & np.isfinite(fields[:, k])
        f = FACTOR[k]
        rows.append({"loop_speed": loop_speed, "variable": name,
                     "truth_mean": f * truth[:, k][ok].mean(),
                     "estimate_minus_truth": f * (fields[:, k] - truth[:, k])[ok].mean(),
                     "estimate_minus_equilibrium": f * (fields[:, k][ok].mean() - ref[k]),
                     "rmse_relative": scores[name]["relative"]})
    return rows


def station_speeds(rec: Any) -> list[str]:
    """Per class: mean time-mean and harmonic loop speed over the control periods and
    the interior stations, and the truth's cell speed at those stations (km/h); each over
    the station-periods where all three are known."""
    k = slice(rec.start + 1, None)
    truth = rec.truth()
    cell = np.array([int(np.argmin(np.abs(rec.x - x))) for x in rec.loop_x])
    lines = []
    for c, name in enumerate(("h", "a")):
        tm, hm = rec.speed[k][:, c, 1:-1], rec.speed_harmonic[k][:, c, 1:-1]
        v = truth[:, 2 * c + 1][:, cell[1:-1]]
        # one set of station-periods for all three means, so they compare like with like
        ok = np.isfinite(tm) & np.isfinite(hm) & np.isfinite(v)
        tm_kmh, hm_kmh, v_kmh = (ms_to_kmh(a[ok].mean()) for a in (tm, hm, v))
        lines.append(f"v_{name} at the stations, km/h: time-mean {tm_kmh:.2f}, "
                     f"harmonic {hm_kmh:.2f}, probe cells {v_kmh:.2f}"
                     f" ({int(ok.sum())} station-periods)")
    return lines


@dataclass(frozen=True)
class LoopSpeedOptions(checks.Shared):
    """What the loop-speed study records and replays, and where it writes (SI: s).

    Parameters
    ----------
    scenario : Path, optional
        The scenario recorded (None: the former default, lateral_files).
    seeds : tuple of int
        SUMO seeds, one recorded open-loop run each.
    horizon_s : float
        Control horizon recorded, s.
    method : str
        The estimator replayed: ``smoothing`` or ``enkf``.

    ``out``, ``docs``, ``workers``, ``scheduler``: as every study's
    (:data:`~arzsumo_studies.common.SHARED_FIELDS`).
    """

    scenario: Path | None = None
    seeds: tuple[int, ...] = (1,)
    horizon_s: float = 300.0
    method: str = "smoothing"
    out: Path = RESULTS_DIR / NAME

    def __post_init__(self) -> None:
        super().__post_init__()
        checks.seeds(self.seeds)
        checks.positive(self.horizon_s, "horizon_s")
        checks.among(self.method, METHODS, "method")


@dataclass(frozen=True)
class LoopSpeedResult:
    """The study's outcome: ``table`` (one row per run, loop speed and variable, report
    units), the station ``notes`` (one line per run and class), the markdown ``text``
    printed and published, and the ``files`` written."""

    table: pd.DataFrame
    notes: tuple[str, ...]
    text: str
    files: tuple[Path, ...]


def design(opts: LoopSpeedOptions) -> list[StudyRun]:
    """The recorded open-loop runs, one per seed."""
    return estimation_layouts.design(opts.scenario or shipped_scenario(FORMER_DEFAULT),
                                     list(opts.seeds), horizon=opts.horizon_s)


def run_loop_speed(opts: LoopSpeedOptions, *, progress: bool = True) -> LoopSpeedResult:
    """Record (or reuse) the runs, replay both loop speeds, write the table.

    Parameters
    ----------
    opts : LoopSpeedOptions
        The study's options.
    progress : bool, optional
        Show a progress bar while recording.

    Returns
    -------
    LoopSpeedResult
        The table, the station notes and the files written (``loop_speed.csv``,
        ``loop_speed.md`` in ``opts.out``).
    """
    from arzsumo.scenario import scenario_from_dict
    from arzsumo_studies.estimation.sensor_record import SensorRecord

    runs = design(opts)
    rows, notes = [], []
    with resumable_dir(opts.out, f"study-{NAME}") as out:
        paths = estimation_layouts.record_paths(runs, workers=opts.workers,
                                                scheduler=opts.scheduler, progress=progress)
        for r, path in zip(runs, paths, strict=True):
            rec, _ = SensorRecord.load(Path(path))
            sc = scenario_from_dict(r.scenario, r.source)
            for speed in LOOP_SPEEDS:
                rows += [{"run": r.run_id, **row} for row in offsets(rec, sc, speed,
                                                                      opts.method)]
            notes += [f"{r.run_id}: {line}" for line in station_speeds(rec)]
        df = pd.DataFrame(rows)
        text = markdown_table(df, ".3f") + "\n\n" + "\n".join(f"- {n}" for n in notes)
        files = [write_csv(df, out / "loop_speed.csv"), write_text(text, out / "loop_speed.md")]
        if opts.docs is not None:
            publish(opts.docs, PAGE, NAME, "Estimation error against sensor layout",
                    f"Time-mean against harmonic loop speeds: loops every 250 m + AV probes, "
                    f"{opts.method}, open loop (`arzsumo study {NAME}`). Table: "
                    f"[loop_speed.csv]({PAGE}/loop_speed.csv).\n\n{text}", files)
    return LoopSpeedResult(df, tuple(notes), text, tuple(Path(f) for f in files))
