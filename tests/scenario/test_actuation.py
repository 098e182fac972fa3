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
    ({"u_max": 0.2}, r"^s.toml: \[actuation\] unknown key 'u_max'; allowed: anti_windup, "),
])
def test_bad_values_are_one_line_errors(table, message):
    with pytest.raises(ScenarioError, match=message) as info:
        scenario_from_dict({"actuation": table}, "s.toml")
    assert "\n" not in str(info.value)
