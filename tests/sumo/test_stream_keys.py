"""The [sumo] keys of the stream's lateral behaviour, HV driving and the bottleneck: each
reaches the vType, the flows or the network SUMO is given, and bad values are refused."""

import pytest

from arzsumo.errors import ScenarioError
from arzsumo.model import get_preset
from arzsumo.scenario import scenario_from_dict
from arzsumo.sumo.config import SumoConfig
from arzsumo.sumo.demand import demand_flows
from arzsumo.sumo.network import NetworkSpec, network_sources
from arzsumo.sumo.run_network import network_spec
from arzsumo.sumo.vtypes import vehicle_types

PARAMS = get_preset("paper_base").params


def test_lateral_and_driving_keys_reach_the_vehicle_types():
    cfg = scenario_from_dict({"sumo": {
        "lat_alignment": "center", "lc_sublane": 0.2, "lc_speed_gain": 0, "lc_pushy": 0.5,
        "hv_tau_s": 1.4, "hv_action_step_s": 0.5, "step_length_s": 0.1}}).sumo
    hv, av = (t.to_xml() for t in vehicle_types(PARAMS, cfg))
    for xml in (hv, av):
        assert 'latAlignment="center"' in xml and 'lcSublane="0.2"' in xml
        assert 'lcSpeedGain="0"' in xml and 'lcPushy="0.5"' in xml
    assert 'tau="1.4"' in hv and 'actionStepLength="0.5"' in hv
    assert "actionStepLength" not in av and 'tau="1.0"' in av


def test_defaults_keep_the_vehicle_types_as_they_were():
    hv, _ = (t.to_xml() for t in vehicle_types(PARAMS, SumoConfig()))
    assert 'latAlignment="arbitrary"' in hv and 'lcSublane="1"' in hv
    assert 'lcPushy="0.2"' in hv and 'lcSpeedGain="0.5"' in hv and 'tau="1"' in hv
    assert "actionStepLength" not in hv


def test_sumo_lateral_insertion_gives_one_flow_per_class():
    columns = demand_flows(SumoConfig(demand_h=1.0, demand_a=0.5))
    assert sorted(f.id for f in columns) == ["av_0", "hv_0", "hv_1", "ramp_hv"]
    free = demand_flows(SumoConfig(demand_h=1.0, demand_a=0.5, depart_pos_lat="random"))
    main = [f for f in free if not f.id.startswith("ramp")]
    assert [(f.id, f.lat, f.rate) for f in main] == [("hv_0", "random", 1.0),
                                                     ("av_0", "random", 0.5)]


def test_bottleneck_keys_build_their_network():
    cfg = scenario_from_dict({"sumo": {"down_speed_kmh": 36, "down_length_m": 400}}).sumo
    spec = network_spec(cfg)
    assert spec.down_speed == pytest.approx(10.0) and spec.down_length == 400
    assert network_spec(SumoConfig()) == NetworkSpec()
    edges = network_sources(spec)["ramp.edg.xml"]
    assert 'id="down"' in edges and 'speed="10"' in edges and 'length="400"' in edges


@pytest.mark.parametrize(("table", "message"), [
    ({"lat_alignment": "middle"}, 'lat_alignment = "middle" is not allowed: one of '
                                  "arbitrary, center"),
    ({"depart_pos_lat": "left"}, 'depart_pos_lat = "left" is not allowed: one of columns'),
    ({"lc_pushy": 1.5}, "lc_pushy = 1.5 is not allowed: a number in [0, 1]"),
    ({"lc_sublane": -1}, "lc_sublane = -1 is not allowed"),
    ({"hv_tau_s": 0}, "hv_tau_s = 0 is not allowed"),
    ({"hv_action_step_s": 0.25, "step_length_s": 0.1}, "hv_action_step_s = 0.25 is not "
                                                       "allowed: 0 (every step) or a multiple"),
    ({"down_speed_kmh": 0}, "down_speed_kmh = 0 is not allowed"),
])
def test_bad_stream_keys_name_key_and_value(table, message):
    with pytest.raises(ScenarioError) as info:
        scenario_from_dict({"sumo": table}, "test")
    assert message in str(info.value)
    assert str(info.value).startswith("test: [sumo]")
