"""SUMO-side pure pieces: config table, Edie grid, meter timing and curve, placement."""

import itertools
import math

import numpy as np
import pytest

from arzsumo.errors import ArzsumoError, ModelError, ScenarioError
from arzsumo.model import get_preset
from arzsumo.scenario import scenario_from_dict
from arzsumo.sumo.config import SumoConfig
from arzsumo.sumo.demand import Flow, demand_flows, route_file_text
from arzsumo.sumo.green_share import GreenShareCurve, plan_green_steps
from arzsumo.sumo.measure import EdieGrid
from arzsumo.sumo.placement import place_vehicles
from arzsumo.sumo.vtypes import VehicleType, vehicle_types

PARAMS = get_preset("paper_base").params


def requested(flow: Flow, t: float) -> int:
    """Vehicles of ``flow`` due by time ``t`` (s): departures at begin + k period < end, <= t."""
    if flow.rate <= 0 or t < flow.begin:
        return 0
    last = min(t, math.nextafter(flow.end, -math.inf))
    return math.floor((last - flow.begin) / flow.period + 1e-9) + 1


def spacing(vtype: VehicleType) -> float:
    """length + minGap of ``vtype``, m (the model's spacing policy s_i)."""
    return vtype.length + vtype.min_gap


def test_sumo_table_converts_units():
    cfg = scenario_from_dict({"sumo": {"step_length_s": 0.2, "demand_h_veh_h": 3600,
                                       "ramp_demand_veh_h": 720, "seed": 7,
                                       "av_model": "CACC"}}).sumo
    assert cfg.step_length == 0.2 and cfg.seed == 7 and cfg.av_model == "CACC"
    assert cfg.demand_h == pytest.approx(1.0)
    assert cfg.ramp_demand == pytest.approx(0.2)


@pytest.mark.parametrize(("table", "message"), [
    ({"step_lenght_s": 0.1}, "unknown key 'step_lenght_s'"),
    ({"step_length_s": "fast"}, 'step_length_s = "fast" is not allowed: a finite number'),
    ({"step_length_s": 2.0}, "step_length_s = 2.0 is not allowed: at most 1 s"),
    ({"seed": 1.5}, "seed = 1.5 is not allowed: an integer"),
    ({"control_period_s": 0.25, "step_length_s": 0.1}, "a multiple of step_length"),
    ({"hv_model": "Wiedemann"}, 'hv_model = "Wiedemann" is not allowed: one of Krauss, IDM'),
    ({"green_share": 1.2}, "green_share = 1.2 is not allowed: a number in [0, 1]"),
    ({"min_green_s": 4, "min_red_s": 4}, "at most meter_cycle"),
    ({"lateral_resolution_m": 0.7}, "lateral_resolution_m = 0.7 is not allowed: a width "
                                      "dividing the 6.5 m lane"),
    ({"meter_curve": 3}, "meter_curve = 3 is not allowed: a string"),
])
def test_bad_sumo_table_names_key_and_value(table, message):
    with pytest.raises(ScenarioError, match=None) as info:
        scenario_from_dict({"sumo": table}, "test")
    assert message in str(info.value)
    assert str(info.value).startswith("test: [sumo]")


def test_scenario_sumo_table_is_validated_and_reachable():
    sc = scenario_from_dict({"model": {"preset": "paper_base"},
                             "sumo": {"horizon_s": 60, "seed": 3}})
    assert sc.sumo.horizon == 60 and sc.sumo.seed == 3
    with pytest.raises(ScenarioError, match="unknown key 'horizon'"):
        scenario_from_dict({"sumo": {"horizon": 60}})


def test_vtypes_follow_spacing_policy():
    hv, av = vehicle_types(PARAMS, SumoConfig())
    assert spacing(hv) == pytest.approx(PARAMS.spacing_h)
    assert spacing(av) == pytest.approx(PARAMS.spacing_a)
    assert hv.width == av.width == PARAMS.vehicle_width
    assert hv.max_speed == pytest.approx(80 / 3.6) and av.max_speed == pytest.approx(60 / 3.6)
    assert av.car_follow_model == "ACC" and 'sigma="0.500"' in hv.to_xml()


