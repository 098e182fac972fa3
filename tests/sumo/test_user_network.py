"""A ``[network]`` scenario on networks the package does not ship.

Checks before SUMO starts (sumolib only), then short SUMO runs on both test networks of
:mod:`tests.sumo.user_nets`: vehicles conserved between the section's loops, the sensor
and SUMO's own edge counts; the loops' ASM estimate against SUMO's Edie cells; the open
loop and the ETC end to end.
"""

from __future__ import annotations

import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

import arzsumo
from arzsumo.errors import ScenarioError
from arzsumo.estimate.smoothing import data_points, smooth
from arzsumo.scenario import load_scenario
from arzsumo.sumo.network_measures import EDGEDATA_FILE, edge_left, network_options
from arzsumo.sumo.plant import SumoPlant
from arzsumo.sumo.sensing import SensorLayout
from arzsumo.sumo.simulation import open_simulation
from tests.sumo import user_nets


@pytest.fixture(scope="module")
def net_a(tmp_path_factory: pytest.TempPathFactory) -> Path:
    d = tmp_path_factory.mktemp("two_lane")
    user_nets.two_lane(d)
    (d / "a.toml").write_text(user_nets.TWO_LANE_TOML, encoding="utf-8")
    return d / "a.toml"


@pytest.fixture(scope="module")
def net_b(tmp_path_factory: pytest.TempPathFactory) -> Path:
    d = tmp_path_factory.mktemp("partway")
    user_nets.partway(d)
    text = user_nets.PARTWAY_TOML + "[equilibrium]\nrho_h_veh_km = 100\nrho_a_veh_km = 20\n"
    (d / "b.toml").write_text(text, encoding="utf-8")
    return d / "b.toml"


def _variant(path: Path, old: str, new: str) -> Path:
    out = path.with_name(f"bad_{abs(hash((old, new)))}.toml")
    text = path.read_text(encoding="utf-8")
    assert old in text
    out.write_text(text.replace(old, new), encoding="utf-8")
    return out


def test_layout_of_the_two_lane_network(net_a):
    run = arzsumo.prepare(str(net_a), controller="open")
    lay = run.sumo.layout
    assert lay.section_edges == ("s1", "s2", "s3") and lay.length == pytest.approx(1500.0)
    assert lay.lanes == 2 and lay.width == pytest.approx(7.0)
    assert run.scenario.params.length == pytest.approx(1500.0)
    assert run.scenario.params.road_width == pytest.approx(7.0)
    assert lay.meter_tl == "rm1" and lay.ramp_links == (0,) and lay.signal("r") == "r"
    assert lay.ramp_route[:3] == ("onramp", "ramp_link", "mrg") and lay.outlet_edge == "out"
    assert lay.av_types == frozenset({"cav"}) and run.sumo.ramp_storage == 37
    assert lay.locate(1000.0) == ("s3", 0.0) and lay.locate(1600.0) == ("mrg", 100.0)


def test_layout_of_a_section_starting_partway(net_b):
    lay = arzsumo.prepare(str(net_b), controller="open").sumo.layout
    assert lay.length == pytest.approx(1000.0) and lay.starts[:2] == (-300.0, 500.0)
    assert lay.locate(0.0) == ("up", 300.0) and not lay.sublane and lay.lanes == 1


