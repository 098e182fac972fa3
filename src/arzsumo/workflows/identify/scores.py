"""Scoring an identification: the fit's start, and the replay error of runs and sets.

:func:`ao_floor` and :func:`start_params` keep the fit where every state SUMO showed is
admissible; :func:`score_run` and :func:`score_set` replay runs under a parameter set and
report their errors (on the grid and on 100 m x 10 s blocks), replay stops and the cells
beyond AO_max, for ``identification.json``.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass, replace

import numpy as np

from arzsumo.evaluation.fields import field_rmse
from arzsumo.identify import (
    DEFAULT_BOUNDS,
    VARIABLES,
    ReplayData,
    ReplayOptions,
    ValidationReport,
    run_replay,
    validate,
)
from arzsumo.identify.objective import DEFAULT_PENALTY
from arzsumo.model.fd import area_occupancy
from arzsumo.model.params import ModelParameters


def ao_floor(params: ModelParameters, datasets: Sequence[ReplayData],
             ao_limit: float) -> float:
    """The smallest AO_max that holds every observed area occupancy (cells and inlet)
    within the replay's AO limit ``ao_limit``: max AO / ao_limit (at most the bound 1).

    Below it a replay stops where SUMO holds a state the model cannot (in practice in the
    inlet cell, where the ghost-cell inlet compresses traffic), and the fit's objective
    turns into a flat penalty; so it is the lower bound of AO_max in the fit, and the
    start is raised to it.
    """
    ao = []
    for d in datasets:
        seen = np.isfinite(d.fields[:, 0]) & np.isfinite(d.fields[:, 2])
        ao.append(area_occupancy(params, d.fields[:, 0][seen], d.fields[:, 2][seen]))
        ao.append(area_occupancy(params, d.inlet[:, 0], d.inlet[:, 2]))
    return min(float(np.max(np.concatenate(ao))) / ao_limit, DEFAULT_BOUNDS["ao_max_h"][1])


def start_params(params: ModelParameters, datasets: Sequence[ReplayData],
                 ao_limit: float) -> ModelParameters:
    """``params`` with each class's AO_max raised to :func:`ao_floor` where below it."""
    need = ao_floor(params, datasets, ao_limit)
    return replace(params, ao_max_h=max(params.ao_max_h, need),
                   ao_max_a=max(params.ao_max_a, need))


@dataclass(frozen=True)
class RunScore:
    """The replay of one run under one parameter set, against the run.

    ``rmse``, ``stopped`` (s), ``periods_not_predicted`` and ``beyond_ao_max`` are the
    run's entries of ``identification.json`` (``docs/outputs.md``, 'identification.json').
    """

    name: str
    rmse: dict[str, dict[str, float]]
    stopped: float | None
    reason: str
    periods_not_predicted: int
    beyond_ao_max: dict[str, int]
    predicted: np.ndarray
    sums: np.ndarray          # (3, 4): squared absolute and relative errors, counts


def _beyond(params: ModelParameters, data: ReplayData) -> dict[str, int]:
    rho = data.fields[:, [0, 2]]
    seen = np.isfinite(rho).all(axis=1)
    ao = area_occupancy(params, np.where(seen, rho[:, 0], 0.0), np.where(seen, rho[:, 1], 0.0))
    return {"model": int((ao[seen] > params.ao_max).sum()),
            "h": int((ao[seen] > params.ao_max_h).sum()),
            "a": int((ao[seen] > params.ao_max_a).sum()), "observed": int(seen.sum())}


def _rmse(sums: np.ndarray, j: int, penalised: float) -> dict[str, float]:
    """Absolute and relative RMSE of variable ``j`` from ``sums`` (as
    :attr:`RunScore.sums`), NaN without samples; and the ``penalised`` one."""
    n = sums[2, j]
    return {"absolute": math.sqrt(sums[0, j] / n) if n else math.nan,
            "relative": math.sqrt(sums[1, j] / n) if n else math.nan,
            "penalised": float(penalised)}


def score_run(params: ModelParameters, data: ReplayData, options: ReplayOptions,
              penalised: np.ndarray) -> RunScore:
    """:class:`RunScore` of ``data`` under ``params``; ``penalised`` (4,) from
    :func:`arzsumo.identify.validate`."""
    run = run_replay(params, data, options)
    both = data.mask & np.isfinite(run.fields)
    err = np.where(both, run.fields - np.where(data.mask, data.fields, 0.0), 0.0)
    sums = np.vstack([(err ** 2).sum(axis=(0, 2)),
                      ((err / data.scale[None, :, None]) ** 2).sum(axis=(0, 2)),
                      both.sum(axis=(0, 2))])
    blocks, n_blocks = field_rmse(data.fields, run.fields, *_block_shape(data))
    rmse = {var: {**_rmse(sums, j, penalised[j]), "samples": int(sums[2, j]),
                  "blocks_relative": float(blocks[j] / data.scale[j]),
                  "blocks": int(n_blocks[j])}
            for j, var in enumerate(VARIABLES)}
    lost = int(np.isnan(run.fields).all(axis=(1, 2)).sum())
    return RunScore(data.name, rmse, run.stopped, run.reason, lost, _beyond(params, data),
                    run.fields, sums)


#: block of the RMSE at a macroscopic resolution (as ``rmse_blocks`` of ``arzsumo run``)
BLOCK_M, BLOCK_S = 100.0, 10.0


def _block_shape(data: ReplayData) -> tuple[int, int]:
    """(periods, cells) per BLOCK_S x BLOCK_M block on the data's grid."""
    dt = float(data.t[1] - data.t[0]) if data.t.size > 1 else float(data.t[0])
    dx = float(data.x[1] - data.x[0])
    return max(1, round(BLOCK_S / dt)), max(1, round(BLOCK_M / dx))


@dataclass(frozen=True)
class SetScore:
    """Scores of a set of runs (training or validation) under one parameter set;
    ``pooled`` and ``total`` as ``rmse.SET`` of ``identification.json``."""

    runs: tuple[RunScore, ...]
    report: ValidationReport
    pooled: dict[str, dict[str, float]]
    total: float


def score_set(params: ModelParameters, datasets: Sequence[ReplayData],
              options: ReplayOptions) -> SetScore:
    """Validate ``params`` on ``datasets`` (:func:`arzsumo.identify.validate`) and score
    each run (:func:`score_run`)."""
    report = validate(params, datasets, options, DEFAULT_PENALTY)
    runs = tuple(score_run(params, d, options, report.rmse[i])
                 for i, d in enumerate(datasets))
    sums = sum(r.sums for r in runs)
    observed = np.array([d.mask.sum(axis=(0, 2)) for d in datasets], float)
    pooled = {var: _rmse(sums, j, report.pooled[j]) for j, var in enumerate(VARIABLES)}
    total = math.sqrt(float((report.rmse ** 2 * observed).sum() / observed.sum()))
    return SetScore(runs, report, pooled, total)
