"""The [disturbance] table: SI values, none by default, one-line errors in the user's terms."""

from __future__ import annotations

import pytest

from arzsumo.errors import ScenarioError
from arzsumo.scenario import scenario_from_dict
from arzsumo.sumo.disturbance import Slowdown


def test_keys_read_in_si_and_default_none():
    sc = scenario_from_dict({"disturbance": {"kind": "slowdown", "edge": "merge",
                                             "speed_kmh": 18, "start_s": 10,
                                             "duration_s": 25}}, "s.toml")
    assert sc.disturbance == Slowdown("slowdown", "merge", 5.0, 10.0, 25.0)
    assert sc.disturbance.active
    assert not scenario_from_dict({}, "s.toml").disturbance.active


@pytest.mark.parametrize(("table", "message"), [
    ({"kind": "pulse"}, r'^s.toml: \[disturbance\] kind = "pulse" is not allowed: one of '
                        r"none, slowdown"),
    ({"edge": "ramp_up"}, r'^s.toml: \[disturbance\] edge = "ramp_up" is not allowed: one '
                          r"of main, merge, down"),
    ({"speed_kmh": 0}, r"^s.toml: \[disturbance\] speed_kmh = 0 is not allowed: a speed "
                       r"> 0 km/h$"),
    ({"start_s": -5}, r"^s.toml: \[disturbance\] start_s = -5 is not allowed: a time >= 0 s"),
    ({"duration_s": 0}, r"^s.toml: \[disturbance\] duration_s = 0 is not allowed: a "
                        r"duration > 0 s$"),
    ({"speed": 10}, r"^s.toml: \[disturbance\] unknown key 'speed'; allowed: duration_s, "),
])
def test_bad_values_are_one_line_errors(table, message):
    with pytest.raises(ScenarioError, match=message) as info:
        scenario_from_dict({"disturbance": table}, "s.toml")
    assert "\n" not in str(info.value)
