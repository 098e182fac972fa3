"""Piecewise Lagrange interpolation on a uniform grid (kernel solver, plant, observer)."""

from __future__ import annotations

import numpy as np


def lagrange_stencil(nodes: np.ndarray, x_eval: np.ndarray,
                     order: int = 4) -> tuple[np.ndarray, np.ndarray]:
    """Indices and weights for interpolating at ``x_eval`` from ``order`` nearby nodes.

    ``nodes`` is uniform; the stencil is centred on the interval holding each point and
    shifted near the ends (fewer nodes than ``order`` lower the order). Returns
    ``idx, w`` of shape (*x_eval.shape, p) with f(x_eval) = sum(w * f[idx], axis=-1).
    """
    m = nodes.size
    p = min(order, m)
    if p == 1:
        shape = (*x_eval.shape, 1)
        return np.zeros(shape, int), np.ones(shape)
    h = nodes[1] - nodes[0]
    base = np.floor((x_eval - nodes[0]) / h + 1e-9).astype(int)
    start = np.clip(base - (p // 2 - 1), 0, m - p)
    idx = start[..., None] + np.arange(p)
    xs = nodes[idx]
    w = np.ones_like(xs)
    for a in range(p):
        for b in range(p):
            if a != b:
                w[..., a] *= (x_eval - xs[..., b]) / (xs[..., a] - xs[..., b])
    return idx, w


def interpolate(nodes: np.ndarray, values: np.ndarray, x_eval: np.ndarray,
                order: int = 4) -> np.ndarray:
    """Values (C, m) on ``nodes`` interpolated at ``x_eval`` (any shape E): (C, *E)."""
    idx, w = lagrange_stencil(nodes, x_eval, order)
    return np.sum(w * values[:, idx], axis=-1)
