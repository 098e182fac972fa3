"""Backstepping kernels K, M (label back4) and inverse kernels L, N (label invback)."""

from __future__ import annotations

import numpy as np
from matplotlib.figure import Figure

from arzsumo.plots import plt


def kernels_figure(x: np.ndarray, K: np.ndarray, M: np.ndarray, L: np.ndarray,
                   N: np.ndarray, title: str = "") -> Figure:
    """One panel per kernel component over the triangle 0 <= xi <= x <= L (km), in 1/km.

    ``x`` is the grid (m); ``K`` (n, m, m) and ``M`` (m, m) the kernels of label back4,
    ``L`` and ``N`` the inverse kernels of label invback (1/m), as in
    :class:`arzsumo.control.kernels.Kernels`.
    """
    n = K.shape[0]
    panels = [(f"$k_{i + 1}$", K[i]) for i in range(n)] + [("$M$", M)]
    panels += [(f"$\\ell_{i + 1}$", L[i]) for i in range(n)] + [("$N$", N)]
    cols = n + 1
    fig, axes = plt.subplots(2, cols, figsize=(3.2 * cols, 6.0), layout="constrained",
                             squeeze=False)
    x_km = x / 1000.0
    lower = np.tril(np.ones_like(M, dtype=bool))
    for ax, (label, field) in zip(axes.ravel(), panels, strict=True):
        data = np.where(lower, field * 1000.0, np.nan)       # 1/m -> 1/km
        span = np.nanmax(np.abs(data)) or 1.0
        mesh = ax.pcolormesh(x_km, x_km, data.T, cmap="RdBu_r", vmin=-span, vmax=span,
                             shading="auto")
        fig.colorbar(mesh, ax=ax, shrink=0.8, format="%.2g")
        ax.set_title(f"{label} (1/km)")
        ax.set_xlabel("x (km)")
        ax.set_ylabel(r"$\xi$ (km)")
        ax.set_aspect("equal")
    if title:
        fig.suptitle(title)
    return fig
