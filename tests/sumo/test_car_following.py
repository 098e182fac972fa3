"""The car-following keys: today's vTypes unchanged by default, each key written as the
attribute its model reads, a key the model ignores refused in one line, and SUMO itself
loading every model with every attribute it reads."""

from __future__ import annotations

import subprocess
from pathlib import Path

import pytest

from arzsumo.errors import ScenarioError
from arzsumo.model import get_preset
from arzsumo.scenario import load_scenario, scenario_from_dict
from arzsumo.sumo.car_following import ATTRIBUTES
from arzsumo.sumo.paths import default_nets_dir, sumo_binary
from arzsumo.sumo.vtypes import vehicle_types

ROOT = Path(__file__).resolve().parents[2]
PARAMS = get_preset("paper_base").params
#: the default scenario's vTypes as they were written before the car-following keys
DEFAULT_HV = (
    '<vType id="hv" length="4.8000" minGap="3.2000" width="2.0000" maxSpeed="22.666667" '
    'desiredMaxSpeed="22.666667" carFollowModel="Krauss" vClass="passenger" accel="2.6" '
    'decel="4.5" emergencyDecel="9.0" tau="1" speedFactor="1" speedDev="0.05" '
    'sigma="0.500" color="0.2,0.4,1" latAlignment="arbitrary" minGapLat="0.600" '
    'maxSpeedLat="1.0" lcSublane="1" lcPushy="0.2" lcStrategic="1.0" lcKeepRight="0" '
    'lcSpeedGain="0.5"/>')
DEFAULT_AV = (
    '<vType id="av" length="5.0000" minGap="10.0000" width="2.0000" maxSpeed="17.000000" '
    'desiredMaxSpeed="17.000000" carFollowModel="ACC" vClass="passenger" accel="2.0" '
    'decel="4.5" emergencyDecel="9.0" tau="1.0" speedFactor="1" speedDev="0" '
    'color="1,0.3,0.1" latAlignment="arbitrary" minGapLat="0.600" maxSpeedLat="1.0" '
    'lcSublane="1" lcPushy="0.2" lcStrategic="1.0" lcKeepRight="0" lcSpeedGain="0.5"/>')

EIDM = {"hv_model": "EIDM", "hv_accel_m_s2": 1.0, "hv_decel_m_s2": 1.5, "hv_delta": 4,
        "hv_stepping_s": 0.25, "hv_reaction_s": 0.5, "hv_sigma_error": 0.1,
        "hv_sigma_gap": 0.1, "hv_sigma_leader": 0.02}
CACC = {"av_model": "CACC", "av_accel_m_s2": 1.5, "av_speed_gain": -0.4,
        "av_gap_gain_space": 0.23, "av_gap_gain_speed": 0.07, "av_gap_gain_gap": 0.45,
        "av_gap_gain_gap_dot": 0.0125}


def _xml(sumo: dict) -> tuple[str, str]:
    sc = scenario_from_dict({"sumo": sumo})
    hv, av = vehicle_types(sc.params, sc.sumo)
    return hv.to_xml(), av.to_xml()


def test_the_default_scenarios_vtypes_are_unchanged_to_the_byte():
    sc = load_scenario(ROOT / "scenarios" / "default.toml")
    hv, av = vehicle_types(sc.params, sc.sumo)
    assert (hv.to_xml(), av.to_xml()) == (DEFAULT_HV, DEFAULT_AV)


def test_each_key_becomes_the_attribute_its_model_reads():
    hv, av = _xml({"hv_sigma": 0.75, "hv_sigma_step_s": 1, "hv_accel_m_s2": 1.2})
    assert 'sigma="0.750"' in hv and 'sigmaStep="1"' in hv and 'accel="1.2"' in hv
    hv, av = _xml({**EIDM, **CACC})
    assert 'carFollowModel="EIDM"' in hv and "sigma=" not in hv
    for attr in ('accel="1"', 'decel="1.5"', 'delta="4"', 'stepping="0.25"',
                 'treaction="0.5"', 'sigmaerror="0.1"', 'sigmagap="0.1"',
                 'sigmaleader="0.02"'):
        assert attr in hv, attr
    for attr in ('accel="1.5"', 'speedControlGain="-0.4"', 'gapControlGainSpace="0.23"',
                 'gapControlGainSpeed="0.07"', 'gapControlGainGap="0.45"',
                 'gapControlGainGapDot="0.0125"'):
        assert attr in av, attr
    assert {a.field for a in ATTRIBUTES} <= set(scenario_from_dict({}).sumo.__dataclass_fields__)


