"""Meter realisation settings and the outflow-command-to-release-rate rule (no SUMO)."""

import re

import pytest

from arzsumo.errors import ArzsumoError, ScenarioError
from arzsumo.scenario import scenario_from_dict
from arzsumo.sumo.config import SumoConfig, ramp_capacity
from arzsumo.sumo.green_share import plan_green_steps
from arzsumo.sumo.meter_release import nominal_phases, release_rate_for
from arzsumo.sumo.run_files import meter_program_text


def test_meter_keys_convert_units_and_default_to_todays_meter():
    cfg = SumoConfig()
    assert (cfg.meter_mode, cfg.meter_clearance, cfg.drain_max) == ("fixed_cycle", 0, 0)
    # the ramp stores what its 300 m hold at 8 m per vehicle unless told otherwise
    assert cfg.ramp_storage == ramp_capacity() == 37
    assert ramp_capacity(100.0, 7.5) == 13
    assert SumoConfig(ramp_storage=0).ramp_storage == 0
    cfg = scenario_from_dict({"sumo": {"meter_mode": "one_per_green", "meter_clearance_s": 2,
                                       "release_rate_veh_h": 720, "release_rate_min_veh_h": 360,
                                       "release_rate_max_veh_h": 720,
                                       "max_green_s": 2.5}}).sumo
    assert cfg.meter_mode == "one_per_green" and cfg.meter_clearance == 2.0
    assert cfg.release_rate == pytest.approx(0.2) and cfg.release_rate_min == pytest.approx(0.1)
    assert cfg.max_green == 2.5


@pytest.mark.parametrize(("table", "message"), [
    ({"meter_mode": "ramp"}, 'meter_mode = "ramp" is not allowed: one of fixed_cycle, '
                             "one_per_green"),
    ({"meter_clearance_s": -1}, "meter_clearance_s = -1 is not allowed: a finite number of "
                                "at least 0"),
    ({"meter_clearance_s": 5}, "min_green_s + meter_clearance_s + min_red_s = 7.0 is not "
                               "allowed: at most meter_cycle"),
    ({"release_rate_veh_h": 1000}, "release_rate_veh_h = 1000 is not allowed: a rate > 0 "
                                   "veh/h, with release_rate_min_veh_h <= release_rate_veh_h"),
    ({"max_green_s": 0.5}, "max_green_s = 0.5 is not allowed: at least min_green_s = 1.0 s"),
    ({"meter_mode": "one_per_green", "meter_clearance_s": 2.5},
     "is not allowed: at most the cycle 1 / release_rate_max = 4 s"),
])
def test_bad_meter_keys_name_key_and_value(table, message):
    with pytest.raises(ScenarioError) as info:
        scenario_from_dict({"sumo": table}, "test")
    assert message in str(info.value)
    assert str(info.value).startswith("test: [sumo]")


def test_release_rate_is_nominal_minus_u():
    cfg = SumoConfig()                         # 600 veh/h nominal, in [240, 900] veh/h
    assert release_rate_for(0.0, cfg) == pytest.approx(600 / 3600)
    assert release_rate_for(-200 / 3600, cfg) == pytest.approx(800 / 3600)   # U < 0: more
    assert release_rate_for(200 / 3600, cfg) == pytest.approx(400 / 3600)
    # beyond the bounds: the rule alone; the actuator saturates (tests/bridge/test_actuator)
    assert release_rate_for(-1.0, cfg) == pytest.approx(600 / 3600 + 1.0)
    with pytest.raises(ArzsumoError, match="U = nan is not allowed"):
        release_rate_for(float("nan"), cfg)


def test_clearance_is_taken_from_the_red_of_the_cycle():
    # 60-step cycle, 10-step minimum green and red; a 20-step clearance joins the red
    assert plan_green_steps(0.5, 60, 10, 10) == 30
    assert plan_green_steps(0.5, 60, 10, 10 + 20) == 30    # yellow 20, red 10
    assert plan_green_steps(0.6, 60, 10, 10 + 20) == 30    # the red holds yellow + min red
    assert plan_green_steps(0.8, 60, 10, 10 + 20) == 60    # nearer all green


@pytest.mark.parametrize(("table", "message"), [
    ({"meter_mode": "one_per_green", "green_share": 0},
     'green_share = 0 is not allowed with meter_mode = "one_per_green": it acts only under '
     'meter_mode = "fixed_cycle"; allowed: remove it, or set meter_mode = "fixed_cycle"'),
    ({"meter_mode": "one_per_green", "meter_cycle_s": 6}, "meter_cycle_s = 6 is not allowed"),
    ({"release_rate_max_veh_h": 900}, 'release_rate_max_veh_h = 900 is not allowed with '
                                      'meter_mode = "fixed_cycle"'),
    ({"meter_mode": "fixed_cycle", "max_green_s": 3}, "max_green_s = 3 is not allowed"),
])
def test_a_key_the_meter_mode_ignores_is_refused(table, message):
    with pytest.raises(ScenarioError, match=re.escape(message)):
        scenario_from_dict({"sumo": table})


def test_keys_of_the_chosen_meter_mode_are_accepted():
    cfg = scenario_from_dict({"sumo": {"meter_mode": "one_per_green",
                                       "release_rate_veh_h": 500, "max_green_s": 3}}).sumo
    assert cfg.release_rate == pytest.approx(500 / 3600) and cfg.green_share == 0.5
    cfg = scenario_from_dict({"sumo": {"green_share": 0.3, "meter_cycle_s": 8}}).sumo
    assert (cfg.green_share, cfg.meter_cycle) == (0.3, 8.0)


@pytest.mark.parametrize(("changes", "phases"), [
    ({}, [("G", 30), ("r", 30)]),                                  # 6 s cycle, share 0.5
    ({"meter_clearance": 2.0}, [("G", 30), ("y", 20), ("r", 10)]),
    ({"green_share": 0.0}, [("r", 60)]), ({"green_share": 1.0}, [("G", 60)]),
    ({"meter_mode": "one_per_green", "meter_clearance": 2.0},      # 600 veh/h: 6 s cycle
     [("G", 10), ("y", 20), ("r", 30)]),
    ({"meter_mode": "one_per_green", "release_rate": 900 / 3600},  # 4 s cycle, no yellow
     [("G", 10), ("r", 30)]),
])
def test_the_nominal_plan_as_phases_of_whole_steps(changes, phases):
    cfg = SumoConfig(**changes)
    assert nominal_phases(cfg) == phases
    assert sum(n for _, n in phases) * cfg.step_length == pytest.approx(
        1 / cfg.release_rate if cfg.meter_mode == "one_per_green" else cfg.meter_cycle)


def test_the_nominal_plan_becomes_a_static_program_of_the_meter_light():
    text = meter_program_text(SumoConfig(meter_clearance=2.0))
    assert '<tlLogic id="meter" type="static" programID="nominal" offset="0">' in text
    assert '<phase duration="3" state="G"/>' in text and 'duration="2" state="y"' in text
