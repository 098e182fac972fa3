"""The approach (buffer) edge before x = 0: network, routes, runs and the [sumo] key."""

import numpy as np
import pytest

from arzsumo.cli import main
from arzsumo.errors import ScenarioError
from arzsumo.model import get_preset
from arzsumo.scenario import scenario_from_dict
from arzsumo.sumo.config import SumoConfig
from arzsumo.sumo.demand import InitialVehicle, route_file_text
from arzsumo.sumo.measure import MainlineSensor
from arzsumo.sumo.network import (
    APPROACH,
    MAIN,
    NetworkSpec,
    approach_edges,
    approach_length_of,
    approach_of,
    build_network,
    edge_lengths,
    network_sources,
)
from arzsumo.sumo.paths import NET_FILE, SumoError, default_nets_dir
from arzsumo.sumo.period_reads import approach_queue
from arzsumo.sumo.simulation import open_simulation
from tests.sumo import run_until

PARAMS = get_preset("paper_base").params
FAST = SumoConfig(horizon=40.0, step_length=0.2, control_period=1.0)


def test_approach_edge_has_the_stated_length_and_leads_into_main(tmp_path):
    import sumolib

    net_file = build_network(tmp_path, NetworkSpec(approach_length=437.5))
    lengths = edge_lengths(net_file)
    assert lengths[APPROACH] == 437.5 and lengths[MAIN] == 1000.0
    assert approach_length_of(net_file) == 437.5
    net = sumolib.net.readNet(str(net_file))
    approach = net.getEdge(APPROACH)
    assert [e.getID() for e in approach.getOutgoing()] == [MAIN]
    assert approach.getLane(0).getWidth() == pytest.approx(6.5)
    assert approach.getSpeed() == pytest.approx(net.getEdge(MAIN).getSpeed())


def test_the_approach_cut_into_pieces_is_a_chain_of_equal_edges_of_the_same_length(tmp_path):
    import sumolib

    net_file = build_network(tmp_path, NetworkSpec(approach_length=2500.0,
                                                   approach_piece=250.0))
    pieces = approach_of(net_file)
    assert pieces == tuple(f"approach{k}" for k in range(10))
    assert approach_length_of(net_file) == pytest.approx(2500.0)
    lengths = edge_lengths(net_file)
    assert {round(lengths[e], 6) for e in pieces} == {250.0}
    net = sumolib.net.readNet(str(net_file))
    chain = [e.getID() for e in net.getEdge(pieces[0]).getToNode().getOutgoing()]
    assert chain == [pieces[1]]
    assert [e.getID() for e in net.getEdge(pieces[-1]).getOutgoing()] == [MAIN]
    assert all(net.getEdge(e).getSpeed() == net.getEdge(MAIN).getSpeed() for e in pieces)
    # a last piece within a millimetre of P makes none more; a remainder makes one
    assert len(approach_edges(1000.0004, 250.0)) == 4
    assert len(approach_edges(1001.0, 250.0)) == 5
    assert approach_edges(2500.0, 0.0) == (APPROACH,) and approach_edges(0.0, 250.0) == ()


def test_zero_approach_is_the_shipped_network():
    assert network_sources(NetworkSpec(approach_length=0.0)) == network_sources(NetworkSpec())
    assert APPROACH not in "".join(network_sources(NetworkSpec()).values())
    assert approach_length_of(default_nets_dir() / NET_FILE) == 0.0


@pytest.mark.parametrize("bad", [-1.0, float("nan"), 1e7])
def test_bad_approach_lengths_are_refused(bad):
    with pytest.raises(Exception, match=r"approach_length = .*allowed: a length in \[0, 1e6\)"):
        NetworkSpec(approach_length=bad)


def test_routes_start_on_the_approach_only_when_there_is_one():
    init = [InitialVehicle("hv_init.0", "hv", 500.0, 10.0, 0.0)]
    plain = route_file_text(PARAMS, FAST, init)
    assert '<route id="r_main" edges="main merge down"/>' in plain
    assert APPROACH not in plain and 'route="r_main" depart="0"' in plain
    text = route_file_text(PARAMS, FAST.with_(approach_length=300.0), init)
    assert '<route id="r_main" edges="approach main merge down"/>' in text
    assert '<route id="r_section" edges="main merge down"/>' in text
    assert 'id="hv_init.0" type="hv" route="r_section" depart="0"' in text
    # the same flows, but mainline vehicles enter behind a queue at the highest safe speed
    flows = lambda t: [ln for ln in t.splitlines() if "<flow " in ln]  # noqa: E731
    assert len(flows(plain)) == len(flows(text)) == 4
    assert [ln.replace('departSpeed="max"', 'departSpeed="desired"') if "r_main" in ln
            else ln for ln in flows(text)] == flows(plain)
    assert sum('route="r_main"' in ln and 'departSpeed="max"' in ln for ln in flows(text)) == 3


