"""The model's figures: the regime map over equilibrium densities (paper, figure
congestedregion) and the backstepping kernels K, M (label back4) with the inverse kernels
L, N (label invback)."""

from __future__ import annotations

import numpy as np
from matplotlib.colors import TwoSlopeNorm
from matplotlib.figure import Figure

from arzsumo.model.regime import RegimeMap
from arzsumo.plots import plt
from arzsumo.units import ms_to_kmh, veh_m_to_veh_km


def regime_figure(rmap: RegimeMap, point: tuple[float, float] | None = None,
                  title: str = "") -> Figure:
    """lambda_4 (km/h) over (rho_h*, rho_a*) in veh/km, with the lambda_4 = 0 boundary.

    ``point`` (rho_h, rho_a) in veh/m marks an equilibrium.
    """
    rho_h, rho_a = veh_m_to_veh_km(rmap.rho_h), veh_m_to_veh_km(rmap.rho_a)
    lam4 = ms_to_kmh(rmap.lambda_4)
    fig, ax = plt.subplots(figsize=(6.4, 5.0), layout="constrained")
    span = np.nanmax(np.abs(lam4))
    mesh = ax.pcolormesh(rho_h, rho_a, lam4, cmap="RdBu", shading="auto",
                         norm=TwoSlopeNorm(0.0, -span, span))
    ax.contour(rho_h, rho_a, np.ma.masked_invalid(lam4), levels=[0.0], colors="k",
               linewidths=1.5)
    fig.colorbar(mesh, ax=ax, label=r"$\lambda_4$ (km/h)")
    ax.text(0.97, 0.97, "infeasible\n(AO ≥ AO max)", transform=ax.transAxes, ha="right",
            va="top", fontsize=9, color="0.3")
    ax.text(0.05, 0.05, "free\n$\\lambda_4>0$", transform=ax.transAxes, fontsize=10)
    ax.text(0.55, 0.3, "congested\n$\\lambda_4<0$", transform=ax.transAxes, fontsize=10)
    if point is not None:
        ax.plot(veh_m_to_veh_km(point[0]), veh_m_to_veh_km(point[1]), "k*", ms=12,
                label="equilibrium")
        ax.legend(loc="upper center")
    ax.set_xlabel(r"$\rho_h^\star$ (veh/km)")
    ax.set_ylabel(r"$\rho_a^\star$ (veh/km)")
    ax.set_title(title or r"Congested region: $\lambda_4<0$ (red)")
    ax.set_facecolor("0.85")
    return fig


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
