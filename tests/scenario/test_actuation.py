"""The [actuation] table: SI values, defaults off, one-line errors in the user's terms."""

from __future__ import annotations

import pytest

from arzsumo.errors import ScenarioError
from arzsumo.scenario import scenario_from_dict
from arzsumo.scenario.actuation import ActuationSettings


def test_keys_read_in_si_and_default_off():
    sc = scenario_from_dict({"actuation": {"u_max_fraction": 0.2, "u_rate_max_veh_h_s": 180,
                                           "ramp_bound": True}}, "s.toml")
    assert sc.actuation == ActuationSettings(0.2, 0.05, True, True)
    assert sc.actuation.active
    default = scenario_from_dict({}, "s.toml").actuation
    assert default == ActuationSettings() and not default.active
    assert sc.with_({"actuation.anti_windup": False}).actuation.anti_windup is False


@pytest.mark.parametrize(("table", "message"), [
    ({"u_max_fraction": 1.5}, r"^s.toml: \[actuation\] u_max_fraction = 1.5 is not allowed: "
                              r"a fraction of q\* in \[0, 1\]"),
    ({"u_max_fraction": -0.1}, r"u_max_fraction = -0.1 is not allowed"),
    ({"u_rate_max_veh_h_s": -5}, r"^s.toml: \[actuation\] u_rate_max_veh_h_s = -5 is not "
                                 r"allowed: a rate >= 0 veh/h per s"),
    ({"ramp_bound": "yes"}, r'^s.toml: \[actuation\] ramp_bound = "yes" is not allowed: '
                            r"true or false$"),
    ({"u_max": 0.2}, r"^s.toml: \[actuation\] unknown key 'u_max'; allowed: actuator, "
                     r"anti_windup, "),
    ({"actuator": "vsl"}, r'^s.toml: \[actuation\] actuator = "vsl" is not allowed: one of '
                          r"meter, speed_limit"),
    ({"speed_limit_gain_veh_h_per_kmh": 0}, r"speed_limit_gain_veh_h_per_kmh = 0 is not "
                                            r"allowed: a gain > 0 veh/h per km/h$"),
    ({"speed_limit_min_kmh": 40, "speed_limit_max_kmh": 30},
     r"speed_limit_max_kmh = 30 is not allowed: a speed above speed_limit_min_kmh$"),
    ({"speed_limit_step_kmh": -1}, r"speed_limit_step_kmh = -1 is not allowed"),
])
def test_bad_values_are_one_line_errors(table, message):
    with pytest.raises(ScenarioError, match=message) as info:
        scenario_from_dict({"actuation": table}, "s.toml")
    assert "\n" not in str(info.value)


def test_speed_limit_keys_read_in_si():
    sc = scenario_from_dict({"actuation": {
        "actuator": "speed_limit", "speed_limit_gain_veh_h_per_kmh": 40,
        "speed_limit_min_kmh": 18, "speed_limit_max_kmh": 72, "speed_limit_step_kmh": 3.6}},
        "s.toml")
    act = sc.actuation
    assert act.actuator == "speed_limit"
    assert act.speed_limit_gain == pytest.approx(0.04)        # veh/h per km/h is veh/km
    assert (act.speed_limit_min, act.speed_limit_max) == pytest.approx((5.0, 20.0))
    assert act.speed_limit_step == pytest.approx(1.0)
    assert scenario_from_dict({}, "s.toml").actuation.actuator == "meter"


@pytest.mark.parametrize(("tables", "message"), [
    ({"actuation": {"actuator": "speed_limit", "speed_limit_min_kmh": 55}},
     r"^s.toml: \[actuation\] speed_limit_min_kmh = 55 is not allowed: a range that holds "
     r"the outlet's own limit, \[sumo\] down_speed_kmh = 50$"),
    ({"actuation": {"actuator": "speed_limit", "speed_limit_max_kmh": 25},
      "sumo": {"down_speed_kmh": 30}},
     r"speed_limit_max_kmh = 25 is not allowed: .* down_speed_kmh = 30$"),
    ({"actuation": {"actuator": "speed_limit"}, "disturbance": {"kind": "slowdown"}},
     r'^s.toml: \[actuation\] actuator = "speed_limit" is not allowed: meter while '
     r"\[disturbance\] slows the edge past the merge"),
])
def test_speed_limit_refused_where_it_cannot_act(tables, message):
    with pytest.raises(ScenarioError, match=message) as info:
        scenario_from_dict(tables, "s.toml")
    assert "\n" not in str(info.value)


@pytest.mark.parametrize(("design", "message"), [
    ({"trigger": "band", "trigger_energy": "acted"},
     r'^s.toml: \[design\] trigger_energy = "acted" is not allowed: state with trigger = band'),
    ({"trigger": "static"}, r'^s.toml: \[design\] trigger = "static" is not allowed'),
])
def test_the_triggers_keys_are_refused_in_one_line(design, message):
    with pytest.raises(ScenarioError, match=message) as info:
        scenario_from_dict({"design": design}, "s.toml")
    assert "\n" not in str(info.value)


def test_the_band_trigger_reads_in():
    sc = scenario_from_dict({"design": {"trigger": "band", "noise_from_estimate": True}},
                            "s.toml")
    assert (sc.design.trigger, sc.design.trigger_energy) == ("band", "state")
