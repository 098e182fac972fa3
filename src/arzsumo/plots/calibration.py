"""Figures of open-loop SUMO runs: the calibration (SUMO speeds against area occupancy with
the fitted and paper curves, the mainline outflow against the meter's green share) and
ALINEA's loop (flow against occupancy, the triangular fit, the critical occupancy and the
target of ``arzsumo alinea-target``; occupancy in %, flow in veh/h, a report)."""

from __future__ import annotations

import numpy as np
from matplotlib.figure import Figure

from arzsumo.model.fd import power_law_speed
from arzsumo.plots import plt
from arzsumo.units import ms_to_kmh, veh_s_to_veh_h


def _fd(ao: np.ndarray, v: float, ao_max: float, gamma: float) -> np.ndarray:
    """The power law, drawn at 0 where it would turn negative."""
    return np.maximum(power_law_speed(ao, v, ao_max, gamma), 0.0)


def calibration_figure(points: dict[str, tuple[np.ndarray, np.ndarray]],
                       fitted: dict[str, tuple[float, float, float]],
                       paper: dict[str, tuple[float, float, float]],
                       r2: dict[str, float], curve: tuple[np.ndarray, np.ndarray],
                       equilibrium: tuple[float, float, float] | None = None) -> Figure:
    """Three panels: HV and AV speed (km/h) vs AO, and outflow (veh/h) vs green share.

    ``fitted`` and ``paper`` map class ("h", "a") to (V m/s, AO_max, gamma); ``curve`` is
    (green shares, outflows veh/s); ``equilibrium`` (AO, v_h, v_a m/s) marks SUMO's state.
    """
    fig, axes = plt.subplots(1, 3, figsize=(14, 4.4), layout="constrained")
    names = {"h": "HV", "a": "AV"}
    for ax, cls in zip(axes[:2], ("h", "a"), strict=True):
        ao, v = points[cls]
        ax.plot(ao, ms_to_kmh(v), ".", ms=3, alpha=0.35, color="0.4", label="SUMO cells")
        grid = np.linspace(0.0, max(1.0, float(ao.max()) if ao.size else 1.0), 200)
        ax.plot(grid, ms_to_kmh(_fd(grid, *fitted[cls])), "C0", lw=2,
                label=f"fit (R² = {r2[cls]:.2f})")
        ax.plot(grid, ms_to_kmh(_fd(grid, *paper[cls])), "C3--", lw=1.5, label="paper")
        if equilibrium is not None:
            ax.plot(equilibrium[0], ms_to_kmh(equilibrium[1 if cls == "h" else 2]), "k*",
                    ms=12, label="medium demand, nominal meter")
        ax.set_xlabel("area occupancy AO")
        ax.set_ylabel(f"{names[cls]} speed (km/h)")
        ax.set_title(f"{names[cls]} speed against AO")
        ax.set_xlim(0, grid[-1])
        ax.set_ylim(0, None)
        ax.legend(fontsize=8)
    g, q = curve
    axes[2].plot(g, veh_s_to_veh_h(np.asarray(q)), "o-", color="C2")
    axes[2].set_xlabel("meter green share")
    axes[2].set_ylabel("mainline outflow q(L) (veh/h)")
    axes[2].set_title("Outflow against green share (medium demand)")
    axes[2].grid(alpha=0.3)
    return fig


def loop_curve_figure(occupancy: np.ndarray, flow: np.ndarray, centres: np.ndarray,
                      mean: np.ndarray, fit: tuple[np.ndarray, np.ndarray], critical: float,
                      target: float, title: str, lower_bound: bool = False) -> Figure:
    """Period means (occupancy fraction, flow veh/s), the binned mean, the fitted curve
    ``fit`` (occupancies, flows) and the critical occupancy and target (fractions);
    ``lower_bound``: the critical occupancy is only a lower bound (no peak in the data)."""
    fig, ax = plt.subplots(figsize=(7, 4.6), layout="constrained")
    ax.plot(100 * occupancy, veh_s_to_veh_h(flow), ".", ms=4, alpha=0.4, color="0.45",
            label="period means")
    ax.plot(100 * centres, veh_s_to_veh_h(mean), "C0o-", ms=3, lw=1, label="bin mean")
    ax.plot(100 * fit[0], veh_s_to_veh_h(fit[1]), "C3", lw=2, label="triangular fit")
    what = "critical >=" if lower_bound else "critical"
    ax.axvline(100 * critical, color="C3", ls="--", label=f"{what} {100 * critical:.1f} %")
    ax.axvline(100 * target, color="C2", ls="-.", label=f"target {100 * target:.1f} %")
    ax.set_xlabel("loop occupancy (%)")
    ax.set_ylabel("loop flow (veh/h)")
    ax.set_title(title)
    ax.legend(fontsize=8)
    return fig
