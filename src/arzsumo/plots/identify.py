"""Figures of an identification (``arzsumo identify``): SUMO against the replay twin of the
identified model in space and time, and predicted against observed per cell (SI arrays)."""

from __future__ import annotations

from collections.abc import Sequence

import matplotlib.pyplot as plt
import numpy as np
from matplotlib.figure import Figure

from arzsumo.units import ms_to_kmh, veh_m_to_veh_km

#: (title, unit, SI -> display) of rho_h, v_h, rho_a, v_a
PANELS = (("HV density", "veh/km", veh_m_to_veh_km), ("HV speed", "km/h", ms_to_kmh),
          ("AV density", "veh/km", veh_m_to_veh_km), ("AV speed", "km/h", ms_to_kmh))


def fields_figure(t: np.ndarray, x: np.ndarray, observed: np.ndarray, predicted: np.ndarray,
                  title: str = "", labels: tuple[str, str] = ("SUMO", "replay twin")
                  ) -> Figure:
    """Heat maps of (rho_h, v_h, rho_a, v_a) over times ``t`` (s) and cell centres ``x``
    (m): ``observed`` (T, 4, N; SI) on the top row, ``predicted`` below, one colour scale
    per variable; NaN (unobserved, or after the twin stopped) is drawn grey."""
    fig, axes = plt.subplots(2, 4, figsize=(16, 7.5), layout="constrained", sharex=True,
                             sharey=True)
    for j, (name, unit, conv) in enumerate(PANELS):
        rows = [conv(observed[:, j]), conv(predicted[:, j])]
        finite = np.concatenate([r[np.isfinite(r)] for r in rows])
        vmin, vmax = np.percentile(finite, [1, 99]) if finite.size else (0.0, 1.0)
        cmap = "viridis" if unit == "veh/km" else "plasma"
        for i, (label, data) in enumerate(zip(labels, rows, strict=True)):
            ax = axes[i, j]
            ax.set_facecolor("0.8")
            mesh = ax.pcolormesh(x / 1000.0, t, np.ma.masked_invalid(data), shading="auto",
                                 cmap=cmap, vmin=vmin, vmax=vmax)
            ax.set_title(f"{label}: {name}", fontsize=10)
            if i == 1:
                ax.set_xlabel("x (km)")
            if j == 0:
                ax.set_ylabel("t since control start (s)")
        fig.colorbar(mesh, ax=axes[:, j], label=unit, location="bottom", shrink=0.9)
    if title:
        fig.suptitle(title)
    return fig


def scatter_figure(observed: Sequence[np.ndarray], predicted: Sequence[np.ndarray],
                   rmse: Sequence[float], title: str = "", max_points: int = 20000,
                   seed: int = 0) -> Figure:
    """Predicted against observed per cell and period (paired values of rho_h, v_h, rho_a,
    v_a, SI), one panel per variable with its relative ``rmse``; at most ``max_points``
    per panel are drawn (a seeded random subset)."""
    rng = np.random.default_rng(seed)
    fig, axes = plt.subplots(1, 4, figsize=(16, 4.4), layout="constrained")
    for j, (name, unit, conv) in enumerate(PANELS):
        obs, pred = conv(np.asarray(observed[j])), conv(np.asarray(predicted[j]))
        if obs.size > max_points:
            pick = rng.choice(obs.size, max_points, replace=False)
            obs, pred = obs[pick], pred[pick]
        ax = axes[j]
        ax.scatter(obs, pred, s=3, alpha=0.25, lw=0)
        both = np.concatenate([obs, pred])
        lo, hi = (float(both.min()), float(both.max())) if both.size else (0.0, 1.0)
        ax.plot([lo, hi], [lo, hi], "k--", lw=1)
        ax.set_xlabel(f"SUMO {name} ({unit})")
        ax.set_ylabel(f"replay twin ({unit})")
        ax.set_title(f"{name}: relative RMSE {rmse[j]:.1%}", fontsize=10)
        ax.grid(alpha=0.3)
    if title:
        fig.suptitle(title)
    return fig
