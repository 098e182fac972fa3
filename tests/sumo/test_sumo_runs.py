"""Integration tests with the real SUMO (libsumo), short horizons, one run at a time."""

import numpy as np
import pytest

from arzsumo.bridge.actuator import command_meter
from arzsumo.model import get_preset
from arzsumo.sumo.calibrate import run_fixed_meter
from arzsumo.sumo.config import SumoConfig
from arzsumo.sumo.measure import MainlineSensor
from arzsumo.sumo.network import MAIN, RAMP_UP
from arzsumo.sumo.paths import SumoError
from arzsumo.sumo.placement import place_vehicles
from arzsumo.sumo.plant import SumoPlant
from arzsumo.sumo.simulation import open_simulation
from tests.sumo import run_until

pytestmark = pytest.mark.sumo

PARAMS = get_preset("paper_base").params
FAST = SumoConfig(horizon=40.0, step_length=0.2, control_period=1.0)


def test_vehicles_are_conserved():
    cfg = FAST.with_(horizon=100.0, ramp_demand=1500 / 3600, collision_check=True)
    checked = 0
    with open_simulation(PARAMS, cfg) as sim:
        plant = SumoPlant(sim, PARAMS.length, cfg, measure=False)
        while sim.time < cfg.horizon:
            plant.step()
            if round(sim.time / cfg.step_length) % 50 == 0:
                r = sim.take_report()
                assert r.requested == r.inserted + r.waiting
                assert r.inserted == r.arrived + r.on_network
                ramp_waiting = sum(1 for v in sim.lib.simulation.getPendingVehicles()
                                   if v.startswith("ramp"))
                assert r.requested_ramp == r.inserted_ramp + ramp_waiting
                checked += 1
    r = sim.report
    assert checked >= 9 and r.requested > 190 and r.arrived > 10
    assert r.requested == r.inserted + r.waiting
    assert r.inserted == r.arrived + r.on_network
    assert r.teleports == 0 and r.collisions == 0 and r.emergency_stops == 0
    assert r.requested_ramp > 30 and r.delivered_main == 1.0


def test_no_emergency_braking_without_merging_traffic():
    """Emergency braking is read from SUMO's statistics (-1 when it is not there). SUMO
    reports a few at the merge when the ramp has traffic; with none, nobody brakes hard."""
    cfg = FAST.with_(horizon=100.0, ramp_demand=0.0, collision_check=True)
    r = run_fixed_meter(PARAMS, cfg, measure=False).report
    assert r.requested > 150 and r.requested_ramp == 0
    assert r.requested == r.inserted + r.waiting and r.inserted == r.arrived + r.on_network
    assert r.emergency_braking == 0 and r.emergency_stops == 0 and r.collisions == 0


def test_edie_density_of_single_step_is_count_over_length():
    cfg = FAST.with_(horizon=30.0)
    with open_simulation(PARAMS, cfg) as sim:
        run_until(sim, 25.0)
        sensor = MainlineSensor(sim.lib, PARAMS.length, 50.0, cfg.step_length, 1)
        data = sensor.collect(sim.step())
        ids = sim.lib.edge.getLastStepVehicleIDs(MAIN)
        pos = np.array([sim.lib.vehicle.getLanePosition(v) for v in ids])
        av = np.array([sim.lib.vehicle.getTypeID(v) == "av" for v in ids])
    assert data is not None and len(ids) >= 30
    bins = np.arange(0.0, 1000.1, 50.0)
    count_h = np.histogram(np.minimum(pos[~av], 999.9), bins)[0]
    count_a = np.histogram(np.minimum(pos[av], 999.9), bins)[0]
    np.testing.assert_allclose(data.rho_h, count_h / 50.0, rtol=0, atol=1e-12)
    np.testing.assert_allclose(data.rho_a, count_a / 50.0, rtol=0, atol=1e-12)


def test_always_red_holds_ramp_and_always_green_releases_it():
    cfg = FAST.with_(horizon=50.0, ramp_demand=1200 / 3600)
    red = run_fixed_meter(PARAMS, cfg, 0.0, measure=False)
    green = run_fixed_meter(PARAMS, cfg, 1.0, measure=False)
    assert red.ramp_passed == 0 and red.meter["light_changes"] == 0
    assert red.meter["max_queue"] >= 5
    assert green.ramp_passed >= 5 and green.meter["light_changes"] == 0
    assert green.meter["max_queue"] < red.meter["max_queue"]