@pytest.mark.parametrize(("old", "new", "message"), [
    ('"s2"', '"s22"', 'section_edges = ["s1", "s22", "s3"] is not allowed: edges of the '
                      "network (edge 's22' is not in it; did you mean 's2'?)"),
    ('["s1", "s2", "s3"]', '["s1", "s3"]', "'s1' does not lead into 's3'"),
    ('["s1", "s2", "s3"]', '["s1", "s2", "s3", "mrg"]', "the same lanes along its length"),
    ('"rm1"', '"rm2"', 'meter_tls = "rm2" is not allowed: a traffic light of the network'),
    ('ramp_edge = "onramp"', 'ramp_edge = "ramp_link"', "controls none"),
    ('["cav"]', '["acc"]', "'acc' is not among ['car', 'cav']"),
    ("two_lane.net.xml", "nope.net.xml", 'net_file = "nope.net.xml" is not allowed'),
    ('["demand.rou.xml"]', '["nope.rou.xml"]', "route_files = [\"nope.rou.xml\"]"),
    ("[sumo]", "[model]\nroad_width_m = 6.5\n[sumo]", "road_width_m = 6.5 is not allowed"),
    ("[sumo]", "[sumo]\napproach_length_m = 100", "approach_length_m = 100 is not allowed"),
])
def test_bad_network_input_is_refused_before_sumo(net_a, old, new, message):
    with pytest.raises(ScenarioError, match="^" + str(_variant(net_a, old, new)).replace(
            "\\", "\\\\").replace(".", r"\.") + r": \[") as err:
        arzsumo.prepare(str(_variant(net_a, old, new)), controller="open")
    assert message in str(err.value) and "\n" not in str(err.value)


def test_partway_offsets_are_checked(net_b):
    bad = _variant(net_b, "start_offset_m = 300", "start_offset_m = 800")
    with pytest.raises(ScenarioError, match="start_offset_m = 800 is not allowed"):
        arzsumo.prepare(str(bad), controller="open")


def test_dry_run_exit_2_names_section_edges(net_a):
    bad = _variant(net_a, '"s2"', '"s2x"')
    proc = subprocess.run([sys.executable, "-m", "arzsumo.cli", "run", str(bad), "--dry-run"],
                          capture_output=True, text=True, timeout=120)
    assert proc.returncode == 2 and proc.stdout == ""
    assert "section_edges" in proc.stderr and "'s2x'" in proc.stderr
    assert len(proc.stderr.splitlines()) == 1 and "Traceback" not in proc.stderr
    ok = subprocess.run([sys.executable, "-m", "arzsumo.cli", "run", str(net_a), "--dry-run"],
                        capture_output=True, text=True, timeout=120)
    assert ok.returncode == 0 and "valid" in ok.stdout


def test_without_network_the_scenario_has_none():
    sc = load_scenario("src/arzsumo/data/scenarios/default.toml")
    assert sc.network is None and sc.sumo.layout is None


def _open_loop(path: Path, out: Path, horizon: float) -> tuple:
    """A plant-level open loop with the scenario's loops and SUMO's edge data."""
    run = arzsumo.prepare(str(path), controller="open")
    sc, cfg = run.scenario, run.sumo.with_(horizon=horizon)
    L = sc.params.length
    layout = sc.sensing
    assert layout.loops and isinstance(layout, SensorLayout)
    periods = []
    with open_simulation(sc.params, cfg, extra_args=network_options(out), output_dir=out,
                         loops=layout.loop_x(L)) as sim:
        plant = SumoPlant(sim, L, cfg, layout=layout)
        plant.run_open_loop(on_period=periods.append, until=horizon)
        inside = len(plant.sensor.mainline.last_ids)
    return cfg.layout, periods, inside


