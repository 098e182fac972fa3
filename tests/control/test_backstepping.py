"""Finite-time convergence (first theorem), the law's two forms, and the controller."""

import numpy as np
import pytest

from arzsumo.control.backstepping import Backstepping
from arzsumo.control.base import MacroState
from arzsumo.control.kernels import Kernels, solve_kernels
from arzsumo.control.transform import BacksteppingLaw, BacksteppingTransform
from arzsumo.control.verify import _run, sinusoidal_deviation, verify_backstepping
from arzsumo.model.characteristic import CharacteristicSystem
from tests.control.conftest import N_CELLS


@pytest.fixture(scope="module")
def report(lin, kernels):
    return verify_backstepping(lin, N_CELLS, kernels, growth_horizon=900.0)


def test_finite_time_convergence(report):
    assert report.closed_loop_ratio < 3e-5


def test_no_kernel_law_is_clearly_worse(report):
    assert report.no_kernel_ratio > 100 * report.closed_loop_ratio


def test_open_loop_does_not_decay_and_grows(report):
    assert report.open_loop_ratio > 1.0                 # larger at 450 s than at t = 0
    assert report.open_loop_growth_rate > 1e-3          # 1/s: exponentially unstable


def test_inverse_transform_undoes_the_forward_one(report):
    assert report.inverse_error < 1e-3
    assert report.law_forms_error < 1e-10               # L, N form = K, M form of the law


def _closed_loop_ratio(lin, kernels, system=None):
    system = system or lin.system
    law = BacksteppingLaw(system, kernels)
    w0 = lin.to_riemann(sinusoidal_deviation(lin, kernels.x), kernels.x)
    _, norms = _run(lin, kernels.n_cells, w0, lin.system.t_f + 20, lambda t, w: law.u_bar(w))
    return norms[-1] / norms[0]


@pytest.mark.parametrize("mutation", ["kernel sign", "M boundary condition", "R sign"])
def test_a_wrong_sign_or_boundary_condition_fails_the_check(lin, kernels, mutation):
    s = lin.system
    if mutation == "kernel sign":
        ratio = _closed_loop_ratio(lin, Kernels(kernels.x, -kernels.K, -kernels.M,
                                                kernels.L, kernels.N))
    elif mutation == "M boundary condition":     # M(x, 0) = 0 instead of sum k lambda q / mu
        wrong = CharacteristicSystem(s.lam, s.j_hat, np.zeros(3), s.R, s.length)
        ratio = _closed_loop_ratio(lin, solve_kernels(wrong, N_CELLS))
    else:
        wrong = CharacteristicSystem(s.lam, s.j_hat, s.Q, -s.R, s.length)
        ratio = _closed_loop_ratio(lin, kernels, wrong)
    assert ratio > 3e-5


def test_transform_round_trip_on_the_same_grid(lin, kernels):
    tr = BacksteppingTransform(kernels)
    w0 = lin.to_riemann(sinusoidal_deviation(lin, kernels.x, waves=3), kernels.x)
    back = tr.inverse(*tr.forward(w0))
    np.testing.assert_allclose(back, w0, atol=1e-12 * np.abs(w0).max())


def _state(lin, x, z, t=0.0):
    eq = lin.equilibrium
    return MacroState(t, x, eq.rho_h + z[0], eq.v_h + z[1], eq.rho_a + z[2], eq.v_a + z[3])


def test_controller_applies_the_law_in_physical_units(lin, kernels):
    ctrl = Backstepping(lin, kernels)
    z = sinusoidal_deviation(lin, kernels.x)
    u = ctrl.check(_state(lin, kernels.x, z))
    expected = ctrl.law.u_bar(lin.to_riemann(z, kernels.x)) / lin.u_bar_per_u
    assert u == pytest.approx(expected, rel=1e-12)
    assert ctrl.log.triggers == 1 and ctrl.log.u_applied == [u]
    # the same state on a 50 m grid (cell centres) gives nearly the same U
    xc = np.arange(25.0, 1000.0, 50.0)
    coarse = _state(lin, xc, sinusoidal_deviation(lin, xc))
    assert ctrl.check(coarse) == pytest.approx(u, rel=0.05)
    assert ctrl.check(_state(lin, kernels.x, 0 * z)) == 0.0


def test_registry_builds_every_controller(lin, kernels):
    from arzsumo.control.alinea import Alinea, HeldMeter, PiAlinea, ReleaseRates
    from arzsumo.control.registry import ControllerInputs, controller_names, controller_spec
    from arzsumo.errors import ModelError, ScenarioError

    eq = lin.equilibrium
    x = kernels.x
    z = sinusoidal_deviation(lin, x)
    state = MacroState(0.0, x, eq.rho_h + z[0], eq.v_h + z[1], eq.rho_a + z[2], eq.v_a + z[3])
    rates = ReleaseRates(600 / 3600, 240 / 3600, 900 / 3600)
    inputs = ControllerInputs(lin, kernels, constant_u=0.125, rates=rates)
    us = {name: controller_spec(name).build(inputs).check(state)
          for name in controller_names()}
    assert set(us) == {"open", "backstepping", "etc", "observer-etc", "constant", "alinea",
                       "pi-alinea", "held"}
    assert us["open"] == 0.0 and us["constant"] == 0.125
    assert us["alinea"] == us["pi-alinea"] == 0.0              # nominal until a period ends
    assert us["held"] == pytest.approx(360 / 3600)              # r_nominal - r_min
    assert us["backstepping"] == pytest.approx(us["etc"])        # first ETC check is an event
    for name, cls in (("alinea", Alinea), ("pi-alinea", PiAlinea), ("held", HeldMeter)):
        assert type(controller_spec(name).build(inputs)) is cls
    with pytest.raises(ModelError, match="needs the meter's release rates"):
        controller_spec("held").build(ControllerInputs(lin))
    with pytest.raises(ScenarioError, match="controller = 'pid' is not allowed"):
        controller_spec("pid").build(ControllerInputs(lin, kernels))
    with pytest.raises(ModelError, match="needs backstepping kernels"):
        controller_spec("etc").build(ControllerInputs(lin, None))
