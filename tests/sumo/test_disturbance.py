"""The disturbance experiment's slowdown: the same on every controller of a seed, and felt.

Runs of a seed with and without ``[disturbance]`` share one warm-up; up to the start of
control they are the same run, and the slowdown begins and ends at the same SUMO times on
every controller. Slowing the edge past the merge must cut the section's discharge
against the undisturbed run of the same seed.
"""

from __future__ import annotations

import numpy as np
import pytest

from arzsumo.bridge.branches import run_branched, warmup_key
from arzsumo.bridge.session import SumoSession, prepare_run
from arzsumo.outputs.bridge import summary
from arzsumo.resources import shipped_scenarios_dir
from arzsumo.scenario import load_scenario
from arzsumo.sumo.fork import BranchFailed, can_fork

pytestmark = [pytest.mark.sumo, pytest.mark.slow,
              pytest.mark.skipif(not can_fork(), reason="needs fork and /proc")]

SC = load_scenario(shipped_scenarios_dir() / "default.toml").with_(
    {"sumo.drain_max_s": 0.0, "sumo.approach_length_m": 200.0, "run.kernel_cells": 50,
     "run.twin_cells": 50})   # a short approach: the section carries traffic within the warm-up
SLOW = {"disturbance.kind": "slowdown", "disturbance.edge": "down",
        "disturbance.speed_kmh": 5.0, "disturbance.start_s": 5.0,
        "disturbance.duration_s": 20.0}
DISTURBED = SC.with_(SLOW)
WARMUP, HORIZON = 120.0, 60.0


def prepared(scenario, controller: str):
    return prepare_run(scenario, controller=controller, seed=2, horizon=HORIZON,
                       warmup=WARMUP)


def kept(session: SumoSession) -> dict:
    res = session.result
    return {"start": np.asarray(res.start), "disturbance": res.disturbance,
            "warmup": summary(res).to_dict()["warmup"],
            "outflow_veh": float(np.sum(res.periods["outflow_h"] + res.periods["outflow_a"])
                                 * res.sumo.control_period)}


@pytest.fixture(scope="module")
def runs(tmp_path_factory):
    import os
    os.environ.setdefault("ARZSUMO_CACHE", str(tmp_path_factory.mktemp("cache")))
    group = [prepared(DISTURBED, "open"), prepared(DISTURBED, "etc"), prepared(SC, "open")]
    assert len({warmup_key(r) for r in group}) == 1      # one warm-up for the three
    got = run_branched(group, kept)
    assert not any(isinstance(g, BranchFailed) for g in got), got
    return dict(zip(("open", "etc", "undisturbed"), got, strict=True))


def test_the_runs_are_one_run_up_to_the_start_of_control(runs):
    for name in ("etc", "undisturbed"):
        assert np.array_equal(runs[name]["start"], runs["open"]["start"], equal_nan=True)
        assert runs[name]["warmup"] == runs["open"]["warmup"]


def test_the_slowdown_is_the_same_on_every_controller(runs):
    a, b = runs["open"]["disturbance"], runs["etc"]["disturbance"]
    assert a == b
    assert a["began_s"] == pytest.approx(WARMUP + 5.0, abs=1e-6)
    assert a["ended_s"] == pytest.approx(WARMUP + 25.0, abs=1e-6)
    assert a["speed_m_s"] == pytest.approx(5.0 / 3.6)
    assert a["original_speed_m_s"] == pytest.approx(13.89, abs=0.01)   # "down" at 50 km/h
    assert runs["undisturbed"]["disturbance"] is None


def test_the_slowdown_cuts_the_section_discharge(runs):
    # the edge past the merge at 5 km/h for 20 s: the merge backs up into the section
    assert runs["open"]["outflow_veh"] < runs["undisturbed"]["outflow_veh"] - 10
