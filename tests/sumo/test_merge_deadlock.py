"""The IDM stream's merge deadlock and SUMO's way out of it (docs/sumo.md): on seed 2 of
``stop_and_go_idm`` two ramp vehicles finish their merge overhanging the main lane's edge
and stop on the junction lane past the acceleration lane, from which an overhanging
vehicle cannot leave; without teleports (the shipped scenario) the queue behind them
reaches the approach, 511 vehicles standing at t = 1200 s (measured). SUMO's own gridlock
resolution at its default 300 s teleports the blocker once and the stream runs on."""

import pytest

from arzsumo.bridge.session import run_prepared
from arzsumo.outputs.bridge import summary
from arzsumo.sumo.simulation import DEADLOCK_S
from tests.runs import ROOT, prepared

pytestmark = pytest.mark.sumo

IDM = ROOT / "scenarios" / "stop_and_go_idm.toml"


def test_the_idm_seed_that_deadlocked_runs_through_with_sumos_teleport():
    run = prepared(IDM, {"sumo.time_to_teleport_s": 300, "sumo.drain_max_s": 0},
                   controller="open", seed=2, warmup=800.0, horizon=30.0)
    summ = summary(run_prepared(run).result).to_dict()
    assert summ["teleports"] == 1                 # the blocker, once
    assert summ["longest_standstill_main"] < DEADLOCK_S / 2   # 114.5 s measured
    assert summ["inserted_fraction_main"] > 0.98
