"""Figures of a co-simulation: micro and twin space-time fields side by side, and the
control and meter signals with release instants (:func:`bridge_figures`, by name).
"""

from __future__ import annotations

import textwrap
from dataclasses import dataclass
from typing import Any

import matplotlib.pyplot as plt
import numpy as np
from matplotlib import patheffects
from matplotlib.axes import Axes
from matplotlib.figure import Figure
from matplotlib.lines import Line2D

from arzsumo.units import ms_to_kmh, veh_m_to_veh_km, veh_s_to_veh_h

_LABEL = {"h": ("HVs", 0), "a": ("AVs", 2)}


@dataclass(frozen=True)
class TravelGuides:
    """Two directions drawn on space-time fields so a reader tells them apart: the waves'
    measured travel speed (km/h, < 0 upstream; NaN when unresolved) and the vehicles' own
    mean speed (km/h, downstream), along which platoons and density stripes move."""

    wave_kmh: float
    vehicles_kmh: float


def _draw_guides(ax: Axes, x_km: np.ndarray, guides: TravelGuides) -> list[Line2D]:
    """A line of each speed of ``guides`` through the panel's centre, limits kept."""
    xlim, ylim = ax.get_xlim(), ax.get_ylim()
    xc, tc = float(np.mean(xlim)), float(np.mean(ylim))
    xs = np.linspace(float(x_km.min()), float(x_km.max()), 50)
    halo = [patheffects.Stroke(linewidth=3.2, foreground="k"), patheffects.Normal()]
    lines = []
    for speed, style in ((guides.wave_kmh, "-"), (guides.vehicles_kmh, ":")):
        if not np.isfinite(speed) or speed == 0:
            continue
        (line,) = ax.plot(xs, tc + (xs - xc) / (speed / 3600.0), style, color="w", lw=1.6,
                          path_effects=halo)
        lines.append(line)
    ax.set_xlim(xlim)
    ax.set_ylim(ylim)
    return lines


def guide_labels(guides: TravelGuides) -> tuple[str, str]:
    """Legend texts of the wave line and of the vehicles' line."""
    wave = ("waves (speed fluctuations), measured: no travel speed resolved"
            if not np.isfinite(guides.wave_kmh) else
            f"waves (speed fluctuations), measured: {guides.wave_kmh:+.0f} km/h, "
            f"{'upstream' if guides.wave_kmh < 0 else 'downstream'}")
    vehicles = (f"vehicles' mean speed: {guides.vehicles_kmh:+.0f} km/h, downstream; "
                "stripes along it move with the vehicles (groups and gaps), not waves")
    return wave, vehicles


def side_by_side_figure(t: np.ndarray, x: np.ndarray, panels: dict[str, np.ndarray],
                        cls: str, star: tuple[float, float], title: str = "",
                        guides: TravelGuides | None = None) -> Figure:
    """Density (veh/km, top) and speed (km/h, bottom) of one class for each source.

    ``panels`` maps a source name to fields (n_t, 4, n_x) in SI; colour scales are shared
    per row so the sources compare directly; empty or stopped cells are grey; the dashed
    mark on each colour bar is the equilibrium (``star``, veh/m and m/s). ``guides``
    draws the waves' and the vehicles' directions on every panel, with a legend.
    """
    label, k = _LABEL[cls]
    names = list(panels)
    fig, axes = plt.subplots(2, len(names), figsize=(4.2 * len(names), 7.0),
                             layout="constrained", sharex=True, sharey=True, squeeze=False)
    for row, (scale, unit, cmap, ref) in enumerate(
            ((veh_m_to_veh_km, "veh/km", "viridis", star[0]),
             (ms_to_kmh, "km/h", "plasma", star[1]))):
        data = {n: scale(panels[n][:, k + row]) for n in names}
        finite = np.concatenate([d[np.isfinite(d)] for d in data.values()])
        vmin, vmax = (np.percentile(finite, [1, 99]) if finite.size else (0, 1))
        for col, name in enumerate(names):
            ax = axes[row, col]
            ax.set_facecolor("0.8")
            mesh = ax.pcolormesh(x / 1000.0, t, np.ma.masked_invalid(data[name]),
                                 shading="auto", cmap=cmap, vmin=vmin, vmax=vmax)
            ax.set_title(textwrap.fill(f"{name}: {label} "      # long run labels wrap
                                       f"{'density' if row == 0 else 'speed'}", 48),
                         fontsize=9)
            if row == 1:
                ax.set_xlabel("x (km)")
            if col == 0:
                ax.set_ylabel("t since control start (s)")
            if guides is not None:
                drawn = _draw_guides(ax, x / 1000.0, guides)
        bar = fig.colorbar(mesh, ax=axes[row, :],
                           label=f"{unit}; dashed: equilibrium {scale(ref):.0f}")
        bar.ax.axhline(scale(ref), color="k", lw=1, ls="--")
    if guides is not None and drawn:
        wave, vehicles = guide_labels(guides)
        resolved = np.isfinite(guides.wave_kmh)
        fig.legend(drawn, [wave, vehicles] if resolved else [vehicles],
                   title=None if resolved else wave, title_fontsize=9,
                   loc="outside lower center", fontsize=9, facecolor="0.6", framealpha=1.0)
    if title:
        fig.suptitle(title)
    return fig


