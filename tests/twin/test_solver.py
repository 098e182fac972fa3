"""The time loop: conservation, steady equilibrium, open loop, control hook, domain guard."""

from __future__ import annotations

import numpy as np
import pytest

from arzsumo.control.base import ConstantControl, Controller, MacroState
from arzsumo.errors import ModelError
from arzsumo.pde import InitialCondition, SolverOptions, initial_fields, simulate
from arzsumo.pde.metrics import deviation_norm
from arzsumo.pde.state import cell_centres, total_vehicles


def _init(eq, cells=200, **ic):
    return initial_fields(InitialCondition(**ic), eq, cell_centres(eq.params.length, cells))


@pytest.mark.parametrize("scheme", ["first", "muscl"])
def test_vehicles_change_only_by_boundary_fluxes_every_step(any_family_eq, scheme):
    """U = 0 and inflow = outflow = q*: the number of vehicles is constant, every step."""
    eq = any_family_eq
    opts = SolverOptions(scheme=scheme, horizon=120.0)
    init = _init(eq, amplitude=0.02)
    dx = eq.params.length / opts.cells
    n0 = float((init[0] + init[2]).sum() * dx)
    worst = [0.0, 0.0]

    def check(t, q, vin, vout):
        worst[0] = max(worst[0], abs(total_vehicles(q, dx) - n0))
        worst[1] = max(worst[1], abs(vin - vout))

    res = simulate(eq, init, options=opts, callback=check)
    assert res.complete and res.steps > 100
    assert worst[0] < 1e-10 * n0                    # 205 vehicles, to rounding
    assert worst[1] < 1e-12                         # inflow equals outflow each step
    assert res.inflow == pytest.approx(eq.q * 120.0, rel=1e-12)


def test_with_constant_u_the_balance_is_the_boundary_flux(base_eq):
    """U = -0.1 veh/s: N(t) = N(0) - 0.1 t exactly (inflow q*, outflow q* + U)."""
    eq = base_eq
    u = -0.1
    opts = SolverOptions(horizon=60.0)
    init = _init(eq, amplitude=0.02)
    dx = eq.params.length / opts.cells
    n0 = float((init[0] + init[2]).sum() * dx)
    errors = []
    res = simulate(eq, init, controller=ConstantControl(u), options=opts,
                   callback=lambda t, q, vi, vo: errors.append(total_vehicles(q, dx)
                                                              - (n0 - u * t)))
    assert res.complete
    assert np.max(np.abs(errors)) < 1e-10 * n0
    assert res.outflow - res.inflow == pytest.approx(u * 60.0, rel=1e-9)
    np.testing.assert_allclose(res.control_u, u)


@pytest.mark.parametrize(("scheme", "flux"), [("first", "hll"), ("muscl", "hll"),
                                              ("first", "rusanov")])
def test_equilibrium_is_a_steady_state_to_rounding(any_family_eq, scheme, flux):
    eq = any_family_eq
    star = np.array([eq.rho_h, eq.v_h, eq.rho_a, eq.v_a])[:, None]
    res = simulate(eq, _init(eq, kind="equilibrium"),
                   options=SolverOptions(scheme=scheme, flux=flux, horizon=100.0))
    rel = np.abs(res.fields - star[None]) / star[None]
    assert res.complete and rel.max() < 1e-12


def test_open_loop_on_paper_base_does_not_settle(base_eq):
    """Sinusoidal stop-and-go under U = 0: the deviation grows, it does not decay."""
    res = simulate(base_eq, _init(base_eq, amplitude=(0.02, -0.02, 0.02, -0.02)),
                   options=SolverOptions(horizon=450.0))
    norm = deviation_norm(base_eq, res.x, res.fields)
    assert res.complete
    assert norm[-1] > 2.0 * norm[0]                 # about 4x at first order, 200 cells
    assert norm[-60:].min() > norm[0]               # still far from equilibrium at the end


class _Recorder(Controller):
    """Returns a large U and records when and with what it was checked."""

    name = "recorder"

    def __init__(self, u: float) -> None:
        super().__init__()
        self.u = u
        self.states: list[MacroState] = []

    def decide(self, state: MacroState) -> float:
        self.states.append(state)
        self.log.record(state.t, self.u, self.u, len(self.states) == 1)
        return self.u


