"""What a boundary can reach, read off run directories: the share of the section's HV
speed variance, per band of periods, coherent with the inlet's flow q(0, t), the outlet's
flow q(L, t) and the law's input U(t) (:mod:`arzsumo_studies.measures.coherence`).

A run directory is what ``arzsumo run --out`` (or :meth:`arzsumo.RunResult.save`) writes:
``cells.parquet`` (SUMO's Edie cells, ``source == "micro"``), ``periods.parquet`` (the
class in- and outflows and U per control period) and ``summary.json`` (lambda_4). The
runs of one condition (a stream and a controller, over seeds) are pooled: their spectra
are averaged over every segment of every run.

* The speed field is averaged over ``block_s`` in time (empty 1 s cells are NaN in SUMO's
  cells; a block keeps the 20 s-1 min band at 5 s), its remaining gaps filled linearly in
  time per cell; a cell empty over a whole run is dropped from every run of the condition.
* The flows and U are averaged over the same blocks (veh/s).
* Each cell is aligned with its boundary by the travel time of what the boundary sends:
  from x = L upstream at lambda_4 (q(L) and U), from x = 0 downstream at the equilibrium's
  HV speed (q(0)).

SI inside: s, m, m/s, veh/s; the shares are dimensionless.
"""

from __future__ import annotations

import json
import warnings
from collections.abc import Mapping, Sequence
from dataclasses import dataclass
from pathlib import Path

import numpy as np
import pandas as pd

from arzsumo.errors import require
from arzsumo.evaluation.authority import window_means
from arzsumo_studies.common import StudyError
from arzsumo_studies.measures.coherence import BoundaryShares, boundary_shares, travel_lags

#: the boundary series, in the table's order
BOUNDARIES = ("q0", "qL", "U")


@dataclass(frozen=True)
class RunSeries:
    """One run's HV speed field (T, N) on blocks of ``dt`` s, the cells' centres ``x``
    (m), the boundary series (T,) by name, lambda_4 and the HV equilibrium speed (m/s)."""

    v: np.ndarray
    x: np.ndarray
    dt: float
    series: Mapping[str, np.ndarray]
    lambda_4: float
    v_star: float

    def __post_init__(self) -> None:
        require(self.v.ndim == 2 and self.v.shape[1] == self.x.size, "v", self.v.shape,
                "a (blocks, cells) field on x", StudyError)
        require(all(s.shape == (self.v.shape[0],) for s in self.series.values()), "series",
                {k: s.shape for k, s in self.series.items()}, "one value per block",
                StudyError)


def _filled(v: np.ndarray) -> np.ndarray:
    """Each column's NaN filled linearly in time (its ends held)."""
    out = v.copy()
    t = np.arange(v.shape[0])
    for j in range(v.shape[1]):
        ok = np.isfinite(v[:, j])
        if ok.any():
            out[:, j] = np.interp(t, t[ok], v[ok, j])
    return out


def read_run(path: Path, block_s: float = 5.0) -> RunSeries:
    """The HV speed field and the boundary series of the run directory ``path``."""
    cells = pd.read_parquet(path / "cells.parquet", filters=[("source", "==", "micro")])
    per = pd.read_parquet(path / "periods.parquet")
    summ = json.loads((path / "summary.json").read_text(encoding="utf-8"))
    period = float(np.median(np.diff(per["t_s"]))) if len(per) > 1 else 1.0
    # the cells at t_s are the end of the period checked at t_s - period: the row of t_s = 0
    # (the measurement control starts from) has no period of its own
    field = cells.pivot(index="t_s", columns="x_m", values="v_h")
    field = field.loc[np.isin(field.index, per["t_s"].to_numpy() + period)]
    blocks = max(1, round(block_s / period))
    n = len(field) // blocks
    with warnings.catch_warnings():    # a block of a cell that stayed empty: NaN, filled
        warnings.simplefilter("ignore", RuntimeWarning)
        v = np.nanmean(field.to_numpy()[: n * blocks].reshape(n, blocks, -1), axis=1)
    series = {"q0": per["inflow_h"] + per["inflow_a"],
              "qL": per["outflow_h"] + per["outflow_a"], "U": per["u_applied"]}
    means = {k: window_means(np.asarray(s, float), period, blocks * period)[:n]
             for k, s in series.items()}
    return RunSeries(v, field.columns.to_numpy(float), blocks * period, means,
                     float(summ["lambda_4"]), float(summ["equilibrium"]["v_h"]))


def reach(runs: Sequence[RunSeries]) -> BoundaryShares:
    """The coherent shares of the pooled runs (one condition): q(0), q(L) and U, each cell
    aligned by its travel time (module docstring)."""
    require(len(runs) >= 1, "runs", len(runs), "at least one run", StudyError)
    first = runs[0]
    seen = np.all([np.isfinite(r.v).any(axis=0) for r in runs], axis=0)
    require(seen.sum() >= 2, "cells", int(seen.sum()), "at least 2 cells seen in every run",
            StudyError)
    x, length = first.x[seen], float(first.x[-1] + first.x[0])
    fields = [_filled(r.v[:, seen]) for r in runs]
    lags = {"q0": travel_lags(x, 0.0, first.v_star),
            "qL": travel_lags(x, length, first.lambda_4),
            "U": travel_lags(x, length, first.lambda_4)}
    return boundary_shares(fields, {k: [r.series[k] for r in runs] for k in BOUNDARIES},
                           first.dt, x, lags=lags)


def reach_table(conditions: Mapping[str, Sequence[Path]], block_s: float = 5.0
                ) -> pd.DataFrame:
    """One row per condition, boundary and band: the section's coherent share, its floor
    and the share beyond the floor, with the runs pooled (the directories of each
    condition)."""
    parts = []
    for name, dirs in conditions.items():
        table = reach([read_run(Path(d), block_s) for d in dirs]).table()
        parts.append(table.assign(condition=name, runs=len(dirs)))
    return pd.concat(parts, ignore_index=True)