def signals_figure(t: np.ndarray, u: np.ndarray, u_cont: np.ndarray, events: np.ndarray,
                   green_cmd: np.ndarray, green_run: np.ndarray, queue: np.ndarray,
                   light_changes: float, plan_changes: float, title: str = "") -> Figure:
    """U commanded and continuous (veh/h), green share, ramp queue, release instants.

    ``light_changes`` and ``plan_changes`` are the counts of the control window shown.
    """
    fig, axes = plt.subplots(4, 1, figsize=(10, 9), sharex=True, layout="constrained",
                             gridspec_kw={"height_ratios": [3, 2, 1, 2]})
    axes[0].step(t, veh_s_to_veh_h(u), where="post", label="U commanded")
    axes[0].plot(t, veh_s_to_veh_h(u_cont), "--", lw=1, label="continuous law")
    axes[0].set_ylabel("U (veh/h)")
    axes[0].legend(loc="upper right")
    axes[0].grid(alpha=0.3)
    axes[1].step(t, green_cmd, where="post", label="commanded")
    axes[1].step(t, green_run, where="post", label="running plan", alpha=0.7)
    axes[1].set_ylabel("green share")
    axes[1].set_ylim(-0.05, 1.05)
    axes[1].legend(loc="upper right")
    axes[1].set_title(f"{int(plan_changes)} plan changes, {int(light_changes)} light changes "
                      "in the control window", fontsize=9)
    axes[2].vlines(t[events], 0, 1, lw=0.8)
    axes[2].set_yticks([])
    axes[2].set_ylabel("events")
    axes[2].set_title(f"{int(events.sum())} controller updates (release instants between)",
                      fontsize=9)
    axes[3].plot(t, queue)
    axes[3].set_ylabel("ramp queue (veh)")
    axes[3].set_xlabel("t since control start (s)")
    axes[3].grid(alpha=0.3)
    if title:
        fig.suptitle(title)
    return fig


def bridge_figures(res: Any, wave_kmh: dict[str, float] | None = None) -> dict[str, Figure]:
    """The open figures of a co-simulation run ``res`` (a
    :class:`~arzsumo.bridge.result.CoSimResult`, read by attribute), by name: ``fields_h``,
    ``fields_a``, ``control``. ``wave_kmh``: per class, the measured travel speed of
    SUMO's speed fluctuations (km/h, < 0 upstream; NaN when unresolved), drawn on the
    fields with the vehicles' mean speed so that waves and platoons are told apart."""
    eq = res.equilibrium
    title = f"{res.scenario.name}: {res.settings.controller}, seed {res.sumo.seed}"
    panels = {"SUMO (Edie)": res.micro, "twin replay": res.replay,
              "twin reference": res.reference}
    figs = {}
    for cls, star in (("h", (eq.rho_h, eq.v_h)), ("a", (eq.rho_a, eq.v_a))):
        guides = None
        if wave_kmh is not None:
            v = res.micro[:, _LABEL[cls][1] + 1]
            mean = float(ms_to_kmh(np.nanmean(v))) if np.isfinite(v).any() else np.nan
            guides = TravelGuides(float(wave_kmh.get(cls, np.nan)), mean)
        figs[f"fields_{cls}"] = side_by_side_figure(res.t, res.x, panels, cls, star, title,
                                                    guides)
    p = res.periods
    figs["control"] = signals_figure(p["t"], p["u"], p["u_continuous"],
                                     p["triggered"].astype(bool), p["green_commanded"],
                                     p["green_running"], p["queue"],
                                     res.meter["light_changes"], res.meter["plan_changes"],
                                     title)
    return figs
