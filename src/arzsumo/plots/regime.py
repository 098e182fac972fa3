"""Regime map over equilibrium densities (paper, figure congestedregion)."""

from __future__ import annotations

import matplotlib.pyplot as plt
import numpy as np
from matplotlib.colors import TwoSlopeNorm
from matplotlib.figure import Figure

from arzsumo.model.regime import RegimeMap
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
