"""The figure of ``arzsumo premise``: the paired pulse's deviation norm against the pulse
gate's window, and the release-rate staircase with the outflow it moved."""

from __future__ import annotations

from collections.abc import Mapping

import numpy as np
from matplotlib.figure import Figure

from arzsumo.plots import plt
from arzsumo.units import veh_s_to_veh_h

#: (t - t0 s, D raw, D smoothed, floor, window s) of one seed's pulse
PulseSeries = tuple[np.ndarray, np.ndarray, np.ndarray, float, float]
#: (t s, q(L) veh/s, commanded r veh/s, step times s) of one seed's staircase
StairSeries = tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]
#: bins of the staircase's outflow means, s
MEAN_S = 10.0


def _pulse_panel(ax, pulses: Mapping[int, PulseSeries]) -> None:
    window = 0.0
    for k, (seed, (t, raw, smooth, floor, win)) in enumerate(sorted(pulses.items())):
        colour = f"C{k % 10}"
        ax.plot(t, raw, color=colour, lw=0.4, alpha=0.35)
        ax.plot(t, smooth, color=colour, lw=1.4, label=f"seed {seed}")
        if floor > 0:
            ax.axhline(floor, color=colour, ls=":", lw=1)
        window = max(window, win)
    ax.axvline(window, color="k", ls="--", lw=1, label="2 round trips")
    ax.axvline(window / 2, color="0.5", ls="--", lw=0.8, label="1 round trip")
    ax.set_xlabel("time after the pulse t - t0, s")
    ax.set_ylabel("D(t), m/s m^(1/2)")
    ax.set_title("paired pulse: ||pulse - baseline|| (thin raw, thick smoothed; "
                 "dotted: floor)", fontsize=9)
    ax.legend(fontsize=7, ncol=4)


def _means(t: np.ndarray, q: np.ndarray, dt: float) -> tuple[np.ndarray, np.ndarray]:
    k = max(1, round(MEAN_S / dt))
    n = q.size // k
    return t[: n * k].reshape(n, k)[:, -1], q[: n * k].reshape(n, k).mean(axis=1)


def _stair_panel(ax, stairs: Mapping[int, StairSeries]) -> None:
    tw = ax.twinx()
    for k, (seed, (t, q, r, steps)) in enumerate(sorted(stairs.items())):
        dt = float(t[1] - t[0]) if t.size > 1 else 1.0
        start = float(t[0]) - dt
        tb, qb = _means(t, q, dt)
        ax.step(tb - start, veh_s_to_veh_h(qb), where="pre", color=f"C{k % 10}", lw=1,
                label=f"q(L), seed {seed} ({MEAN_S:g} s means)")
        if k == 0:
            tw.step(t - start, veh_s_to_veh_h(r), where="pre", color="k", lw=1.2,
                    label="commanded release rate")
            for s in steps:
                ax.axvline(float(s) - start, color="0.8", lw=0.6)
    ax.set_xlabel("time since the staircase's start, s")
    ax.set_ylabel("mainline outflow q(L), veh/h")
    tw.set_ylabel("release rate r, veh/h")
    ax.set_title("release-rate staircase: the outflow's answer", fontsize=9)
    lines, labels = ax.get_legend_handles_labels()
    more, more_labels = tw.get_legend_handles_labels()
    ax.legend(lines + more, labels + more_labels, fontsize=7, ncol=2, loc="best",
              framealpha=0.8)


def premise_figure(pulses: Mapping[int, PulseSeries],
                   stairs: Mapping[int, StairSeries]) -> Figure:
    """Two panels: per seed the pulse's deviation norm D(t) (raw and smoothed, its floor)
    against one and two round trips after the pulse; and per seed the staircase's outflow
    q(L) in 10 s means with the first seed's commanded release rate (both veh/h)."""
    fig, (a, b) = plt.subplots(2, 1, figsize=(9, 7.5))
    _pulse_panel(a, pulses)
    _stair_panel(b, stairs)
    fig.tight_layout()
    return fig
