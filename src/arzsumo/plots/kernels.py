"""Backstepping kernels K, M (label back4) and inverse kernels L, N (label invback)."""

from __future__ import annotations

from pathlib import Path

import matplotlib.pyplot as plt
import numpy as np
from matplotlib.figure import Figure

from arzsumo.control.kernels import Kernels
from arzsumo.io import atomic_file


def kernels_figure(kernels: Kernels, title: str = "") -> Figure:
    """One panel per kernel component over the triangle 0 <= xi <= x <= L (km), in 1/km."""
    n = kernels.K.shape[0]
    panels = [(f"$k_{i + 1}$", kernels.K[i]) for i in range(n)] + [("$M$", kernels.M)]
    panels += [(f"$\\ell_{i + 1}$", kernels.L[i]) for i in range(n)] + [("$N$", kernels.N)]
    cols = n + 1
    fig, axes = plt.subplots(2, cols, figsize=(3.2 * cols, 6.0), layout="constrained",
                             squeeze=False)
    x_km = kernels.x / 1000.0
    lower = np.tril(np.ones_like(kernels.M, dtype=bool))
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


def write_kernels_plot(path: str | Path, kernels: Kernels, title: str = "") -> Path:
    """Save :func:`kernels_figure` as PNG (atomically)."""
    fig = kernels_figure(kernels, title)
    with atomic_file(path) as tmp:
        fig.savefig(tmp, dpi=110, format="png")
    plt.close(fig)
    return Path(path)