@pytest.mark.sumo
@pytest.mark.parametrize("which", ["a", "b"])
def test_vehicles_conserved_and_estimate_against_edie(which, net_a, net_b, tmp_path):
    path = net_a if which == "a" else net_b
    layout, periods, inside = _open_loop(path, tmp_path, 150.0)
    loops = [p.measurement.loops for p in periods]
    cells = [p.measurement.cells for p in periods]
    T = periods[0].measurement.cells.window
    entered = sum((o.flow[0] + o.flow[1]) * T for o in loops)          # per station
    left_sensor = round(sum((c.outflow_h + c.outflow_a) * T for c in cells))
    left_sumo, _, _ = edge_left(tmp_path / EDGEDATA_FILE, layout.section_edges[-1])
    assert left_sumo > 20
    assert abs(left_sensor - left_sumo) <= 1
    assert abs(round(entered[-1]) - left_sumo) <= layout.lanes
    # in through the x = 0+ loop, out through x = L-: what stayed is on the section
    assert abs(round(entered[0] - entered[-1]) - inside) <= 2 * layout.lanes + 2
    # the loops' ASM estimate on SUMO's cells, over the last 60 s
    t = np.array([c.t for c in cells])
    late = t >= t[-1] - 60
    est = smooth(data_points(loops), cells[0].x, t[late])
    edie = np.array([c.rho_h + c.rho_a for c in cells])[late]
    rho = est[:, 0] + est[:, 2]
    err = abs(np.nanmean(rho) - edie.mean()) / edie.mean()
    assert err < 0.25, (np.nanmean(rho) * 1000, edie.mean() * 1000)


@pytest.mark.sumo
@pytest.mark.parametrize("which", ["a", "b"])
@pytest.mark.parametrize("controller", ["open", "etc"])
def test_runs_to_the_end(which, controller, net_a, net_b):
    path = net_a if which == "a" else net_b
    res = arzsumo.run(str(path), controller=controller, seed=1, horizon_s=20, warmup_s=30)
    s = res.summary.to_dict()
    assert s["complete"] and not s["collisions"]       # None: [sumo] collision_check off
    assert isinstance(s["plan_changes"], int) and s["plan_changes"] >= 0
    micro = res.cells.query("source == 'micro'")
    assert micro["x_m"].max() < res.scenario.params.length
    assert (micro["rho_h"] + micro["rho_a"]).mean() > 0.005      # vehicles on the section


@pytest.mark.sumo
def test_trip_measures_tell_ramp_vehicles_by_route(net_a):
    """The user's ramp flow is ``r_car`` (route onramp ramp_link mrg out): its vehicles
    are the ramp's in every trip measure and have a wait at the meter."""
    import gzip
    import xml.etree.ElementTree as ET

    drained = _variant(net_a, "[sumo]", "[sumo]\ndrain_max_s = 20")
    res = arzsumo.run(str(drained), controller="open", seed=1, horizon_s=20, warmup_s=30)
    s = res.summary.to_dict()
    trips = ET.fromstring(gzip.decompress(res.cosim.network.tripinfo_gz)).iter("tripinfo")
    ids = [t.get("id") for t in trips]
    ramp = sum(i.startswith("r_car.") for i in ids)
    assert ramp >= 15                                           # one every 4 s over 70 s
    for block in ("network_whole_run", "network_whole_demand"):
        assert s[block]["vehicles"]["loaded"] == {"mainline": len(ids) - ramp, "ramp": ramp,
                                                  "total": len(ids)}
        assert s[block]["time_spent_s"]["ramp"] > 0
    assert s["network"]["vehicles"]["loaded"]["ramp"] == 13     # due by t = 50 s: 0, 4, .., 48
    wait = s["network_whole_demand"]["ramp_wait_s"]
    assert wait["vehicles"] + wait["not_crossed"] == ramp and wait["vehicles"] >= 10
    assert 0 <= wait["mean"] < 60


def test_identify_fits_on_the_networks_road(net_a):
    """``arzsumo identify`` replays on L and W read from the network, and the scenario it
    writes elsewhere points at the network by absolute paths."""
    from arzsumo.workflows.identify.study import make_setup

    sc = load_scenario(net_a)
    setup = make_setup(sc, [1], [2], horizon=60, warmup=60)
    assert setup.scenario.params.length == pytest.approx(1500.0)
    assert setup.scenario.params.road_width == pytest.approx(7.0)
    table = sc.network.absolute_table(dict(sc.tables["network"]))
    assert table["net_file"] == str(net_a.parent / "two_lane.net.xml")
    assert table["route_files"] == [str(net_a.parent / "demand.rou.xml")]
    assert table["section_edges"] == ["s1", "s2", "s3"]
