"""The studies' paired tables: a controller's measure on chosen seeds, a paired cell of
treatment minus baseline, and the seeds SUMO deadlocked before control."""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np
import pandas as pd

from arzsumo.evaluation.report import Measure, per_seed
from arzsumo.evaluation.stats import StatisticsError, paired_difference

#: the summary block of the whole demand's measures
WHOLE = "network_whole_demand"


def deadlocked_seeds(runs: pd.DataFrame, controllers: Sequence[str]) -> list[int]:
    """The seeds on which SUMO deadlocked before control began, under every controller.

    A seed counts when each of ``controllers`` has a run on it whose drain ended in a
    gridlock with a mainline vehicle standing since before the window opened (its
    standstill at the end at least the window plus the drain, s). A comparison leaves
    these out: their zero differences would narrow every interval (docs/sumo.md).
    """
    keys = (f"{WHOLE}.drain.gridlock", f"{WHOLE}.drain.duration_s",
            "longest_standstill_main", "horizon")
    if runs.empty or any(k not in runs for k in keys):
        return []
    num = {k: pd.to_numeric(runs[k], errors="coerce") for k in keys[1:]}
    before = num["longest_standstill_main"] >= num["horizon"] + num[keys[1]] - 1.0
    stuck = (runs[keys[0]].astype(str).str.lower() == "true") & before
    return sorted(int(seed) for seed, rows in runs.assign(_stuck=stuck).groupby("seed")
                  if set(controllers) <= set(rows["controller"]) and bool(rows["_stuck"].all()))


def seed_values(runs: pd.DataFrame, measure: Measure, controller: str,
                seeds: Sequence[int]) -> np.ndarray:
    """``controller``'s ``measure`` on ``seeds``, in that order (its human unit; NaN where
    missing)."""
    return per_seed(runs, measure, [controller])[controller].reindex(seeds).to_numpy(float)


def paired_cell(treatment: np.ndarray, baseline: np.ndarray, *, lower_is_better: bool = True,
                bracket_counts: bool = False, bootstrap: bool = False) -> str:
    """Treatment minus baseline, paired by seed, as a table cell: the mean difference
    [95 % t interval] (unit of the data), with ``bootstrap`` its {95 % bootstrap
    interval}, then the seeds won / lost by the treatment (``(wins/losses)`` with
    ``bracket_counts``); empty where the pairs are too few."""
    try:
        d = paired_difference(treatment, baseline, lower_is_better=lower_is_better)
    except StatisticsError:
        return ""
    counts = f"{d.wins}/{d.losses}"
    boot = f"{{{d.bootstrap.low:+.3g}, {d.bootstrap.high:+.3g}}} " if bootstrap else ""
    return (f"{d.mean_diff:+.3g} [{d.t.low:+.3g}, {d.t.high:+.3g}] {boot}"
            + (f"({counts})" if bracket_counts else counts))
