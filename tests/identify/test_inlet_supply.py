"""The replay's bounded inlets (``supply``, ``ctm``): a queue at x = 0 keeps the first cell
below the jam, vehicles are conserved, in free flow the inlet is the ghost cell's to the
bit, and behind a congested held state ``ctm`` refills a first cell in free flow."""

from __future__ import annotations

import numpy as np
import pytest

from arzsumo.identify import ReplayData, ReplayOptions, run_replay
from arzsumo.identify.replay import HeldInlet
from arzsumo.identify.synthetic import SyntheticRun, synthetic_data
from arzsumo.model import ModelParameters
from arzsumo.model.equilibrium import Equilibrium
from arzsumo.model.fd import area_occupancy, speed_of_ao
from arzsumo.pde import SolverOptions, TwinStepper, TwinStoppedError
from arzsumo.pde.state import total_vehicles
from arzsumo.pde.supply import ReceivingCapacity

#: the two-stage identification's smoothed-Newell diagram (equal jam occupancies) with
#: almost no relaxation, as stage 2 found it
NEWELL = ModelParameters(family="newell", ao_max_h=0.6728, ao_max_a=0.6728,
                         v_free_h=81.6 / 3.6, v_free_a=61.2 / 3.6, wave_speed_h=33.2 / 3.6,
                         wave_speed_a=32.3 / 3.6, corner=6.0, tau_h=900.0, tau_a=900.0)
CELLS, PERIODS = 50, 120


def _state(p, ao, speeds=None, share_a=0.2):
    """(rho_h, v_h, rho_a, v_a) at occupancy ``ao``, the AVs holding ``share_a`` of it;
    speeds Ve unless given."""
    rho_h = (1 - share_a) * ao * p.road_width / p.area_h
    rho_a = share_a * ao * p.road_width / p.area_a
    v_h, v_a = speeds if speeds is not None else (float(v) for v in speed_of_ao(p, ao))
    return np.array([rho_h, v_h, rho_a, v_a])


@pytest.fixture
def queue_at_inlet():
    """A congested road (AO 0.85 AO_max, at equilibrium) and a held inlet state at 0.9
    AO_max moving at 2 m/s, seven times its equilibrium speed: SUMO's smoothed first cell
    when the queue's tail reaches x = 0 (a queue's density, the arrivals' speed)."""
    z0 = _state(NEWELL, 0.85 * NEWELL.ao_max)
    ghost = _state(NEWELL, 0.9 * NEWELL.ao_max, speeds=(2.0, 2.0))
    x = (np.arange(CELLS) + 0.5) * NEWELL.length / CELLS
    t = np.arange(1, PERIODS + 1) * 1.0
    q0 = z0[0] * z0[1] + z0[2] * z0[3]
    return ReplayData.from_arrays(t, x, np.ones((PERIODS, 4, CELLS)),
                                  np.repeat(z0[:, None], CELLS, axis=1),
                                  np.tile(ghost, (PERIODS, 1)), np.full(PERIODS, q0))


def _stepper(data, inlet_flux):
    p = NEWELL
    eq = Equilibrium(p, float(data.initial[0].mean()), float(data.initial[2].mean()))
    inlet = HeldInlet(eq.rho_h, eq.rho_a, eq.q, np.zeros(4),
                      supply=ReceivingCapacity(p) if inlet_flux != "ghost" else None,
                      sending=inlet_flux == "ctm")
    stepper = TwinStepper(eq, data.initial, SolverOptions(cells=CELLS), inlet)
    return stepper, inlet


def test_old_inlet_pushes_the_first_cell_past_the_jam(queue_at_inlet):
    data = queue_at_inlet
    run = run_replay(NEWELL, data, ReplayOptions(cells=CELLS, inlet="ghost"))
    assert run.stopped is not None and run.stopped <= 10.0
    assert "(cell 0): at or above AO_max" in run.reason
    stepper, inlet = _stepper(data, "ghost")
    inlet.hold(data.inlet[0])
    with pytest.raises(TwinStoppedError, match=r"\(cell 0\): at or above AO_max"):
        stepper.advance(float(data.t[-1]), float(data.outflow[0]) - stepper.q_star)


