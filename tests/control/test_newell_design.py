"""The laws' linear-plant checks on the smoothed-Newell family, as on the power law:
finite-time convergence of backstepping, the inverse transform, and design_for /
design_check (only the decay condition esthm #1 fails, and design_for says why)."""

from __future__ import annotations

import pytest

from arzsumo.control.design import design_for
from arzsumo.control.design_check import check_design
from arzsumo.control.kernels import solve_kernels
from arzsumo.control.verify import verify_backstepping
from arzsumo.model.characteristic import CharacteristicSystem

CELLS = 200


@pytest.fixture(scope="module")
def newell_report():
    from arzsumo.model import PRESETS, equilibrium_from_densities, linearize
    from tests.conftest import NEWELL_CHANGES

    p = PRESETS["paper_base"]
    lin = linearize(equilibrium_from_densities(p.params.with_(**NEWELL_CHANGES), p.rho_h,
                                               p.rho_a))
    kernels = solve_kernels(lin.system, CELLS)
    return lin, verify_backstepping(lin, CELLS, kernels, growth_horizon=900.0)


def test_backstepping_converges_in_finite_time_on_newell(newell_report):
    lin, report = newell_report
    assert lin.eigenvalues[3] == pytest.approx(-35 / 3.6, rel=2e-3)   # Newell's wave speed
    assert report.closed_loop_ratio < 1e-4                  # 4.4e-5 at 200 cells
    assert report.no_kernel_ratio > 100 * report.closed_loop_ratio
    assert report.inverse_error < 1e-3 and report.law_forms_error < 1e-10
    assert report.open_loop_ratio > 1.0                      # unstable without control


def test_design_check_on_newell_fails_only_the_decay_condition(newell_lin):
    system = newell_lin.system
    kernels = solve_kernels(system, 40)
    choice = design_for(system, kernels)
    assert check_design(system, kernels, choice.design).failing() == ["esthm #1"]
    assert list(choice.cannot_hold) == ["esthm #1"] and "would have to be" in choice.why[0]
    weak = CharacteristicSystem(system.lam, system.j_hat * 1e-3, system.Q, system.R,
                                system.length)
    weak_choice = design_for(weak, solve_kernels(weak, 40))
    assert weak_choice.feasible
    assert check_design(weak, solve_kernels(weak, 40), weak_choice.design).all_hold
