"""The section and the detectors placed on it, on the plan and unrolled along x
(``arzsumo network``; the two panels: docs/networks.md).

Every artist that stands for a piece of the road carries a gid, so a test can count them:
``lane:EDGE:K`` (a lane's centre line on the plan), ``cell:K`` (a cell boundary along x),
``loops`` / ``downstream`` / ``light`` (markers, both panels; the along-x panel's end
in ``:x``), ``edge:EDGE`` (an edge's boundary along x), ``ramp:x``.
"""

from __future__ import annotations

from typing import Any

import numpy as np
from matplotlib.axes import Axes
from matplotlib.figure import Figure

from arzsumo.plots import plt

#: colour of each lane role
COLOURS = {"section": "C0", "mainline": "0.55", "ramp": "C1"}
LIGHT = "C3"


def _plan(ax: Axes, road: Any) -> None:
    for i, (edge, role, shape) in enumerate(zip(road.lane_edges, road.lane_roles,
                                                road.lane_shapes, strict=True)):
        k = road.lane_edges[:i].count(edge)
        ax.plot(shape[:, 0], shape[:, 1], color=COLOURS[role], lw=2.2 if role == "section"
                else 1.4, solid_capstyle="butt", gid=f"lane:{edge}:{k}")
    for k, seg in enumerate(road.cells):
        ax.plot(seg[:, 0], seg[:, 1], color="0.2", lw=0.6, gid=f"cellplan:{k}")
    if len(road.loops):
        ax.plot(road.loops[:, 0], road.loops[:, 1], "s", color="C2", ms=5, ls="none",
                gid="loops", label=f"loop stations ({len(road.loop_x)}, one E1 per lane)")
    ax.plot(road.downstream[:, 0], road.downstream[:, 1], "D", color="C4", ms=5, ls="none",
            gid="downstream", label="ALINEA's loop")
    ax.plot(*road.light, "o", color=LIGHT, ms=8, ls="none", gid="light",
            label=f"meter {road.meter_tl}")
    ax.set_aspect("equal")
    ax.set_xlabel("network x (m)")
    ax.set_ylabel("network y (m)")
    ax.set_title("plan (to scale): section blue, mainline past it grey, ramp orange")
    ax.legend(fontsize=7, loc="best")


def _lane_y(road: Any) -> np.ndarray:
    """Centres of the section's lanes across the road, m (lane 0 lowest)."""
    return (np.arange(road.lanes) + 0.5) * (road.width / road.lanes)


def _along(ax: Axes, road: Any) -> None:
    W = road.width
    end = road.edge_starts[-1] + road.edge_lengths[-1]
    ax.axhspan(0.0, W, xmin=0, xmax=1, color="0.92", zorder=0)
    ax.fill_between([0.0, road.length], 0.0, W, color="C0", alpha=0.18, lw=0, zorder=0)
    for y in np.arange(1, road.lanes) * W / road.lanes:
        ax.axhline(y, color="0.5", lw=0.6, ls="--")
    for k, x in enumerate(road.cell_x):
        ax.plot([x, x], [0.0, W], color="0.2", lw=0.6, gid=f"cell:{k}")
    for e, s in zip(road.edges, road.edge_starts, strict=True):
        ax.plot([s, s], [W, 1.6 * W], color="k", lw=1.0, gid=f"edge:{e}")
        ax.annotate(e, (s, 1.6 * W), xytext=(3, 0), textcoords="offset points",
                    fontsize=8, va="top")
    ys = _lane_y(road)
    if road.loop_x.size:
        gx, gy = np.meshgrid(road.loop_x, ys, indexing="ij")
        ax.plot(gx.ravel(), gy.ravel(), "s", color="C2", ms=5, ls="none", gid="loops:x")
    dy = (np.arange(len(road.downstream)) + 0.5) * W / max(len(road.downstream), 1)
    ax.plot(np.full(dy.size, road.downstream_x), dy, "D", color="C4", ms=5, ls="none",
            gid="downstream:x")
    xl = road.join_x + road.light_x
    start = xl - road.ramp_length
    slope = 1.5 * W / max(road.join_x - start, 1e-9)
    ax.plot([start, road.join_x], [-1.5 * W, 0.0], color=COLOURS["ramp"], lw=2,
            gid="ramp:x")
    ax.plot([xl], [-1.5 * W + slope * (xl - start)], "o", color=LIGHT, ms=8,
            gid="light:x")
    ax.set_xlim(min(road.edge_starts[0], start) - 20.0, end + 20.0)
    ax.set_ylim(-1.8 * W, 1.8 * W)
    ax.set_xlabel("x along the mainline (m; the section is [0, L], shaded)")
    ax.set_ylabel("across (m, not to scale)")
    ax.set_title(f"along the section: L = {road.length:g} m, {road.lanes} lane(s), "
                 f"{road.cell_x.size - 1} cells (thin lines), loops per lane (squares)")


def network_figure(road: Any, title: str = "") -> Figure:
    """The section and its detectors, on the plan (to scale) and along x, of ``road`` (a
    :class:`~arzsumo.sumo.geometry.RoadGeometry`, read by attribute; m)."""
    fig, (top, bottom) = plt.subplots(2, 1, figsize=(11.0, 6.5), layout="constrained",
                                      height_ratios=(1.0, 1.0))
    _plan(top, road)
    _along(bottom, road)
    if title:
        fig.suptitle(title)
    return fig