def test_controller_checked_once_per_period_and_saturated(base_eq):
    ctrl = _Recorder(u=10.0)                        # far above the default +q*
    opts = SolverOptions(horizon=20.0, control_period=2.0, u_max=0.2)
    res = simulate(base_eq, _init(base_eq, kind="equilibrium"), controller=ctrl,
                   options=opts)
    assert [s.t for s in ctrl.states] == pytest.approx(np.arange(0.0, 20.0, 2.0))
    assert ctrl.states[0].x.shape == (200,) and ctrl.states[0].rho_h.shape == (200,)
    np.testing.assert_allclose(res.control_u, 0.2)
    np.testing.assert_allclose(res.control_u_requested, 10.0)
    assert res.saturated_time == pytest.approx(20.0)
    # held U: outflow (q* + 0.2) over 20 s while the inflow stays q*
    assert res.outflow - res.inflow == pytest.approx(0.2 * 20.0, rel=1e-9)


def test_leaving_the_domain_stops_with_time_position_variable(base_eq):
    """Metering 20 % below q*: the queue spills back to the inlet, where AO hits its max."""
    opts = SolverOptions(horizon=450.0)
    res = simulate(base_eq, _init(base_eq, kind="equilibrium"),
                   controller=ConstantControl(-0.2 * base_eq.q), options=opts)
    assert not res.complete
    assert res.status.startswith("stopped at t = 253.8")
    assert "AO = 0.85" in res.status and "at or above AO_max = 0.85" in res.status
    assert "at x = 7.5 m (cell 1)" in res.status
    # partial results kept: every output before the stop, plus the last valid state
    assert res.t.size == 255 and 253.0 < res.t[-1] < 253.9
    assert res.fields.shape == (255, 4, 200)
    assert np.all(np.isfinite(res.fields))


def test_closing_the_meter_stops_within_a_step(base_eq):
    res = simulate(base_eq, _init(base_eq, kind="equilibrium"),
                   controller=ConstantControl(-base_eq.q), options=SolverOptions())
    assert not res.complete
    assert "x = 997.5 m (cell 199)" in res.status and "AO = " in res.status
    assert res.t.size == 1                          # only the initial state was valid


def test_initial_state_outside_the_domain_is_refused(base_eq):
    with pytest.raises(ModelError, match=r"largest feasible fraction here is f < 0\.198"):
        _init(base_eq, kind="nonrecurrent", amplitude=0.25)


def test_options_validate_themselves():
    with pytest.raises(ModelError, match="scheme = 'weno' is not allowed"):
        SolverOptions(scheme="weno")
    with pytest.raises(ModelError, match=r"cfl = 1\.5 is not allowed"):
        SolverOptions(cfl=1.5)


def test_inlet_demand_series_sets_the_inflow(base_lin):
    """A class-demand ramp at the inlet: the vehicles entering are its integral."""
    from .demands import inlet_from_demands

    eq = base_lin.equilibrium
    inlet = inlet_from_demands(base_lin, np.array([0.0, 30.0, 60.0]),
                               np.array([eq.q_h, 0.95 * eq.q_h, 0.95 * eq.q_h]),
                               np.array([eq.q_a, eq.q_a, eq.q_a]))
    res = simulate(eq, _init(eq, kind="equilibrium"), inlet=inlet,
                   options=SolverOptions(horizon=60.0))
    expected = eq.q * 60.0 - 0.05 * eq.q_h * (15.0 + 30.0)     # trapezoid of the ramp
    assert res.complete
    assert res.inflow == pytest.approx(expected, rel=2e-3)     # flow interpolated per step


def test_stepper_advances_and_can_be_reset_from_fields(base_eq):
    """The bridge's building block: advance with a held U, read and replace the state."""
    from arzsumo.pde import TwinStepper, TwinStoppedError

    eq = base_eq
    st = TwinStepper(eq, _init(eq, cells=100, amplitude=0.02), SolverOptions(cells=100))
    n0 = st.total_vehicles()
    st.advance(10.0, -0.05)
    assert st.t == 10.0 and st.steps > 10
    assert st.total_vehicles() == pytest.approx(n0 + 0.05 * 10.0, rel=1e-12)
    state = st.macro_state()
    assert state.t == 10.0 and state.x.shape == (100,)
    st.set_state(state)                              # e.g. aggregated SUMO fields
    assert st.total_vehicles() == pytest.approx(n0 + 0.5, rel=1e-12)
    st.advance(12.5, 0.0)
    assert st.t == 12.5
    with pytest.raises(TwinStoppedError, match=r"stopped at t = .* AO = .* x = 995.0 m"):
        st.advance(20.0, -eq.q)                      # meter closed: the outlet jams
    assert st.t < 20.0 and np.all(np.isfinite(st.q))  # last valid state kept
    with pytest.raises(ModelError, match=r"initial = \(4, 3\) is not allowed"):
        st.set_state(np.ones((4, 3)))
