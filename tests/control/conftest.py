"""Fixtures shared by the controller tests: the paper_base linearisation and its kernels."""

import pytest

from arzsumo.control.kernels import solve_kernels
from arzsumo.model import PRESETS, equilibrium_from_densities, linearize

N_CELLS = 200


@pytest.fixture(scope="session")
def lin():
    p = PRESETS["paper_base"]
    return linearize(equilibrium_from_densities(p.params, p.rho_h, p.rho_a))


@pytest.fixture(scope="session")
def kernels(lin):
    return solve_kernels(lin.system, N_CELLS)
