"""The EnKF's model-error noise and inflation, chosen offline on SUMO records
(``arzsumo study enkf-noise``).

On SUMO data the EnKF with a perfect-model ensemble is over-confident (spread about a
tenth of its error). This study chooses the additive model-error noise per forecast
(``[estimation] model_sd_*``) on the records of ``--tune-seeds`` (the open-loop records
of :mod:`arzsumo_studies.estimation.layouts`, made when missing) for one layout
(``--layout``), then reports on ``--report-seeds`` the normalised error RMSE / mean
spread per variable (target near 1) and the RMSE, for every EnKF layout, without and
with the chosen noise (both at ``--inflation``).

Calibration: starting from ``--start``, each round runs the filter offline on the tuning
seeds and scales each variable's sd by its normalised error (pooled over seeds, clipped
to [1/4, 4]) to the power ``--gain``; ``--rounds`` rounds, the result rounded to two
significant digits. Inflation-only settings (no model noise) are reported beside it.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np
import pandas as pd

from arzsumo.outdir import resumable_dir
from arzsumo.sweep.driver import default_workers, map_runs
from arzsumo_studies import checks
from arzsumo_studies.common import (
    FORMER_DEFAULT,
    RESULTS_DIR,
    StudyError,
    file_stem,
    shipped_scenario,
)
from arzsumo_studies.estimation import layouts
from arzsumo_studies.outputs.pages import publish, write_csv, write_text

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
    from arzsumo.scenario import scenario_from_dict
    from arzsumo_studies.estimation.sensor_record import SensorRecord

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


#: the layouts the EnKF is reported on (and may be tuned on): those with sensors
ENKF_LAYOUTS = tuple(name for name, keys in layouts.LAYOUTS.items() if keys)


@dataclass(frozen=True)
class EnkfNoiseOptions(checks.Shared):
    """What the study records, tunes and reports, and where it writes (SI: s, m; the sd
    in veh/km and km/h).

    Parameters
    ----------
    scenario : Path, optional
        The scenario recorded (None: the former default, lateral_files).
    tune_seeds : tuple of int
        Seeds the noise is tuned on.
    report_seeds : tuple of int
        Held-out seeds reported on (empty: no report).
    warmup_s, horizon_s : float, optional
        Warm-up and control horizon, s (None: the scenario's).
    layout : str
        The layout tuned on, one of :data:`ENKF_LAYOUTS`.
    start : tuple of float
        Starting sd: rho_h veh/km, v_h km/h, rho_a veh/km, v_a km/h.
    inflation : float
        The EnKF's inflation in the tuning rounds and in both report settings.
    length_m : float
        Correlation length of the model noise, m.
    rounds : int
        Calibration rounds (0: report ``start`` as it is).
    inflation_only : tuple of float
        Inflations tried without model noise.
    gain : float
        Each round scales the sd by its clipped normalised error to this power.
    workers : int, optional
        Local processes (None: one per core).
    scheduler : str, optional
        Record on this Dask scheduler.

    ``out``, ``docs``: as every study's
    (:data:`~arzsumo_studies.common.SHARED_FIELDS`).
    """

    scenario: Path | None = None
    tune_seeds: tuple[int, ...] = (1, 2)
    report_seeds: tuple[int, ...] = (3, 4, 5)
    warmup_s: float | None = None
    horizon_s: float | None = None
    layout: str = "loops 250 m + AV probes"
    start: tuple[float, ...] = (2.0, 1.0, 1.0, 1.0)
    inflation: float = 1.05
    length_m: float = 150.0
    rounds: int = 6
    inflation_only: tuple[float, ...] = (1.05, 1.3, 2.0)
    gain: float = 1.5
    out: Path = RESULTS_DIR / NAME

    def __post_init__(self) -> None:
        super().__post_init__()
        if len(self.start) != 4:
            raise StudyError(f"--start = {list(self.start)} is not allowed: 4 sd (rho_h "
                             "veh/km, v_h km/h, rho_a veh/km, v_a km/h)")
        checks.seeds(self.tune_seeds, "tune_seeds")
        checks.seeds(self.report_seeds, "report_seeds", empty=True)
        checks.positive(self.warmup_s, "warmup_s", optional=True)
        checks.positive(self.horizon_s, "horizon_s", optional=True)
        checks.among(self.layout, ENKF_LAYOUTS, "layout")
        for field in ("inflation", "length_m", "gain"):
            checks.positive(getattr(self, field), field)
        checks.count(self.rounds, "rounds", least=0)
        checks.numbers(self.inflation_only, "inflation_only")


@dataclass(frozen=True)
class EnkfNoiseResult:
    """The study's outcome: the chosen model-error ``sd`` (rho_h veh/km, v_h km/h, rho_a
    veh/km, v_a km/h), the report's ``rows`` (per layout, setting and seed), the
    markdown ``text`` and the ``files`` written."""

    sd: tuple[float, ...]
    rows: pd.DataFrame
    text: str
    files: tuple[Path, ...]


class Tuner:
    """Scores settings on the records of some seeds through the sweep engine."""

    def __init__(self, records: dict[int, tuple[str, dict[str, Any]]], workers: int) -> None:
        self.records, self.workers = records, workers

    def rows(self, seeds: Sequence[int], layout: str, extra: dict[str, Any]
             ) -> list[dict[str, Any]]:
        """The scores of ``layout`` with the keys ``extra`` on the records of ``seeds``."""
        jobs = [(*self.records[s], s, layout, extra) for s in seeds]
        return map_runs(score, jobs, workers=self.workers)


def tune(tuner: Tuner, opts: EnkfNoiseOptions) -> tuple[np.ndarray, list[str]]:
    """The inflation-only lines and the calibration rounds on the tuning seeds; the
    chosen sd (veh/km, km/h)."""
    lines = []
    for infl in opts.inflation_only:
        rows = tuner.rows(opts.tune_seeds, opts.layout, settings(np.zeros(4), infl))
        lines.append(fmt(rows, f"tune: no model noise, inflation {infl:g}"))
    sd = np.array(opts.start, float)
    for k in range(opts.rounds):
        rows = tuner.rows(opts.tune_seeds, opts.layout,
                          settings(sd, opts.inflation, opts.length_m))
        lines.append(fmt(rows, f"tune round {k}: sd " + ", ".join(f"{v:.3g}" for v in sd)))
        sd = next_sd(sd, rows, opts.gain)
    if opts.rounds:
        sd = np.array([float(f"{v:.2g}") for v in sd])
    return sd, lines


def report(tuner: Tuner, sd: np.ndarray, opts: EnkfNoiseOptions
           ) -> tuple[list[dict[str, Any]], list[str]]:
    """Every EnKF layout on the report seeds, without and with the chosen noise, both at
    ``opts.inflation`` (so the lines differ by the noise alone)."""
    out, lines = [], []
    for lay in ENKF_LAYOUTS:
        for label, extra in (("perfect model", settings(np.zeros(4), opts.inflation)),
                             ("model noise", settings(sd, opts.inflation, opts.length_m))):
            rows = tuner.rows(opts.report_seeds, lay, extra)
            lines.append(fmt(rows, f"report {lay}: {label}"))
            out += [{**r, "setting": label} for r in rows]
    return out, lines


def run_enkf_noise(opts: EnkfNoiseOptions, *, progress: bool = True) -> EnkfNoiseResult:
    """Record the missing seeds, tune, report, write the table.

    Parameters
    ----------
    opts : EnkfNoiseOptions
        The study's options.
    progress : bool, optional
        Show a progress bar while recording.

    Returns
    -------
    EnkfNoiseResult
        The chosen sd, the report's rows and the files written (``enkf_noise.md``, with
        report seeds ``enkf_noise.csv``, in ``opts.out``).
    """
    seeds = sorted(set(opts.tune_seeds) | set(opts.report_seeds))
    runs = layouts.design(opts.scenario or shipped_scenario(FORMER_DEFAULT), seeds,
                          opts.warmup_s, opts.horizon_s)
    workers = opts.workers or default_workers()
    with resumable_dir(opts.out, f"study-{NAME}") as out:
        paths = layouts.record_paths(runs, workers=opts.workers, scheduler=opts.scheduler,
                                     progress=progress)
        tuner = Tuner({s: (p, dict(r.scenario)) for s, p, r in zip(seeds, paths, runs,
                                                                     strict=True)}, workers)
        sd, lines = tune(tuner, opts)
        rows, more = report(tuner, sd, opts) if opts.report_seeds else ([], [])
        head = ("| setting | " + " | ".join(f"RMSE/spread {v}" for v in VARS) + " | "
                + " | ".join(f"RMSE {v}" for v in VARS) + " |\n|---|" + "---|" * 8)
        chosen = (f"Chosen model-error sd per forecast: {', '.join(f'{v:g}' for v in sd)} "
                  f"(rho_h veh/km, v_h km/h, rho_a veh/km, v_a km/h), inflation "
                  f"{opts.inflation:g}; tuned on seeds {list(opts.tune_seeds)}, "
                  f"{opts.layout}; reported on seeds {list(opts.report_seeds)}.")
        text = f"{chosen}\n\n{head}\n" + "\n".join(lines + more)
        files: list = [write_text(text, out / "enkf_noise.md")]
        if rows:
            csv = f"{PAGE}_{file_stem(runs[0].scenario.get('name', 'scenario'))}.csv"
            files.append((write_csv(pd.DataFrame(rows), out / "enkf_noise.csv"), csv))
        if opts.docs is not None:
            publish(opts.docs, PAGE, NAME, "The EnKF's model-error noise",
                    f"`arzsumo study {NAME}`. {text}", files)
    return EnkfNoiseResult(tuple(float(v) for v in sd), pd.DataFrame(rows), text,
                           tuple(f if isinstance(f, Path) else f[0] for f in files))
