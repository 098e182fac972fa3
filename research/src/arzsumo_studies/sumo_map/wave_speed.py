"""Which way SUMO's speed and density fluctuations travel on the section
(``arzsumo study wave-speed``).

The paper's actuator sits at the outlet x = L and acts on the section through the one
characteristic that travels upstream (lambda_4 < 0 in congestion); whatever enters at
x = 0 and travels downstream reaches the meter without the meter acting on it. This
study measures the direction: for pairs of cells 250 m apart it cross-correlates the
fluctuation of each variable (a cell's series minus its mean over the control window) in
SUMO's measured cells, and reports the lag of the peak (s; > 0: the downstream cell
follows) and the travel speed it implies (km/h).

The runs are closed-loop SUMO runs of ``--scenario`` (default: the former default,
lateral_files) for each of ``--controllers`` and ``--seeds``, through the sweep engine;
``--from DIR ...`` reads the cells of earlier ``arzsumo run`` results (``cells.parquet``) instead.
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np
import pandas as pd

from arzsumo.outdir import resumable_dir
from arzsumo.units import ms_to_kmh
from arzsumo_studies import checks
from arzsumo_studies.common import (
    FORMER_DEFAULT,
    RESULTS_DIR,
    StudyError,
    shipped_scenario,
    study_spec,
)
from arzsumo_studies.design import StudyRun, design_runs, run_design
from arzsumo_studies.outputs.pages import markdown_table, publish, write_csv

NAME = "wave-speed"
#: the results page this study keeps a block of
PAGE = "control_in_sumo"
#: cell pairs (indices of the 50 m cells): 250 m apart, upstream, middle, downstream
PAIRS = ((2, 7), (5, 10), (10, 15))
MAX_LAG_S = 60.0
VARIABLES = ("rho_h", "v_h", "rho_a", "v_a")


def lagged_corr(u: np.ndarray, w: np.ndarray, lag: int) -> float:
    """Correlation of u(t) with w(t + lag) (lag in samples, either sign)."""
    if lag >= 0:
        return float(np.corrcoef(u[:len(u) - lag], w[lag:])[0, 1])
    return float(np.corrcoef(u[-lag:], w[:len(w) + lag])[0, 1])


def travel(t: np.ndarray, x: np.ndarray, field: np.ndarray, var: str
           ) -> list[dict[str, float | str]]:
    """Peak lag (s) and implied speed (km/h) of the fluctuations of ``field`` (T, N) at
    times ``t`` (s) and cell centres ``x`` (m), for every pair of :data:`PAIRS`."""
    filled = pd.DataFrame(field).interpolate(limit_direction="both").to_numpy()
    dt = float(np.median(np.diff(t)))
    a = filled - filled.mean(axis=0)
    lags = np.arange(-int(MAX_LAG_S / dt), int(MAX_LAG_S / dt) + 1)
    rows: list[dict[str, float | str]] = []
    for i, j in PAIRS:
        corr = np.array([lagged_corr(a[:, i], a[:, j], int(k)) for k in lags])
        k = int(np.nanargmax(corr))
        lag_s = float(lags[k] * dt)
        rows.append({"variable": var, "x_up_m": float(x[i]), "x_down_m": float(x[j]),
                     "lag_s": lag_s, "peak_corr": float(corr[k]),
                     "speed_kmh": ms_to_kmh((x[j] - x[i]) / lag_s) if lag_s else np.nan})
    return rows


def travel_all(t: np.ndarray, x: np.ndarray, fields: np.ndarray) -> list[dict[str, Any]]:
    """:func:`travel` of every variable of ``fields`` (T, 4, N) in :data:`VARIABLES` order."""
    return [r for k, var in enumerate(VARIABLES) for r in travel(t, x, fields[:, k], var)]


def from_cells(path: Path) -> list[dict[str, Any]]:
    """The rows of an ``arzsumo run`` result directory (its measured cells)."""
    cells = pd.read_parquet(Path(path) / "cells.parquet")
    micro = cells[cells["source"] == "micro"]
    fields = np.stack([micro.pivot(index="t_s", columns="x_m", values=v).to_numpy()
                       for v in VARIABLES], axis=1)
    t = np.sort(micro["t_s"].unique())
    x = np.sort(micro["x_m"].unique())
    return [{"run": Path(path).name, **r} for r in travel_all(t, x, fields)]


def run_cells(run: StudyRun) -> dict[str, Any]:
    """One closed-loop SUMO run; its rows (one per variable and pair)."""
    from arzsumo.bridge.session import run_in_sumo
    from arzsumo.scenario import scenario_from_dict

    res = run_in_sumo(scenario_from_dict(run.scenario, run.source)).result
    rows = travel_all(np.asarray(res.t), np.asarray(res.x), np.asarray(res.micro))
    return {"rows": [{"run": run.run_id, **r} for r in rows]}


@dataclass(frozen=True)
class WaveSpeedOptions(checks.Shared):
    """What the wave-speed study runs (or reads) and where it writes.

    Parameters
    ----------
    scenario : Path, optional
        The scenario run (None: the former default, lateral_files).
    controllers : tuple of str
        The controllers, one run each per seed.
    seeds : tuple of int
        SUMO seeds.
    source : tuple of Path
        ``arzsumo run`` result directories read instead of running SUMO (empty: run).

    ``out``, ``docs``, ``workers``, ``scheduler``: as every study's
    (:data:`~arzsumo_studies.common.SHARED_FIELDS`).
    """

    scenario: Path | None = None
    controllers: tuple[str, ...] = ("open", "etc")
    seeds: tuple[int, ...] = (42,)
    source: tuple[Path, ...] = ()
    out: Path = RESULTS_DIR / NAME

    def __post_init__(self) -> None:
        super().__post_init__()
        checks.seeds(self.seeds)


@dataclass(frozen=True)
class WaveSpeedResult:
    """The study's outcome: the ``table`` (one row per run, variable and cell pair: the
    peak lag, s, and the speed it implies, km/h), its markdown ``text`` and the
    ``files`` written."""

    table: pd.DataFrame
    text: str
    files: tuple[Path, ...]


def design(opts: WaveSpeedOptions) -> list[StudyRun]:
    """One run per controller and seed."""
    spec = study_spec(NAME, opts.scenario or shipped_scenario(FORMER_DEFAULT),
                      seeds=list(opts.seeds),
                      axis=[{"field": "run.controller", "name": "controller",
                             "values": list(opts.controllers)}])
    return design_runs(spec)


def run_wave_speed(opts: WaveSpeedOptions, *, progress: bool = True) -> WaveSpeedResult:
    """Run (or read ``opts.source``) and write the table of lags and speeds.

    ``opts``: the study's :class:`WaveSpeedOptions`; ``progress``: draw a progress bar.

    Returns
    -------
    WaveSpeedResult
        The table and the file written (``wave_speed.csv`` in ``opts.out``).
    """
    runs = design(opts)
    with resumable_dir(opts.out, f"study-{NAME}") as out:
        if opts.source:
            missing = [str(d) for d in opts.source if not (Path(d) / "cells.parquet").is_file()]
            if missing:
                raise StudyError(f"--from: {', '.join(missing)} has no cells.parquet; "
                                 "allowed: arzsumo run result directories")
            rows = [r for d in opts.source for r in from_cells(d)]
        else:
            done = run_design(runs, run_cells, out, workers=opts.workers,
                              scheduler=opts.scheduler, progress=progress, label=NAME)
            rows = [r for d in done for r in d["rows"]]
        df = pd.DataFrame(rows)
        path = write_csv(df, out / "wave_speed.csv")
        text = markdown_table(df, ".3g")
        if opts.docs is not None:
            publish(opts.docs, PAGE, NAME, "Control in SUMO",
                    f"Lag of the peak cross-correlation of cell fluctuations 250 m apart "
                    f"(> 0: downstream follows) and the speed it implies (`arzsumo study "
                    f"{NAME}`). Table: [wave_speed.csv]({PAGE}/wave_speed.csv).\n\n{text}",
                    [path])
    return WaveSpeedResult(df, text, (path,))