def test_flows_request_exactly_and_are_sorted():
    f = Flow("x", "hv", "r_main", 0.5, 1.0, 10.0)
    assert [requested(f, t) for t in (0.9, 1.0, 2.9, 3.0, 9.99, 100)] == [0, 1, 1, 2, 5, 5]
    flows = demand_flows(SumoConfig(horizon=3600))
    total = sum(requested(fl, 3600) for fl in flows)
    assert total == pytest.approx(4104 + 1560 + 1200, abs=4)
    text = route_file_text(PARAMS, SumoConfig())
    begins = [float(s.split('begin="')[1].split('"')[0]) for s in text.splitlines()
              if "<flow" in s]
    assert begins == sorted(begins)


def test_vehicle_speeds_come_from_the_sumo_table_when_given():
    hv, av = vehicle_types(PARAMS, SumoConfig(hv_max_speed=25.0, av_max_speed=15.0))
    assert (hv.max_speed, av.max_speed) == (25.0, 15.0)
    assert 'maxSpeed="25.000000"' in hv.to_xml()
    hv, av = vehicle_types(PARAMS, SumoConfig())
    assert (hv.max_speed, av.max_speed) == (PARAMS.v_free_h, PARAMS.v_free_a)


def test_a_fill_phase_requests_the_fill_demand_then_the_hold_demand():
    cfg = SumoConfig(horizon=1200, demand_h=3600 / 3600, demand_a=720 / 3600,
                     fill_duration=600, fill_demand_h=7200 / 3600, fill_demand_a=1440 / 3600)
    flows = [f for f in demand_flows(cfg) if f.route == "r_main"]
    by = {c: [f for f in flows if f.type == c] for c in ("hv", "av")}
    # 10 min at the fill rate, then 10 min at the hold rate, per class (+- one per column)
    assert sum(requested(f, 600) for f in by["hv"]) == pytest.approx(1200, abs=2)
    assert sum(requested(f, 1200) for f in by["hv"]) == pytest.approx(1200 + 600, abs=2)
    assert sum(requested(f, 600) for f in by["av"]) == pytest.approx(240, abs=2)
    assert sum(requested(f, 1200) for f in by["av"]) == pytest.approx(240 + 120, abs=2)
    assert len({f.id for f in flows}) == len(flows)
    assert min(f.begin for f in flows if f.rate == pytest.approx(0.5)) >= 600
    short = [f for f in demand_flows(cfg.with_(horizon=300)) if f.route == "r_main"]
    assert short and all(f.end == 300 and f.begin < f.end for f in short)
    assert demand_flows(cfg.with_(fill_duration=0)) == demand_flows(
        SumoConfig(horizon=1200, demand_h=1.0, demand_a=0.2))


def test_sublane_grid_must_separate_insertion_columns():
    with pytest.raises(ScenarioError, match=r"lateral_resolution = 0\.65 is not allowed: "
                                            r"with vehicles 2 m wide in columns at -2\.25, "
                                            r"0, 2\.25 m on a 6\.5 m lane"):
        route_file_text(PARAMS, SumoConfig(lateral_resolution=0.65))
    # without the fixed columns SUMO places every vehicle itself: any sublane grid
    free = route_file_text(PARAMS, SumoConfig(lateral_resolution=1.3,
                                              depart_pos_lat="random_free"))
    assert 'departPosLat="random_free"' in free


def test_edie_single_step_density_is_count_over_length():
    grid = EdieGrid(1000.0, 50.0, 0.1)
    pos = np.array([1.0, 20.0, 49.9, 50.0, 999.0, 1000.0])
    speed = np.array([10.0, 20.0, 30.0, 5.0, 7.0, 9.0])
    av = np.array([False, False, True, False, False, True])
    grid.add(pos, speed, av)
    d = grid.flush(0.1)
    assert d.rho_h[0] == pytest.approx(2 / 50) and d.rho_a[0] == pytest.approx(1 / 50)
    assert d.rho_h[1] == pytest.approx(1 / 50) and d.rho_h[-1] == pytest.approx(1 / 50)
    assert d.v_h[0] == pytest.approx(15.0) and d.v_a[-1] == pytest.approx(9.0)
    assert np.isnan(d.v_a[5]) and d.rho_h.sum() * 50 == pytest.approx(4)


