"""The meter's dead time from paired runs, on real SUMO: the runs of a seed part only
after the meter's change, first at the light, then at the section's outflow.

The held meter and the open loop share one warm-up. Their periods agree to the last bit
until the held meter's command; the light parts after it, and the outflow at x = L only
later, when the change has travelled from the meter to the section's end.
"""

from __future__ import annotations

import numpy as np
import pandas as pd
import pytest
from arzsumo_studies.control.meter_delay import first_difference, paired_events

from arzsumo.bridge.branches import run_branched, warmup_key
from arzsumo.bridge.session import SumoSession, prepare_run
from arzsumo.outputs.bridge import periods_table
from arzsumo.resources import shipped_scenarios_dir
from arzsumo.scenario import load_scenario
from arzsumo.sumo.fork import BranchFailed, can_fork

pytestmark = [pytest.mark.sumo, pytest.mark.slow,
              pytest.mark.skipif(not can_fork(), reason="needs fork and /proc")]

SC = load_scenario(shipped_scenarios_dir() / "default.toml").with_(
    {"sumo.drain_max_s": 0.0, "sumo.approach_length_m": 200.0, "run.kernel_cells": 50,
     "run.twin_cells": 50})
WARMUP, HORIZON = 120.0, 60.0


def periods(session: SumoSession) -> pd.DataFrame:
    """The run's periods as ``periods.parquet`` holds them (what the study reads)."""
    return periods_table(session.result).to_pandas()


@pytest.fixture(scope="module")
def runs(tmp_path_factory):
    import os
    os.environ.setdefault("ARZSUMO_CACHE", str(tmp_path_factory.mktemp("cache")))
    group = [prepare_run(SC, controller=c, seed=3, horizon=HORIZON, warmup=WARMUP)
             for c in ("open", "held", "open")]
    assert len({warmup_key(r) for r in group}) == 1
    got = run_branched(group, periods)
    assert not any(isinstance(g, BranchFailed) for g in got), got
    return dict(zip(("open", "held", "open_again"), got, strict=True))


def test_two_open_loops_of_a_seed_never_part(runs):
    cols = ["release_rate", "green_running", "outflow_h", "outflow_a", "inflow_h"]
    assert first_difference(runs["open"][cols].to_numpy(),
                            runs["open_again"][cols].to_numpy()) is None
    ev = paired_events(runs["open_again"], runs["open"])
    assert all(np.isnan(v) for v in ev.values())


def test_the_held_meter_parts_at_its_command_then_the_light_then_the_outflow(runs):
    ev = paired_events(runs["held"], runs["open"])
    assert ev["command_s"] == 1.0                 # the first period's command
    assert ev["command_s"] < ev["light_s"] <= 1.0 + 6.0   # the next green of a 6 s cycle
    # the outflow at x = L parts later: the first vehicle the meter keeps has to reach
    # the merge first (the default's ramp_dn), at least several seconds
    assert ev["outflow_s"] - ev["light_s"] >= 5.0
    assert ev["dead_time_s"] == ev["outflow_s"] - ev["command_s"]
