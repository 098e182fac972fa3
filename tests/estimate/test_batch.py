"""The batched first-order stepper equals single twin runs, member by member."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import pytest

from arzsumo.estimate.batch import BatchStepper, project
from arzsumo.model.characteristic import linearize
from arzsumo.pde import Inlet, SolverOptions, TwinStepper
from arzsumo.pde.state import to_conserved, to_primitive
from tests.estimate.conftest import default_eq


@dataclass(frozen=True)
class GhostInlet(Inlet):
    """The bridge's inlet: a fixed ghost state at x = 0 (as bridge.twins._GhostInlet)."""

    ghost: tuple = (0.0, 0.0, 0.0, 0.0)

    def boundary_primitive(self, t, z0):
        return np.asarray(self.ghost)


@pytest.mark.parametrize("flux", ["hll", "rusanov"])
def test_member_k_equals_a_single_twin_run(flux):
    eq = default_eq()
    lin, p, cells, m = linearize(eq), eq.params, 40, 5
    star = np.array([eq.rho_h, eq.v_h, eq.rho_a, eq.v_a])
    rng = np.random.default_rng(3)
    x = (np.arange(cells) + 0.5) * p.length / cells
    z0 = star[:, None, None] * (1 + 0.1 * np.sin(2 * np.pi * (x / 600.0 + rng.uniform(
        size=(4, m, 1)))))
    ghost = star[:, None] * (1 + 0.05 * rng.standard_normal((4, m)))
    outflow = eq.q * (1 + 0.2 * rng.standard_normal(m))
    batch = BatchStepper(p, cells, flux, cfl=0.9)
    q, t, times = batch.advance(to_conserved(p, *z0), 0.0, 40.0, ghost, outflow)
    assert t == 40.0 and len(times) > 20 and batch.projected == 0
    for k in range(m):
        single = TwinStepper(eq, z0[:, k], SolverOptions(cells=cells, scheme="first", flux=flux),
                             GhostInlet(eq.rho_h, eq.rho_a, eq.q, lin.T[3], ghost[:, k]))
        for tk in times:
            single.advance(tk, outflow[k] - eq.q)
        assert single.steps == len(times)
        np.testing.assert_allclose(q[:, k], single.q, rtol=1e-12, atol=1e-15)
    z = to_primitive(p, q)
    assert np.abs(z - z0).max(axis=(1, 2)).min() > 1e-3       # the state did move


def test_projection_keeps_physical_states_and_repairs_others():
    p = default_eq().params
    good = np.array([[0.05], [10.0], [0.03], [8.0]])
    np.testing.assert_array_equal(project(p, good), good)
    bad = np.array([[-0.01, 0.2], [-3.0, 40.0], [0.03, 0.2], [np.nan, 5.0]])
    fixed = project(p, bad)
    assert fixed[[0, 2]].min() > 0 and fixed[[1, 3]].min() >= 0
    assert fixed[1, 1] == p.v_free_h and fixed[3, 0] == 0.0
    ao = (p.area_h * fixed[0] + p.area_a * fixed[2]) / p.road_width
    assert ao.max() == pytest.approx(0.98 * p.ao_max)
