"""Figures of a twin run: space-time fields per class (the paper's figures open-loop and
cl_event, as heatmaps) and the control input with release instants (figure event-control);
:func:`twin_figures` gives them by name.
"""

from __future__ import annotations

from typing import Any

import matplotlib.pyplot as plt
import numpy as np
from matplotlib.figure import Figure

from arzsumo.units import ms_to_kmh, veh_m_to_veh_km, veh_s_to_veh_h

_CLASS = {"h": ("HVs", 0), "a": ("AVs", 2)}


def fields_figure(t: np.ndarray, x: np.ndarray, fields: np.ndarray, cls: str,
                  star: tuple[float, float], title: str = "") -> Figure:
    """Density (veh/km) and speed (km/h) of class ``cls`` over (x, t), with the equilibrium.

    ``t`` output times (s), ``x`` cell centres (m), ``fields`` (n_t, 4, n_x) in SI; ``star``
    (rho* veh/m, v* m/s) of the class is marked on the colour bars.
    """
    label, k = _CLASS[cls]
    rho = veh_m_to_veh_km(fields[:, k])
    v = ms_to_kmh(fields[:, k + 1])
    fig, axes = plt.subplots(1, 2, figsize=(11, 4.2), layout="constrained", sharey=True)
    for ax, data, name, unit, ref, cmap in (
            (axes[0], rho, "density", "veh/km", veh_m_to_veh_km(star[0]), "viridis"),
            (axes[1], v, "speed", "km/h", ms_to_kmh(star[1]), "plasma")):
        mesh = ax.pcolormesh(x / 1000.0, t, data, shading="auto", cmap=cmap)
        bar = fig.colorbar(mesh, ax=ax, label=f"{name} ({unit})")
        bar.ax.axhline(ref, color="w", lw=2)
        bar.ax.axhline(ref, color="k", lw=0.8, ls="--")
        ax.set_xlabel("x (km)")
        ax.set_title(f"{label} {name} (equilibrium {ref:.1f} {unit}, dashed on bar)")
    axes[0].set_ylabel("t (s)")
    if title:
        fig.suptitle(title)
    return fig


def control_figure(control_t: np.ndarray, u_applied: np.ndarray, events: np.ndarray,
                   u_continuous: np.ndarray | None = None, u_range: tuple[float, float] |
                   None = None, norm_t: np.ndarray | None = None,
                   norm: np.ndarray | None = None, release: float | None = None,
                   title: str = "") -> Figure:
    """Control input U (veh/h) held between checks, events, and the deviation norm.

    ``u_continuous`` (the continuous law at each check, e.g. backstepping beside ETC) is
    drawn dashed when given; release instants (events) are marked below.
    """
    rows = 3 if norm is not None else 2
    fig, axes = plt.subplots(rows, 1, figsize=(9, 2.6 * rows + 0.6), layout="constrained",
                             sharex=True, height_ratios=[3, 1, 2][:rows])
    ax = axes[0]
    ax.step(control_t, veh_s_to_veh_h(u_applied), where="post", lw=1.6, label="applied U")
    if u_continuous is not None and np.any(u_continuous != u_applied):
        ax.plot(control_t, veh_s_to_veh_h(u_continuous), "--", lw=1.0, label="continuous law")
    if u_range is not None:          # draw the saturation bounds only when U comes near
        reach = float(np.max(np.abs(u_applied))) if u_applied.size else 0.0
        for bound in u_range:
            if abs(bound) <= 1.5 * reach:
                ax.axhline(veh_s_to_veh_h(bound), color="0.5", lw=0.8, ls=":",
                           label="saturation" if bound == u_range[0] else None)
    ax.set_ylabel("U (veh/h)")
    ax.legend(loc="upper right")
    ax.grid(alpha=0.3)
    ax = axes[1]
    ax.vlines(control_t[events], 0, 1, lw=0.8)
    ax.set_yticks([])
    ax.set_ylabel("events")
    text = f"{int(events.sum())} updates of U (release instants)"
    if release is not None:
        text += f", total release time {release:.0f} s"
    ax.set_title(text, fontsize=9)
    if norm is not None and norm_t is not None:
        ax = axes[2]
        ax.semilogy(norm_t, norm, lw=1.4)
        ax.set_ylabel("relative L2\ndeviation")
        ax.grid(alpha=0.3, which="both")
    axes[-1].set_xlabel("t (s)")
    if title:
        fig.suptitle(title)
    return fig


def twin_figures(run: Any) -> dict[str, Figure]:
    """The open figures of a twin ``run`` (a :class:`~arzsumo.engines.twin.TwinRun`, read
    by attribute), by name: ``fields_h``, ``fields_a``, ``control``."""
    r, eq = run.result, run.scenario.equilibrium
    tag = f"{run.scenario.name}, {r.controller.name}"
    if not r.complete:
        tag += " (INCOMPLETE)"
    figs = {"fields_h": fields_figure(r.t, r.x, r.fields, "h", (eq.rho_h, eq.v_h), tag),
            "fields_a": fields_figure(r.t, r.x, r.fields, "a", (eq.rho_a, eq.v_a), tag)}
    log = r.controller.log
    cont = np.asarray(log.u_continuous) if len(log.u_continuous) == r.control_t.size else None
    figs["control"] = control_figure(r.control_t, r.control_u, run.events, cont, r.u_range,
                                     r.t, run.norm, run.release_time, tag)
    return figs