def test_edie_window_averages_time():
    grid = EdieGrid(100.0, 50.0, 0.5)
    grid.add(np.array([10.0]), np.array([4.0]), np.array([False]))
    grid.add(np.array([12.0]), np.array([2.0]), np.array([False]))
    d = grid.flush(1.0)
    # one vehicle present for the whole 1 s window in cell 0
    assert d.rho_h[0] == pytest.approx(1 / 50) and d.q_h[0] == pytest.approx(3.0 / 50)
    assert d.v_h[0] == pytest.approx(3.0) and d.window == pytest.approx(1.0)
    with pytest.raises(ArzsumoError, match=r"cell_length = 30\.0"):
        EdieGrid(100.0, 30.0, 0.1)


@pytest.mark.parametrize(("g", "green"), [
    (0.0, 0), (0.05, 0), (0.13, 10), (0.5, 30), (0.9, 50), (0.95, 60), (1.0, 60)])
def test_meter_timing_respects_min_green_and_red(g, green):
    assert plan_green_steps(g, cycle=60, min_green=10, min_red=10) == green


def test_green_share_curve_inverts_and_saturates():
    c = GreenShareCurve((0.0, 0.5, 1.0), (1.5, 1.3, 1.2))
    assert c.green_share_for(1.4) == pytest.approx(0.25)
    assert c.green_share_for(2.0) == 0.0 and c.green_share_for(1.0) == 1.0
    assert c.outflow_at(0.75) == pytest.approx(1.25)
    with pytest.raises(ArzsumoError, match="green_share"):
        GreenShareCurve((0.5, 0.2), (1.0, 1.1))


def test_placement_reproduces_step_profile_exactly_per_100m():
    x = np.arange(25.0, 1000.0, 50.0)
    k = (x // 100).astype(int)
    rho_h, rho_a = (90 + 10 * (k % 5)) / 1000, (100 - 10 * (k % 4)) / 1000
    cfg = SumoConfig()
    veh, rep = place_vehicles(PARAMS, cfg, x, rho_h, np.full_like(x, 8.0), rho_a,
                              np.full_like(x, 5.0))
    pos_h = [v.pos for v in veh if v.type == "hv"]
    pos_a = [v.pos for v in veh if v.type == "av"]
    bins = np.arange(0, 1001, 100)
    assert list(np.histogram(pos_h, bins)[0]) == list((90 + 10 * (np.arange(10) % 5)) // 10)
    assert list(np.histogram(pos_a, bins)[0]) == list((100 - 10 * (np.arange(10) % 4)) // 10)
    assert rep.dropped == 0 and rep.n_h == len(pos_h)
    # gaps: in each column the follower keeps its minimum gap behind the leader's back
    hv, av = vehicle_types(PARAMS, cfg)
    types = {"hv": hv, "av": av}
    for lat in {v.lat for v in veh}:
        col = sorted((v for v in veh if v.lat == lat), key=lambda v: v.pos)
        for f, lead in itertools.pairwise(col):
            assert lead.pos - types[lead.type].length - f.pos >= types[f.type].min_gap - 1e-9
    again, _ = place_vehicles(PARAMS, cfg, x, rho_h, np.full_like(x, 8.0), rho_a,
                              np.full_like(x, 5.0))
    assert again == veh


def test_placement_rejects_bad_profiles():
    x = np.array([250.0, 750.0])
    with pytest.raises(ModelError, match="rho_h"):
        place_vehicles(PARAMS, SumoConfig(), x, [-0.1, 0.1], [1, 1], [0, 0], [1, 1])
    with pytest.raises(ModelError, match="do not fit"):
        place_vehicles(PARAMS, SumoConfig(), x, [0.5, 0.5], [1, 1], [0.2, 0.2], [1, 1])


def test_fd_fit_recovers_parameters_and_scores_paper_curve():
    from arzsumo.model.fd import power_law_speed as fd_speed
    from arzsumo.sumo.calibrate import fit_class

    ao = np.linspace(0.02, 0.6, 200)
    v = fd_speed(ao, 20.0, 0.7, 2.0)
    fit = fit_class(ao, v, (22.0, 0.9, 2.5))
    assert fit.v_free == pytest.approx(20.0, rel=1e-4)
    assert fit.ao_max == pytest.approx(0.7, rel=1e-4) and fit.gamma == pytest.approx(2.0, rel=1e-3)
    assert fit.r2 == pytest.approx(1.0) and fit.rmse < 1e-4 and fit.r2_paper < 0.9
    with pytest.raises(ArzsumoError, match="too few"):
        fit_class(ao[:3], v[:3], (22.0, 0.9, 2.5))
