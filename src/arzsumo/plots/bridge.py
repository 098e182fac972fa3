"""Figures of a co-simulation: micro and twin space-time fields side by side, and the
control and meter signals with release instants.

``*_figure`` functions take arrays and return a Figure; :func:`bridge_figures` takes a
:class:`arzsumo.bridge.result.CoSimResult` and returns the three figures of a run by name.
Nothing is written here: :func:`arzsumo.outputs.figures.save_figures` saves them.
"""

from __future__ import annotations

import textwrap
from typing import Any

import matplotlib.pyplot as plt
import numpy as np
from matplotlib.figure import Figure

from arzsumo.units import ms_to_kmh, veh_m_to_veh_km, veh_s_to_veh_h

_LABEL = {"h": ("HVs", 0), "a": ("AVs", 2)}


def side_by_side_figure(t: np.ndarray, x: np.ndarray, panels: dict[str, np.ndarray],
                        cls: str, star: tuple[float, float], title: str = "") -> Figure:
    """Density (veh/km, top) and speed (km/h, bottom) of one class for each source.

    ``panels`` maps a source name to fields (n_t, 4, n_x) in SI; colour scales are shared
    per row so the sources compare directly; empty or stopped cells are grey.
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
        bar = fig.colorbar(mesh, ax=axes[row, :], label=unit)
        bar.ax.axhline(scale(ref), color="k", lw=1, ls="--")
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


def bridge_figures(res: Any) -> dict[str, Figure]:
    """The figures of a co-simulation run, by name: ``fields_h``, ``fields_a``, ``control``.

    Parameters
    ----------
    res : CoSimResult
        Read by attribute (:class:`arzsumo.bridge.result.CoSimResult`): fields in SI, the
        equilibrium (veh/m, m/s), the per-period table and the meter's counts.

    Returns
    -------
    dict of str to Figure
        Open figures; the caller saves and closes them.
    """
    eq = res.equilibrium
    title = f"{res.scenario.name}: {res.settings.controller}, seed {res.sumo.seed}"
    panels = {"SUMO (Edie)": res.micro, "twin replay": res.replay,
              "twin reference": res.reference}
    figs = {f"fields_{cls}": side_by_side_figure(res.t, res.x, panels, cls, star, title)
            for cls, star in (("h", (eq.rho_h, eq.v_h)), ("a", (eq.rho_a, eq.v_a)))}
    p = res.periods
    figs["control"] = signals_figure(p["t"], p["u"], p["u_continuous"],
                                     p["triggered"].astype(bool), p["green_commanded"],
                                     p["green_running"], p["queue"],
                                     res.meter["light_changes"], res.meter["plan_changes"],
                                     title)
    return figs