def test_lane_change_gap_acceptance_is_written_only_when_set():
    hv, av = _xml({"hv_model": "IDM", "lc_assertive": 3, "lc_impatience": 1})
    for xml in (hv, av):
        assert 'lcAssertive="3"' in xml and 'lcImpatience="1"' in xml
    hv, av = _xml({"hv_model": "IDM"})
    assert "lcAssertive" not in hv + av and "lcImpatience" not in hv + av


@pytest.mark.parametrize(("sumo", "message"), [
    ({"hv_model": "IDM", "hv_sigma": 0.5},
     'x.toml: [sumo] hv_sigma = 0.5 is not read by hv_model = "IDM" (SUMO would ignore '
     'it); allowed: remove it, or set hv_model = "Krauss"'),
    ({"hv_sigma_step_s": 1, "hv_model": "EIDM"}, 'hv_sigma_step_s = 1 is not read by '
                                                 'hv_model = "EIDM"'),
    ({"hv_reaction_s": 0.5, "hv_model": "IDM"}, 'hv_reaction_s = 0.5 is not read by '
                                                'hv_model = "IDM" (SUMO would ignore it); '
                                                'allowed: remove it, or set hv_model = '
                                                '"EIDM"'),
    ({"hv_delta": 4}, 'hv_delta = 4 is not read by hv_model = "Krauss"'),
    ({"av_gap_gain_gap": 0.4}, 'av_gap_gain_gap = 0.4 is not read by av_model = "ACC"'),
    ({"hv_model": "EIDM", "hv_sigma_gap": 1.5}, "hv_sigma_gap = 1.5 is not allowed: a "
                                                "number in [0, 1]"),
    ({"hv_accel_m_s2": 0}, "hv_accel_m_s2 = 0 is not allowed"),
    ({"lc_assertive": 0}, "lc_assertive = 0 is not allowed: a finite number above 0"),
    ({"lc_impatience": 1.5}, "lc_impatience = 1.5 is not allowed: a number in [0, 1]"),
])
def test_a_key_its_model_does_not_read_or_a_bad_value_is_refused_in_one_line(sumo, message):
    with pytest.raises(ScenarioError) as err:
        scenario_from_dict({"sumo": sumo}, "x.toml")
    assert message in str(err.value) and "\n" not in str(err.value)


@pytest.mark.sumo
@pytest.mark.parametrize("sumo", [{"hv_sigma": 0.75, "hv_sigma_step_s": 1},
                                  {**EIDM, **CACC},
                                  {"hv_model": "IDM", "hv_delta": 4, "hv_stepping_s": 0.1,
                                   "lc_assertive": 3, "lc_impatience": 1}])
def test_sumo_loads_every_attribute_without_a_warning(sumo, tmp_path):
    """SUMO itself reads the vTypes: no error, no warning about an attribute."""
    hv, av = _xml(sumo)
    routes = tmp_path / "vtypes.rou.xml"
    routes.write_text(f"<routes>\n{hv}\n{av}\n"
                      '<vehicle id="h" type="hv" depart="0"><route edges="main"/></vehicle>\n'
                      '<vehicle id="a" type="av" depart="1"><route edges="main"/></vehicle>\n'
                      "</routes>\n", encoding="utf-8")
    net = default_nets_dir() / "ramp.net.xml"
    done = subprocess.run([str(sumo_binary("sumo")), "-n", str(net), "-r", str(routes),
                           "--end", "5", "--lateral-resolution", "0.5", "--no-step-log"],
                          capture_output=True, text=True, timeout=60)
    out = done.stdout + done.stderr
    assert done.returncode == 0, out
    assert "Warning" not in out and "Error" not in out, out
