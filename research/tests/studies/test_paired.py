"""The studies' paired tables on known per-seed data (no SUMO)."""

import numpy as np
import pandas as pd
import pytest
from arzsumo_studies.paired import deadlocked_seeds, paired_cell

from arzsumo.evaluation.stats import paired_difference


def test_a_seed_deadlocked_before_control_under_every_controller_is_the_only_one_named():
    grid = "network_whole_demand.drain.gridlock"
    drain = "network_whole_demand.drain.duration_s"
    # seed 2: stuck since the warm-up under both; seed 3: only the ETC gridlocks; seed 4:
    # both gridlock in the drain (standstill 300 s of a 450 + 1800 s run after control)
    runs = pd.DataFrame({
        "seed": [1, 1, 2, 2, 3, 3, 4, 4],
        "controller": ["open", "etc"] * 4,
        grid: [False, False, True, True, False, True, True, True],
        drain: [200.0, 210.0, 1800.0, 1800.0, 200.0, 1800.0, 1800.0, 1800.0],
        "longest_standstill_main": [0.0, 0.0, 2600.0, 2600.0, 0.0, 2600.0, 300.0, 300.0],
        "horizon": [450.0] * 8,
    })
    assert deadlocked_seeds(runs, ["open", "etc"]) == [2]
    # a seed whose baseline has not finished yet is not named on the ETC's word alone
    assert deadlocked_seeds(runs[runs["controller"] == "etc"], ["open", "etc"]) == []
    assert deadlocked_seeds(runs.drop(columns=[grid]), ["open", "etc"]) == []


def test_a_paired_cell_gives_the_bootstrap_interval_of_the_same_differences():
    """The cell's {bootstrap} bounds are those of ``paired_difference`` on the same pairs,
    and they bracket the mean; without ``bootstrap`` the cell has none."""
    base = np.arange(12.0)
    treat = base + np.array([1.0, 3.0, -1.0, 2.0, 0.5, 4.0, 1.5, -0.5, 2.5, 1.0, 3.5, 0.0])
    d = paired_difference(treat, base)
    cell = paired_cell(treat, base, bootstrap=True)
    low, high = (float(x) for x in cell.split("{")[1].split("}")[0].split(","))
    assert (low, high) == pytest.approx((d.bootstrap.low, d.bootstrap.high), rel=5e-3)
    assert low < d.mean_diff < high
    assert cell.endswith(f"{d.wins}/{d.losses}") and "{" not in paired_cell(treat, base)
