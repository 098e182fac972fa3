"""Order of accuracy on a smooth small perturbation, by self-convergence under refinement.

The perturbation is a smooth bump inside the road, compatible with the boundary
conditions (equilibrium at both ends at t = 0); by t = 40 s its waves have reached both
boundaries, so the boundary closures are part of what is measured.
"""

from __future__ import annotations

import itertools

import numpy as np
import pytest

from arzsumo.pde import InitialCondition, SolverOptions, initial_fields, simulate
from arzsumo.pde.state import cell_centres

T = 40.0
AMP = 0.01


def _bump(x: np.ndarray) -> np.ndarray:
    s = np.clip((x - 300.0) / 400.0, 0.0, 1.0)
    return np.sin(np.pi * s) ** 4


def _final(eq, star, cells: int, scheme: str) -> np.ndarray:
    x = cell_centres(eq.params.length, cells)
    shape = np.array([1.0, -1.0, 1.0, -0.5])[:, None] * _bump(x)[None, :]
    ic = InitialCondition("array", fields=tuple(star * (1.0 + AMP * shape)))
    opts = SolverOptions(cells=cells, scheme=scheme, horizon=T, output_period=T, cfl=0.8)
    res = simulate(eq, initial_fields(ic, eq, x), options=opts)
    assert res.complete
    return res.fields[-1]


def observed_orders(eq, star, scheme: str, grids=(100, 200, 400, 800)) -> np.ndarray:
    """log2 of successive ratios of |u_n - R u_2n|_1 (R: average onto the coarse grid)."""
    sols = [_final(eq, star, n, scheme) for n in grids]
    diffs = []
    for coarse, fine in itertools.pairwise(sols):
        restricted = fine.reshape(4, coarse.shape[1], 2).mean(axis=2)
        diffs.append(np.mean(np.abs((coarse - restricted) / star)))
    diffs = np.array(diffs)
    return np.log2(diffs[:-1] / diffs[1:])


@pytest.mark.slow
def test_first_order_scheme_converges_at_order_one(base_eq, star):
    # first order approaches 1 from below (0.68, 0.81, 0.89 from 200 to 3200 cells)
    orders = observed_orders(base_eq, star, "first", (800, 1600, 3200))
    assert 0.8 < orders[-1] < 1.2, orders


@pytest.mark.slow
def test_muscl_converges_at_order_two(base_eq, star):
    orders = observed_orders(base_eq, star, "muscl")
    assert orders[-1] > 1.75, orders
    assert orders[-1] < 2.5, orders
