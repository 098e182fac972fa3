"""Fixtures shared by the controller tests: the paper_base linearisation and its kernels."""

import numpy as np
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


def run_norms(plant, t_end, u_bar_fn, sample_every=10.0):
    """Step ``plant`` until ``t_end`` (s); the L2 norm of w-bar about every ``sample_every``
    s, the first at the start and the last at ``t_end``."""
    def norm():
        return float(np.sqrt(np.trapezoid(np.sum(plant.state**2, axis=0), plant.x)))

    norms, next_sample = [norm()], plant.t + sample_every
    while plant.t < t_end - 1e-9:
        plant.step(u_bar_fn)
        if plant.t >= next_sample - 1e-9 or plant.t >= t_end - 1e-9:
            norms.append(norm())
            next_sample += sample_every
    return np.array(norms)