def test_meter_counts_plan_and_light_changes():
    cfg = FAST.with_(horizon=30.0, meter_cycle=6.0, min_green=1.0, min_red=1.0)
    with open_simulation(PARAMS, cfg) as sim:
        plant = SumoPlant(sim, PARAMS.length, cfg, measure=False)
        meter = plant.meter                           # nominal green share 0.5
        assert meter.set_green_share(0.5) is False    # same timing: no plan change
        for _ in range(round(12.0 / cfg.step_length)):
            plant.step()
            states = sim.lib.trafficlight.getRedYellowGreenState("meter")
            assert states == meter.light
        assert meter.light_changes == 4               # two cycles: G->r, r->G, G->r, r->G
        assert command_meter(meter, 1e6, 0.0) == 0.0  # more outflow than possible: all red
        assert meter.plan_changes == 1
    sat = cfg.with_(green_share_min=0.2, green_share_max=0.8)
    with open_simulation(PARAMS, sat) as sim:
        meter = SumoPlant(sim, PARAMS.length, sat, measure=False).meter
        assert command_meter(meter, 1e6, 0.0) == pytest.approx(0.2, abs=0.02)
        assert command_meter(meter, 0.0, 0.0) == pytest.approx(0.8, abs=0.02)
        assert meter.plan_changes == 2
        run_until(sim, 30.0)


def test_meter_window_restarts_the_counts_but_not_the_light():
    cfg = FAST.with_(horizon=30.0, meter_cycle=6.0, min_green=1.0, min_red=1.0)
    with open_simulation(PARAMS, cfg) as sim:
        plant = SumoPlant(sim, PARAMS.length, cfg, measure=False)
        meter = plant.meter
        command_meter(meter, 1e6, 0.0)                # all red from the next cycle on
        for _ in range(round(12.0 / cfg.step_length)):
            plant.step()
        light, plan = meter.light, meter.green_share
        closed = meter.start_window()
        assert closed["plan_changes"] == 1 and closed["light_changes"] == 1   # G->r once
        assert (meter.plan_changes, meter.light_changes, meter.max_queue) == (0, 0, 0)
        assert (meter.light, meter.green_share) == (light, plan)
        assert command_meter(meter, 0.0, 0.0) == 1.0  # all green from the next cycle on
        for _ in range(round(7.0 / cfg.step_length)):
            plant.step()
        assert meter.plan_changes == 1 and meter.light_changes == 1          # r->G once
        assert meter.max_queue >= meter.queue              # the window's own maximum


def test_same_seed_gives_identical_cells_and_another_seed_differs():
    cfg = FAST.with_(horizon=30.0, seed=11)
    a = run_fixed_meter(PARAMS, cfg).measurements
    b = run_fixed_meter(PARAMS, cfg).measurements
    c = run_fixed_meter(PARAMS, cfg.with_(seed=12)).measurements
    for name in ("rho_h", "rho_a", "q_h", "q_a", "outflow_h", "inflow_a"):
        np.testing.assert_array_equal(a.array(name), b.array(name))
    assert len(a.records) == 30
    assert not np.array_equal(a.array("q_h"), c.array("q_h"))


def test_placement_reproduces_target_density_within_5_percent_per_100m():
    x = np.arange(25.0, 1000.0, 50.0)
    rho_h = np.where(x < 500, 0.110, 0.080)
    rho_a = np.where(x < 300, 0.100, 0.060)
    v_h, v_a = np.full_like(x, 10.0), np.full_like(x, 8.0)
    cfg = FAST.with_(demand_h=0.0, demand_a=0.0, ramp_demand=0.0, horizon=1.0)
    veh, rep = place_vehicles(PARAMS, cfg, x, rho_h, v_h, rho_a, v_a)
    with open_simulation(PARAMS, cfg, initial=veh) as sim:
        sensor = MainlineSensor(sim.lib, PARAMS.length, 100.0, cfg.step_length, 1)
        data = sensor.collect(sim.step())
        r = sim.take_report()
    assert r.inserted == len(veh) == rep.n_h + rep.n_a
    target_h = rho_h.reshape(10, 2).mean(axis=1)
    target_a = rho_a.reshape(10, 2).mean(axis=1)
    np.testing.assert_allclose(data.rho_h, target_h, rtol=0.05)
    np.testing.assert_allclose(data.rho_a, target_a, rtol=0.05)


def test_lifecycle_close_twice_one_at_a_time_and_errors_in_one_line():
    sim = open_simulation(PARAMS, FAST)
    try:
        with pytest.raises(SumoError, match="another SUMO simulation is open"):
            open_simulation(PARAMS, FAST)
        sim.step()
    finally:
        sim.close()
    sim.close()                                        # safe twice
    with pytest.raises(SumoError, match="not running"):
        sim.step()
    with pytest.raises(SumoError) as info:
        open_simulation(PARAMS, FAST, extra_args=["--no-such-option", "1"])
    assert "SUMO did not start" in str(info.value) and "\n" not in str(info.value)
    with open_simulation(PARAMS, FAST) as again:       # libsumo restarts in one process
        run_until(again, 2.0)
        r = again.take_report()
        # counts start again from zero; in 2 s no vehicle leaves the edge it entered
        assert r.time == pytest.approx(2.0) and r.inserted == r.on_network > 0
        assert again.lib.edge.getLastStepVehicleNumber(RAMP_UP) == r.inserted_ramp
        assert again.lib.edge.getLastStepVehicleNumber(MAIN) == r.inserted - r.inserted_ramp
    assert again.closed


