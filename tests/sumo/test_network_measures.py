"""Network-wide measures from SUMO's outputs: real SUMO runs (short) and parsing checks."""

from dataclasses import dataclass
from pathlib import Path

import pytest

from arzsumo.errors import ArzsumoError
from arzsumo.model import get_preset
from arzsumo.sumo.config import SumoConfig
from arzsumo.sumo.network_measures import (
    EDGEDATA_FILE,
    STATISTICS_FILE,
    TRIPINFO_FILE,
    network_options,
    network_summary,
    read_trips,
)
from arzsumo.sumo.paths import SumoError
from arzsumo.sumo.plant import SumoPlant
from arzsumo.sumo.simulation import open_simulation

PARAMS = get_preset("paper_base").params
CFG = SumoConfig(horizon=180.0, step_length=0.2, control_period=1.0)


@dataclass
class Run:
    """A finished run: its network summary, libsumo's counts at the end, and the
    per-step integral of vehicles in the system (on the network plus insertion backlog)."""

    network: dict
    live: dict
    integral_s: dict


def _run(out: Path, green_share: float) -> Run:
    cfg = CFG.with_(green_share=green_share)
    integral = {"mainline": 0.0, "ramp": 0.0}
    with open_simulation(PARAMS, cfg, extra_args=network_options(out), output_dir=out) as sim:
        lib = sim.lib
        plant = SumoPlant(sim, PARAMS.length, cfg, measure=False)
        while sim.time < cfg.horizon - 1e-9:
            plant.step()
            ids = [*lib.vehicle.getIDList(), *lib.simulation.getPendingVehicles()]
            ramp = sum(1 for v in ids if v.startswith("ramp"))
            integral["ramp"] += ramp * cfg.step_length
            integral["mainline"] += (len(ids) - ramp) * cfg.step_length
        live = {"en_route": lib.vehicle.getIDCount(),
                "waiting": len(lib.simulation.getPendingVehicles()),
                "min_expected": lib.simulation.getMinExpectedNumber(),
                "completed": sim.arrived, "inserted": sim.inserted,
                "requested": sim.requested(),
                "requested_ramp": sim.requested(ramp_only=True), "time": sim.time}
    integral["total"] = integral["mainline"] + integral["ramp"]
    return Run(network_summary(out, end_time=cfg.horizon), live, integral)


@pytest.fixture(scope="module")
def runs(tmp_path_factory) -> dict[str, Run]:
    """Always red (green share 0) and always green (1), same seed and demand."""
    base = tmp_path_factory.mktemp("network")
    return {"red": _run(base / "red", 0.0), "green": _run(base / "green", 1.0)}


@pytest.mark.sumo
def test_red_meter_moves_delay_from_the_mainline_to_the_ramp(runs):
    red, green = runs["red"].network, runs["green"].network
    ramp_red = red["depart_delay_s"]["ramp"] + red["waiting_time_s"]["ramp"]
    ramp_green = green["depart_delay_s"]["ramp"] + green["waiting_time_s"]["ramp"]
    # measured (seed 42, 180 s): ramp 4864 s against 0 s; mainline 1237 s against 7917 s
    assert ramp_red > ramp_green + 1000.0
    assert red["time_loss_s"]["mainline"] < 0.5 * green["time_loss_s"]["mainline"]
    assert red["vehicles"]["waiting"]["ramp"] > 0 == green["vehicles"]["waiting"]["ramp"]
    assert red["throughput_veh_h"]["section_outlet"] > green["throughput_veh_h"]["section_outlet"]


@pytest.mark.sumo
@pytest.mark.parametrize("light", ["red", "green"])
def test_vehicle_accounting_closes(runs, light):
    veh, live = runs[light].network["vehicles"], runs[light].live
    for part in ("mainline", "ramp", "total"):
        assert (veh["completed"][part] + veh["en_route"][part] + veh["waiting"][part]
                == veh["loaded"][part])
    assert veh["loaded"]["total"] == veh["loaded"]["mainline"] + veh["loaded"]["ramp"]
    # cross-check against libsumo's own counts at the end of the run
    assert veh["en_route"]["total"] == live["en_route"] > 100
    assert veh["waiting"]["total"] == live["waiting"] > 0
    assert veh["completed"]["total"] == live["completed"] > 50
    assert veh["loaded"]["total"] == live["inserted"] + live["waiting"]
    # requested() is SUMO's own count of loaded vehicles (no drift of the flow periods)
    assert veh["loaded"]["total"] == live["requested"]
    assert veh["loaded"]["ramp"] == live["requested_ramp"]
    assert live["min_expected"] == live["en_route"] + live["waiting"]


@pytest.mark.sumo
@pytest.mark.parametrize("light", ["red", "green"])
def test_time_spent_is_the_integral_of_vehicles_in_the_system(runs, light):
    run = runs[light]
    loaded = run.network["vehicles"]["loaded"]
    for part in ("mainline", "ramp", "total"):
        spent, integral = run.network["time_spent_s"][part], run.integral_s[part]
        assert integral > 0 or loaded[part] == 0
        assert abs(spent - integral) <= CFG.step_length * loaded[part], (part, spent, integral)
    # the backlog counts: without the waiting vehicles' delay the sum would fall short
    delay_waiting = run.network["depart_delay_s"]["total"]
    assert delay_waiting > CFG.step_length * loaded["total"]