@pytest.mark.parametrize("inlet_flux", ["supply", "ctm"])
def test_supply_keeps_the_first_cell_below_the_jam_and_conserves(queue_at_inlet, inlet_flux):
    data = queue_at_inlet
    stepper, inlet = _stepper(data, inlet_flux)
    dx = stepper.dx
    n0 = stepper.total_vehicles()
    seen = {"ao": 0.0, "balance": 0.0, "limited": 0, "steps": 0}
    moved = [0.0]

    def check(t, q, vehicles_in, vehicles_out):
        ao = area_occupancy(NEWELL, q[0], q[2])
        seen["ao"] = max(seen["ao"], float(ao.max()))
        moved[0] += vehicles_in - vehicles_out
        seen["balance"] = max(seen["balance"], abs(total_vehicles(q, dx) - n0 - moved[0]))
        seen["limited"] += inlet.theta[0] < 0.9
        seen["steps"] += 1

    for k in range(data.periods):
        inlet.hold(data.inlet[k])
        stepper.advance(float(data.t[k]), float(data.outflow[k]) - stepper.q_star, check)
    assert stepper.t == data.t[-1]
    assert seen["ao"] <= NEWELL.ao_max
    assert seen["ao"] < 0.95 * NEWELL.ao_max
    assert seen["limited"] == seen["steps"] > 100      # the supply bound every step
    assert seen["balance"] < 1e-12 * n0                  # vehicles: to rounding, every step
    assert stepper.total_vehicles() - n0 == pytest.approx(stepper.inflow - stepper.outflow,
                                                          rel=1e-10)
    run = run_replay(NEWELL, data, ReplayOptions(cells=CELLS, inlet=inlet_flux))
    assert run.stopped is None and run.inlet_limited == pytest.approx(data.t[-1])
    assert run.vehicles_in == stepper.inflow and run.vehicles_out == stepper.outflow


@pytest.mark.parametrize("params", [
    ModelParameters(v_free_h=22.0, v_free_a=17.0, ao_max_h=0.8, ao_max_a=0.78,
                    gamma_h=1.6, gamma_a=2.2, tau_h=20.0, tau_a=40.0),
    NEWELL.with_(tau_h=20.0, tau_a=40.0)], ids=["power", "newell"])
def test_in_free_flow_the_supply_inlet_is_the_ghost_cell(params):
    """First cell below its critical occupancy, the held state's demand within capacity:
    the same fluxes, hence the same fields and counts, to the last bit."""
    data = synthetic_data(params, SyntheticRun(0.03, 0.015, inlet=0.1, inlet_speed=0.05),
                          horizon=120.0, period=2.0, options=ReplayOptions(cells=30,
                                                                           inlet="ghost"))
    cap = ReceivingCapacity(params)
    ao = area_occupancy(params, data.fields[:, 0, 0], data.fields[:, 2, 0])
    flux = cap.equilibrium_flux(*_state(params, float(ao.max()))[[0, 2]])
    assert flux < cap(*_state(params, float(ao.max()))[[0, 2]])  # below critical
    held = area_occupancy(params, data.inlet[:, 0], data.inlet[:, 2])
    assert cap.equilibrium_flux(*_state(params, float(held.max()))[[0, 2]]) < cap(
        *_state(params, float(held.max()))[[0, 2]])             # the held state too
    ghost = run_replay(params, data, ReplayOptions(cells=30, inlet="ghost"))
    assert ghost.stopped is None and ghost.vehicles_in > 0
    for inlet_flux in ("supply", "ctm"):
        bounded = run_replay(params, data, ReplayOptions(cells=30, inlet=inlet_flux))
        assert bounded.stopped is None and bounded.inlet_limited == 0.0
        np.testing.assert_array_equal(bounded.fields, ghost.fields)
        assert (bounded.vehicles_in, bounded.vehicles_out) == (ghost.vehicles_in,
                                                                ghost.vehicles_out)


def test_behind_a_congested_held_state_ctm_refills_a_free_first_cell():
    """A queue upstream of x = 0 (held state at equilibrium, 0.5 AO_max) and a road in free
    flow with its outlet metered to that queue's flow: the ghost and supply inlets let in
    the queue's own (sub-capacity) flow and the road stays free; ctm lets in the capacity
    until the first cell is congested, then the supply: the queue enters the road, as a
    queue spilling back from the outlet would."""
    p = NEWELL
    held = _state(p, 0.5 * p.ao_max)
    q_held = held[0] * held[1] + held[2] * held[3]
    free = _state(p, 0.15)
    x = (np.arange(CELLS) + 0.5) * p.length / CELLS
    t = np.arange(1, 301) * 1.0
    data = ReplayData.from_arrays(t, x, np.ones((300, 4, CELLS)),
                                  np.repeat(free[:, None], CELLS, axis=1),
                                  np.tile(held, (300, 1)), np.full(300, q_held))
    first = {}
    for inlet_flux in ("ghost", "supply", "ctm"):
        run = run_replay(p, data, ReplayOptions(cells=CELLS, inlet=inlet_flux))
        assert run.stopped is None
        first[inlet_flux] = float(area_occupancy(p, run.fields[-1, 0, 0],
                                                 run.fields[-1, 2, 0]))
    assert first["ghost"] == first["supply"] < 0.25                 # free flow
    assert first["ctm"] == pytest.approx(0.5 * p.ao_max, rel=0.05)   # the queue's state


def test_an_unknown_inlet_is_refused():
    with pytest.raises(ValueError, match="inlet = 'wall' is not allowed: one of ctm, "
                                         "supply, ghost"):
        ReplayOptions(inlet="wall")