def test_teleports_counted_when_enabled():
    cfg = FAST.with_(horizon=40.0, time_to_teleport=5.0, ramp_demand=1800 / 3600)
    res = run_fixed_meter(PARAMS, cfg, 0.0, measure=False)   # red: ramp queue stands
    assert res.report.teleports > 0
    # vehicles in a teleport still count as on the network
    assert res.report.inserted == res.report.arrived + res.report.on_network


def test_spillback_override_releases_a_long_queue():
    cfg = FAST.with_(horizon=50.0, ramp_demand=1200 / 3600, ramp_storage=4)
    res = run_fixed_meter(PARAMS, cfg, 0.0, measure=False)
    assert res.meter["override_steps"] > 0 and res.ramp_passed > 0
    assert res.meter["max_queue"] >= 4


def test_plan_changes_count_requests_and_light_changes_count_green_edges():
    """The counts as docs/outputs.md defines them: two timings asked within one cycle are
    two plan changes and only the last runs; a yellow is not a light change."""
    cfg = FAST.with_(horizon=30.0, meter_cycle=6.0, min_green=1.0, min_red=1.0,
                     meter_clearance=1.0)
    with open_simulation(PARAMS, cfg) as sim:
        plant = SumoPlant(sim, PARAMS.length, cfg, measure=False)
        meter = plant.meter                       # nominal green share 0.5
        assert command_meter(meter, 1e6, 0.0) == 0.0            # all red asked ...
        assert command_meter(meter, -1e6, 0.0) == 1.0           # ... then all green
        shown = []
        for _ in range(round(18.0 / cfg.step_length)):
            plant.step()
            shown.append(meter.light)
    assert meter.plan_changes == 2
    # the first cycle runs the nominal plan (G, y, r: one change at G->y, one at r->G),
    # then all green: no red ever again
    last = round(12.0 / cfg.step_length)
    assert "y" in shown and shown[-last:] == ["G"] * last
    assert meter.light_changes == 2


def test_a_mainline_vehicle_held_still_is_the_longest_standstill_and_told(caplog,
                                                                          monkeypatch):
    """A mainline vehicle stopped by hand stands longest; at the end it is named as a
    deadlock once its standstill passes the threshold."""
    from arzsumo.sumo import simulation

    monkeypatch.setattr(simulation, "DEADLOCK_S", 30.0)
    cfg = FAST.with_(horizon=100.0, ramp_demand=0.0, collision_check=True)
    with caplog.at_level("WARNING", logger="arzsumo.sumo.simulation"), \
            open_simulation(PARAMS, cfg) as sim:
        run_until(sim, 20.0)
        veh = sim.lib.vehicle
        held = max((v for v in veh.getIDList() if not v.startswith("ramp")),
                   key=veh.getLanePosition)           # the front one: nothing ahead
        veh.setSpeed(held, 0.0)
        stopped = None
        while sim.time < 90.0 - 1e-9:
            sim.step()
            if stopped is None and veh.getSpeed(held) < 0.1:
                stopped = sim.time
        rep = sim.take_report()
    assert stopped is not None and stopped < 40.0
    assert rep.standstill_vehicle == held
    assert abs(rep.standstill_main_s - (90.0 - stopped)) <= 2 * cfg.step_length
    told = [r.getMessage() for r in caplog.records if "SUMO deadlock" in r.getMessage()]
    assert len(told) == 1 and held in told[0]


def test_a_flowing_run_stands_nobody_still_for_long():
    cfg = FAST.with_(horizon=60.0, ramp_demand=0.0)
    with open_simulation(PARAMS, cfg) as sim:
        run_until(sim, 60.0)
        rep = sim.take_report()
    assert rep.on_network > 20 and rep.standstill_main_s < 5.0


def test_the_collision_check_changes_no_vehicle_and_is_off_by_default():
    """SUMO's collision check with ``warn`` changes no vehicle: the same trajectories to
    the last bit without it (a third of the sublane step saved); its count is None then."""
    cfg = FAST.with_(horizon=60.0, ramp_demand=1200 / 3600)
    assert not cfg.collision_check and cfg.collision_options == {"collision.action": "none"}
    runs = {}
    for check in (False, True):
        c = cfg.with_(collision_check=check)
        with open_simulation(PARAMS, c) as sim:
            plant, seen = SumoPlant(sim, PARAMS.length, c, measure=False), []
            while sim.time < c.horizon:
                plant.step()
                lib = sim.lib.vehicle
                seen.append(sorted((v, lib.getPosition(v), lib.getSpeed(v),
                                    lib.getLateralLanePosition(v)) for v in lib.getIDList()))
        runs[check] = (seen, sim.report)
    assert runs[False][0] == runs[True][0] and len(runs[True][0][-1]) > 20
    assert runs[False][1].collisions is None and runs[True][1].collisions == 0