def test_sumo_key_and_its_errors_name_the_key_in_metres():
    sc = scenario_from_dict({"sumo": {"approach_length_m": 1500}}, "s.toml")
    assert sc.sumo.approach_length == 1500.0
    assert SumoConfig().approach_length == 0.0
    with pytest.raises(ScenarioError, match=r"\[sumo\] approach_length_m = -5 .*at least 0"):
        scenario_from_dict({"sumo": {"approach_length_m": -5}}, "s.toml")


@pytest.mark.sumo
@pytest.mark.parametrize("piece", [0.0, 100.0])
def test_vehicles_depart_on_the_approach_and_main_is_measured_from_x0(piece):
    """One edge or three of 100 m: the same road, the same conservation."""
    cfg = FAST.with_(approach_length=300.0, horizon=40.0, ramp_demand=0.0,
                     collision_check=True, approach_piece=piece)
    edges = approach_edges(300.0, piece)
    first_on_main, roads = None, set()
    with open_simulation(PARAMS, cfg) as sim:
        sensor = MainlineSensor(sim.lib, PARAMS.length, cfg.cell_length, cfg.step_length,
                                cfg.steps_per_period)
        inflow = 0.0
        while sim.time < cfg.horizon - 1e-9:
            t = sim.step()
            roads |= {sim.lib.vehicle.getRoadID(v) for v in sim.lib.simulation.getDepartedIDList()}
            data = sensor.collect(t)
            if data is not None:
                inflow += (data.inflow_h + data.inflow_a) * data.window
                if first_on_main is None and data.rho_h.sum() + data.rho_a.sum() > 0:
                    first_on_main = t
                    first = data
        on_approach = sum(sim.lib.edge.getLastStepVehicleNumber(e) for e in edges)
        count, queue = approach_queue(sim.lib, 300.0, 30.0, edges)
    rep = sim.report
    assert roads == {edges[0]} and len(edges) == (3 if piece else 1)
    assert count == on_approach and 0.0 <= queue <= 300.0
    # 300 m at the desired speed (<= 80 km/h) takes more than 13 s
    assert first_on_main is not None and 13.0 <= first_on_main <= 20.0
    # the first vehicles on main sit in the first cells (x = 0 is the approach's end)
    assert np.flatnonzero(first.rho_h + first.rho_a).max() <= 1
    assert rep.delivered_main == 1.0 and rep.collisions == 0
    assert rep.inserted == rep.arrived + rep.on_network
    assert inflow + on_approach == pytest.approx(rep.inserted, abs=2)


@pytest.mark.sumo
def test_a_network_that_does_not_match_the_approach_length_is_refused(tmp_path):
    with pytest.raises(SumoError,
                       match=r"approach_length = 300 m \(1 edge\) does not match the network"):
        open_simulation(PARAMS, FAST.with_(approach_length=300.0), net_dir=default_nets_dir())
    build_network(tmp_path, NetworkSpec(approach_length=200.0))
    with pytest.raises(SumoError, match=r"whose approach is 200 m long \(1 edge\)"):
        open_simulation(PARAMS, FAST, net_dir=tmp_path)
    with open_simulation(PARAMS, FAST.with_(approach_length=200.0, horizon=2.0),
                         net_dir=tmp_path) as sim:
        run_until(sim, 2.0)
    assert sim.report is not None and sim.report.inserted > 0


def test_build_net_cli_builds_the_approach(tmp_path, capsys):
    assert main(["build-net", "--out", str(tmp_path), "--approach-length-m", "800"]) == 0
    out = capsys.readouterr().out
    assert "approach 800.00" in out and "main 1000.00" in out
    assert 'edges="approach main merge down"' in (tmp_path / "ramp.rou.xml").read_text()
    assert main(["build-net", "--out", str(tmp_path), "--approach-length-m", "-3"]) == 2
