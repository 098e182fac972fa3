"""RunSummary: summary.json key for key, typed blocks, the whole-demand headline."""

from __future__ import annotations

import math

import pytest

from arzsumo.outputs.run_summary import Accounting, RunIdentity, RunSummary, WindowCounts


def _summary(whole: dict | None) -> RunSummary:
    return RunSummary(
        identity=RunIdentity("default", "x.toml", "0.1.0", 7, "etc"), equilibrium={},
        lambda_4=-3.1, q_nominal=1.2, horizon=450.0, warmup={"duration_s": 600.0},
        counts=WindowCounts(26, 25, 30, 120.0, 37), meter={}, speed_variance={"h": 1.0},
        micro={"TTT": {"total": 3600.0}}, section={}, network=None, network_whole_run=None,
        network_whole_demand=whole, twin_replay={}, twin_reference={}, rmse={},
        rmse_blocks={}, section_trend={}, estimation={}, actuation={}, twin_status={},
        accounting=Accounting(inserted=10, arrived=9), placement="none", wall_time=1.0,
        timings={}, controller_time_per_period=None, settings={})


def test_the_dict_is_summary_json_in_its_order():
    d = _summary(None).to_dict()
    keys = list(d)
    assert keys[:8] == ["kind", "scenario", "source", "version", "seed", "controller",
                        "complete", "units"]
    # the window counts follow the warm-up, the micro indices sit at the top level
    at = keys.index("warmup")
    assert keys[at + 1:at + 7] == ["plan_changes", "light_changes", "triggers",
                                   "release_time", "max_ramp_queue", "meter"]
    assert d["TTT"] == {"total": 3600.0} and d["inserted"] == 10 and d["waiting"] is None
    assert keys[-1] == "units_by_key" and d["units_by_key"]["max_ramp_queue"] == "veh"
    assert _summary(None)["plan_changes"] == 26 and "triggers" in _summary(None)


def test_whole_demand_time_spent_in_veh_h_only_when_complete():
    done = {"complete": True, "time_spent_s": {"total": 36000.0}}
    assert _summary(done).whole_demand_tts_h() == pytest.approx(10.0)
    assert math.isnan(_summary({**done, "complete": False}).whole_demand_tts_h())
    assert math.isnan(_summary(None).whole_demand_tts_h())