@pytest.mark.sumo
def test_fuel_and_throughput_are_in_stated_units(runs):
    net = runs["green"].network
    completed = net["vehicles"]["completed"]["total"]
    assert net["throughput_veh_h"]["network_exit"] == pytest.approx(completed / 180.0 * 3600.0)
    # HBEFA passenger car: tens of grams of fuel per km; CO2 about 3.1 times the fuel mass
    km = net["distance_m"]["total"] / 1000.0
    assert km > completed * 1.0
    assert 25.0 < net["fuel_g"]["total"] / km < 150.0
    assert net["co2_g"]["total"] / net["fuel_g"]["total"] == pytest.approx(3.1, rel=0.05)


# -- parsing on hand-written outputs (no SUMO) ----------------------------------------------

def _write_outputs(d: Path, waiting_in_stats: int = 1) -> None:
    trips = """<tripinfos>
  <tripinfo id="hv_0.0" depart="0.00" departDelay="0.50" arrival="90.00" duration="90.00"
    timeLoss="10.00" waitingTime="2.00" routeLength="1650.00" vType="hv">
    <emissions fuel_abs="80000.00" CO2_abs="250000.00"/></tripinfo>
  <tripinfo id="ramp_hv.0" depart="5.00" departDelay="5.00" arrival="-1.00" duration="95.00"
    timeLoss="40.00" waitingTime="30.00" routeLength="300.00" vType="hv">
    <emissions fuel_abs="20000.00" CO2_abs="62000.00"/></tripinfo>
  <tripinfo id="ramp_hv.1" depart="-1" departDelay="40.00" arrival="-1.00" duration="0.00"
    timeLoss="0.00" waitingTime="0.00" routeLength="4.90" vType="hv">
    <emissions fuel_abs="0.00" CO2_abs="0.00"/></tripinfo>
</tripinfos>"""
    stats = f"""<statistics><performance begin="0.00" end="100.00"/>
  <vehicles loaded="3" inserted="2" running="1" waiting="{waiting_in_stats}"/></statistics>"""
    edges = """<meandata><interval begin="0.00" end="100.00" id="d">
  <edge id="main" left="2"/><edge id="down" left="0"/></interval></meandata>"""
    for name, text in ((TRIPINFO_FILE, trips), (STATISTICS_FILE, stats), (EDGEDATA_FILE, edges)):
        (d / name).write_text(text, encoding="utf-8")


def test_summary_of_known_outputs(tmp_path):
    _write_outputs(tmp_path)
    trips = read_trips(tmp_path / TRIPINFO_FILE)
    assert list(trips["state"]) == ["completed", "en_route", "waiting"]
    assert list(trips["origin"]) == ["mainline", "ramp", "ramp"]
    net = network_summary(tmp_path, end_time=100.0)
    assert net["time_spent_s"] == {"mainline": 90.5, "ramp": 140.0, "total": 230.5}
    assert net["time_loss_s"] == {"mainline": 10.5, "ramp": 85.0, "total": 95.5}
    assert net["depart_delay_s"] == {"mainline": 0.5, "ramp": 45.0, "total": 45.5}
    assert net["fuel_g"] == {"mainline": 80.0, "ramp": 20.0, "total": 100.0}
    assert net["co2_g"]["total"] == 312.0
    assert net["distance_m"] == {"mainline": 1650.0, "ramp": 300.0, "total": 1950.0}
    assert net["vehicles"]["waiting"] == {"mainline": 0, "ramp": 1, "total": 1}
    assert net["throughput_veh_h"] == {"section_outlet": 72.0, "network_exit": 36.0}


@pytest.mark.parametrize(("setup", "match"), [
    (lambda d: _write_outputs(d, waiting_in_stats=0), "counts .* but statistics.xml"),
    (lambda d: (_write_outputs(d), (d / EDGEDATA_FILE).unlink()), "edgedata.xml is missing"),
    (lambda d: None, "tripinfo.xml is missing"),
])
def test_incomplete_outputs_are_refused(tmp_path, setup, match):
    setup(tmp_path)
    with pytest.raises(SumoError, match=match):
        network_summary(tmp_path)


def test_end_time_of_another_run_is_refused(tmp_path):
    _write_outputs(tmp_path)
    with pytest.raises(SumoError, match=r"end_time = 450.0 s but the outputs end at 100.0 s"):
        network_summary(tmp_path, end_time=450.0)


def test_options_never_overwrite_outputs(tmp_path):
    opts = network_options(tmp_path / "new" / "dir")
    assert (tmp_path / "new" / "dir").is_dir()
    assert opts[opts.index("--tripinfo-output.write-undeparted") + 1] == "true"
    assert opts[opts.index("--device.emissions.probability") + 1] == "1"
    (tmp_path / TRIPINFO_FILE).write_text("mine", encoding="utf-8")
    with pytest.raises(ArzsumoError, match=r"already holds \['tripinfo.xml'\]"):
        network_options(tmp_path)
    assert (tmp_path / TRIPINFO_FILE).read_text(encoding="utf-8") == "mine"
